//! The conformal scale of the cone metric: per face, the target edge
//! length under which the cross field's cones are the only curvature.
//!
//! A seamless map is a flat metric with cones (Ebke 2014 §5: the map's
//! singularities are the cross field's cones; Campen et al. 2016 §5 measure
//! how far the map is from the target by its stretch and shear). A map
//! with one target edge length S everywhere cannot be both: on a curved
//! surface the Gaussian curvature between the cones has to go somewhere,
//! and E_orient spreads it as shear over the whole surface (on rocker-arm
//! the quads four rings and more away from any extraordinary vertex
//! deviated 8.6° from square, Instant Meshes' 1.1°). The metric
//! e^{2φ}g that is flat away from the cones and has their angle at them
//! has, with the Laplace–Beltrami operator Δ, the curvature
//! K' = e^{−2φ}(K − Δφ) (the conformal change of the Gaussian curvature);
//! K' = K̂ (0 off the cones, the cone's quarter turns · π/2 at a cone
//! vertex) asks for Δφ = K − K̂, discretely L φ = K̂ − K with the cotangent
//! Laplacian L (positive semidefinite) and K the angle defects. A unit of
//! the flat metric is e^{−φ} units of the surface's, so the target edge
//! becomes S · e^{−φ}: smaller near positive cones, larger near negative
//! ones, and square quads (no shear) wherever the map follows the metric.
//! The mean density is kept (Σ A/S² unchanged), so the vertex count is.
//!
//! A graded sizing S (the thesis' curvature-adaptive field) is a metric of
//! its own, S^{−2}g, and the map's metric is that one times e^{2φ}: with
//! u = φ − ln S flat off the cones, L u = K̂ − K, i.e.
//! L φ = K̂ − K + L ln S and the target edge S · e^{−φ}. On a closed part
//! the result depends on S only through the cones: a size change costs
//! cones, which is why the cross field is computed in the sizing's metric
//! (its transport turns by the harmonic conjugate of ln S, see
//! [`super::cross_field`]), so that its cones are where the sizing asks
//! for them. With one S everywhere L ln S = 0.
//!
//! Boundary vertices keep φ = 0 (their boundary's turning is not
//! prescribed), so the map meets the target there.

use crate::mesh::TriMesh;

use super::cross_field::Cone;
use super::solve::solve_spd;
use super::topology::Fan;

