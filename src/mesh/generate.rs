//! Analytic test surfaces: meshes whose exact normals and curvatures are
//! known, for tests and benchmarks of every stage.
//!
//! All triangles are counter-clockwise seen from outside (normals point away
//! from the sphere/cylinder axis/torus tube, and towards +z for height
//! fields). Sizes are clamped to small minimums so no generator panics.

use std::collections::HashMap;
use std::f64::consts::TAU;

use glam::DVec3;

use super::{FaceList, TriMesh};

/// Sphere of `radius` about the origin: an icosahedron whose faces are split
/// into four `subdivisions` times, vertices projected onto the sphere.
/// Vertex count is `10 · 4^subdivisions + 2`.
pub fn icosphere(radius: f64, subdivisions: u32) -> TriMesh {
    let t = (1.0 + 5f64.sqrt()) / 2.0;
    let mut positions: Vec<DVec3> = [
        [-1.0, t, 0.0],
        [1.0, t, 0.0],
        [-1.0, -t, 0.0],
        [1.0, -t, 0.0],
        [0.0, -1.0, t],
        [0.0, 1.0, t],
        [0.0, -1.0, -t],
        [0.0, 1.0, -t],
        [t, 0.0, -1.0],
        [t, 0.0, 1.0],
        [-t, 0.0, -1.0],
        [-t, 0.0, 1.0],
    ]
    .iter()
    .map(|&p| DVec3::from_array(p).normalize())
    .collect();
    let mut triangles: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..subdivisions.min(8) {
        let mut midpoint: HashMap<(u32, u32), u32> = HashMap::new();
        let mut mid = |a: u32, b: u32, positions: &mut Vec<DVec3>| -> u32 {
            *midpoint.entry((a.min(b), a.max(b))).or_insert_with(|| {
                let p = (positions[a as usize] + positions[b as usize]).normalize();
                positions.push(p);
                (positions.len() - 1) as u32
            })
        };
        let mut next = Vec::with_capacity(triangles.len() * 4);
        for &[a, b, c] in &triangles {
            let ab = mid(a, b, &mut positions);
            let bc = mid(b, c, &mut positions);
            let ca = mid(c, a, &mut positions);
            next.extend_from_slice(&[[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        triangles = next;
    }
    for p in &mut positions {
        *p *= radius;
    }
    TriMesh {
        positions,
        triangles,
    }
}

/// Grid of `(nu + 1) × (nv + 1)` points `point(u, v)` for `u, v ∈ [0, 1]`,
/// each cell split into two triangles ordered counter-clockwise with respect
/// to `∂u × ∂v`. With `wrap_u`/`wrap_v` the last column/row is the first.
fn parametric(
    nu: u32,
    nv: u32,
    wrap_u: bool,
    wrap_v: bool,
    point: impl Fn(f64, f64) -> DVec3,
) -> TriMesh {
    let nu = nu.max(if wrap_u { 3 } else { 1 });
    let nv = nv.max(if wrap_v { 3 } else { 1 });
    let cols = if wrap_u { nu } else { nu + 1 };
    let rows = if wrap_v { nv } else { nv + 1 };
    let mut positions = Vec::with_capacity((cols * rows) as usize);
    for j in 0..rows {
        for i in 0..cols {
            positions.push(point(i as f64 / nu as f64, j as f64 / nv as f64));
        }
    }
    let index = |i: u32, j: u32| (j % rows) * cols + (i % cols);
    let mut triangles = Vec::with_capacity((2 * nu * nv) as usize);
    for j in 0..nv {
        for i in 0..nu {
            let (a, b, c, d) = (
                index(i, j),
                index(i + 1, j),
                index(i + 1, j + 1),
                index(i, j + 1),
            );
            triangles.push([a, b, c]);
            triangles.push([a, c, d]);
        }
    }
    TriMesh {
        positions,
        triangles,
    }
}

/// Open cylinder (no caps) of `radius` around the z axis, from
/// `z = -height/2` to `height/2`, with `segments` around and `stacks` along.
pub fn cylinder(radius: f64, height: f64, segments: u32, stacks: u32) -> TriMesh {
    parametric(segments, stacks, true, false, |u, v| {
        let a = TAU * u;
        DVec3::new(radius * a.cos(), radius * a.sin(), height * (v - 0.5))
    })
}

/// Closed capsule around the z axis: a cylinder of `radius` and `length`
/// (from `z = -length/2` to `length/2`, `stacks` rows of quads) with a
/// hemispherical cap at each end (`cap_rings` rings of latitude, a pole
/// vertex), `segments` around.
pub fn capsule(radius: f64, length: f64, segments: u32, cap_rings: u32, stacks: u32) -> TriMesh {
    let (n, caps, stacks) = (segments.max(3), cap_rings.max(1), stacks.max(1));
    // (z, ring radius) from the south cap's first ring to the north cap's last.
    let mut rings = Vec::new();
    for i in 1..=caps {
        let phi = std::f64::consts::FRAC_PI_2 * i as f64 / caps as f64;
        rings.push((-0.5 * length - radius * phi.cos(), radius * phi.sin()));
    }
    for j in 1..stacks {
        rings.push((length * (j as f64 / stacks as f64 - 0.5), radius));
    }
    for i in (1..=caps).rev() {
        let phi = std::f64::consts::FRAC_PI_2 * i as f64 / caps as f64;
        rings.push((0.5 * length + radius * phi.cos(), radius * phi.sin()));
    }
    let mut positions = vec![DVec3::new(0.0, 0.0, -0.5 * length - radius)];
    for &(z, r) in &rings {
        for i in 0..n {
            let a = TAU * i as f64 / n as f64;
            positions.push(DVec3::new(r * a.cos(), r * a.sin(), z));
        }
    }
    let north = positions.len() as u32;
    positions.push(DVec3::new(0.0, 0.0, 0.5 * length + radius));
    let at = |ring: usize, i: u32| 1 + ring as u32 * n + i % n;
    let mut triangles = Vec::new();
    for i in 0..n {
        triangles.push([0, at(0, i + 1), at(0, i)]);
    }
    for ring in 0..rings.len() - 1 {
        for i in 0..n {
            let (a, b, c, d) = (
                at(ring, i),
                at(ring, i + 1),
                at(ring + 1, i + 1),
                at(ring + 1, i),
            );
            triangles.push([a, b, c]);
            triangles.push([a, c, d]);
        }
    }
    let last = rings.len() - 1;
    for i in 0..n {
        triangles.push([at(last, i), at(last, i + 1), north]);
    }
    TriMesh {
        positions,
        triangles,
    }
}

/// Torus around the z axis: tube of radius `minor` whose centre circle has
/// radius `major`. The point at angles (u, v) is
/// `((major + minor cos v) cos u, (major + minor cos v) sin u, minor sin v)`;
/// `v = 0` is the outer equator.
pub fn torus(major: f64, minor: f64, major_segments: u32, minor_segments: u32) -> TriMesh {
    parametric(major_segments, minor_segments, true, true, |u, v| {
        let (a, b) = (TAU * u, TAU * v);
        let ring = major + minor * b.cos();
        DVec3::new(ring * a.cos(), ring * a.sin(), minor * b.sin())
    })
}

/// Height field `z = f(x, y)` over `[-half, half]²` sampled on an
/// `n × n`-cell grid.
pub fn height_field(half: f64, n: u32, f: impl Fn(f64, f64) -> f64) -> TriMesh {
    parametric(n, n, false, false, |u, v| {
        let (x, y) = (half * (2.0 * u - 1.0), half * (2.0 * v - 1.0));
        DVec3::new(x, y, f(x, y))
    })
}

/// Flat square `[-half, half]²` in the plane z = 0, `n × n` cells.
pub fn flat_grid(half: f64, n: u32) -> TriMesh {
    height_field(half, n, |_, _| 0.0)
}

/// The unit cells of `[0, n]²` (z = 0) that `keep(i, j)` keeps, cell (i, j)
/// at `[i, i + 1] × [j, j + 1]`, two triangles each: pixelated shapes,
/// whose boundaries are staircases. Every grid point is a vertex, used or
/// not.
pub fn grid_cells(n: usize, keep: impl Fn(usize, usize) -> bool) -> TriMesh {
    let mut positions = Vec::with_capacity((n + 1) * (n + 1));
    for j in 0..=n {
        for i in 0..=n {
            positions.push(DVec3::new(i as f64, j as f64, 0.0));
        }
    }
    let at = |i: usize, j: usize| (j * (n + 1) + i) as u32;
    let mut triangles = Vec::new();
    for j in 0..n {
        for i in (0..n).filter(|&i| keep(i, j)) {
            triangles.push([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
            triangles.push([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
        }
    }
    TriMesh {
        positions,
        triangles,
    }
}

/// Regular tetrahedron inscribed in the unit sphere.
pub fn tetrahedron() -> TriMesh {
    let s = 1.0 / 3f64.sqrt();
    TriMesh {
        positions: vec![
            DVec3::new(s, s, s),
            DVec3::new(s, -s, -s),
            DVec3::new(-s, s, -s),
            DVec3::new(-s, -s, s),
        ],
        triangles: vec![[0, 1, 2], [0, 3, 1], [0, 2, 3], [1, 3, 2]],
    }
}

/// The box `[-half, half]³` with edges rounded by fillets of `radius`
/// (quarter cylinders) and corners by sphere octants: the set of points at
/// distance `radius` from the box shrunk by `radius`. Each cube face is a
/// grid whose lines are spaced `flat_cells` across the flat part and
/// `fillet_cells` across each fillet band, so fillets are resolved at any
/// radius.
pub fn rounded_box(half: f64, radius: f64, flat_cells: u32, fillet_cells: u32) -> TriMesh {
    let radius = radius.clamp(1e-6 * half, half);
    let inner = half - radius;
    let (nf, nr) = (flat_cells.max(1), fillet_cells.max(1));
    let mut coords: Vec<f64> = Vec::new();
    for i in 0..nr {
        coords.push(-half + radius * i as f64 / nr as f64);
    }
    for i in 0..nf {
        coords.push(-inner + 2.0 * inner * i as f64 / nf as f64);
    }
    for i in 0..=nr {
        coords.push(inner + radius * i as f64 / nr as f64);
    }
    coords.dedup_by(|a, b| (*a - *b).abs() < 1e-12 * half);
    let m = coords.len();
    let mut index: HashMap<[i64; 3], u32> = HashMap::new();
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    let key = |q: DVec3| (q / half * 1e9).round().as_i64vec3().to_array();
    for axis in 0..3 {
        for sign in [-1.0, 1.0] {
            // (u, v) with u × v along the outward normal.
            let n = DVec3::from_array(std::array::from_fn(|k| if k == axis { sign } else { 0.0 }));
            let u = DVec3::from_array(std::array::from_fn(|k| {
                if k == (axis + 1) % 3 { 1.0 } else { 0.0 }
            }));
            let v = n.cross(u);
            let mut ids = vec![0u32; m * m];
            for (j, &b) in coords.iter().enumerate() {
                for (i, &a) in coords.iter().enumerate() {
                    let q = n * half + u * a + v * b;
                    let id = *index.entry(key(q)).or_insert_with(|| {
                        let c = q.clamp(DVec3::splat(-inner), DVec3::splat(inner));
                        positions.push(c + radius * (q - c).normalize());
                        (positions.len() - 1) as u32
                    });
                    ids[j * m + i] = id;
                }
            }
            for j in 0..m - 1 {
                for i in 0..m - 1 {
                    let (a, b, c, d) = (
                        ids[j * m + i],
                        ids[j * m + i + 1],
                        ids[(j + 1) * m + i + 1],
                        ids[(j + 1) * m + i],
                    );
                    triangles.push([a, b, c]);
                    triangles.push([a, c, d]);
                }
            }
        }
    }
    TriMesh {
        positions,
        triangles,
    }
}

/// The unit cube [0, 1]³ as six outward-oriented quads (vertex `i` at
/// `(i & 1, i >> 1 & 1, i >> 2 & 1)`).
pub fn unit_cube_quads() -> (Vec<DVec3>, FaceList) {
    let p = (0..8)
        .map(|i| DVec3::new((i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64))
        .collect();
    let mut faces = FaceList::new();
    for q in [
        [0, 2, 3, 1],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 4, 6, 2],
        [1, 3, 7, 5],
    ] {
        faces.push(&q);
    }
    (p, faces)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn outward(mesh: &TriMesh, center: impl Fn(DVec3) -> DVec3) -> bool {
        (0..mesh.face_count()).all(|f| {
            let [a, b, c] = mesh.corners(f);
            let centroid = (a + b + c) / 3.0;
            mesh.face_normal_unnormalized(f)
                .dot(centroid - center(centroid))
                > 0.0
        })
    }

    #[test]
    fn generated_meshes_are_valid_and_outward() {
        let s = icosphere(2.0, 2);
        s.validate().unwrap();
        assert_eq!(s.vertex_count(), 162);
        assert!(s.topology().is_closed_manifold());
        assert!(s.positions.iter().all(|p| (p.length() - 2.0).abs() < 1e-12));
        assert!(outward(&s, |_| DVec3::ZERO));

        let c = cylinder(1.0, 2.0, 16, 4);
        c.validate().unwrap();
        assert_eq!(c.vertex_count(), 16 * 5);
        assert!(outward(&c, |p| DVec3::new(0.0, 0.0, p.z)));

        let t = torus(2.0, 0.5, 24, 12);
        t.validate().unwrap();
        let topo = t.topology();
        assert!(topo.is_closed_manifold());
        assert_eq!(topo.genus(), Some(1));
        assert!(outward(&t, |p| {
            let r = DVec3::new(p.x, p.y, 0.0);
            r.normalize() * 2.0
        }));

        let h = height_field(1.0, 4, |x, y| x * y);
        h.validate().unwrap();
        assert!((0..h.face_count()).all(|f| h.face_normal_unnormalized(f).z > 0.0));

        let tet = tetrahedron();
        assert!(tet.topology().is_closed_manifold());
        assert!(outward(&tet, |_| DVec3::ZERO));
    }
}
