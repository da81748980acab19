//! Faces from the vertex graph: Instant Meshes' steps 6–8 (digest §5.7–5.10)
//! with Kloiber 2018 §3.5.3.
//!
//! The graph becomes a rotation system (neighbours sorted by angle about the
//! cluster normal) and every orbit of it is a candidate face. IM walks
//! orbits by target size 3, 4, …, 8; since every directed link lies on
//! exactly one orbit the set of faces does not depend on that order (digest
//! §5.8), so all orbits are traced once. An orbit that revisits a vertex is
//! cut into simple loops at the repeats (spurs of length 2 vanish).
//!
//! Loops of up to 8 corners are faces; longer loops up to `max_hole` (30,
//! thesis) are holes and filled the same way. Loops that run along the
//! input's boundary are kept open (the input's own holes). Faces of more than
//! 5 corners are split by [`fill_polygon`] with the thesis' score (the four
//! corner angles of the candidate quad itself, not IM's four consecutive
//! ring angles); triangles and pentagons stay single polygons (IM's
//! centroid fans are an internal representation we do not need).

use glam::DVec3;

use super::clusters::Graph;

/// Traces every orbit of the rotation system of `g` (neighbours sorted
/// counter-clockwise about the vertex normal: faces come out
/// counter-clockwise, i.e. oriented like the input) and cuts it into simple
/// loops.
pub fn trace_loops(g: &Graph) -> Vec<Vec<u32>> {
    let n = g.len();
    let rings: Vec<Vec<u32>> = (0..n).map(|v| super::snap::sorted_ring(g, v)).collect();
    let mut offset = vec![0usize; n + 1];
    for v in 0..n {
        offset[v + 1] = offset[v] + rings[v].len();
    }
    let mut used = vec![false; offset[n]];
    let mut loops = Vec::new();
    let mut orbit = Vec::new();
    for v in 0..n {
        for k in 0..rings[v].len() {
            if used[offset[v] + k] {
                continue;
            }
            orbit.clear();
            let (mut cur, mut idx) = (v, k);
            loop {
                let h = offset[cur] + idx;
                if used[h] {
                    break;
                }
                used[h] = true;
                orbit.push(cur as u32);
                let nxt = rings[cur][idx] as usize;
                let Some(r) = rings[nxt].iter().position(|&x| x as usize == cur) else {
                    break;
                };
                // Arriving at `nxt` from `cur`, leave by the neighbour just
                // clockwise of `cur`: the face lies to the left (CCW).
                let deg = rings[nxt].len();
                cur = nxt;
                idx = (r + deg - 1) % deg;
            }
            simple_loops(&orbit, &mut loops);
        }
    }
    loops
}

/// Cuts a closed vertex sequence into simple loops at repeated vertices;
/// pieces with fewer than 3 corners (spurs) are dropped.
pub fn simple_loops(seq: &[u32], out: &mut Vec<Vec<u32>>) {
    let mut stack: Vec<u32> = Vec::with_capacity(seq.len());
    for &v in seq {
        if let Some(t) = stack.iter().position(|&x| x == v) {
            if stack.len() - t >= 3 {
                out.push(stack[t..].to_vec());
            }
            stack.truncate(t + 1);
        } else {
            stack.push(v);
        }
    }
    if stack.len() >= 3 {
        out.push(stack);
    }
}

/// The angle at `b` between `a` and `c`, in degrees.
fn corner_angle(a: DVec3, b: DVec3, c: DVec3) -> f64 {
    let (u, v) = (a - b, c - b);
    if u.length_squared() == 0.0 || v.length_squared() == 0.0 {
        return 0.0;
    }
    u.angle_between(v).to_degrees()
}

/// Kloiber's quad score (§3.5.3): Σ |90° − corner angle| over the four
/// corners of the quad `q` itself.
pub fn quad_score(pos: &[DVec3], q: [u32; 4]) -> f64 {
    (0..4)
        .map(|j| {
            let a = pos[q[(j + 3) % 4] as usize];
            let b = pos[q[j] as usize];
            let c = pos[q[(j + 1) % 4] as usize];
            (90.0 - corner_angle(a, b, c)).abs()
        })
        .sum()
}

