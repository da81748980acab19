//! The global path's integer-grid map (Bommes, Zimmer & Kobbelt 2009,
//! *Mixed-Integer Quadrangulation*, as Ebke et al. 2014 §3–5 and Campen et
//! al. 2016 §4 use it; `../shared/reference/integer-grid-maps-digest.md`):
//!
//! 1. [`cross_field`]: per-face crosses in the filtered tangent planes with
//!    period jumps and cones (Ebke §4);
//! 2. [`cut`]: combing along a dual spanning tree, the cut graph through
//!    the cones, wedges and matchings (MIQ §4) — shared with the layout
//!    tool's parametrization;
//! 3. [`seamless`]: one (u, v) per wedge, transitions with integer
//!    rotations and translations, Ebke §5's E_orient with projected
//!    non-orthonormal crosses and the sizing S(f), Campen §4.2's alignment
//!    weight, Campen §4.3's closed isolines around cyclic smooth regions,
//!    boundaries on isolines, exact linear constraints
//!    ([`constraints`]); greedy integer rounding with re-solves;
//! 4. [`measures`]: flips, Campen §5's stretch, shear and misalignment;
//!    [`export`]: the input mesh with per-corner texture coordinates.
//!
//! Parameter units: one unit is one target edge of the calibrated sizing
//! field (the same calibration as the local path's).

pub mod anisotropy;
pub mod boundary;
pub mod conformal;
pub mod constraints;
pub mod cross_field;
pub mod cut;
pub mod export;
pub mod manifold;
pub mod measures;
pub mod seamless;
pub mod small_holes;
pub mod solve;
pub mod thin_parts;
pub mod topology;

use glam::DVec3;
use serde::{Deserialize, Serialize};

use crate::analysis::filtered_normals::{Sigma, face_sigma_from_sizing, filtered_normals};
use crate::analysis::smooth_regions::{SmoothRegionParams, SmoothRegions, smooth_regions};
use crate::analysis::{self, AnalysisParams, FilteredNormalsMode, SurfaceAnalysis};
use crate::mesh::TriMesh;
use crate::sizing::SizingParams;

pub use cross_field::{Cone, CrossField, CrossFieldInput};
pub use cut::{Cut, CutInput};
pub use seamless::{GridMap, MapInput, Transition, rotate};
pub use topology::{EdgeTopology, Fan, NO_FACE, vertex_fans};

/// Which principal directions constrain the cross field (besides the
/// boundary, which is always aligned).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Alignment {
    /// Only the boundary (the smoothest field otherwise).
    #[default]
    None,
    /// Faces at feature vertices (Kloiber §3.3) get the feature direction.
    FeatureVertices,
    /// Faces in filtered smooth regions get a_min (Campen §4.1, weight ∞)
    /// and the parametrization alignment weight (Campen §4.2).
    SmoothRegions,
    /// Both.
    Both,
}

