use glam::{DVec2, DVec3};

/// Polygons of any degree in compressed-row form: face `f` is
/// `indices[offsets[f]..offsets[f + 1]]`, counter-clockwise seen from outside.
///
/// Invariants: `offsets[0] == 0`, `offsets` is non-decreasing, its last entry
/// equals `indices.len()`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FaceList {
    pub offsets: Vec<u32>,
    pub indices: Vec<u32>,
}

impl Default for FaceList {
    fn default() -> Self {
        Self::new()
    }
}

impl FaceList {
    pub fn new() -> Self {
        FaceList {
            offsets: vec![0],
            indices: Vec::new(),
        }
    }

    pub fn from_triangles(triangles: &[[u32; 3]]) -> Self {
        let mut list = FaceList::new();
        for t in triangles {
            list.push(t);
        }
        list
    }

    /// Appends one face.
    ///
    /// # Panics
    /// If the index list outgrows 32-bit offsets (readers check sizes first).
    pub fn push(&mut self, face: &[u32]) {
        self.indices.extend_from_slice(face);
        let end = u32::try_from(self.indices.len()).expect("face list exceeds u32 indices");
        self.offsets.push(end);
    }

    pub fn len(&self) -> usize {
        self.offsets.len() - 1
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    pub fn face(&self, f: usize) -> &[u32] {
        &self.indices[self.offsets[f] as usize..self.offsets[f + 1] as usize]
    }

    pub fn iter(&self) -> impl ExactSizeIterator<Item = &[u32]> + '_ {
        self.offsets
            .windows(2)
            .map(move |w| &self.indices[w[0] as usize..w[1] as usize])
    }

    /// Number of faces of each degree, indexed by degree (entries 0–2 are 0
    /// for a valid list).
    pub fn degree_histogram(&self) -> Vec<usize> {
        let mut hist = Vec::new();
        for face in self.iter() {
            if hist.len() <= face.len() {
                hist.resize(face.len() + 1, 0);
            }
            hist[face.len()] += 1;
        }
        hist
    }

    /// Splits every face into triangles (triangles stay as they are).
    ///
    /// Polygons are projected onto the plane of their Newell normal and split
    /// by ear clipping, taking at each step the ear with the largest smallest
    /// angle (a quad gets its better diagonal; concave polygons stay inside
    /// their outline). Faces of more than [`EAR_CLIPPING_LIMIT`] corners, or
    /// where no ear is found (self-intersecting outlines), fall back to a fan.
    pub fn triangulate(&self, positions: &[DVec3]) -> Vec<[u32; 3]> {
        let mut out = Vec::with_capacity(self.indices.len().saturating_sub(2 * self.len()));
        for face in self.iter() {
            triangulate_polygon(positions, face, &mut out);
        }
        out
    }

    /// Checks the structural invariants and that every index is `< vertex_count`.
    pub fn validate(&self, vertex_count: usize) -> Result<(), super::MeshError> {
        use super::MeshError;
        if self.offsets.first() != Some(&0)
            || self.offsets.windows(2).any(|w| w[0] > w[1])
            || *self.offsets.last().unwrap_or(&0) as usize != self.indices.len()
        {
            return Err(MeshError::Connectivity(
                "face offsets are not a valid CSR".into(),
            ));
        }
        for (f, face) in self.iter().enumerate() {
            if face.len() < 3 {
                return Err(MeshError::DegenerateFace { face: f });
            }
            for &i in face {
                if i as usize >= vertex_count {
                    return Err(MeshError::IndexOutOfRange {
                        face: f,
                        index: i,
                        count: vertex_count,
                    });
                }
            }
        }
        Ok(())
    }
}

/// Polygons with more corners than this are fanned (ear clipping is O(n²)).
pub const EAR_CLIPPING_LIMIT: usize = 64;

