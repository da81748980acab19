//! The seamless integer-grid map: Bommes et al. 2009 (MIQ) §4 with Ebke et
//! al. 2014 §5's energy (`../shared/seeds/000_…`).
//!
//! Unknowns: (u, v) per wedge of the [`super::cut`] and a translation t per
//! cut edge. Hard constraints, eliminated exactly ([`super::constraints`]):
//! across every cut edge both end points map by X_g = R^k·X_f + t (k the
//! combed matching); boundary edges lie on isolines (the coordinate whose
//! cross axis is more transversal is constant along them); one wedge per
//! component is fixed at the origin (at a cone if it has one). Energy:
//! E_orient = Σ_f A(f̂) ‖∇g·[w̄0 w̄1] − Id/S(f)‖² with w̄_k the crosses
//! projected from the filtered plane onto the face along n̂ (non-orthonormal
//! where n ≠ n̂) and A(f̂) the face's area projected into the filtered plane.
//! Integer rounding (MIQ's greedy scheme, batched): cone coordinates first,
//! then translations and boundary isolines, each group in order of the
//! distance to an integer, a fraction of the group's open quantities per
//! re-solve (the cones one at a time when a loop is constrained).
//!
//! With filtered smooth regions, Campen et al. 2016 §4.2's term
//! w·A_f·(∇g_c · ŵ)² (w = 5 inside the regions) is added for the
//! coordinate c whose cross axis is transversal to a_min, ŵ the unit
//! (projected) cross axis nearest a_min: Campen's equivalent anisotropic
//! norm ‖∇u − u‖²_{1,w+1} in the cross frame. Campen writes a_min, which
//! is ŵ under his hard cross-field constraint (§4.1); our region
//! constraint is soft ([`super::Params::region_cross_weight`]), and where
//! the field leaves a_min (next to the regions' boundaries) a_min would
//! pull ∇g_c against E_orient's own target. Campen §4.3's
//! topology constraints: around every zero-turning boundary loop of a
//! cyclic region one component of the loop's holonomy translation is 0
//! (isolines close there; no helix), the one whose closing raises the
//! energy least.
//!
//! Thin parts (not from the seeds; Campen §4.3's kind of constraint on
//! another loop): round a loop of [`MapInput::thin_loops`] (a part
//! between one and a few target edges round,
//! [`super::thin_parts::thin_part_loops`]) the chord of the loop's image
//! is the one E_orient asks for, scaled to [`MapInput::thin_loop_translation`]
//! units ([`widen_loops`]): without it the map folds such a part flat
//! (its cones round together) and QEx drops it.
//!
//! Deviations: the target is Id/S(f) (one parameter unit = one target
//! edge; Ebke writes S(f)·Id, a density convention); the re-solves are
//! not MIQ's local Gauss–Seidel updates but exact: the continuous unknowns
//! are condensed out once (a Schur complement onto the unknowns the
//! integer quantities use, [`Condensed`]), so each re-solve is a small
//! dense solve; no stiffening (fold-overs are left to the extraction, as
//! Ebke §6 does).

// Parallel per-face arrays read best indexed.
#![allow(clippy::needless_range_loop)]

use glam::{DVec2, DVec3};

use super::constraints::{Added, Eliminator, Expr};
use super::cross_field::{Cone, CrossField, face_components};
use super::cut::{Cut, CutInput, cut};
use faer::Mat;
use nalgebra::{DMatrix, DVector};

use super::solve::{ForwardSubstitution, NormalEquations, SpdFactor, SpdPattern};
use super::topology::EdgeTopology;
use crate::mesh::TriMesh;

/// Rotation of parameter vectors by −k·π/2.
pub fn rotate(k: u8, x: DVec2) -> DVec2 {
    match k % 4 {
        0 => x,
        1 => DVec2::new(x.y, -x.x),
        2 => -x,
        _ => DVec2::new(-x.y, x.x),
    }
}

/// `rotate(k, ·)` as a signed component map: out[c] = sign[c] · in[src[c]].
fn rotation_map(k: u8) -> ([usize; 2], [f64; 2]) {
    match k % 4 {
        0 => ([0, 1], [1.0, 1.0]),
        1 => ([1, 0], [1.0, -1.0]),
        2 => ([0, 1], [-1.0, -1.0]),
        _ => ([1, 0], [-1.0, 1.0]),
    }
}

/// A chart transition X' = rotate(k, X) + t.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Transition {
    pub k: u8,
    pub t: DVec2,
}

impl Transition {
    pub const IDENTITY: Transition = Transition {
        k: 0,
        t: DVec2::ZERO,
    };

    pub fn apply(&self, x: DVec2) -> DVec2 {
        rotate(self.k, x) + self.t
    }

    /// `self` after `first`: x ↦ self(first(x)).
    pub fn after(&self, first: &Transition) -> Transition {
        Transition {
            k: (self.k + first.k) % 4,
            t: rotate(self.k, first.t) + self.t,
        }
    }

    pub fn inverse(&self) -> Transition {
        let k = (4 - self.k % 4) % 4;
        Transition {
            k,
            t: -rotate(k, self.t),
        }
    }
}

/// What the map is computed from.
pub struct MapInput<'a> {
    pub mesh: &'a TriMesh,
    pub topology: &'a EdgeTopology,
    pub field: &'a CrossField,
    /// S(f), the target edge length per face.
    pub face_sizing: &'a [f64],
    /// Round the integer variables.
    pub round: bool,
    /// Fraction of the remaining integer variables fixed per re-solve.
    pub batch_fraction: f64,
    /// Campen §4.2's {0, w} alignment: per face the unit a_min where the
    /// weight applies (filtered smooth regions; it picks the cross axis
    /// the weight strengthens), and w.
    pub region_alignment: Option<(&'a [Option<DVec3>], f64)>,
    /// Per face edge: a feature curve, which lies on an integer isoline
    /// like the boundary (empty: none).
    pub feature_edges: &'a [[bool; 3]],
    /// Per face edge: the boundary's tangent at the target scale, which
    /// picks the coordinate a boundary edge keeps (empty or `None`: the
    /// edge's own direction).
    pub boundary_tangents: &'a [[Option<DVec3>; 3]],
    /// Campen §4.3's topology constraints: closed loops of faces
    /// (consecutive ones sharing an edge, the last sharing one with the
    /// first; the boundary loops of cyclic smooth regions) around which
    /// one coordinate must come back to its start value through the
    /// transitions, so that isolines close around them (empty: none).
    pub cyclic_loops: &'a [Vec<u32>],
    /// Per face: its target lengths per direction (`super::anisotropy`;
    /// empty or `None`: S(f) both ways).
    pub anisotropy: &'a [Option<super::anisotropy::AxisLengths>],
    /// Re-solves of MIQ's stiffening after the rounding (see
    /// [`super::Params::stiffening`]); 0: none.
    pub stiffening: usize,
    /// Loops round thin parts ([`super::thin_parts::thin_part_loops`])
    /// whose image must be at least `thin_loop_translation` units long
    /// ([`widen_loops`]; empty: none).
    pub thin_loops: &'a [super::thin_parts::ThinLoop],
    /// The least length of a thin part's loop in the map, in units
    /// (target edges); 0: no constraint.
    pub thin_loop_translation: f64,
}

/// The factor on a flipped face's E_orient weight per stiffening re-solve
/// (its edge neighbours get its square root).
const STIFFENING_FACTOR: f64 = 4.0;

/// The integer-grid map.
#[derive(Debug, Clone, PartialEq)]
pub struct GridMap {
    /// Per face corner: (u, v) in the face's chart.
    pub uv: Vec<[DVec2; 3]>,
    pub cut: Cut,
    /// Per face: the combed cross projected onto the face (w̄0, w̄1).
    pub frames: Vec<[DVec3; 2]>,
    pub cones: Vec<Cone>,
    pub topology: EdgeTopology,
    /// E_orient at the solution.
    pub energy: f64,
    /// Re-solves of the rounding.
    pub rounding_steps: usize,
    /// Sparse symbolic Cholesky analyses (fill-reducing ordering): one,
    /// of the continuous unknowns' system (the rounding's re-solves are
    /// dense ones on the condensed system, [`Condensed`]).
    pub symbolic_analyses: usize,
    /// Seam constraints that contradicted earlier ones plus integer
    /// quantities left non-integer (0 in a valid map).
    pub conflicts: usize,
    /// Loops of [`MapInput::cyclic_loops`] that got a closing constraint.
    pub closed_loops: usize,
    /// Loops of [`MapInput::thin_loops`] that got a translation constraint.
    pub widened_loops: usize,
}

