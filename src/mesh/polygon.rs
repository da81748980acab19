//! Primitives on polygons and polygon soups (faces as vertex loops, before
//! or outside a half-edge mesh): the undirected edge key, the edge → faces
//! table and Newell's normal. The extraction, its repair and
//! post-processing, the subdivision and the import all use these.

use std::collections::HashMap;

use glam::DVec3;

/// The undirected edge {a, b} as (min, max), so both directions meet.
pub(crate) fn edge_key(a: u32, b: u32) -> (u32, u32) {
    (a.min(b), a.max(b))
}

/// Undirected edge → the faces using it, in face order (a face using an
/// edge twice is listed twice).
pub(crate) fn edge_faces(faces: &[Vec<u32>]) -> HashMap<(u32, u32), Vec<usize>> {
    let mut m: HashMap<(u32, u32), Vec<usize>> = HashMap::new();
    for (fi, f) in faces.iter().enumerate() {
        for k in 0..f.len() {
            m.entry(edge_key(f[k], f[(k + 1) % f.len()]))
                .or_default()
                .push(fi);
        }
    }
    m
}

/// Newell's vector area of the polygon through `corners` (in order):
/// Σ pₖ × pₖ₊₁. Its direction is the polygon's normal (right hand around
/// the corners), its length twice the area when the polygon is planar;
/// zero for fewer than three corners.
pub(crate) fn newell_normal(corners: impl IntoIterator<Item = DVec3>) -> DVec3 {
    let mut corners = corners.into_iter();
    let Some(first) = corners.next() else {
        return DVec3::ZERO;
    };
    let mut n = DVec3::ZERO;
    let mut prev = first;
    for p in corners {
        n += prev.cross(p);
        prev = p;
    }
    n + prev.cross(first)
}

/// [`newell_normal`] of the face `face` (vertex indices into `positions`).
pub(crate) fn face_newell_normal(positions: &[DVec3], face: &[u32]) -> DVec3 {
    newell_normal(face.iter().map(|&v| positions[v as usize]))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn newell_normal_of_a_unit_square_is_twice_its_area_along_z() {
        let pos = [
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(1.0, 1.0, 0.0),
            DVec3::new(0.0, 1.0, 0.0),
        ];
        assert_eq!(
            face_newell_normal(&pos, &[0, 1, 2, 3]),
            DVec3::new(0.0, 0.0, 2.0)
        );
        assert_eq!(
            face_newell_normal(&pos, &[3, 2, 1, 0]),
            DVec3::new(0.0, 0.0, -2.0)
        );
        assert_eq!(newell_normal([]), DVec3::ZERO);
    }

    #[test]
    fn edge_faces_meets_both_directions() {
        let m = edge_faces(&[vec![0, 1, 2], vec![2, 1, 3]]);
        assert_eq!(m[&edge_key(1, 2)], vec![0, 1]);
        assert_eq!(m[&(0, 1)], vec![0]);
        assert_eq!(m.len(), 5);
    }
}