/// Parameters of the integer-grid map. Every field has a default.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Params {
    /// Surface analysis (curvature, features); its filtered-normal setting
    /// is ignored: the map filters with the calibrated sizing itself.
    pub analysis: AnalysisParams,
    /// Sizing field; calibrated to the target vertex count as in the
    /// local path. Default: input vertices / 16.
    pub sizing: SizingParams,
    /// Filter the normals (Ebke §3). Default true.
    pub filtered_normals: bool,
    /// σ(f) = factor · S(f). Default 0.5 (Ebke: σ = s/2).
    pub sigma_factor: f64,
    /// Kernel truncation in units of σ. Default 2.
    pub truncation: f64,
    /// Default [`Alignment::None`]: the cones are the field's own.
    pub alignment: Alignment,
    /// Smooth-region significance threshold (default 70°).
    pub smooth_regions: SmoothRegionParams,
    /// Campen §4.2's w in the {0, w} weight field, on the cross axis
    /// nearest a_min (see `seamless`). Default 5. Smooth regions, shear /
    /// misalignment (°) with w = 0 → 5 at the default target and at 1000
    /// vertices: fandisk 7.88/5.87 → 6.21/4.79, 7.03/5.47 → 6.06/4.50;
    /// rocker-arm 7.17/5.75 → 6.66/5.52, 6.41/4.98 → 5.40/4.15; spot
    /// 13.24/11.79 → 12.17/9.89, 10.45/8.73 → 8.88/6.96; bunny
    /// 9.05/8.65 → 9.30/8.15, 9.87/9.51 → 9.33/8.46. With a_min itself
    /// as the axis (Campen's literal term; our cross-field constraint is
    /// soft) w = 5 gave 6.24/4.77, 6.76/4.51; 6.28/5.07, 5.71/4.45;
    /// 15.89/12.30, 11.92/8.23; 9.25/8.53, 9.95/8.55 (measured when the
    /// topology constraints chose the closed coordinate by the loop's
    /// direction, which then gave 6.37/4.93, 5.79/4.35; 14.96/11.35,
    /// 11.19/8.14; 8.71/8.49, 9.85/8.64 with ŵ).
    pub region_weight: f64,
    /// The smooth regions' cross-field constraint: None fixes the region
    /// faces' crosses to a_min (Campen §4.1's ∞ weight); a weight w makes
    /// it soft, w · A(f) · (θ_f − θ(a_min))² modulo quarter turns next to
    /// E_smooth (areas normalised to mean 1, E_smooth's edges weigh 1), so
    /// the field need not jump where neighbouring regions' a_min disagree.
    /// Default 1. Smooth regions, shear / misalignment (°) at the default
    /// target, 1000 and 3000 vertices: fandisk hard 8.15/5.21, 6.79/5.08,
    /// 5.65/3.93 → soft 6.21/4.79, 6.06/4.50, 5.60/3.96 (feature vertices
    /// 7.64/7.92, 6.91/7.34, 5.30/6.05); rocker-arm hard 6.26/4.75,
    /// 5.48/4.13, 5.25/3.99 → soft 6.66/5.52, 5.40/4.15, 5.26/4.18
    /// (feature vertices 6.11/7.41, 5.72/6.90, 5.71/6.43). Flipped
    /// triangles at the default target: fandisk 21 → 8, rocker-arm 25 →
    /// 32. (Rocker-arm's figures are with its topology constraints closing
    /// the cheaper coordinate, [`Params::cyclic_constraints`]; when they
    /// chose it by the loop's direction, hard 7.09/5.11, 5.60/4.33,
    /// 5.91/4.21 → soft 6.37/4.93, 5.79/4.35, 5.15/4.10, flips 41 → 32.)
    /// (The soft constraint's weight against E_smooth depends on the
    /// input's face density, not on the target edge: at the default
    /// target, input vertices / 16, S² ≈ 32 mean face areas.)
    pub region_cross_weight: Option<f64>,
    /// Sharp edges (face normals more than this many degrees apart) on
    /// curves at least one target edge long are feature curves: their
    /// faces' crosses contain them and they lie on integer isolines
    /// (Bommes et al. 2009 §4, as Ebke §5 keeps them). 0 turns it off.
    /// At every vertex of the curves the cross field's sectors between
    /// them get whole quarter turns, so corners are cones of the index
    /// their angles ask for (`cross_field::corner_sectors`; on fandisk
    /// the plain rounding put 5 of its 23 corner cones one or two rings
    /// away); of two feature edges less than 45° apart around a vertex
    /// one is dropped (`drop_sliver_sectors`: such a sector would get a
    /// quarter turn), and so is the shorter of two curve segments closer
    /// than [`Params::feature_curve_spacing`]. Default 0 (off) here; the
    /// pipeline's global mode uses 60°, filtered at the target scale
    /// ([`crate::pipeline::RemeshParams::feature_curve_degrees`] has the
    /// figures). Measured before that filter, at 60°
    /// fandisk's misalignment falls 25.65° → 5.41°, but the map still
    /// folds more. Flipped triangles / cones without features → with 60°
    /// at the default target and at 1000 vertices: fandisk 6/16 → 24/30,
    /// 7/24 → 24/30 — the rest next to cones a ring off the curves, four
    /// of them +¼ at rounded corners of the curves (sectors of 158° and
    /// 180° at four vertices each: no single vertex asks for the cone),
    /// which the rounding puts on the curve's isoline
    /// ([`Params::feature_cone_snap`] moves them); rocker-arm 7/20 →
    /// 9/22, 6/20 → 5/24; bunny 77/38 → 100/48, 116/40 → 119/48 (its
    /// sharp edges are scan noise); with feature-vertex alignment fandisk
    /// 10 → 32, rocker-arm 22 → 24 flips. (Before the sliver rule:
    /// fandisk 192 and 46, rocker-arm 27 and 25, bunny 129 and 150.)
    /// Zero-area triangles count as flipped (`degenerate_triangles` counts
    /// them apart): of the bunny's 77 without features 54 have zero area,
    /// 48 of them with two boundary corners at the same (u, v) (its small
    /// holes, whose boundary edges lie on isolines of both coordinates,
    /// collapse); fandisk's 24 with 60° curves have 6.
    pub feature_curve_degrees: f64,
    /// Of two feature curve segments closer than this many target edges
    /// (away from a corner they share), the shorter is no feature curve
    /// (`drop_close_curves`): both on integer isolines less than half a
    /// unit apart round onto one isoline and the strip between them
    /// collapses (fandisk's narrow faces between parallel creases: a
    /// 61-triangle strip at u = 6), and up to a unit apart they round
    /// either onto one or a unit apart, a stretch. 0 keeps them all.
    /// Default 0.75. With 60° curves, flipped triangles / cones /
    /// misalignment / shear (°) with 0 → 0.75 at the default target and
    /// at 1000 vertices: fandisk 124/30/4.22/6.91 → 24/30/5.41/6.72,
    /// 40/30/3.91/5.22 → 24/30/4.32/5.63; rocker-arm 16/24/20.74/5.54 →
    /// 9/22/18.80/5.10, 15/26/18.59/4.55 → 5/24/18.69/4.45; bunny
    /// 114/54/22.89/6.23 → 100/48/22.85/5.96, 139/52/24.28/6.50 →
    /// 119/48/23.86/6.73; spot has no 60° curves. With feature-vertex
    /// alignment: fandisk 59 → 32, rocker-arm 34 → 24 flips. At 0.5:
    /// fandisk 34 and 34, rocker-arm 9 and 16 flips; at 1: fandisk 17
    /// flips but 18 cones and misalignment 7.36°.
    pub feature_curve_spacing: f64,
    /// Keep only the feature edges that are creases at the target scale
    /// (`keep_sharp_at_target_scale`). Default true: with 60° curves over
    /// 5 vertex orders (docs/QUALITY.md) it is what makes them pay on
    /// every shared mesh — without it the cow's facets became curves (EV
    /// 12.4 → 15.6 %, corner deviation 7.33° → 10.4°).
    pub feature_curve_scale: bool,
    /// Re-solves of MIQ's stiffening after the rounding: faces flipped
    /// against an unflipped cross weigh 4× more (their neighbours 2×) per
    /// re-solve, until none is left. Default 4. Flipped triangles (after
    /// the extraction's unfolding) / traces that did not meet / Euler
    /// characteristic of the extracted quads, at the default target,
    /// 0 → 4: spot 41/27/4 → 6/1/2 (input 2), fandisk 3/2/2 → 2/0/2,
    /// rocker-arm 4/8/0 → 0/0/0, bunny 71/15 → 67/13; cow 394 → 390
    /// (its folds are Ebke's deliberate ones, flipped crosses). Cost: one
    /// sparse solve each (bunny 1.8 → 2.8 s for the map).
    pub stiffening: usize,
    /// The map's target edge is S(f) · e^{−φ}, the conformal scale of the
    /// metric whose only curvature is the cross field's cones
    /// ([`conformal`]), bounded to within this factor of S(f); 0 keeps
    /// S(f). Default 2. Campen §5's shear without → with, at the default
    /// target: fandisk 5.62° → 4.97° (flipped triangles 7 → 0), rocker-arm
    /// 7.66° → 3.79°, spot 10.04° → 8.37° (52 → 69 flips)
    /// (tests/param.rs), the bunny 6.37° → 3.28° (`quadrille param`). Unbounded, the factor spans
    /// 0.40–54 on the cow (1st–99th percentile of faces: its legs and
    /// horns are long protrusions, which a conformal scale shrinks
    /// exponentially) and 0.75–4.3 on spot, against 0.69–1.36 on the
    /// bunny; bounded by 2 the cow's quad corners deviate 7.1° instead of
    /// 10.7° (one vertex order). The quality table's figures are at
    /// [`crate::pipeline::RemeshParams::conformal_scale`].
    pub conformal_scale: f64,
    /// With feature curves: cones of the field off the curves but nearer a
    /// vertex of them (two or more feature edges) than this many target
    /// edges move onto it (its sectors get the cone's quarter turns, and
    /// the period jumps are rounded again, `cross_field::snap_cones`): a
    /// cone at an integer point less than half a unit from a curve's
    /// integer isoline is rounded onto it and the ring between folds; on
    /// fandisk four +¼ cones sit a ring off rounded corners of the curves
    /// (sectors of 158° and 180° at four vertices each). 0 (the default)
    /// leaves them: with 60° curves, flipped triangles / cones / shear /
    /// misalignment (°) with 0 → 0.5 at the default target: fandisk
    /// 24/30/6.72/5.41 → 15/30/6.41/5.15, rocker-arm 9/22/5.10/18.80 →
    /// 7/22/5.77/19.96, bunny 100/48/5.96/22.85 → 92/44/5.86/22.54; but at
    /// 1000 vertices fandisk 24 → 29 and bunny 119 → 144 flips (rocker-arm
    /// 5 → 5): the moved cone's old neighbourhood is not re-solved, only
    /// the period jumps re-rounded.
    pub feature_cone_snap: f64,
    /// Campen §4.3's topology constraints: around every boundary loop of a
    /// filtered cyclic smooth region with turning number zero (only with
    /// smooth-region alignment), one coordinate comes back to its start
    /// value through the transitions, so isolines close there (no
    /// helix). Default true: on a capsule the closure error (the smaller
    /// holonomy component around the loops) is 3 without and 0 with it,
    /// and with a helical field there 7 without and 0 with it
    /// (tests/param.rs). The closed component is the one whose closing
    /// costs the least energy (`seamless::close_loops`): choosing it by
    /// the loop's direction closed, on spot at 1000 vertices, the
    /// coordinate that was not closing around a loop the map already
    /// closed in the other, and the map collapsed there (200 flipped
    /// triangles against 21 without). Misalignment / shear (°) / flipped
    /// triangles without → with (fandisk has no cyclic region: the same
    /// map): rocker-arm 4.57/5.51/38 → 5.52/6.66/32 at the default
    /// target, 4.41/5.70/16 → 4.15/5.40/19 at 1000 vertices,
    /// 4.38/5.52/17 → 4.18/5.26/13 at 3000; spot 12.23/13.23/143 →
    /// 9.89/12.17/113, at 1000 vertices 8.50/9.37/21 → 6.96/8.88/15;
    /// bunny 8.15/9.33/137 → 8.15/9.30/134. Flipped triangles are not
    /// fewer with them at every target (rocker-arm 600: 34 → 38, bunny
    /// 800: 166 → 194). Those differences are the integer rounding's
    /// (with them the cones round one at a time, a different greedy
    /// path), not the constraints': on the seamless relaxation (`round`
    /// false) shear (°) / flipped triangles without → with are
    /// rocker-arm 4.98/8 → 4.98/9 at the default target, 4.99/8 →
    /// 5.00/8 at 1000; spot 8.42/46 → 8.39/46, 8.30/6 → 8.26/7; bunny
    /// 8.38/36 → 8.45/35, 8.29/35 → 8.36/34; and rounding the
    /// unconstrained map one quantity at a time (`batch_fraction` 0.001)
    /// gives rocker-arm at the default target the figures with them
    /// (6.66°, 32 flips).
    pub cyclic_constraints: bool,
    /// Round integer variables (translations, cones, boundary isolines).
    /// Default true; false gives the seamless relaxation.
    pub round: bool,
    /// Fraction of the remaining integer variables rounded per re-solve,
    /// the cone coordinates first (a fraction of them, nearest to an
    /// integer first), then the rest. Default 0.5 (1 would round all at
    /// once). Rounding every cone coordinate in the first step instead
    /// (as before) gave E_orient / flipped triangles / shear (°) at the
    /// default target, against now: fandisk 15.06/3/5.45 → 14.19/6/5.61,
    /// with feature vertices 34.63/11/8.00 → 21.23/10/7.64, smooth
    /// regions 36.26/10/6.42 → 29.19/8/6.24; rocker-arm 37.55/26/7.28 →
    /// 21.41/7/7.50, 43.95/39/7.03 → 41.45/22/6.11, 92.08/51/8.36 →
    /// 66.94/37/6.28; spot 60.69/135/13.61 → 17.66/67/9.38,
    /// 150.72/1050/23.07 → 22.62/84/11.06, 110.50/393/19.94 →
    /// 73.72/332/15.89; bunny 109.05/76/6.38 → 97.93/77/6.15 (no extra
    /// time: the re-solves are small dense ones). The re-solves are small
    /// dense ones on the condensed system, so MIQ's one at a time costs
    /// about the same: on the bunny 0.001 takes 113 re-solves instead of
    /// 9 in the same parametrization time, E_orient 109.05 → 106.56,
    /// flipped triangles 76 → 79; fandisk, rocker-arm and spot are
    /// unchanged (their translations follow from the cones).
    pub batch_fraction: f64,
    /// Target edges across the narrowest strip between two boundary
    /// loops: the map's target edge is capped at the strip's width over
    /// this, graded like the thin-part cap
    /// ([`crate::analysis::thickness::loop_gap_cap`]; loops shorter than
    /// a quad's perimeter, and surfaces where the cap would cost more
    /// than the count tolerance, get none: `cap_loop_gaps`), so the
    /// loops' isolines round to different integers and the strip between
    /// them keeps its quads. 0 turns it off.
    ///
    /// Default 4. If the map followed S(f) exactly 2 would do (each of the
    /// strip's two isolines moves by at most half a unit in the
    /// rounding), and on a flat sheet it does (tests/qex.rs); but a dip of
    /// S(f) without cones is only partly realised by the seamless map: on
    /// the bunny's strip between its two bottom holes (1.04 edges) the
    /// map's scale was 1.43 units per target edge where the cap asked
    /// about 1.6–2. Medians over 5 vertex orders at the default target
    /// (`scripts/quality.py --orders 5`, rows global / global - loop
    /// separation / loop separation 2, 3): the bunny's Hausdorff distance
    /// 0.0577 (off) → 0.0560 (2), 0.0439 (3), 0.0441 (4); its 5 input
    /// loops came out as 3, 5, 3, 4, 3 loops off, 3–4 with 2, 4 with 3
    /// and all 5 in every order with 4; EV 3.6 → 3.5 %, corner deviation
    /// 4.05° → 4.10°, vertices 2,133 → 2,239 (target 2,177).
    /// Teapot, suzanne and the beetle are unchanged (their loops are
    /// short or the cap is over the budget; without the budget the
    /// beetle's Hausdorff distance went 0.200 → 0.306–0.360); the closed
    /// meshes have no loops.
    pub loop_separation: f64,
    /// The map's mesh is made manifold and closed where the input's holes
    /// are below the target scale before the map: non-manifold vertices
    /// split, one per fan ([`manifold`]), and boundary loops shorter than
    /// the loops the output is to keep
    /// ([`crate::metrics::KEPT_LOOP_EDGES`] target edges of the
    /// calibrated sizing) closed ([`small_holes`]); the map runs on that
    /// mesh ([`Run::mesh`]). Default true. Medians over 5 vertex orders
    /// at the default target (`docs/RESULTS.md`, "The global mode's map
    /// mesh"), off → on: the beetle's Hausdorff distance 0.350 → 0.145
    /// (a part lost in 4 orders → in none), mean input → output distance
    /// 0.088 → 0.040, corner deviation 21.9° → 21.9°; suzanne 0.351 →
    /// 0.299 (one order 27 vertices for 32); the teapot 0.0815 → 0.0790,
    /// corner deviation 20.6° → 21.1°; the bunny and the closed meshes
    /// unchanged (no loop below two target edges, no sheets touching).
    /// On one map of the beetle (no count correction) the quads went 8 →
    /// 14 → 25 faces and the Hausdorff distance 0.435 → 0.442 → 0.178
    /// (off → holes closed at 4 target edges → also the vertices split).
    pub close_small_holes: bool,
    /// Thin parts: target edges round a part thinner than this many
    /// target edges round (its shape diameter), asked across the part
    /// only ([`thin_parts`]: the map's target edge across it is capped,
    /// along it stays S(f)); 0 turns it off. Default 0 (off).
    ///
    /// Off because it brings back neither the cow's legs nor spot's
    /// horns: the map unfolds them (the cow's front legs below the knee:
    /// parametric area 0.16 − 0.16 units² off, 2.2 − 0.08 with 5 round),
    /// but their hooves' cones still round together and QEx drops them.
    /// Medians over 5 vertex orders at the table's targets (`FIT=0
    /// python3 scripts/orders.py BIN TAG
    /// '{"remesh":{"mode":"global","thin_part_across":E}}' MESH…`), off
    /// → 3 / 5 edges round (Instant Meshes in brackets), Hausdorff and
    /// corner deviation: cow 0.195, 7.52° → 0.209, 11.1° / 0.201, 15.7°
    /// (0.115, 11.55°; its tail, hung from the back by one vertex, comes
    /// back as distorted quads); spot 0.125, 9.35° → 0.130, 9.90° /
    /// 0.105, 9.95° (0.110, 9.77°); suzanne 0.299, 15.9° → 0.242, 12.7°
    /// / 0.248, 15.6° (0.272, 16.6°: its ears); teapot 0.079, 21.6° →
    /// 0.085, 19.6° / 0.065, 21.0° (0.117, 31.4°); beetle 0.239, 22.2° →
    /// 0.259, 16.2° / 0.263, 17.6° (0.149, 18.2°; over 15 orders 0.165,
    /// 22.2° → 0.263, 17.1° at 3: a part near its bottom lost in 12 of 15
    /// orders); fandisk 0.0447, 5.67° → 0.0445, 5.51° / 0.0451, 5.99°
    /// (0.0587, 5.81°); rocker-arm 0.0314, 5.24° → unchanged / 0.0291,
    /// 5.03°; the bunny 0.0380, 3.95° → 0.0367, 4.13° / 0.0380, 4.51°
    /// (0.0379, 4.83°). At 8 round the bunny went to 0.0505, 5.98°. With
    /// the filtered normals' σ capped as well (5 round): cow 0.179,
    /// 13.4°; spot 0.094, 11.0°; suzanne 0.255, 17.7°.
    pub thin_part_across: f64,
    /// Thin parts, the hard way: round every part between
    /// [`thin_parts::LEVEL_OF_DETAIL`] and this many target edges round
    /// (the shortest plane section through a face,
    /// [`thin_parts::thin_part_loops`]) the loop's image in the map gets
    /// the development E_orient asks for, scaled to this many units
    /// (`seamless::widen_loops`, a hard constraint of the integer
    /// rounding like Campen §4.3's): an integer translation of that
    /// length round a loop whose holonomy does not rotate, the base
    /// point's distance from the holonomy's centre where it does. 0 turns
    /// it off. Default 0 (off).
    ///
    /// Off because it keeps the cow's legs only in part and costs its
    /// corners: medians over 5 vertex orders at the default target
    /// (`FIT=0 ORDERS=5 python3 scripts/orders.py BIN TAG
    /// '{"remesh":{"mode":"global","thin_part_loops":L}}' MESH…`,
    /// docs/RESULTS.md "Thin parts: the loop constraint"), Hausdorff and
    /// corner deviation, off → 3 → 4 (Instant Meshes in brackets): cow
    /// 0.195, 7.52° → 0.193, 12.7° → 0.179, 14.7° (0.115, 11.55°); spot
    /// 0.125, 9.35° → 0.099, 9.66° → 0.132, 9.75° (0.110, 9.77°); suzanne
    /// 0.299, 15.9° → 0.269, 15.0° → 0.267, 12.6° (0.272, 16.6°); teapot
    /// 0.079 → 0.062 → 0.050 (0.117); the bunny 0.0380 → 0.0391 →
    /// 0.0389 (0.0379); rocker-arm 0.0314 → 0.0325 → 0.0294; fandisk
    /// within 2 %, its corners 5.67° → 5.28° at 3; the beetle has no
    /// loop. On the cow (`quadrille param`, default target) the legs'
    /// parametric area below the knee rises from 0.01–0.16 to 0.03–1.2
    /// units² per slab a quarter of a unit high, with folds left in one
    /// leg; most loops there rotate (the legs carry −¼ cones above +¼
    /// ones at the hooves), and QEx keeps a leg in part, as distorted
    /// quads or as a piece of its own (tests/qex.rs's finger: a closed
    /// piece apart from the sphere).
    pub thin_part_loops: f64,
    /// Curvature-aligned anisotropic target lengths ([`anisotropy`]): per
    /// face, the edge along the direction of largest |κ| shorter and the
    /// one across it longer, equal sagittas both ways at the same quad
    /// area, the ratio of the two capped at this; ≤ 1 turns it off.
    /// Default 0 (off).
    ///
    /// Off because it does not bring issue 19's limit bar (≤ 0.8× Instant
    /// Meshes' at equal control-vertex count) to the organic meshes: the
    /// smoothest cross field is not aligned with their principal
    /// directions (`measures.anisotropy_realised` 0.18 on spot, 0.40 on
    /// rocker-arm at ratio 2), so the map realises little of what it is
    /// asked. Medians over 5 vertex orders at 4× the default target
    /// (`FIT=1 TARGET_X=4 python3 scripts/orders.py BIN TAG
    /// '{"remesh":{"mode":"global","curvature_anisotropy":R}}' MESH…`),
    /// limit after fit / Instant Meshes' (docs/QUALITY.md's medians at the
    /// default target, split) and control vertices, off → 1.5 → 2 → 3:
    /// spot 0.88 (732) → 0.86 (750) → 0.86 (736) → 0.86 (746); cow 0.92
    /// (704) → 0.92 (701) → 0.91 (696) → 0.90 (714); bunny 0.98 (8,630)
    /// → 0.97 (8,780) → 0.96 (8,817) → 0.96 (8,797); rocker-arm 0.96
    /// (2,482) → 0.92 (2,549) → 0.92 (2,580) → 0.90 (2,572); fandisk 0.23
    /// (1,526) → 0.17 (1,562) → 0.17 (1,590) → 0.17 (1,609); beetle 0.53
    /// → 0.47 → 0.50 → 0.52; teapot 1.02 (833) → 0.88 (910) → 0.84 (848)
    /// → 0.75 (847); suzanne 0.82 → 0.79 → 0.76 → 0.76. Spot's Hausdorff
    /// distance rises 0.029 → 0.045–0.049 (the others' within ±15 % or
    /// lower). The maps come out a few per cent denser; at the
    /// base's count (target scaled to it) ratio 3 gives spot 0.90 (731),
    /// bunny 0.98 (8,618), rocker-arm 0.94 (2,498), against teapot 0.72
    /// (836) and fandisk 0.18 (1,486): the surfaces of revolution and
    /// the fillets gain 20–30 %, the organic ones nothing. Corner
    /// deviation off → 3: spot 5.22° → 5.53°, cow 7.12° → 6.95°, bunny
    /// 3.07° → 3.40°, rocker-arm 3.00° → 3.30°, fandisk 4.54° → 4.67°,
    /// beetle 25.0° → 27.7° (Instant Meshes 9.77°, 11.55°, 4.83°, 5.42°,
    /// 5.81°, 17.3°); EV within 1 point of off (all far below Instant
    /// Meshes'). The sagitta's exponent ¼ replaced by ⅜ (a cubic
    /// spline's error κ³h⁴ per direction), ratio 3: spot 0.86, cow 0.95,
    /// bunny 0.96, rocker-arm 0.88 (2,675 vertices), teapot 0.70.
    pub curvature_anisotropy: f64,
    /// With [`Params::curvature_anisotropy`]: the faces whose ratio
    /// reaches the cap get a soft cross-field constraint to the direction
    /// of largest |κ| (weight [`Params::region_cross_weight`], 1 when that
    /// is a hard constraint), so the cross follows the anisotropy it is
    /// asked (the smoothest field need not: at 45° to it the map's quads
    /// stay square). Default false: it realises more of the anisotropy
    /// (`measures.anisotropy_realised` at ratio 2, one map: rocker-arm
    /// 0.40 → 0.73, spot 0.18 → 0.35, its cones 44 → 70) but costs
    /// corners and, on the organic meshes, the limit. With ratio 2,
    /// medians as at [`Params::curvature_anisotropy`], without → with:
    /// limit / Instant Meshes' spot 0.86 → 1.00, cow 0.91 → 0.96, bunny
    /// 0.96 → 0.99, rocker-arm 0.92 → 0.90, teapot 0.84 → 0.86; corner
    /// deviation spot 5.46° → 8.91°, cow 7.54° → 9.43°, bunny 3.31° →
    /// 5.74°; EV spot 5.8 → 9.6 %, cow 6.5 → 9.3 %.
    pub curvature_anisotropy_cross: bool,
}