impl GridMap {
    /// The transition from face `f`'s chart to the chart across its local
    /// edge `e` (None on the boundary), from the edge's first end point.
    pub fn transition(&self, f: usize, e: usize) -> Option<(Transition, DVec2)> {
        let (g, ge) = self.topology.across(f, e)?;
        let k = self.cut.matching[f][e];
        let (fa, fb) = (self.uv[f][e], self.uv[f][(e + 1) % 3]);
        let (ga, gb) = (self.uv[g][(ge + 1) % 3], self.uv[g][ge]);
        let ta = ga - rotate(k, fa);
        let tb = gb - rotate(k, fb);
        Some((Transition { k, t: ta }, tb - ta))
    }

    /// The transition from the chart of `faces[0]` to itself once around
    /// the closed loop of faces (consecutive ones sharing an edge, the
    /// last one sharing an edge with the first): its rotation, and its
    /// translation (a helix around the loop when no coordinate comes back,
    /// i.e. both components are non-zero while the rotation is 0). `None`
    /// when two consecutive faces are not neighbours.
    pub fn holonomy(&self, faces: &[u32]) -> Option<Transition> {
        let mut total = Transition::IDENTITY;
        for i in 0..faces.len() {
            let (a, b) = (faces[i] as usize, faces[(i + 1) % faces.len()] as usize);
            if a == b {
                continue;
            }
            let e = (0..3).find(|&e| self.topology.across(a, e).is_some_and(|(g, _)| g == b))?;
            let (step, _) = self.transition(a, e)?;
            total = step.after(&total);
        }
        Some(total)
    }

    /// Faces whose parametric area is not positive.
    pub fn flipped(&self) -> Vec<bool> {
        self.uv
            .iter()
            .map(|q| (q[1] - q[0]).perp_dot(q[2] - q[0]) <= 0.0)
            .collect()
    }
}

struct Layout {
    wedges: usize,
    /// Per seam edge (f, e) with g > f.
    seams: Vec<(usize, usize)>,
}

impl Layout {
    fn w(&self, wedge: u32, c: usize) -> usize {
        2 * wedge as usize + c
    }
    fn t(&self, seam: usize, c: usize) -> usize {
        2 * self.wedges + 2 * seam + c
    }
    fn len(&self) -> usize {
        2 * self.wedges + 2 * self.seams.len()
    }
}

fn combed_frames(mesh: &TriMesh, field: &CrossField, c: &Cut) -> Vec<[DVec3; 2]> {
    (0..mesh.triangles.len())
        .map(|f| {
            let n = mesh.face_normal_unnormalized(f).normalize_or_zero();
            let nh = field.normals[f];
            let d = n.dot(nh);
            let d = if d.abs() < 0.05 {
                0.05f64.copysign(d)
            } else {
                d
            };
            std::array::from_fn(|k| {
                let w = field.arm(f, c.comb[f] as i32 + k as i32);
                w - nh * (n.dot(w) / d)
            })
        })
        .collect()
}

/// The linear functionals that must become integers, cones first.
struct Integers {
    quantities: Vec<Vec<(usize, f64)>>,
    /// The leading quantities (cone coordinates) are rounded before the rest.
    first: usize,
}

fn seam_constraints(el: &mut Eliminator, input: &MapInput<'_>, c: &Cut, lay: &Layout) -> usize {
    let mut conflicts = 0;
    for (s, &(f, e)) in lay.seams.iter().enumerate() {
        let Some((g, ge)) = input.topology.across(f, e) else {
            continue;
        };
        let (src, sign) = rotation_map(c.matching[f][e]);
        for (cf, cg) in [(e, (ge + 1) % 3), ((e + 1) % 3, ge)] {
            for comp in 0..2 {
                let terms = [
                    (lay.w(c.wedge[g][cg], comp), 1.0),
                    (lay.w(c.wedge[f][cf], src[comp]), -sign[comp]),
                    (lay.t(s, comp), -1.0),
                ];
                if let Added::Conflict(_) = el.add(&terms, 0.0, 1e-9) {
                    conflicts += 1;
                }
            }
        }
    }
    conflicts
}

/// Boundary and feature-curve isolines; returns the integer quantities
/// they add.
fn boundary_constraints(
    el: &mut Eliminator,
    input: &MapInput<'_>,
    c: &Cut,
    frames: &[[DVec3; 2]],
    lay: &Layout,
) -> Vec<Vec<(usize, f64)>> {
    let mut out = Vec::new();
    for (f, t) in input.mesh.triangles.iter().enumerate() {
        for e in 0..3 {
            // The boundary, and a feature edge once, from its lower face
            // (the other side follows through the transition).
            let isoline = match input.topology.across(f, e) {
                None => true,
                Some((g, _)) => g > f && input.feature_edges.get(f).is_some_and(|s| s[e]),
            };
            if !isoline {
                continue;
            }
            let d = input
                .boundary_tangents
                .get(f)
                .and_then(|b| b[e])
                .unwrap_or_else(|| {
                    input.mesh.positions[t[(e + 1) % 3] as usize]
                        - input.mesh.positions[t[e] as usize]
                });
            let along0 = d.dot(frames[f][0].normalize_or_zero()).abs()
                >= d.dot(frames[f][1].normalize_or_zero()).abs();
            let comp = if along0 { 1 } else { 0 };
            let (a, b) = (
                lay.w(c.wedge[f][e], comp),
                lay.w(c.wedge[f][(e + 1) % 3], comp),
            );
            el.add(&[(a, 1.0), (b, -1.0)], 0.0, 1e-9);
            out.push(vec![(a, 1.0)]);
        }
    }
    out
}

/// One wedge per face component at the origin: at a cone, else on the
/// boundary, else the component's first face.
fn gauge(el: &mut Eliminator, input: &MapInput<'_>, c: &Cut, lay: &Layout) {
    let nf = input.mesh.triangles.len();
    let comp = face_components(input.topology);
    let mut done = vec![false; nf];
    let mut corner_of = vec![None; input.mesh.positions.len()];
    for (f, t) in input.mesh.triangles.iter().enumerate() {
        for (i, &v) in t.iter().enumerate() {
            corner_of[v as usize].get_or_insert((f, i));
        }
    }
    let cones = input
        .field
        .cones
        .iter()
        .filter_map(|k| corner_of[k.vertex as usize]);
    let boundary = (0..nf).flat_map(|f| {
        (0..3)
            .filter(move |&e| input.topology.across(f, e).is_none())
            .map(move |e| (f, e))
    });
    let faces = (0..nf).map(|f| (f, 0));
    for (f, i) in cones.chain(boundary).chain(faces) {
        let k = comp[f] as usize;
        if done[k] {
            continue;
        }
        done[k] = true;
        for cc in 0..2 {
            el.add(&[(lay.w(c.wedge[f][i], cc), 1.0)], 0.0, 1e-9);
        }
    }
}

/// A linear expression per coordinate over the unknowns.
type Affine = [Vec<(usize, f64)>; 2];

/// R^k applied to a symbolic translation.
fn rotate_terms(k: u8, t: &Affine) -> Affine {
    let (src, sign) = rotation_map(k);
    std::array::from_fn(|c| t[src[c]].iter().map(|&(i, x)| (i, sign[c] * x)).collect())
}

