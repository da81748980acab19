//! The `Viewer` handed to the page's main thread: plain data in (typed
//! arrays), pixels out. The page wires input events to `orbit`, `pan`,
//! `zoom` and `pick` and calls `render` when something changed.

use std::collections::{BTreeMap, BTreeSet};

use glam::Vec3;
use wasm_bindgen::prelude::*;

use super::camera::OrbitCamera;
use super::gpu::{BackendPreference, Gpu, Tier};
use super::scene::{GlyphSet, LineSet, PLAIN, PointSet, Scalar, SceneError, Surface};

fn js(e: impl std::fmt::Display) -> JsError {
    JsError::new(&e.to_string())
}

/// Layer names with a fixed meaning; line and point layers use their own names.
const SURFACE: &str = "surface";
const SCALAR: &str = "scalar";

#[wasm_bindgen]
pub struct Viewer {
    gpu: Gpu,
    camera: OrbitCamera,
    surface: Option<Surface>,
    scalar: Option<Scalar>,
    hidden: BTreeSet<String>,
    line_width: f32,
    flat: bool,
    /// The surface's own per-vertex colours (the parametrization layer's
    /// flipped-triangle tint), shown when no scalar is.
    own_colors: Option<Vec<[u8; 4]>>,
    /// The surface carries (u, v): draw the checkerboard.
    grid: bool,
    /// The surface's (u, v), kept to upload again when the crease split changes.
    uv: Option<Vec<[f32; 2]>>,
    /// Smooth shading keeps edges sharper than this (degrees) sharp.
    crease_degrees: f32,
    /// Glyph layers by name, thinned to `glyph_spacing` drawing-buffer
    /// pixels whenever the view changes (`glyph_view` is the last one).
    glyphs: BTreeMap<String, (GlyphSet, usize)>,
    glyph_spacing: f32,
    glyph_view: Option<[f32; 9]>,
}

/// Where `pick` met the surface (local coordinates).
#[wasm_bindgen]
#[derive(Debug, Clone, Copy)]
pub struct PickHit {
    point: Vec3,
    pub triangle: u32,
    /// The hit triangle's corner nearest to the point.
    pub vertex: u32,
}

#[wasm_bindgen]
impl PickHit {
    #[wasm_bindgen(getter)]
    pub fn point(&self) -> Vec<f32> {
        self.point.to_array().to_vec()
    }
}

#[wasm_bindgen]
impl Viewer {
    /// Opens the renderer on `canvas` (`backend`: "auto" or "webgl2"),
    /// with a drawing buffer of `width` × `height` pixels.
    pub async fn create(
        canvas: web_sys::HtmlCanvasElement,
        backend: String,
        width: u32,
        height: u32,
    ) -> Result<Viewer, JsError> {
        let preference = match backend.as_str() {
            "webgl2" | "webgl" | "gl" => BackendPreference::WebGl2,
            _ => BackendPreference::Auto,
        };
        let gpu = Gpu::new(canvas, preference, width, height)
            .await
            .map_err(js)?;
        let mut camera = OrbitCamera::default();
        let (w, h) = gpu.size();
        camera.aspect = w as f32 / h as f32;
        Ok(Viewer {
            gpu,
            camera,
            surface: None,
            scalar: None,
            hidden: BTreeSet::new(),
            line_width: 1.5,
            flat: false,
            own_colors: None,
            grid: false,
            uv: None,
            crease_degrees: super::scene::CREASE_DEGREES,
            glyphs: BTreeMap::new(),
            glyph_spacing: 24.0,
            glyph_view: None,
        })
    }

    /// "webgpu" or "webgl2".
    #[wasm_bindgen(getter)]
    pub fn backend(&self) -> String {
        match self.gpu.tier {
            Tier::Full => "webgpu",
            Tier::Limited => "webgl2",
        }
        .into()
    }

    /// "full" (WebGPU) or "limited" (WebGL2), decided once at start-up.
    #[wasm_bindgen(getter)]
    pub fn tier(&self) -> String {
        match self.gpu.tier {
            Tier::Full => "full",
            Tier::Limited => "limited",
        }
        .into()
    }

    /// Multisampling used for anti-aliasing (1 or 4).
    #[wasm_bindgen(getter)]
    pub fn samples(&self) -> u32 {
        self.gpu.msaa_samples()
    }

