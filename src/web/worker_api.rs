//! The stateful object that lives in the Web Worker (Squoosh / wasm-bindgen
//! worker pattern): the worker script creates one [`Session`], hands it a
//! file with `start`, then calls `step` until the run is complete. Every
//! stage's result goes to the page through the `emit` callback as soon as it
//! exists, with its big arrays as typed arrays that own their buffers, so
//! the worker transfers them instead of copying.
//!
//! Steps: `import`, then `pipeline` (analysis, hierarchy, orientation,
//! position, extraction, post-processing, control-mesh fit in the local
//! mode; analysis, parametrization, extraction, post-processing, fit in the
//! global mode, `remesh.mode`; [`crate::pipeline::Pipeline::run`]). The worker goes back to its event
//! loop between steps, where a `cancel` message is seen.
//!
//! Parameters: `setParams(object)` (serde-wasm-bindgen, like every small
//! structured value crossing the boundary) hands the pipeline new parameters
//! ([`crate::pipeline::Pipeline::set_params`]); only the stages from the
//! first one they change on run again at the next `step`. `summary()`
//! lists the stages the latest run ran (`stagesRun`). `parameterSchema()`
//! describes every parameter ([`crate::params_schema`]).
//!
//! Export: `export(kind, format)` writes the quad-dominant, pure-quad,
//! control or limit mesh as OBJ or PLY with the crate's own writers, in
//! the file's coordinates.
//!
//! Cancellation inside a step. The pipeline's progress sink asks the
//! worker's `progress` callback whether to go on. Without cross-origin
//! isolation (COOP/COEP headers, which a plain static host cannot promise)
//! there is no `SharedArrayBuffer`, and the callback cannot learn about a
//! cancel while wasm runs: then the page terminates the worker as the last
//! resort (`www/main.js`). With isolation the page passes a shared flag and
//! the callback reads it.
//!
//! Result messages (all arrays in local coordinates, see `mesh_arrays`):
//! `{ stage, ms, report?, mesh?, scalars?: { name: { values, min, max, colormap } },
//!    lines?: { name: { segments, colors, triangles? } }, points?: { name: { positions, colors } }, counts? }`

use glam::{DVec3, Vec3};
use js_sys::{Float32Array, Function, Object, Reflect, Uint8Array, Uint32Array};
use wasm_bindgen::prelude::*;

use super::mesh_arrays::MeshArrays;
use crate::field::Singularity;
use crate::mesh::{PolyMesh, TriMesh};
use crate::pipeline::{Params, Pipeline, PipelineError, RemeshMode, Stage};

const STEPS: [&str; 2] = ["import", "pipeline"];

/// One run of the pipeline over one input file, kept between messages.
/// The limit surface of a fit as the page draws it: `{ name, positions,
/// triangles, normals, scalar }`, coloured by the signed error on a
/// symmetric range. Shared with the design mode's fit.
pub fn limit_surface_object(f: &crate::subdivision::FitResult) -> Result<Object, JsError> {
    let faces = f.limit.to_face_list();
    let tri = TriMesh {
        positions: f.limit.positions.clone(),
        triangles: faces.triangulate(&f.limit.positions),
    };
    let arrays = MeshArrays::new(&tri, &faces);
    let values: Vec<f32> = f
        .after
        .per_vertex_signed
        .iter()
        .map(|&v| v as f32)
        .collect();
    // Diverging map: a symmetric range around zero (98th percentile
    // of |error|), so white means "on the input".
    let abs: Vec<f32> = values.iter().map(|v| v.abs()).collect();
    let m = robust_range(&abs).1.max(1e-9);
    let scalar = Object::new();
    set(&scalar, "name", "limit surface error")?;
    set(&scalar, "values", Float32Array::from(&values[..]))?;
    set(&scalar, "min", -m)?;
    set(&scalar, "max", m)?;
    set(&scalar, "colormap", "violet-green")?;
    let surface = surface_object(
        "limit surface",
        &arrays.positions,
        &arrays.triangles,
        &arrays.normals,
    )?;
    set(&surface, "scalar", scalar)?;
    Ok(surface)
}

/// What the integer-grid map depends on, for the page's parameters (an
/// object shaped as [`Params`]): the JSON text of the map's own parameters
/// ([`crate::param::Params::from_pipeline`]) and the remeshing mode (the
/// global mode's map is the pipeline's own, on the mesh its fields use), a
/// key the page compares; it keeps the map across a parameter change that
/// leaves the key the same.
#[wasm_bindgen(js_name = gridMapKey)]
pub fn grid_map_key(params: JsValue) -> Result<String, JsError> {
    let params = params_from_js(params)?;
    serde_json::to_string(&serde_json::json!({
        "mode": params.remesh.mode,
        "map": crate::param::Params::from_pipeline(&params),
    }))
    .map_err(js_err)
}

#[wasm_bindgen]
#[derive(Default)]
pub struct Session {
    name: String,
    bytes: Vec<u8>,
    next: usize,
    params: Params,
    pipeline: Option<Pipeline>,
    /// Milliseconds of the latest run of each stage, in pipeline order.
    timings: Vec<(String, f64)>,
    /// The stages run since the latest `start` or parameter change.
    stages_run: Vec<String>,
    /// The metrics of the post-processed mesh (`quadrille remesh --stats`'s
    /// `metrics`), and the fitting summary (its `limit_surface`).
    metrics: Option<serde_json::Value>,
    limit_surface: Option<serde_json::Value>,
    cancelled: bool,
}