/// Campen §4.3: each loop's holonomy X ↦ R^k X + t from its first face's
/// chart to itself, k and t (a sum of seam translations rotated along the
/// way, per coordinate). Loops that are not closed face paths get None.
fn loop_holonomies<'l>(
    input: &MapInput<'_>,
    loops: impl Iterator<Item = &'l [u32]>,
    c: &Cut,
    lay: &Layout,
) -> Vec<Option<(u8, Affine)>> {
    let mut seam_of = vec![[u32::MAX; 3]; input.mesh.triangles.len()];
    for (s, &(f, e)) in lay.seams.iter().enumerate() {
        seam_of[f][e] = s as u32;
        if let Some((g, ge)) = input.topology.across(f, e) {
            seam_of[g][ge] = s as u32;
        }
    }
    let holonomy = |faces: &[u32]| -> Option<(u8, Affine)> {
        let n = faces.len();
        if n < 3 {
            return None;
        }
        let mut t: Affine = [Vec::new(), Vec::new()];
        let mut k = 0u8;
        for i in 0..n {
            let (a, b) = (faces[i] as usize, faces[(i + 1) % n] as usize);
            let e = (0..3).find(|&e| input.topology.across(a, e).is_some_and(|(g, _)| g == b))?;
            let s = seam_of[a][e];
            if s == u32::MAX {
                continue;
            }
            let (f, fe) = lay.seams[s as usize];
            let km = c.matching[f][fe];
            let var = |comp: usize| (lay.t(s as usize, comp), 1.0);
            if a == f {
                // X_b = R^k X_a + t_s.
                t = rotate_terms(km, &t);
                for comp in 0..2 {
                    t[comp].push(var(comp));
                }
                k = (k + km) % 4;
            } else {
                // X_b = R^{-k} (X_a - t_s).
                for comp in 0..2 {
                    t[comp].push((var(comp).0, -1.0));
                }
                let m = (4 - km % 4) % 4;
                t = rotate_terms(m, &t);
                k = (k + m) % 4;
            }
        }
        Some((k, t))
    };
    loops.map(holonomy).collect()
}

/// The translations of [`MapInput::cyclic_loops`]' holonomies: Campen's
/// loops close isolines only where the holonomy does not rotate (None
/// elsewhere).
fn cyclic_holonomies(input: &MapInput<'_>, c: &Cut, lay: &Layout) -> Vec<Option<Affine>> {
    let loops = input.cyclic_loops.iter().map(Vec::as_slice);
    loop_holonomies(input, loops, c, lay)
        .into_iter()
        .map(|h| h.and_then(|(k, t)| (k == 0).then_some(t)))
        .collect()
}

/// Campen §4.3 on the [`Condensed`] system (the holonomies are sums of
/// seam translations, so they involve Z unknowns only): around each loop
/// in turn, the holonomy component whose closing raises the energy least
/// becomes 0 — its exact increase, q(y*)² / (gᵀM⁻¹g) at the current
/// minimiser ([`Reduced::cost`]). The component the field already
/// closes costs nothing, where a choice by the loop's direction (which
/// coordinate's axis is more transversal to a jagged face path) can
/// close the other and collapse the map around the loop. A loop that
/// already closes in either coordinate (through the constraints so far,
/// e.g. a homotopic loop's) needs nothing more: closing the other too
/// would collapse the map. Returns the number of loops constrained.
fn close_loops(
    el: &mut Eliminator,
    sys: &Condensed,
    holonomies: &[Option<Affine>],
) -> Result<usize, MapStop> {
    let mut constrained = 0;
    let mut reduced: Option<Reduced<'_>> = None;
    for t in holonomies.iter().flatten() {
        let e = [el.reduce(&t[0], 0.0), el.reduce(&t[1], 0.0)];
        let closes =
            |e: &Expr| e.terms.iter().all(|t| t.1.abs() < 1e-12) && e.constant.abs() < 1e-9;
        if closes(&e[0]) || closes(&e[1]) {
            continue;
        }
        if reduced.is_none() {
            reduced = Some(sys.reduced(el).ok_or(MapStop::Solve)?);
        }
        let r = reduced.as_ref().expect("just computed");
        let cost = [r.cost(&e[0]), r.cost(&e[1])];
        let comp = usize::from(cost[1] < cost[0]);
        if !cost[comp].is_finite() {
            continue;
        }
        if let Added::Eliminated(_) = el.add(&t[comp], 0.0, 1e-9) {
            constrained += 1;
            reduced = None;
        }
    }
    Ok(constrained)
}

/// A thin loop's development in the map ([`widen_loops`]).
struct Development {
    /// The chord T⁻¹(X₀) − X₀ of the loop's image, from its base point
    /// X₀ (a corner of the first face) round to the same point in
    /// the chart continued along the loop, over the unknowns; T is the
    /// holonomy X ↦ R^k X + t ([`GridMap::holonomy`]).
    chord: Affine,
    /// The holonomy's rotation k.
    k: u8,
    /// The chord E_orient asks for (the loop's segments written in the
    /// combed crosses, over S(f) or the anisotropy's lengths, turned into
    /// the first face's chart), and the loop's length in those units.
    asked: DVec2,
    length: f64,
}

/// Per thin loop of the input, its [`Development`]; None when the loop
/// is not a closed face path or its frames are degenerate.
fn thin_loop_developments(
    input: &MapInput<'_>,
    c: &Cut,
    frames: &[[DVec3; 2]],
    lay: &Layout,
) -> Vec<Option<Development>> {
    if input.thin_loops.is_empty() {
        return Vec::new();
    }
    let holonomies = loop_holonomies(
        input,
        input.thin_loops.iter().map(|l| l.faces.as_slice()),
        c,
        lay,
    );
    // Vertices with an integer coordinate (cones, boundary and feature
    // isolines): no base point, a continuous value there would contradict
    // the rounding. Nor a wedge another loop uses.
    let mut pinned = vec![false; input.mesh.positions.len()];
    for k in &input.field.cones {
        if let Some(p) = pinned.get_mut(k.vertex as usize) {
            *p = true;
        }
    }
    for (f, t) in input.mesh.triangles.iter().enumerate() {
        for e in 0..3 {
            let feature = input.feature_edges.get(f).is_some_and(|x| x[e]);
            if feature || input.topology.across(f, e).is_none() {
                pinned[t[e] as usize] = true;
                pinned[t[(e + 1) % 3] as usize] = true;
            }
        }
    }
    let mut used = std::collections::HashSet::new();
    input
        .thin_loops
        .iter()
        .zip(holonomies)
        .map(|(l, h)| {
            let (k, t) = h?;
            let n = l.faces.len();
            if l.points.len() != n {
                return None;
            }
            // Σ over the faces of the segment in the face's chart (the
            // combed cross's coordinates over S), turned back into the
            // first face's chart: X_b = R^m X_a + t across an edge of
            // matching m, so vectors of chart i are R^acc of chart 0's.
            let mut acc = 0u8;
            let (mut asked, mut length) = (DVec2::ZERO, 0.0);
            for i in 0..n {
                let f = l.faces[i] as usize;
                let s = input.face_sizing.get(f).copied().unwrap_or(1.0);
                if !(s.is_finite() && s > 0.0) {
                    return None;
                }
                // E_orient's target per face: ∇g_c · w̄_c = its inverse
                // length along w̄_c (1/S, or the anisotropy's).
                let lengths = input.anisotropy.get(f).copied().flatten();
                let inverse = super::anisotropy::inverse_lengths(s, frames[f], lengths);
                let seg = in_frame(&frames[f], l.points[(i + 1) % n] - l.points[i])?
                    * DVec2::from(inverse);
                asked += rotate((4 - acc) % 4, seg);
                length += seg.length();
                let g = l.faces[(i + 1) % n] as usize;
                let e =
                    (0..3).find(|&e| input.topology.across(f, e).is_some_and(|(h, _)| h == g))?;
                acc = (acc + c.matching[f][e]) % 4;
            }
            // T⁻¹(X) = R^{−k}(X − t); chord = R^{−k}(X₀ − t) − X₀, X₀ a
            // corner of the first face (its chart is the holonomy's).
            let f0 = l.faces[0] as usize;
            let corner = (0..3).find(|&i| {
                let v = input.mesh.triangles[f0][i] as usize;
                !pinned[v] && !used.contains(&c.wedge[f0][i])
            })?;
            let w = c.wedge[f0][corner];
            used.insert(w);
            let x0: Affine = std::array::from_fn(|comp| vec![(lay.w(w, comp), 1.0)]);
            let shifted: Affine = std::array::from_fn(|comp| {
                let mut terms = x0[comp].clone();
                terms.extend(t[comp].iter().map(|&(i, v)| (i, -v)));
                terms
            });
            let mut chord = rotate_terms((4 - k) % 4, &shifted);
            for comp in 0..2 {
                chord[comp].push((lay.w(w, comp), -1.0));
            }
            Some(Development {
                chord,
                k,
                asked,
                length,
            })
        })
        .collect()
}

