//! The position field: extrinsic 4-PoSy smoothing of Instant Meshes (digest
//! §4.4) with per-vertex lattice spacing (Kloiber 2018 §3.4).
//!
//! Every vertex `i` carries a lattice origin `o_i` in its tangent plane,
//! axes `q_i`, `n_i × q_i` from the orientation field, and spacing `s_i`
//! from the sizing field. One Gauss–Seidel step averages, over the
//! neighbours, the closest pair of lattice points of `i`'s and `j`'s lattices
//! near their middle point, then rounds the average to the lattice point of
//! `i`'s own lattice nearest to `v_i` (so `o_i` stays canonical). The thesis'
//! three scale modes choose the spacings used in that comparison:
//! [`ScaleMode::Average`] both `(s_i + s_j)/2`; [`ScaleMode::ReferencePoint`]
//! both `s_i`; [`ScaleMode::PerVertex`] (default, the thesis' best) each its
//! own.

use glam::Vec3;
use rand_core::{RngCore, SeedableRng};
use rand_pcg::Pcg32;
use serde::{Deserialize, Serialize};

use super::hierarchy::{Hierarchy, Level};
use super::lattice::{Lattice, compat_position_extrinsic_4, coordinate_system, position_round_4};
use super::orientation::OrientationConstraints;
use crate::parallel::map_into;
use crate::progress::{Cancelled, Progress};

/// How neighbouring lattices of different spacing are compared (Kloiber §3.4).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ScaleMode {
    /// Both lattices at the mean of the two spacings.
    Average,
    /// Both at the spacing of the vertex being updated.
    ReferencePoint,
    /// Each lattice at its own spacing.
    #[default]
    PerVertex,
}

impl ScaleMode {
    /// The lattice spacings used when vertex `i` (spacing `si`) meets its
    /// neighbour `j` (spacing `sj`).
    #[inline]
    pub fn spacings(self, si: f32, sj: f32) -> (f32, f32) {
        match self {
            ScaleMode::PerVertex => (si, sj),
            ScaleMode::ReferencePoint => (si, si),
            ScaleMode::Average => {
                let m = 0.5 * (si + sj);
                (m, m)
            }
        }
    }
}

/// Solves the position field coarse to fine. `q` holds the orientation
/// field per level, `scale` the lattice spacing per level. Returns the
/// lattice origins of level 0.
///
/// `alignment` (optional, level 0) strengthens agreement along a direction
/// per vertex: see [`update`].
#[allow(clippy::too_many_arguments)]
pub fn solve_position(
    hierarchy: &Hierarchy,
    q: &[Vec<Vec3>],
    scale: &[Vec<f32>],
    mode: ScaleMode,
    iterations: usize,
    seed: u64,
    alignment: Option<&OrientationConstraints>,
    progress: &mut Progress<'_>,
) -> Result<Vec<Vec3>, Cancelled> {
    let levels = &hierarchy.levels;
    let top = levels.len() - 1;
    let none = OrientationConstraints::none(levels[0].len());
    let mut per_level = vec![alignment.unwrap_or(&none).clone()];
    for l in 1..levels.len() {
        let next = per_level[l - 1].restrict(&levels[l], &levels[l - 1]);
        per_level.push(next);
    }
    let mut o = random_origins(&levels[top], &scale[top], seed ^ 0x5eed ^ top as u64);
    let mut scratch = Vec::new();
    let work: f32 = levels.iter().map(|l| l.len() as f32).sum::<f32>().max(1.0);
    let mut done = 0.0;
    for l in (0..=top).rev() {
        let level = &levels[l];
        if l < top {
            o = prolongate(&levels[l + 1], level, &o);
        }
        let (ql, sl, al) = (&q[l], &scale[l], &per_level[l]);
        for it in 0..iterations {
            for phase in &level.phases {
                let current = &o;
                map_into(phase, &mut scratch, |&i| {
                    update(level, ql, sl, current, mode, al, i as usize)
                });
                for (k, &i) in phase.iter().enumerate() {
                    o[i as usize] = scratch[k];
                }
            }
            progress.report(
                (done + level.len() as f32 * (it + 1) as f32 / iterations as f32) / work,
                &format!("position field, level {l}"),
            )?;
        }
        done += level.len() as f32;
    }
    Ok(o)
}

/// The lattice of vertex `i` with origin `o`.
#[inline]
pub fn lattice_at(level: &Level, q: &[Vec3], scale: &[f32], o: &[Vec3], i: usize) -> Lattice {
    Lattice {
        p: level.positions[i],
        n: level.normals[i],
        q: q[i],
        o: o[i],
        s: scale[i],
    }
}

