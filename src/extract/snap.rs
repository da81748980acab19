//! Snapping thin triangles and removing quad diagonals in the vertex graph:
//! Instant Meshes' step 5 (digest §5.6) with Kloiber 2018 §3.5.2.
//!
//! - Threshold per candidate triangle `(i, j, k)`: 10 % of each of the three
//!   vertices' scales, summed (the thesis; equals IM's 0.3·s for one scale).
//! - A merge keeps the position of the vertex with the greater curvature
//!   (thesis) instead of the midpoint; the other attributes are averaged by
//!   cluster size, the normal renormalised (IM quirk 4 fixed).
//! - Collinear snapping (moving `i` onto edge `jk`) only when `i` is not a
//!   geometric feature vertex and its cluster holds fewer than two feature
//!   vertices, or when all three clusters hold more than one (thesis).
//!   The geometric test: normals of consecutive neighbour pairs of the
//!   angle-sorted ring (a pair closer than 10° takes the next neighbour)
//!   differing by more than 45°.
//! - IM's "recomputed height is bit-equal" staleness test becomes "none of
//!   the three vertices moved or merged since the candidates were collected".
//! - Diagonal removal as IM: edges bordering exactly two graph triangles,
//!   most diagonal-like first, no threshold.

use glam::DVec3;

use super::clusters::Graph;
use crate::progress::{Cancelled, Progress};

/// Counts of what snapping did.
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SnapReport {
    pub merges: usize,
    pub collinear_snaps: usize,
    pub removed_diagonals: usize,
}

/// Angle-sorted ring of `v` (counter-clockwise about its normal).
pub fn sorted_ring(g: &Graph, v: usize) -> Vec<u32> {
    let n = g.normal[v];
    let s = n.any_orthonormal_vector();
    let t = n.cross(s);
    let mut ring: Vec<(f64, u32)> = g.adj[v]
        .iter()
        .map(|&j| {
            let d = g.pos[j as usize] - g.pos[v];
            (t.dot(d).atan2(s.dot(d)), j)
        })
        .collect();
    ring.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    ring.into_iter().map(|x| x.1).collect()
}

/// Thesis §3.5.2's geometric feature test on the potential faces around `v`.
fn is_geometric_feature(g: &Graph, v: usize) -> bool {
    let ring = sorted_ring(g, v);
    let k = ring.len();
    if k < 3 {
        return false;
    }
    let p = g.pos[v];
    let mut normals: Vec<DVec3> = Vec::with_capacity(k);
    for a in 0..k {
        let da = g.pos[ring[a] as usize] - p;
        let mut b = (a + 1) % k;
        let mut db = g.pos[ring[b] as usize] - p;
        if da.angle_between(db).to_degrees() < 10.0
            || (180.0 - da.angle_between(db).to_degrees()) < 10.0
        {
            b = (a + 2) % k;
            db = g.pos[ring[b] as usize] - p;
        }
        if let Some(n) = da.cross(db).try_normalize() {
            normals.push(n);
        }
    }
    let cos45 = std::f64::consts::FRAC_PI_4.cos();
    for a in 0..normals.len() {
        for b in a + 1..normals.len() {
            if normals[a].dot(normals[b]) < cos45 {
                return true;
            }
        }
    }
    false
}

fn height(pi: DVec3, pj: DVec3, pk: DVec3) -> Option<f64> {
    let a = pj.distance(pk);
    let b = pi.distance(pj);
    let c = pi.distance(pk);
    if a <= b.max(c) || a <= 0.0 {
        return None;
    }
    let s = 0.5 * (a + b + c);
    let area2 = (s * (s - a) * (s - b) * (s - c)).max(0.0);
    Some(2.0 * area2.sqrt() / a)
}

/// Merges `m` into `i`.
fn merge(g: &mut Graph, i: usize, m: usize, alive: &mut [bool]) {
    let (si, sm) = (g.size[i].max(1) as f64, g.size[m].max(1) as f64);
    let w = si + sm;
    if g.curvature[m] > g.curvature[i] {
        g.pos[i] = g.pos[m];
    }
    g.normal[i] = ((si * g.normal[i] + sm * g.normal[m]) / w)
        .try_normalize()
        .unwrap_or(g.normal[i]);
    g.scale[i] = (si * g.scale[i] + sm * g.scale[m]) / w;
    g.curvature[i] = g.curvature[i].max(g.curvature[m]);
    g.feature_count[i] += g.feature_count[m];
    g.size[i] += g.size[m];
    g.boundary[i] |= g.boundary[m];
    if g.boundary_loop[i] == u32::MAX {
        g.boundary_loop[i] = g.boundary_loop[m];
    }
    let list = std::mem::take(&mut g.adj[m]);
    for x in list {
        g.adj[x as usize].retain(|&y| y != m as u32);
        if x as usize != i {
            g.add_edge(i as u32, x);
        }
    }
    alive[m] = false;
}

