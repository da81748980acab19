//! Reflectional symmetry for the layout design (Campen & Kobbelt 2014,
//! *Dual Strip Weaving*, §5.8): a mirror plane, its detection among simple
//! candidates, and mirroring a committed loop onto the other half.
//!
//! Deviations from the paper:
//! - The paper leaves the symmetry map to the user or to symmetry detection
//!   [Mitra et al. 2013]; we only test the three axis-aligned planes through
//!   the bounding-box centre and through the area-weighted centroid, scored
//!   by the mean distance of the reflected vertices to the surface relative
//!   to the bounding-box diagonal.
//! - The paper designs on one half with dual curves ending orthogonally on
//!   (or reflected at) the half's boundary (§5.8); here a loop designed on
//!   the whole surface is mirrored point by point and snapped to the
//!   surface, and [`is_self_symmetric`] tells when the mirror image is the
//!   loop itself, so no second copy is added.

use glam::DVec3;

use crate::mesh::TriMesh;
use crate::spatial::SurfaceIndex;

/// Largest mean reflection distance (relative to the bounding-box diagonal)
/// for which [`detect`] reports a plane.
pub const DETECT_THRESHOLD: f64 = 0.005;

/// Vertices sampled by [`detect`] (evenly strided).
const DETECT_SAMPLES: usize = 4000;

#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct MirrorPlane {
    pub point: DVec3,
    /// Unit normal.
    pub normal: DVec3,
}

impl MirrorPlane {
    /// Plane through `point` with normal along `normal` (normalized);
    /// `None` for a zero or non-finite normal.
    pub fn new(point: DVec3, normal: DVec3) -> Option<MirrorPlane> {
        let n = normal.try_normalize()?;
        point
            .is_finite()
            .then_some(MirrorPlane { point, normal: n })
    }

    /// Signed distance of `p` from the plane.
    pub fn side(&self, p: DVec3) -> f64 {
        (p - self.point).dot(self.normal)
    }

    pub fn reflect(&self, p: DVec3) -> DVec3 {
        p - 2.0 * self.side(p) * self.normal
    }
}

/// The best axis-aligned mirror plane of `mesh` and its score (mean
/// distance of reflected vertices to the surface / bbox diagonal), or
/// `None` if no candidate scores below [`DETECT_THRESHOLD`].
pub fn detect(mesh: &TriMesh) -> Option<(MirrorPlane, f64)> {
    best_axis_plane(mesh).filter(|&(_, s)| s < DETECT_THRESHOLD)
}

/// The best of the axis-aligned candidate planes and its score, however
/// poor (`None` only for an empty or degenerate mesh).
pub fn best_axis_plane(mesh: &TriMesh) -> Option<(MirrorPlane, f64)> {
    let bbox = mesh.bbox()?;
    let diagonal = bbox.diagonal();
    if diagonal.is_nan() || diagonal <= 0.0 {
        return None;
    }
    let index = SurfaceIndex::new(mesh)?;
    let mut centroid = DVec3::ZERO;
    let mut area = 0.0;
    for f in 0..mesh.face_count() {
        let a = mesh.face_area(f);
        let [p, q, r] = mesh.corners(f);
        centroid += a * (p + q + r) / 3.0;
        area += a;
    }
    let mut centres = vec![bbox.center()];
    if area > 0.0 && (centroid / area).is_finite() {
        centres.push(centroid / area);
    }
    let stride = (mesh.positions.len() / DETECT_SAMPLES).max(1);
    let samples: Vec<DVec3> = mesh.positions.iter().step_by(stride).copied().collect();
    let mut best: Option<(MirrorPlane, f64)> = None;
    for &c in &centres {
        for n in [DVec3::X, DVec3::Y, DVec3::Z] {
            let plane = MirrorPlane {
                point: c,
                normal: n,
            };
            let sum: f64 = samples
                .iter()
                .map(|&p| index.closest(plane.reflect(p)).distance)
                .sum();
            let score = sum / samples.len() as f64 / diagonal;
            if best.is_none_or(|(_, s)| score < s) {
                best = Some((plane, score));
            }
        }
    }
    best
}

/// The mirror image of a curve on the surface: each point reflected and
/// snapped to the closest surface point.
pub fn mirror_polyline(index: &SurfaceIndex, plane: &MirrorPlane, points: &[DVec3]) -> Vec<DVec3> {
    points
        .iter()
        .map(|&p| index.closest(plane.reflect(p)).point)
        .collect()
}

/// Whether two closed polylines coincide within `tol` (every point of each
/// lies within `tol` of the other polyline, the last point joined to the
/// first): a loop that is its own mirror image needs no second copy. For
/// open dual curves the closing segment makes the test slightly lenient.
pub fn is_self_symmetric(points: &[DVec3], mirrored: &[DVec3], tol: f64) -> bool {
    if points.is_empty() || mirrored.is_empty() {
        return points.is_empty() && mirrored.is_empty();
    }
    let near = |p: DVec3, line: &[DVec3]| {
        (0..line.len())
            .any(|i| point_segment_distance(p, line[i], line[(i + 1) % line.len()]) <= tol)
    };
    points.iter().all(|&p| near(p, mirrored)) && mirrored.iter().all(|&p| near(p, points))
}

fn point_segment_distance(p: DVec3, a: DVec3, b: DVec3) -> f64 {
    let d = b - a;
    let len2 = d.length_squared();
    let t = if len2 > 0.0 {
        ((p - a).dot(d) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    p.distance(a + t * d)
}
