//! A lattice spacing consistent with the cross field (integrability of the
//! scaled frame): the position field's grid closes without position
//! singularities only where the spacing follows the field's turning.
//!
//! Facts used (Ray et al. 2006, *Periodic global parameterization*, the
//! curl of the guidance field; Bommes et al. 2009, §4; QuadriFlow's
//! "adaptive scale", Huang et al. 2018, summarised in
//! `../shared/reference/instant-meshes-digest.md` §7.3, which makes its
//! per-vertex scale follow the field the same way): a quad grid of spacing
//! `s` whose lines follow the unit cross `u`, `v = n × u` is the level set of
//! a map `f` with `∇f₁ = u/s`, `∇f₂ = v/s`. Both are gradients only if their
//! curl vanishes; with `u = (cos θ, sin θ)` in a local frame that is
//!
//! ```text
//! ∇ log s = −J ∇θ        (J: the quarter turn n ×),
//! ```
//!
//! i.e. `log s` is the harmonic conjugate of the field angle. A polar grid
//! (radial field, `θ` = polar angle) gets `s ∝ r`, the conformal polar net.
//! A spacing that ignores this — the uniform one of Instant Meshes, or the
//! curvature-adaptive one of Kloiber 2018 — leaves a curl that the local
//! position optimisation can only absorb as position singularities, which
//! become valence 3/5 pairs and odd faces in the extracted mesh.
//!
//! On a curved surface the condition has no exact solution (Gaussian
//! curvature and the cones are sources of the curl), so the spacing is the
//! least-squares compromise between following the field and keeping the
//! target spacing `s⁰` of the sizing field:
//!
//! ```text
//! min_φ  Σ_f A_f |∇φ − g_f|² + Σ_i A_i / (c s⁰_i)² (φ_i − log s⁰_i)²,   g_f = −J ∇θ_f,
//! ```
//!
//! `φ = log s` piecewise linear, `∇θ_f` from the three crosses of a
//! non-singular triangle turned to a common representative and measured in
//! the triangle's plane. `c` (the healing length in target edges) is how far
//! the spacing may drift from the target before the data term pulls it
//! back. The field's demand `|g_f|` is capped at 0.25 per target edge
//! ([`MAX_GROWTH_PER_EDGE`]: a graded spacing, as near cones it is
//! unbounded), the ratio `s / s⁰` is clamped to `[1/3, 3]` (QuadriFlow's clamp),
//! and the result is rescaled so that `Σ A_i / s_i²` (the vertex count a
//! quad mesh of that spacing has) equals that of `s⁰`.

use glam::{DVec3, Vec3};

use super::hierarchy::Level;
use super::singularities::{orientation_index, turned_to};
use crate::param::solve::{NormalEquations, solve_spd};

/// The largest factor between the consistent spacing and the target.
pub const MAX_RATIO: f64 = 3.0;

/// The steepest change of `log s` the field may ask for, per target edge:
/// neighbouring lattices one edge apart then differ by at most ~25 %, half
/// the ±½-cell tolerance within which the position field rounds a
/// neighbour's lattice point to its own. Near a cone `∇θ` grows like
/// 1/r and would ask for more. Measured on the defaults (medians over 5
/// vertex orders), unbounded → 0.25: odd faces suzanne 12.9 → 7.1 %, EV %
/// suzanne 58.6 → 48.3, cow 30.8 → 26.1, beetle 60.6 → 56.5, spot 27.5 →
/// 26.2; corner deviation beetle 22.9 → 18.4°, cow 16.1 → 15.0°; the
/// cow's Hausdorff distance rose 0.122 → 0.166. 0.5 and 1 per edge left
/// suzanne at 7.7 and 13.8 % odd faces.
pub const MAX_GROWTH_PER_EDGE: f64 = 0.25;