/// Records `ms` for `stage`, replacing an earlier run's time and keeping
/// the pipeline's order.
fn record_timing(timings: &mut Vec<(String, f64)>, stage: &str, ms: f64) {
    let order = |name: &str| {
        std::iter::once("import")
            .chain(Stage::EVERY.iter().map(|s| s.name()))
            .position(|s| s == name)
            .unwrap_or(usize::MAX)
    };
    timings.retain(|(s, _)| s != stage);
    let at = timings
        .iter()
        .position(|(s, _)| order(s) > order(stage))
        .unwrap_or(timings.len());
    timings.insert(at, (stage.to_string(), ms));
}

fn set(target: &Object, key: &str, value: impl Into<JsValue>) -> Result<(), JsError> {
    Reflect::set(target, &JsValue::from_str(key), &value.into())
        .map(|_| ())
        .map_err(|_| JsError::new(&format!("could not set {key}")))
}

/// A small structured value (parameters, summaries, a stage's metadata)
/// as a plain JS value through serde-wasm-bindgen, shaped as its JSON
/// would be (maps as objects, `None` as `null`); big arrays go as typed
/// arrays instead.
pub(crate) fn to_js<T: serde::Serialize + ?Sized>(value: &T) -> Result<JsValue, JsError> {
    value
        .serialize(&serde_wasm_bindgen::Serializer::json_compatible())
        .map_err(|e| JsError::new(&format!("could not encode a result: {e}")))
}

/// The page's parameters (a plain object shaped as [`Params`]' JSON;
/// missing fields take their defaults), or an error naming what is wrong.
fn params_from_js(value: JsValue) -> Result<Params, JsError> {
    if value.is_undefined() || value.is_null() {
        return Ok(Params::default());
    }
    if let Some((path, x)) = first_non_finite(&value, "") {
        let x = match x {
            x if x.is_nan() => "NaN",
            x if x > 0.0 => "Infinity",
            _ => "-Infinity",
        };
        return Err(js_err(format!(
            "parameters: {path} is {x}, not a finite number"
        )));
    }
    serde_wasm_bindgen::from_value(value).map_err(|e| js_err(format!("parameters: {e}")))
}

/// The path and value of the first number in `value` that is not finite:
/// a JS object can carry NaN and ±Infinity (JSON text cannot), and no
/// parameter takes them (an infinite weight is `null`).
fn first_non_finite(value: &JsValue, path: &str) -> Option<(String, f64)> {
    if let Some(x) = value.as_f64() {
        return (!x.is_finite()).then(|| (path.to_string(), x));
    }
    if !value.is_object() {
        return None;
    }
    let entries = Object::entries(value.unchecked_ref::<Object>());
    entries.iter().find_map(|entry| {
        let pair: js_sys::Array = entry.unchecked_into();
        let key = pair.get(0).as_string().unwrap_or_default();
        let inner = if path.is_empty() {
            key
        } else {
            format!("{path}.{key}")
        };
        first_non_finite(&pair.get(1), &inner)
    })
}

fn js_err(e: impl std::fmt::Display) -> JsError {
    JsError::new(&e.to_string())
}

/// A stage result under construction.
struct StageResult {
    obj: Object,
}

impl StageResult {
    fn new(stage: &str, ms: f64) -> Result<Self, JsError> {
        let obj = Object::new();
        set(&obj, "stage", stage)?;
        set(&obj, "ms", ms)?;
        Ok(StageResult { obj })
    }

    fn group(&self, key: &str) -> Result<Object, JsError> {
        let existing =
            Reflect::get(&self.obj, &JsValue::from_str(key)).unwrap_or(JsValue::UNDEFINED);
        if existing.is_object() {
            return Ok(existing.into());
        }
        let group = Object::new();
        set(&self.obj, key, group.clone())?;
        Ok(group)
    }

    /// A per-vertex scalar shown over [min, max] (robust: the 2nd and 98th
    /// percentiles, so a few extreme values do not wash out the map).
    fn scalar(&self, name: &str, values: &[f64], colormap: &str) -> Result<(), JsError> {
        let values: Vec<f32> = values.iter().map(|&v| v as f32).collect();
        let (min, max) = robust_range(&values);
        let entry = Object::new();
        set(&entry, "values", Float32Array::from(&values[..]))?;
        set(&entry, "min", min)?;
        set(&entry, "max", max)?;
        set(&entry, "colormap", colormap)?;
        set(&self.group("scalars")?, name, entry)
    }

    fn lines(&self, name: &str, segments: &[f32], colors: &[u8]) -> Result<(), JsError> {
        let entry = Object::new();
        set(&entry, "segments", Float32Array::from(segments))?;
        set(&entry, "colors", Uint8Array::from(colors))?;
        set(&self.group("lines")?, name, entry)
    }

    /// A field's glyph layer: a line layer with the field mesh's triangles
    /// (`triangles`, site index triples), over which the viewer places
    /// glyphs between the vertices when zoomed in.
    fn glyphs(
        &self,
        name: &str,
        segments: &[f32],
        colors: &[u8],
        mesh: &TriMesh,
    ) -> Result<(), JsError> {
        let triangles: Vec<u32> = mesh.triangles.iter().flatten().copied().collect();
        let entry = Object::new();
        set(&entry, "segments", Float32Array::from(segments))?;
        set(&entry, "colors", Uint8Array::from(colors))?;
        set(&entry, "triangles", Uint32Array::from(&triangles[..]))?;
        set(&self.group("lines")?, name, entry)
    }

