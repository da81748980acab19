//! The global chart-based parametrization of Campen & Kobbelt 2014, *Dual
//! Strip Weaving*, §6.1: a map S aligned with the strip cross field, every
//! loop constrained to an isoline, computed by one sparse least-squares
//! solve in the manner of Kälberer et al. 2007 / Bommes et al. 2009 (MIQ)
//! without integer rounding.
//!
//! Steps: comb the crosses into frames (u, v) along a breadth-first dual
//! spanning tree; the matching k (quarter turns) of every interior edge;
//! the cut graph (interior edges the tree does not cross, dangling branches
//! pruned unless they end at a singularity or the boundary); one (u, v)
//! unknown per wedge (the corners around a vertex between cut edges); then
//! minimize Σ_f area_f |∇(u, v) − s·(u_f, v_f)|² (s = 1: parameters in world
//! units) + w_seam Σ_cut |ΔX_g − R_k ΔX_f|² + w_iso Σ_loops Σ_faces
//! (entry − exit of the transversal coordinate)² + ε|X|².
//!
//! The combing, the cut graph and the wedges are the integer-grid map's
//! ([`crate::param::cut`]), the transitions its [`Transition`].
//!
//! Deviations: seams and loop isolines are soft constraints (weight 10⁴
//! against the O(1) area-normalized gradient rows) instead of being
//! eliminated exactly; seams constrain edge vectors only, so charts may be
//! translated against each other (no integer translations: no rounding);
//! the gauge is a 1e-8 Tikhonov term instead of one fixed vertex (1e-6,
//! then 1e-4 when the factorization fails).

use std::f64::consts::FRAC_PI_2;

use glam::{DVec2, DVec3};

use super::embed::{EdgeTopology, EmbeddedLoop};
use super::strip_field::{StripField, face_frames};
use crate::mesh::TriMesh;
use crate::param::cut::{CutInput, cut};
pub use crate::param::seamless::{Transition, rotate};
use crate::param::solve::{NormalEquations as Normal, solve_spd};

/// Weight of seam and isoline rows.
const HARD: f64 = 1e4;

/// The map S.
#[derive(Debug, Clone, PartialEq)]
pub struct Parametrization {
    /// Per face corner: (u, v) in the face's chart (world units).
    pub uv: Vec<[DVec2; 3]>,
    /// Per face: negative (or zero) parametric area.
    pub folded: Vec<bool>,
    /// Per face: the combed frame (u axis, v axis), world unit vectors.
    pub frames: Vec<[DVec3; 2]>,
    /// Per face and local edge (corner i → i + 1): the matching k such that
    /// the edge vector in the neighbour's chart is `rotate(k, ·)` of ours.
    pub matching: Vec<[u8; 3]>,
    /// Per face and local edge: the edge is on the cut graph (charts of the
    /// two faces are independent there).
    pub seam: Vec<[bool; 3]>,
    /// Per face corner: its wedge (corners with equal wedge share (u, v)).
    pub wedge: Vec<[u32; 3]>,
    pub(crate) topology: EdgeTopology,
}

impl Parametrization {
    /// The transition from face `f`'s chart to the chart of the face across
    /// its local edge `e` (None on the boundary): exact for non-seam
    /// edges (identity), fitted from the edge's end points on seams.
    pub fn transition(&self, f: usize, e: usize) -> Option<Transition> {
        let g = self.topology.opposite[f][e];
        if g == u32::MAX {
            return None;
        }
        if !self.seam[f][e] {
            return Some(Transition::IDENTITY);
        }
        let (g, ge) = (g as usize, self.topology.opposite_edge[f][e] as usize);
        let k = self.matching[f][e];
        // Edge corner i → i+1 in f is corner ge+1 → ge in g.
        let (fa, fb) = (self.uv[f][e], self.uv[f][(e + 1) % 3]);
        let (ga, gb) = (self.uv[g][(ge + 1) % 3], self.uv[g][ge]);
        let t = 0.5 * ((ga - rotate(k, fa)) + (gb - rotate(k, fb)));
        Some(Transition { k, t })
    }

    /// (u, v) at a point of face `f` on its edge {a, b} given as the mesh
    /// vertices and the parameter t from a to b.
    pub fn uv_on_edge(&self, mesh: &TriMesh, f: usize, a: u32, b: u32, t: f64) -> Option<DVec2> {
        let tri = mesh.triangles[f];
        let ia = tri.iter().position(|&x| x == a)?;
        let ib = tri.iter().position(|&x| x == b)?;
        Some(self.uv[f][ia].lerp(self.uv[f][ib], t))
    }
}

impl Parametrization {
    /// Which coordinate (0: u, 1: v) is transversal to direction `d` in
    /// face `f`: the one whose frame axis is more orthogonal to `d`.
    pub fn transversal(&self, f: usize, d: DVec3) -> usize {
        if d.dot(self.frames[f][0]).abs() >= d.dot(self.frames[f][1]).abs() {
            1
        } else {
            0
        }
    }

