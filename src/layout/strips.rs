//! Dual strips of Campen & Kobbelt 2014, *Dual Strip Weaving*, §6 and §6.2:
//! each loop's strip is the continuum of isocurves of the global map S
//! ([`super::parametrization`]) next to it, grown to both sides until a
//! singularity of S (or a fold) is met; the strip's isocurve directions
//! disable elastica nodes for the next loops (§6.2, [`StripAnalysis::covered`]
//! for `LoopEngine::set_covered`). [`strip_analysis`] runs the whole of §6
//! (field, parametrization, strips) for a set of embedded loops.
//!
//! Deviations: the strip is grown face by face (Dijkstra order of the
//! distance |w| of a face's nearest corner from the loop's isoline, w the
//! transversal coordinate relative to the loop, carried through the chart
//! transitions); on each side it stops at the first face that is folded or
//! touches a singular vertex; the side's bound is the isoline |w| through
//! the singular vertex (for a fold: the folded face's nearest corner), and
//! faces touching singular vertices or folded are left out.
//! A face belongs to one sheet of the strip only (the one reached first),
//! so a strip wrapping around a handle is not doubly covered.

use std::cmp::Ordering;
use std::collections::BinaryHeap;

use glam::{DVec2, DVec3};

use super::embed::{EdgeTopology, EmbeddedLoop, Singularity};
use super::parametrization::{Parametrization, Transition, parametrize_with};
use super::strip_field::strip_field_with;
use crate::mesh::TriMesh;
use crate::progress::{Cancelled, Progress};

/// One loop's strip.
#[derive(Debug, Clone, PartialEq)]
pub struct Strip {
    /// The loop it was grown from (index into the loops given).
    pub loop_index: usize,
    /// Its faces.
    pub faces: Vec<u32>,
    /// Per face (parallel to `faces`), per corner: the transversal
    /// coordinate w relative to the loop (0 on the loop, world units).
    pub coordinate: Vec<[f64; 3]>,
    /// Extent on the side of negative w (a positive distance).
    pub left: f64,
    /// Extent on the side of positive w.
    pub right: f64,
    /// Per face: the gradient of w (world), for the isocurve direction.
    pub gradient: Vec<DVec3>,
}

impl Strip {
    /// The stripes: isolines w = k·`spacing` inside the strip as segments
    /// (marching triangles), world coordinates.
    pub fn stripe_segments(&self, mesh: &TriMesh, spacing: f64) -> Vec<[DVec3; 2]> {
        let mut out = Vec::new();
        if spacing.is_nan() || spacing <= 0.0 {
            return out;
        }
        for (&f, w) in self.faces.iter().zip(&self.coordinate) {
            let p = mesh.corners(f as usize);
            let lo = w.iter().copied().fold(f64::MAX, f64::min).max(-self.left);
            let hi = w.iter().copied().fold(f64::MIN, f64::max).min(self.right);
            let (k0, k1) = ((lo / spacing).ceil() as i64, (hi / spacing).floor() as i64);
            for k in k0..=k1.min(k0 + 1000) {
                let level = k as f64 * spacing;
                let above = w.map(|x| x >= level);
                let mut ends = Vec::with_capacity(2);
                for i in 0..3 {
                    let j = (i + 1) % 3;
                    if above[i] != above[j] {
                        let s = (level - w[i]) / (w[j] - w[i]);
                        ends.push(p[i].lerp(p[j], s));
                    }
                }
                if let [a, b] = ends[..] {
                    out.push([a, b]);
                }
            }
        }
        out
    }
}

/// Parameters of [`strip_analysis`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StripParams {
    /// Stripe spacing relative to the bounding-box diagonal (default 0.01).
    pub spacing: f64,
}

impl Default for StripParams {
    fn default() -> Self {
        StripParams { spacing: 0.01 }
    }
}

/// Everything §6 derives from the committed loops.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct StripAnalysis {
    /// Per face: an arm of the cross (world unit vector), zero where
    /// undefined (no loops, or no loop in that component).
    pub cross: Vec<DVec3>,
    pub singularities: Vec<Singularity>,
    /// Per face corner: (u, v) of S in the face's chart (empty without loops).
    pub uv: Vec<[DVec2; 3]>,
    /// Per face: S folds there (empty without loops).
    pub folded: Vec<bool>,
    /// One per loop that could be grown.
    pub strips: Vec<Strip>,
    /// Per vertex: the isocurve tangent (world) of the first strip covering
    /// it (§6.2), for `LoopEngine::set_covered`.
    pub covered: Vec<Vec<DVec3>>,
    /// Stripe spacing in world units.
    pub spacing: f64,
    /// Why something is missing (a failed solve, a loop that was skipped).
    pub notes: Vec<String>,
    pub field_ms: f64,
    pub parametrization_ms: f64,
    pub strips_ms: f64,
}

