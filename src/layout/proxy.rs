//! A coarse proxy of a large mesh for interactive dual strip weaving
//! (Campen & Kobbelt 2014, *Dual Strip Weaving*, §4: the design tool must
//! answer hover queries at interactive rates; the paper's timings are at
//! ~30k faces, and §8.1 suggests designing on a simplified proxy). Not part
//! of the paper: shortest-edge-first edge collapse to the edge midpoint,
//! refused when it would break the surface — the link condition (the two
//! ends share exactly the neighbours opposite the edge, so the result stays
//! a manifold with the same topology), no collapse of an interior edge
//! between two boundary vertices, and no neighbouring triangle may flip
//! (its normal turning by more than 60°) or degenerate. The regions and
//! the layout of §4.2/§7 need a manifold; vertex clustering was tried
//! first and made non-manifold edges on the bunny.

use std::cmp::Reverse;
use std::collections::BinaryHeap;

use super::OrdF64;
use crate::mesh::TriMesh;

/// Meshes with more faces than this are designed on a proxy.
pub const PROXY_ABOVE_FACES: usize = 40_000;
/// The proxy's target face count.
pub const PROXY_FACES: usize = 30_000;

/// A triangle normal turning by more than this (cosine) refuses a collapse.
const MIN_NORMAL_COS: f64 = 0.5;