    /// The loop in one chart: per face of the loop the transition from its
    /// chart into the chart of the loop's first face, (u, v) of every
    /// crossing carried into that chart (for a closed loop the first
    /// crossing is repeated at the end, after going round), and the
    /// transversal coordinate there. None for an empty loop or a broken
    /// walk.
    pub fn loop_chart(&self, mesh: &TriMesh, l: &EmbeddedLoop) -> Option<LoopChart> {
        let &f0 = l.faces.first()?;
        let c0 = *l.crossings.first()?;
        let c1 = *l.crossings.get(1 % l.crossings.len())?;
        let comp = self.transversal(f0 as usize, c1.point(mesh) - c0.point(mesh));
        let mut to_ref = Transition::IDENTITY;
        let mut chart = LoopChart {
            to_ref: Vec::with_capacity(l.faces.len()),
            values: Vec::with_capacity(l.faces.len() + 1),
            comp,
        };
        for (i, (f, a, b)) in l.segments().enumerate() {
            let f = f as usize;
            chart.to_ref.push(to_ref);
            chart
                .values
                .push(to_ref.apply(self.uv_on_edge(mesh, f, a.a, a.b, a.t)?));
            if i + 1 == l.faces.len() {
                chart
                    .values
                    .push(to_ref.apply(self.uv_on_edge(mesh, f, b.a, b.b, b.t)?));
                break;
            }
            let t = mesh.triangles[f];
            let e = (0..3).find(|&e| {
                let (x, y) = (t[e], t[(e + 1) % 3]);
                (x.min(y), x.max(y)) == (b.a, b.b)
            })?;
            to_ref = to_ref.after(&self.transition(f, e)?.inverse());
        }
        Some(chart)
    }
}

/// A loop carried into one chart, see [`Parametrization::loop_chart`].
#[derive(Debug, Clone, PartialEq)]
pub struct LoopChart {
    /// Per face of the loop: its chart → the reference chart.
    pub to_ref: Vec<Transition>,
    /// (u, v) of the crossings in the reference chart.
    pub values: Vec<DVec2>,
    /// The transversal coordinate (0: u, 1: v) in the reference chart.
    pub comp: usize,
}

/// The §6.1 parametrization for `field` (from [`super::strip_field`]) and
/// the loops it was built from; None if the solve fails. Loops that are
/// not valid walks on `mesh` are ignored.
pub fn parametrize(
    mesh: &TriMesh,
    field: &StripField,
    loops: &[EmbeddedLoop],
) -> Option<Parametrization> {
    let valid: Vec<EmbeddedLoop> = loops
        .iter()
        .filter(|l| l.check(mesh).is_ok())
        .cloned()
        .collect();
    parametrize_with(mesh, EdgeTopology::new(mesh), field, &valid)
}