/// Milliseconds from an arbitrary origin (`std::time::Instant` panics on
/// wasm32).
fn now_ms() -> f64 {
    #[cfg(target_arch = "wasm32")]
    {
        js_sys::Date::now()
    }
    #[cfg(not(target_arch = "wasm32"))]
    {
        static START: std::sync::OnceLock<std::time::Instant> = std::sync::OnceLock::new();
        START
            .get_or_init(std::time::Instant::now)
            .elapsed()
            .as_secs_f64()
            * 1e3
    }
}

/// §6 for `loops` on `mesh`: the cross field, the parametrization, the
/// strips and the covered directions (see [`StripAnalysis`]).
pub fn strip_analysis(
    mesh: &TriMesh,
    loops: &[EmbeddedLoop],
    params: &StripParams,
) -> StripAnalysis {
    // A sink that never cancels: never `Cancelled`.
    crate::progress::silently("strips", |p| strip_analysis_with(mesh, loops, params, p))
        .unwrap_or_default()
}

/// [`strip_analysis`], reporting to `progress` between its steps (the
/// cross field, the parametrization, each strip) and stopping at once when
/// the sink cancels (the design mode's analysis when a newer action made
/// it stale). The solves themselves run to their end.
pub fn strip_analysis_with(
    mesh: &TriMesh,
    loops: &[EmbeddedLoop],
    params: &StripParams,
    progress: &mut Progress<'_>,
) -> Result<StripAnalysis, Cancelled> {
    let nv = mesh.positions.len();
    let mut out = StripAnalysis {
        cross: vec![DVec3::ZERO; mesh.triangles.len()],
        covered: vec![Vec::new(); nv],
        spacing: params.spacing * mesh.bbox().map_or(0.0, |b| b.diagonal()),
        ..StripAnalysis::default()
    };
    let start = now_ms();
    let topology = EdgeTopology::new(mesh);
    let valid: Vec<EmbeddedLoop> = loops
        .iter()
        .enumerate()
        .filter_map(|(i, l)| match l.check(mesh) {
            Ok(()) => Some(l.clone()),
            Err(e) => {
                out.notes.push(format!("loop {i} skipped: {e}"));
                None
            }
        })
        .collect();
    progress.report(0.0, "cross field")?;
    let Some(field) = strip_field_with(mesh, &topology, &valid) else {
        out.field_ms = now_ms() - start;
        if !valid.is_empty() {
            out.notes.push("no cross field (the solve failed)".into());
        }
        return Ok(out);
    };
    out.cross = field.cross.clone();
    out.singularities = field.singularities.clone();
    let t1 = now_ms();
    out.field_ms = t1 - start;
    progress.report(0.3, "parametrization")?;
    let Some(param) = parametrize_with(mesh, topology, &field, &valid) else {
        out.parametrization_ms = now_ms() - t1;
        out.notes
            .push("no parametrization (the solve failed)".into());
        return Ok(out);
    };
    let t2 = now_ms();
    out.parametrization_ms = t2 - t1;
    let mut singular = vec![false; nv];
    for s in &field.singularities {
        singular[s.vertex as usize] = true;
    }
    // Map back to the caller's loop indices.
    let indices: Vec<usize> = (0..loops.len())
        .filter(|&i| loops[i].check(mesh).is_ok())
        .collect();
    for (j, l) in valid.iter().enumerate() {
        progress.report(0.7 + 0.3 * j as f32 / valid.len() as f32, "strips")?;
        match grow_strip(mesh, &param, &singular, l) {
            Some(mut s) => {
                s.loop_index = indices[j];
                out.strips.push(s);
            }
            None => out
                .notes
                .push(format!("loop {}: no strip (broken chart walk)", indices[j])),
        }
    }
    out.covered = covered_directions(mesh, &out.strips);
    out.uv = param.uv;
    out.folded = param.folded;
    out.strips_ms = now_ms() - t2;
    Ok(out)
}

#[derive(Debug, PartialEq)]
struct Item {
    key: f64,
    face: u32,
    to_ref: Transition,
}

impl Eq for Item {}

impl Ord for Item {
    fn cmp(&self, other: &Self) -> Ordering {
        other
            .key
            .total_cmp(&self.key)
            .then(other.face.cmp(&self.face))
    }
}

