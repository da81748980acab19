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
//!
//! The hard counterpart is [`thin_part_loops`]: closed loops round the
//! parts between one and a few target edges round, whose translation in
//! the map (the holonomy of the loop, MIQ's seam translations summed
//! round it) the rounding keeps at least a few units
//! (`seamless::widen_loops`), as Campen et al. 2016 §4.3
//! (`../shared/seeds/001_…`) constrains the holonomy of its cyclic
//! regions' loops. A loop is the shortest plane section through a face
//! (planes containing the face's normal, [`SECTION_DIRECTIONS`] of them),
//! measured in target edges; the map cannot fold a part whose loop
//! translation is a few units, and QEx then gives it faces round it.
//! Parts less than [`LEVEL_OF_DETAIL`] target edges round get no loop:
//! Ebke §6's level of detail drops them by design (tests/qex.rs's small
//! handle).

use glam::DVec3;

use super::anisotropy::{Anisotropy, AxisLengths};
use super::topology::EdgeTopology;
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

/// Parts less than this many target edges round are below the target
/// scale (Ebke §6: a handle or fold below it produces no faces) and get
/// no loop ([`thin_part_loops`]).
pub const LEVEL_OF_DETAIL: f64 = 1.0;

/// Plane directions tried per face (over half a turn): the shortest
/// section is within 180° / 16 of a tube's cross-section, at most
/// 1 / cos(11.25°) ≈ 2 % longer.
pub const SECTION_DIRECTIONS: usize = 8;

/// A closed loop of faces round a thin part.
#[derive(Debug, Clone, PartialEq)]
pub struct ThinLoop {
    /// Consecutive faces share an edge, the last one with the first.
    pub faces: Vec<u32>,
    /// Per face: where the loop enters it (on its edge shared with the
    /// previous face); the loop runs from `points[i]` to `points[i + 1]`
    /// in `faces[i]`.
    pub points: Vec<DVec3>,
    /// Its length in target edges (Σ segment length / S(f)).
    pub units: f64,
}

/// Loops round the parts between [`LEVEL_OF_DETAIL`] and `below` target
/// edges round (S(f) = `face_sizing`), at most one per face and spaced
/// about half a target edge apart along a part, the narrowest first.
/// Empty when `below` is not above [`LEVEL_OF_DETAIL`].
pub fn thin_part_loops(
    mesh: &TriMesh,
    topology: &EdgeTopology,
    face_sizing: &[f64],
    below: f64,
) -> Vec<ThinLoop> {
    let nf = mesh.triangles.len();
    if !(below.is_finite() && below > LEVEL_OF_DETAIL) || face_sizing.len() != nf {
        return Vec::new();
    }
    let mut stamp = vec![0u32; nf];
    let mut walk = 0u32;
    // Per face: its shortest closed section within the bound, with the
    // plane it lies in.
    let mut candidates: Vec<(ThinLoop, DVec3, DVec3)> = Vec::new();
    // Per face: its shortest section's length (∞: none within the bound).
    let mut shortest = vec![f64::INFINITY; nf];
    for f in 0..nf {
        let n = mesh.face_normal_unnormalized(f);
        let Some(n) = n.try_normalize() else {
            continue;
        };
        let centre = mesh.corners(f).iter().sum::<DVec3>() / 3.0;
        let (a, b) = n.any_orthonormal_pair();
        let mut best: Option<(ThinLoop, DVec3)> = None;
        for k in 0..SECTION_DIRECTIONS {
            let phi = std::f64::consts::PI * k as f64 / SECTION_DIRECTIONS as f64;
            let m = phi.cos() * a + phi.sin() * b;
            walk = walk.wrapping_add(1);
            if walk == 0 {
                stamp.fill(0);
                walk = 1;
            }
            let limit = best.as_ref().map_or(below, |b| b.0.units);
            if let Some(l) = section(
                mesh,
                topology,
                face_sizing,
                f,
                centre,
                m,
                limit,
                &mut stamp,
                walk,
            ) {
                best = Some((l, m));
            }
        }
        if let Some((l, m)) = best {
            shortest[f] = l.units;
            candidates.push((l, centre, m));
        }
    }
    // A loop through a part below the level of detail is none (a tilted
    // section over the cap of a part thinner than that, say).
    candidates.retain(|(l, _, _)| {
        l.faces
            .iter()
            .all(|&g| shortest[g as usize] >= LEVEL_OF_DETAIL)
    });
    candidates.sort_by(|x, y| {
        x.0.units
            .total_cmp(&y.0.units)
            .then(x.0.faces[0].cmp(&y.0.faces[0]))
    });
    // The narrowest first; a loop covers the seeds within half a target
    // edge of its plane and near it.
    let mut covered = vec![false; nf];
    let mut out = Vec::new();
    let seeds: Vec<(u32, DVec3)> = candidates.iter().map(|c| (c.0.faces[0], c.1)).collect();
    for (l, p0, m) in candidates {
        if covered[l.faces[0] as usize] {
            continue;
        }
        let s = l
            .faces
            .iter()
            .map(|&f| face_sizing[f as usize])
            .sum::<f64>()
            / l.faces.len() as f64;
        let points = &l.points;
        let centre = points.iter().sum::<DVec3>() / points.len() as f64;
        let radius = points
            .iter()
            .map(|p| p.distance(centre))
            .fold(0.0, f64::max);
        for &(g, c) in &seeds {
            if (c - p0).dot(m).abs() < 0.5 * s && c.distance(centre) < radius + 0.5 * s {
                covered[g as usize] = true;
            }
        }
        out.push(l);
    }
    out
}