/// The hard constraint round thin parts, on the [`Condensed`] system as
/// [`close_loops`]: round each loop of [`MapInput::thin_loops`] shorter
/// than `least` units in the map's own sizing, the loop's image gets the
/// chord E_orient asks for scaled to a loop of `least` units. Without
/// rotation (k = 0) the chord is the holonomy's translation, integer: the
/// nearest reachable integers ([`nearest_reachable_integer`]); with a
/// rotation it fixes the base point's distance from the holonomy's
/// centre (the cones inside acting as one), a continuous quantity. The
/// asked chord, not the relaxed map's, which is about 0 round a part the
/// map folds flat. A loop whose chord is already fixed (a homotopic
/// loop's constraint, no cone between) or whose constraint would
/// contradict the ones so far gets none. Returns the number of loops
/// constrained.
fn widen_loops(el: &mut Eliminator, least: f64, developments: &[Option<Development>]) -> usize {
    if !(least.is_finite() && least > 0.0) {
        return 0;
    }
    let mut widened = 0;
    for d in developments.iter().flatten() {
        if !(d.length > 1e-9 && d.length < least) {
            continue;
        }
        let target = d.asked * (least / d.length);
        let mut added = false;
        for comp in 0..2 {
            let e = el.reduce(&d.chord[comp], 0.0);
            if e.terms.iter().all(|x| x.1.abs() < 1e-12) {
                continue;
            }
            let value = if d.k == 0 {
                nearest_reachable_integer(&e, target[comp])
            } else {
                target[comp]
            };
            if let Added::Eliminated(_) = el.add(&d.chord[comp], value, 1e-9) {
                added = true;
            }
        }
        widened += usize::from(added);
    }
    widened
}

/// `d` (in the face's plane) as a·w̄0 + b·w̄1; None for a degenerate
/// frame.
fn in_frame(w: &[DVec3; 2], d: DVec3) -> Option<DVec2> {
    // Least squares in 3D: the 2×2 Gram system.
    let (g00, g01, g11) = (w[0].dot(w[0]), w[0].dot(w[1]), w[1].dot(w[1]));
    let (r0, r1) = (w[0].dot(d), w[1].dot(d));
    let det = g00 * g11 - g01 * g01;
    if !(det.is_finite() && det > 1e-12 * (g00 * g11).max(1e-300)) {
        return None;
    }
    Some(DVec2::new(g11 * r0 - g01 * r1, g00 * r1 - g01 * r0) / det)
}

/// Per face: the four weighted E_orient rows (terms over x, target).
fn energy_rows(
    input: &MapInput<'_>,
    c: &Cut,
    frames: &[[DVec3; 2]],
    lay: &Layout,
    stiffness: Option<&[f64]>,
) -> Vec<(Vec<(usize, f64)>, f64)> {
    let mesh = input.mesh;
    let mut rows = Vec::with_capacity(4 * mesh.triangles.len());
    for f in 0..mesh.triangles.len() {
        let p = mesh.corners(f);
        let nrm = mesh.face_normal_unnormalized(f);
        let area2 = nrm.length();
        let s = input.face_sizing.get(f).copied().unwrap_or(1.0);
        if area2 <= 1e-300 || !(s > 0.0 && s.is_finite()) {
            continue;
        }
        let n = nrm / area2;
        let projected = 0.5 * area2 * n.dot(input.field.normals[f]).abs().max(1e-3);
        let w = (projected * stiffness.map_or(1.0, |k| k[f])).sqrt();
        let grad: [DVec3; 3] =
            std::array::from_fn(|i| n.cross(p[(i + 2) % 3] - p[(i + 1) % 3]) / area2);
        let lengths = input.anisotropy.get(f).copied().flatten();
        let inverse = super::anisotropy::inverse_lengths(s, frames[f], lengths);
        for comp in 0..2 {
            for (k, axis) in frames[f].iter().enumerate() {
                let terms = (0..3)
                    .map(|i| (lay.w(c.wedge[f][i], comp), w * grad[i].dot(*axis)))
                    .collect();
                let target = if k == comp { w * inverse[k] } else { 0.0 };
                rows.push((terms, target));
            }
        }
        if let Some((dirs, weight)) = input.region_alignment {
            if let Some(a) = dirs.get(f).copied().flatten() {
                // E_align for the coordinate c whose cross axis is
                // transversal to a_min: ∇g_c · ŵ = 0 along the field's
                // axis ŵ nearest a_min (Campen's anisotropic norm in the
                // cross frame; ŵ = a_min where the field follows a_min).
                let a = a.reject_from_normalized(n);
                let along = usize::from(frames[f][0].dot(a).abs() < frames[f][1].dot(a).abs());
                let comp = 1 - along;
                let axis = frames[f][along].normalize_or_zero();
                let wa = (weight.max(0.0) * projected).sqrt();
                let terms = (0..3)
                    .map(|i| (lay.w(c.wedge[f][i], comp), wa * grad[i].dot(axis)))
                    .collect();
                rows.push((terms, 0.0));
            }
        }
    }
    rows
}

/// The rounding's system with the integer unknowns last: the free
/// variables split into Z, those the integer quantities use (cone
/// coordinates, seam translations, isoline values: a few hundred), and
/// the continuous rest F. The energy's normal equations
/// [K_FF K_FZ; K_ZF K_ZZ] y = [b_F; b_Z] are condensed once onto Z, the
/// Schur complement S = K_ZZ − K_ZF K_FF⁻¹ K_FZ and b̃ = b_Z − K_ZF K_FF⁻¹
/// b_F (one sparse Cholesky factorization K_FF = PᵀLLᵀP; then
/// K_ZF K_FF⁻¹ K_FZ = WᵀW with W = L⁻¹ P K_FZ by sparse forward
/// substitutions along the elimination tree, [`subtract_inverse_forms`],
/// or block solves for K_FZ's columns when the factor is simplicial: on
/// the bunny the condensation took 285 ms by block solves, 92 ms so). The rounding's constraints only involve Z
/// (a rounded quantity is an expression of Z unknowns, and eliminating
/// one of them keeps every other quantity's reduction in Z), so every
/// re-solve of MIQ's greedy rounding is a small dense one,
/// min yᵀS y − 2b̃ᵀy over the Z unknowns still free, and the continuous
/// unknowns follow once at the end, y_F = K_FF⁻¹ (b_F − K_FZ y_Z). The
/// same minimiser as re-solving the whole system after each batch.
struct Condensed {
    /// Per variable: its index in Z, or `usize::MAX`.
    z_index: Vec<usize>,
    /// The Z unknowns (variable indices).
    z_vars: Vec<usize>,
    /// The F unknowns (variable indices).
    f_vars: Vec<usize>,
    factor: SpdFactor,
    /// Per Z unknown: its column of K_FZ, (F index, value).
    k_fz: Vec<Vec<(usize, f64)>>,
    b_f: Vec<f64>,
    s: DMatrix<f64>,
    b_z: DVector<f64>,
}

/// Right-hand sides solved together in [`Condensed::new`].
const BLOCK: usize = 32;

/// Diagonal shifts tried in turn when a system is singular (or its
/// solution not finite).
const SHIFTS: [f64; 3] = [0.0, 1e-10, 1e-7];

