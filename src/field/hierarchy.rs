//! The multiresolution hierarchy of Instant Meshes (digest §2.1–2.3) with the
//! normal-based pair weights of Kloiber 2018 §3.1.4: pairs of neighbours are
//! scored by `dot(n_i, n_k) · max(A_i/A_k, A_k/A_i)` (barycentric cell areas
//! A) and merged greedily, best score first, roughly halving the vertex
//! count per level; every level gets a graph colouring so that each colour
//! class can be updated at once (phase-parallel Gauss–Seidel).
//!
//! Decisions on the digest's quirks: coarsening stops when a pass merges
//! nothing or a level has at most [`COARSEST_SIZE`] vertices (not at 25
//! identical copies, quirk 7); ties in the score sort break on the vertex
//! ids and unmatched vertices keep their order, so the hierarchy is the same
//! on every machine; the colouring is the deterministic greedy one over a
//! seeded shuffle.

use glam::Vec3;
use rand_core::{RngCore, SeedableRng};
use rand_pcg::Pcg32;

use crate::progress::{Cancelled, Progress};

/// Coarsening stops once a level has this many vertices or fewer.
pub const COARSEST_SIZE: usize = 8;
/// And after this many levels in any case.
pub const MAX_LEVELS: usize = 32;

/// Weighted links in compressed rows: the neighbours of `i` are
/// `ids[offsets[i]..offsets[i+1]]` with `weights` alongside. Level 0 has
/// weight 1 per mesh edge; coarse weights count the fine links they merge.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Links {
    pub offsets: Vec<u32>,
    pub ids: Vec<u32>,
    pub weights: Vec<f32>,
}

impl Links {
    /// From undirected edges (each listed once or twice; duplicates merge,
    /// self-loops are dropped), all with weight 1.
    pub fn from_edges(n: usize, edges: impl IntoIterator<Item = [u32; 2]>) -> Links {
        let mut pairs: Vec<(u32, u32, f32)> = Vec::new();
        for [a, b] in edges {
            if a != b {
                pairs.push((a, b, 1.0));
                pairs.push((b, a, 1.0));
            }
        }
        pairs.sort_unstable_by_key(|x| (x.0, x.1));
        pairs.dedup_by(|x, y| x.0 == y.0 && x.1 == y.1);
        Links::from_sorted(n, &pairs)
    }

    fn from_sorted(n: usize, pairs: &[(u32, u32, f32)]) -> Links {
        let mut offsets = vec![0u32; n + 1];
        for &(a, _, _) in pairs {
            offsets[a as usize + 1] += 1;
        }
        for i in 0..n {
            offsets[i + 1] += offsets[i];
        }
        Links {
            offsets,
            ids: pairs.iter().map(|p| p.1).collect(),
            weights: pairs.iter().map(|p| p.2).collect(),
        }
    }

    pub fn len(&self) -> usize {
        self.offsets.len().saturating_sub(1)
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// `(neighbour, weight)` pairs of vertex `i`.
    #[inline]
    pub fn of(&self, i: usize) -> impl Iterator<Item = (usize, f32)> + '_ {
        let r = self.offsets[i] as usize..self.offsets[i + 1] as usize;
        self.ids[r.clone()]
            .iter()
            .map(|&j| j as usize)
            .zip(self.weights[r].iter().copied())
    }

    pub fn degree(&self, i: usize) -> usize {
        (self.offsets[i + 1] - self.offsets[i]) as usize
    }
}

/// One level of the hierarchy: a vertex graph with geometry.
#[derive(Debug, Clone, Default)]
pub struct Level {
    pub positions: Vec<Vec3>,
    /// Unit normals (of the tangent planes the fields live in).
    pub normals: Vec<Vec3>,
    /// Barycentric cell areas (summed when merging).
    pub areas: Vec<f32>,
    pub links: Links,
    /// Colour classes: no two vertices of a class are linked.
    pub phases: Vec<Vec<u32>>,
    /// For each vertex, its one or two children on the finer level
    /// (`u32::MAX` when there is one); empty on level 0.
    pub to_finer: Vec<[u32; 2]>,
    /// For each vertex, its parent on the coarser level; empty on the top.
    pub to_coarser: Vec<u32>,
}

impl Level {
    pub fn len(&self) -> usize {
        self.positions.len()
    }

    pub fn is_empty(&self) -> bool {
        self.positions.is_empty()
    }