/// The plane section through `seed` (the plane through `p0` with normal
/// `m`), walked from face to face across the edges it crosses until it
/// comes back to `seed`; `None` when it reaches the boundary, comes back
/// elsewhere, or is `limit` target edges long before it closes.
#[allow(clippy::too_many_arguments)]
fn section(
    mesh: &TriMesh,
    topology: &EdgeTopology,
    face_sizing: &[f64],
    seed: usize,
    p0: DVec3,
    m: DVec3,
    limit: f64,
    stamp: &mut [u32],
    walk: u32,
) -> Option<ThinLoop> {
    let height = |v: u32| (mesh.positions[v as usize] - p0).dot(m);
    let crossing = |f: usize, e: usize| {
        let t = mesh.triangles[f];
        let (ha, hb) = (height(t[e]), height(t[(e + 1) % 3]));
        ((ha >= 0.0) != (hb >= 0.0)).then(|| {
            let (pa, pb) = (
                mesh.positions[t[e] as usize],
                mesh.positions[t[(e + 1) % 3] as usize],
            );
            pa + (pb - pa) * (ha / (ha - hb))
        })
    };
    let first = (0..3).find(|&e| crossing(seed, e).is_some())?;
    let mut faces = vec![seed as u32];
    let mut points = Vec::new();
    let mut units = 0.0;
    let (mut f, mut e_in) = (seed, first);
    stamp[seed] = walk;
    loop {
        let e_out = (0..3).find(|&e| e != e_in && crossing(f, e).is_some())?;
        let (a, b) = (crossing(f, e_in)?, crossing(f, e_out)?);
        let s = face_sizing[f];
        if !(s.is_finite() && s > 0.0) {
            return None;
        }
        points.push(a);
        units += a.distance(b) / s;
        if units >= limit {
            return None;
        }
        let (g, ge) = topology.across(f, e_out)?;
        if g == seed {
            return (ge == first && faces.len() >= 3).then_some(ThinLoop {
                faces,
                points,
                units,
            });
        }
        if stamp[g] == walk {
            return None;
        }
        stamp[g] = walk;
        faces.push(g as u32);
        (f, e_in) = (g, ge);
    }
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

    #[test]
    fn loops_go_round_a_thin_capsule_and_not_round_a_sphere_or_below_the_detail() {
        let loops = |mesh: &TriMesh, s: f64| {
            let topology = EdgeTopology::new(mesh);
            thin_part_loops(mesh, &topology, &vec![s; mesh.face_count()], 3.0)
        };
        // A great circle of the unit sphere is 2π / 0.5 ≈ 12.6 edges.
        assert!(loops(&crate::mesh::generate::icosphere(1.0, 3), 0.5).is_empty());
        // A capsule of circumference 2π · 0.1 ≈ 0.63: 2.1 target edges
        // round at 0.3, loops round it (at most 1 / cos(11.25°) longer
        // than the circle, the polygon a little shorter); 0.63 edges at
        // 1, below the level of detail.
        let capsule = crate::mesh::generate::capsule(0.1, 3.0, 32, 8, 60);
        let round = loops(&capsule, 0.3);
        assert!(round.len() >= 4, "{} loops", round.len());
        let circle = std::f64::consts::TAU * 0.1 / 0.3;
        for l in &round {
            assert!(
                l.units > 0.97 * circle && l.units < 1.03 * circle,
                "{} against {circle}",
                l.units
            );
            assert_eq!(l.faces.len(), l.points.len());
            // Each point lies on the edge shared with the previous face.
            for (i, p) in l.points.iter().enumerate() {
                let prev = l.faces[(i + l.faces.len() - 1) % l.faces.len()];
                let c = capsule.corners(prev as usize);
                let on = (0..3).any(|e| {
                    let (a, b) = (c[e], c[(e + 1) % 3]);
                    (p - a).cross(b - a).length() <= 1e-9 * (b - a).length()
                });
                assert!(on, "point {i} of a loop");
            }
        }
        assert!(loops(&capsule, 1.0).is_empty());
    }
}
