//! The 4-RoSy and 4-PoSy compatibility functions of Instant Meshes (Jakob et
//! al. 2015; `../shared/reference/instant-meshes-digest.md` §3.1–3.2, §4.1–4.3),
//! extrinsic variants, with a per-vertex lattice scale (Kloiber 2018, §3.4):
//! each vertex's lattice has its own spacing `s`, and every floor, round and
//! corner offset uses the scale of the lattice it belongs to.

use glam::{IVec2, Vec3};

/// `n × q`: `q` turned by 90° about `n`.
#[inline]
pub fn rotate90(q: Vec3, n: Vec3) -> Vec3 {
    n.cross(q)
}

/// `q` turned by `k` × 90° about `n`.
#[inline]
pub fn rotate90_by(q: Vec3, n: Vec3, k: u32) -> Vec3 {
    let r = if k % 2 == 1 { n.cross(q) } else { q };
    if k % 4 >= 2 { -r } else { r }
}

/// Integer lattice offsets turned by `k` × 90°: (u, v) → (−v, u) per step.
#[inline]
pub fn rshift90(u: IVec2, k: u32) -> IVec2 {
    let r = if k % 2 == 1 { IVec2::new(-u.y, u.x) } else { u };
    if k % 4 >= 2 { -r } else { r }
}

/// Extrinsic 4-RoSy compatibility: the representatives of the two crosses
/// (`q0`, `q1` at normals `n0`, `n1`) that are closest as 3D vectors, as
/// `(r0, r1)`. Both may be turned; ties keep the first pair in the order
/// (0,0), (0,1), (1,0), (1,1).
#[inline]
pub fn compat_orientation_extrinsic_4(q0: Vec3, n0: Vec3, q1: Vec3, n1: Vec3) -> (Vec3, Vec3) {
    let (a, b, dot) = best_pair(q0, n0, q1, n1);
    let r0 = if a == 1 { n0.cross(q0) } else { q0 };
    let r1 = if b == 1 { n1.cross(q1) } else { q1 };
    (r0, if dot < 0.0 { -r1 } else { r1 })
}

/// The integer form: `(a, b)` with `q0` turned `a` times and `q1` turned
/// `b` times matching; the rotation from 0 to 1 is `b − a` (mod 4).
#[inline]
pub fn compat_orientation_extrinsic_index_4(q0: Vec3, n0: Vec3, q1: Vec3, n1: Vec3) -> (u32, u32) {
    let (a, b, dot) = best_pair(q0, n0, q1, n1);
    (a, b + if dot < 0.0 { 2 } else { 0 })
}

#[inline]
fn best_pair(q0: Vec3, n0: Vec3, q1: Vec3, n1: Vec3) -> (u32, u32, f32) {
    let a = [q0, n0.cross(q0)];
    let b = [q1, n1.cross(q1)];
    let mut best = (0, 0, a[0].dot(b[0]));
    for (i, ai) in a.iter().enumerate() {
        for (j, bj) in b.iter().enumerate() {
            let d = ai.dot(*bj);
            if d.abs() > best.2.abs() {
                best = (i as u32, j as u32, d);
            }
        }
    }
    best
}

/// The point closest to `p0` and `p1` that lies in both tangent planes
/// (least squares with Lagrange multipliers, regularised for parallel normals).
#[inline]
pub fn middle_point(p0: Vec3, n0: Vec3, p1: Vec3, n1: Vec3) -> Vec3 {
    let c = n0.dot(n1);
    let d = 1.0 / (1.0 - c * c + 1e-4);
    let l0 = 2.0 * (n0.dot(p1) - n0.dot(p0) - c * (n1.dot(p0) - n1.dot(p1))) * d;
    let l1 = 2.0 * (n1.dot(p0) - n1.dot(p1) - c * (n0.dot(p1) - n0.dot(p0))) * d;
    0.5 * (p0 + p1) - 0.25 * (l0 * n0 + l1 * n1)
}

/// Integer coordinates of the lattice cell (origin `o`, axes `q`, `n × q`,
/// spacing `s`) containing `p`, rounded down.
#[inline]
pub fn lattice_floor(o: Vec3, q: Vec3, n: Vec3, p: Vec3, s: f32) -> IVec2 {
    let t = n.cross(q);
    let d = p - o;
    IVec2::new((q.dot(d) / s).floor() as i32, (t.dot(d) / s).floor() as i32)
}

/// Integer coordinates of the lattice point nearest to `p` (per axis).
#[inline]
pub fn lattice_round(o: Vec3, q: Vec3, n: Vec3, p: Vec3, s: f32) -> IVec2 {
    let t = n.cross(q);
    let d = p - o;
    IVec2::new((q.dot(d) / s).round() as i32, (t.dot(d) / s).round() as i32)
}

/// The 3D point of integer lattice coordinates `u`.
#[inline]
pub fn lattice_point(o: Vec3, q: Vec3, n: Vec3, u: IVec2, s: f32) -> Vec3 {
    o + s * (u.x as f32 * q + u.y as f32 * n.cross(q))
}

/// The lattice point nearest to `p`.
#[inline]
pub fn position_round_4(o: Vec3, q: Vec3, n: Vec3, p: Vec3, s: f32) -> Vec3 {
    lattice_point(o, q, n, lattice_round(o, q, n, p, s), s)
}