/// The most integer variables (cone positions and seam translations after
/// elimination) the rounding's dense Schur complement is built for: 4096²
/// doubles are 128 MiB.
pub const MAX_INTEGER_VARIABLES: usize = 4096;
/// Entries of the condensed normal equations allowed beyond 32 per
/// variable (32 M: 768 MiB of triplets). The shared meshes need under 35
/// per variable (the bunny 2.2 M for 69 k); rocker-arm with a thousand
/// cones needed billions (rows through long seams reduce to a term per
/// cone, and a row's terms enter squared).
const EXTRA_TRIPLETS: usize = 32 << 20;

impl Condensed {
    /// The condensed system of the rows under the eliminator's
    /// constraints, Z the free variables the `integer` quantities reduce
    /// to. `go_on()` is asked between the block solves.
    fn new(
        el: &Eliminator,
        rows: &[(Vec<(usize, f64)>, f64)],
        integer: &[Vec<(usize, f64)>],
        go_on: &mut dyn FnMut() -> bool,
    ) -> Result<Condensed, MapStop> {
        let n = el.len();
        let mut z_index = vec![usize::MAX; n];
        let mut z_vars = Vec::new();
        for q in integer {
            for (i, _) in el.reduce(q, 0.0).terms {
                if z_index[i] == usize::MAX {
                    z_index[i] = z_vars.len();
                    z_vars.push(i);
                }
            }
        }
        let mut f_index = vec![usize::MAX; n];
        let mut f_vars = Vec::new();
        for i in 0..n {
            if el.is_free(i) && z_index[i] == usize::MAX {
                f_index[i] = f_vars.len();
                f_vars.push(i);
            }
        }
        let (nf, nz) = (f_vars.len(), z_vars.len());
        // S below is dense: nz² doubles and an nz³ factorization. The shared
        // meshes need at most about 200 (two per cone and per seam); a field
        // with thousands of cones (a noisy sizing, see the cross field's
        // sizing transport) would take gigabytes, so it stops here instead.
        if nz > MAX_INTEGER_VARIABLES {
            return Err(MapStop::TooManyIntegers(nz));
        }
        // The normal equations in the index space F, then Z.
        let mut eq = NormalEquations::new(nf + nz);
        let mut compact = Vec::new();
        for (terms, target) in rows {
            let e = el.reduce(terms, 0.0);
            compact.clear();
            compact.extend(e.terms.iter().map(|&(j, c)| {
                let k = if f_index[j] != usize::MAX {
                    f_index[j]
                } else {
                    nf + z_index[j]
                };
                (k, c)
            }));
            eq.row(1.0, &compact, target - e.constant);
            // A row through a seam between many cones reduces to a term
            // per cone: its square in the normal equations grows fast.
            if eq.triplets.len() > 32 * (nf + nz) + EXTRA_TRIPLETS {
                return Err(MapStop::TooManyIntegers(nz));
            }
        }
        let mut ff: Vec<(usize, usize, f64)> = Vec::with_capacity(eq.triplets.len() + nf);
        let mut k_fz = vec![Vec::new(); nz];
        let mut s = DMatrix::zeros(nz, nz);
        for &(r, c, v) in &eq.triplets {
            match (r < nf, c < nf) {
                (true, _) => ff.push((r, c, v)),
                (false, true) => k_fz[r - nf].push((c, v)),
                (false, false) => {
                    s[(r - nf, c - nf)] += v;
                    if r != c {
                        s[(c - nf, r - nf)] += v;
                    }
                }
            }
        }
        drop(eq.triplets);
        for col in &mut k_fz {
            col.sort_unstable_by_key(|e| e.0);
            col.dedup_by(|b, a| {
                if a.0 == b.0 {
                    a.1 += b.1;
                    true
                } else {
                    false
                }
            });
        }
        // The full diagonal in the pattern, for a shift.
        ff.extend((0..nf).map(|i| (i, i, 0.0)));
        let pattern = SpdPattern::new(nf, &ff).ok_or(MapStop::Solve)?;
        let mut factor = None;
        for eps in SHIFTS {
            let result = if eps == 0.0 {
                pattern.factor(&ff)
            } else {
                let mut t = ff.clone();
                t.extend((0..nf).map(|i| (i, i, eps)));
                pattern.factor(&t)
            };
            if let Ok(f) = result {
                factor = Some(f);
                break;
            }
        }
        drop(ff);
        let factor = factor.ok_or(MapStop::Solve)?;
        let b_f = eq.rhs[..nf].to_vec();
        let mut b_z = DVector::from_column_slice(&eq.rhs[nf..]);
        if let Some(mut forward) = factor.forward_substitution() {
            if !go_on() {
                return Err(MapStop::Cancelled);
            }
            subtract_inverse_forms(&mut forward, &k_fz, &b_f, &mut s, &mut b_z)
                .ok_or(MapStop::Solve)?;
        } else {
            // A simplicial factor: block solves.
            // Column None is b_F, Some(z) the column of K_FZ.
            let columns: Vec<Option<usize>> =
                std::iter::once(None).chain((0..nz).map(Some)).collect();
            for chunk in columns.chunks(BLOCK) {
                if !go_on() {
                    return Err(MapStop::Cancelled);
                }
                let mut x = Mat::<f64>::zeros(nf, chunk.len());
                for (j, c) in chunk.iter().enumerate() {
                    match *c {
                        None => {
                            for (i, &b) in b_f.iter().enumerate() {
                                x[(i, j)] = b;
                            }
                        }
                        Some(z) => {
                            for &(i, v) in &k_fz[z] {
                                x[(i, j)] = v;
                            }
                        }
                    }
                }
                if !factor.solve_in_place(x.as_mut()) {
                    return Err(MapStop::Solve);
                }
                for (j, c) in chunk.iter().enumerate() {
                    for (z2, col) in k_fz.iter().enumerate() {
                        let d: f64 = col.iter().map(|&(i, v)| v * x[(i, j)]).sum();
                        match *c {
                            None => b_z[z2] -= d,
                            Some(z) => s[(z2, z)] -= d,
                        }
                    }
                }
            }
        }
        let s = (&s + s.transpose()) * 0.5;
        Ok(Condensed {
            z_index,
            z_vars,
            f_vars,
            factor,
            k_fz,
            b_f,
            s,
            b_z,
        })
    }

    /// The Z unknowns minimising the energy under the eliminator's
    /// constraints (those added since [`Condensed::new`] involve Z only).
    fn solve(&self, el: &Eliminator) -> Option<DVector<f64>> {
        self.reduced(el).map(|r| r.y)
    }

