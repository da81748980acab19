//! Quad mesh extraction from an integer-grid map in the manner of QEx
//! (Ebke, Bommes, Campen & Kobbelt 2013, as Ebke et al. 2014 §6 uses it;
//! `../shared/reference/integer-grid-maps-digest.md` §4).
//!
//! (Work in progress: the skeleton of the interface.)

use crate::mesh::{PolyMesh, TriMesh};
use crate::param::GridMap;
use crate::progress::{Cancelled, Progress};

/// What the extraction found and what it had to drop.
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize)]
pub struct QexReport {
    /// Integer points of the map that became vertices.
    pub grid_vertices: usize,
    /// Quad-mesh edges (pairs of traced local edges that met).
    pub edges: usize,
    /// Faces of the output.
    pub faces: usize,
}

/// The extracted quad mesh, in the coordinates of the map's mesh.
#[derive(Debug, Clone)]
pub struct Quadrangulation {
    pub mesh: PolyMesh,
    pub report: QexReport,
}

/// Why no quad mesh came out.
#[derive(Debug, Clone, PartialEq)]
pub enum QexError {
    Cancelled,
    /// The map has no integer point (the target is too coarse for it).
    Empty,
    /// What was extracted could not be built into a manifold mesh.
    Invalid(String),
}

impl From<Cancelled> for QexError {
    fn from(_: Cancelled) -> QexError {
        QexError::Cancelled
    }
}

impl std::fmt::Display for QexError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            QexError::Cancelled => write!(f, "cancelled"),
            QexError::Empty => write!(f, "the integer-grid map has no integer point (is the target vertex count too small?)"),
            QexError::Invalid(m) => write!(f, "quad extraction failed: {m}"),
        }
    }
}

/// Extracts the quad mesh of `map` on `mesh` (the mesh the map was
/// computed on).
pub fn extract(
    mesh: &TriMesh,
    map: &GridMap,
    progress: &mut Progress<'_>,
) -> Result<Quadrangulation, QexError> {
    let _ = (mesh, map, progress);
    Err(QexError::Invalid("not yet implemented".into()))
}
