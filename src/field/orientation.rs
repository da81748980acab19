//! The orientation field: extrinsic 4-RoSy smoothing of Instant Meshes
//! (digest §2.4–2.6, §3.3), solved coarse to fine, with the orientation
//! constraints of Kloiber 2018 §3.3 (feature vertices' principal directions)
//! and of any other source (smooth regions, strokes).
//!
//! Constraints are general: per vertex a direction and a weight. A weight of
//! `f32::INFINITY` fixes the cross (up to its symmetry); a finite weight `w`
//! pulls the neighbour average toward the constraint as
//! `normalize(average + w · constraint)`. Constraints are propagated to
//! coarse levels like Instant Meshes' `propagateConstraints` (matched
//! average of the children, weight = the larger child weight), so hard
//! constraints stay hard on every level.
//!
//! Decisions: the prolongated cross is normalised (digest quirk 10); after
//! the level-0 solve the result is restricted back up to every level,
//! because the position solve on coarse levels reads it (digest §2.5).

use glam::Vec3;
use rand_core::{RngCore, SeedableRng};
use rand_pcg::Pcg32;

use super::hierarchy::{Hierarchy, Level};
use super::lattice::{compat_orientation_extrinsic_4, coordinate_system};
use crate::parallel::map_into;
use crate::progress::{Cancelled, Progress};

/// Per-vertex orientation constraints on level 0 (weight 0 = none).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct OrientationConstraints {
    pub direction: Vec<Vec3>,
    pub weight: Vec<f32>,
}

impl OrientationConstraints {
    pub fn none(n: usize) -> Self {
        OrientationConstraints {
            direction: vec![Vec3::ZERO; n],
            weight: vec![0.0; n],
        }
    }

    /// Sets a constraint, keeping the stronger one if there is one already.
    pub fn set(&mut self, i: usize, direction: Vec3, weight: f32) {
        if weight >= self.weight[i] {
            self.direction[i] = direction;
            self.weight[i] = weight;
        }
    }

    pub fn count(&self) -> usize {
        self.weight.iter().filter(|&&w| w > 0.0).count()
    }

    /// The constraints of the next coarser level.
    pub(crate) fn restrict(&self, coarse: &Level, fine: &Level) -> OrientationConstraints {
        let mut out = OrientationConstraints::none(coarse.len());
        for c in 0..coarse.len() {
            let mut sum = Vec3::ZERO;
            let mut weight = 0.0f32;
            for child in coarse.children(c) {
                let w = self.weight[child];
                if w <= 0.0 {
                    continue;
                }
                let d = self.direction[child];
                sum = if sum == Vec3::ZERO {
                    d
                } else {
                    let (a, b) = compat_orientation_extrinsic_4(
                        sum,
                        coarse.normals[c],
                        d,
                        fine.normals[child],
                    );
                    a + b
                };
                weight = weight.max(w);
            }
            if weight > 0.0 {
                let n = coarse.normals[c];
                if let Some(d) = (sum - n * n.dot(sum)).try_normalize() {
                    out.direction[c] = d;
                    out.weight[c] = weight;
                }
            }
        }
        out
    }
}