/// The spacing `s` on `level` (level 0, with its `triangles`) that follows
/// the cross field `q` within a healing length of `healing_edges` × `s⁰`
/// of the target spacing `scale` (see the module comment). `None` when the
/// least-squares system could not be solved (the caller keeps `s⁰`).
pub fn consistent_scale(
    level: &Level,
    triangles: &[[u32; 3]],
    q: &[Vec3],
    scale: &[f32],
    healing_edges: f64,
) -> Option<Vec<f32>> {
    let n = level.len();
    if n == 0 || healing_edges <= 0.0 || !healing_edges.is_finite() {
        return None;
    }
    let phi0: Vec<f64> = scale.iter().map(|&s| (s.max(1e-30) as f64).ln()).collect();
    let mut eq = NormalEquations::new(n);
    for &t in triangles {
        if orientation_index(level, q, t) != 0 {
            continue;
        }
        let Some(mut face) = FaceGradient::new(level, q, t) else {
            continue;
        };
        // Graded: at most MAX_GROWTH_PER_EDGE of log-spacing per target edge.
        let s_face = t.iter().map(|&i| scale[i as usize] as f64).sum::<f64>() / 3.0;
        let per_edge = face.g.length() * s_face;
        if per_edge > MAX_GROWTH_PER_EDGE {
            face.g *= MAX_GROWTH_PER_EDGE / per_edge;
        }
        let w = face.area.sqrt();
        for axis in [face.e1, face.e2] {
            let entries: Vec<(usize, f64)> = (0..3)
                .map(|k| (t[k] as usize, face.grad_b[k].dot(axis)))
                .collect();
            eq.row(w, &entries, face.g.dot(axis));
        }
    }
    for i in 0..n {
        let s0 = scale[i].max(1e-30) as f64;
        let w = (level.areas[i].max(1e-30) as f64).sqrt() / (healing_edges * s0);
        eq.row(w, &[(i, 1.0)], phi0[i]);
    }
    let phi = solve_spd(n, &eq.triplets, std::slice::from_ref(&eq.rhs))?.pop()?;
    let bound = MAX_RATIO.ln();
    let mut phi: Vec<f64> = phi
        .iter()
        .zip(&phi0)
        .map(|(&p, &p0)| p0 + (p - p0).clamp(-bound, bound))
        .collect();
    // Keep the vertex count: Σ A e^{−2φ} = Σ A e^{−2φ⁰}.
    let density = |phi: &[f64]| -> f64 {
        phi.iter()
            .zip(&level.areas)
            .map(|(&p, &a)| a as f64 * (-2.0 * p).exp())
            .sum()
    };
    let shift = 0.5 * (density(&phi) / density(&phi0)).ln();
    if !shift.is_finite() {
        return None;
    }
    for p in &mut phi {
        *p += shift;
    }
    Some(phi.iter().map(|&p| p.exp() as f32).collect())
}

/// One triangle's plane frame, the gradients of its hat functions and the
/// consistent log-spacing gradient `g = −J ∇θ`.
struct FaceGradient {
    area: f64,
    e1: DVec3,
    e2: DVec3,
    grad_b: [DVec3; 3],
    g: DVec3,
}