    fn points(&self, name: &str, positions: &[f32], colors: &[u8]) -> Result<(), JsError> {
        let entry = Object::new();
        set(&entry, "positions", Float32Array::from(positions))?;
        set(&entry, "colors", Uint8Array::from(colors))?;
        set(&self.group("points")?, name, entry)
    }

    fn count(&self, name: &str, n: usize) -> Result<(), JsError> {
        set(&self.group("counts")?, name, n as f64)
    }
}

fn robust_range(values: &[f32]) -> (f32, f32) {
    let mut finite: Vec<f32> = values.iter().copied().filter(|v| v.is_finite()).collect();
    if finite.is_empty() {
        return (0.0, 1.0);
    }
    finite.sort_unstable_by(f32::total_cmp);
    let at = |q: f64| finite[((finite.len() - 1) as f64 * q).round() as usize];
    let (lo, hi) = (at(0.02), at(0.98));
    if lo < hi {
        (lo, hi)
    } else {
        (finite[0], finite[finite.len() - 1].max(finite[0] + 1e-6))
    }
}

const D1_COLOR: [u8; 4] = [0xc0, 0x39, 0x2b, 0xff];
const D2_COLOR: [u8; 4] = [0x1f, 0x5f, 0xbf, 0xff];
const FEATURE_COLOR: [u8; 4] = [0xe6, 0x8a, 0x00, 0xff];
const CROSS_COLOR: [u8; 4] = [0x1d, 0x23, 0x30, 0xff];
const POSITION_COLOR: [u8; 4] = [0xff, 0x7f, 0x0e, 0xff];

/// Colour of a singularity by its index, as in the papers' figures: +1/4
/// (valence 3) blue, −1/4 (valence 5) red, others (position) green.
fn singularity_color(index: i32) -> [u8; 4] {
    match index {
        1 => [0x1f, 0x6f, 0xdd, 0xff],
        -1 => [0xd8, 0x34, 0x2c, 0xff],
        _ => [0x1b, 0x9e, 0x4b, 0xff],
    }
}

fn push(out: &mut Vec<f32>, p: Vec3) {
    out.extend_from_slice(&p.to_array());
}

/// A segment of half-length `h` through `p` along `d`.
fn centred(out: &mut Vec<f32>, p: Vec3, d: Vec3, h: f32) {
    push(out, p - d * h);
    push(out, p + d * h);
}

fn singularity_points(result: &StageResult, name: &str, s: &[Singularity]) -> Result<(), JsError> {
    let mut positions = Vec::with_capacity(s.len() * 3);
    let mut colors = Vec::with_capacity(s.len() * 4);
    for x in s {
        push(&mut positions, x.position);
        colors.extend_from_slice(&singularity_color(x.index));
    }
    result.points(name, &positions, &colors)?;
    result.count(name, s.len())
}

const NON_QUAD_COLORS: [[u8; 4]; 2] = [[0xf2, 0x8e, 0x2b, 0xff], [0x8e, 0x44, 0xad, 0xff]];

/// A polygon mesh as a line layer of its true edges (quads stay quads),
/// with counts and, if `non_quads`, its non-quad faces as markers
/// (triangles orange, five or more sides violet).
fn poly_mesh_layers(
    r: &StageResult,
    name: &str,
    mesh: &PolyMesh,
    non_quads: bool,
) -> Result<(), JsError> {
    let faces = mesh.to_face_list();
    let (edges, _) = super::mesh_arrays::polygon_edges(&faces);
    let position = |v: u32| mesh.positions[v as usize].as_vec3();
    let mut segments = Vec::with_capacity(edges.len() * 3);
    for &v in &edges {
        push(&mut segments, position(v));
    }
    r.lines(name, &segments, &[0x11, 0x11, 0x11, 0xff])?;
    r.count(&format!("{name} vertices"), mesh.vertex_count())?;
    r.count(&format!("{name} faces"), faces.len())?;
    let quads = faces.iter().filter(|f| f.len() == 4).count();
    r.count(&format!("{name} quads"), quads)?;
    if non_quads {
        let (mut positions, mut colors) = (Vec::new(), Vec::new());
        for f in faces.iter().filter(|f| f.len() != 4) {
            let c = f.iter().map(|&v| position(v)).sum::<Vec3>() / f.len() as f32;
            push(&mut positions, c);
            colors.extend_from_slice(&NON_QUAD_COLORS[usize::from(f.len() > 4)]);
        }
        r.points("non-quad faces", &positions, &colors)?;
    }
    Ok(())
}

