use glam::DVec3;
use serde::{Deserialize, Serialize};

/// Axis-aligned bounding box.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Aabb {
    pub min: DVec3,
    pub max: DVec3,
}

impl Aabb {
    /// The box around `points`; `None` when there are none.
    pub fn of(points: &[DVec3]) -> Option<Aabb> {
        let first = *points.first()?;
        Some(points.iter().fold(
            Aabb {
                min: first,
                max: first,
            },
            |b, &p| Aabb {
                min: b.min.min(p),
                max: b.max.max(p),
            },
        ))
    }

    pub fn extent(&self) -> DVec3 {
        self.max - self.min
    }

    pub fn center(&self) -> DVec3 {
        0.5 * (self.min + self.max)
    }

    pub fn largest_axis(&self) -> f64 {
        self.extent().max_element()
    }

    pub fn diagonal(&self) -> f64 {
        self.extent().length()
    }
}

/// The similarity between a file's coordinates ("world") and the normalised
/// coordinates the pipeline works in ("local"): `world = center + scale * local`.
///
/// Import maps the bounding box centre to the origin and the largest box axis
/// to length 1, so that tolerances are relative and a scan stored in
/// millimetres a kilometre from the origin behaves like one in metres at the
/// origin. Export applies [`Frame::to_world`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Frame {
    pub center: DVec3,
    pub scale: f64,
}

impl Default for Frame {
    fn default() -> Self {
        Frame::IDENTITY
    }
}

impl Frame {
    pub const IDENTITY: Frame = Frame {
        center: DVec3::ZERO,
        scale: 1.0,
    };

    /// The frame that normalises `points` (identity scale for a degenerate box).
    pub fn fit(points: &[DVec3]) -> Frame {
        match Aabb::of(points) {
            None => Frame::IDENTITY,
            Some(b) => {
                let s = b.largest_axis();
                Frame {
                    center: b.center(),
                    scale: if s.is_finite() && s > 0.0 { s } else { 1.0 },
                }
            }
        }
    }

    pub fn to_local(&self, p: DVec3) -> DVec3 {
        (p - self.center) / self.scale
    }

    pub fn to_world(&self, p: DVec3) -> DVec3 {
        self.center + self.scale * p
    }

    /// Every point of `points` in world coordinates.
    pub fn points_to_world(&self, points: &[DVec3]) -> Vec<DVec3> {
        points.iter().map(|&p| self.to_world(p)).collect()
    }

    /// A length measured in local units, expressed in world units.
    pub fn length_to_world(&self, l: f64) -> f64 {
        l * self.scale
    }
}