/// The conformal factor φ per vertex (0 at boundary and non-manifold
/// vertices); `None` if the solve fails.
pub fn cone_metric_factor(
    mesh: &TriMesh,
    fans: &[Option<Fan>],
    cones: &[Cone],
    log_size: &[f64],
) -> Option<Vec<f64>> {
    let nv = mesh.positions.len();
    let interior: Vec<bool> = (0..nv)
        .map(|v| {
            fans.get(v)
                .and_then(Option::as_ref)
                .is_some_and(|f| f.closed)
        })
        .collect();
    let mut index = vec![usize::MAX; nv];
    let mut n = 0;
    for v in 0..nv {
        if interior[v] {
            index[v] = n;
            n += 1;
        }
    }
    if n == 0 {
        return Some(vec![0.0; nv]);
    }
    // K̂ − K: angle defects subtracted, cone curvature added.
    let mut rhs = vec![0.0; n];
    let mut diagonal = vec![0.0; n];
    let mut triplets = Vec::with_capacity(4 * mesh.triangles.len());
    let half_cot = half_cotangents(mesh);
    for (t, h) in mesh.triangles.iter().zip(&half_cot) {
        for e in 0..3 {
            let (b, c) = (t[e] as usize, t[(e + 1) % 3] as usize);
            let weight = h[e];
            let (ib, ic) = (index[b], index[c]);
            if ib != usize::MAX {
                diagonal[ib] += weight;
            }
            if ic != usize::MAX {
                diagonal[ic] += weight;
            }
            if ib != usize::MAX && ic != usize::MAX {
                triplets.push((ib.max(ic), ib.min(ic), -weight));
            }
            // + L ln S: the sizing's own curvature (see the module doc).
            if let (Some(&sb), Some(&sc)) = (log_size.get(b), log_size.get(c)) {
                if ib != usize::MAX {
                    rhs[ib] += weight * (sb - sc);
                }
                if ic != usize::MAX {
                    rhs[ic] += weight * (sc - sb);
                }
            }
        }
    }
    for (v, k) in mesh.angle_defects().into_iter().enumerate() {
        if index[v] != usize::MAX {
            rhs[index[v]] -= k;
        }
    }
    for cone in cones {
        let i = index[cone.vertex as usize];
        if i != usize::MAX {
            rhs[i] += cone.quarters as f64 * std::f64::consts::FRAC_PI_2;
        }
    }
    // Closed parts have L's constants as their kernel, and their K̂ − K sums
    // to zero when the cones' indices sum to the part's Euler
    // characteristic (Gauss–Bonnet and Poincaré–Hopf). A cross field on
    // filtered planes need not: at a coarse target the handle test's
    // genus-1 surface got cones summing to 2 (the filtered normals of its
    // thin tube average its sides away). What does not sum to zero is
    // spread evenly over the part (otherwise the solve's constant grows
    // without bound), and a tiny diagonal shift picks the solution up to
    // the constant, which the normalisation removes.
    let mut parts = crate::mesh::UnionFind::new(nv);
    for t in &mesh.triangles {
        parts.union(t[0], t[1]);
        parts.union(t[1], t[2]);
    }
    let mut anchored = vec![false; nv];
    let mut part_sum = vec![(0.0, 0usize); nv];
    for v in 0..nv {
        let r = parts.find(v as u32) as usize;
        if index[v] == usize::MAX {
            anchored[r] = true;
        } else {
            part_sum[r].0 += rhs[index[v]];
            part_sum[r].1 += 1;
        }
    }
    for v in 0..nv {
        let r = parts.find(v as u32) as usize;
        if index[v] != usize::MAX && !anchored[r] {
            rhs[index[v]] -= part_sum[r].0 / part_sum[r].1 as f64;
        }
    }
    let mean_diagonal = diagonal.iter().sum::<f64>() / n as f64;
    for (i, d) in diagonal.iter().enumerate() {
        triplets.push((i, i, d + 1e-9 * mean_diagonal.max(1e-300)));
    }
    let phi = solve_spd(n, &triplets, &[rhs])?.pop()?;
    if phi.iter().any(|x| !x.is_finite()) {
        return None;
    }
    Some(
        (0..nv)
            .map(|v| {
                if index[v] == usize::MAX {
                    0.0
                } else {
                    phi[index[v]]
                }
            })
            .collect(),
    )
}

/// Per face and local edge e (from corner e to corner e + 1): half the
/// cotangent of the angle opposite it, clamped to [1e-6, 1e6]: a
/// degenerate corner's huge weight or an obtuse one's negative weight could
/// leave L ill-conditioned or indefinite (so on obtuse triangles this is
/// not the exact cotangent Laplacian; the disc and torus tests below
/// measure the result against the analytic φ). The weight of an interior
/// edge in L is the sum over its two faces; the cross field's sizing
/// transport uses the same weights, so that its holonomy is this L's.
pub fn half_cotangents(mesh: &TriMesh) -> Vec<[f64; 3]> {
    mesh.triangles
        .iter()
        .map(|t| {
            let p = t.map(|v| mesh.positions[v as usize]);
            std::array::from_fn(|e| {
                let k = (e + 2) % 3;
                let u = p[(k + 1) % 3] - p[k];
                let w = p[(k + 2) % 3] - p[k];
                0.5 * (u.dot(w) / u.cross(w).length().max(1e-300)).clamp(1e-6, 1e6)
            })
        })
        .collect()
}