/// A polygon mesh as a drawable surface with its faces coloured by degree:
/// every face gets its own corners (one colour) with the mesh's vertex
/// normals (the viewer shades flat on request and across creases),
/// fan-triangulated.
fn face_degree_surface(name: &str, mesh: &PolyMesh) -> Result<Object, JsError> {
    let faces = mesh.to_face_list();
    let (mut positions, mut normals, mut triangles, mut degree) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    // Area-weighted vertex normals: each face adds its (twice) vector area.
    let mut vertex_normals = vec![DVec3::ZERO; mesh.positions.len()];
    for f in faces.iter() {
        let mut n = DVec3::ZERO;
        for k in 0..f.len() {
            let (a, b) = (f[k] as usize, f[(k + 1) % f.len()] as usize);
            n += mesh.positions[a].cross(mesh.positions[b]);
        }
        for &v in f {
            vertex_normals[v as usize] += n;
        }
    }
    for f in faces.iter() {
        let base = (positions.len() / 3) as u32;
        for &v in f {
            push(&mut positions, mesh.positions[v as usize].as_vec3());
            push(
                &mut normals,
                vertex_normals[v as usize].normalize_or_zero().as_vec3(),
            );
            degree.push(f.len() as f32);
        }
        for k in 1..f.len().saturating_sub(1) as u32 {
            triangles.extend_from_slice(&[base, base + k, base + k + 1]);
        }
    }
    let scalar = Object::new();
    set(&scalar, "name", "face degree")?;
    set(&scalar, "values", Float32Array::from(&degree[..]))?;
    set(&scalar, "min", 3.0)?;
    set(&scalar, "max", 6.0)?;
    set(&scalar, "colormap", "face-degree")?;
    let surface = Object::new();
    set(&surface, "name", name)?;
    set(&surface, "positions", Float32Array::from(&positions[..]))?;
    set(&surface, "triangles", Uint32Array::from(&triangles[..]))?;
    set(&surface, "normals", Float32Array::from(&normals[..]))?;
    set(&surface, "scalar", scalar)?;
    Ok(surface)
}

/// The smooth regions (Campen et al. 2016) as a surface with one colour per
/// filtered region and the discarded ones grey: every input triangle gets
/// its own corners, so triangle `t` of this surface is input face `t`, and
/// `faceRegion[t]` (−1: none) and `regionSignificance[region]` (degrees)
/// serve the pick readout.
fn smooth_region_surface(
    mesh: &TriMesh,
    regions: &crate::analysis::smooth_regions::SmoothRegions,
) -> Result<Object, JsError> {
    let n = mesh.face_count();
    let (mut positions, mut normals, mut values) = (
        Vec::with_capacity(n * 9),
        Vec::with_capacity(n * 9),
        Vec::with_capacity(n * 3),
    );
    let mut face_region = Vec::with_capacity(n);
    for (f, t) in mesh.triangles.iter().enumerate() {
        let normal = mesh
            .face_normal_unnormalized(f)
            .normalize_or_zero()
            .as_vec3();
        let region = regions.region_of_face.get(f).copied().flatten();
        let category = match region {
            Some(r) if regions.filtered[r as usize] => 1.0 + (r % 12) as f32,
            _ => 0.0,
        };
        face_region.push(region.map_or(-1, |r| r as i32));
        for &v in t {
            push(&mut positions, mesh.positions[v as usize].as_vec3());
            push(&mut normals, normal);
            values.push(category);
        }
    }
    let triangles: Vec<u32> = (0..(n * 3) as u32).collect();
    let significance: Vec<f32> = regions.significance.iter().map(|&s| s as f32).collect();
    let scalar = Object::new();
    set(&scalar, "name", "smooth regions (grey: discarded)")?;
    set(&scalar, "values", Float32Array::from(&values[..]))?;
    set(&scalar, "min", 0.0)?;
    set(&scalar, "max", 12.0)?;
    set(&scalar, "colormap", "categories")?;
    let surface = Object::new();
    set(&surface, "name", "smooth regions")?;
    set(&surface, "positions", Float32Array::from(&positions[..]))?;
    set(&surface, "triangles", Uint32Array::from(&triangles[..]))?;
    set(&surface, "normals", Float32Array::from(&normals[..]))?;
    set(&surface, "scalar", scalar)?;
    set(
        &surface,
        "faceRegion",
        js_sys::Int32Array::from(&face_region[..]),
    )?;
    set(
        &surface,
        "regionSignificance",
        Float32Array::from(&significance[..]),
    )?;
    let filtered: Vec<u8> = regions.filtered.iter().map(|&b| b as u8).collect();
    set(&surface, "regionFiltered", Uint8Array::from(&filtered[..]))?;
    Ok(surface)
}

/// The position field's lattice points and singularities.
fn position_layers(r: &StageResult, pos: &crate::pipeline::PositionStage) -> Result<(), JsError> {
    let positions: Vec<f32> = pos.o.iter().flat_map(|p| p.to_array()).collect();
    r.points("position field", &positions, &POSITION_COLOR)?;
    singularity_points(r, "position singularities", &pos.singularities)
}

/// The integer-grid map `run` of `mesh` as the page draws it: `surface`
/// (per-corner `uv` and `colors`, flipped triangles tinted), the cones as
/// the point layer `parametrization cones` (index +¼ blue, −¼ red),
/// `counts` and `param` (timings and Campen §5's measures).
fn parametrization_layers(
    r: &StageResult,
    mesh: &TriMesh,
    run: &crate::param::Run,
    params: &crate::param::Params,
    ms: f64,
) -> Result<(), JsError> {
    let arrays = super::mesh_arrays::GridMapArrays::new(mesh, &run.map);
    let surface = surface_object(
        "parametrization",
        &arrays.positions,
        &arrays.triangles,
        &arrays.normals,
    )?;
    set(&surface, "uv", Float32Array::from(&arrays.uv[..]))?;
    set(&surface, "colors", Uint8Array::from(&arrays.colors[..]))?;
    set(&r.obj, "surface", surface)?;
    let (mut positions, mut colors) = (Vec::new(), Vec::new());
    for c in &run.map.cones {
        push(&mut positions, mesh.positions[c.vertex as usize].as_vec3());
        colors.extend_from_slice(&singularity_color(c.quarters));
    }
    r.points("parametrization cones", &positions, &colors)?;
    r.count("parametrization cones", run.map.cones.len())?;
    r.count("flipped triangles", arrays.flipped)?;
    let summary = serde_json::json!({
        "ms": ms,
        "timings": run.timings,
        "measures": run.measures,
        "integer_conflicts": run.map.conflicts,
        "rounding_steps": run.map.rounding_steps,
        "alignment": params.alignment,
        "closed_loops": run.map.closed_loops,
        "widened_loops": run.map.widened_loops,
    });
    set(&r.obj, "param", to_js(&summary)?)
}

