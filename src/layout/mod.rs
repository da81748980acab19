//! Dual strip weaving (Campen & Kobbelt 2014, *Dual Strip Weaving:
//! Interactive Design of Quad Layouts using Elastica Strips*).
//!
//! The loop engine (§5):
//! - [`surface_graph`]: g, the k-ring neighbourhood graph with approximate
//!   geodesic edges (§5.3);
//! - [`elastica`]: g′, its line graph with curved-edge weights (§5.3),
//!   principal-direction alignment (§5.5), feature curves and boundaries
//!   (§5.6, §5.7);
//! - [`loops`]: constrained dual loops through anchors via shortest paths and
//!   a metagraph (§5.4), dual curves ending on the boundary (§5.7), ranked
//!   alternatives for one anchor, and disabling covered nodes (§6.2);
//! - [`radix_heap`]: the monotone priority queue of its hover searches.
//!
//! From loops to strips, regions and the layout (§4.2, §5.8, §6, §7):
//! - [`embed`]: a loop as the sequence of mesh edges it crosses;
//! - [`strip_field`]: the cross field aligned with all committed loops and
//!   its singularities (§6.1);
//! - [`parametrization`]: the global parametrization with every loop on an
//!   isoline (§6.1);
//! - [`strips`]: each loop's strip grown to the singularities, its stripes
//!   and the covered directions for §6.2;
//! - [`regions`]: the regions between loops and their guidance colours
//!   (§4.2);
//! - [`primal`]: the quad layout implied by the loops, and its export (§7);
//! - [`symmetry`]: reflectional symmetry (§5.8).
//!
//! The design tool (§4.1): [`design`], the undoable session (hover, wheel,
//! anchors, commit, delete, mirror copies); [`proxy`], a coarse stand-in for
//! large meshes.
//!
//! Build once per mesh with [`LoopEngine::new`], then query
//! [`LoopEngine::best_loop`] (hover), [`LoopEngine::loops_through`]
//! (alternatives) or [`LoopEngine::constrained_loop`].

pub mod design;
pub mod elastica;
pub mod embed;
pub mod grid;
pub mod loops;
pub mod parametrization;
pub mod primal;
pub mod proxy;
pub mod radix_heap;
pub mod regions;
pub mod strip_field;
pub mod strips;
pub mod surface_graph;
pub mod symmetry;

pub use design::LayoutDesign;
pub use elastica::{ElasticaGraph, ElasticaParams};
pub use embed::{EdgeCrossing, EmbedError, EmbeddedLoop, LoopEmbedder, Singularity, embed_loop};
pub use loops::{Anchor, DualLoop, HoverStep, LoopEngine, SelfCrossing};
pub use strips::{Strip, StripAnalysis, StripParams, strip_analysis, strip_analysis_with};
pub use surface_graph::SurfaceGraph;

pub(crate) use crate::mesh::OrdF64;