impl Default for Params {
    fn default() -> Self {
        Params {
            analysis: AnalysisParams::default(),
            sizing: SizingParams::default(),
            filtered_normals: true,
            sigma_factor: 0.5,
            truncation: 2.0,
            alignment: Alignment::None,
            feature_curve_degrees: 0.0,
            feature_curve_spacing: 0.75,
            feature_curve_scale: true,
            stiffening: 4,
            conformal_scale: 2.0,
            feature_cone_snap: 0.0,
            smooth_regions: SmoothRegionParams::default(),
            region_weight: 5.0,
            region_cross_weight: Some(1.0),
            cyclic_constraints: true,
            round: true,
            batch_fraction: 0.5,
            loop_separation: 4.0,
            close_small_holes: true,
            thin_part_across: 0.0,
            thin_part_loops: 0.0,
            curvature_anisotropy: 0.0,
            curvature_anisotropy_cross: false,
        }
    }
}

impl From<crate::pipeline::AlignmentMode> for Alignment {
    fn from(mode: crate::pipeline::AlignmentMode) -> Alignment {
        use crate::pipeline::AlignmentMode as M;
        match mode {
            M::None => Alignment::None,
            M::FeatureVertices => Alignment::FeatureVertices,
            M::SmoothRegions => Alignment::SmoothRegions,
            M::Both => Alignment::Both,
        }
    }
}

