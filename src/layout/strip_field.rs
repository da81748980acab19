//! The strip cross field of Campen & Kobbelt 2014, *Dual Strip Weaving*,
//! §6.1: a 4-RoSy field aligned with every committed loop, by the
//! representation-vector method (Palacios & Zhang 2007; 4-RoSy case of
//! Diamanti et al. 2014): each triangle crossed by a loop gets the unit
//! representation vector z = e^{4iθ} of the loop's direction there, the
//! other triangles are harmonically interpolated (one sparse solve), the
//! crosses are recovered as θ = arg z / 4 and the singularities extracted.
//!
//! Deviations / choices the paper leaves open:
//! - the loop's direction in a triangle is the chord from the previous to
//!   the next-but-one crossing (three segments), which smooths out the
//!   detours the embedding makes around vertices;
//! - triangles crossed by several loops average the representation vectors
//!   (equal for orthogonal crossings); if they cancel, the triangle is free;
//! - the Dirichlet energy is Σ_{interior edges} w |z_f − r_fg z_g|² over the
//!   dual graph with w = |e| / |c_f − c_g| (dual-edge weight) and r_fg the
//!   4th power of the rotation between the two triangles' frames across the
//!   shared edge (discrete Levi-Civita transport);
//! - a 1e-9 relative Tikhonov term keeps free components without any loop
//!   solvable (their field is zero, i.e. undefined, and they get no cross).

use std::f64::consts::{FRAC_PI_2, TAU};

use glam::{DVec2, DVec3};

use super::embed::{EdgeTopology, EmbeddedLoop, Singularity};
use crate::mesh::{TriMesh, VertexFaces};

/// The cross field: one cross per face, given by one of its four arms.
#[derive(Debug, Clone, PartialEq)]
pub struct StripField {
    /// Per face: an arm of the cross (world unit vector, tangent), zero
    /// where the field is undefined (no loop in that part of the mesh).
    pub cross: Vec<DVec3>,
    /// Per face: true where a loop prescribed the cross.
    pub constrained: Vec<bool>,
    /// Interior vertices around which the field turns by a multiple of π/2.
    pub singularities: Vec<Singularity>,
}

/// Per-face orthonormal tangent frame (e1 along the first edge) and unit
/// normal.
pub(crate) fn face_frames(mesh: &TriMesh) -> Vec<[DVec3; 3]> {
    (0..mesh.triangles.len())
        .map(|f| {
            let c = mesh.corners(f);
            let n = mesh.face_normal_unnormalized(f).normalize_or_zero();
            let n = if n == DVec3::ZERO { DVec3::Z } else { n };
            let e1 = (c[1] - c[0]).reject_from_normalized(n).normalize_or_zero();
            let e1 = if e1 == DVec3::ZERO {
                n.any_orthonormal_vector()
            } else {
                e1
            };
            [e1, n.cross(e1), n]
        })
        .collect()
}

/// Angle of a vector in a face frame.
pub(crate) fn angle_in(frame: &[DVec3; 3], d: DVec3) -> f64 {
    d.dot(frame[1]).atan2(d.dot(frame[0]))
}

/// `x` reduced into (−π/4, π/4] modulo π/2.
pub(crate) fn reduce_quarter(x: f64) -> f64 {
    x - FRAC_PI_2 * (x / FRAC_PI_2).round()
}

fn cmul(a: DVec2, b: DVec2) -> DVec2 {
    DVec2::new(a.x * b.x - a.y * b.y, a.x * b.y + a.y * b.x)
}

fn polar(angle: f64) -> DVec2 {
    DVec2::new(angle.cos(), angle.sin())
}

pub(crate) use crate::param::solve::solve_spd;

/// The §6.1 cross field aligned with `loops`; None without loops (or when
/// the solve fails).
/// Loops that are not valid walks on `mesh` ([`EmbeddedLoop::check`]) are
/// ignored.
pub fn strip_field(mesh: &TriMesh, loops: &[EmbeddedLoop]) -> Option<StripField> {
    let topology = EdgeTopology::new(mesh);
    let valid: Vec<EmbeddedLoop> = loops
        .iter()
        .filter(|l| l.check(mesh).is_ok())
        .cloned()
        .collect();
    strip_field_with(mesh, &topology, &valid)
}