/// Instant Meshes' quad score (digest §5.9): Σ |90° − angle| at the ring
/// corners `i+1 … i+4`, i.e. the quad's two inner corners and the two ring
/// corners beyond it.
fn ring_score(pos: &[DVec3], ring: &[u32], i: usize) -> f64 {
    let m = ring.len();
    let p = |k: usize| pos[ring[k % m] as usize];
    (0..4)
        .map(|k| (90.0 - corner_angle(p(i + k), p(i + k + 1), p(i + k + 2))).abs())
        .sum()
}

/// Splits polygon `ring` into quads until at most 5 corners remain, taking
/// the best-scoring quad of four consecutive corners each time (the
/// thesis' score, [`quad_score`], when `thesis_score`, else Instant Meshes'
/// ring score); `is_edge` tells which chords already exist elsewhere (those
/// candidates are taken only when nothing else is left). Triangles, quads
/// and pentagons are emitted as they are.
pub fn fill_polygon(
    pos: &[DVec3],
    ring: &[u32],
    is_edge: &dyn Fn(u32, u32) -> bool,
    thesis_score: bool,
    out: &mut Vec<Vec<u32>>,
) {
    let mut ring = ring.to_vec();
    while ring.len() > 5 {
        let m = ring.len();
        let mut best: Option<(f64, usize)> = None;
        for i in 0..m {
            let q = [
                ring[i],
                ring[(i + 1) % m],
                ring[(i + 2) % m],
                ring[(i + 3) % m],
            ];
            let mut score = if thesis_score {
                quad_score(pos, q)
            } else {
                ring_score(pos, &ring, i)
            };
            if is_edge(q[0], q[3]) {
                score += 1e6;
            }
            if best.is_none_or(|(b, _)| score < b) {
                best = Some((score, i));
            }
        }
        let (_, i) = best.expect("ring is not empty");
        let q = [
            ring[i],
            ring[(i + 1) % m],
            ring[(i + 2) % m],
            ring[(i + 3) % m],
        ];
        out.push(q.to_vec());
        let (r1, r2) = ((i + 1) % m, (i + 2) % m);
        let keep: Vec<u32> = ring
            .iter()
            .enumerate()
            .filter(|&(k, _)| k != r1 && k != r2)
            .map(|(_, &v)| v)
            .collect();
        ring = keep;
    }
    if ring.len() >= 3 {
        out.push(ring);
    }
}