    /// Replaces the surface (xyz positions, vertex triples, xyz normals);
    /// drops the scalar quantity and every line and point layer, which
    /// belonged to the old surface, and fits the view.
    pub fn set_mesh(
        &mut self,
        positions: &[f32],
        triangles: &[u32],
        normals: &[f32],
    ) -> Result<(), JsError> {
        let surface = Surface::new(positions, triangles, normals).map_err(js)?;
        let colors = vec![PLAIN; surface.positions.len()];
        self.gpu
            .set_surface(Some((&surface, &colors)), self.crease_degrees);
        self.gpu.clear_layers();
        self.glyphs.clear();
        self.surface = Some(surface);
        self.scalar = None;
        self.own_colors = None;
        self.grid = false;
        self.uv = None;
        self.fit_view();
        Ok(())
    }

    /// Swaps the drawn surface (e.g. the input for the limit surface) and
    /// keeps the camera and every line and point layer; the scalar is
    /// dropped (the page sets the one that belongs to the new surface).
    pub fn replace_surface(
        &mut self,
        positions: &[f32],
        triangles: &[u32],
        normals: &[f32],
    ) -> Result<(), JsError> {
        let surface = Surface::new(positions, triangles, normals).map_err(js)?;
        let colors = vec![PLAIN; surface.positions.len()];
        self.gpu
            .set_surface(Some((&surface, &colors)), self.crease_degrees);
        self.surface = Some(surface);
        self.scalar = None;
        self.own_colors = None;
        self.grid = false;
        self.uv = None;
        Ok(())
    }

    /// Gives the surface per-vertex (u, v) (two floats per vertex) and
    /// draws them as a checkerboard of unit squares with the integer
    /// isolines (the parametrization layer), until the surface changes.
    pub fn set_uv(&mut self, uv: &[f32]) -> Result<(), JsError> {
        let count = self
            .surface
            .as_ref()
            .ok_or_else(|| js(SceneError::NoSurface))?
            .positions
            .len();
        let uv = super::scene::uv_pairs(uv, count).map_err(js)?;
        self.gpu.set_surface_uv(&uv);
        self.uv = Some(uv);
        self.grid = true;
        Ok(())
    }

    /// The surface's own RGBA colour per vertex (four bytes each), shown
    /// when no scalar is, until the surface changes.
    pub fn set_vertex_colors(&mut self, rgba: &[u8]) -> Result<(), JsError> {
        let count = self
            .surface
            .as_ref()
            .ok_or_else(|| js(SceneError::NoSurface))?
            .positions
            .len();
        self.own_colors = Some(super::scene::vertex_colors(rgba, count).map_err(js)?);
        self.upload_colors();
        Ok(())
    }

    /// Colours the surface by a per-vertex scalar through `colormap`
    /// ("viridis" or "violet-green") over [`min`, `max`] (NaN: the values' range).
    pub fn set_scalar(
        &mut self,
        name: &str,
        values: &[f32],
        min: f32,
        max: f32,
        colormap: &str,
    ) -> Result<(), JsError> {
        let count = self
            .surface
            .as_ref()
            .ok_or_else(|| js(SceneError::NoSurface))?
            .positions
            .len();
        self.scalar = Some(Scalar::new(name, values, count, min, max, colormap).map_err(js)?);
        self.upload_colors();
        Ok(())
    }

    pub fn clear_scalar(&mut self) {
        self.scalar = None;
        self.upload_colors();
    }

    /// `{ name, min, max, colormap, stops: [css colours] }` of the shown
    /// scalar, or `null` when the surface is plain.
    pub fn legend(&self) -> Result<JsValue, JsError> {
        match self
            .scalar
            .as_ref()
            .filter(|_| !self.hidden.contains(SCALAR))
        {
            None => Ok(JsValue::NULL),
            Some(s) => crate::web::worker_api::to_js(&serde_json::json!({
                "name": s.name, "min": s.min, "max": s.max,
                "colormap": s.colormap.name(), "stops": s.colormap.css_stops(),
            })),
        }
    }

    /// A line layer from segment endpoints (six floats per segment) and one
    /// RGBA colour for all or one per segment. An empty array removes it.
    pub fn set_lines(&mut self, name: &str, segments: &[f32], rgba: &[u8]) -> Result<(), JsError> {
        let lines = LineSet::from_segments(segments, rgba).map_err(js)?;
        self.glyphs.remove(name);
        self.gpu.set_lines(name, Some(&lines));
        Ok(())
    }

