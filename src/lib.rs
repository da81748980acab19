//! # Quadrille
//!
//! Quadrille turns a triangle mesh (a scan, a sculpt, a CAD tessellation)
//! into a curvature-adaptive, feature-aligned quad-dominant mesh and a
//! Catmull–Clark control mesh whose limit surface hugs the input.
//!
//! The pipeline, one way: bytes → [`io::import`] (validated, repaired,
//! normalised [`mesh::TriMesh`]) → surface analysis (normals, curvature,
//! features, filtered normals) → sizing field → multiresolution hierarchy →
//! orientation field → position field → extraction into a half-edge
//! [`mesh::PolyMesh`] → repair and post-processing → Catmull–Clark fitting →
//! metrics. See `DESIGN.md` for the sources of each stage.
//!
//! Modules:
//! - [`mesh`]: triangle mesh, polygon lists, half-edge mesh, topology, frames;
//! - [`io`]: OBJ, PLY, STL, OFF, glTF readers; OBJ and PLY writers; import
//!   validation and repair;
//! - [`analysis`]: normals, cell areas, principal curvature, curvature
//!   averaging, feature vertices, filtered normals;
//! - [`sizing`]: curvature → target edge length per vertex (the sizing field);
//! - [`field`]: multiresolution hierarchy, orientation and position fields,
//!   singularities;
//! - [`spatial`]: closest points, distances and ray casts (BVH);
//! - [`extract`]: vertex clusters, faces, non-manifold repair, hole filling
//!   and post-processing into a closed quad-dominant [`mesh::PolyMesh`];
//! - [`param`]: the global path's integer-grid map (Bommes et al. 2009 MIQ
//!   as Ebke et al. 2014 §3–5 and Campen et al. 2016 §4 use it): per-face
//!   cross field in filtered tangent planes with period jumps and cones
//!   (Ebke §4), cut graph, wedges and transitions (shared with the
//!   layout), seamless map with Ebke §5's E_orient and Campen §4.2's
//!   alignment weight, greedy integer rounding, Campen §5's measures;
//! - [`layout`]: dual strip weaving: elastica graph and dual loops;
//! - [`metrics`]: the thesis' quality metrics of an output mesh;
//! - [`subdivision`]: Catmull–Clark subdivision, limit positions and
//!   normals, control-mesh fitting and the limit surface's error;
//! - [`pipeline`]: parameters, stages, cache and re-running;
//! - [`progress`]: progress reporting and cancellation for every stage;
//!   [`parallel`]: rayon natively, one thread in wasm.

pub mod analysis;
pub mod extract;
pub mod field;
pub mod io;
pub mod layout;
pub mod mesh;
pub mod metrics;
pub mod parallel;
pub mod param;
pub mod params_schema;
pub mod pipeline;
pub mod progress;
pub mod sizing;
pub mod spatial;
pub mod subdivision;

pub mod web;