    /// The energy over the Z unknowns still free under the eliminator's
    /// constraints, factored, and its minimiser.
    fn reduced(&self, el: &Eliminator) -> Option<Reduced<'_>> {
        let nz = self.z_vars.len();
        let mut column = vec![usize::MAX; nz];
        let mut m = 0;
        for (k, &i) in self.z_vars.iter().enumerate() {
            if el.is_free(i) {
                column[k] = m;
                m += 1;
            }
        }
        // y_Z = A u + c over the free Z unknowns u (A sparse, per row).
        let mut a: Vec<Vec<(usize, f64)>> = Vec::with_capacity(nz);
        let mut c = DVector::zeros(nz);
        for (k, &i) in self.z_vars.iter().enumerate() {
            let e = el.reduce(&[(i, 1.0)], 0.0);
            c[k] = e.constant;
            let mut row = Vec::with_capacity(e.terms.len());
            for (j, v) in e.terms {
                let z = self.z_index[j];
                debug_assert!(z != usize::MAX, "a Z unknown reduces to Z unknowns");
                row.push((column[z], v));
            }
            a.push(row);
        }
        // S·A by columns of A, then Aᵀ(S A) and Aᵀ(b̃ − S c).
        let mut sa = DMatrix::zeros(nz, m);
        for (k, row) in a.iter().enumerate() {
            for &(j, v) in row {
                let mut col = sa.column_mut(j);
                col.axpy(v, &self.s.column(k), 1.0);
            }
        }
        let r0 = &self.b_z - &self.s * &c;
        let mut mat = DMatrix::zeros(m, m);
        let mut rhs = DVector::zeros(m);
        for (k, row) in a.iter().enumerate() {
            for &(j, v) in row {
                // M is symmetric: its column j is its row j.
                mat.column_mut(j).axpy(v, &sa.row(k).transpose(), 1.0);
                rhs[j] += v * r0[k];
            }
        }
        let (factor, u) = SHIFTS.iter().find_map(|&eps| {
            let mut shifted = mat.clone();
            for i in 0..m {
                shifted[(i, i)] += eps;
            }
            let factor = shifted.cholesky()?;
            let u = factor.solve(&rhs);
            u.iter().all(|x| x.is_finite()).then_some((factor, u))
        })?;
        let mut y = c;
        for (k, row) in a.iter().enumerate() {
            y[k] += row.iter().map(|&(j, v)| v * u[j]).sum::<f64>();
        }
        Some(Reduced {
            sys: self,
            column,
            factor,
            u,
            y,
        })
    }

    /// The value of an expression reduced to free variables, all in Z.
    fn value(&self, e: &Expr, y: &DVector<f64>) -> f64 {
        e.constant
            + e.terms
                .iter()
                .map(|&(j, v)| v * y[self.z_index[j]])
                .sum::<f64>()
    }

    /// Every variable's value for the Z unknowns `y`: the continuous ones
    /// from y_F = K_FF⁻¹ (b_F − K_FZ y_Z), the eliminated ones from the
    /// eliminator.
    fn expand(&self, el: &Eliminator, y: &DVector<f64>) -> Option<Vec<f64>> {
        let mut b = Mat::<f64>::zeros(self.f_vars.len(), 1);
        for (i, &v) in self.b_f.iter().enumerate() {
            b[(i, 0)] = v;
        }
        for (z, col) in self.k_fz.iter().enumerate() {
            for &(i, v) in col {
                b[(i, 0)] -= v * y[z];
            }
        }
        if !self.factor.solve_in_place(b.as_mut()) {
            return None;
        }
        let mut free = vec![0.0; el.len()];
        for (i, &var) in self.f_vars.iter().enumerate() {
            free[var] = b[(i, 0)];
        }
        for (z, &var) in self.z_vars.iter().enumerate() {
            free[var] = y[z];
        }
        Some(el.expand(&free))
    }
}

/// Rows of W = L⁻¹ P K_FZ assembled densely per block in
/// [`subtract_inverse_forms`].
const ROW_BLOCK: usize = 2048;

/// S −= K_ZF K_FF⁻¹ K_FZ = WᵀW and b̃ −= K_ZF K_FF⁻¹ b_F = Wᵀ(L⁻¹P b_F)
/// with W = L⁻¹ P K_FZ by sparse forward substitutions (K_FZ's columns
/// are short: each reaches only its rows' paths to the elimination tree's
/// root), the products dense over the rows some column reaches, a block
/// of rows at a time. None when a value is not finite.
fn subtract_inverse_forms(
    forward: &mut ForwardSubstitution<'_>,
    k_fz: &[Vec<(usize, f64)>],
    b_f: &[f64],
    s: &mut DMatrix<f64>,
    b_z: &mut DVector<f64>,
) -> Option<()> {
    let nz = k_fz.len();
    let w: Vec<Vec<(usize, f64)>> = k_fz.iter().map(|col| forward.solve(col)).collect();
    let dense: Vec<(usize, f64)> = b_f.iter().copied().enumerate().collect();
    let mut wb = vec![0.0; b_f.len()];
    for (i, v) in forward.solve(&dense) {
        wb[i] = v;
    }
    let mut rows: Vec<usize> = w.iter().flatten().map(|e| e.0).collect();
    rows.sort_unstable();
    rows.dedup();
    let mut at = vec![0usize; nz];
    let mut block = Mat::<f64>::zeros(ROW_BLOCK.min(rows.len()), nz);
    let mut product = Mat::<f64>::zeros(nz, nz);
    let mut position = vec![usize::MAX; b_f.len()];
    for chunk in rows.chunks(ROW_BLOCK) {
        for (k, &r) in chunk.iter().enumerate() {
            position[r] = k;
        }
        let last = *chunk.last().expect("non-empty");
        block.fill(0.0);
        for (z, col) in w.iter().enumerate() {
            while let Some(&(r, v)) = col.get(at[z]).filter(|e| e.0 <= last) {
                block[(position[r], z)] = v;
                at[z] += 1;
            }
        }
        let b = block.as_ref().subrows(0, chunk.len());
        faer::linalg::matmul::matmul(
            product.as_mut(),
            faer::Accum::Add,
            b.transpose(),
            b,
            1.0,
            faer::Par::Seq,
        );
        for z in 0..nz {
            let d: f64 = chunk
                .iter()
                .enumerate()
                .map(|(k, &r)| b[(k, z)] * wb[r])
                .sum();
            b_z[z] -= d;
        }
    }
    for j in 0..nz {
        for i in 0..nz {
            s[(i, j)] -= product[(i, j)];
        }
    }
    (s.iter().all(|x| x.is_finite()) && b_z.iter().all(|x| x.is_finite())).then_some(())
}

/// The condensed energy restricted to the free Z unknowns u
/// (y_Z = A u + c): E(u) = uᵀM u − 2rᵀu + const, M = AᵀS A factored, and
/// its minimiser u* (y* = A u* + c).
struct Reduced<'a> {
    sys: &'a Condensed,
    /// Per Z unknown: its index in u, or `usize::MAX` when eliminated.
    column: Vec<usize>,
    factor: nalgebra::linalg::Cholesky<f64, nalgebra::Dyn>,
    u: DVector<f64>,
    y: DVector<f64>,
}

impl Reduced<'_> {
    /// The exact increase of the energy when the expression `e` (reduced
    /// to free variables, all in Z) is constrained to 0: with
    /// q(u) = gᵀu + q0, min E under q = 0 exceeds E(u*) by
    /// q(u*)² / (gᵀM⁻¹g). Infinite when q is a non-zero constant.
    fn cost(&self, e: &Expr) -> f64 {
        let mut g = DVector::zeros(self.u.len());
        for &(j, v) in &e.terms {
            let z = self.sys.z_index[j];
            debug_assert!(z != usize::MAX, "an expression of Z unknowns");
            let col = self.column[z];
            debug_assert!(col != usize::MAX, "reduced to free variables");
            g[col] += v;
        }
        let q = e.constant + g.dot(&self.u);
        let d = g.dot(&self.factor.solve(&g));
        if d > 0.0 && d.is_finite() {
            q * q / d
        } else if q.abs() < 1e-9 {
            0.0
        } else {
            f64::INFINITY
        }
    }
}

/// Σ of the rows' squared residuals at x.
fn energy_at(rows: &[(Vec<(usize, f64)>, f64)], x: &[f64]) -> f64 {
    rows.iter()
        .map(|(terms, b)| {
            let r = terms.iter().map(|&(i, c)| c * x[i]).sum::<f64>() - b;
            r * r
        })
        .sum()
}

/// Why [`grid_map_with`] stopped without a map.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MapStop {
    /// A solve failed (singular or non-finite system).
    Solve,
    /// The integer rounding's system would be too large: more than
    /// [`MAX_INTEGER_VARIABLES`] integer variables, or normal equations
    /// past the `EXTRA_TRIPLETS` bound (the count of integer variables).
    TooManyIntegers(usize),
    /// The progress callback asked to stop.
    Cancelled,
}

