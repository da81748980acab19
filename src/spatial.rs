//! Closest points, signed distances and ray casts against a triangle mesh,
//! on `parry3d-f64`'s BVH. Used by the metrics (distances to the input),
//! the extraction's reprojection and the control-mesh fitting (Kloiber
//! §3.8's normal rays).

use glam::DVec3;
use parry3d_f64::query::{PointQuery, PointQueryWithLocation, Ray, RayCast};
use parry3d_f64::shape::{TriMesh as ParryTriMesh, TriMeshFlags};

use crate::mesh::TriMesh;

/// A query structure over one triangle mesh.
pub struct SurfaceIndex {
    shape: ParryTriMesh,
    face_normals: Vec<DVec3>,
}

/// The closest point of the surface to a query point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Closest {
    pub point: DVec3,
    pub distance: f64,
    /// The triangle it lies on.
    pub face: u32,
}

/// Where a ray meets the surface: `origin + t · direction`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RayHit {
    pub t: f64,
    pub point: DVec3,
}

impl SurfaceIndex {
    /// Builds the BVH. `None` for a mesh without triangles.
    pub fn new(mesh: &TriMesh) -> Option<SurfaceIndex> {
        if mesh.triangles.is_empty() {
            return None;
        }
        let shape = ParryTriMesh::with_flags(
            mesh.positions.clone(),
            mesh.triangles.clone(),
            TriMeshFlags::empty(),
        )
        .ok()?;
        let face_normals = (0..mesh.face_count())
            .map(|f| mesh.face_normal_unnormalized(f).normalize_or_zero())
            .collect();
        Some(SurfaceIndex {
            shape,
            face_normals,
        })
    }

    /// The closest point on the surface.
    pub fn closest(&self, p: DVec3) -> Closest {
        let (projection, (face, _)) = self.shape.project_local_point_and_get_location(p, false);
        Closest {
            point: projection.point,
            distance: projection.point.distance(p),
            face,
        }
    }

    /// Distance to the surface, positive on the side the closest triangle's
    /// normal points to. (At edges and corners the closest triangle decides,
    /// which is exact for points near smooth parts and a fair sign elsewhere.)
    pub fn signed_distance(&self, p: DVec3) -> f64 {
        let c = self.closest(p);
        let n = self
            .face_normals
            .get(c.face as usize)
            .copied()
            .unwrap_or(DVec3::ZERO);
        if (p - c.point).dot(n) < 0.0 {
            -c.distance
        } else {
            c.distance
        }
    }

    /// Unsigned distance to the surface.
    pub fn distance(&self, p: DVec3) -> f64 {
        self.shape.distance_to_local_point(p, false)
    }

    /// The first hit of the ray `origin + t · direction`, `0 ≤ t ≤ max_t`.
    pub fn ray(&self, origin: DVec3, direction: DVec3, max_t: f64) -> Option<RayHit> {
        let ray = Ray::new(origin, direction);
        let t = self.shape.cast_local_ray(&ray, max_t, false)?;
        Some(RayHit {
            t,
            point: origin + t * direction,
        })
    }

    /// The nearest hit along the line through `origin` in either direction
    /// (`t` may be negative), within `|t| ≤ max_t`.
    pub fn line(&self, origin: DVec3, direction: DVec3, max_t: f64) -> Option<RayHit> {
        let forward = self.ray(origin, direction, max_t);
        let backward = self.ray(origin, -direction, max_t).map(|h| RayHit {
            t: -h.t,
            point: h.point,
        });
        match (forward, backward) {
            (Some(f), Some(b)) => Some(if f.t <= -b.t { f } else { b }),
            (f, b) => f.or(b),
        }
    }
}

/// Distances from one surface to another, sampled at points.
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize, serde::Deserialize)]
pub struct DistanceStats {
    pub max: f64,
    pub mean: f64,
    pub rms: f64,
}

impl DistanceStats {
    /// Max, mean and root mean square of `distances` (absolute values).
    pub fn of(distances: impl IntoIterator<Item = f64>) -> DistanceStats {
        let (mut max, mut sum, mut sq, mut n) = (0.0f64, 0.0, 0.0, 0usize);
        for d in distances {
            let d = d.abs();
            max = max.max(d);
            sum += d;
            sq += d * d;
            n += 1;
        }
        if n == 0 {
            return DistanceStats::default();
        }
        DistanceStats {
            max,
            mean: sum / n as f64,
            rms: (sq / n as f64).sqrt(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::generate;

    #[test]
    fn distances_to_a_sphere_match_the_radius_offset() {
        let sphere = generate::icosphere(1.0, 5);
        let index = SurfaceIndex::new(&sphere).unwrap();
        for p in [
            DVec3::new(2.0, 0.0, 0.0),
            DVec3::new(0.0, -0.5, 0.0),
            DVec3::new(0.3, 0.4, 1.2),
        ] {
            // The icosphere's chords sit within ~0.1 % of the radius.
            let expected = p.length() - 1.0;
            assert!(
                (index.signed_distance(p) - expected).abs() < 2e-3,
                "{p}: {}",
                index.signed_distance(p)
            );
            assert!((index.distance(p) - expected.abs()).abs() < 2e-3);
        }
    }

    #[test]
    fn rays_hit_the_sphere_from_inside_and_out() {
        let sphere = generate::icosphere(1.0, 5);
        let index = SurfaceIndex::new(&sphere).unwrap();
        let hit = index
            .ray(DVec3::new(-3.0, 0.0, 0.0), DVec3::X, 10.0)
            .unwrap();
        assert!((hit.t - 2.0).abs() < 2e-3);
        let line = index
            .line(DVec3::new(0.0, 0.0, 0.5), DVec3::Z, 10.0)
            .unwrap();
        assert!((line.point.z - 1.0).abs() < 2e-3);
        let back = index
            .line(DVec3::new(0.0, 0.0, -0.9), DVec3::Z, 10.0)
            .unwrap();
        assert!((back.t + 0.1).abs() < 2e-3, "{back:?}");
        assert!(
            index
                .ray(DVec3::new(0.0, 0.0, 3.0), DVec3::Z, 10.0)
                .is_none()
        );
    }
}