/// Edge collapse to about `faces` faces (fewer when every remaining
/// collapse is refused: then as close as possible). Meshes at or below
/// `faces` are returned as they are.
pub fn decimate(mesh: &TriMesh, faces: usize) -> TriMesh {
    if mesh.face_count() <= faces {
        return mesh.clone();
    }
    let mut positions = mesh.positions.clone();
    let mut triangles = mesh.triangles.clone();
    let mut alive = vec![true; triangles.len()];
    let mut faces_of: Vec<Vec<u32>> = vec![Vec::new(); positions.len()];
    for (f, t) in triangles.iter().enumerate() {
        for &v in t {
            faces_of[v as usize].push(f as u32);
        }
    }
    let mut removed_vertex = vec![false; positions.len()];
    let mut boundary = crate::mesh::boundary_vertices(mesh);
    let key = |len: f64, a: u32, b: u32| (Reverse(OrdF64(len)), a, b);
    let mut heap = BinaryHeap::new();
    for t in &triangles {
        for i in 0..3 {
            let (a, b) = (t[i], t[(i + 1) % 3]);
            if a < b {
                heap.push(key(
                    positions[a as usize].distance(positions[b as usize]),
                    a,
                    b,
                ));
            }
        }
    }
    let mut live_faces = triangles.len();
    let neighbours = |v: u32, faces_of: &Vec<Vec<u32>>, triangles: &Vec<[u32; 3]>| {
        let mut n: Vec<u32> = faces_of[v as usize]
            .iter()
            .flat_map(|&f| triangles[f as usize])
            .filter(|&w| w != v)
            .collect();
        n.sort_unstable();
        n.dedup();
        n
    };
    while live_faces > faces {
        let Some((Reverse(OrdF64(len)), a, b)) = heap.pop() else {
            break;
        };
        if removed_vertex[a as usize] || removed_vertex[b as usize] {
            continue;
        }
        let (pa, pb) = (positions[a as usize], positions[b as usize]);
        // Stale entry: the edge changed length or is gone.
        if (pa.distance(pb) - len).abs() > 1e-12 * len.max(1e-300) {
            continue;
        }
        let shared: Vec<u32> = faces_of[a as usize]
            .iter()
            .copied()
            .filter(|&f| triangles[f as usize].contains(&b))
            .collect();
        if shared.is_empty() || shared.len() > 2 {
            continue;
        }
        let edge_on_boundary = shared.len() == 1;
        if !edge_on_boundary && boundary[a as usize] && boundary[b as usize] {
            continue;
        }
        // Link condition.
        let (na, nb) = (
            neighbours(a, &faces_of, &triangles),
            neighbours(b, &faces_of, &triangles),
        );
        let common = na.iter().filter(|v| nb.binary_search(v).is_ok()).count();
        if common != shared.len() {
            continue;
        }
        let m = 0.5 * (pa + pb);
        // No flipped or degenerate neighbour.
        let ok = [a, b].iter().all(|&v| {
            faces_of[v as usize].iter().all(|&f| {
                if shared.contains(&f) {
                    return true;
                }
                let t = triangles[f as usize];
                let p = t.map(|w| positions[w as usize]);
                let q = t.map(|w| {
                    if w == a || w == b {
                        m
                    } else {
                        positions[w as usize]
                    }
                });
                let n0 = (p[1] - p[0]).cross(p[2] - p[0]);
                let n1 = (q[1] - q[0]).cross(q[2] - q[0]);
                n1.length() > 1e-12 * n0.length()
                    && n0.dot(n1) > MIN_NORMAL_COS * n0.length() * n1.length()
            })
        });
        if !ok {
            continue;
        }
        // Collapse b into a at the midpoint.
        positions[a as usize] = m;
        boundary[a as usize] |= boundary[b as usize];
        removed_vertex[b as usize] = true;
        for &f in &shared {
            alive[f as usize] = false;
            live_faces -= 1;
        }
        let moved = std::mem::take(&mut faces_of[b as usize]);
        for f in moved {
            if !alive[f as usize] {
                continue;
            }
            for w in triangles[f as usize].iter_mut() {
                if *w == b {
                    *w = a;
                }
            }
            faces_of[a as usize].push(f);
        }
        for &f in &shared {
            for w in triangles[f as usize] {
                faces_of[w as usize].retain(|&g| alive[g as usize]);
            }
        }
        for w in neighbours(a, &faces_of, &triangles) {
            let (x, y) = (a.min(w), a.max(w));
            heap.push(key(m.distance(positions[w as usize]), x, y));
        }
    }
    // Compact.
    let mut index = vec![u32::MAX; positions.len()];
    let mut kept = Vec::new();
    let mut out = Vec::with_capacity(live_faces);
    for (f, t) in triangles.iter().enumerate() {
        if !alive[f] {
            continue;
        }
        out.push(t.map(|v| {
            if index[v as usize] == u32::MAX {
                index[v as usize] = kept.len() as u32;
                kept.push(positions[v as usize]);
            }
            index[v as usize]
        }));
    }
    TriMesh::new(kept, out).unwrap_or_else(|_| mesh.clone())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::generate::{flat_grid, icosphere, torus};

    #[test]
    fn decimation_reaches_the_target_and_keeps_the_surface() {
        for (mesh, target) in [
            (icosphere(1.0, 5), 5000), // 20 480 faces, genus 0
            (torus(2.0, 0.7, 120, 60), 3000),
            (flat_grid(1.0, 60), 2000),
        ] {
            let proxy = decimate(&mesh, target);
            let f = proxy.face_count();
            assert!((target - 2..=target).contains(&f), "{f} faces for {target}");
            let (t0, t1) = (mesh.topology(), proxy.topology());
            assert_eq!(
                (
                    t1.nonmanifold_edges,
                    t1.nonmanifold_vertices,
                    t1.inconsistent_edges
                ),
                (0, 0, 0),
                "not a consistently oriented manifold"
            );
            assert_eq!(t1.euler_characteristic, t0.euler_characteristic);
            assert_eq!(t1.components, t0.components);
            assert_eq!(t1.boundary_edges > 0, t0.boundary_edges > 0);
            // Every vertex stays near the input surface.
            let index = crate::spatial::SurfaceIndex::new(&mesh).expect("index");
            let diag = mesh.bbox().unwrap().diagonal();
            for p in &proxy.positions {
                assert!(index.closest(*p).point.distance(*p) < 0.02 * diag, "{p}");
            }
        }
        let mesh = icosphere(1.0, 3);
        assert_eq!(decimate(&mesh, 30_000), mesh, "small meshes are kept");
    }
}