impl Params {
    /// The map's parameters for the local pipeline's (the page's): its
    /// analysis, sizing (so one unit is one target edge of its target),
    /// alignment mode, smooth-region threshold and Campen §4.2's
    /// parametrization weight (the position field's `position_weight`,
    /// the same {0, w} field). The cross-field weights (`feature_weight`,
    /// `region_weight`) have no counterpart: the map's cross field is
    /// hard-constrained (∞) where aligned. Everything else is the default.
    pub fn from_pipeline(p: &crate::pipeline::Params) -> Params {
        Params {
            analysis: p.analysis,
            sizing: p.sizing.clone(),
            alignment: p.alignment.mode.into(),
            smooth_regions: p.alignment.smooth_regions,
            region_weight: f64::from(p.alignment.position_weight),
            feature_curve_degrees: p.remesh.feature_curve_degrees,
            stiffening: p.remesh.stiffening,
            conformal_scale: p.remesh.conformal_scale,
            loop_separation: p.remesh.loop_separation,
            close_small_holes: p.remesh.close_small_holes,
            thin_part_across: p.remesh.thin_part_across,
            thin_part_loops: p.remesh.thin_part_loops,
            curvature_anisotropy: p.remesh.curvature_anisotropy,
            curvature_anisotropy_cross: p.remesh.curvature_anisotropy_cross,
            ..Params::default()
        }
    }
}

/// Errors of the map computation.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ParamError {
    #[error("the mesh has no faces")]
    Empty,
    #[error("the {0} solve failed (singular or non-finite system)")]
    Solve(&'static str),
    #[error(
        "the integer rounding's system is too large ({0} integer variables; the cross field has {1} cones): too many singularities for a seamless map; a smoother sizing field or a lower target vertex count has fewer"
    )]
    TooManyIntegers(usize, usize),
    #[error("cancelled")]
    Cancelled,
}

impl From<crate::progress::Cancelled> for ParamError {
    fn from(_: crate::progress::Cancelled) -> Self {
        ParamError::Cancelled
    }
}

/// The surface quantities the map is built from.
pub struct Prepared {
    pub analysis: SurfaceAnalysis,
    /// Target edge length per face (calibrated), S(f).
    pub face_sizing: Vec<f64>,
    /// Unit filtered normal per face.
    pub normals: Vec<DVec3>,
    pub topology: EdgeTopology,
    pub fans: Vec<Option<Fan>>,
    pub regions: Option<SmoothRegions>,
    /// Per face edge: on a feature curve (see [`Params::feature_curve_degrees`]).
    pub feature_edges: Vec<[bool; 3]>,
    /// ln S per vertex at the target scale
    /// ([`conformal::log_size_at_target_scale`]); None when the sizing is
    /// one length (the default), and S(f) above is then its exponential.
    pub log_size: Option<Vec<f64>>,
    /// Per face edge: the boundary's tangent at the target scale
    /// ([`boundary::boundary_tangents`]), which the boundary faces are
    /// aligned with and which picks a boundary edge's isoline; `None` off
    /// the boundary.
    pub boundary_tangents: Vec<[Option<DVec3>; 3]>,
    /// Per face: the map's target lengths per direction ([`anisotropy`]:
    /// the thin parts', [`Params::thin_part_across`], and the curvature's,
    /// [`Params::curvature_anisotropy`]); all `None` when both are off.
    pub anisotropy: anisotropy::Anisotropy,
}

/// Analysis, calibrated sizing, filtered normals (σ = factor · S(f) of the
/// calibrated field), topology.
pub fn prepare(mesh: &TriMesh, params: &Params) -> Prepared {
    prepare_timed(mesh, params, &|| 0.0).0
}