/// One vertex's lattice: position `p`, normal `n`, orientation `q`, origin `o`, spacing `s`.
#[derive(Debug, Clone, Copy)]
pub struct Lattice {
    pub p: Vec3,
    pub n: Vec3,
    pub q: Vec3,
    pub o: Vec3,
    pub s: f32,
}

/// The closest pair of lattice points of two lattices near their middle
/// point: extrinsic 4-PoSy compatibility.
#[derive(Debug, Clone, Copy)]
pub struct PositionMatch {
    pub p0: Vec3,
    pub p1: Vec3,
    /// Integer coordinates of `p0` in lattice 0 and of `p1` in lattice 1.
    pub u0: IVec2,
    pub u1: IVec2,
    /// Squared distance between `p0` and `p1`.
    pub error: f32,
}

/// Extrinsic 4-PoSy compatibility with each lattice at its own spacing:
/// among the four cell corners of each lattice around the middle point,
/// the pair that is closest (first strict minimum wins, lattice 0 outer).
#[inline]
pub fn compat_position_extrinsic_4(l0: &Lattice, l1: &Lattice) -> PositionMatch {
    let m = middle_point(l0.p, l0.n, l1.p, l1.n);
    let f0 = lattice_floor(l0.o, l0.q, l0.n, m, l0.s);
    let f1 = lattice_floor(l1.o, l1.q, l1.n, m, l1.s);
    let (t0, t1) = (l0.n.cross(l0.q), l1.n.cross(l1.q));
    let base0 = l0.o + l0.s * (f0.x as f32 * l0.q + f0.y as f32 * t0);
    let base1 = l1.o + l1.s * (f1.x as f32 * l1.q + f1.y as f32 * t1);
    let corner0 = [
        base0,
        base0 + l0.s * l0.q,
        base0 + l0.s * t0,
        base0 + l0.s * (l0.q + t0),
    ];
    let corner1 = [
        base1,
        base1 + l1.s * l1.q,
        base1 + l1.s * t1,
        base1 + l1.s * (l1.q + t1),
    ];
    let mut best = (0usize, 0usize, f32::INFINITY);
    for (i, c0) in corner0.iter().enumerate() {
        for (j, c1) in corner1.iter().enumerate() {
            let e = c0.distance_squared(*c1);
            if e < best.2 {
                best = (i, j, e);
            }
        }
    }
    let offset = |k: usize| IVec2::new((k & 1) as i32, (k >> 1) as i32);
    PositionMatch {
        p0: corner0[best.0],
        p1: corner1[best.1],
        u0: f0 + offset(best.0),
        u1: f1 + offset(best.1),
        error: best.2,
    }
}

/// An orthonormal tangent frame `(s, t)` for unit normal `n`.
pub fn coordinate_system(n: Vec3) -> (Vec3, Vec3) {
    let c = if n.x.abs() > n.y.abs() {
        Vec3::new(n.z, 0.0, -n.x) / (n.x * n.x + n.z * n.z).sqrt()
    } else {
        Vec3::new(0.0, n.z, -n.y) / (n.y * n.y + n.z * n.z).sqrt()
    };
    (c.cross(n), c)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn orientation_compat_is_invariant_under_quarter_turns() {
        let n = Vec3::Z;
        let q0 = Vec3::new(1.0, 0.2, 0.0).normalize();
        let q1 = Vec3::new(0.9, 0.3, 0.0).normalize();
        for k in 0..4 {
            let (r0, r1) = compat_orientation_extrinsic_4(q0, n, rotate90_by(q1, n, k), n);
            assert!(r0.dot(r1) > 0.99, "k={k}");
            let (a, b) = compat_orientation_extrinsic_index_4(q0, n, rotate90_by(q1, n, k), n);
            // q1 turned k times matches q0 after turning it back: b − a ≡ −k.
            assert_eq!((b + 4 * 4 - a) % 4, (4 - k) % 4, "k={k}");
        }
    }

    #[test]
    fn middle_point_lies_in_both_planes() {
        let (p0, n0) = (Vec3::ZERO, Vec3::Z);
        let (p1, n1) = (
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(-1.0, 0.0, 1.0).normalize(),
        );
        let m = middle_point(p0, n0, p1, n1);
        assert!(n0.dot(m - p0).abs() < 1e-3);
        assert!(n1.dot(m - p1).abs() < 1e-3);
    }

    #[test]
    fn position_compat_finds_the_shared_lattice_point() {
        let n = Vec3::Z;
        let q = Vec3::X;
        // Two vertices on the same unit lattice (origins differ by a lattice vector).
        let l0 = Lattice {
            p: Vec3::new(0.1, 0.2, 0.0),
            n,
            q,
            o: Vec3::ZERO,
            s: 1.0,
        };
        let l1 = Lattice {
            p: Vec3::new(0.9, 0.3, 0.0),
            n,
            q: Vec3::Y,
            o: Vec3::new(1.0, 0.0, 0.0),
            s: 1.0,
        };
        let m = compat_position_extrinsic_4(&l0, &l1);
        assert!(m.error < 1e-10, "{m:?}");
        assert!(m.p0.distance(m.p1) < 1e-5);
    }
}