    /// The children of coarse vertex `i` on the finer level.
    #[inline]
    pub fn children(&self, i: usize) -> impl Iterator<Item = usize> + '_ {
        self.to_finer[i]
            .into_iter()
            .filter(|&c| c != u32::MAX)
            .map(|c| c as usize)
    }
}

/// Level 0 first, the coarsest last.
#[derive(Debug, Clone, Default)]
pub struct Hierarchy {
    pub levels: Vec<Level>,
}

impl Hierarchy {
    /// Builds the hierarchy over the level-0 graph.
    ///
    /// `positions`, `normals` (unit) and `areas` have one entry per vertex;
    /// `links` is the level-0 adjacency.
    pub fn build(
        positions: Vec<Vec3>,
        normals: Vec<Vec3>,
        areas: Vec<f32>,
        links: Links,
        seed: u64,
        progress: &mut Progress<'_>,
    ) -> Result<Hierarchy, Cancelled> {
        let mut level = Level {
            positions,
            normals,
            areas,
            links,
            ..Level::default()
        };
        level.phases = colour(&level.links, seed);
        let mut levels = vec![level];
        let total = levels[0].len().max(1) as f32;
        while levels.len() < MAX_LEVELS {
            let fine = levels.last_mut().expect("level 0 exists");
            if fine.len() <= COARSEST_SIZE {
                break;
            }
            let Some(mut coarse) = coarsen(fine) else {
                break;
            };
            coarse.phases = colour(&coarse.links, seed.wrapping_add(levels.len() as u64));
            let left = coarse.len() as f32;
            levels.push(coarse);
            progress.report(
                1.0 - left / total,
                &format!("hierarchy level {}", levels.len() - 1),
            )?;
        }
        Ok(Hierarchy { levels })
    }

    pub fn depth(&self) -> usize {
        self.levels.len()
    }
}

/// Merges the best-scoring disjoint pairs of `fine` (and records the maps on
/// `fine`); `None` when no pair can merge.
fn coarsen(fine: &mut Level) -> Option<Level> {
    let n = fine.len();
    let mut scored: Vec<(f32, u32, u32)> = Vec::with_capacity(fine.links.ids.len() / 2);
    for i in 0..n {
        for (k, _) in fine.links.of(i) {
            if k > i {
                let (ai, ak) = (
                    fine.areas[i].max(f32::MIN_POSITIVE),
                    fine.areas[k].max(f32::MIN_POSITIVE),
                );
                let score = fine.normals[i].dot(fine.normals[k]) * (ai / ak).max(ak / ai);
                scored.push((score, i as u32, k as u32));
            }
        }
    }
    scored.sort_unstable_by(|x, y| y.0.total_cmp(&x.0).then((x.1, x.2).cmp(&(y.1, y.2))));

    let mut matched = vec![false; n];
    let mut to_finer: Vec<[u32; 2]> = Vec::with_capacity(n / 2 + 1);
    for &(_, i, k) in &scored {
        if !matched[i as usize] && !matched[k as usize] {
            matched[i as usize] = true;
            matched[k as usize] = true;
            to_finer.push([i, k]);
        }
    }
    if to_finer.is_empty() {
        return None;
    }
    for (i, &m) in matched.iter().enumerate() {
        if !m {
            to_finer.push([i as u32, u32::MAX]);
        }
    }
    let mut to_coarser = vec![0u32; n];
    let mut coarse = Level {
        positions: Vec::with_capacity(to_finer.len()),
        normals: Vec::with_capacity(to_finer.len()),
        areas: Vec::with_capacity(to_finer.len()),
        ..Level::default()
    };
    for (c, &[a, b]) in to_finer.iter().enumerate() {
        to_coarser[a as usize] = c as u32;
        let (pa, na, wa) = (
            fine.positions[a as usize],
            fine.normals[a as usize],
            fine.areas[a as usize],
        );
        if b == u32::MAX {
            coarse.positions.push(pa);
            coarse.normals.push(na);
            coarse.areas.push(wa);
            continue;
        }
        to_coarser[b as usize] = c as u32;
        let b = b as usize;
        let (pb, nb, wb) = (fine.positions[b], fine.normals[b], fine.areas[b]);
        let w = wa + wb;
        coarse.positions.push(if w > 1e-30 {
            (wa * pa + wb * pb) / w
        } else {
            0.5 * (pa + pb)
        });
        coarse
            .normals
            .push((wa * na + wb * nb).try_normalize().unwrap_or(na));
        coarse.areas.push(w);
    }
    let mut pairs: Vec<(u32, u32, f32)> = Vec::with_capacity(fine.links.ids.len());
    for i in 0..n {
        let ci = to_coarser[i];
        for (k, w) in fine.links.of(i) {
            let ck = to_coarser[k];
            if ci != ck {
                pairs.push((ci, ck, w));
            }
        }
    }
    pairs.sort_unstable_by_key(|x| (x.0, x.1));
    let mut merged: Vec<(u32, u32, f32)> = Vec::with_capacity(pairs.len());
    for p in pairs {
        match merged.last_mut() {
            Some(last) if last.0 == p.0 && last.1 == p.1 => last.2 += p.2,
            _ => merged.push(p),
        }
    }
    coarse.links = Links::from_sorted(to_finer.len(), &merged);
    coarse.to_finer = to_finer;
    fine.to_coarser = to_coarser;
    Some(coarse)
}