impl PartialOrd for Item {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

/// Grows the strip of loop `l` (see the module docs).
pub fn grow_strip(
    mesh: &TriMesh,
    param: &Parametrization,
    singular: &[bool],
    l: &EmbeddedLoop,
) -> Option<Strip> {
    let chart = param.loop_chart(mesh, l)?;
    let comp = chart.comp;
    let level = chart.values.iter().map(|x| x[comp]).sum::<f64>() / chart.values.len() as f64;
    let nf = mesh.triangles.len();
    // w at the corners of face f given its transition into the reference chart.
    let corner_w = |f: usize, tr: &Transition| param.uv[f].map(|x| tr.apply(x)[comp] - level);
    let mut is_loop_face = vec![false; nf];
    let mut heap = BinaryHeap::new();
    for (&f, tr) in l.faces.iter().zip(&chart.to_ref) {
        is_loop_face[f as usize] = true;
        heap.push(Item {
            key: 0.0,
            face: f,
            to_ref: *tr,
        });
    }
    let mut done = vec![false; nf];
    let (mut left, mut right): (Option<f64>, Option<f64>) = (None, None);
    let (mut reach_left, mut reach_right) = (0.0f64, 0.0f64);
    let mut strip = Strip {
        loop_index: 0,
        faces: Vec::new(),
        coordinate: Vec::new(),
        left: 0.0,
        right: 0.0,
        gradient: Vec::new(),
    };
    while let Some(Item { key, face, to_ref }) = heap.pop() {
        let f = face as usize;
        if done[f] {
            continue;
        }
        let w = corner_w(f, &to_ref);
        let centre = (w[0] + w[1] + w[2]) / 3.0;
        let bound = if centre >= 0.0 { right } else { left };
        if bound.is_some_and(|b| key >= b) {
            continue;
        }
        done[f] = true;
        // A singularity bounds the strip by the isoline through it, a fold
        // by the face's nearest corner.
        let tri = mesh.triangles[f];
        let at_singularity = (0..3)
            .filter(|&i| singular[tri[i] as usize])
            .map(|i| w[i].abs())
            .reduce(f64::min);
        if (param.folded[f] || at_singularity.is_some()) && !is_loop_face[f] {
            let b = at_singularity.unwrap_or(key).max(key);
            let side = if centre >= 0.0 { &mut right } else { &mut left };
            *side = Some(side.map_or(b, |s: f64| s.min(b)));
            continue;
        }
        strip.faces.push(face);
        strip.coordinate.push(w);
        strip.gradient.push(gradient(mesh, f, &w));
        for x in w {
            reach_right = reach_right.max(x);
            reach_left = reach_left.max(-x);
        }
        for e in 0..3 {
            let g = param.topology.opposite[f][e];
            if g == u32::MAX || done[g as usize] {
                continue;
            }
            let Some(tr) = param.transition(f, e) else {
                continue;
            };
            let to_ref = to_ref.after(&tr.inverse());
            let wg = corner_w(g as usize, &to_ref);
            let key = wg.iter().map(|x| x.abs()).fold(f64::MAX, f64::min);
            heap.push(Item {
                key,
                face: g,
                to_ref,
            });
        }
    }
    strip.left = left.unwrap_or(reach_left);
    strip.right = right.unwrap_or(reach_right);
    Some(strip)
}

/// World gradient of the linear function with values `w` at the corners.
fn gradient(mesh: &TriMesh, f: usize, w: &[f64; 3]) -> DVec3 {
    let c = mesh.corners(f);
    let n = mesh.face_normal_unnormalized(f);
    let area2 = n.length_squared();
    if area2 <= 1e-300 {
        return DVec3::ZERO;
    }
    // ∇φ_i = n × (c_{i+2} − c_{i+1}) / |n|².
    (0..3)
        .map(|i| w[i] * n.cross(c[(i + 2) % 3] - c[(i + 1) % 3]))
        .sum::<DVec3>()
        / area2
}

/// §6.2: per vertex the isocurve tangent (n × ∇w, averaged over the
/// vertex's faces in the strip) of every strip covering it (overlapping
/// strips each keep their own constraint).
fn covered_directions(mesh: &TriMesh, strips: &[Strip]) -> Vec<Vec<DVec3>> {
    let nv = mesh.positions.len();
    let mut out = vec![Vec::new(); nv];
    for s in strips {
        let mut sum = vec![DVec3::ZERO; nv];
        for (&f, g) in s.faces.iter().zip(&s.gradient) {
            let n = mesh
                .face_normal_unnormalized(f as usize)
                .normalize_or_zero();
            let t = n.cross(*g);
            for &v in &mesh.triangles[f as usize] {
                sum[v as usize] += t;
            }
        }
        for v in 0..nv {
            if sum[v].length_squared() > 0.0 {
                out[v].push(sum[v].normalize());
            }
        }
    }
    out
}
