//! Per-face anisotropic target lengths in the map: a length of its own
//! along each axis of the combed cross.
//!
//! Ebke et al. 2014 (`../shared/seeds/000_…`) §7 names the extension of
//! the method to anisotropic cross fields (frame fields, Panozzo et al.
//! 2014): the map's energy (MIQ, Bommes et al. 2009 §4, `seamless`'s
//! E_orient) asks per face ∇u = w₀/S, ∇v = w₁/S for the combed cross
//! (w₀, w₁); a frame field asks a length of its own per axis. Here the
//! cross stays a cross (its cones are unchanged) and only the lengths
//! differ: a face's [`AxisLengths`] (unit a in its plane, factors p along
//! a and q across it) ask, on the axis at angle φ from a,
//! 1/L = (p cos²φ + q sin²φ) / S — the metric p a aᵀ + q b bᵀ (b ⊥ a)
//! evaluated on the axis, exact when the cross follows a. Where the
//! metric keeps the area ([`AxisLengths::keep_area`]) both axes' values
//! are then scaled so that their product is p·q, the quad's area asked:
//! a cross at 45° to a would otherwise ask (p + q)/2 ≥ √(pq) both ways,
//! square quads smaller than S² (at 4× the default target with the
//! curvature's ratio capped at 2, medians over 5 vertex orders: spot 732
//! → 764 vertices, rocker-arm 2,482 → 2,655; with the scaling 736 and
//! 2,580).
//!
//! Two sources, each off by default:
//! - thin parts ([`super::thin_parts`]): across a part thinner than a
//!   given number of target edges round, p = 1/r, q = 1;
//! - curvature ([`curvature_lengths`], [`super::Params::curvature_anisotropy`];
//!   not from the seeds): the sagitta of an edge of length h along a
//!   direction of normal curvature κ is ≈ κh²/8, so at a fixed quad area
//!   S² equal sagittas along both principal directions ask
//!   h_a / h_b = (|κ_b| / |κ_a|)^{1/2}: p = ρ, q = 1/ρ with
//!   ρ⁴ = (|κ_a| + κ₀) / (|κ_b| + κ₀) (a the direction of largest |κ|),
//!   h_b / h_a = ρ² capped, and the area p·q = 1 kept. κ from the
//!   curvature tensor at the target scale (one heat step,
//!   [`super::conformal::heat_step_at_target_scale`], of the per-vertex
//!   tensors Σ κᵢ dᵢdᵢᵀ, vertices on feature curves left out: a crease's
//!   curvature is the crease, whose isoline the map keeps anyway);
//!   κ₀ = [`FLAT_SAGITTA`] · 8 / S fades the ratio out where a target
//!   edge's sagitta is below that fraction of it (both κ then are noise).
//!
//! Both at once: the symmetrised product of the two metrics.

use glam::DVec3;

use crate::analysis::SurfaceAnalysis;
use crate::mesh::TriMesh;

/// A face's target lengths per direction: factors on 1/S along the unit
/// `a` (in the face's plane) and across it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AxisLengths {
    pub a: DVec3,
    pub along: f64,
    pub across: f64,
    /// Whichever way the cross turns, its quads keep the area p·q asks
    /// (the curvature's); without, each axis asks its own value (the thin
    /// parts': more edges round the part).
    pub keep_area: bool,
}

/// Per face: its [`AxisLengths`], `None` where S(f) holds both ways.
pub type Anisotropy = Vec<Option<AxisLengths>>;

/// A target edge whose sagitta along the curvature is below this fraction
/// of its length gets no curvature anisotropy: κ₀ = 8 · this / S.
pub const FLAT_SAGITTA: f64 = 0.01;

/// The inverse target lengths along the two `axes` of a face's cross
/// with S = `s`: (p cos²φ + q sin²φ) / S each, φ the angle between the
/// axis and a, both scaled so that their product is p·q / S² when the
/// metric keeps the area; 1/S without.
pub fn inverse_lengths(s: f64, axes: [DVec3; 2], lengths: Option<AxisLengths>) -> [f64; 2] {
    match lengths {
        Some(l) => {
            let m = axes.map(|axis| {
                let c2 = axis.normalize_or_zero().dot(l.a).powi(2);
                c2 * l.along + (1.0 - c2) * l.across
            });
            let k = if l.keep_area {
                (l.along * l.across / (m[0] * m[1])).sqrt()
            } else {
                1.0
            };
            let k = if k.is_finite() { k } else { 1.0 };
            m.map(|x| k * x / s)
        }
        None => [1.0 / s; 2],
    }
}