/// The best quadrangulation of the polygon `ring` (an even number of
/// distinct corners): of all ways to split it into quads whose corners are
/// ring corners in ring order, the one with the smallest total
/// `quad_cost`, where `None` forbids a quad. Returns `None` when no
/// quadrangulation avoids forbidden quads. Interval dynamic programming
/// over the ring: the sub-polygon `i..=j` is closed by the chord (i, j)
/// and split by the quad (i, a, b, j); O(m⁴) for m corners, meant for the
/// short rings of odd-face pairing (m ≤ ~20), where the greedy
/// [`fill_polygon`] can pick a first quad that leaves no valid rest.
pub fn best_quadrangulation(
    ring: &[u32],
    quad_cost: &mut dyn FnMut([u32; 4]) -> Option<f64>,
) -> Option<Vec<[u32; 4]>> {
    let m = ring.len();
    if m < 4 || m % 2 != 0 {
        return None;
    }
    // cost[i][j]: best split of corners i..=j (j − i odd) closed by (i, j);
    // choice[i][j]: the quad's inner corners (a, b).
    let mut cost = vec![vec![f64::INFINITY; m]; m];
    let mut choice = vec![vec![(0usize, 0usize); m]; m];
    for i in 0..m - 1 {
        cost[i][i + 1] = 0.0;
    }
    for len in (3..m).step_by(2) {
        for i in 0..m - len {
            let j = i + len;
            for a in (i + 1..j).step_by(2) {
                if cost[i][a].is_infinite() {
                    continue;
                }
                for b in (a + 1..j).step_by(2) {
                    let rest = cost[i][a] + cost[a][b] + cost[b][j];
                    if rest.is_infinite() || rest >= cost[i][j] {
                        continue;
                    }
                    let Some(q) = quad_cost([ring[i], ring[a], ring[b], ring[j]]) else {
                        continue;
                    };
                    if rest + q < cost[i][j] {
                        cost[i][j] = rest + q;
                        choice[i][j] = (a, b);
                    }
                }
            }
        }
    }
    if cost[0][m - 1].is_infinite() {
        return None;
    }
    let mut quads = Vec::with_capacity((m - 2) / 2);
    let mut stack = vec![(0, m - 1)];
    while let Some((i, j)) = stack.pop() {
        if j == i + 1 {
            continue;
        }
        let (a, b) = choice[i][j];
        quads.push([ring[i], ring[a], ring[b], ring[j]]);
        stack.extend([(i, a), (a, b), (b, j)]);
    }
    Some(quads)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn best_quadrangulation_avoids_a_forbidden_greedy_choice() {
        // A 3×1 strip of unit squares as an 8-gon: the only quadrangulation
        // into convex quads is the three squares; forbidding the middle one
        // leaves none.
        let pos: Vec<DVec3> = [
            (0, 0),
            (1, 0),
            (2, 0),
            (3, 0),
            (3, 1),
            (2, 1),
            (1, 1),
            (0, 1),
        ]
        .iter()
        .map(|&(x, y)| DVec3::new(x as f64, y as f64, 0.0))
        .collect();
        let ring: Vec<u32> = (0..8).collect();
        let convex = |q: [u32; 4]| -> bool {
            (0..4).all(|k| {
                let (a, b, c) = (
                    pos[q[k] as usize],
                    pos[q[(k + 1) % 4] as usize],
                    pos[q[(k + 2) % 4] as usize],
                );
                (b - a).cross(c - b).z > 1e-9
            })
        };
        let quads = best_quadrangulation(&ring, &mut |q| convex(q).then(|| quad_score(&pos, q)))
            .expect("the strip has a quadrangulation");
        let mut got: Vec<Vec<u32>> = quads
            .iter()
            .map(|q| {
                let mut v = q.to_vec();
                v.sort();
                v
            })
            .collect();
        got.sort();
        assert_eq!(
            got,
            vec![vec![0, 1, 6, 7], vec![1, 2, 5, 6], vec![2, 3, 4, 5]]
        );
        let mid = [1u32, 2, 5, 6];
        let none = best_quadrangulation(&ring, &mut |q| {
            let mut s = q;
            s.sort();
            (convex(q) && s != mid).then(|| quad_score(&pos, q))
        });
        assert!(none.is_none());
        // Odd rings have no quadrangulation.
        assert!(best_quadrangulation(&[0, 1, 2, 3, 4], &mut |_| Some(0.0)).is_none());
    }

    #[test]
    fn hexagon_becomes_two_rectangles() {
        // A 2×1 rectangle with midpoints on the long sides: the best first
        // quad is a unit square, leaving another.
        let pos = [
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(2.0, 0.0, 0.0),
            DVec3::new(2.0, 1.0, 0.0),
            DVec3::new(1.0, 1.0, 0.0),
            DVec3::new(0.0, 1.0, 0.0),
        ];
        let mut out = Vec::new();
        fill_polygon(&pos, &[0, 1, 2, 3, 4, 5], &|_, _| false, true, &mut out);
        assert_eq!(out.len(), 2);
        for q in &out {
            assert_eq!(q.len(), 4);
            assert!(quad_score(&pos, [q[0], q[1], q[2], q[3]]) < 1e-9, "{out:?}");
        }
    }

    #[test]
    fn thesis_score_uses_the_quads_own_corners() {
        let pos = [
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(1.0, 1.0, 0.0),
            DVec3::new(0.0, 1.0, 0.0),
            DVec3::new(0.5, 3.0, 0.0),
        ];
        assert!(quad_score(&pos, [0, 1, 2, 3]) < 1e-9);
        assert!(quad_score(&pos, [1, 2, 4, 3]) > 90.0);
    }

    #[test]
    fn simple_loops_cut_spurs_and_figure_eights() {
        let mut out = Vec::new();
        // 0 1 2 (3 spur back to 2) ...: a triangle with a spur.
        simple_loops(&[0, 1, 2, 3, 2], &mut out);
        assert_eq!(out, vec![vec![0, 1, 2]]);
        out.clear();
        simple_loops(&[0, 1, 2, 0, 3, 4], &mut out);
        assert_eq!(out.len(), 2);
    }
}