/// The page-facing result of one pipeline stage.
fn stage_result(
    stage: Stage,
    p: &Pipeline,
    ms: f64,
    metrics: Option<&serde_json::Value>,
) -> Result<JsValue, JsError> {
    let r = StageResult::new(stage.name(), ms)?;
    // The fields' mesh: the input, or the input with long edges split, whose
    // first vertices are the input's (the page colours those).
    let mesh = p.field_mesh();
    let input_vertices = p.input.mesh.vertex_count();
    let as_vec3 = |v: DVec3| v.as_vec3();
    match stage {
        Stage::Analysis => {
            let Some(a) = &p.analysis else {
                return Ok(JsValue::UNDEFINED);
            };
            let s = &a.surface;
            r.scalar("curvature", &s.averaged[..input_vertices], "viridis")?;
            let sizing = &s.sizing.edge_length[..input_vertices];
            r.scalar("sizing field", sizing, "viridis")?;
            let mut segments = Vec::with_capacity(mesh.vertex_count() * 12);
            let mut colors = Vec::with_capacity(mesh.vertex_count() * 8);
            for (v, c) in s.curvature.iter().enumerate() {
                let p = as_vec3(mesh.positions[v]);
                let h = (s.sizing.edge_length[v] * 0.35) as f32;
                // d1 × d2 along the normal: the viewer keeps glyphs that face the eye.
                let n = s.vertex_normals.get(v).copied().unwrap_or_default();
                let d2 = if c.d1.cross(c.d2).dot(n) < 0.0 {
                    -c.d2
                } else {
                    c.d2
                };
                centred(&mut segments, p, as_vec3(c.d1), h);
                centred(&mut segments, p, as_vec3(d2), h);
                colors.extend_from_slice(&D1_COLOR);
                colors.extend_from_slice(&D2_COLOR);
            }
            r.glyphs("principal directions", &segments, &colors, mesh)?;
            let features = s.features.indices();
            let positions: Vec<f32> = features
                .iter()
                .flat_map(|&v| as_vec3(mesh.positions[v as usize]).to_array())
                .collect();
            r.points("feature vertices", &positions, &FEATURE_COLOR)?;
            r.count("feature vertices", features.len())?;
        }
        Stage::Hierarchy => {
            let Some(h) = &p.hierarchy else {
                return Ok(JsValue::UNDEFINED);
            };
            r.count("levels", h.hierarchy.levels.len())?;
        }
        Stage::Orientation => {
            let (Some(o), Some(h)) = (&p.orientation, &p.hierarchy) else {
                return Ok(JsValue::UNDEFINED);
            };
            let level = &h.hierarchy.levels[0];
            let mut segments = Vec::with_capacity(level.positions.len() * 12);
            for (v, &q) in o.q[0].iter().enumerate() {
                let n = level.normals[v];
                let h = h.scale[0].get(v).copied().unwrap_or(0.01) * 0.35;
                centred(&mut segments, level.positions[v], q, h);
                centred(&mut segments, level.positions[v], n.cross(q), h);
            }
            // Level 0 is the field mesh, vertex for vertex.
            debug_assert_eq!(level.positions.len(), mesh.vertex_count());
            r.glyphs("cross field", &segments, &CROSS_COLOR, mesh)?;
            singularity_points(&r, "orientation singularities", &o.singularities)?;
            if let Some(regions) = &o.smooth_regions {
                set(&r.obj, "surface", smooth_region_surface(mesh, regions)?)?;
                r.count("smooth regions", regions.region_count())?;
                r.count(
                    "filtered smooth regions",
                    regions.filtered.iter().filter(|&&f| f).count(),
                )?;
            }
        }
        Stage::Position => {
            let Some(pos) = &p.position else {
                return Ok(JsValue::UNDEFINED);
            };
            position_layers(&r, pos)?;
        }
        Stage::Parametrization => {
            let Some(s) = &p.parametrization else {
                return Ok(JsValue::UNDEFINED);
            };
            parametrization_layers(&r, p.map_mesh(), &s.run, &s.params, ms)?;
        }
        Stage::Extraction => {
            let Some(e) = &p.extraction else {
                return Ok(JsValue::UNDEFINED);
            };
            poly_mesh_layers(&r, "extracted mesh", e.extracted.mesh(), false)?;
            // A restart kept another seed's position field: show that one.
            let restarted = e.extracted.local().is_some_and(|x| x.report.attempts > 1);
            if let (true, Some(pos)) = (restarted, &p.position) {
                position_layers(&r, pos)?;
            }
            if let Some(q) = e.extracted.qex() {
                set(&r.obj, "qex", to_js(q)?)?;
            }
        }
        Stage::PostProcess => {
            let Some(pp) = &p.postprocess else {
                return Ok(JsValue::UNDEFINED);
            };
            poly_mesh_layers(&r, "quad mesh", pp.mesh(), true)?;
            set(
                &r.obj,
                "surface",
                face_degree_surface("quad mesh faces", pp.mesh())?,
            )?;
            if let Some(m) = metrics {
                set(&r.obj, "metrics", to_js(m)?)?;
            }
        }
        Stage::Fit => {
            let Some(f) = &p.fit else {
                return Ok(JsValue::UNDEFINED);
            };
            let f = &f.result;
            poly_mesh_layers(&r, "control cage", &f.control, false)?;
            r.count("limit surface vertices", f.limit.vertex_count())?;
            set(&r.obj, "surface", limit_surface_object(f)?)?;
            set(&r.obj, "limitSurface", to_js(&f.summary)?)?;
        }
    }
    Ok(r.obj.into())
}

