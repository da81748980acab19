//! Thin parts get an anisotropic target in the map: across the part the
//! target edge is capped so that the part has a given number of edges
//! around it, along it the edge stays S(f).
//!
//! Ebke et al. 2014 (`../shared/seeds/000_…`) §7 names the extension of
//! the method to anisotropic cross fields (frame fields, Panozzo et al.
//! 2014): the map's energy (MIQ, Bommes et al. 2009 §4, `seamless`'s
//! E_orient) asks per face ∇u = w₀/S, ∇v = w₁/S for the combed cross
//! (w₀, w₁); a frame field asks a length of its own per axis. Here the
//! cross stays a cross (its cones are unchanged) and only the lengths
//! differ ([`super::anisotropy`]): on a face of a thin part, the axis at
//! angle φ from the direction across the part asks
//! 1/L = (cos²φ / r + sin²φ) / S, r the cap's ratio to S (`analysis::thickness::thin_part_cap`, graded, with
//! its floor; the shape diameter d gives the cross-section's
//! circumference π d). The direction across a tube is its principal
//! direction of largest |κ| (round the tube), averaged over the face's
//! corners.
//!
//! Not from the seeds: the choice of where (the shape diameter) and of
//! the direction. Below the target scale the map folds a part a target
//! edge round and QEx drops it (Ebke §6's level of detail: the cow's legs
//! and the ears of suzanne at their default targets), which is Instant
//! Meshes' lead in the Hausdorff distance there. An isotropic cap
//! (`sizing.thin_part_edges`) refines the part along its length too and
//! brings the cones of the sizing transport with it; this asks only for
//! the edges round it. Off by default; the figures are at
//! [`super::Params::thin_part_across`].

use glam::DVec3;

use super::anisotropy::{Anisotropy, AxisLengths};
use crate::analysis::{SurfaceAnalysis, thickness};
use crate::mesh::TriMesh;
use crate::spatial::SurfaceIndex;

/// The faces of the parts thinner than `edges_around` target edges round
/// (the calibrated sizing `analysis.sizing.edge_length`): along the unit
/// direction across the part 1/r, r ∈ (0, 1) the target edge across as a
/// fraction of S(f), and 1 along the part; all `None` when `edges_around`
/// is not positive or no part is that thin.
pub fn across_thin_parts(
    mesh: &TriMesh,
    analysis: &SurfaceAnalysis,
    edges_around: f64,
) -> Anisotropy {
    let nf = mesh.triangles.len();
    if !(edges_around.is_finite() && edges_around > 0.0) {
        return vec![None; nf];
    }
    let Some(index) = SurfaceIndex::new(mesh) else {
        return vec![None; nf];
    };
    let s = &analysis.sizing.edge_length;
    let diameter = thickness::shape_diameter(mesh, &analysis.vertex_normals, &index);
    let Some(cap) = thickness::thin_part_cap(
        mesh,
        &analysis.adjacency,
        &diameter,
        s,
        edges_around,
        thickness::FLOOR,
        crate::sizing::SizingParams::default().thin_part_gradation,
    ) else {
        return vec![None; nf];
    };
    (0..nf)
        .map(|f| {
            let t = mesh.triangles[f];
            let ratio = t
                .iter()
                .map(|&v| (cap[v as usize] / s[v as usize]).min(1.0))
                .sum::<f64>()
                / 3.0;
            if !(ratio.is_finite() && ratio > 0.0 && ratio < 1.0) {
                return None;
            }
            let n = mesh.face_normal_unnormalized(f).normalize_or_zero();
            // The corners' directions of largest |κ| in the face's plane,
            // as a line field: signs matched to the first before the mean.
            let mut sum = DVec3::ZERO;
            let mut first: Option<DVec3> = None;
            for &v in &t {
                let c = analysis.curvature[v as usize];
                let d = if c.k1.abs() >= c.k2.abs() { c.d1 } else { c.d2 };
                let d = d.reject_from_normalized(n);
                let d = match first {
                    Some(f0) if f0.dot(d) < 0.0 => -d,
                    _ => d,
                };
                first.get_or_insert(d);
                sum += d;
            }
            sum.try_normalize().map(|a| AxisLengths {
                a,
                along: 1.0 / ratio,
                across: 1.0,
                keep_area: false,
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_thick_sphere_has_no_thin_part_and_a_thin_tube_is_thin_round_it() {
        let sizing = |mesh: &TriMesh, s: f64| {
            let mut a = crate::analysis::analyze(
                mesh,
                &Default::default(),
                &crate::sizing::SizingParams::default(),
            );
            a.sizing.edge_length.iter_mut().for_each(|x| *x = s);
            a
        };
        // A unit sphere at a target edge of 0.5: about 12 edges round.
        let sphere = crate::mesh::generate::icosphere(1.0, 3);
        let a = sizing(&sphere, 0.5);
        assert!(
            across_thin_parts(&sphere, &a, 4.0)
                .iter()
                .all(Option::is_none)
        );
        // An open tube of circumference 2π · 0.1 ≈ 0.63 at a target edge
        // of 0.5 (1.3 edges round): 4 edges round ask r = 0.63 / 4 / 0.5
        // ≈ 0.31, the cap's floor 0.35; the direction round the tube.
        let tube = crate::mesh::generate::cylinder(0.1, 4.0, 24, 40);
        let a = sizing(&tube, 0.5);
        let across = across_thin_parts(&tube, &a, 4.0);
        let mut checked = 0;
        for (f, x) in across.iter().enumerate() {
            let c = tube.corners(f).iter().sum::<DVec3>() / 3.0;
            if c.z.abs() > 1.5 {
                continue; // the rims' curvature estimate
            }
            let l = x.expect("the tube is thin");
            let (r, d) = (1.0 / l.along, l.a);
            assert!((r - thickness::FLOOR).abs() < 1e-9, "r {r}");
            assert_eq!(l.across, 1.0);
            assert!(d.z.abs() < 0.1, "face {f}: {d} is along the tube");
            checked += 1;
        }
        assert!(checked > 100);
    }
}
