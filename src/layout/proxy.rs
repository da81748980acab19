//! A coarse proxy of a large mesh for interactive dual strip weaving
//! (Campen & Kobbelt 2014, *Dual Strip Weaving*, §4: the design tool must
//! answer hover queries at interactive rates; the paper's timings are at
//! ~30k faces). Not part of the paper: uniform-grid vertex clustering
//! (Rossignac & Borrel 1993) — vertices in one grid cell are merged at their
//! mean, collapsed and duplicate triangles dropped, unused vertices removed.
//! Crude (it may create non-manifold spots, which the loop engine tolerates),
//! but fast and never fails.

use std::collections::HashMap;

use glam::DVec3;

use crate::mesh::TriMesh;

/// Meshes with more faces than this are designed on a proxy.
pub const PROXY_ABOVE_FACES: usize = 40_000;
/// The proxy's target face count.
pub const PROXY_FACES: usize = 30_000;

/// Vertex clustering on a grid of cell size `h`.
pub fn cluster(mesh: &TriMesh, h: f64) -> TriMesh {
    let Some(b) = mesh.bbox() else {
        return mesh.clone();
    };
    let mut cell_of: HashMap<(i64, i64, i64), u32> = HashMap::new();
    let mut sum: Vec<(DVec3, f64)> = Vec::new();
    let mut remap = Vec::with_capacity(mesh.vertex_count());
    for p in &mesh.positions {
        let c = ((*p - b.min) / h).floor();
        let id = *cell_of
            .entry((c.x as i64, c.y as i64, c.z as i64))
            .or_insert_with(|| {
                sum.push((DVec3::ZERO, 0.0));
                sum.len() as u32 - 1
            });
        sum[id as usize].0 += *p;
        sum[id as usize].1 += 1.0;
        remap.push(id);
    }
    let positions: Vec<DVec3> = sum.iter().map(|(s, n)| *s / *n).collect();
    let mut seen = std::collections::HashSet::new();
    let mut triangles = Vec::new();
    for t in &mesh.triangles {
        let [a, b, c] = t.map(|v| remap[v as usize]);
        if a == b || b == c || a == c {
            continue;
        }
        let mut key = [a, b, c];
        key.sort_unstable();
        if seen.insert(key) {
            triangles.push([a, b, c]);
        }
    }
    // Drop vertices no triangle uses.
    let mut used = vec![u32::MAX; positions.len()];
    let mut kept = Vec::new();
    for t in &mut triangles {
        for v in t.iter_mut() {
            if used[*v as usize] == u32::MAX {
                used[*v as usize] = kept.len() as u32;
                kept.push(positions[*v as usize]);
            }
            *v = used[*v as usize];
        }
    }
    TriMesh::new(kept, triangles).unwrap_or_else(|_| mesh.clone())
}

/// Vertex clustering with the cell size bisected to about `faces` faces.
pub fn decimate(mesh: &TriMesh, faces: usize) -> TriMesh {
    if mesh.face_count() <= faces {
        return mesh.clone();
    }
    let diag = mesh.bbox().map_or(1.0, |b| b.diagonal());
    let (mut lo, mut hi) = (1e-5 * diag, 0.1 * diag);
    let mut best = mesh.clone();
    for _ in 0..30 {
        let h = (lo * hi).sqrt();
        let m = cluster(mesh, h);
        if m.face_count() > faces {
            lo = h;
        } else {
            hi = h;
        }
        if best.face_count() > faces
            || m.face_count().abs_diff(faces) < best.face_count().abs_diff(faces)
        {
            best = m;
        }
        if best.face_count().abs_diff(faces) * 100 < faces {
            break;
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::generate::icosphere;

    #[test]
    fn decimation_reaches_about_the_target_and_keeps_a_closed_sphere() {
        let mesh = icosphere(1.0, 5); // 20 480 faces
        let proxy = decimate(&mesh, 5000);
        let f = proxy.face_count();
        assert!((4000..=5000).contains(&f), "{f} faces");
        // Every vertex stays on (near) the unit sphere.
        for p in &proxy.positions {
            assert!((p.length() - 1.0).abs() < 0.05, "{p}");
        }
        assert_eq!(
            decimate(&mesh, 30_000).face_count(),
            mesh.face_count(),
            "small meshes are kept"
        );
    }
}