/// Greedy rounding with re-solves on the [`Condensed`] system `sys` (Z
/// covering the integer quantities); returns the final solution.
/// `go_on(fraction rounded)` is asked before every re-solve. With
/// `cones_one_at_a_time` the cone coordinates are rounded singly (MIQ's
/// greedy) whatever the fraction.
fn round(
    el: &mut Eliminator,
    sys: &Condensed,
    rows: &[(Vec<(usize, f64)>, f64)],
    ints: &Integers,
    fraction: f64,
    cones_one_at_a_time: bool,
    go_on: &mut dyn FnMut(f32) -> bool,
) -> Result<(Vec<f64>, f64, usize, usize, usize), MapStop> {
    let mut done = vec![false; ints.quantities.len()];
    let mut steps = 0;
    loop {
        let finished = done.iter().filter(|&&d| d).count();
        if !go_on(finished as f32 / ints.quantities.len().max(1) as f32) {
            return Err(MapStop::Cancelled);
        }
        let y = sys.solve(el).ok_or(MapStop::Solve)?;
        let mut open: Vec<(f64, usize, f64, Expr)> = Vec::new();
        for (q, terms) in ints.quantities.iter().enumerate() {
            if done[q] {
                continue;
            }
            let e = el.reduce(terms, 0.0);
            if e.terms.is_empty() {
                done[q] = true;
                continue;
            }
            let value = sys.value(&e, &y);
            // Cone coordinates before the rest, each group nearest to an
            // integer first.
            let distance = (value - value.round()).abs();
            let priority = if q < ints.first {
                distance - 1.0
            } else {
                distance
            };
            open.push((priority, q, value, e));
        }
        if open.is_empty() {
            let x = sys.expand(el, &y).ok_or(MapStop::Solve)?;
            // Integer quantities the rounding could not make integer (a
            // batch's targets can contradict each other).
            let missed = ints
                .quantities
                .iter()
                .filter(|terms| {
                    let v: f64 = terms.iter().map(|&(i, c)| c * x[i]).sum();
                    (v - v.round()).abs() > 1e-6
                })
                .count();
            let energy = energy_at(rows, &x);
            return Ok((x, energy, steps, missed, 1));
        }
        open.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        // The same fraction of the open cone coordinates, or once they
        // are integer of the rest, per re-solve: rounding every cone at
        // once (each to its nearest integer with none of the others'
        // shifts seen) raised E_orient by a fifth to a half more than this
        // on fandisk, rocker-arm, spot and the bunny.
        //
        // Around constrained loops (Campen §4.3) the loop relations tie
        // cone coordinates together (coefficients ±1, ±2), and a batch
        // rounded with pre-batch values pushes its accumulated error into
        // the cones left: on spot at 600 vertices one ended 1.65 units
        // from its relaxed value, and the map folded (147 flipped
        // triangles against 33 without the constraints); so there the
        // cones go one at a time.
        let cones = open.iter().filter(|o| o.0 < 0.0).count();
        let pool = if cones > 0 { cones } else { open.len() };
        let batch = if cones > 0 && cones_one_at_a_time {
            1
        } else {
            ((pool as f64 * fraction).ceil() as usize).clamp(1, pool)
        };
        for (_, q, value, _) in open.iter().take(batch) {
            done[*q] = true;
            // The reduction again: earlier ones of this batch changed it.
            let target = nearest_reachable_integer(&el.reduce(&ints.quantities[*q], 0.0), *value);
            el.add(&ints.quantities[*q], target, 1e-6);
        }
        steps += 1;
    }
}

/// The integer nearest `value` that the quantity `expr` (reduced to free
/// variables) can take with integer free variables: with integer
/// coefficients of greatest common divisor g and an integer constant k,
/// only k + gℤ is reachable (a translation that the earlier roundings
/// tied to 2t + 13 must become odd, or rounding it would leave t at a
/// half-integer). Otherwise the nearest integer.
fn nearest_reachable_integer(expr: &Expr, value: f64) -> f64 {
    let integral = |x: f64| (x - x.round()).abs() < 1e-9;
    if !integral(expr.constant) || !expr.terms.iter().all(|t| integral(t.1)) {
        return value.round();
    }
    let g = expr
        .terms
        .iter()
        .map(|t| t.1.round().abs() as u64)
        .fold(0, gcd);
    if g <= 1 {
        return value.round();
    }
    let (g, k) = (g as f64, expr.constant.round());
    k + g * ((value - k) / g).round()
}

fn gcd(a: u64, b: u64) -> u64 {
    if b == 0 { a } else { gcd(b, a % b) }
}

/// Computes the map; None when a solve fails.
pub fn grid_map(input: &MapInput<'_>) -> Option<GridMap> {
    grid_map_with(input, &mut |_| true).ok()
}

/// [`grid_map`] that asks `go_on(fraction of the integer quantities
/// rounded)` before every solve and stops when it answers false.
pub fn grid_map_with(
    input: &MapInput<'_>,
    go_on: &mut dyn FnMut(f32) -> bool,
) -> Result<GridMap, MapStop> {
    grid_map_timed(input, &|| 0.0, go_on).map(|(map, _)| map)
}

/// Milliseconds of [`grid_map_timed`]'s stages.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct MapTimings {
    /// Combing, cut graph and wedges ([`cut`]), the combed frames.
    pub cut_ms: f64,
    /// Constraints, energy rows, the `Condensed` system (the sparse
    /// factorization and block solves), the loops' constraints.
    pub seamless_ms: f64,
    /// The greedy rounding's re-solves (or the relaxation's solve) and
    /// the back-substitution to every unknown.
    pub rounding_ms: f64,
}

