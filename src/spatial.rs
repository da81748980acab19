//! Closest points, signed distances and ray casts against a triangle mesh,
//! on `parry3d-f64`'s BVH. Used by the metrics (distances to the input),
//! the extraction's reprojection and the control-mesh fitting (Kloiber
//! §3.8's normal rays).

use glam::DVec3;
use parry3d_f64::query::{PointQuery, PointQueryWithLocation, Ray, RayCast};
use parry3d_f64::shape::{Polyline, TriMesh as ParryTriMesh, TriMeshFlags};

use crate::mesh::{Aabb, TriMesh};
use crate::progress::Cancelled;

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

    /// The unit normal of triangle `face` (zero for a degenerate or unknown
    /// one).
    pub fn face_normal(&self, face: u32) -> DVec3 {
        self.face_normals
            .get(face as usize)
            .copied()
            .unwrap_or(DVec3::ZERO)
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

/// Closest points on a set of line segments (a network of feature curves),
/// on `parry3d-f64`'s BVH over a polyline.
pub struct CurveIndex {
    shape: Polyline,
}

impl CurveIndex {
    /// Builds the BVH over the segments `(positions[a], positions[b])`.
    /// `None` without segments.
    pub fn new(positions: &[DVec3], segments: &[[u32; 2]]) -> Option<CurveIndex> {
        if segments.is_empty() {
            return None;
        }
        Some(CurveIndex {
            shape: Polyline::new(positions.to_vec(), Some(segments.to_vec())),
        })
    }

    /// The closest point on the segments, its distance and the index of
    /// the segment it lies on.
    pub fn closest(&self, p: DVec3) -> (DVec3, f64, u32) {
        let (projection, (segment, _)) = self.shape.project_local_point_and_get_location(p, false);
        (projection.point, projection.point.distance(p), segment)
    }

    /// Unit direction of segment `i` (zero for a degenerate one).
    pub fn direction(&self, i: u32) -> DVec3 {
        let s = self.shape.segment(i);
        (s.b - s.a).normalize_or_zero()
    }
}

/// Unsigned distances to a large triangle mesh whose BVH is built in
/// pieces — slabs of at most `max_triangles` triangles along the largest
/// axis — so that the caller can report progress (and cancel) between the
/// builds: one parry BVH build is a single uninterruptible call, ~200 ms
/// for the bunny's 275k-triangle limit mesh. A query visits the pieces
/// nearest box first and stops at a box farther than the best distance.
pub struct PiecewiseDistance {
    pieces: Vec<(Aabb, SurfaceIndex)>,
}

impl PiecewiseDistance {
    /// Builds the pieces; `between(done)` runs before each build with the
    /// fraction of triangles done.
    pub fn build(
        mesh: &TriMesh,
        max_triangles: usize,
        between: &mut dyn FnMut(f32) -> Result<(), Cancelled>,
    ) -> Result<PiecewiseDistance, Cancelled> {
        let Some(bbox) = Aabb::of(&mesh.positions) else {
            return Ok(PiecewiseDistance { pieces: Vec::new() });
        };
        let e = bbox.extent();
        let axis = if e.x >= e.y && e.x >= e.z {
            0
        } else if e.y >= e.z {
            1
        } else {
            2
        };
        let centroid = |t: &[u32; 3]| {
            t.iter()
                .map(|&v| mesh.positions[v as usize][axis])
                .sum::<f64>()
        };
        let mut order: Vec<usize> = (0..mesh.triangles.len()).collect();
        order.sort_by(|&a, &b| {
            centroid(&mesh.triangles[a]).total_cmp(&centroid(&mesh.triangles[b]))
        });
        let mut pieces = Vec::new();
        let mut local = vec![u32::MAX; mesh.positions.len()];
        for (c, chunk) in order.chunks(max_triangles.max(1)).enumerate() {
            between((c * max_triangles) as f32 / order.len() as f32)?;
            let mut piece = TriMesh {
                positions: Vec::new(),
                triangles: Vec::with_capacity(chunk.len()),
            };
            for &t in chunk {
                let tri = mesh.triangles[t].map(|v| {
                    if local[v as usize] == u32::MAX {
                        local[v as usize] = piece.positions.len() as u32;
                        piece.positions.push(mesh.positions[v as usize]);
                    }
                    local[v as usize]
                });
                piece.triangles.push(tri);
            }
            for &t in chunk {
                for v in mesh.triangles[t] {
                    local[v as usize] = u32::MAX;
                }
            }
            if let (Some(b), Some(index)) = (Aabb::of(&piece.positions), SurfaceIndex::new(&piece))
            {
                pieces.push((b, index));
            }
        }
        Ok(PiecewiseDistance { pieces })
    }

    /// Unsigned distance to the mesh (∞ for an empty one).
    pub fn distance(&self, p: DVec3) -> f64 {
        let mut near: Vec<(f64, usize)> = self
            .pieces
            .iter()
            .enumerate()
            .map(|(i, (b, _))| ((b.min - p).max(p - b.max).max(DVec3::ZERO).length(), i))
            .collect();
        near.sort_by(|a, b| a.0.total_cmp(&b.0));
        let mut best = f64::INFINITY;
        for (box_distance, i) in near {
            if box_distance >= best {
                break;
            }
            best = best.min(self.pieces[i].1.distance(p));
        }
        best
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

/// Segments bucketed in a uniform grid of cell `cell`, each with a tag,
/// for "is there a segment within r of q" queries with r ≤ cell.
pub(crate) struct SegmentGrid<T> {
    cell: f64,
    segments: Vec<([DVec3; 2], T)>,
    buckets: std::collections::HashMap<[i64; 3], Vec<u32>>,
}

impl<T: Copy> SegmentGrid<T> {
    pub(crate) fn new(segments: Vec<([DVec3; 2], T)>, cell: f64) -> SegmentGrid<T> {
        let cell = if cell > 0.0 { cell } else { 1.0 };
        let mut buckets: std::collections::HashMap<[i64; 3], Vec<u32>> = Default::default();
        for (i, ([a, b], _)) in segments.iter().enumerate() {
            let (lo, hi) = (Self::key(a.min(*b), cell), Self::key(a.max(*b), cell));
            for x in lo[0]..=hi[0] {
                for y in lo[1]..=hi[1] {
                    for z in lo[2]..=hi[2] {
                        buckets.entry([x, y, z]).or_default().push(i as u32);
                    }
                }
            }
        }
        SegmentGrid {
            cell,
            segments,
            buckets,
        }
    }

    fn key(p: DVec3, cell: f64) -> [i64; 3] {
        (p / cell).floor().as_i64vec3().to_array()
    }

    /// Whether a segment whose tag passes `keep` lies within `r` (≤ the
    /// cell) of `q`.
    pub(crate) fn any_within(&self, q: DVec3, r: f64, keep: impl Fn(T) -> bool) -> bool {
        self.first_within(q, r, keep).is_some()
    }

    /// The tag of a segment within `r` (≤ the cell) of `q` whose tag
    /// passes `keep`, if any.
    pub(crate) fn first_within(&self, q: DVec3, r: f64, keep: impl Fn(T) -> bool) -> Option<T> {
        let k = Self::key(q, self.cell);
        for x in k[0] - 1..=k[0] + 1 {
            for y in k[1] - 1..=k[1] + 1 {
                for z in k[2] - 1..=k[2] + 1 {
                    for &i in self.buckets.get(&[x, y, z]).map_or(&[][..], |v| v) {
                        let ([a, b], tag) = self.segments[i as usize];
                        if keep(tag) && segment_distance(q, a, b) <= r {
                            return Some(tag);
                        }
                    }
                }
            }
        }
        None
    }
}

/// Distance from `q` to the segment `a`–`b`.
pub(crate) fn segment_distance(q: DVec3, a: DVec3, b: DVec3) -> f64 {
    let d = b - a;
    let t = if d.length_squared() > 0.0 {
        ((q - a).dot(d) / d.length_squared()).clamp(0.0, 1.0)
    } else {
        0.0
    };
    q.distance(a + t * d)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::generate;

    #[test]
    fn piecewise_distances_equal_one_index() {
        // A torus (non-convex, so pieces overlap in their boxes' shadows)
        // in pieces of 100 triangles against one BVH, at points inside,
        // outside and far away; the reports arrive in order.
        let torus = generate::torus(1.0, 0.3, 48, 24);
        let whole = SurfaceIndex::new(&torus).unwrap();
        let mut reports = Vec::new();
        let pieces = PiecewiseDistance::build(&torus, 100, &mut |done| {
            reports.push(done);
            Ok(())
        })
        .unwrap();
        assert_eq!(reports.len(), torus.face_count().div_ceil(100));
        assert!(reports.windows(2).all(|w| w[0] < w[1]) && reports[0] == 0.0);
        for i in 0..300 {
            let t = i as f64 * 0.7;
            let p = DVec3::new(2.0 * t.sin(), 1.5 * (1.3 * t).cos(), 0.8 * (0.4 * t).sin())
                * (1.0 + (i % 7) as f64);
            let (a, b) = (whole.distance(p), pieces.distance(p));
            assert!((a - b).abs() < 1e-12, "{p}: {a} vs {b}");
        }
        let empty = TriMesh {
            positions: Vec::new(),
            triangles: Vec::new(),
        };
        let none = PiecewiseDistance::build(&empty, 100, &mut |_| Ok(())).unwrap();
        assert_eq!(none.distance(DVec3::ZERO), f64::INFINITY);
    }

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