// Parallel per-face arrays read best indexed.
#[allow(clippy::needless_range_loop)]
pub(crate) fn parametrize_with(
    mesh: &TriMesh,
    topology: EdgeTopology,
    field: &StripField,
    loops: &[EmbeddedLoop],
) -> Option<Parametrization> {
    let nf = mesh.triangles.len();
    if field.cross.len() != nf {
        return None;
    }
    let base = face_frames(mesh);
    let mut frames: Vec<[DVec3; 2]> = (0..nf)
        .map(|f| {
            let u = if field.cross[f] == DVec3::ZERO {
                base[f][0]
            } else {
                field.cross[f]
            };
            [u, base[f][2].cross(u)]
        })
        .collect();
    let edge_vector = |f: usize, e: usize| {
        let t = mesh.triangles[f];
        mesh.positions[t[(e + 1) % 3] as usize] - mesh.positions[t[e] as usize]
    };
    let angle = |fr: &[DVec3; 2], d: DVec3| d.dot(fr[1]).atan2(d.dot(fr[0]));
    // Matchings of the uncombed frames, then the shared combing, cut
    // graph and wedges.
    let mut raw = vec![[0u8; 3]; nf];
    for f in 0..nf {
        for e in 0..3 {
            if let Some((g, _)) = topology.across(f, e) {
                let d = edge_vector(f, e);
                let k = ((angle(&frames[f], d) - angle(&frames[g], d)) / FRAC_PI_2).round() as i64;
                raw[f][e] = k.rem_euclid(4) as u8;
            }
        }
    }
    let nv = mesh.positions.len();
    let mut anchored = vec![false; nv];
    for s in &field.singularities {
        if let Some(a) = anchored.get_mut(s.vertex as usize) {
            *a = true;
        }
    }
    let c = cut(&CutInput {
        triangles: &mesh.triangles,
        vertex_count: nv,
        topology: &topology,
        raw_matching: &raw,
        anchored: &anchored,
    });
    for (f, fr) in frames.iter_mut().enumerate() {
        for _ in 0..c.comb[f] {
            *fr = [fr[1], -fr[0]];
        }
    }
    let (matching, seam, wedge, count) = (c.matching, c.seam, c.wedge, c.wedge_count as u32);
    let n = 2 * count as usize;
    let var = |f: usize, i: usize, comp: usize| 2 * wedge[f][i] as usize + comp;
    let mut normal = Normal::new(n);
    // Area-weighted alignment of the gradients with the frames, with the
    // rows scaled so that area-normalized coefficients are O(1).
    for f in 0..nf {
        let c = mesh.corners(f);
        let nrm = mesh.face_normal_unnormalized(f);
        let area2 = nrm.length();
        if area2 <= 1e-300 || field.cross[f] == DVec3::ZERO {
            continue;
        }
        let nrm = nrm / area2;
        let grad: [DVec3; 3] =
            std::array::from_fn(|i| nrm.cross(c[(i + 2) % 3] - c[(i + 1) % 3]) / area2);
        let w = (0.5 * area2).sqrt();
        for comp in 0..2 {
            for (axis, frame_axis) in frames[f].iter().enumerate() {
                let entries: Vec<(usize, f64)> = (0..3)
                    .map(|i| (var(f, i, comp), grad[i].dot(*frame_axis)))
                    .collect();
                normal.row(w, &entries, if axis == comp { 1.0 } else { 0.0 });
            }
        }
    }
    // Seams: ΔX_g = rotate(k, ΔX_f), scaled by the mean edge length.
    let mean_edge = {
        let s: f64 = (0..nf).map(|f| edge_vector(f, 0).length()).sum();
        (s / nf.max(1) as f64).max(1e-300)
    };
    for f in 0..nf {
        for e in 0..3 {
            let g = topology.opposite[f][e];
            if !seam[f][e] || (g as usize) < f {
                continue;
            }
            let (g, ge) = (g as usize, topology.opposite_edge[f][e] as usize);
            let k = matching[f][e];
            // rotate(k, ·) as a signed component map: out[c] = sign · in[src].
            let (src, sign): ([usize; 2], [f64; 2]) = match k {
                0 => ([0, 1], [1.0, 1.0]),
                1 => ([1, 0], [1.0, -1.0]),
                2 => ([0, 1], [-1.0, -1.0]),
                _ => ([1, 0], [-1.0, 1.0]),
            };
            for c in 0..2 {
                let entries = [
                    (var(g, ge, c), 1.0),
                    (var(g, (ge + 1) % 3, c), -1.0),
                    (var(f, (e + 1) % 3, src[c]), -sign[c]),
                    (var(f, e, src[c]), sign[c]),
                ];
                normal.row(HARD / mean_edge, &entries, 0.0);
            }
        }
    }
    loop_rows(mesh, loops, &frames, &wedge, &mut normal, mean_edge);
    // The gauge term; raised when the factorization fails (near-singular
    // systems on small or irregular meshes).
    let x = [1e-8, 1e-6, 1e-4].iter().find_map(|&relative| {
        let eps = relative / (mean_edge * mean_edge);
        let mut triplets = normal.triplets.clone();
        triplets.extend((0..n).map(|i| (i, i, eps)));
        solve_spd(n, &triplets, std::slice::from_ref(&normal.rhs))?.pop()
    })?;
    let uv: Vec<[DVec2; 3]> = (0..nf)
        .map(|f| std::array::from_fn(|i| DVec2::new(x[var(f, i, 0)], x[var(f, i, 1)])))
        .collect();
    let folded = uv
        .iter()
        .map(|q| (q[1] - q[0]).perp_dot(q[2] - q[0]) <= 0.0)
        .collect();
    Some(Parametrization {
        uv,
        folded,
        frames,
        matching,
        seam,
        wedge,
        topology,
    })
}

/// Loops are isolines: in each crossed face the transversal coordinate is
/// equal at the entry and the exit crossing (hard rows of [`parametrize_with`]).
fn loop_rows(
    mesh: &TriMesh,
    loops: &[EmbeddedLoop],
    frames: &[[DVec3; 2]],
    wedge: &[[u32; 3]],
    normal: &mut Normal,
    mean_edge: f64,
) {
    let var = |f: usize, i: usize, comp: usize| 2 * wedge[f][i] as usize + comp;
    for l in loops {
        for (f, c0, c1) in l.segments() {
            let f = f as usize;
            let Some(t) = mesh.triangles.get(f) else {
                continue;
            };
            let d = c1.point(mesh) - c0.point(mesh);
            let comp = if d.dot(frames[f][0]).abs() >= d.dot(frames[f][1]).abs() {
                1
            } else {
                0
            };
            let mut entries = Vec::with_capacity(4);
            for (c, sign) in [(c0, 1.0), (c1, -1.0)] {
                let (Some(ia), Some(ib)) = (
                    t.iter().position(|&x| x == c.a),
                    t.iter().position(|&x| x == c.b),
                ) else {
                    continue;
                };
                entries.push((var(f, ia, comp), sign * (1.0 - c.t)));
                entries.push((var(f, ib, comp), sign * c.t));
            }
            if entries.len() == 4 {
                normal.row(HARD / mean_edge, &entries, 0.0);
            }
        }
    }
}