/// ln S per vertex at the target scale: one implicit heat step
/// (M + t L) x = M ln S with the lumped areas M, the clamped cotangent L and
/// t = S̄²/2 (S̄ the area-weighted mean of S, so σ = S̄), or None when S is
/// one length everywhere (the map needs no sizing metric then) or the solve
/// fails.
///
/// Why: every unit of ∮ ∂ln S/∂n around a region is a radian of cones
/// inside it (see the module doc). The thesis' sizing follows the
/// per-vertex curvature, whose steps over an input edge asked rocker-arm
/// at 2,500 vertices for 872 cones; variations shorter than a target edge
/// cannot be meshed anyway.
pub fn log_size_at_target_scale(mesh: &TriMesh, vertex_sizing: &[f64]) -> Option<Vec<f64>> {
    let nv = mesh.positions.len();
    if vertex_sizing.len() != nv {
        return None;
    }
    let ln: Vec<f64> = vertex_sizing
        .iter()
        .map(|&s| {
            if s > 0.0 && s.is_finite() {
                s.ln()
            } else {
                0.0
            }
        })
        .collect();
    let used: Vec<f64> = mesh
        .triangles
        .iter()
        .flat_map(|t| t.map(|v| ln[v as usize]))
        .collect();
    if used.iter().all(|&x| x == used[0]) {
        return None;
    }
    heat_step_at_target_scale(mesh, vertex_sizing, vec![ln])?.pop()
}

/// Per-vertex `channels` at the target scale: one implicit heat step
/// (M + t L) x = M x₀ each, with the lumped areas M, the clamped cotangent
/// L ([`half_cotangents`]) and t = S̄²/2 (S̄ the area-weighted mean of
/// `vertex_sizing`, so σ = S̄); unreferenced vertices keep their values.
/// `None` when the solve fails or a result is not finite.
pub fn heat_step_at_target_scale(
    mesh: &TriMesh,
    vertex_sizing: &[f64],
    channels: Vec<Vec<f64>>,
) -> Option<Vec<Vec<f64>>> {
    let nv = mesh.positions.len();
    if vertex_sizing.len() != nv || channels.iter().any(|c| c.len() != nv) {
        return None;
    }
    let mut mass = vec![0.0; nv];
    let (mut area, mut weighted) = (0.0, 0.0);
    for (f, t) in mesh.triangles.iter().enumerate() {
        let a = mesh.face_area(f);
        let s = t.iter().map(|&v| vertex_sizing[v as usize]).sum::<f64>() / 3.0;
        area += a;
        weighted += a * s;
        for &v in t {
            mass[v as usize] += a / 3.0;
        }
    }
    let mean_s = weighted / area.max(1e-300);
    let t = 0.5 * mean_s * mean_s;
    let mut triplets = Vec::with_capacity(4 * mesh.triangles.len() + nv);
    for (tri, h) in mesh.triangles.iter().zip(half_cotangents(mesh)) {
        for e in 0..3 {
            let (a, b) = (tri[e] as usize, tri[(e + 1) % 3] as usize);
            let w = t * h[e];
            triplets.push((a, a, w));
            triplets.push((b, b, w));
            triplets.push((a.max(b), a.min(b), -w));
        }
    }
    // Unreferenced vertices get a unit row and keep their value.
    let m: Vec<f64> = mass
        .iter()
        .map(|&m| if m > 0.0 { m } else { 1.0 })
        .collect();
    for (v, &mv) in m.iter().enumerate() {
        triplets.push((v, v, mv));
    }
    let rhs: Vec<Vec<f64>> = channels
        .iter()
        .map(|c| c.iter().zip(&m).map(|(x, mv)| mv * x).collect())
        .collect();
    let x = solve_spd(nv, &triplets, &rhs)?;
    x.iter()
        .all(|c| c.iter().all(|x| x.is_finite()))
        .then_some(x)
}

