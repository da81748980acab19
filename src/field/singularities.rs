//! Singularities of the fields on the level-0 triangles (digest §3.4, §4.6).
//!
//! Orientation: the rotations of the 4-RoSy field summed around a triangle,
//! mod 4; 1 and 3 are singular. A singularity of index +1/4 becomes an
//! irregular vertex of valence 3 in the quad mesh, −1/4 one of valence 5;
//! over a closed surface the indices sum to the Euler characteristic
//! (Poincaré–Hopf), which the tests check.
//!
//! Position: on triangles without an orientation singularity, the integer
//! lattice translations summed around the triangle (after turning the three
//! crosses into a common frame); a non-zero sum means the lattice does not
//! close up there.

use glam::{IVec2, Vec3};
use serde::{Deserialize, Serialize};

use super::hierarchy::Level;
use super::lattice::{
    Lattice, compat_orientation_extrinsic_index_4, compat_position_extrinsic_4, rotate90_by,
};

/// A singular triangle.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Singularity {
    pub face: u32,
    /// Orientation singularities: +1 for index +1/4 (valence 3 to be), −1
    /// for −1/4 (valence 5). Position singularities: 0.
    pub index: i32,
    /// The triangle's centroid, for drawing.
    pub position: Vec3,
}

impl Singularity {
    /// The valence the quad mesh vertex near it will have (orientation only).
    pub fn valence(&self) -> Option<u32> {
        match self.index {
            1 => Some(3),
            -1 => Some(5),
            _ => None,
        }
    }
}

/// The rotation index (0..4) of the orientation field around triangle `t`.
pub fn orientation_index(level: &Level, q: &[Vec3], t: [u32; 3]) -> u32 {
    let mut index = 0u32;
    for k in 0..3 {
        let (i, j) = (t[k] as usize, t[(k + 1) % 3] as usize);
        let (a, b) =
            compat_orientation_extrinsic_index_4(q[i], level.normals[i], q[j], level.normals[j]);
        index += b + 4 - a;
    }
    index % 4
}

/// The cross of vertex `j` turned to the representative closest to vertex
/// `a`'s own (rot(q_a, i) ≈ rot(q_j, k) means q_a ≈ rot(q_j, k − i)): the
/// common frame of a non-singular triangle.
pub fn turned_to(level: &Level, q: &[Vec3], a: usize, j: usize) -> Vec3 {
    let (i, k) =
        compat_orientation_extrinsic_index_4(q[a], level.normals[a], q[j], level.normals[j]);
    rotate90_by(q[j], level.normals[j], (k + 4 - i) % 4)
}

/// Orientation singularities: triangles whose index is 1 or 3.
pub fn orientation_singularities(
    level: &Level,
    q: &[Vec3],
    triangles: &[[u32; 3]],
) -> Vec<Singularity> {
    triangles
        .iter()
        .enumerate()
        .filter_map(|(f, &t)| {
            let index = match orientation_index(level, q, t) {
                // Rotation 1 around the triangle is index +1/4 (a sphere's
                // eight singularities all have it), 3 is −1/4.
                1 => 1,
                3 => -1,
                _ => return None,
            };
            Some(Singularity {
                face: f as u32,
                index,
                position: centroid(level, t),
            })
        })
        .collect()
}

/// Position singularities on triangles free of orientation singularities.
pub fn position_singularities(
    level: &Level,
    q: &[Vec3],
    scale: &[f32],
    o: &[Vec3],
    triangles: &[[u32; 3]],
) -> Vec<Singularity> {
    let mut out = Vec::new();
    for (f, &t) in triangles.iter().enumerate() {
        if orientation_index(level, q, t) != 0 {
            continue;
        }
        let [a, b, c] = t.map(|i| i as usize);
        let frames = [q[a], turned_to(level, q, a, b), turned_to(level, q, a, c)];
        let lattice = |k: usize, i: usize| Lattice {
            p: level.positions[i],
            n: level.normals[i],
            q: frames[k],
            o: o[i],
            s: scale[i],
        };
        let mut sum = IVec2::ZERO;
        for k in 0..3 {
            let (i, j) = ([a, b, c][k], [a, b, c][(k + 1) % 3]);
            let m = compat_position_extrinsic_4(&lattice(k, i), &lattice((k + 1) % 3, j));
            sum += m.u0 - m.u1;
        }
        if sum != IVec2::ZERO {
            out.push(Singularity {
                face: f as u32,
                index: 0,
                position: centroid(level, t),
            });
        }
    }
    out
}

fn centroid(level: &Level, t: [u32; 3]) -> Vec3 {
    t.iter().map(|&i| level.positions[i as usize]).sum::<Vec3>() / 3.0
}
