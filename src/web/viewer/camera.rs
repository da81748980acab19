//! An orbit camera: it turns around a target point, pans in the view plane
//! and zooms by changing its distance. Right-handed, y up, WebGPU clip depth
//! in [0, 1] (wgpu maps it for WebGL).

use glam::{Mat4, Vec3};

#[derive(Debug, Clone, PartialEq)]
pub struct OrbitCamera {
    pub target: Vec3,
    /// Angle around the y axis, radians.
    pub yaw: f32,
    /// Angle above the horizontal plane, radians, kept inside (−π/2, π/2).
    pub pitch: f32,
    pub distance: f32,
    /// Vertical field of view, radians.
    pub fov_y: f32,
    /// Width / height of the viewport.
    pub aspect: f32,
    /// Radius of the scene's bounding sphere (sets near and far planes).
    pub scene_radius: f32,
}

const MAX_PITCH: f32 = 1.55;

impl Default for OrbitCamera {
    fn default() -> Self {
        OrbitCamera {
            target: Vec3::ZERO,
            yaw: 0.5,
            pitch: 0.35,
            distance: 3.0,
            fov_y: 40f32.to_radians(),
            aspect: 1.0,
            scene_radius: 1.0,
        }
    }
}

impl OrbitCamera {
    pub fn eye(&self) -> Vec3 {
        let dir = Vec3::new(
            self.pitch.cos() * self.yaw.sin(),
            self.pitch.sin(),
            self.pitch.cos() * self.yaw.cos(),
        );
        self.target + dir * self.distance
    }

    pub fn view(&self) -> Mat4 {
        glam::camera::rh::view::look_at_mat4(self.eye(), self.target, Vec3::Y)
    }

    pub fn projection(&self) -> Mat4 {
        let r = self.scene_radius.max(1e-6);
        let far = self.distance + 2.0 * r;
        let near = (self.distance - 2.0 * r).max(far * 1e-4);
        // WebGPU clip space: depth in [0, 1], y up (glam calls it the DirectX convention).
        glam::camera::rh::proj::directx::perspective(self.fov_y, self.aspect.max(1e-6), near, far)
    }

    pub fn view_proj(&self) -> Mat4 {
        self.projection() * self.view()
    }

    /// Turns the camera by a drag of (`dx`, `dy`) pixels on a viewport `height` pixels tall.
    pub fn orbit(&mut self, dx: f32, dy: f32, height: f32) {
        let k = std::f32::consts::PI / height.max(1.0);
        self.yaw -= dx * k;
        self.pitch = (self.pitch + dy * k).clamp(-MAX_PITCH, MAX_PITCH);
    }

    /// Moves the target so the surface follows a drag of (`dx`, `dy`) pixels.
    pub fn pan(&mut self, dx: f32, dy: f32, height: f32) {
        let view = self.view();
        let right = view.row(0).truncate();
        let up = view.row(1).truncate();
        let per_pixel = 2.0 * self.distance * (self.fov_y * 0.5).tan() / height.max(1.0);
        self.target += (-dx * right + dy * up) * per_pixel;
    }

    /// Multiplies the distance by `factor` (< 1 zooms in), within sane bounds.
    pub fn zoom(&mut self, factor: f32) {
        if factor.is_finite() && factor > 0.0 {
            let r = self.scene_radius.max(1e-6);
            self.distance = (self.distance * factor).clamp(r * 0.05, r * 50.0);
        }
    }

    /// Zooms by `factor` keeping `anchor` (a point in view, e.g. the
    /// surface under the cursor) where it is on screen: the eye and the
    /// target scale about it.
    pub fn zoom_about(&mut self, factor: f32, anchor: Vec3) {
        let before = self.distance;
        self.zoom(factor);
        let k = self.distance / before;
        self.target = anchor + (self.target - anchor) * k;
    }

    /// The point where the ray through pixel (`x`, `y`) meets the plane
    /// through the target facing the camera (the anchor when no surface is
    /// under the cursor).
    pub fn focal_point(&self, x: f32, y: f32, width: f32, height: f32) -> Vec3 {
        let (origin, dir) = self.ray(x, y, width, height);
        let forward = (self.target - self.eye()).normalize_or_zero();
        let along = dir.dot(forward);
        if along.abs() < 1e-6 {
            return self.target;
        }
        origin + dir * ((self.target - origin).dot(forward) / along)
    }

    /// `[yaw, pitch, distance, target x, y, z]`, for share links.
    pub fn state(&self) -> [f32; 6] {
        [
            self.yaw,
            self.pitch,
            self.distance,
            self.target.x,
            self.target.y,
            self.target.z,
        ]
    }

    /// Restores [`OrbitCamera::state`]; returns false (and changes
    /// nothing) unless six finite values with a positive distance.
    pub fn set_state(&mut self, s: &[f32]) -> bool {
        if s.len() != 6 || s.iter().any(|x| !x.is_finite()) || s[2] <= 0.0 {
            return false;
        }
        self.yaw = s[0];
        self.pitch = s[1].clamp(-MAX_PITCH, MAX_PITCH);
        let r = self.scene_radius.max(1e-6);
        self.distance = s[2].clamp(r * 0.05, r * 50.0);
        self.target = Vec3::new(s[3], s[4], s[5]);
        true
    }