/// One Gauss–Seidel step at vertex `i`.
///
/// Alignment (Campen et al. 2016 §4.2, adapted to the local update): the
/// paper adds `w (∇u · a_min)²` to the parametrisation energy so that the
/// coordinate `u` across `a_min` varies little *along* `a_min`. Here the
/// running mean is kept per tangent axis of vertex `i` — across `a_min` and
/// along it — and a neighbour's vote for the across-coordinate counts
/// `1 + w cos²θ` times, θ the angle between the link and `a_min`: the
/// finite-difference form of the same term. With no alignment this is the
/// plain update.
#[inline]
fn update(
    level: &Level,
    q: &[Vec3],
    scale: &[f32],
    o: &[Vec3],
    mode: ScaleMode,
    alignment: &OrientationConstraints,
    i: usize,
) -> Vec3 {
    let w_align = alignment.weight[i];
    if w_align > 0.0 && w_align.is_finite() {
        return update_aligned(level, q, scale, o, mode, alignment.direction[i], w_align, i);
    }
    let (v, n, qi, si) = (level.positions[i], level.normals[i], q[i], scale[i]);
    let mut sum = o[i];
    let mut wsum = 0.0f32;
    for (j, w) in level.links.of(i) {
        let (s0, s1) = mode.spacings(si, scale[j]);
        let l0 = Lattice {
            p: v,
            n,
            q: qi,
            o: sum,
            s: s0,
        };
        let l1 = Lattice {
            s: s1,
            ..lattice_at(level, q, scale, o, j)
        };
        let m = compat_position_extrinsic_4(&l0, &l1);
        sum = (m.p0 * wsum + m.p1 * w) / (wsum + w);
        wsum += w;
        sum -= n * n.dot(sum - v);
    }
    if wsum > 0.0 {
        position_round_4(sum, qi, n, v, si)
    } else {
        o[i]
    }
}

#[allow(clippy::too_many_arguments)]
fn update_aligned(
    level: &Level,
    q: &[Vec3],
    scale: &[f32],
    o: &[Vec3],
    mode: ScaleMode,
    along: Vec3,
    w_align: f32,
    i: usize,
) -> Vec3 {
    let (v, n, qi, si) = (level.positions[i], level.normals[i], q[i], scale[i]);
    let along = (along - n * n.dot(along)).normalize_or_zero();
    let across = n.cross(along);
    let (mut x, mut y) = ((o[i] - v).dot(across), (o[i] - v).dot(along));
    let (mut wx, mut wy) = (0.0f32, 0.0f32);
    for (j, w) in level.links.of(i) {
        let (s0, s1) = mode.spacings(si, scale[j]);
        let l0 = Lattice {
            p: v,
            n,
            q: qi,
            o: v + x * across + y * along,
            s: s0,
        };
        let l1 = Lattice {
            s: s1,
            ..lattice_at(level, q, scale, o, j)
        };
        let m = compat_position_extrinsic_4(&l0, &l1);
        let cos = (level.positions[j] - v).normalize_or_zero().dot(along);
        let w_across = w * (1.0 + w_align * cos * cos);
        x = ((m.p0 - v).dot(across) * wx + (m.p1 - v).dot(across) * w_across) / (wx + w_across);
        y = ((m.p0 - v).dot(along) * wy + (m.p1 - v).dot(along) * w) / (wy + w);
        wx += w_across;
        wy += w;
    }
    if wy > 0.0 {
        position_round_4(v + x * across + y * along, qi, n, v, si)
    } else {
        o[i]
    }
}

fn random_origins(level: &Level, scale: &[f32], seed: u64) -> Vec<Vec3> {
    let mut rng = Pcg32::seed_from_u64(seed);
    let mut uniform = move || (rng.next_u32() >> 8) as f32 / (1u32 << 23) as f32 - 1.0;
    (0..level.len())
        .map(|i| {
            let (s, t) = coordinate_system(level.normals[i]);
            let (x, y) = (uniform(), uniform());
            level.positions[i] + (s * x + t * y) * scale[i]
        })
        .collect()
}

/// Coarse → fine: each child takes its parent's origin, projected into its
/// own tangent plane.
fn prolongate(coarse: &Level, fine: &Level, o_coarse: &[Vec3]) -> Vec<Vec3> {
    let mut o = fine.positions.clone();
    for c in 0..coarse.len() {
        for child in coarse.children(c) {
            let n = fine.normals[child];
            o[child] = o_coarse[c] - n * n.dot(o_coarse[c] - fine.positions[child]);
        }
    }
    o
}