/// [`prepare`] and the milliseconds (by `clock`) of the filtered normals.
fn prepare_timed(mesh: &TriMesh, params: &Params, clock: &dyn Fn() -> f64) -> (Prepared, f64) {
    let mut ap = params.analysis;
    ap.filtered_normals.mode = FilteredNormalsMode::Off;
    let mut analysis = analysis::analyze(mesh, &ap, &params.sizing);
    let target = crate::pipeline::target_vertex_count(mesh.vertex_count(), &params.sizing);
    crate::pipeline::calibrate_to_vertex_count(&mut analysis, target);
    let log_size = conformal::log_size_at_target_scale(mesh, &analysis.sizing.edge_length);
    let face_sizing = match &log_size {
        // S(f) from the smoothed ln S, with the calibrated Σ A/S².
        Some(ln) => {
            let raw = face_sigma_from_sizing(mesh, &analysis.sizing.edge_length, 1.0);
            let mut s: Vec<f64> = mesh
                .triangles
                .iter()
                .map(|t| (t.iter().map(|&v| ln[v as usize]).sum::<f64>() / 3.0).exp())
                .collect();
            let density = |s: &[f64]| {
                (0..s.len())
                    .map(|f| mesh.face_area(f) / (s[f] * s[f]))
                    .sum::<f64>()
            };
            let c = (density(&s) / density(&raw)).sqrt();
            if c.is_finite() && c > 0.0 {
                s.iter_mut().for_each(|x| *x *= c);
                s
            } else {
                raw
            }
        }
        None => face_sigma_from_sizing(mesh, &analysis.sizing.edge_length, 1.0),
    };
    // The boundary's tangents at the scale of the field itself (a strip's
    // cap below is about the distance between loops, not their shape).
    let boundary_sizing = face_sizing.clone();
    let face_sizing = cap_loop_gaps(mesh, &analysis, face_sizing, params.loop_separation);
    let filtering = clock();
    let normals = if params.filtered_normals {
        let sigma: Vec<f64> = face_sizing
            .iter()
            .map(|s| params.sigma_factor * s)
            .collect();
        let filtered = filtered_normals(
            mesh,
            &analysis.face_adjacency,
            &analysis.face_normals,
            Sigma::PerFace(&sigma),
            params.truncation,
        );
        if filtered.len() == mesh.face_count() {
            filtered
        } else {
            analysis.face_normals.clone()
        }
    } else {
        analysis.face_normals.clone()
    };
    let normals = normals
        .iter()
        .map(|n| n.try_normalize().unwrap_or(DVec3::Z))
        .collect();
    let filtered_ms = clock() - filtering;
    let topology = EdgeTopology::new(mesh);
    let boundary_tangents = boundary::boundary_tangents(mesh, &topology, &boundary_sizing);
    let fans = vertex_fans(mesh, &topology);
    let regions = matches!(params.alignment, Alignment::SmoothRegions | Alignment::Both)
        .then(|| smooth_regions(mesh, &analysis.curvature, &params.smooth_regions));
    let feature_edges = feature_curves(
        mesh,
        &topology,
        &fans,
        &analysis.face_normals,
        &face_sizing,
        params,
    );
    let across = thin_parts::across_thin_parts(mesh, &analysis, params.thin_part_across);
    let curvature = anisotropy::curvature_lengths(
        mesh,
        &analysis,
        &face_sizing,
        &feature_edges,
        params.curvature_anisotropy,
    );
    let prepared = Prepared {
        anisotropy: anisotropy::combine(across, &curvature, &analysis.face_normals),
        analysis,
        face_sizing,
        normals,
        topology,
        fans,
        regions,
        feature_edges,
        log_size,
        boundary_tangents,
    };
    (prepared, filtered_ms)
}

/// S(f) capped where two boundary loops are close
/// ([`Params::loop_separation`]): the mean of the face's corners' caps.
/// Not when the cap would add more vertices than the count tolerance
/// ([`crate::pipeline::COUNT_TOLERANCE`] of the field's count, Σ A/S² over
/// the vertex cells): then most of the surface lies between loops closer
/// than a few target edges, it is below the target scale as a whole, and
/// the count correction would take the vertices from everywhere else (the
/// beetle at its default target: 962 of its 1,148 vertices capped, 170
/// more quad vertices asked for on a budget of 71; the bunny: 574 capped,
/// 62 more on 2,177).
fn cap_loop_gaps(
    mesh: &TriMesh,
    analysis: &SurfaceAnalysis,
    mut face_sizing: Vec<f64>,
    separation: f64,
) -> Vec<f64> {
    let s = &analysis.sizing.edge_length;
    let Some(cap) = analysis::thickness::loop_gap_cap(
        mesh,
        &analysis.adjacency,
        s,
        separation,
        analysis::thickness::FLOOR,
        SizingParams::default().thin_part_gradation,
    ) else {
        return face_sizing;
    };
    let density = |v: usize, x: f64| analysis.cell_areas.get(v).map_or(0.0, |a| a / (x * x));
    let count: f64 = (0..s.len()).map(|v| density(v, s[v])).sum();
    let extra: f64 = (0..s.len())
        .filter(|&v| cap[v] < s[v])
        .map(|v| density(v, cap[v]) - density(v, s[v]))
        .sum();
    let within = extra <= crate::pipeline::COUNT_TOLERANCE * count;
    if !within {
        return face_sizing;
    }
    for (x, t) in face_sizing.iter_mut().zip(&mesh.triangles) {
        let c = t.iter().map(|&v| cap[v as usize]).sum::<f64>() / 3.0;
        if c.is_finite() && c > 0.0 {
            *x = x.min(c);
        }
    }
    face_sizing
}

/// The feature-curve edges: interior edges whose faces' normals differ by
/// more than `feature_curve_degrees`, grouped into curves by shared
/// vertices; curves shorter than the mean target edge along them are
/// dropped (an isolated sharp edge of a scan is noise, and snapping it to
/// an isoline would only distort the map).
fn feature_curves(
    mesh: &TriMesh,
    topology: &EdgeTopology,
    fans: &[Option<Fan>],
    face_normals: &[DVec3],
    face_sizing: &[f64],
    params: &Params,
) -> Vec<[bool; 3]> {
    let nf = mesh.face_count();
    let mut sharp = vec![[false; 3]; nf];
    if params.feature_curve_degrees <= 0.0 {
        return sharp;
    }
    let mut curves = crate::mesh::UnionFind::new(mesh.vertex_count());
    let mut edges = Vec::new();
    let sharp_edges =
        EdgeTopology::sharp_edges(mesh, face_normals, params.feature_curve_degrees, false);
    for s in sharp_edges {
        let [(f, e), (g, ge)] = s.sides.map(|(f, e)| (f as usize, e as usize));
        // Only edges the map's charts cross (consistently oriented pairs).
        if topology.across(f, e) != Some((g, ge)) {
            continue;
        }
        edges.push((f, e, g, ge, s.a, s.b));
    }
    if params.feature_curve_scale {
        keep_sharp_at_target_scale(
            mesh,
            topology,
            face_normals,
            face_sizing,
            params,
            &mut edges,
        );
    }
    drop_sliver_sectors(mesh, fans, &mut edges);
    drop_close_curves(mesh, face_sizing, params.feature_curve_spacing, &mut edges);
    for &(_, _, _, _, a, b) in &edges {
        curves.union(a, b);
    }
    let mut length = vec![0.0; mesh.vertex_count()];
    let mut sizing = vec![(0.0, 0.0); mesh.vertex_count()];
    for &(f, _, g, _, a, b) in &edges {
        let r = curves.find(a) as usize;
        length[r] += mesh.positions[a as usize].distance(mesh.positions[b as usize]);
        sizing[r].0 += 0.5 * (face_sizing[f] + face_sizing[g]);
        sizing[r].1 += 1.0;
    }
    for &(f, e, g, ge, a, _) in &edges {
        let r = curves.find(a) as usize;
        if length[r] >= sizing[r].0 / sizing[r].1 {
            sharp[f][e] = true;
            sharp[g][ge] = true;
        }
    }
    sharp
}

/// A feature edge as (face, local edge, face across, its local edge, end
/// vertices).
type FeatureEdge = (usize, usize, usize, usize, u32, u32);