// Parallel per-face arrays read best indexed.
#[allow(clippy::needless_range_loop)]
pub(crate) fn strip_field_with(
    mesh: &TriMesh,
    topology: &EdgeTopology,
    loops: &[EmbeddedLoop],
) -> Option<StripField> {
    let nf = mesh.triangles.len();
    let frames = face_frames(mesh);
    // Prescribed representation vectors.
    let mut sum = vec![DVec2::ZERO; nf];
    let mut count = vec![0u32; nf];
    for l in loops {
        let n = l.crossings.len() as isize;
        let at = |i: isize| {
            let i = if l.closed {
                i.rem_euclid(n)
            } else {
                i.clamp(0, n - 1)
            };
            l.crossings[i as usize].point(mesh)
        };
        for (i, &f) in l.faces.iter().enumerate() {
            let Some(frame) = frames.get(f as usize) else {
                continue;
            };
            // The loop's direction: the chord over the neighbouring
            // segments too (crossings next to a vertex the loop was pushed
            // off make single segments unreliable).
            let i = i as isize;
            let d = at(i + 2) - at(i - 1);
            if d.length_squared() > 0.0 {
                sum[f as usize] += polar(4.0 * angle_in(frame, d));
                count[f as usize] += 1;
            }
        }
    }
    let mut z = vec![DVec2::ZERO; nf];
    let mut constrained = vec![false; nf];
    for f in 0..nf {
        if count[f] > 0 && sum[f].length() > 1e-3 * count[f] as f64 {
            z[f] = sum[f].normalize();
            constrained[f] = true;
        }
    }
    if !constrained.iter().any(|&c| c) {
        return None;
    }
    // Free unknowns: (re, im) of every unconstrained face.
    let mut index = vec![usize::MAX; nf];
    let mut n = 0;
    for f in 0..nf {
        if !constrained[f] {
            index[f] = n;
            n += 1;
        }
    }
    let centroid = |f: usize| {
        let c = mesh.corners(f);
        (c[0] + c[1] + c[2]) / 3.0
    };
    let mut triplets = Vec::with_capacity(16 * n);
    let mut rhs = vec![0.0; 2 * n];
    let mut diag = vec![0.0; n];
    // Adds the complex entry `m` at block (i, j).
    let block = |triplets: &mut Vec<(usize, usize, f64)>, i: usize, j: usize, m: DVec2| {
        triplets.push((2 * i, 2 * j, m.x));
        triplets.push((2 * i, 2 * j + 1, -m.y));
        triplets.push((2 * i + 1, 2 * j, m.y));
        triplets.push((2 * i + 1, 2 * j + 1, m.x));
    };
    for f in 0..nf {
        let t = mesh.triangles[f];
        for e in 0..3 {
            let g = topology.opposite[f][e] as usize;
            if g == u32::MAX as usize || g < f || (constrained[f] && constrained[g]) {
                continue;
            }
            let (pa, pb) = (
                mesh.positions[t[e] as usize],
                mesh.positions[t[(e + 1) % 3] as usize],
            );
            let edge = pb - pa;
            let w = edge.length()
                / centroid(f)
                    .distance(centroid(g))
                    .max(1e-12 * edge.length().max(1e-300));
            if !w.is_finite() {
                continue;
            }
            // z_g seen in f's frame: z_g · r_fg.
            let r_fg = polar(4.0 * (angle_in(&frames[f], edge) - angle_in(&frames[g], edge)));
            let r_gf = DVec2::new(r_fg.x, -r_fg.y);
            match (index[f], index[g]) {
                (i, j) if i != usize::MAX && j != usize::MAX => {
                    diag[i] += w;
                    diag[j] += w;
                    block(&mut triplets, i, j, -w * r_fg);
                    block(&mut triplets, j, i, -w * r_gf);
                }
                (i, _) if i != usize::MAX => {
                    diag[i] += w;
                    let b = w * cmul(r_fg, z[g]);
                    rhs[2 * i] += b.x;
                    rhs[2 * i + 1] += b.y;
                }
                (_, j) => {
                    diag[j] += w;
                    let b = w * cmul(r_gf, z[f]);
                    rhs[2 * j] += b.x;
                    rhs[2 * j + 1] += b.y;
                }
            }
        }
    }
    let mean = diag.iter().sum::<f64>() / n.max(1) as f64;
    for (i, d) in diag.iter().enumerate() {
        let d = d + 1e-9 * mean.max(1e-300);
        triplets.push((2 * i, 2 * i, d));
        triplets.push((2 * i + 1, 2 * i + 1, d));
    }
    let x = solve_spd(2 * n, &triplets, &[rhs])?;
    for f in 0..nf {
        if let Some(&i) = index.get(f).filter(|&&i| i != usize::MAX) {
            z[f] = DVec2::new(x[0][2 * i], x[0][2 * i + 1]);
        }
    }
    // Near a high-index zero |z| decays like r^k: only exact zeros (parts of
    // the mesh no loop reaches) are undefined.
    let defined: Vec<bool> = z.iter().map(|v| v.length_squared() > 1e-60).collect();
    let theta: Vec<f64> = z.iter().map(|v| v.y.atan2(v.x) / 4.0).collect();
    let cross = (0..nf)
        .map(|f| {
            if defined[f] {
                frames[f][0] * theta[f].cos() + frames[f][1] * theta[f].sin()
            } else {
                DVec3::ZERO
            }
        })
        .collect();
    let singularities = singularities(mesh, topology, &frames, &theta, &defined);
    Some(StripField {
        cross,
        constrained,
        singularities,
    })
}