impl FaceGradient {
    fn new(level: &Level, q: &[Vec3], t: [u32; 3]) -> Option<FaceGradient> {
        let [a, b, c] = t.map(|i| i as usize);
        let p = [a, b, c].map(|i| level.positions[i].as_dvec3());
        let cross = (p[1] - p[0]).cross(p[2] - p[0]);
        let twice_area = cross.length();
        if twice_area <= 1e-30 || !twice_area.is_finite() {
            return None;
        }
        let normal = cross / twice_area;
        let e1 = (p[1] - p[0]).normalize();
        let e2 = normal.cross(e1);
        let reps =
            [q[a], turned_to(level, q, a, b), turned_to(level, q, a, c)].map(|r| r.as_dvec3());
        let angle = |r: DVec3| r.dot(e2).atan2(r.dot(e1));
        let theta_a = angle(reps[0]);
        let wrap = |d: f64| {
            (d + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI
        };
        let theta = [
            theta_a,
            theta_a + wrap(angle(reps[1]) - theta_a),
            theta_a + wrap(angle(reps[2]) - theta_a),
        ];
        let grad_b = [
            normal.cross(p[2] - p[1]) / twice_area,
            normal.cross(p[0] - p[2]) / twice_area,
            normal.cross(p[1] - p[0]) / twice_area,
        ];
        let grad_theta: DVec3 = (0..3).map(|k| grad_b[k] * theta[k]).sum();
        Some(FaceGradient {
            area: 0.5 * twice_area,
            e1,
            e2,
            grad_b,
            g: -normal.cross(grad_theta),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::field::lattice::rotate90_by;
    use crate::field::{Hierarchy, mesh_links};
    use crate::progress::silently;

    /// A flat annulus r ∈ [1, 2.5], `rings` × `sectors` vertices, as a
    /// level-0 field level and its triangles.
    fn annulus(rings: usize, sectors: usize) -> (Level, Vec<[u32; 3]>) {
        let mut positions = Vec::new();
        for i in 0..rings {
            let r = 1.0 + 1.5 * i as f32 / (rings - 1) as f32;
            for j in 0..sectors {
                let a = std::f32::consts::TAU * j as f32 / sectors as f32;
                positions.push(Vec3::new(r * a.cos(), r * a.sin(), 0.0));
            }
        }
        let id = |i: usize, j: usize| (i * sectors + j % sectors) as u32;
        let mut triangles = Vec::new();
        for i in 0..rings - 1 {
            for j in 0..sectors {
                triangles.push([id(i, j), id(i, j + 1), id(i + 1, j + 1)]);
                triangles.push([id(i, j), id(i + 1, j + 1), id(i + 1, j)]);
            }
        }
        let n = positions.len();
        let normals = vec![Vec3::Z; n];
        let mut areas = vec![0.0f32; n];
        for t in &triangles {
            let [a, b, c] = t.map(|i| positions[i as usize]);
            let area = 0.5 * (b - a).cross(c - a).length();
            for &i in t {
                areas[i as usize] += area / 3.0;
            }
        }
        let links = mesh_links(n, &triangles);
        let h = silently("test", |p| {
            Hierarchy::build(positions, normals, areas, links, 0, p)
        })
        .unwrap();
        (h.levels.into_iter().next().unwrap(), triangles)
    }

    fn spread(values: impl Iterator<Item = f64>) -> f64 {
        let v: Vec<f64> = values.collect();
        let (lo, hi) = v
            .iter()
            .fold((f64::MAX, f64::MIN), |(l, h), &x| (l.min(x), h.max(x)));
        hi / lo
    }

    #[test]
    fn a_radial_field_on_an_annulus_gets_the_polar_net() {
        let (level, triangles) = annulus(16, 96);
        let uniform = vec![0.1f32; level.len()];
        // Radial crosses, and the same crosses turned by 90° (one 4-RoSy).
        for turn in [0u32, 1] {
            let q: Vec<Vec3> = level
                .positions
                .iter()
                .map(|p| rotate90_by(p.normalize(), Vec3::Z, turn))
                .collect();
            let s = consistent_scale(&level, &triangles, &q, &uniform, 1e4).unwrap();
            // s ∝ r: s / r is constant (exactly, on the continuous annulus).
            let ratio = spread(
                level
                    .positions
                    .iter()
                    .zip(&s)
                    .map(|(p, &s)| (s / p.length()) as f64),
            );
            assert!(ratio < 1.03, "s / r varies by {ratio}");
            // The target-spacing range of r ∈ [1, 2.5] is 2.5.
            let range = spread(s.iter().map(|&x| x as f64));
            assert!((range - 2.5).abs() < 0.08, "s range {range}");
            // The vertex count Σ A / s² is kept.
            let count = |s: &[f32]| -> f64 {
                s.iter()
                    .zip(&level.areas)
                    .map(|(&s, &a)| a as f64 / (s as f64).powi(2))
                    .sum()
            };
            assert!((count(&s) / count(&uniform) - 1.0).abs() < 1e-6);
        }
    }

    #[test]
    fn a_parallel_field_keeps_the_target_and_a_short_healing_length_stays_near_it() {
        let (level, triangles) = annulus(12, 64);
        let target: Vec<f32> = level.positions.iter().map(|p| 0.05 + 0.02 * p.x).collect();
        // A constant direction has no curl: the consistent spacing would be
        // uniform, the target is not; the data term alone decides how far.
        let q = vec![Vec3::X; level.len()];
        let near = consistent_scale(&level, &triangles, &q, &target, 0.01).unwrap();
        let worst = spread(near.iter().zip(&target).map(|(&s, &t)| (s / t) as f64));
        assert!(
            worst < 1.01,
            "short healing length moved the spacing by {worst}"
        );
        // With a radial field and a short healing length the spacing stays
        // within a few % of the target; with a long one it turns polar.
        let radial: Vec<Vec3> = level.positions.iter().map(|p| p.normalize()).collect();
        let uniform = vec![0.1f32; level.len()];
        let short = consistent_scale(&level, &triangles, &radial, &uniform, 0.01).unwrap();
        assert!(spread(short.iter().map(|&x| x as f64)) < 1.05);
        let long = consistent_scale(&level, &triangles, &radial, &uniform, 1e4).unwrap();
        assert!(spread(long.iter().map(|&x| x as f64)) > 2.3);
    }

    #[test]
    fn off_and_degenerate_inputs_give_none() {
        let (level, triangles) = annulus(4, 16);
        let q = vec![Vec3::X; level.len()];
        let s = vec![0.1f32; level.len()];
        assert!(consistent_scale(&level, &triangles, &q, &s, 0.0).is_none());
        assert!(consistent_scale(&level, &triangles, &q, &s, f64::NAN).is_none());
    }
}