/// [`grid_map_with`] with its stages timed by `clock` (milliseconds).
pub fn grid_map_timed(
    input: &MapInput<'_>,
    clock: &dyn Fn() -> f64,
    go_on: &mut dyn FnMut(f32) -> bool,
) -> Result<(GridMap, MapTimings), MapStop> {
    let t0 = clock();
    let mesh = input.mesh;
    let nf = mesh.triangles.len();
    let raw: Vec<[u8; 3]> = input
        .field
        .period_jump
        .iter()
        .map(|p| p.map(|k| k.rem_euclid(4) as u8))
        .collect();
    let mut anchored = vec![false; mesh.positions.len()];
    for c in &input.field.cones {
        anchored[c.vertex as usize] = true;
    }
    let c = cut(&CutInput {
        triangles: &mesh.triangles,
        vertex_count: mesh.positions.len(),
        topology: input.topology,
        raw_matching: &raw,
        anchored: &anchored,
    });
    let frames = combed_frames(mesh, input.field, &c);
    let t1 = clock();
    let seams: Vec<(usize, usize)> = (0..nf)
        .flat_map(|f| (0..3).map(move |e| (f, e)))
        .filter(|&(f, e)| c.seam[f][e] && input.topology.across(f, e).is_some_and(|(g, _)| g > f))
        .collect();
    let lay = Layout {
        wedges: c.wedge_count,
        seams,
    };
    let mut el = Eliminator::new(lay.len(), 2 * lay.wedges);
    let mut conflicts = seam_constraints(&mut el, input, &c, &lay);
    let boundary = boundary_constraints(&mut el, input, &c, &frames, &lay);
    let holonomies = cyclic_holonomies(input, &c, &lay);
    let thin = thin_loop_developments(input, &c, &frames, &lay);
    gauge(&mut el, input, &c, &lay);
    let mut quantities: Vec<Vec<(usize, f64)>> = Vec::new();
    for k in &input.field.cones {
        if let Some((f, i)) = (0..nf).find_map(|f| {
            mesh.triangles[f]
                .iter()
                .position(|&v| v == k.vertex)
                .map(|i| (f, i))
        }) {
            quantities.push(vec![(lay.w(c.wedge[f][i], 0), 1.0)]);
            quantities.push(vec![(lay.w(c.wedge[f][i], 1), 1.0)]);
        }
    }
    let first = quantities.len();
    for s in 0..lay.seams.len() {
        quantities.push(vec![(lay.t(s, 0), 1.0)]);
        quantities.push(vec![(lay.t(s, 1), 1.0)]);
    }
    quantities.extend(boundary);
    let rows = energy_rows(input, &c, &frames, &lay, None);
    if !go_on(0.0) {
        return Err(MapStop::Cancelled);
    }
    // Z: the unknowns of the integer quantities (when rounding) and of
    // the loops' holonomies (sums of seam translations, so within the
    // former's when rounding).
    let mut z_quantities: Vec<Vec<(usize, f64)>> = if input.round {
        quantities.clone()
    } else {
        Vec::new()
    };
    let loops = holonomies.iter().flatten();
    let chords = thin.iter().flatten().map(|d| &d.chord);
    z_quantities.extend(loops.chain(chords).flat_map(|t| t.iter().cloned()));
    let sys = Condensed::new(&el, &rows, &z_quantities, &mut || go_on(0.0))?;
    drop(z_quantities);
    let closed_loops = close_loops(&mut el, &sys, &holonomies)?;
    let widened_loops = widen_loops(&mut el, input.thin_loop_translation, &thin);
    let t2 = clock();
    let (x, energy, steps, more, analyses) = if input.round {
        round(
            &mut el,
            &sys,
            &rows,
            &Integers { quantities, first },
            input.batch_fraction.clamp(1e-3, 1.0),
            closed_loops + widened_loops > 0,
            go_on,
        )?
    } else {
        let y = sys.solve(&el).ok_or(MapStop::Solve)?;
        let x = sys.expand(&el, &y).ok_or(MapStop::Solve)?;
        let e = energy_at(&rows, &x);
        (x, e, 0, 0, 1)
    };
    conflicts += more;
    let face_uv = |x: &[f64]| -> Vec<[DVec2; 3]> {
        (0..nf)
            .map(|f| {
                std::array::from_fn(|i| {
                    DVec2::new(x[lay.w(c.wedge[f][i], 0)], x[lay.w(c.wedge[f][i], 1)])
                })
            })
            .collect()
    };
    // MIQ's stiffening (Bommes et al. 2009 §5): with the integers fixed,
    // faces flipped against a cross that is not flipped themselves (Ebke
    // §6's deliberate folds have flipped crosses and are kept) weigh more
    // in E_orient, and the map is solved again.
    let mut x = x;
    if input.round && input.stiffening > 0 {
        let mut stiffness = vec![1.0; nf];
        for _ in 0..input.stiffening {
            let uv = face_uv(&x);
            let flipped: Vec<usize> = (0..nf)
                .filter(|&f| {
                    let q = uv[f];
                    (q[1] - q[0]).perp_dot(q[2] - q[0]) <= 0.0
                        && mesh.face_normal_unnormalized(f).dot(input.field.normals[f]) > 0.0
                })
                .collect();
            if flipped.is_empty() {
                break;
            }
            for &f in &flipped {
                stiffness[f] *= STIFFENING_FACTOR;
                for e in 0..3 {
                    if let Some((g, _)) = input.topology.across(f, e) {
                        stiffness[g] *= STIFFENING_FACTOR.sqrt();
                    }
                }
            }
            if !go_on(1.0) {
                return Err(MapStop::Cancelled);
            }
            let rows = energy_rows(input, &c, &frames, &lay, Some(&stiffness));
            let sys = Condensed::new(&el, &rows, &[], &mut || go_on(1.0))?;
            let y = sys.solve(&el).ok_or(MapStop::Solve)?;
            x = sys.expand(&el, &y).ok_or(MapStop::Solve)?;
        }
    }
    let uv = face_uv(&x);
    let map = GridMap {
        uv,
        cut: c,
        frames,
        cones: input.field.cones.clone(),
        topology: input.topology.clone(),
        energy,
        rounding_steps: steps,
        symbolic_analyses: analyses,
        conflicts,
        closed_loops,
        widened_loops,
    };
    let t3 = clock();
    let timings = MapTimings {
        cut_ms: t1 - t0,
        seamless_ms: t2 - t1,
        rounding_ms: t3 - t2,
    };
    Ok((map, timings))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The condensed re-solve against the direct one: after constraints
    /// on the integer unknowns, minimising over the Schur complement and
    /// expanding gives the minimiser of the whole least-squares problem
    /// under the same constraints (a dense solve of all free unknowns).
    #[test]
    fn condensed_resolve_equals_the_direct_constrained_minimiser() {
        let n = 14;
        let mut rng = rand_pcg::Pcg32::new(7, 11);
        let mut next = || rand_core::RngCore::next_u32(&mut rng) as f64 / u32::MAX as f64 - 0.5;
        // Rows: a chain Laplacian with random weights and targets, plus a
        // few random three-term rows.
        let mut rows: Vec<(Vec<(usize, f64)>, f64)> = Vec::new();
        for i in 0..n - 1 {
            let w = 1.0 + next();
            rows.push((vec![(i, w), (i + 1, -w)], next()));
        }
        for i in 0..n - 2 {
            rows.push((
                vec![(i, next()), (i + 2, next()), ((i + 5) % n, next())],
                next(),
            ));
        }
        rows.push((vec![(0, 1.0)], 0.3));
        let mut el = Eliminator::new(n, n);
        el.add(&[(1, 1.0), (4, -1.0)], 0.25, 1e-9);
        el.add(&[(6, 1.0), (7, 1.0), (9, -1.0)], 0.0, 1e-9);
        let integer = vec![vec![(2, 1.0)], vec![(9, 1.0)], vec![(11, 1.0), (12, 2.0)]];
        let sys = Condensed::new(&el, &rows, &integer, &mut || true).expect("condensed");
        assert!(!sys.z_vars.is_empty() && !sys.f_vars.is_empty());
        // Round two of the quantities, as the greedy rounding does.
        el.add(&integer[0], 1.0, 1e-6);
        el.add(&integer[2], -2.0, 1e-6);
        let y = sys.solve(&el).expect("dense solve");
        let x = sys.expand(&el, &y).expect("expanded");

        // Direct: every row reduced to the free unknowns, dense normal
        // equations.
        let free: Vec<usize> = (0..n).filter(|&i| el.is_free(i)).collect();
        let col = |i: usize| free.iter().position(|&j| j == i).unwrap();
        let m = free.len();
        let mut a = DMatrix::<f64>::zeros(m, m);
        let mut b = DVector::<f64>::zeros(m);
        for (terms, target) in &rows {
            let e = el.reduce(terms, 0.0);
            for &(i, ci) in &e.terms {
                b[col(i)] += ci * (target - e.constant);
                for &(j, cj) in &e.terms {
                    a[(col(i), col(j))] += ci * cj;
                }
            }
        }
        let u = a.cholesky().expect("SPD").solve(&b);
        let mut full = vec![0.0; n];
        for (k, &i) in free.iter().enumerate() {
            full[i] = u[k];
        }
        let direct = el.expand(&full);
        for i in 0..n {
            assert!(
                (x[i] - direct[i]).abs() < 1e-9,
                "x{i}: {} vs {}",
                x[i],
                direct[i]
            );
        }
        assert!((x[2] - 1.0).abs() < 1e-12);
        assert!((x[11] + 2.0 * x[12] + 2.0).abs() < 1e-12);
        assert!((x[1] - x[4] - 0.25).abs() < 1e-12);
    }

    #[test]
    fn rounding_targets_are_reachable_with_integer_unknowns() {
        // q = 2t + 13: only odd values are reachable.
        let odd = Expr {
            terms: vec![(7, 2.0)],
            constant: 13.0,
        };
        assert_eq!(nearest_reachable_integer(&odd, 20.2), 21.0);
        assert_eq!(nearest_reachable_integer(&odd, 18.9), 19.0);
        // q = 3a − 6b + 1: 1 + 3ℤ.
        let three = Expr {
            terms: vec![(0, 3.0), (1, -6.0)],
            constant: 1.0,
        };
        assert_eq!(nearest_reachable_integer(&three, -0.6), -2.0);
        assert_eq!(nearest_reachable_integer(&three, 2.6), 4.0);
        // Unit coefficient or fractional data: the nearest integer.
        let unit = Expr {
            terms: vec![(0, 1.0), (1, 2.0)],
            constant: 0.0,
        };
        assert_eq!(nearest_reachable_integer(&unit, 2.6), 3.0);
        let half = Expr {
            terms: vec![(0, 0.5)],
            constant: 0.0,
        };
        assert_eq!(nearest_reachable_integer(&half, 2.4), 2.0);
    }
}