/// The faces around interior vertex `v` in counter-clockwise order, each as
/// (face, a, b) with the face's corners (v, a, b) counter-clockwise; None at
/// boundary and non-manifold vertices.
pub(crate) fn fan(
    mesh: &TriMesh,
    topology: &EdgeTopology,
    faces: &[u32],
    v: u32,
) -> Option<Vec<(u32, u32, u32)>> {
    let &start = faces.first()?;
    let mut out = Vec::with_capacity(faces.len());
    let mut f = start;
    loop {
        let t = mesh.triangles[f as usize];
        let k = t.iter().position(|&x| x == v)?;
        let (a, b) = (t[(k + 1) % 3], t[(k + 2) % 3]);
        out.push((f, a, b));
        // Next face across the edge (b, v): local edge (k + 2) % 3.
        f = topology.opposite[f as usize][(k + 2) % 3];
        if f == u32::MAX || out.len() > faces.len() {
            return None;
        }
        if f == start {
            break;
        }
    }
    (out.len() == faces.len()).then_some(out)
}

/// Index (quarter turns) of the field around every interior vertex:
/// round((Σ d_j + K_v) / (π/2)), where d_j is the cross's rotation from
/// face j to face j + 1 of the fan relative to the discrete parallel
/// transport (reduced to (−π/4, π/4]) and K_v the angle defect.
fn singularities(
    mesh: &TriMesh,
    topology: &EdgeTopology,
    frames: &[[DVec3; 3]],
    theta: &[f64],
    defined: &[bool],
) -> Vec<Singularity> {
    let vertex_faces = VertexFaces::new(mesh);
    let mut out = Vec::new();
    for v in 0..mesh.positions.len() {
        let faces = vertex_faces.faces(v);
        if faces.iter().any(|&f| !defined[f as usize]) {
            continue;
        }
        let Some(fan) = fan(mesh, topology, faces, v as u32) else {
            continue;
        };
        let p = mesh.positions[v];
        // φ_j: the cross angle relative to the edge v→a_j; β_j: angle at v.
        let mut phi = Vec::with_capacity(fan.len());
        let mut beta = Vec::with_capacity(fan.len());
        for &(f, a, b) in &fan {
            let (da, db) = (
                mesh.positions[a as usize] - p,
                mesh.positions[b as usize] - p,
            );
            phi.push(theta[f as usize] - angle_in(&frames[f as usize], da));
            beta.push(da.angle_between(db));
        }
        let m = fan.len();
        let turning: f64 = (0..m)
            .map(|j| reduce_quarter(phi[(j + 1) % m] - (phi[j] - beta[j])))
            .sum();
        let defect = TAU - beta.iter().sum::<f64>();
        let index = ((turning + defect) / FRAC_PI_2).round() as i32;
        if index != 0 {
            out.push(Singularity {
                vertex: v as u32,
                index,
            });
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::layout::embed::embed_loop;
    use crate::mesh::generate::{flat_grid, icosphere};

    #[test]
    fn straight_line_on_a_plane_gives_a_constant_field() {
        let mesh = flat_grid(1.0, 20);
        let pts = [DVec3::new(-1.0, 0.013, 0.0), DVec3::new(1.0, 0.013, 0.0)];
        let l = embed_loop(&mesh, &pts, false).unwrap();
        let f = strip_field(&mesh, &[l]).unwrap();
        for c in &f.cross {
            let a = c.x.abs().min(1.0).acos().to_degrees();
            assert!(a.min(90.0 - a) < 1e-3, "{c}");
        }
        assert!(f.singularities.is_empty());
    }

    #[test]
    fn equator_gives_eight_plus_one_singularities() {
        let mesh = icosphere(1.0, 3);
        let pts: Vec<DVec3> = (0..=200)
            .map(|k| {
                let a = TAU * k as f64 / 200.0;
                DVec3::new(a.cos(), a.sin(), 0.0)
            })
            .collect();
        let l = embed_loop(&mesh, &pts, true).unwrap();
        let f = strip_field(&mesh, &[l]).unwrap();
        assert_eq!(f.singularities.len(), 8, "{:?}", f.singularities);
        assert!(f.singularities.iter().all(|s| s.index == 1));
        // Four near each pole.
        let north = f
            .singularities
            .iter()
            .filter(|s| mesh.positions[s.vertex as usize].z > 0.5)
            .count();
        let south = f
            .singularities
            .iter()
            .filter(|s| mesh.positions[s.vertex as usize].z < -0.5)
            .count();
        assert_eq!((north, south), (4, 4));
    }
}
