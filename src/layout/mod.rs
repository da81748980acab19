//! Dual strip weaving (Campen & Kobbelt 2014, *Dual Strip Weaving:
//! Interactive Design of Quad Layouts using Elastica Strips*), part 1: the
//! elastica loop engine of §5.2–§5.7 and the strip compatibility of §6.2.
//!
//! - [`surface_graph`]: g, the k-ring neighbourhood graph with approximate
//!   geodesic edges (§5.3);
//! - [`elastica`]: g′, its line graph with curved-edge weights (§5.3),
//!   principal-direction alignment (§5.5), feature curves and boundaries
//!   (§5.6, §5.7);
//! - [`loops`]: constrained dual loops through anchors via shortest paths and
//!   a metagraph (§5.4), dual curves ending on the boundary (§5.7), ranked
//!   alternatives for one anchor, and disabling covered nodes (§6.2).
//!
//! Build once per mesh with [`LoopEngine::new`], then query
//! [`LoopEngine::best_loop`] (hover), [`LoopEngine::loops_through`]
//! (alternatives) or [`LoopEngine::constrained_loop`].

pub mod design;
pub mod elastica;
pub mod embed;
pub mod loops;
pub mod parametrization;
pub mod proxy;
pub mod strip_field;
pub mod strips;
pub mod surface_graph;

pub use design::{LayoutDesign, Mirror};
pub use elastica::{ElasticaGraph, ElasticaParams};
pub use embed::{EdgeCrossing, EmbedError, EmbeddedLoop, LoopEmbedder, Singularity, embed_loop};
pub use loops::{Anchor, DualLoop, LoopEngine};
pub use strips::{Strip, StripAnalysis, StripParams, strip_analysis};
pub use surface_graph::SurfaceGraph;