/// Two feature curves less than half a target edge apart cannot both lie
/// on integer isolines of a map with unit target edges unless the strip
/// between them collapses onto one isoline (both round to the same
/// integer; the strip's triangles become degenerate or fold). Ebke §3
/// merges features closer than the target edge in the normal field; here,
/// of two curve segments (chains of feature edges between vertices with
/// other than two feature edges) that come closer than S/2 away from any
/// feature path of length S joining them (so not merely at a shared
/// corner), the shorter one stops being a feature curve, until no such
/// pair is left.
fn drop_close_curves(
    mesh: &TriMesh,
    face_sizing: &[f64],
    spacing: f64,
    edges: &mut Vec<FeatureEdge>,
) {
    if spacing <= 0.0 {
        return;
    }
    let nv = mesh.vertex_count();
    let position = |v: u32| mesh.positions[v as usize];
    let length = |k: &FeatureEdge| position(k.4).distance(position(k.5));
    let sizing = |k: &FeatureEdge| 0.5 * (face_sizing[k.0] + face_sizing[k.2]);
    let mut at_vertex: Vec<Vec<usize>> = vec![Vec::new(); nv];
    for (k, e) in edges.iter().enumerate() {
        at_vertex[e.4 as usize].push(k);
        at_vertex[e.5 as usize].push(k);
    }
    // Segments: chains through vertices with exactly two feature edges.
    let mut segment = vec![usize::MAX; edges.len()];
    let mut segment_length = Vec::new();
    for start in 0..edges.len() {
        if segment[start] != usize::MAX {
            continue;
        }
        let id = segment_length.len();
        let mut total = 0.0;
        let mut stack = vec![start];
        segment[start] = id;
        while let Some(k) = stack.pop() {
            total += length(&edges[k]);
            for v in [edges[k].4, edges[k].5] {
                let here = &at_vertex[v as usize];
                if here.len() != 2 {
                    continue;
                }
                for &j in here {
                    if segment[j] == usize::MAX {
                        segment[j] = id;
                        stack.push(j);
                    }
                }
            }
        }
        segment_length.push(total);
    }
    // Close pairs of segments: an edge's midpoint nearer than S/2 to an
    // edge of another segment that no feature path of length S from it
    // reaches.
    let midpoint = |k: &FeatureEdge| 0.5 * (position(k.4) + position(k.5));
    let distance_to = |p: DVec3, k: &FeatureEdge| {
        let (a, b) = (position(k.4), position(k.5));
        let d = b - a;
        let t = ((p - a).dot(d) / d.length_squared().max(1e-300)).clamp(0.0, 1.0);
        p.distance(a + d * t)
    };
    // Grid cells of the mean search radius (edges search as many cells as
    // their own radius needs).
    let cell = (edges.iter().map(sizing).sum::<f64>() / edges.len().max(1) as f64).max(1e-12)
        * spacing.max(0.1);
    let key = |p: DVec3| (p / cell).floor().as_i64vec3().to_array();
    let mut grid: std::collections::HashMap<[i64; 3], Vec<usize>> =
        std::collections::HashMap::new();
    for (k, e) in edges.iter().enumerate() {
        grid.entry(key(midpoint(e))).or_default().push(k);
    }
    let mut pairs: Vec<(usize, usize)> = Vec::new();
    for (k, e) in edges.iter().enumerate() {
        let (m, s) = (midpoint(e), sizing(e));
        let reach = (spacing * s + length(e)) / cell;
        let r = reach.ceil() as i64;
        let c = key(m);
        let mut near = Vec::new();
        for dx in -r..=r {
            for dy in -r..=r {
                for dz in -r..=r {
                    if let Some(list) = grid.get(&[c[0] + dx, c[1] + dy, c[2] + dz]) {
                        near.extend(list.iter().copied().filter(|&j| {
                            segment[j] != segment[k] && distance_to(m, &edges[j]) < spacing * s
                        }));
                    }
                }
            }
        }
        if near.is_empty() {
            continue;
        }
        // Feature paths of length S from the edge's ends (Dijkstra).
        let mut reached = std::collections::HashSet::new();
        let mut best: std::collections::HashMap<u32, f64> = std::collections::HashMap::new();
        let mut queue = vec![(e.4, 0.0), (e.5, 0.0)];
        while let Some((v, d)) = queue.pop() {
            if best.get(&v).is_some_and(|&b| b <= d) {
                continue;
            }
            best.insert(v, d);
            for &j in &at_vertex[v as usize] {
                reached.insert(j);
                let o = if edges[j].4 == v {
                    edges[j].5
                } else {
                    edges[j].4
                };
                let nd = d + length(&edges[j]);
                if nd < s {
                    queue.push((o, nd));
                }
            }
        }
        for j in near {
            if !reached.contains(&j) {
                let (a, b) = (segment[k].min(segment[j]), segment[k].max(segment[j]));
                pairs.push((a, b));
            }
        }
    }
    pairs.sort_unstable();
    pairs.dedup();
    let mut dropped = vec![false; segment_length.len()];
    for (a, b) in pairs {
        if dropped[a] || dropped[b] {
            continue;
        }
        let shorter = if segment_length[a] <= segment_length[b] {
            a
        } else {
            b
        };
        dropped[shorter] = true;
    }
    let mut k = 0;
    edges.retain(|_| {
        let keep = !dropped[segment[k]];
        k += 1;
        keep
    });
}

/// Sides turned further apart than this are the two faces of a thin
/// part and the edge is its rim: the wedge between them is under 45°,
/// which no quad corner follows (the bound of `drop_sliver_sectors`).
const RIM: f64 = 0.75 * std::f64::consts::PI;

/// Keeps the feature edges that are creases at the target scale. From
/// each of the edge's two faces, the faces reached without crossing a
/// feature edge whose centroids lie within half a target edge of the
/// edge's midpoint are its side. The edge stays if the sides are apart
/// (neither reaches the other's face), their area-weighted normals are
/// still `feature_curve_degrees` apart, and each side is smoother than
/// the crease: its faces' normals stay within half that angle of the
/// side's. A scan's noise crease ends within a target edge (its sides
/// meet round its end); a coarse tessellation of a smooth shape (the
/// cow, suzanne) has facets at that angle on either side too; a machined
/// crease (fandisk) has neither. Ebke §3 filters the normals at the
/// target scale for the same reason. Rims of thin parts (sides more than
/// [`RIM`] apart) are no feature either.
fn keep_sharp_at_target_scale(
    mesh: &TriMesh,
    topology: &EdgeTopology,
    face_normals: &[DVec3],
    face_sizing: &[f64],
    params: &Params,
    edges: &mut Vec<FeatureEdge>,
) {
    let nf = mesh.face_count();
    let mut feature = vec![[false; 3]; nf];
    for &(f, e, g, ge, _, _) in edges.iter() {
        feature[f][e] = true;
        feature[g][ge] = true;
    }
    let centroid = |f: usize| {
        let [a, b, c] = mesh.corners(f);
        (a + b + c) / 3.0
    };
    let crease = params.feature_curve_degrees.to_radians();
    let mut mark = vec![u32::MAX; nf];
    let mut faces = Vec::new();
    // The side from `start` (None when it reaches `other`), as its unit
    // normal and the largest angle of its faces' normals from it.
    let mut side = |start: usize, other: usize, mid: DVec3, r: f64, id: u32| {
        faces.clear();
        faces.push(start);
        mark[start] = id;
        let mut next = 0;
        while next < faces.len() {
            let f = faces[next];
            next += 1;
            if f == other {
                return None;
            }
            for e in 0..3 {
                let Some((g, _)) = topology.across(f, e) else {
                    continue;
                };
                if feature[f][e] || mark[g] == id || centroid(g).distance(mid) > r {
                    continue;
                }
                mark[g] = id;
                faces.push(g);
            }
        }
        let n = faces
            .iter()
            .map(|&f| face_normals[f] * mesh.face_area(f))
            .sum::<DVec3>()
            .try_normalize()?;
        let spread = faces
            .iter()
            .map(|&f| face_normals[f].angle_between(n))
            .fold(0.0, f64::max);
        Some((n, spread))
    };
    let mut id = 0u32;
    edges.retain(|&(f, _, g, _, a, b)| {
        let mid = 0.5 * (mesh.positions[a as usize] + mesh.positions[b as usize]);
        let r = 0.25 * (face_sizing[f] + face_sizing[g]);
        id += 2;
        let (Some((n, s)), Some((m, t))) = (side(f, g, mid, r, id), side(g, f, mid, r, id + 1))
        else {
            return false;
        };
        let angle = n.angle_between(m);
        angle >= crease && angle <= RIM && s.max(t) < 0.5 * angle
    });
}

/// Feature edges less than 45° apart around a vertex bound a sector that
/// rounds to no quarter turn; the integer grid can only give it one (90°:
/// a 19° dart on fandisk became a −¼ cone with a +¼ cone a quarter edge
/// away, and the strip between them and along the curve folded). Of the
/// two edges of such a sector, the one whose other end has fewer feature
/// edges (the end of a curve), then the shorter, stops being a feature
/// edge, until no sector is that narrow.
fn drop_sliver_sectors(mesh: &TriMesh, fans: &[Option<Fan>], edges: &mut Vec<FeatureEdge>) {
    loop {
        let mut degree = vec![0u32; mesh.vertex_count()];
        let mut at: std::collections::HashMap<(usize, usize), usize> =
            std::collections::HashMap::new();
        for (k, &(f, e, g, ge, a, b)) in edges.iter().enumerate() {
            degree[a as usize] += 1;
            degree[b as usize] += 1;
            at.insert((f, e), k);
            at.insert((g, ge), k);
        }
        let mut drop = None;
        'vertices: for (v, fan) in fans.iter().enumerate() {
            let Some(fan) = fan.as_ref().filter(|f| f.closed && degree[v] >= 2) else {
                continue;
            };
            // Corner angles between consecutive feature edges, starting
            // after one (crossing j leaves corner j over its edge i + 2).
            let corners = &fan.corners;
            let m = corners.len();
            let Some(start) = (0..m).find(|&j| {
                let (f, i) = corners[j];
                at.contains_key(&(f as usize, (i as usize + 2) % 3))
            }) else {
                continue;
            };
            let mut angle = 0.0;
            let mut first = at[&(
                corners[start].0 as usize,
                (corners[start].1 as usize + 2) % 3,
            )];
            for k in 1..=m {
                let (f, i) = corners[(start + k) % m];
                let (f, i) = (f as usize, i as usize);
                let p = |c: usize| mesh.positions[mesh.triangles[f][c] as usize];
                angle += (p((i + 1) % 3) - p(i)).angle_between(p((i + 2) % 3) - p(i));
                if let Some(&second) = at.get(&(f, (i + 2) % 3)) {
                    if angle < std::f64::consts::FRAC_PI_4 && first != second {
                        let other = |k: usize| {
                            let (_, _, _, _, a, b) = edges[k];
                            let o = if a as usize == v { b } else { a };
                            let len =
                                mesh.positions[a as usize].distance(mesh.positions[b as usize]);
                            (degree[o as usize], len)
                        };
                        let (d1, d2) = (other(first), other(second));
                        drop = Some(if d1.0 < d2.0 || (d1.0 == d2.0 && d1.1 <= d2.1) {
                            first
                        } else {
                            second
                        });
                        break 'vertices;
                    }
                    angle = 0.0;
                    first = second;
                }
            }
        }
        match drop {
            Some(k) => {
                edges.swap_remove(k);
            }
            None => return,
        }
    }
}