    /// A glyph layer: centred segments (six floats each), `per_site`
    /// consecutive ones per glyph (a cross field's two arms), one RGBA
    /// colour for all or one per segment, and the field mesh's triangles
    /// over the glyphs (three site indices each; may be empty). Drawn at
    /// screen density, at most one glyph per cell of the glyph spacing,
    /// each about that size on screen, re-sampled when the view changes;
    /// triangles too big on screen for the spacing get glyphs inside them
    /// too. An empty array removes it.
    pub fn set_glyphs(
        &mut self,
        name: &str,
        segments: &[f32],
        rgba: &[u8],
        per_site: u32,
        triangles: &[u32],
    ) -> Result<(), JsError> {
        let glyphs =
            GlyphSet::from_segments(segments, rgba, per_site as usize, triangles).map_err(js)?;
        self.glyphs.insert(name.to_string(), (glyphs, 0));
        self.glyph_view = None;
        Ok(())
    }

    /// Distance between glyphs in drawing-buffer pixels (at least 4).
    pub fn set_glyph_spacing(&mut self, px: f32) -> f32 {
        if px.is_finite() {
            self.glyph_spacing = px.max(4.0);
            self.glyph_view = None;
        }
        self.glyph_spacing
    }

    /// How many glyphs of a glyph layer the last frame drew.
    pub fn glyph_count(&self, name: &str) -> u32 {
        self.glyphs.get(name).map_or(0, |g| g.1 as u32)
    }

    /// A line layer from vertex index pairs over the surface, e.g. the
    /// polygon edges, so quads show as quads.
    pub fn set_edges(&mut self, name: &str, edges: &[u32], rgba: &[u8]) -> Result<(), JsError> {
        let surface = self
            .surface
            .as_ref()
            .ok_or_else(|| js(SceneError::NoSurface))?;
        let lines = LineSet::from_edges(surface, edges, rgba).map_err(js)?;
        self.gpu.set_lines(name, Some(&lines));
        Ok(())
    }

    /// A point layer: xyz positions, one RGBA colour for all or one per
    /// point, marker diameter in pixels. An empty array removes it.
    pub fn set_points(
        &mut self,
        name: &str,
        positions: &[f32],
        rgba: &[u8],
        size_px: f32,
    ) -> Result<(), JsError> {
        let points = PointSet::new(positions, rgba, size_px).map_err(js)?;
        self.gpu.set_points(name, Some(&points));
        Ok(())
    }

    /// Shows or hides a layer: "surface", "scalar" (the surface's colouring)
    /// or a line or point layer's name.
    pub fn set_layer_visible(&mut self, name: &str, visible: bool) {
        if visible {
            self.hidden.remove(name);
        } else {
            self.hidden.insert(name.to_string());
        }
        if name == SCALAR {
            self.upload_colors();
        }
    }

    pub fn layer_visible(&self, name: &str) -> bool {
        !self.hidden.contains(name)
    }

    /// Line width in pixels of the drawing buffer.
    pub fn set_line_width(&mut self, px: f32) {
        if px.is_finite() && px > 0.0 {
            self.line_width = px;
        }
    }

    /// Resizes the drawing buffer (pixels).
    pub fn resize(&mut self, width: u32, height: u32) {
        self.gpu.resize(width, height);
        let (w, h) = self.gpu.size();
        self.camera.aspect = w as f32 / h as f32;
    }

    /// Turns the view by a drag of (`dx`, `dy`) drawing-buffer pixels.
    pub fn orbit(&mut self, dx: f32, dy: f32) {
        let h = self.gpu.size().1 as f32;
        self.camera.orbit(dx, dy, h);
    }

    /// Moves the view so the surface follows a drag of (`dx`, `dy`) pixels.
    pub fn pan(&mut self, dx: f32, dy: f32) {
        let h = self.gpu.size().1 as f32;
        self.camera.pan(dx, dy, h);
    }

    /// Moves closer (`factor` < 1) or farther (> 1).
    pub fn zoom(&mut self, factor: f32) {
        self.camera.zoom(factor);
    }

    /// Zooms by `factor` toward what is under drawing-buffer pixel (`x`,
    /// `y`): the surface point there, else the point on the target's plane;
    /// that point stays under the cursor.
    pub fn zoom_at(&mut self, factor: f32, x: f32, y: f32) {
        let (w, h) = self.gpu.size();
        let anchor = match self.pick(x, y) {
            Some(hit) => hit.point,
            None => self.camera.focal_point(x, y, w as f32, h as f32),
        };
        self.camera.zoom_about(factor, anchor);
    }

