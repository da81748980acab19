use glam::DVec3;

use super::{Aabb, FaceList, MeshError, Topology};

/// An indexed triangle mesh: the pipeline's input surface.
///
/// Invariants (checked by [`TriMesh::validate`]): every coordinate is finite;
/// every index is `< positions.len()`; no triangle repeats a vertex.
/// Connectivity may be non-manifold or have boundaries; [`Topology`] reports it.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct TriMesh {
    pub positions: Vec<DVec3>,
    pub triangles: Vec<[u32; 3]>,
}

impl TriMesh {
    /// Builds a mesh and validates it.
    pub fn new(positions: Vec<DVec3>, triangles: Vec<[u32; 3]>) -> Result<TriMesh, MeshError> {
        let mesh = TriMesh {
            positions,
            triangles,
        };
        mesh.validate()?;
        Ok(mesh)
    }

    pub fn vertex_count(&self) -> usize {
        self.positions.len()
    }

    pub fn face_count(&self) -> usize {
        self.triangles.len()
    }

    pub fn validate(&self) -> Result<(), MeshError> {
        if self.positions.len() > u32::MAX as usize || self.triangles.len() > u32::MAX as usize {
            return Err(MeshError::TooLarge);
        }
        if let Some(v) = self.positions.iter().position(|p| !p.is_finite()) {
            return Err(MeshError::NonFinite { vertex: v });
        }
        let n = self.positions.len();
        for (f, t) in self.triangles.iter().enumerate() {
            for &i in t {
                if i as usize >= n {
                    return Err(MeshError::IndexOutOfRange {
                        face: f,
                        index: i,
                        count: n,
                    });
                }
            }
            if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] {
                return Err(MeshError::DegenerateFace { face: f });
            }
        }
        Ok(())
    }

    pub fn bbox(&self) -> Option<Aabb> {
        Aabb::of(&self.positions)
    }

    /// The three corner positions of triangle `f`.
    pub fn corners(&self, f: usize) -> [DVec3; 3] {
        let [a, b, c] = self.triangles[f];
        [
            self.positions[a as usize],
            self.positions[b as usize],
            self.positions[c as usize],
        ]
    }

    /// Area-weighted normal direction of triangle `f` (length = 2 × area).
    pub fn face_normal_unnormalized(&self, f: usize) -> DVec3 {
        let [a, b, c] = self.corners(f);
        (b - a).cross(c - a)
    }

    pub fn face_area(&self, f: usize) -> f64 {
        0.5 * self.face_normal_unnormalized(f).length()
    }

    pub fn total_area(&self) -> f64 {
        (0..self.face_count()).map(|f| self.face_area(f)).sum()
    }

    pub fn face_list(&self) -> FaceList {
        FaceList::from_triangles(&self.triangles)
    }

    /// Angle defect 2π − Σ corner angles of every vertex, the discrete
    /// Gaussian curvature (boundary vertices included: π minus it is the
    /// boundary's turning there).
    pub fn angle_defects(&self) -> Vec<f64> {
        let mut defect = vec![std::f64::consts::TAU; self.positions.len()];
        for t in &self.triangles {
            for k in 0..3 {
                let p = self.positions[t[k] as usize];
                let u = self.positions[t[(k + 1) % 3] as usize] - p;
                let v = self.positions[t[(k + 2) % 3] as usize] - p;
                let angle = u.angle_between(v);
                if angle.is_finite() {
                    defect[t[k] as usize] -= angle;
                }
            }
        }
        defect
    }

    pub fn topology(&self) -> Topology {
        Topology::of(self.positions.len(), &self.face_list())
    }

    /// Applies `f` to every position (e.g. a scale for invariance tests).
    pub fn map_positions(&mut self, f: impl Fn(DVec3) -> DVec3) {
        for p in &mut self.positions {
            *p = f(*p);
        }
    }
}
