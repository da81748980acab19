//! Quality of an integer-grid map: flipped triangles, seam consistency and
//! Campen et al. 2016 §5's measures (`../shared/seeds/001_…`): stretch
//! (mean relative deviation of |∇u|, |∇v| from the target 1/S(f)), shear
//! (mean deviation of the angle between ∇u and ∇v from 90°),
//! misalignment (mean angle between the gradients and the principal
//! directions, (κ_min − κ_max)²-weighted), singularities (cones); and how
//! much of the anisotropy asked (`super::anisotropy`) the map realises.
//! Means are area-weighted; the parametrization-curvature measure is not
//! computed.

use glam::DVec3;
use serde::Serialize;

use super::seamless::GridMap;
use crate::analysis::smooth_regions::FaceCurvature;
use crate::mesh::TriMesh;

#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Measures {
    pub faces: usize,
    /// Faces whose parametric area is not positive ([`GridMap::flipped`]).
    pub flipped_triangles: usize,
    /// Of those, the ones whose parametric area is zero to 1e-12 (all
    /// three corners on one line or two at one point, e.g. a boundary loop
    /// collapsed by its isoline constraints) rather than negative.
    pub degenerate_triangles: usize,
    pub cones: usize,
    pub cones_by_quarters: Vec<(i32, usize)>,
    pub cone_index_sum: f64,
    /// Largest disagreement of a cut edge's two end points' translations.
    pub seam_mismatch: f64,
    /// Largest distance of a translation component from an integer.
    pub translation_integrality: f64,
    pub stretch: f64,
    pub shear_degrees: f64,
    pub misalignment_degrees: f64,
    /// Over the faces with anisotropic target lengths
    /// ([`super::anisotropy`]), area-weighted: the ratio asked of the
    /// edges across and along a (the geometric mean of p/q), and the
    /// fraction of its logarithm the map realises, ln(|J a| / |J b|) /
    /// ln(p/q) with J the map's Jacobian (1: as asked; 0: isotropic, e.g.
    /// a cross at 45° to a). Both 0 without.
    pub anisotropy_asked: f64,
    pub anisotropy_realised: f64,
    pub cut_edges: usize,
    pub wedges: usize,
}

/// Parametric gradients of u and v in face f (world vectors).
pub fn gradients(mesh: &TriMesh, map: &GridMap, f: usize) -> Option<[DVec3; 2]> {
    let p = mesh.corners(f);
    let nrm = mesh.face_normal_unnormalized(f);
    let a2 = nrm.length();
    if a2 <= 1e-300 {
        return None;
    }
    let n = nrm / a2;
    let mut g = [DVec3::ZERO; 2];
    for i in 0..3 {
        let grad = n.cross(p[(i + 2) % 3] - p[(i + 1) % 3]) / a2;
        g[0] += grad * map.uv[f][i].x;
        g[1] += grad * map.uv[f][i].y;
    }
    Some(g)
}

fn seam_figures(mesh: &TriMesh, map: &GridMap) -> (f64, f64, usize) {
    let (mut mismatch, mut integrality, mut cut) = (0.0f64, 0.0f64, 0);
    for f in 0..mesh.face_count() {
        for e in 0..3 {
            if let Some((tr, d)) = map.transition(f, e) {
                mismatch = mismatch.max(d.length());
                integrality = integrality
                    .max((tr.t.x - tr.t.x.round()).abs())
                    .max((tr.t.y - tr.t.y.round()).abs());
                cut += usize::from(map.cut.seam[f][e]);
            }
        }
    }
    (mismatch, integrality, cut / 2)
}

fn angle_to_axes(g: DVec3, c: &FaceCurvature) -> f64 {
    let a = g
        .dot(c.a_max)
        .abs()
        .atan2(g.dot(c.a_min).abs())
        .to_degrees();
    a.min(90.0 - a)
}

/// All measures; `face_sizing` is S(f), `curvature` the per-face principal
/// curvatures (for the misalignment).
pub fn measures(
    mesh: &TriMesh,
    map: &GridMap,
    face_sizing: &[f64],
    curvature: &[FaceCurvature],
    anisotropy: &[Option<super::anisotropy::AxisLengths>],
) -> Measures {
    let (mut area, mut stretch, mut shear) = (0.0, 0.0, 0.0);
    let (mut aniso_area, mut asked, mut realised) = (0.0, 0.0, 0.0);
    let (mut weight, mut misalignment) = (0.0, 0.0);
    for f in 0..mesh.face_count() {
        let Some(g) = gradients(mesh, map, f) else {
            continue;
        };
        let a = mesh.face_area(f);
        let s = face_sizing.get(f).copied().unwrap_or(1.0);
        area += a;
        stretch += a * 0.5 * ((g[0].length() * s - 1.0).abs() + (g[1].length() * s - 1.0).abs());
        let angle = g[0].angle_between(g[1]).to_degrees();
        if angle.is_finite() {
            shear += a * (angle - 90.0).abs();
        }
        if let Some(l) = anisotropy.get(f).copied().flatten() {
            let n = g[0].cross(g[1]).normalize_or_zero();
            let b = n.cross(l.a);
            let jacobian = |d: DVec3| (g[0].dot(d).powi(2) + g[1].dot(d).powi(2)).sqrt();
            let (want, got) = (
                (l.along / l.across).ln(),
                (jacobian(l.a) / jacobian(b)).ln(),
            );
            if want.abs() > 1e-9 && got.is_finite() {
                aniso_area += a;
                asked += a * want;
                realised += a * got / want;
            }
        }
        if let Some(c) = curvature.get(f) {
            let w = a * (c.kappa_min - c.kappa_max).powi(2);
            let m = 0.5 * (angle_to_axes(g[0], c) + angle_to_axes(g[1], c));
            if w.is_finite() && m.is_finite() {
                weight += w;
                misalignment += w * m;
            }
        }
    }
    let mean = |x: f64, w: f64| if w > 0.0 { x / w } else { 0.0 };
    let mut by: Vec<(i32, usize)> = Vec::new();
    for c in &map.cones {
        match by.iter_mut().find(|b| b.0 == c.quarters) {
            Some(b) => b.1 += 1,
            None => by.push((c.quarters, 1)),
        }
    }
    by.sort_unstable();
    let (seam_mismatch, translation_integrality, cut_edges) = seam_figures(mesh, map);
    Measures {
        faces: mesh.face_count(),
        flipped_triangles: map.flipped().iter().filter(|&&x| x).count(),
        degenerate_triangles: map
            .uv
            .iter()
            .map(|q| (q[1] - q[0]).perp_dot(q[2] - q[0]))
            .filter(|a| (-1e-12..=0.0).contains(a))
            .count(),
        cones: map.cones.len(),
        cones_by_quarters: by,
        cone_index_sum: map.cones.iter().map(|c| c.index()).sum(),
        seam_mismatch,
        translation_integrality,
        stretch: mean(stretch, area),
        shear_degrees: mean(shear, area),
        misalignment_degrees: mean(misalignment, weight),
        anisotropy_asked: if aniso_area > 0.0 {
            (asked / aniso_area).exp()
        } else {
            0.0
        },
        anisotropy_realised: mean(realised, aniso_area),
        cut_edges,
        wedges: map.cut.wedge_count,
    }
}