/// Greedy colouring in a seeded random order: each vertex takes the
/// smallest colour none of its already coloured neighbours has.
fn colour(links: &Links, seed: u64) -> Vec<Vec<u32>> {
    let n = links.len();
    let mut order: Vec<u32> = (0..n as u32).collect();
    let mut rng = Pcg32::seed_from_u64(seed ^ 0x9e37_79b9_7f4a_7c15);
    for i in (1..n).rev() {
        let j = (rng.next_u64() % (i as u64 + 1)) as usize;
        order.swap(i, j);
    }
    let mut colour_of = vec![u32::MAX; n];
    let mut used: Vec<bool> = Vec::new();
    let mut phases: Vec<Vec<u32>> = Vec::new();
    for &v in &order {
        used.clear();
        used.resize(phases.len() + 1, false);
        for (k, _) in links.of(v as usize) {
            let c = colour_of[k];
            if (c as usize) < used.len() {
                used[c as usize] = true;
            }
        }
        let c = used.iter().position(|&u| !u).unwrap_or(used.len());
        if c == phases.len() {
            phases.push(Vec::new());
        }
        colour_of[v as usize] = c as u32;
        phases[c].push(v);
    }
    for phase in &mut phases {
        phase.sort_unstable();
    }
    phases
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::progress::silently;

    fn grid(n: usize) -> (Vec<Vec3>, Links) {
        let id = |i: usize, j: usize| (j * n + i) as u32;
        let mut edges = Vec::new();
        let mut p = Vec::new();
        for j in 0..n {
            for i in 0..n {
                p.push(Vec3::new(i as f32, j as f32, 0.0));
                if i + 1 < n {
                    edges.push([id(i, j), id(i + 1, j)]);
                }
                if j + 1 < n {
                    edges.push([id(i, j), id(i, j + 1)]);
                }
                if i + 1 < n && j + 1 < n {
                    edges.push([id(i, j), id(i + 1, j + 1)]);
                }
            }
        }
        (p, Links::from_edges(n * n, edges))
    }

    #[test]
    fn levels_halve_and_colourings_are_proper() {
        let (p, links) = grid(32);
        let n = p.len();
        let h = silently("hierarchy", |pr| {
            Hierarchy::build(p, vec![Vec3::Z; n], vec![1.0; n], links, 7, pr)
        })
        .unwrap();
        assert!(h.depth() >= 8, "depth {}", h.depth());
        assert!(h.levels.last().unwrap().len() <= COARSEST_SIZE);
        for (l, level) in h.levels.iter().enumerate() {
            if l > 0 {
                let ratio = level.len() as f32 / h.levels[l - 1].len() as f32;
                assert!((0.45..0.8).contains(&ratio), "level {l}: ratio {ratio}");
                // Areas are conserved.
                let a: f32 = level.areas.iter().sum();
                assert!((a - n as f32).abs() < 1e-2 * n as f32);
            }
            let mut seen = vec![0; level.len()];
            for phase in &level.phases {
                for &v in phase {
                    seen[v as usize] += 1;
                    for (k, _) in level.links.of(v as usize) {
                        assert!(
                            !phase.contains(&(k as u32)),
                            "level {l}: {v} and {k} share a colour"
                        );
                    }
                }
            }
            assert!(seen.iter().all(|&s| s == 1));
            // Links stay symmetric with equal weights.
            for i in 0..level.len() {
                for (k, w) in level.links.of(i) {
                    assert!(level.links.of(k).any(|(b, wb)| b == i && wb == w));
                }
            }
        }
    }
}