    /// Looks from a named direction ("front": +z, "top": +y, "side": +x),
    /// keeping target and distance; false for an unknown name.
    pub fn preset(&mut self, name: &str) -> bool {
        let (yaw, pitch) = match name {
            "front" => (0.0, 0.0),
            "top" => (0.0, MAX_PITCH),
            "side" => (std::f32::consts::FRAC_PI_2, 0.0),
            _ => return false,
        };
        self.yaw = yaw;
        self.pitch = pitch;
        true
    }

    /// Centres the bounding sphere (`center`, `radius`) and moves back until it fits.
    pub fn fit(&mut self, center: Vec3, radius: f32) {
        let radius = if radius.is_finite() && radius > 0.0 {
            radius
        } else {
            1.0
        };
        self.target = center;
        self.scene_radius = radius;
        let half_fov = (self.fov_y * 0.5).min((self.aspect * (self.fov_y * 0.5).tan()).atan());
        self.distance = radius / half_fov.sin() * 1.05;
    }

    /// The ray through pixel (`x`, `y`) of a `width` × `height` viewport
    /// (origin top left): origin and unit direction.
    pub fn ray(&self, x: f32, y: f32, width: f32, height: f32) -> (Vec3, Vec3) {
        let ndc_x = 2.0 * x / width.max(1.0) - 1.0;
        let ndc_y = 1.0 - 2.0 * y / height.max(1.0);
        let inverse = self.view_proj().inverse();
        let near = inverse.project_point3(Vec3::new(ndc_x, ndc_y, 0.0));
        let far = inverse.project_point3(Vec3::new(ndc_x, ndc_y, 1.0));
        (near, (far - near).normalize_or_zero())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fit_puts_the_sphere_in_view() {
        let mut c = OrbitCamera {
            aspect: 0.5,
            ..Default::default()
        };
        c.fit(Vec3::new(1.0, 2.0, 3.0), 2.0);
        let vp = c.view_proj();
        for d in [Vec3::X, Vec3::Y, Vec3::Z, -Vec3::X, -Vec3::Y, -Vec3::Z] {
            let p = vp.project_point3(Vec3::new(1.0, 2.0, 3.0) + d * 2.0);
            assert!(p.x.abs() <= 1.0 && p.y.abs() <= 1.0, "{d} → {p}");
            assert!((0.0..=1.0).contains(&p.z), "{d} depth {}", p.z);
        }
    }

    #[test]
    fn centre_ray_hits_the_target() {
        let mut c = OrbitCamera::default();
        c.fit(Vec3::new(0.5, 0.0, 0.0), 1.0);
        let (o, d) = c.ray(50.0, 50.0, 100.0, 100.0);
        let to_target = c.target - o;
        assert!(to_target.cross(d).length() < 1e-3 * to_target.length());
    }

    #[test]
    fn orbit_keeps_distance_and_clamps_pitch() {
        let mut c = OrbitCamera::default();
        let d0 = (c.eye() - c.target).length();
        c.orbit(123.0, 10_000.0, 600.0);
        assert!(((c.eye() - c.target).length() - d0).abs() < 1e-4);
        assert!(c.pitch <= MAX_PITCH);
    }

    #[test]
    fn pan_moves_the_target_in_the_view_plane() {
        let mut c = OrbitCamera::default();
        let forward = (c.target - c.eye()).normalize();
        let t0 = c.target;
        c.pan(30.0, -20.0, 600.0);
        assert!((c.target - t0).dot(forward).abs() < 1e-5);
        assert!((c.target - t0).length() > 0.0);
    }

    #[test]
    fn zoom_about_keeps_the_anchor_on_screen() {
        let mut c = OrbitCamera {
            aspect: 1.5,
            ..Default::default()
        };
        c.fit(Vec3::ZERO, 1.0);
        let anchor = c.focal_point(500.0, 120.0, 600.0, 400.0);
        let before = c.view_proj().project_point3(anchor);
        let d = c.distance;
        c.zoom_about(0.5, anchor);
        let after = c.view_proj().project_point3(anchor);
        assert!((c.distance - d * 0.5).abs() < 1e-5);
        assert!(
            (before.truncate() - after.truncate()).length() < 1e-4,
            "{before} → {after}"
        );
        // Zooming to the centre would have moved it.
        let mut centred = OrbitCamera {
            aspect: 1.5,
            ..Default::default()
        };
        centred.fit(Vec3::ZERO, 1.0);
        centred.zoom(0.5);
        let moved = centred.view_proj().project_point3(anchor);
        assert!((before.truncate() - moved.truncate()).length() > 0.1);
    }

    #[test]
    fn state_round_trips_and_rejects_garbage() {
        let mut c = OrbitCamera::default();
        c.fit(Vec3::new(0.1, 0.2, 0.3), 1.0);
        c.orbit(40.0, 10.0, 600.0);
        let s = c.state();
        let mut d = OrbitCamera::default();
        d.fit(Vec3::ZERO, 1.0);
        assert!(d.set_state(&s));
        assert_eq!(d.view_proj(), c.view_proj());
        assert!(!d.set_state(&[1.0, f32::NAN, 1.0, 0.0, 0.0, 0.0]));
        assert!(!d.set_state(&[1.0; 5]));
        assert!(d.preset("top") && !d.preset("diagonal"));
    }

    #[test]
    fn zoom_ignores_garbage() {
        let mut c = OrbitCamera::default();
        let d = c.distance;
        c.zoom(f32::NAN);
        c.zoom(-1.0);
        assert_eq!(c.distance, d);
        c.zoom(0.5);
        assert!(c.distance < d);
    }
}