/// Solves the orientation field on every level, coarse to fine, then
/// restricts the fine result back up. Returns `q` per level (unit tangent
/// vectors), level 0 first.
pub fn solve_orientation(
    hierarchy: &Hierarchy,
    constraints: &OrientationConstraints,
    iterations: usize,
    seed: u64,
    progress: &mut Progress<'_>,
) -> Result<Vec<Vec<Vec3>>, Cancelled> {
    let levels = &hierarchy.levels;
    let mut per_level = vec![constraints.clone()];
    for l in 1..levels.len() {
        let next = per_level[l - 1].restrict(&levels[l], &levels[l - 1]);
        per_level.push(next);
    }
    let top = levels.len() - 1;
    let mut q: Vec<Vec<Vec3>> = levels.iter().map(|_| Vec::new()).collect();
    q[top] = random_orientations(&levels[top], seed ^ top as u64);
    let mut scratch = Vec::new();
    let work: f32 = levels.iter().map(|l| l.len() as f32).sum::<f32>().max(1.0);
    let mut done = 0.0;
    for l in (0..=top).rev() {
        let level = &levels[l];
        if l < top {
            q[l] = prolongate(&levels[l + 1], level, &q[l + 1]);
            // Vertices with no links keep a random cross (never updated).
        }
        let cons = &per_level[l];
        for it in 0..iterations {
            for phase in &level.phases {
                let current = &q[l];
                map_into(phase, &mut scratch, |&i| {
                    update(level, current, cons, i as usize)
                });
                for (k, &i) in phase.iter().enumerate() {
                    q[l][i as usize] = scratch[k];
                }
            }
            progress.report(
                (done + level.len() as f32 * (it + 1) as f32 / iterations as f32) / work,
                &format!("orientation field, level {l}"),
            )?;
        }
        done += level.len() as f32;
    }
    for l in 1..=top {
        q[l] = restrict(&levels[l], &levels[l - 1], &q[l - 1]);
    }
    Ok(q)
}

/// One Gauss–Seidel step at vertex `i`: the running, normalised, matched
/// average of the neighbours' crosses, then the constraint.
#[inline]
fn update(level: &Level, q: &[Vec3], cons: &OrientationConstraints, i: usize) -> Vec3 {
    let n = level.normals[i];
    let w_c = cons.weight[i];
    if w_c == f32::INFINITY {
        return cons.direction[i];
    }
    let mut sum = q[i];
    let mut wsum = 0.0f32;
    for (j, w) in level.links.of(i) {
        let (a, b) = compat_orientation_extrinsic_4(sum, n, q[j], level.normals[j]);
        sum = a * wsum + b * w;
        sum -= n * n.dot(sum);
        wsum += w;
        sum = sum.try_normalize().unwrap_or(sum);
    }
    if w_c > 0.0 {
        let (a, b) = compat_orientation_extrinsic_4(sum, n, cons.direction[i], n);
        sum = a + w_c * b;
        sum -= n * n.dot(sum);
        sum = sum.try_normalize().unwrap_or(b);
    }
    if wsum > 0.0 || w_c > 0.0 { sum } else { q[i] }
}

/// A random unit tangent vector per vertex (seeded).
pub(crate) fn random_orientations(level: &Level, seed: u64) -> Vec<Vec3> {
    let mut rng = Pcg32::seed_from_u64(seed);
    level
        .normals
        .iter()
        .map(|&n| {
            let angle = (rng.next_u32() >> 8) as f32 / (1u32 << 24) as f32 * std::f32::consts::TAU;
            let (s, t) = coordinate_system(n);
            s * angle.cos() + t * angle.sin()
        })
        .collect()
}

/// Coarse → fine: each child takes its parent's cross, projected into its
/// own tangent plane.
fn prolongate(coarse: &Level, fine: &Level, q_coarse: &[Vec3]) -> Vec<Vec3> {
    let mut q = vec![Vec3::ZERO; fine.len()];
    for c in 0..coarse.len() {
        for child in coarse.children(c) {
            let n = fine.normals[child];
            let v = q_coarse[c] - n * n.dot(q_coarse[c]);
            q[child] = v.try_normalize().unwrap_or_else(|| coordinate_system(n).0);
        }
    }
    q
}

/// Fine → coarse: the matched sum of the children, projected and normalised.
fn restrict(coarse: &Level, fine: &Level, q_fine: &[Vec3]) -> Vec<Vec3> {
    (0..coarse.len())
        .map(|c| {
            let n = coarse.normals[c];
            let [a, b] = coarse.to_finer[c];
            let (a, b) = (a as usize, b as usize);
            let sum = if b == u32::MAX as usize {
                q_fine[a]
            } else {
                let (x, y) = compat_orientation_extrinsic_4(
                    q_fine[a],
                    fine.normals[a],
                    q_fine[b],
                    fine.normals[b],
                );
                x + y
            };
            (sum - n * n.dot(sum))
                .try_normalize()
                .unwrap_or_else(|| coordinate_system(n).0)
        })
        .collect()
}