#[wasm_bindgen]
impl Session {
    #[wasm_bindgen(constructor)]
    pub fn new() -> Session {
        Session::default()
    }

    /// Starts a run on a file's bytes, dropping the previous run's results.
    pub fn start(&mut self, bytes: Vec<u8>, name: String) {
        *self = Session {
            name,
            bytes,
            params: std::mem::take(&mut self.params),
            ..Session::default()
        };
    }

    /// Every parameter: `[{ path, help, kind, min?, max?, options?,
    /// nullable, default }]` ([`crate::params_schema::schema_json`]).
    #[wasm_bindgen(js_name = parameterSchema)]
    pub fn parameter_schema() -> Result<JsValue, JsError> {
        to_js(&crate::params_schema::schema_json())
    }

    /// New parameters (a plain object shaped as [`Params`]' JSON; missing
    /// fields take their defaults). Returns the first stage that must run
    /// again, or `undefined` when nothing changed; the next `step` runs
    /// from there.
    #[wasm_bindgen(js_name = setParams)]
    pub fn set_params(&mut self, params: JsValue) -> Result<Option<String>, JsError> {
        let params = params_from_js(params)?;
        let changed = match self.pipeline.as_mut() {
            Some(p) => p.set_params(params.clone()),
            None => None,
        };
        // The other mode's stage times go with its outputs (`summary`'s
        // `stages` and `total_ms` are the current mode's).
        let mode = Stage::remeshing(params.remesh.mode);
        self.timings.retain(|(s, _)| {
            s == "import" || s == Stage::Fit.name() || mode.iter().any(|m| m.name() == s)
        });
        self.params = params;
        if let Some(stage) = changed {
            self.next = self.next.min(1);
            self.stages_run.clear();
            self.cancelled = false;
            if stage <= Stage::PostProcess {
                self.metrics = None;
            }
            self.limit_surface = None;
        }
        Ok(changed.map(|s| s.name().to_string()))
    }

    /// The file bytes of a result mesh: `kind` "quad-dominant" (the
    /// post-processed mesh), "pure-quad" (its Catmull–Clark split, or
    /// itself when it is all quads), "control" (the fitted control mesh)
    /// or "limit" (its limit surface); `format` "obj" or "ply" (binary).
    /// Coordinates are the input file's.
    pub fn export(&self, kind: &str, format: &str) -> Result<Vec<u8>, JsError> {
        let p = self
            .pipeline
            .as_ref()
            .ok_or_else(|| js_err("nothing was imported"))?;
        let pure_quad = p
            .postprocess
            .as_ref()
            .filter(|_| kind == "pure-quad")
            .map(|s| {
                let m = s.mesh();
                if m.to_face_list().iter().all(|f| f.len() == 4) {
                    m.clone()
                } else {
                    crate::subdivision::subdivide(m, self.params.fit.boundary)
                }
            });
        let mesh: &PolyMesh = match kind {
            "quad-dominant" => p.postprocess.as_ref().map(|s| s.mesh()),
            "pure-quad" => pure_quad.as_ref(),
            "control" => p.fit.as_ref().map(|f| &f.result.control),
            "limit" => p.fit.as_ref().map(|f| &f.result.limit),
            _ => return Err(js_err(format!("unknown export {kind}"))),
        }
        .ok_or_else(|| js_err(format!("the {kind} mesh is not computed yet")))?;
        let world: Vec<DVec3> = mesh
            .positions
            .iter()
            .map(|&x| p.input.frame.to_world(x))
            .collect();
        let faces = mesh.to_face_list();
        // The control mesh's OBJ carries its sharp creases (OpenSubdiv's
        // `t crease` tags); PLY has no place for them.
        let creases = match (kind, &p.fit) {
            ("control", Some(f)) => f.result.crease_vertex_pairs(),
            _ => Vec::new(),
        };
        match format {
            "obj" => Ok(crate::io::write_obj_with_creases(&world, &faces, &creases).into_bytes()),
            "ply" => Ok(crate::io::write_ply(
                &world,
                &faces,
                crate::io::PlyEncoding::BinaryLittleEndian,
            )),
            _ => Err(js_err(format!("unknown format {format}"))),
        }
    }

    /// The step `step` runs next, or `undefined` when the run is complete.
    #[wasm_bindgen(js_name = nextStep)]
    pub fn next_step(&self) -> Option<String> {
        STEPS.get(self.next).map(|s| s.to_string())
    }

    /// Whether the last step stopped because `progress` returned false.
    #[wasm_bindgen(getter)]
    pub fn cancelled(&self) -> bool {
        self.cancelled
    }