/// Per face: the direction its cross must contain — the boundary edge on
/// boundary faces and on feature curves (the first such edge), else
/// feature-vertex / smooth-region
/// directions by `params.alignment` — and the directions it should
/// contain (the smooth regions' with [`Params::region_cross_weight`]).
pub fn alignment_constraints(
    mesh: &TriMesh,
    p: &Prepared,
    params: &Params,
) -> (Vec<Option<DVec3>>, Vec<Option<DVec3>>) {
    let nf = mesh.face_count();
    let mut out: Vec<Option<DVec3>> = vec![None; nf];
    let mut soft: Vec<Option<DVec3>> = Vec::new();
    if let Some(r) = &p.regions {
        let selected = r.selected_faces();
        let target = if params.region_cross_weight.is_some() {
            soft = vec![None; nf];
            &mut soft
        } else {
            &mut out
        };
        for (f, s) in selected.iter().enumerate() {
            if *s {
                target[f] = Some(r.faces[f].a_min);
            }
        }
    }
    if matches!(
        params.alignment,
        Alignment::FeatureVertices | Alignment::Both
    ) {
        let directions =
            analysis::orientation_constraints(&p.analysis.features, &p.analysis.curvature);
        let mut at_vertex: Vec<Option<DVec3>> = vec![None; mesh.vertex_count()];
        for (v, d) in directions {
            at_vertex[v as usize] = Some(d);
        }
        for (f, t) in mesh.triangles.iter().enumerate() {
            if let Some(d) = t.iter().find_map(|&v| at_vertex[v as usize]) {
                out[f] = Some(d);
            }
        }
    }
    let cap = params.curvature_anisotropy;
    if params.curvature_anisotropy_cross && cap > 1.0 {
        if soft.is_empty() {
            soft = vec![None; nf];
        }
        for (f, l) in p.anisotropy.iter().enumerate() {
            if let Some(l) = l
                && soft[f].is_none()
                && l.along / l.across >= cap * (1.0 - 1e-9)
            {
                soft[f] = Some(l.a);
            }
        }
    }
    for (f, t) in mesh.triangles.iter().enumerate() {
        let edge = (0..3).find(|&e| p.topology.opposite[f][e] == NO_FACE || p.feature_edges[f][e]);
        if let Some(e) = edge {
            out[f] = Some(p.boundary_tangents[f][e].unwrap_or_else(|| {
                mesh.positions[t[(e + 1) % 3] as usize] - mesh.positions[t[e] as usize]
            }));
        }
    }
    (out, soft)
}

/// The cross field of [`prepare`]d data.
pub fn cross_field_of(
    mesh: &TriMesh,
    p: &Prepared,
    params: &Params,
) -> Result<CrossField, ParamError> {
    if mesh.face_count() == 0 {
        return Err(ParamError::Empty);
    }
    let (constraints, soft) = alignment_constraints(mesh, p, params);
    cross_field::cross_field(&CrossFieldInput {
        mesh,
        topology: &p.topology,
        fans: &p.fans,
        normals: &p.normals,
        constraints: &constraints,
        soft_constraints: &soft,
        soft_weight: params.region_cross_weight.unwrap_or(1.0),
        feature_edges: &p.feature_edges,
        face_sizing: &p.face_sizing,
        snap_distance: if params.feature_curve_degrees > 0.0 {
            params.feature_cone_snap
        } else {
            0.0
        },
        log_size: p.log_size.as_deref().unwrap_or(&[]),
    })
    .ok_or(ParamError::Solve("cross field"))
}

/// The faces of every zero-turning boundary loop of a filtered smooth
/// region (Campen §4.3), when [`Params::cyclic_constraints`] is on.
pub fn cyclic_loops(p: &Prepared, params: &Params) -> Vec<Vec<u32>> {
    match &p.regions {
        Some(r) if params.cyclic_constraints => r
            .zero_turning_loops
            .iter()
            .filter(|(region, _)| r.filtered[*region as usize])
            .map(|(_, faces)| faces.clone())
            .collect(),
        _ => Vec::new(),
    }
}

/// The integer-grid map of a cross field.
pub fn grid_map_of(
    mesh: &TriMesh,
    p: &Prepared,
    field: &CrossField,
    params: &Params,
) -> Result<GridMap, ParamError> {
    grid_map_with_progress(mesh, p, field, params, &|| 0.0, &mut |_| true).map(|(m, _)| m)
}

/// [`grid_map_of`] asking `go_on(fraction rounded)` before every solve,
/// with its stages' milliseconds by `clock`.
fn grid_map_with_progress(
    mesh: &TriMesh,
    p: &Prepared,
    field: &CrossField,
    params: &Params,
    clock: &dyn Fn() -> f64,
    go_on: &mut dyn FnMut(f32) -> bool,
) -> Result<(GridMap, seamless::MapTimings), ParamError> {
    let dirs: Option<Vec<Option<DVec3>>> = p.regions.as_ref().map(|r| {
        r.selected_faces()
            .iter()
            .zip(&r.faces)
            .map(|(&s, c)| s.then_some(c.a_min))
            .collect()
    });
    let loops = cyclic_loops(p, params);
    let thin_loops =
        thin_parts::thin_part_loops(mesh, &p.topology, &p.face_sizing, params.thin_part_loops);
    let conformal = (params.conformal_scale > 0.0)
        .then(|| {
            let log_size = p.log_size.as_deref().unwrap_or(&[]);
            conformal::cone_metric_factor(mesh, &p.fans, &field.cones, log_size)
        })
        .flatten()
        .map(|phi| conformal::conformal_sizing(mesh, &p.face_sizing, &phi, params.conformal_scale));
    let input = MapInput {
        mesh,
        topology: &p.topology,
        field,
        face_sizing: conformal.as_deref().unwrap_or(&p.face_sizing),
        round: params.round,
        batch_fraction: params.batch_fraction,
        region_alignment: dirs.as_deref().map(|d| (d, params.region_weight)),
        feature_edges: &p.feature_edges,
        boundary_tangents: &p.boundary_tangents,
        anisotropy: &p.anisotropy,
        cyclic_loops: &loops,
        stiffening: params.stiffening,
        thin_loops: &thin_loops,
        thin_loop_translation: params.thin_part_loops,
    };
    seamless::grid_map_timed(&input, clock, go_on).map_err(|e| match e {
        seamless::MapStop::Solve => ParamError::Solve("parametrization"),
        seamless::MapStop::TooManyIntegers(n) => ParamError::TooManyIntegers(n, field.cones.len()),
        seamless::MapStop::Cancelled => ParamError::Cancelled,
    })
}

/// Milliseconds per stage of [`run`].
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct Timings {
    /// Curvature, features, the calibrated sizing, topology, smooth
    /// regions and feature curves: [`prepare`] without the filtered normals.
    pub analysis_ms: f64,
    /// Ebke §3's filtered normals (σ = factor · S(f)).
    pub filtered_normals_ms: f64,
    /// The cross field, its period jumps and cones.
    pub cross_field_ms: f64,
    /// Combing, the cut graph through the cones, wedges (MIQ §4).
    pub cut_ms: f64,
    /// The seamless map's constraints and energy, the condensed system's
    /// sparse factorization and Campen §4.3's loop constraints.
    pub seamless_ms: f64,
    /// The greedy integer rounding with its re-solves (or the relaxation's
    /// one solve) and the continuous unknowns' back-substitution.
    pub rounding_ms: f64,
    /// `cut_ms + seamless_ms + rounding_ms`.
    pub parametrization_ms: f64,
    /// Flips and Campen §5's measures.
    pub measures_ms: f64,
}

/// Everything [`run`] computes.
pub struct Run {
    /// The input with its holes below the target scale closed
    /// ([`Params::close_small_holes`]), when it had any: the mesh the map
    /// is on (its first vertices are the input's). `None`: the input.
    pub mesh: Option<TriMesh>,
    pub prepared: Prepared,
    pub field: CrossField,
    pub map: GridMap,
    pub measures: measures::Measures,
    pub timings: Timings,
}

impl Run {
    /// The mesh the map is on: [`Run::mesh`], or `input` (the mesh the
    /// map was computed for).
    pub fn map_mesh<'a>(&'a self, input: &'a TriMesh) -> &'a TriMesh {
        self.mesh.as_ref().unwrap_or(input)
    }
}

