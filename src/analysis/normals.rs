//! Face and vertex normals.
//!
//! Vertex normals are the normalised sum of incident face normals, weighted by
//! the face's corner angle at the vertex (Thürmer & Wüthrich 1998; default,
//! independent of how the fan is triangulated) or by face area (what Instant
//! Meshes uses). They feed the local frames of the curvature fit (Kloiber
//! 3.1.1) and, on coarser levels, the hierarchy.
//!
//! Degenerate cases never give NaN: a zero-area face has a zero normal and
//! contributes nothing; a vertex whose weighted sum vanishes (isolated, or
//! faces cancelling) falls back to the area-weighted sum, then to +z.

use glam::DVec3;
use serde::{Deserialize, Serialize};

use crate::mesh::TriMesh;

/// How incident faces are weighted in a vertex normal.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum NormalWeighting {
    /// By the face's interior angle at the vertex.
    #[default]
    Angle,
    /// By the face's area.
    Area,
}

/// Unit normal of every triangle (zero for a zero-area triangle).
pub fn face_normals(mesh: &TriMesh) -> Vec<DVec3> {
    (0..mesh.face_count())
        .map(|f| mesh.face_normal_unnormalized(f).normalize_or_zero())
        .collect()
}

/// Unit normal of every vertex (`+z` for vertices without faces).
pub fn vertex_normals(mesh: &TriMesh, weighting: NormalWeighting) -> Vec<DVec3> {
    let n = mesh.vertex_count();
    let mut weighted = vec![DVec3::ZERO; n];
    let mut by_area = vec![DVec3::ZERO; n];
    for (f, t) in mesh.triangles.iter().enumerate() {
        let [a, b, c] = mesh.corners(f);
        let area_normal = (b - a).cross(c - a);
        let unit = area_normal.normalize_or_zero();
        let corners = [(a, b, c), (b, c, a), (c, a, b)];
        for (k, &v) in t.iter().enumerate() {
            by_area[v as usize] += area_normal;
            if weighting == NormalWeighting::Angle {
                let (p, q, r) = corners[k];
                let angle = (q - p).angle_between(r - p);
                if angle.is_finite() {
                    weighted[v as usize] += angle * unit;
                }
            }
        }
    }
    if weighting == NormalWeighting::Area {
        weighted.clone_from(&by_area);
    }
    weighted
        .iter()
        .zip(&by_area)
        .map(|(w, a)| {
            w.try_normalize()
                .or_else(|| a.try_normalize())
                .unwrap_or(DVec3::Z)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::generate;

    #[test]
    fn sphere_vertex_normals_are_radial() {
        let m = generate::icosphere(3.0, 3);
        for w in [NormalWeighting::Angle, NormalWeighting::Area] {
            let normals = vertex_normals(&m, w);
            for (p, n) in m.positions.iter().zip(&normals) {
                assert!(n.dot(p.normalize()) > 0.9999);
            }
        }
    }

    #[test]
    fn isolated_vertex_gets_a_unit_normal() {
        let mut m = generate::tetrahedron();
        m.positions.push(DVec3::ONE);
        let normals = vertex_normals(&m, NormalWeighting::Angle);
        assert!(normals.iter().all(|n| (n.length() - 1.0).abs() < 1e-12));
        assert!(face_normals(&m).iter().all(|n| n.is_finite()));
    }
}