/// Both anisotropies per face: the symmetrised product (M₁M₂ + M₂M₁)/2
/// of their metrics where both have one, else the one there is.
pub fn combine(x: Anisotropy, y: &[Option<AxisLengths>], normals: &[DVec3]) -> Anisotropy {
    x.into_iter()
        .enumerate()
        .map(|(f, a)| match (a, y.get(f).copied().flatten()) {
            (Some(m1), Some(m2)) => {
                let n = normals.get(f).copied().unwrap_or(DVec3::Z);
                let b1 = n.cross(m1.a).normalize_or_zero();
                // M₂ in the basis (a₁, b₁).
                let (c, s) = (m2.a.dot(m1.a), m2.a.dot(b1));
                let xx = m2.along * c * c + m2.across * s * s;
                let yy = m2.along * s * s + m2.across * c * c;
                let xy = (m2.along - m2.across) * c * s;
                // (M₁M₂ + M₂M₁)/2 with M₁ = diag(p₁, q₁).
                let (xx, yy, xy) = (
                    m1.along * xx,
                    m1.across * yy,
                    0.5 * (m1.along + m1.across) * xy,
                );
                let (l1, d1, l2) = eigen(xx, xy, yy);
                Some(AxisLengths {
                    a: (m1.a * d1.0 + b1 * d1.1).normalize_or_zero(),
                    along: l1,
                    across: l2,
                    keep_area: m1.keep_area && m2.keep_area,
                })
            }
            (a, b) => a.or(b),
        })
        .collect()
}

/// Eigen-decomposition of [[xx, xy], [xy, yy]]: (λ₁, unit (x, y) of λ₁,
/// λ₂), λ₁ ≥ λ₂.
fn eigen(xx: f64, xy: f64, yy: f64) -> (f64, (f64, f64), f64) {
    let mean = 0.5 * (xx + yy);
    let radius = (0.25 * (xx - yy) * (xx - yy) + xy * xy).sqrt();
    let angle = 0.5 * (2.0 * xy).atan2(xx - yy);
    (mean + radius, (angle.cos(), angle.sin()), mean - radius)
}

