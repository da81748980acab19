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
//! metrics. That is the local mode; in the global mode
//! ([`pipeline::RemeshMode::Global`]) the analysis is followed by the
//! integer-grid map ([`param`]) and its quads extracted in the manner of
//! QEx ([`extract::qex`]): pure quads, fitted without the extra split.
//!
//! The sources, cited by section below and in each file's opening comment:
//!
//! - **Kloiber 2018**, *Creating Subdivision Meshes from Scan Data* (thesis):
//!   the main pipeline, §3.1–3.9, metrics chapter 4;
//! - **Instant Meshes** (Jakob et al. 2015), the local field optimisation the
//!   thesis modifies, cited as "digest §" after the project's prose digest of
//!   it (hierarchy §2, orientation §3, position §4, extraction §5);
//! - **Ebke et al. 2014**, *Level-of-Detail Quad Meshing*: filtered normals
//!   (§3);
//! - **Campen et al. 2016**, *Scale-Invariant Directional Alignment of
//!   Surface Parametrizations*: smooth regions and significance (§3–4);
//! - **Campen & Kobbelt 2014**, *Dual Strip Weaving: Interactive Design of
//!   Quad Layouts using Elastica Strips*: the layout tool (§4–7).
//!
//! Modules (and the sections each implements):
//! - [`mesh`]: triangle mesh, polygon lists, half-edge mesh, topology,
//!   frames, adjacency (CSR), and the mesh primitives every stage shares
//!   (union-find, edge keys and edge tables, Newell normals); analytic test
//!   surfaces in [`mesh::generate`];
//! - [`io`]: OBJ, PLY, STL, OFF, glTF readers; OBJ and PLY writers; import
//!   validation and repair;
//! - [`analysis`]: normals, cell areas (Kloiber Fig. 3.9), principal
//!   curvature (§3.1.1), curvature selection (§3.1.2) and averaging
//!   (§3.1.3), feature vertices (§3.3), filtered normals (Ebke §3), smooth
//!   regions (Campen 2016 §3.1–3.2);
//! - [`sizing`]: curvature → target edge length per vertex, the sizing field
//!   (Kloiber §3.2);
//! - [`field`]: multiresolution hierarchy (digest §2.1–2.3, Kloiber §3.1.4),
//!   4-RoSy/4-PoSy lattice compatibility (digest §3.1–3.2, §4.1–4.3),
//!   orientation field (digest §2.4–2.6, §3.3; Kloiber §3.3), position field
//!   (digest §4.4; Kloiber §3.4), singularities (digest §3.4, §4.6);
//! - [`spatial`]: closest points, distances and ray casts (BVH) for the
//!   metrics, the extraction's reprojection and the fitting;
//! - [`extract`]: vertex clusters (digest §5.1–5.5, Kloiber §3.5.1), snapping
//!   (digest §5.6, Kloiber §3.5.2), faces and hole filling (digest §5.7–5.10,
//!   Kloiber §3.5.3), non-manifold repair (Kloiber §3.6), post-processing
//!   (Kloiber §3.7) and the pure-quad split (digest §5.11) into a closed
//!   quad-dominant [`mesh::PolyMesh`];
//! - [`param`]: the global path's integer-grid map (Bommes et al. 2009 MIQ
//!   as Ebke et al. 2014 §3–5 and Campen et al. 2016 §4 use it): per-face
//!   cross field in filtered tangent planes with period jumps and cones
//!   (Ebke §4), cut graph, wedges and transitions (shared with the
//!   layout), seamless map with Ebke §5's E_orient and Campen §4.2's
//!   alignment weight, greedy integer rounding, Campen §5's measures;
//! - [`subdivision`]: Catmull–Clark subdivision, limit positions and normals
//!   (Kloiber §3.8, Halstead et al. 1993 stencils), control-mesh fitting
//!   (Kloiber §3.8) and the limit surface's error (§3.9, §5);
//! - [`metrics`]: the thesis' quality metrics of an output mesh (Kloiber
//!   chapter 4);
//! - [`layout`]: dual strip weaving (Campen & Kobbelt 2014):
//!   - [`layout::surface_graph`]: the surface graph g (§5.3);
//!   - [`layout::elastica`]: the elastica graph g′ (§5.3, §5.5–5.7);
//!   - [`layout::loops`]: dual loops through anchors (§5.4, §5.7);
//!   - [`layout::symmetry`]: mirror planes and mirrored loops (§5.8);
//!   - [`layout::embed`]: loops as curves on the triangulation (§6.1, §4.2);
//!   - [`layout::strip_field`]: the strip cross field (§6.1);
//!   - [`layout::parametrization`]: the global map S with loops on
//!     isolines (§6.1);
//!   - [`layout::strips`]: dual strips from S (§6, §6.2);
//!   - [`layout::regions`]: regions and their guidance colours (§4.2), the
//!     loop arrangement;
//!   - [`layout::primal`]: primalization into a quad layout (§7);
//!   - [`layout::design`]: the design session, hover, anchors, commit, undo
//!     (§4.1, §6.2, §5.8);
//!   - [`layout::proxy`]: a coarse proxy of a large mesh for interactive
//!     design (§4);
//! - [`pipeline`]: parameters, stages, cache and re-running;
//! - [`params_schema`]: every pipeline parameter's path, explanation, kind
//!   and range, for the Parameters panel;
//! - [`progress`]: progress reporting and cancellation for every stage;
//! - [`parallel`]: rayon natively, one thread in wasm;
//! - [`web`]: the browser side: [`web::mesh_arrays`] (the flat arrays a mesh
//!   is drawn from), [`web::layout_glue`] (what design mode draws after each
//!   change: region guidance §4.2, strips §6, layout §7), [`web::viewer`]
//!   (the wgpu renderer and its layers, Kloiber §3.9), and, wasm32 only,
//!   `web::worker_api` (the Web Worker's session running the pipeline stage
//!   by stage) and `web::layout_api` (timing the loop engine, §5.2–5.7).

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
