//! Mesh types: the indexed triangle mesh the pipeline reads ([`TriMesh`]),
//! polygon lists as files store them ([`FaceList`]), the half-edge polygon
//! mesh the extraction writes ([`PolyMesh`]), topology statistics
//! ([`Topology`]) and the similarity that normalises coordinates ([`Frame`]).
//!
//! Every type has a `validate()` that checks its documented invariants; tests
//! call it after every mutating operation.

mod adjacency;
mod face_list;
mod frame;
pub mod generate;
mod poly;
mod polygon;
pub mod refine;
mod topology;
mod tri;

pub use adjacency::EdgeTopology;
pub use adjacency::{
    BoundaryArcs, Csr, FaceAdjacency, RingCollector, VertexAdjacency, VertexFaces,
    boundary_half_edges, boundary_vertices,
};
pub use face_list::{EAR_CLIPPING_LIMIT, FaceList, drop_unused};
pub use frame::{Aabb, Frame};
pub use poly::{NONE, PolyMesh};
pub(crate) use polygon::{edge_faces, edge_key, face_newell_normal, newell_normal};
pub use topology::Topology;
pub(crate) use topology::UnionFind;
pub use tri::TriMesh;

/// A broken mesh invariant. Produced by `validate()` and by constructors that
/// refuse input they cannot represent.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MeshError {
    #[error("vertex {vertex} has a non-finite coordinate")]
    NonFinite { vertex: usize },
    #[error("face {face} refers to vertex {index}, but there are only {count} vertices")]
    IndexOutOfRange {
        face: usize,
        index: u32,
        count: usize,
    },
    #[error("face {face} has fewer than 3 distinct vertices")]
    DegenerateFace { face: usize },
    #[error("edge {a}-{b} is shared by more than two faces")]
    NonManifoldEdge { a: u32, b: u32 },
    #[error("edge {a}-{b} is used twice in the same direction (faces inconsistently oriented)")]
    InconsistentOrientation { a: u32, b: u32 },
    #[error("vertex {vertex} is non-manifold (its faces form more than one fan)")]
    NonManifoldVertex { vertex: u32 },
    #[error("vertex {vertex} is not used by any face")]
    IsolatedVertex { vertex: u32 },
    #[error("too many elements for 32-bit indices")]
    TooLarge,
    #[error("half-edge structure broken: {0}")]
    Connectivity(String),
}

/// An `f64` ordered by `total_cmp`, for the binary heaps of the
/// shortest-path searches (the layout's, the thin-part cap's).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct OrdF64(pub f64);
impl Eq for OrdF64 {}
impl PartialOrd for OrdF64 {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}
impl Ord for OrdF64 {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        self.0.total_cmp(&other.0)
    }
}