/// The curvature anisotropy (module doc) with h_b / h_a capped at
/// `max_ratio`; all `None` when `max_ratio` ≤ 1 or the heat step fails.
/// `face_sizing` is S(f); `feature_edges` per face edge (empty: none).
pub fn curvature_lengths(
    mesh: &TriMesh,
    analysis: &SurfaceAnalysis,
    face_sizing: &[f64],
    feature_edges: &[[bool; 3]],
    max_ratio: f64,
) -> Anisotropy {
    let nf = mesh.face_count();
    let nv = mesh.vertex_count();
    if !(max_ratio.is_finite() && max_ratio > 1.0) || analysis.curvature.len() != nv {
        return vec![None; nf];
    }
    let mut kept = vec![1.0; nv];
    for (t, e) in mesh.triangles.iter().zip(feature_edges) {
        for k in 0..3 {
            if e[k] {
                kept[t[k] as usize] = 0.0;
                kept[t[(k + 1) % 3] as usize] = 0.0;
            }
        }
    }
    // Σ κᵢ dᵢdᵢᵀ per vertex (xx, xy, xz, yy, yz, zz), times kept, and kept.
    let mut channels = vec![vec![0.0; nv]; 7];
    for (v, c) in analysis.curvature.iter().enumerate() {
        let w = kept[v];
        for (k, d) in [(c.k1, c.d1), (c.k2, c.d2)] {
            let t = [
                d.x * d.x,
                d.x * d.y,
                d.x * d.z,
                d.y * d.y,
                d.y * d.z,
                d.z * d.z,
            ];
            for (ch, x) in channels.iter_mut().zip(t) {
                ch[v] += w * k * x;
            }
        }
        channels[6][v] = w;
    }
    let Some(smooth) =
        super::conformal::heat_step_at_target_scale(mesh, &analysis.sizing.edge_length, channels)
    else {
        return vec![None; nf];
    };
    let max_rho = max_ratio.sqrt();
    (0..nf)
        .map(|f| {
            let t = mesh.triangles[f];
            let weight: f64 = t.iter().map(|&v| smooth[6][v as usize]).sum();
            let s = face_sizing.get(f).copied().unwrap_or(0.0);
            if !(weight > 1e-9 && s > 0.0 && s.is_finite()) {
                return None;
            }
            let m = |i: usize| t.iter().map(|&v| smooth[i][v as usize]).sum::<f64>() / weight;
            let (xx, xy, xz, yy, yz, zz) = (m(0), m(1), m(2), m(3), m(4), m(5));
            let n = mesh.face_normal_unnormalized(f).normalize_or_zero();
            let (e1, e2) = n.any_orthonormal_pair();
            let form = |u: DVec3, w: DVec3| {
                u.x * (xx * w.x + xy * w.y + xz * w.z)
                    + u.y * (xy * w.x + yy * w.y + yz * w.z)
                    + u.z * (xz * w.x + yz * w.y + zz * w.z)
            };
            let (l1, d1, l2) = eigen(form(e1, e1), form(e1, e2), form(e2, e2));
            let d1 = e1 * d1.0 + e2 * d1.1;
            let (ka, a, kb) = if l1.abs() >= l2.abs() {
                (l1.abs(), d1, l2.abs())
            } else {
                (l2.abs(), n.cross(d1), l1.abs())
            };
            let k0 = 8.0 * FLAT_SAGITTA / s;
            let rho = ((ka + k0) / (kb + k0)).powf(0.25).min(max_rho);
            (rho.is_finite() && rho > 1.0 + 1e-9).then_some(AxisLengths {
                a,
                along: rho,
                across: 1.0 / rho,
                keep_area: true,
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_inverse_lengths_are_p_along_and_q_across() {
        let mut l = AxisLengths {
            a: DVec3::X,
            along: 4.0,
            across: 1.0,
            keep_area: false,
        };
        let s = 2.0;
        let close = |x: [f64; 2], y: [f64; 2]| (x[0] - y[0]).abs() + (x[1] - y[1]).abs() < 1e-12;
        assert_eq!(inverse_lengths(s, [DVec3::X, DVec3::Y], None), [0.5; 2]);
        let aligned = [-3.0 * DVec3::X, DVec3::Y];
        assert!(close(inverse_lengths(s, aligned, Some(l)), [2.0, 0.5]));
        // 45°: the mean of the two both ways, or their geometric mean
        // when the area is kept.
        let d = [DVec3::new(1.0, 1.0, 0.0), DVec3::new(-1.0, 1.0, 0.0)];
        assert!(close(inverse_lengths(s, d, Some(l)), [1.25, 1.25]));
        l.keep_area = true;
        assert!(close(inverse_lengths(s, aligned, Some(l)), [2.0, 0.5]));
        assert!(close(inverse_lengths(s, d, Some(l)), [1.0, 1.0]));
    }

    #[test]
    fn aligned_metrics_combine_by_product_and_crossed_ones_cancel() {
        let m = |a: DVec3, along: f64, across: f64| {
            Some(AxisLengths {
                a,
                along,
                across,
                keep_area: true,
            })
        };
        let n = [DVec3::Z];
        let c = combine(vec![m(DVec3::X, 2.0, 1.0)], &[m(DVec3::X, 1.5, 0.5)], &n)[0].unwrap();
        assert!((c.along - 3.0).abs() < 1e-12 && (c.across - 0.5).abs() < 1e-12);
        assert!(c.a.dot(DVec3::X).abs() > 1.0 - 1e-12);
        let c = combine(vec![m(DVec3::X, 2.0, 0.5)], &[m(DVec3::Y, 2.0, 0.5)], &n)[0].unwrap();
        assert!((c.along - 1.0).abs() < 1e-12 && (c.across - 1.0).abs() < 1e-12);
        let one = combine(vec![None], &[m(DVec3::Y, 2.0, 0.5)], &n)[0].unwrap();
        assert_eq!(one.a, DVec3::Y);
    }

    #[test]
    fn a_cylinder_asks_short_edges_round_it_and_a_sphere_none() {
        let analysis = |mesh: &TriMesh, s: f64| {
            let mut a = crate::analysis::analyze(
                mesh,
                &Default::default(),
                &crate::sizing::SizingParams::default(),
            );
            a.sizing.edge_length.iter_mut().for_each(|x| *x = s);
            a
        };
        // Radius 1 at S = 0.4: κ₀ = 0.2, ρ⁴ = 1.2 / 0.2 = 6, ρ² ≈ 2.45.
        let tube = crate::mesh::generate::cylinder(1.0, 6.0, 48, 48);
        let a = analysis(&tube, 0.4);
        let s = vec![0.4; tube.face_count()];
        for (cap, want) in [(2.0_f64, 2.0_f64), (3.0, 6.0_f64.sqrt())] {
            let l = curvature_lengths(&tube, &a, &s, &[], cap);
            let mut checked = 0;
            for (f, x) in l.iter().enumerate() {
                let c = tube.corners(f).iter().sum::<DVec3>() / 3.0;
                if c.z.abs() > 2.0 {
                    continue; // the rims' curvature estimate
                }
                let x = x.expect("the cylinder is anisotropic");
                let ratio = x.along / x.across;
                assert!((ratio - want).abs() < 0.05 * want, "face {f}: {ratio}");
                assert!(x.a.z.abs() < 0.05, "face {f}: {} is along the axis", x.a);
                assert!((x.along * x.across - 1.0).abs() < 1e-12);
                checked += 1;
            }
            assert!(checked > 1000);
        }
        let sphere = crate::mesh::generate::icosphere(1.0, 4);
        let a = analysis(&sphere, 0.2);
        let s = vec![0.2; sphere.face_count()];
        let l = curvature_lengths(&sphere, &a, &s, &[], 3.0);
        for x in l.iter().flatten() {
            assert!(x.along / x.across < 1.1, "{x:?}");
        }
        assert!(
            curvature_lengths(&sphere, &a, &s, &[], 1.0)
                .iter()
                .all(Option::is_none)
        );
    }
}