fn triangulate_polygon(positions: &[DVec3], face: &[u32], out: &mut Vec<[u32; 3]>) {
    let n = face.len();
    if n == 3 {
        out.push([face[0], face[1], face[2]]);
        return;
    }
    let fan = |out: &mut Vec<[u32; 3]>, ring: &[u32]| {
        for k in 1..ring.len() - 1 {
            out.push([ring[0], ring[k], ring[k + 1]]);
        }
    };
    if n > EAR_CLIPPING_LIMIT {
        fan(out, face);
        return;
    }
    let p3: Vec<DVec3> = face.iter().map(|&i| positions[i as usize]).collect();
    let Some(normal) = super::newell_normal(p3.iter().copied()).try_normalize() else {
        fan(out, face);
        return;
    };
    let u = normal.any_orthonormal_vector();
    let v = normal.cross(u);
    let p2: Vec<DVec2> = p3.iter().map(|&p| DVec2::new(p.dot(u), p.dot(v))).collect();
    let cross = |a: DVec2, b: DVec2, c: DVec2| (b - a).perp_dot(c - a);
    let mut ring: Vec<usize> = (0..n).collect();
    while ring.len() > 3 {
        let m = ring.len();
        let mut best: Option<(f64, usize)> = None;
        for k in 0..m {
            let (a, b, c) = (ring[(k + m - 1) % m], ring[k], ring[(k + 1) % m]);
            if cross(p2[a], p2[b], p2[c]) <= 0.0 {
                continue;
            }
            let inside = ring.iter().any(|&o| {
                o != a
                    && o != b
                    && o != c
                    && cross(p2[a], p2[b], p2[o]) >= 0.0
                    && cross(p2[b], p2[c], p2[o]) >= 0.0
                    && cross(p2[c], p2[a], p2[o]) >= 0.0
            });
            if inside {
                continue;
            }
            let quality = min_angle(p3[a], p3[b], p3[c]);
            if best.is_none_or(|(q, _)| quality > q) {
                best = Some((quality, k));
            }
        }
        let Some((_, k)) = best else {
            let rest: Vec<u32> = ring.iter().map(|&r| face[r]).collect();
            fan(out, &rest);
            return;
        };
        let (a, b, c) = (ring[(k + m - 1) % m], ring[k], ring[(k + 1) % m]);
        out.push([face[a], face[b], face[c]]);
        ring.remove(k);
    }
    out.push([face[ring[0]], face[ring[1]], face[ring[2]]]);
}

fn min_angle(a: DVec3, b: DVec3, c: DVec3) -> f64 {
    let angle = |p: DVec3, q: DVec3, r: DVec3| (q - p).angle_between(r - p);
    angle(a, b, c).min(angle(b, c, a)).min(angle(c, a, b))
}

/// The positions `faces` use, in their order, and the faces renumbered.
pub fn drop_unused(positions: Vec<DVec3>, faces: &FaceList) -> (Vec<DVec3>, FaceList) {
    let mut used = vec![false; positions.len()];
    for &v in &faces.indices {
        used[v as usize] = true;
    }
    let mut new_id = vec![u32::MAX; positions.len()];
    let mut kept = Vec::new();
    for (v, p) in positions.into_iter().enumerate() {
        if used[v] {
            new_id[v] = kept.len() as u32;
            kept.push(p);
        }
    }
    let mut out = FaceList::new();
    for face in faces.iter() {
        let renumbered: Vec<u32> = face.iter().map(|&v| new_id[v as usize]).collect();
        out.push(&renumbered);
    }
    (kept, out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quad_takes_the_shorter_diagonal() {
        // A rhombus: the diagonal 1-3 is much shorter than 0-2.
        let p = [
            DVec3::new(-2.0, 0.0, 0.0),
            DVec3::new(0.0, -0.5, 0.0),
            DVec3::new(2.0, 0.0, 0.0),
            DVec3::new(0.0, 0.5, 0.0),
        ];
        let tris = FaceList::from_triangles(&[]).triangulate(&p);
        assert!(tris.is_empty());
        let mut quad = FaceList::new();
        quad.push(&[0, 1, 2, 3]);
        let tris = quad.triangulate(&p);
        assert_eq!(tris.len(), 2);
        for t in &tris {
            assert!(t.contains(&1) && t.contains(&3), "{tris:?}");
        }
    }

    #[test]
    fn concave_polygon_stays_inside_and_keeps_area() {
        // An L shape (area 3) with a reflex corner at vertex 3.
        let p: Vec<DVec3> = [(0., 0.), (2., 0.), (2., 1.), (1., 1.), (1., 2.), (0., 2.)]
            .iter()
            .map(|&(x, y)| DVec3::new(x, y, 0.0))
            .collect();
        let mut l = FaceList::new();
        l.push(&[0, 1, 2, 3, 4, 5]);
        let tris = l.triangulate(&p);
        assert_eq!(tris.len(), 4);
        let area: f64 = tris
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| p[i as usize]);
                0.5 * (b - a).cross(c - a).z
            })
            .sum();
        assert!((area - 3.0).abs() < 1e-12, "signed area {area}");
    }
}