    /// `[yaw, pitch, distance, target x, y, z]` of the camera.
    pub fn camera_state(&self) -> Vec<f32> {
        self.camera.state().to_vec()
    }

    /// Restores `camera_state`; false when the values are unusable.
    pub fn set_camera_state(&mut self, state: &[f32]) -> bool {
        self.camera.set_state(state)
    }

    /// Looks from the front (+z), top (+y) or side (+x) and frames the
    /// surface; false for another name.
    pub fn view_preset(&mut self, name: &str) -> bool {
        let ok = self.camera.preset(name);
        if ok {
            self.fit_view();
        }
        ok
    }

    /// Flat shading (one normal per triangle) or smooth (vertex normals).
    pub fn set_flat_shading(&mut self, flat: bool) {
        self.flat = flat;
    }

    /// Smooth shading keeps edges whose dihedral angle exceeds `degrees`
    /// sharp (default [`CREASE_DEGREES`]; 180 smooths across every edge).
    /// Returns the angle in use.
    ///
    /// [`CREASE_DEGREES`]: super::scene::CREASE_DEGREES
    pub fn set_crease_angle(&mut self, degrees: f32) -> f32 {
        if degrees.is_finite() && (0.0..=180.0).contains(&degrees) && degrees != self.crease_degrees
        {
            self.crease_degrees = degrees;
            if let Some(surface) = &self.surface {
                let colors = vec![PLAIN; surface.positions.len()];
                self.gpu.set_surface(Some((surface, &colors)), degrees);
                if let Some(uv) = &self.uv {
                    self.gpu.set_surface_uv(uv);
                }
                self.upload_colors();
            }
        }
        self.crease_degrees
    }

    /// Frames the whole surface.
    pub fn fit_view(&mut self) {
        if let Some((center, radius)) = self.surface.as_ref().and_then(Surface::bounding_sphere) {
            self.camera.fit(center, radius);
        }
    }

    /// The surface point under drawing-buffer pixel (`x`, `y`), if any.
    pub fn pick(&self, x: f32, y: f32) -> Option<PickHit> {
        let surface = self
            .surface
            .as_ref()
            .filter(|_| !self.hidden.contains(SURFACE))?;
        let (w, h) = self.gpu.size();
        let (origin, dir) = self.camera.ray(x, y, w as f32, h as f32);
        let hit = surface.pick(origin, dir)?;
        Some(PickHit {
            point: hit.point,
            triangle: hit.triangle,
            vertex: hit.vertex,
        })
    }

    /// The scalar value at a vertex, if a scalar is shown.
    pub fn scalar_at(&self, vertex: u32) -> Option<f32> {
        self.scalar.as_ref()?.values.get(vertex as usize).copied()
    }

    /// Draws a frame.
    pub fn render(&mut self) -> Result<(), JsError> {
        self.thin_glyphs();
        let hidden = &self.hidden;
        self.gpu
            .render(
                &self.camera,
                &|name| !hidden.contains(name),
                self.line_width,
                self.flat,
                self.grid,
            )
            .map_err(js)
    }
}

impl Viewer {
    /// Re-samples the glyph layers when the camera, the target size or the
    /// spacing changed since the last frame.
    fn thin_glyphs(&mut self) {
        let (w, h) = self.gpu.size();
        let c = self.camera.state();
        let view = [
            c[0],
            c[1],
            c[2],
            c[3],
            c[4],
            c[5],
            w as f32,
            h as f32,
            self.glyph_spacing,
        ];
        if self.glyph_view == Some(view) {
            return;
        }
        self.glyph_view = Some(view);
        let (view_proj, eye) = (self.camera.view_proj(), self.camera.eye());
        for (name, (glyphs, count)) in self.glyphs.iter_mut() {
            let (lines, n) = glyphs.thin(
                view_proj,
                eye,
                self.camera.fov_y,
                (w as f32, h as f32),
                self.glyph_spacing,
            );
            *count = n;
            self.gpu.set_lines(name, Some(&lines));
        }
    }

    fn upload_colors(&mut self) {
        let Some(surface) = &self.surface else { return };
        let colors = match self
            .scalar
            .as_ref()
            .filter(|_| !self.hidden.contains(SCALAR))
        {
            Some(s) => s.colors(),
            None => match &self.own_colors {
                Some(c) => c.clone(),
                None => vec![PLAIN; surface.positions.len()],
            },
        };
        self.gpu.set_surface_colors(&colors);
    }
}