    /// Runs the next step. `progress(stage, fraction, text)` is called at
    /// least at every stage's start and end and at most every 50 ms in
    /// between; returning `false` cancels. `emit(result)` receives each
    /// stage's result as soon as it exists. Errors are thrown as `Error`s
    /// with the message (file and place for input errors).
    pub fn step(&mut self, progress: &Function, emit: &Function) -> Result<(), JsError> {
        let Some(&step) = STEPS.get(self.next) else {
            return Ok(());
        };
        match step {
            "import" => self.import(progress, emit)?,
            _ => self.run_pipeline(progress, emit)?,
        }
        if !self.cancelled {
            self.next += 1;
        }
        Ok(())
    }

    fn import(&mut self, progress: &Function, emit: &Function) -> Result<(), JsError> {
        let call = |fraction: f64, text: &str| {
            let _ = progress.call3(
                &JsValue::NULL,
                &"import".into(),
                &fraction.into(),
                &text.into(),
            );
        };
        call(0.0, "reading");
        let started = js_sys::Date::now();
        let bytes = std::mem::take(&mut self.bytes);
        let imported = crate::io::import(&bytes, &self.name).map_err(js_err)?;
        drop(bytes);
        let arrays = MeshArrays::new(&imported.mesh, &imported.polygons);
        let ms = js_sys::Date::now() - started;
        let r = StageResult::new("import", ms)?;
        set(&r.obj, "report", to_js(&imported.report)?)?;
        let mesh = Object::new();
        set(
            &mesh,
            "positions",
            Float32Array::from(&arrays.positions[..]),
        )?;
        set(&mesh, "triangles", Uint32Array::from(&arrays.triangles[..]))?;
        set(&mesh, "normals", Float32Array::from(&arrays.normals[..]))?;
        set(
            &mesh,
            "polygonEdges",
            Uint32Array::from(&arrays.polygon_edges[..]),
        )?;
        set(
            &mesh,
            "boundaryEdges",
            Uint32Array::from(&arrays.boundary_edges[..]),
        )?;
        set(&r.obj, "mesh", mesh)?;
        record_timing(&mut self.timings, "import", ms);
        self.stages_run.push("import".into());
        call(1.0, &format!("{} vertices", imported.mesh.vertex_count()));
        let mut pipeline = Pipeline::new(imported, self.params.clone());
        pipeline.fit_enabled = true;
        self.pipeline = Some(pipeline);
        emit.call1(&JsValue::NULL, &r.obj)
            .map(|_| ())
            .map_err(|_| js_err("could not send the import result"))
    }

    fn run_pipeline(&mut self, progress: &Function, emit: &Function) -> Result<(), JsError> {
        let Some(pipeline) = self.pipeline.as_mut() else {
            return Err(js_err("nothing was imported"));
        };
        crate::pipeline::check_target(pipeline.input.mesh.vertex_count(), &pipeline.params.sizing)
            .map_err(|e| js_err(format!("{}: {e}", pipeline.input.name)))?;
        let mut last = f64::NEG_INFINITY;
        let mut go_on = true;
        let mut sink = |stage: &str, fraction: f32, text: &str| {
            let now = js_sys::Date::now();
            if fraction <= 0.0 || fraction >= 1.0 || now - last >= 50.0 {
                last = now;
                go_on = progress
                    .call3(
                        &JsValue::NULL,
                        &stage.into(),
                        &(fraction as f64).into(),
                        &text.into(),
                    )
                    .map(|v| v.as_bool() != Some(false))
                    .unwrap_or(true);
            }
            go_on
        };
        let mut failure: Option<JsError> = None;
        let mut finished: Vec<(String, f64)> = Vec::new();
        let mut metrics = self.metrics.take();
        let mut limit_surface = self.limit_surface.take();
        let mut done = |stage: Stage, p: &Pipeline| {
            let ms = p
                .timings
                .iter()
                .find(|(s, _)| *s == stage)
                .map_or(0.0, |t| t.1);
            finished.push((stage.name().to_string(), ms));
            if failure.is_some() {
                return;
            }
            // The metrics of `quadrille remesh --stats`, for the page's panel.
            if stage == Stage::PostProcess {
                metrics = match (&p.postprocess, &p.surface) {
                    (Some(pp), Some(index)) => serde_json::to_value(crate::metrics::metrics(
                        pp.mesh(),
                        &p.input.mesh,
                        index,
                    ))
                    .ok(),
                    _ => None,
                };
            }
            if stage == Stage::Fit {
                limit_surface = p
                    .fit
                    .as_ref()
                    .and_then(|f| serde_json::to_value(&f.result.summary).ok());
            }
            match stage_result(stage, p, ms, metrics.as_ref()) {
                Ok(result) if !result.is_undefined() => {
                    if emit.call1(&JsValue::NULL, &result).is_err() {
                        failure = Some(js_err("could not send a stage result"));
                    }
                }
                Ok(_) => {}
                Err(e) => failure = Some(e),
            }
        };
        let outcome = pipeline.run(&mut sink, &mut done, &js_sys::Date::now);
        for (stage, ms) in finished {
            record_timing(&mut self.timings, &stage, ms);
            self.stages_run.push(stage);
        }
        self.metrics = metrics;
        self.limit_surface = limit_surface;
        if let Some(e) = failure {
            return Err(e);
        }
        match outcome {
            Ok(()) => self.cancelled = false,
            Err(PipelineError::Cancelled) => self.cancelled = true,
            Err(e) => return Err(js_err(format!("{}: {e}", pipeline.input.name))),
        }
        Ok(())
    }