/// Runs the snapping and diagonal removal until nothing changes.
pub fn snap(g: &mut Graph, progress: &mut Progress<'_>) -> Result<SnapReport, Cancelled> {
    let mut report = SnapReport::default();
    let mut alive = vec![true; g.len()];
    for outer in 0..64 {
        progress.report(0.4 + 0.005 * outer as f32, "snapping thin triangles")?;
        let mut changed = false;
        for _inner in 0..64 {
            let mut candidates: Vec<(f64, u32, u32, u32)> = Vec::new();
            for j in 0..g.len() {
                if !alive[j] {
                    continue;
                }
                let nj = &g.adj[j];
                for &i in nj {
                    for &k in nj {
                        if i == k {
                            continue;
                        }
                        let (i, k) = (i as usize, k as usize);
                        if let Some(h) = height(g.pos[i], g.pos[j], g.pos[k]) {
                            let thresh = 0.1 * (g.scale[i] + g.scale[j] + g.scale[k]);
                            if h < thresh {
                                candidates.push((h, i as u32, j as u32, k as u32));
                            }
                        }
                    }
                }
            }
            if candidates.is_empty() {
                break;
            }
            candidates.sort_by(|a, b| {
                a.0.total_cmp(&b.0)
                    .then((a.1, a.2, a.3).cmp(&(b.1, b.2, b.3)))
            });
            let mut touched = vec![false; g.len()];
            let mut snapped = false;
            for &(_, i, j, k) in &candidates {
                let (i, j, k) = (i as usize, j as usize, k as usize);
                if touched[i] || touched[j] || touched[k] || !alive[i] || !alive[j] || !alive[k] {
                    continue;
                }
                if !g.has_edge(i as u32, j as u32) || !g.has_edge(j as u32, k as u32) {
                    continue;
                }
                let thresh = 0.1 * (g.scale[i] + g.scale[j] + g.scale[k]);
                let m = if g.pos[i].distance(g.pos[j]) < thresh {
                    Some(j)
                } else if g.pos[i].distance(g.pos[k]) < thresh {
                    Some(k)
                } else {
                    None
                };
                match m {
                    Some(m) => {
                        merge(g, i, m, &mut alive);
                        report.merges += 1;
                    }
                    None => {
                        let fc = &g.feature_count;
                        let allowed = (!is_geometric_feature(g, i) && fc[i] < 2)
                            || (fc[i] > 1 && fc[j] > 1 && fc[k] > 1);
                        if !allowed {
                            continue;
                        }
                        g.pos[i] = 0.5 * (g.pos[j] + g.pos[k]);
                        g.normal[i] = (g.normal[j] + g.normal[k])
                            .try_normalize()
                            .unwrap_or(g.normal[i]);
                        g.remove_edge(j as u32, k as u32);
                        g.add_edge(i as u32, k as u32);
                        report.collinear_snaps += 1;
                    }
                }
                touched[i] = true;
                touched[j] = true;
                touched[k] = true;
                snapped = true;
            }
            if !snapped {
                break;
            }
            changed = true;
        }

        // Quad diagonals: edges bordering exactly two graph triangles.
        let common = |g: &Graph, i: usize, j: usize| -> Vec<u32> {
            g.adj[i]
                .iter()
                .copied()
                .filter(|&k| g.adj[j].contains(&k))
                .collect()
        };
        let mut diagonals: Vec<(f64, u32, u32)> = Vec::new();
        for i in 0..g.len() {
            for &j in &g.adj[i] {
                let j = j as usize;
                if j <= i {
                    continue;
                }
                let c = common(g, i, j);
                if c.len() != 2 {
                    continue;
                }
                let l: f64 = c
                    .iter()
                    .map(|&k| {
                        g.pos[k as usize].distance(g.pos[i]) + g.pos[k as usize].distance(g.pos[j])
                    })
                    .sum();
                let expected = l / 4.0 * std::f64::consts::SQRT_2;
                let d = g.pos[i].distance(g.pos[j]);
                let score = ((d - expected) / d.min(expected).max(1e-300)).abs();
                diagonals.push((score, i as u32, j as u32));
            }
        }
        diagonals.sort_by(|a, b| a.0.total_cmp(&b.0).then((a.1, a.2).cmp(&(b.1, b.2))));
        for &(_, i, j) in &diagonals {
            if common(g, i as usize, j as usize).len() == 2 {
                g.remove_edge(i, j);
                report.removed_diagonals += 1;
                changed = true;
            }
        }
        if !changed {
            break;
        }
    }
    // Dead (merged) vertices have no links; the face step ignores them.
    Ok(report)
}
