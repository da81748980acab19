//! Dual loops as curves on the triangulation (Campen & Kobbelt 2014, §6.1
//! and §4.2 need every loop as the sequence of mesh edges it crosses): the
//! shared representation of the strip field, the parametrization, the
//! regions between loops and the primal layout.

/// Where a loop crosses a mesh edge: the point `(1 − t)·p[a] + t·p[b]` on
/// the undirected edge `{a, b}` with `a < b`, `t` strictly inside (0, 1).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EdgeCrossing {
    pub a: u32,
    pub b: u32,
    pub t: f64,
}

/// A dual loop (closed) or dual curve (open: from a boundary edge to a
/// boundary edge) traced on the triangulation.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct EmbeddedLoop {
    /// Consecutive edge crossings along the loop.
    pub crossings: Vec<EdgeCrossing>,
    /// `faces[i]` is the triangle holding the segment from `crossings[i]`
    /// to `crossings[i + 1]` (index taken mod n when closed): n entries when
    /// closed, n − 1 when open.
    pub faces: Vec<u32>,
    pub closed: bool,
}

/// A singularity of a cross field at a mesh vertex: `index` in quarter
/// turns (+1: the field turns by +π/2 around the vertex, a valence-3-like
/// corner; −1: valence 5).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Singularity {
    pub vertex: u32,
    pub index: i32,
}