/// The whole map: analysis, cross field, seamless map with rounding and
/// the measures. `clock` returns milliseconds (the browser has no
/// `Instant`).
pub fn run(mesh: &TriMesh, params: &Params, clock: &dyn Fn() -> f64) -> Result<Run, ParamError> {
    crate::progress::silently("parametrization", |progress| {
        run_with_progress(mesh, params, clock, progress)
    })
}

/// [`run`] reporting to `progress` (analysis to 15 %, cross field to 30 %,
/// then the rounding's share of integer quantities fixed) and stopping
/// with [`ParamError::Cancelled`] when the sink says so.
pub fn run_with_progress(
    mesh: &TriMesh,
    params: &Params,
    clock: &dyn Fn() -> f64,
    progress: &mut crate::progress::Progress<'_>,
) -> Result<Run, ParamError> {
    let t0 = clock();
    progress.report(0.0, "analysis")?;
    // The map's mesh: manifold ([`manifold`]), and without the holes
    // below the target scale ([`small_holes`]).
    let split = params
        .close_small_holes
        .then(|| manifold::split_nonmanifold_vertices(mesh))
        .flatten();
    let mesh = split.as_ref().unwrap_or(mesh);
    let (mut prepared, mut filtered_normals_ms) = prepare_timed(mesh, params, clock);
    let closed = params
        .close_small_holes
        .then(|| {
            small_holes::close_holes_too_small_to_keep(mesh, &prepared.analysis.sizing.edge_length)
        })
        .flatten();
    if let Some(c) = &closed {
        (prepared, filtered_normals_ms) = prepare_timed(c, params, clock);
    }
    let mesh = closed.as_ref().unwrap_or(mesh);
    let t1 = clock();
    progress.report(0.15, "cross field")?;
    let field = cross_field_of(mesh, &prepared, params)?;
    let t2 = clock();
    progress.report(0.3, "seamless map")?;
    let (map, stages) = grid_map_with_progress(mesh, &prepared, &field, params, clock, &mut |f| {
        progress
            .report(0.3 + 0.7 * f, "seamless map, integer rounding")
            .is_ok()
    })?;
    let t3 = clock();
    progress.report(1.0, "done")?;
    let curvature = prepared.regions.as_ref().map_or_else(
        || analysis::smooth_regions::face_curvatures(mesh, &prepared.analysis.curvature),
        |r| r.faces.clone(),
    );
    let measures = measures::measures(
        mesh,
        &map,
        &prepared.face_sizing,
        &curvature,
        &prepared.anisotropy,
    );
    let t4 = clock();
    Ok(Run {
        mesh: closed.or(split),
        prepared,
        field,
        map,
        measures,
        timings: Timings {
            analysis_ms: t1 - t0 - filtered_normals_ms,
            filtered_normals_ms,
            cross_field_ms: t2 - t1,
            cut_ms: stages.cut_ms,
            seamless_ms: stages.seamless_ms,
            rounding_ms: stages.rounding_ms,
            parametrization_ms: t3 - t2,
            measures_ms: t4 - t3,
        },
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pipeline::AlignmentMode;

    /// A flat fan around the origin with spokes at the given angles (°),
    /// and the feature edges of the spokes `marked` as [`feature_curves`]
    /// lists them.
    fn fan_with_features(spokes: &[f64], marked: &[usize]) -> (TriMesh, Vec<FeatureEdge>) {
        let mut positions = vec![DVec3::ZERO];
        positions.extend(spokes.iter().map(|a| {
            let a = a.to_radians();
            DVec3::new(a.cos(), a.sin(), 0.0)
        }));
        let n = spokes.len() as u32;
        let triangles = (0..n).map(|k| [0, 1 + k, 1 + (k + 1) % n]).collect();
        let mesh = TriMesh {
            positions,
            triangles,
        };
        let topology = EdgeTopology::new(&mesh);
        let mut edges = Vec::new();
        for &k in marked {
            // Spoke k is local edge 2 (vertex 2 → 0) of face k − 1 and
            // local edge 0 (0 → 1) of face k.
            let f = k;
            let (g, ge) = topology.across(f, 0).expect("an interior spoke");
            edges.push((f, 0, g, ge, 0, 1 + k as u32));
        }
        (mesh, edges)
    }

    /// Two feature edges 20° apart at a vertex bound a sector no quarter
    /// turn fits: one of them goes (the one ending in the curve's end,
    /// here the shorter spoke, as both ends are curve ends); 90° apart
    /// both stay, and so do three at 120°.
    #[test]
    fn sliver_sectors_between_feature_edges_are_dropped() {
        let spokes = [0.0, 20.0, 90.0, 135.0, 180.0, 225.0, 270.0, 315.0];
        let (mut mesh, mut edges) = fan_with_features(&spokes, &[0, 1]);
        mesh.positions[2] *= 0.5;
        let fans = vertex_fans(&mesh, &EdgeTopology::new(&mesh));
        drop_sliver_sectors(&mesh, &fans, &mut edges);
        assert_eq!(edges.len(), 1);
        assert_eq!(edges[0].5, 1, "the shorter spoke (to vertex 2) is dropped");
        let (mesh, mut edges) = fan_with_features(&spokes, &[0, 2]);
        let fans = vertex_fans(&mesh, &EdgeTopology::new(&mesh));
        drop_sliver_sectors(&mesh, &fans, &mut edges);
        assert_eq!(edges.len(), 2);
        let spokes = [0.0, 60.0, 120.0, 180.0, 240.0, 300.0];
        let (mesh, mut edges) = fan_with_features(&spokes, &[0, 2, 4]);
        let fans = vertex_fans(&mesh, &EdgeTopology::new(&mesh));
        drop_sliver_sectors(&mesh, &fans, &mut edges);
        assert_eq!(edges.len(), 3);
    }

    /// The page's alignment mode, smooth-region threshold and §4.2 weight
    /// reach the map; parameters the map does not read (the local path's
    /// field and extraction, the cross-field weights) leave it the same,
    /// so the page keeps the map across them.
    #[test]
    fn pipeline_parameters_map_to_the_maps_own() {
        let mut page = crate::pipeline::Params::default();
        assert_eq!(
            Params::from_pipeline(&page).alignment,
            Alignment::None,
            "the page's default mode"
        );
        page.alignment.mode = AlignmentMode::SmoothRegions;
        page.alignment.smooth_regions.significance_threshold = 50.0;
        page.alignment.position_weight = 3.0;
        page.sizing.target_vertex_count = Some(1234);
        let map = Params::from_pipeline(&page);
        assert_eq!(map.alignment, Alignment::SmoothRegions);
        assert_eq!(map.smooth_regions.significance_threshold, 50.0);
        assert_eq!(map.region_weight, 3.0);
        assert_eq!(map.sizing.target_vertex_count, Some(1234));
        for (mode, want) in [
            (AlignmentMode::None, Alignment::None),
            (AlignmentMode::Both, Alignment::Both),
        ] {
            assert_eq!(Alignment::from(mode), want);
        }

        let mut other = page.clone();
        other.field.orientation_iterations += 7;
        other.alignment.feature_weight = 2.0;
        other.alignment.region_weight = 0.25;
        other.extraction = Default::default();
        other.fit = Default::default();
        assert_eq!(Params::from_pipeline(&other), map, "unchanged map");
        let mut target = page.clone();
        target.sizing.target_vertex_count = Some(999);
        let mut mode = page.clone();
        mode.alignment.mode = AlignmentMode::Both;
        let mut analysis = page.clone();
        analysis.analysis.features.anisotropy_threshold += 0.1;
        for changed in [target, mode, analysis] {
            assert_ne!(Params::from_pipeline(&changed), map);
        }
    }

    /// With the page in smooth-regions mode, the map gets Campen §4.2's
    /// regions and §4.3's closed loops (a capsule's cylinder is a cyclic
    /// region); in the page's default mode it has no regions.
    #[test]
    fn page_smooth_region_mode_gives_the_map_its_regions_and_closed_loops() {
        let mesh = crate::mesh::generate::capsule(1.0, 4.0, 64, 12, 32);
        let mut page = crate::pipeline::Params::default();
        page.sizing.method = crate::sizing::EdgeLengthMethod::Uniform;
        page.sizing.target_vertex_count = Some(400);
        let clock = || 0.0;
        let plain = run(&mesh, &Params::from_pipeline(&page), &clock).expect("a map");
        assert!(plain.prepared.regions.is_none());
        assert_eq!(plain.map.closed_loops, 0);
        page.alignment.mode = AlignmentMode::SmoothRegions;
        let smooth = run(&mesh, &Params::from_pipeline(&page), &clock).expect("a map");
        assert!(smooth.prepared.regions.is_some());
        assert!(
            smooth.map.closed_loops > 0,
            "the cylinder's loops get closing constraints"
        );
        assert_eq!(smooth.map.conflicts, 0);
    }
}
