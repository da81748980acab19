//! Combing, matchings, the cut graph and wedges (Bommes et al. 2009, MIQ
//! §4; `../shared/reference/integer-grid-maps-digest.md` §2), shared by the
//! integer-grid map and the layout tool's strip parametrization.
//!
//! The crosses are combed along a breadth-first dual spanning tree (each
//! face's frame turned by quarter turns so the tree edges match with
//! rotation 0); the cut graph is the set of interior edges the tree does
//! not cross, with dangling branches pruned unless they end at an anchored
//! vertex (a cone) or the boundary; a wedge is a maximal set of corners
//! around one vertex joined across non-cut interior edges — one (u, v)
//! each. Non-manifold edges count as boundary.

// Parallel per-face arrays read best indexed.
#![allow(clippy::needless_range_loop)]

use std::collections::VecDeque;

use super::topology::EdgeTopology;
use crate::mesh::UnionFind;

/// What the cut is computed from.
pub struct CutInput<'a> {
    pub triangles: &'a [[u32; 3]],
    pub vertex_count: usize,
    pub topology: &'a EdgeTopology,
    /// Per face and local edge, before combing: k such that an edge vector
    /// in the neighbour's chart is `rotate(k, ·)` of ours (a direction's
    /// angle drops by k quarter turns from this face to the neighbour).
    pub raw_matching: &'a [[u8; 3]],
    /// Per vertex: keep cut branches ending here (cones).
    pub anchored: &'a [bool],
}

/// The combed frames, the cut graph and the wedges.
#[derive(Debug, Clone, PartialEq)]
pub struct Cut {
    /// Per face: quarter turns applied to its frame by the combing (the new
    /// u axis is the old v axis, once per turn).
    pub comb: Vec<u8>,
    /// Per face and local edge: the matching after combing.
    pub matching: Vec<[u8; 3]>,
    /// Per face and local edge: crossed by the dual spanning tree.
    pub tree: Vec<[bool; 3]>,
    /// Per face and local edge: on the cut graph.
    pub seam: Vec<[bool; 3]>,
    /// Per face corner: its wedge.
    pub wedge: Vec<[u32; 3]>,
    pub wedge_count: usize,
}

/// The breadth-first dual spanning tree (roots in face order) and the
/// quarter turns that make its edges match.
fn comb(input: &CutInput<'_>) -> (Vec<u8>, Vec<[bool; 3]>) {
    let nf = input.triangles.len();
    let top = input.topology;
    let mut turns = vec![0u8; nf];
    let mut tree = vec![[false; 3]; nf];
    let mut seen = vec![false; nf];
    for root in 0..nf {
        if seen[root] {
            continue;
        }
        seen[root] = true;
        let mut queue = VecDeque::from([root]);
        while let Some(f) = queue.pop_front() {
            for e in 0..3 {
                let Some((g, ge)) = top.across(f, e) else {
                    continue;
                };
                if seen[g] {
                    continue;
                }
                seen[g] = true;
                // Combed matching k − c_f + c_g ≡ 0.
                turns[g] = (turns[f] + 4 - input.raw_matching[f][e] % 4) % 4;
                tree[f][e] = true;
                tree[g][ge] = true;
                queue.push_back(g);
            }
        }
    }
    (turns, tree)
}

/// Interior non-tree edges, pruned of dangling branches.
fn cut_graph(input: &CutInput<'_>, tree: &[[bool; 3]]) -> Vec<[bool; 3]> {
    let (nf, nv, top) = (input.triangles.len(), input.vertex_count, input.topology);
    let mut anchored = vec![false; nv];
    for (v, &a) in input.anchored.iter().enumerate().take(nv) {
        anchored[v] = a;
    }
    let mut cut_edges: Vec<(usize, usize)> = Vec::new();
    for f in 0..nf {
        let t = input.triangles[f];
        for e in 0..3 {
            match top.across(f, e) {
                None => {
                    anchored[t[e] as usize] = true;
                    anchored[t[(e + 1) % 3] as usize] = true;
                }
                Some((g, _)) if g > f && !tree[f][e] => cut_edges.push((f, e)),
                _ => {}
            }
        }
    }
    let mut incident: Vec<Vec<u32>> = vec![Vec::new(); nv];
    for (i, &(f, e)) in cut_edges.iter().enumerate() {
        let t = input.triangles[f];
        incident[t[e] as usize].push(i as u32);
        incident[t[(e + 1) % 3] as usize].push(i as u32);
    }
    let mut alive = vec![true; cut_edges.len()];
    let mut degree: Vec<usize> = incident.iter().map(Vec::len).collect();
    let mut stack: Vec<usize> = (0..nv)
        .filter(|&v| degree[v] == 1 && !anchored[v])
        .collect();
    while let Some(v) = stack.pop() {
        if degree[v] != 1 {
            continue;
        }
        let Some(&i) = incident[v].iter().find(|&&i| alive[i as usize]) else {
            continue;
        };
        alive[i as usize] = false;
        let (f, e) = cut_edges[i as usize];
        let t = input.triangles[f];
        for w in [t[e] as usize, t[(e + 1) % 3] as usize] {
            degree[w] -= 1;
            if w != v && degree[w] == 1 && !anchored[w] {
                stack.push(w);
            }
        }
    }
    let mut seam = vec![[false; 3]; nf];
    for (i, &(f, e)) in cut_edges.iter().enumerate() {
        if alive[i] {
            if let Some((g, ge)) = top.across(f, e) {
                seam[f][e] = true;
                seam[g][ge] = true;
            }
        }
    }
    seam
}

/// Corners joined across non-seam interior edges.
fn wedges(input: &CutInput<'_>, seam: &[[bool; 3]]) -> (Vec<[u32; 3]>, usize) {
    let nf = input.triangles.len();
    let mut uf = UnionFind::new(3 * nf);
    for f in 0..nf {
        for e in 0..3 {
            let Some((g, ge)) = input.topology.across(f, e) else {
                continue;
            };
            if seam[f][e] || g < f {
                continue;
            }
            let (f3, g3) = (3 * f as u32, 3 * g as u32);
            // f's corner e ↔ g's corner ge + 1; f's e + 1 ↔ g's ge.
            uf.union(f3 + e as u32, g3 + (ge as u32 + 1) % 3);
            uf.union(f3 + (e as u32 + 1) % 3, g3 + ge as u32);
        }
    }
    let mut id = vec![u32::MAX; 3 * nf];
    let mut wedge = vec![[0u32; 3]; nf];
    let mut count = 0u32;
    for c in 0..3 * nf {
        let r = uf.find(c as u32) as usize;
        if id[r] == u32::MAX {
            id[r] = count;
            count += 1;
        }
        wedge[c / 3][c % 3] = id[r];
    }
    (wedge, count as usize)
}

/// Combs, cuts and splits the corners into wedges.
pub fn cut(input: &CutInput<'_>) -> Cut {
    let nf = input.triangles.len();
    let (comb, tree) = comb(input);
    let mut matching = vec![[0u8; 3]; nf];
    for f in 0..nf {
        for e in 0..3 {
            if let Some((g, _)) = input.topology.across(f, e) {
                let k = input.raw_matching[f][e] as i32 - comb[f] as i32 + comb[g] as i32;
                matching[f][e] = k.rem_euclid(4) as u8;
            }
        }
    }
    let seam = cut_graph(input, &tree);
    let (wedge, wedge_count) = wedges(input, &seam);
    Cut {
        comb,
        matching,
        tree,
        seam,
        wedge,
        wedge_count,
    }
}