    /// The parametrization layer, computed only when the page asks for it
    /// (it takes seconds on big meshes) — in the global mode the pipeline's
    /// own map, sent again without computing it twice: the integer-grid map of the input
    /// ([`crate::param::run_with_progress`], with the pipeline's analysis
    /// and sizing parameters, so one unit is one target edge of the run's
    /// target), emitted as a `parametrization` stage result with
    /// `surface` (per-corner `uv` and `colors`, flipped triangles tinted),
    /// the cones as the point layer `parametrization cones` (index +¼
    /// blue, −¼ red), `counts` and `param` (timings and Campen §5's
    /// measures). Returns false when `progress` cancelled it.
    pub fn parametrize(&mut self, progress: &Function, emit: &Function) -> Result<bool, JsError> {
        let p = self
            .pipeline
            .as_ref()
            .ok_or_else(|| js_err("nothing was imported"))?;
        let params = crate::param::Params::from_pipeline(&self.params);
        let mut last = f64::NEG_INFINITY;
        let mut sink = |stage: &str, fraction: f32, text: &str| {
            let now = js_sys::Date::now();
            if fraction > 0.0 && fraction < 1.0 && now - last < 50.0 {
                return true;
            }
            last = now;
            progress
                .call3(
                    &JsValue::NULL,
                    &stage.into(),
                    &(fraction as f64).into(),
                    &text.into(),
                )
                .map(|v| v.as_bool() != Some(false))
                .unwrap_or(true)
        };
        let mut sink = crate::progress::Progress::new(&mut sink, "parametrization");
        // The global mode's map is the pipeline's own: no second computation.
        if let Some(s) = p
            .parametrization
            .as_ref()
            .filter(|_| p.mode() == RemeshMode::Global)
        {
            let ms = p
                .timings
                .iter()
                .find(|(stage, _)| *stage == Stage::Parametrization)
                .map_or(0.0, |t| t.1);
            let r = StageResult::new("parametrization", ms)?;
            parametrization_layers(&r, p.map_mesh(), &s.run, &s.params, ms)?;
            emit.call1(&JsValue::NULL, &r.obj)
                .map_err(|_| js_err("could not send the parametrization"))?;
            return Ok(true);
        }
        let started = js_sys::Date::now();
        let mesh = &p.input.mesh;
        let run =
            match crate::param::run_with_progress(mesh, &params, &js_sys::Date::now, &mut sink) {
                Ok(run) => run,
                Err(crate::param::ParamError::Cancelled) => return Ok(false),
                Err(e) => return Err(js_err(format!("{}: parametrization: {e}", p.input.name))),
            };
        let ms = js_sys::Date::now() - started;
        let r = StageResult::new("parametrization", ms)?;
        parametrization_layers(&r, run.map_mesh(mesh), &run, &params, ms)?;
        emit.call1(&JsValue::NULL, &r.obj)
            .map_err(|_| js_err("could not send the parametrization"))?;
        Ok(true)
    }

    /// What the page keeps as `window.quadrille.lastRun`: input name,
    /// parameters, milliseconds per stage, counts.
    pub fn summary(&self) -> Result<JsValue, JsError> {
        let stages: serde_json::Map<String, serde_json::Value> = self
            .timings
            .iter()
            .map(|(s, ms)| (s.clone(), serde_json::json!((ms * 10.0).round() / 10.0)))
            .collect();
        let counts = self.pipeline.as_ref().map(|p| {
            let m = &p.input;
            serde_json::json!({
                "vertices": m.mesh.vertex_count(),
                "triangles": m.mesh.face_count(),
                "polygons": m.polygons.len(),
                "feature_vertices": p.analysis.as_ref().map(|a| a.surface.features.indices().len()),
                "hierarchy_levels": p.hierarchy.as_ref().map(|h| h.hierarchy.levels.len()),
                "mode": p.mode(),
                "orientation_singularities": p.orientation.as_ref().map(|o| o.singularities.len()),
                "cones": p.parametrization.as_ref().map(|s| s.run.map.cones.len()),
                "position_singularities": p.position.as_ref().map(|o| o.singularities.len()),
                "quad_mesh_vertices": p.postprocess.as_ref().map(|q| q.mesh().vertex_count()),
                "quad_mesh_faces": p.postprocess.as_ref().map(|q| q.mesh().face_count()),
                "control_vertices": p.fit.as_ref().map(|f| f.result.control.vertex_count()),
                "control_faces": p.fit.as_ref().map(|f| f.result.control.face_count()),
                "limit_vertices": p.fit.as_ref().map(|f| f.result.limit.vertex_count()),
                "limit_faces": p.fit.as_ref().map(|f| f.result.limit.face_count()),
            })
        });
        to_js(&serde_json::json!({
            "input": self.name,
            "parameters": self.params,
            "stages": stages,
            "total_ms": (self.timings.iter().map(|(_, ms)| ms).sum::<f64>() * 10.0).round() / 10.0,
            "complete": self.next == STEPS.len(),
            "stagesRun": self.stages_run,
            "counts": counts,
            "metrics": self.metrics,
            "limit_surface": self.limit_surface,
        }))
    }
}

/// An extra surface for the page: its name, positions, triangles and
/// normals as typed arrays.
fn surface_object(
    name: &str,
    positions: &[f32],
    triangles: &[u32],
    normals: &[f32],
) -> Result<Object, JsError> {
    let surface = Object::new();
    set(&surface, "name", name)?;
    set(&surface, "positions", Float32Array::from(positions))?;
    set(&surface, "triangles", Uint32Array::from(triangles))?;
    set(&surface, "normals", Float32Array::from(normals))?;
    Ok(surface)
}