/// S(f) · e^{−φ(f)} (φ averaged over the face's corners), scaled so that
/// Σ A/S² is unchanged, with the factor against S(f) kept within
/// [1/limit, limit] (`limit` ≤ 1: no bound).
pub fn conformal_sizing(mesh: &TriMesh, face_sizing: &[f64], phi: &[f64], limit: f64) -> Vec<f64> {
    // φ per face, less its mean (the constant is the normalisation's; an
    // offset would only overflow the exponential).
    let face_phi: Vec<f64> = mesh
        .triangles
        .iter()
        .map(|t| t.iter().map(|&v| phi[v as usize]).sum::<f64>() / 3.0)
        .collect();
    let mean = face_phi.iter().sum::<f64>() / face_phi.len().max(1) as f64;
    let mut factor: Vec<f64> = face_phi.iter().map(|p| (mean - p).exp()).collect();
    if factor.iter().any(|x| !(x.is_finite() && *x > 0.0)) {
        return face_sizing.to_vec();
    }
    let valid: Vec<usize> = (0..mesh.triangles.len())
        .filter(|&f| face_sizing[f] > 0.0 && face_sizing[f].is_finite())
        .collect();
    let density = |factor: &[f64]| {
        valid
            .iter()
            .map(|&f| mesh.face_area(f) / (face_sizing[f] * factor[f]).powi(2))
            .sum::<f64>()
    };
    let before = density(&vec![1.0; factor.len()]);
    // Normalising moves every factor, which can move some past the bound
    // again: a few rounds settle it.
    for round in 0..4 {
        let after = density(&factor);
        if before > 0.0 && after > 0.0 {
            let c = (after / before).sqrt();
            for x in &mut factor {
                *x *= c;
            }
        }
        if limit <= 1.0 || round == 3 {
            break;
        }
        for x in &mut factor {
            *x = x.clamp(1.0 / limit, limit);
        }
    }
    face_sizing
        .iter()
        .zip(&factor)
        .map(|(s, x)| s * x)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::generate::torus;
    use crate::param::topology::{EdgeTopology, vertex_fans};
    use glam::DVec3;

    fn factor(mesh: &TriMesh, cones: &[Cone]) -> Vec<f64> {
        let fans = vertex_fans(mesh, &EdgeTopology::new(mesh));
        cone_metric_factor(mesh, &fans, cones, &[]).expect("a solve")
    }

    /// The unit disc in polar rings (vertex 0 at the centre).
    fn polar_disc(rings: u32, spokes: u32) -> TriMesh {
        let mut positions = vec![DVec3::ZERO];
        for r in 1..=rings {
            for s in 0..spokes {
                let (a, rho) = (
                    std::f64::consts::TAU * s as f64 / spokes as f64,
                    r as f64 / rings as f64,
                );
                positions.push(DVec3::new(rho * a.cos(), rho * a.sin(), 0.0));
            }
        }
        let at = |r: u32, s: u32| {
            if r == 0 {
                0
            } else {
                1 + (r - 1) * spokes + s % spokes
            }
        };
        let mut triangles = Vec::new();
        for s in 0..spokes {
            triangles.push([0, at(1, s), at(1, s + 1)]);
        }
        for r in 1..rings {
            for s in 0..spokes {
                triangles.push([at(r, s), at(r + 1, s), at(r + 1, s + 1)]);
                triangles.push([at(r, s), at(r + 1, s + 1), at(r, s + 1)]);
            }
        }
        TriMesh {
            positions,
            triangles,
        }
    }

    /// A +¼ cone at the centre of the flat unit disc, φ = 0 on its rim:
    /// the flat cone metric |z|^{−1/2}|dz|² (cone angle 3π/2) has
    /// φ = −¼ ln r, and a −¼ cone the opposite.
    #[test]
    fn a_cone_in_the_flat_disc_gives_the_logarithm() {
        let mesh = polar_disc(40, 96);
        for quarters in [1, -1] {
            let phi = factor(
                &mesh,
                &[Cone {
                    vertex: 0,
                    quarters,
                }],
            );
            let mut worst: f64 = 0.0;
            for (p, &x) in mesh.positions.iter().zip(&phi) {
                let r = p.length();
                if (0.2..=0.8).contains(&r) {
                    let exact = -0.25 * quarters as f64 * r.ln();
                    worst = worst.max((x - exact).abs());
                }
            }
            // The exact values run from 0.06 to 0.40.
            assert!(
                worst < 0.015,
                "quarters {quarters}: φ off the logarithm by {worst}"
            );
        }
        // No cone: the flat disc is already flat.
        assert!(factor(&mesh, &[]).iter().all(|x| x.abs() < 1e-9));
    }

    /// The torus of revolution g = r²dv² + ρ²dθ² (ρ = R + r cos v) is
    /// conformally flat with factor 1/ρ² and needs no cone: φ = −ln ρ up
    /// to a constant, so the target edge grows with the distance to the
    /// axis.
    #[test]
    fn the_torus_is_flat_at_the_scale_of_its_distance_to_the_axis() {
        let mesh = torus(2.0, 0.7, 96, 40);
        let phi = factor(&mesh, &[]);
        let residual: Vec<f64> = mesh
            .positions
            .iter()
            .zip(&phi)
            .map(|(p, x)| x + p.truncate().length().ln())
            .collect();
        let mean = residual.iter().sum::<f64>() / residual.len() as f64;
        let spread = residual
            .iter()
            .map(|x| (x - mean).abs())
            .fold(0.0, f64::max);
        // ln ρ itself spans ln(2.7 / 1.3) = 0.73.
        assert!(spread < 0.02, "φ + ln ρ varies by {spread}");
    }

    /// Cones that do not sum to the Euler characteristic (a cross field
    /// on filtered planes can give that) leave L φ = K̂ − K without a
    /// solution on a closed surface; the excess is spread over the part and
    /// φ stays bounded: on the torus with one +¼ cone, φ is the torus'
    /// −ln ρ plus a bounded bump, not the solve's runaway constant.
    #[test]
    fn cones_off_the_euler_characteristic_leave_phi_bounded() {
        let mesh = torus(2.0, 0.7, 96, 40);
        let phi = factor(
            &mesh,
            &[Cone {
                vertex: 0,
                quarters: 1,
            }],
        );
        let (lo, hi) = phi
            .iter()
            .fold((f64::MAX, f64::MIN), |(a, b), &x| (a.min(x), b.max(x)));
        assert!(
            hi - lo < 3.0 && lo.abs().max(hi.abs()) < 10.0,
            "φ spans {lo} … {hi}"
        );
        let s = conformal_sizing(&mesh, &vec![0.1; mesh.triangles.len()], &phi, 0.0);
        assert!(s.iter().all(|x| x.is_finite() && *x > 0.0));
    }

    #[test]
    fn the_sizing_keeps_its_density_within_the_bound() {
        let mesh = polar_disc(20, 48);
        let phi = factor(
            &mesh,
            &[Cone {
                vertex: 0,
                quarters: 1,
            }],
        );
        let s = vec![0.1; mesh.triangles.len()];
        let density = |s: &[f64]| {
            (0..s.len())
                .map(|f| mesh.face_area(f) / (s[f] * s[f]))
                .sum::<f64>()
        };
        for limit in [0.0, 1.2, 2.0] {
            let c = conformal_sizing(&mesh, &s, &phi, limit);
            let ratio = density(&c) / density(&s);
            assert!(
                (ratio - 1.0).abs() < 1e-9,
                "limit {limit}: density × {ratio}"
            );
            // Smaller near the positive cone, larger at the rim.
            assert!(c[0] < c[c.len() - 1], "limit {limit}");
            if limit > 1.0 {
                let (lo, hi) = c
                    .iter()
                    .fold((f64::MAX, 0.0f64), |(a, b), &x| (a.min(x), b.max(x)));
                // The last normalisation may move the bound by its factor.
                assert!(
                    hi / lo <= limit * limit * 1.05,
                    "limit {limit}: spread {}",
                    hi / lo
                );
            }
        }
    }
}
