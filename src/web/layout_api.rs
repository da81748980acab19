//! A small wasm entry for timing the dual-strip-weaving loop engine
//! (Campen & Kobbelt 2014, §5.2–§5.7; [`crate::layout`]) in a JS engine:
//! build g and g′ for one mesh, then answer hover queries (the best loop
//! through one vertex). `tests/e2e/bench_layout.mjs` times it under Node.
//!
//! [`LayoutDesigner`]: the design mode's session (§4.1) that lives in the
//! layout worker (`www/layout-worker.js`).

use glam::DVec3;
use js_sys::{Array, Float32Array, Object, Reflect, Uint8Array};
use wasm_bindgen::prelude::*;

use super::layout_glue as analysis_glue;
use crate::layout::design::{DesignError, LayoutDesign};
use crate::layout::symmetry::MirrorPlane;
use crate::layout::{ElasticaParams, LoopEngine, proxy};
use crate::mesh::{Frame, TriMesh};

/// One mesh's loop engine, built once.
#[wasm_bindgen]
pub struct LayoutEngine {
    mesh: TriMesh,
    engine: LoopEngine,
    last_closed: bool,
}

#[wasm_bindgen]
impl LayoutEngine {
    /// Imports a mesh file (any supported format, by `name`'s extension or
    /// content) and builds g and g′ with the default parameters.
    #[wasm_bindgen(constructor)]
    pub fn new(bytes: &[u8], name: &str) -> Result<LayoutEngine, JsError> {
        let imported = crate::io::import(bytes, name).map_err(|e| JsError::new(&e.to_string()))?;
        let engine = LoopEngine::new(&imported.mesh, &ElasticaParams::default());
        Ok(LayoutEngine {
            mesh: imported.mesh,
            engine,
            last_closed: false,
        })
    }

    #[wasm_bindgen(js_name = vertexCount)]
    pub fn vertex_count(&self) -> u32 {
        self.mesh.vertex_count() as u32
    }

    #[wasm_bindgen(js_name = faceCount)]
    pub fn face_count(&self) -> u32 {
        self.mesh.face_count() as u32
    }

    /// Number of g′-nodes.
    #[wasm_bindgen(js_name = nodeCount)]
    pub fn node_count(&self) -> u32 {
        self.engine.graph.node_count() as u32
    }

    /// Bytes of g and g′ (without the query buffers).
    #[wasm_bindgen(js_name = graphBytes)]
    pub fn graph_bytes(&self) -> f64 {
        self.engine.graph.memory_bytes() as f64
    }

    /// Bytes of g, g′ and the query buffers.
    #[wasm_bindgen(js_name = engineBytes)]
    pub fn engine_bytes(&self) -> f64 {
        self.engine.memory_bytes() as f64
    }

    /// g′-nodes settled by all queries so far.
    #[wasm_bindgen(js_name = settledNodes)]
    pub fn settled_nodes(&self) -> f64 {
        self.engine.settled_nodes() as f64
    }

    /// `count` random vertex indices (PCG32 seeded with `seed`), the same
    /// anchors as `examples/bench_layout.rs` for the same mesh.
    #[wasm_bindgen(js_name = benchVertices)]
    pub fn bench_vertices(&self, count: u32, seed: u64) -> Vec<u32> {
        use rand_core::{RngCore, SeedableRng};
        let mut rng = rand_pcg::Pcg32::seed_from_u64(seed);
        let n = self.mesh.vertex_count().max(1);
        (0..count)
            .map(|_| (rng.next_u32() as usize % n) as u32)
            .collect()
    }

    /// The hover query at input vertex `v`: the best loop's cost
    /// (normalised units); NaN when there is none or `v` is out of range.
    #[wasm_bindgen(js_name = bestLoopAtVertex)]
    pub fn best_loop_at_vertex(&mut self, v: u32) -> f64 {
        self.last_closed = false;
        let Some(&p) = self.mesh.positions.get(v as usize) else {
            return f64::NAN;
        };
        match self.engine.best_loop(p) {
            Some(l) => {
                self.last_closed = l.closed;
                l.cost
            }
            None => f64::NAN,
        }
    }

    /// Whether the last query's result was a closed loop (not a dual curve
    /// ending on the boundary).
    #[wasm_bindgen(js_name = lastWasClosed)]
    pub fn last_was_closed(&self) -> bool {
        self.last_closed
    }
}

/// The design mode's session (Campen & Kobbelt 2014 §4.1, [`LayoutDesign`])
/// in the layout worker: the mesh (or its proxy above
/// [`proxy::PROXY_ABOVE_FACES`] faces), its loop engine and the undoable
/// design state. Points cross as `[x, y, z]` in the page's (local)
/// coordinates; polylines as flat `Float32Array`s. The committed loops'
/// analysis, and the exports, grid and fit made from it, are the analysis
/// worker's ([`super::analysis_api::LayoutAnalyzer`]).
#[wasm_bindgen]
pub struct LayoutDesigner {
    mesh: TriMesh,
    input_faces: usize,
    design: LayoutDesign,
    /// The key ([`Self::key`]) last handed to the analysis worker, which
    /// also exports, grids and fits the layout of its newest analysis.
    posted: Option<Key>,
    last_error: Option<String>,
    /// The anchor inserted by the last grab, moved by the drag that follows.
    grabbed: Option<usize>,
    /// Whether the last progressive hover answered exactly.
    hover_exact: bool,
    /// The input (when the design runs on a proxy) and the file's frame,
    /// until [`Self::take_analysis_meshes`] hands them over.
    handover: Option<(Option<TriMesh>, Frame)>,
}

/// The mesh the design runs on (the input, or its proxy above
/// [`proxy::PROXY_ABOVE_FACES`] faces), the input when it is a proxy, the
/// file's frame and the input's face count. Made once, in the layout
/// worker, which hands the analysis worker its copy
/// ([`LayoutDesigner::take_analysis_meshes`]).
fn design_meshes(
    bytes: &[u8],
    name: &str,
) -> Result<(TriMesh, Option<TriMesh>, Frame, usize), JsError> {
    let imported = crate::io::import(bytes, name).map_err(|e| JsError::new(&e.to_string()))?;
    let input_faces = imported.mesh.face_count();
    let frame = imported.frame;
    Ok(if input_faces > proxy::PROXY_ABOVE_FACES {
        (
            proxy::decimate(&imported.mesh, proxy::PROXY_FACES),
            Some(imported.mesh),
            frame,
            input_faces,
        )
    } else {
        (imported.mesh, None, frame, input_faces)
    })
}

fn point(p: &[f64]) -> Result<DVec3, JsError> {
    match p {
        [x, y, z] if x.is_finite() && y.is_finite() && z.is_finite() => Ok(DVec3::new(*x, *y, *z)),
        _ => Err(JsError::new("a point needs three finite coordinates")),
    }
}

fn polyline(points: &[DVec3]) -> Float32Array {
    let flat: Vec<f32> = points
        .iter()
        .flat_map(|p| [p.x as f32, p.y as f32, p.z as f32])
        .collect();
    Float32Array::from(&flat[..])
}

pub(super) fn set(target: &Object, key: &str, value: impl Into<JsValue>) -> Result<(), JsError> {
    Reflect::set(target, &JsValue::from_str(key), &value.into())
        .map(|_| ())
        .map_err(|_| JsError::new(&format!("could not set {key}")))
}

#[wasm_bindgen]
impl LayoutDesigner {
    /// Imports a mesh file and builds the loop engine (on a decimated
    /// proxy of about [`proxy::PROXY_FACES`] faces for large meshes).
    #[wasm_bindgen(constructor)]
    pub fn new(bytes: &[u8], name: &str) -> Result<LayoutDesigner, JsError> {
        let (mesh, original, frame, input_faces) = design_meshes(bytes, name)?;
        let engine = LoopEngine::new(&mesh, &ElasticaParams::default());
        Ok(LayoutDesigner {
            mesh,
            input_faces,
            design: LayoutDesign::new(engine),
            posted: None,
            last_error: None,
            grabbed: None,
            hover_exact: true,
            handover: Some((original, frame)),
        })
    }

    /// One hover query at the first vertex, forgotten: settles the engine's
    /// lazily computed parts (the distances from the boundary node ∂ of
    /// §5.7, as far as that query needed) before the first real hover.
    /// Returns its milliseconds.
    #[wasm_bindgen(js_name = warmUp)]
    pub fn warm_up(&mut self) -> f64 {
        let started = now_ms();
        if let Some(&p) = self.mesh.positions.first() {
            self.design.hover(p);
        }
        self.design.clear_hover();
        now_ms() - started
    }

    /// Faces of the mesh the design runs on (the proxy's when there is one).
    #[wasm_bindgen(js_name = faceCount)]
    pub fn face_count(&self) -> u32 {
        self.mesh.face_count() as u32
    }

    #[wasm_bindgen(js_name = inputFaceCount)]
    pub fn input_face_count(&self) -> u32 {
        self.input_faces as u32
    }

    #[wasm_bindgen(js_name = usesProxy)]
    pub fn uses_proxy(&self) -> bool {
        self.mesh.face_count() != self.input_faces
    }

    /// The hover query: the proposal polyline at `p` (empty: none).
    pub fn hover(&mut self, p: &[f64]) -> Result<Float32Array, JsError> {
        let p = point(p)?;
        Ok(self
            .design
            .hover(p)
            .map_or_else(|| Float32Array::new_with_length(0), |l| polyline(&l.points)))
    }

    /// The hover query answered progressively: at most `budget` settled g′
    /// nodes of search now; the proposal polyline (empty: none) is the
    /// exact best loop when [`Self::hover_exact`] says so, else the
    /// cheapest loop or dual curve found so far, replaced by
    /// [`Self::hover_step`]'s answer.
    #[wasm_bindgen(js_name = hoverBegin)]
    pub fn hover_begin(&mut self, p: &[f64], budget: u32) -> Result<Float32Array, JsError> {
        let p = point(p)?;
        let (l, exact) = self.design.hover_begin(p, budget as u64);
        let out = l.map_or_else(|| Float32Array::new_with_length(0), |l| polyline(&l.points));
        self.hover_exact = exact;
        Ok(out)
    }

    /// Whether a hover with nothing else to show bridges to a recent loop
    /// (on by default; `?hoverBridge=0` turns it off, for benchmarks).
    #[wasm_bindgen(js_name = setHoverBridge)]
    pub fn set_hover_bridge(&mut self, on: bool) {
        self.design.engine.bridge = on;
    }

    /// Whether the last [`Self::hover_begin`] answered exactly.
    #[wasm_bindgen(js_name = hoverExact)]
    pub fn hover_exact(&self) -> bool {
        self.hover_exact
    }

    /// Resumes an unfinished hover for at most `budget` settled g′ nodes;
    /// returns the exact proposal once it is known (empty: no loop), else
    /// `undefined`.
    #[wasm_bindgen(js_name = hoverStep)]
    pub fn hover_step(&mut self, budget: u32) -> Option<Float32Array> {
        let l = self.design.hover_resume(budget as u64)?;
        Some(l.map_or_else(|| Float32Array::new_with_length(0), |l| polyline(&l.points)))
    }

    /// Whether the exact proposal [`Self::hover_step`] gave last is the
    /// provisional one shown before it (the same loop).
    #[wasm_bindgen(js_name = hoverUnchanged)]
    pub fn hover_unchanged(&self) -> bool {
        self.design.hover_unchanged()
    }

    /// Whether [`Self::hover_step`] has something to do.
    #[wasm_bindgen(js_name = hoverPending)]
    pub fn hover_pending(&self) -> bool {
        self.design.hover_pending()
    }

    /// The wheel: `delta` steps through the alternatives.
    pub fn browse(&mut self, delta: i32) {
        self.design.browse(delta);
    }

    /// A click (`direction` empty or zero) or the start of a drag.
    #[wasm_bindgen(js_name = addAnchor)]
    pub fn add_anchor(&mut self, p: &[f64], direction: &[f64]) -> Result<(), JsError> {
        let d = point(direction).ok();
        self.design.add_anchor(point(p)?, d);
        Ok(())
    }

    #[wasm_bindgen(js_name = setLastAnchorDirection)]
    pub fn set_last_anchor_direction(&mut self, direction: &[f64]) -> Result<(), JsError> {
        self.design.set_last_anchor_direction(point(direction)?);
        Ok(())
    }

    /// Grab: inserts an anchor where the loop was grabbed; returns its index.
    #[wasm_bindgen(js_name = insertAnchorOnLoop)]
    pub fn insert_anchor_on_loop(&mut self, grabbed: &[f64], p: &[f64]) -> Result<u32, JsError> {
        let i = self
            .design
            .insert_anchor_on_loop(point(grabbed)?, point(p)?);
        self.grabbed = Some(i);
        Ok(i as u32)
    }

    /// The drag after a grab: moves the anchor the grab inserted.
    #[wasm_bindgen(js_name = moveGrabbedAnchor)]
    pub fn move_grabbed_anchor(&mut self, p: &[f64]) -> Result<(), JsError> {
        let p = point(p)?;
        if let Some(i) = self.grabbed {
            self.design.move_anchor(i, p);
        }
        Ok(())
    }

    /// Idle time (between messages): settles a slice of `budget` g′ nodes
    /// of the distance fields the next grab, drag update or click reads,
    /// then of the distances from ∂ every hover reads; returns whether more
    /// remains. Changes no answer, only its time.
    #[wasm_bindgen(js_name = prepareFields)]
    pub fn prepare_fields(&mut self, budget: u32) -> bool {
        self.design.prepare_fields(budget as u64)
    }

    #[wasm_bindgen(js_name = clearAnchors)]
    pub fn clear_anchors(&mut self) {
        self.design.clear_anchors();
    }

    /// Enter: returns how many strips were added (0 with a reason in
    /// `state().error` when there was no loop).
    pub fn commit(&mut self) -> u32 {
        let r = self.design.commit().map(|n| n as u32);
        self.result(r)
    }

    #[wasm_bindgen(js_name = deleteStrip)]
    pub fn delete_strip(&mut self, i: u32) -> bool {
        let r = self.design.delete_strip(i as usize).map(|_| true);
        self.result(r)
    }

    pub fn undo(&mut self) -> bool {
        let r = self.design.undo().map(|_| true);
        self.result(r)
    }

    pub fn redo(&mut self) -> bool {
        let r = self.design.redo().map(|_| true);
        self.result(r)
    }

    #[wasm_bindgen(js_name = moveLayoutVertex)]
    pub fn move_layout_vertex(&mut self, vertex: u32, p: &[f64]) -> Result<(), JsError> {
        self.design.move_layout_vertex(vertex, point(p)?);
        Ok(())
    }

    /// The symmetry option: "off", "auto" (detected), "x", "y" or "z"
    /// (planes through the bounding-box centre). Returns the plane as
    /// `[px, py, pz, nx, ny, nz]`, empty when off or none was detected.
    #[wasm_bindgen(js_name = setMirror)]
    pub fn set_mirror(&mut self, mode: &str) -> Vec<f64> {
        let centre = self
            .mesh
            .bbox()
            .map_or(DVec3::ZERO, |b| (b.min + b.max) * 0.5);
        let mirror = match mode {
            "x" => MirrorPlane::new(centre, DVec3::X),
            "y" => MirrorPlane::new(centre, DVec3::Y),
            "z" => MirrorPlane::new(centre, DVec3::Z),
            "auto" => analysis_glue::detect_mirror(&self.mesh),
            _ => None,
        };
        self.design.set_mirror(mirror);
        mirror.map_or_else(Vec::new, |m| {
            vec![
                m.point.x, m.point.y, m.point.z, m.normal.x, m.normal.y, m.normal.z,
            ]
        })
    }

    /// The design state: `{ revision, loops: [{ id, points, mirrored, closed }],
    /// anchors: Float32Array (xyz), anchorDirections: Float32Array (xyz,
    /// zero = positional), proposal: Float32Array, selfCrossings: Float32Array
    /// (xyz), selfCrossingAngles: Float32Array (degrees), browse: [index, count],
    /// canUndo, canRedo, error }`.
    pub fn state(&mut self) -> Result<Object, JsError> {
        let d = &self.design;
        let out = Object::new();
        set(&out, "revision", d.revision() as f64)?;
        let loops = Array::new();
        for c in d.committed() {
            let l = Object::new();
            set(&l, "id", c.id as f64)?;
            set(&l, "points", polyline(&c.dual.points))?;
            set(&l, "mirrored", c.mirrored)?;
            set(&l, "closed", c.dual.closed)?;
            loops.push(&l);
        }
        set(&out, "loops", loops)?;
        let positions: Vec<DVec3> = d.anchors().iter().map(|a| a.position).collect();
        let directions: Vec<DVec3> = d.anchors().iter().map(|a| a.direction).collect();
        set(&out, "anchors", polyline(&positions))?;
        set(&out, "anchorDirections", polyline(&directions))?;
        let proposal = d.proposal().map_or_else(Vec::new, |l| l.points.clone());
        set(&out, "proposal", polyline(&proposal))?;
        // §8.1: where the proposal crosses itself, and at what angles.
        let crossings = d
            .proposal()
            .map_or_else(Vec::new, |l| d.engine.self_crossings(l));
        let points: Vec<DVec3> = crossings.iter().map(|c| c.point).collect();
        let angles: Vec<f32> = crossings.iter().map(|c| c.angle_degrees as f32).collect();
        set(&out, "selfCrossings", polyline(&points))?;
        set(&out, "selfCrossingAngles", Float32Array::from(&angles[..]))?;
        let (i, n) = d.browse_position();
        set(
            &out,
            "browse",
            Array::of2(&(i as u32).into(), &(n as u32).into()),
        )?;
        set(&out, "canUndo", d.can_undo())?;
        set(&out, "canRedo", d.can_redo())?;
        set(
            &out,
            "error",
            self.last_error.take().map_or(JsValue::NULL, JsValue::from),
        )?;
        Ok(out)
    }

    /// What the analysis worker needs for the current committed loops
    /// (`{ revision, points: Float64Array (xyz), lengths: Uint32Array
    /// (points per loop), closed: Uint8Array, moves: Float64Array (vertex,
    /// x, y, z) }`), or null when it was already handed out for them.
    #[wasm_bindgen(js_name = takeAnalysisInput)]
    pub fn take_analysis_input(&mut self) -> Result<JsValue, JsError> {
        let key = self.key();
        if self.posted.as_ref() == Some(&key) {
            return Ok(JsValue::NULL);
        }
        let out = Object::new();
        set(&out, "revision", key.0 as f64)?;
        let c = self.design.committed();
        let points: Vec<f64> = c
            .iter()
            .flat_map(|c| c.dual.points.iter().flat_map(|p| [p.x, p.y, p.z]))
            .collect();
        let lengths: Vec<u32> = c.iter().map(|c| c.dual.points.len() as u32).collect();
        let closed: Vec<u8> = c.iter().map(|c| c.dual.closed as u8).collect();
        let moves: Vec<f64> = key
            .1
            .iter()
            .flat_map(|&(v, p)| [v as f64, p.x, p.y, p.z])
            .collect();
        set(&out, "points", js_sys::Float64Array::from(&points[..]))?;
        set(&out, "lengths", js_sys::Uint32Array::from(&lengths[..]))?;
        set(&out, "closed", Uint8Array::from(&closed[..]))?;
        set(&out, "moves", js_sys::Float64Array::from(&moves[..]))?;
        self.posted = Some(key);
        Ok(out.into())
    }

    /// §6.2 from the analysis worker: the covered directions of revision
    /// `revision` (`counts[v]` directions of vertex v, xyz each in
    /// `directions`); ignored when stale. Returns whether they were applied.
    #[wasm_bindgen(js_name = applyCovered)]
    pub fn apply_covered(&mut self, revision: f64, counts: &[u32], directions: &[f64]) -> bool {
        let Some(covered) = analysis_glue::unflatten_covered(counts, directions) else {
            self.last_error = Some("malformed covered directions".to_string());
            return false;
        };
        covered.len() == self.mesh.vertex_count()
            && self.design.apply_covered(revision as u64, &covered)
    }

    /// What the analysis worker needs, made here once so that it neither
    /// imports nor decimates the file again: `{ positions: Float64Array,
    /// triangles: Uint32Array }` of the design mesh (xyz, vertex triples),
    /// `originalPositions`, `originalTriangles` of the input when the
    /// design runs on a proxy (empty otherwise), and `frame: Float64Array`
    /// (the file frame's centre xyz and scale). The input and frame are
    /// moved out: a second call is an error.
    #[wasm_bindgen(js_name = takeAnalysisMeshes)]
    pub fn take_analysis_meshes(&mut self) -> Result<Object, JsError> {
        let (original, frame) = self
            .handover
            .take()
            .ok_or_else(|| JsError::new("the analysis meshes were handed over already"))?;
        let flat = |m: Option<&TriMesh>| {
            let positions: Vec<f64> = m
                .iter()
                .flat_map(|m| m.positions.iter().flat_map(|p| p.to_array()))
                .collect();
            let triangles: Vec<u32> = m
                .iter()
                .flat_map(|m| m.triangles.iter().flatten().copied())
                .collect();
            (
                js_sys::Float64Array::from(&positions[..]),
                js_sys::Uint32Array::from(&triangles[..]),
            )
        };
        let out = Object::new();
        let (positions, triangles) = flat(Some(&self.mesh));
        set(&out, "positions", positions)?;
        set(&out, "triangles", triangles)?;
        let (positions, triangles) = flat(original.as_ref());
        set(&out, "originalPositions", positions)?;
        set(&out, "originalTriangles", triangles)?;
        let c = frame.center;
        set(
            &out,
            "frame",
            js_sys::Float64Array::from(&[c.x, c.y, c.z, frame.scale][..]),
        )?;
        Ok(out)
    }

    /// The design mesh as flat arrays (positions xyz, triangles), for the
    /// page to draw per-face colourings of the proxy.
    pub fn surface(&self) -> Result<Object, JsError> {
        let out = Object::new();
        let positions: Vec<f32> = self
            .mesh
            .positions
            .iter()
            .flat_map(|p| [p.x as f32, p.y as f32, p.z as f32])
            .collect();
        let triangles: Vec<u32> = self.mesh.triangles.iter().flatten().copied().collect();
        set(&out, "positions", Float32Array::from(&positions[..]))?;
        set(&out, "triangles", js_sys::Uint32Array::from(&triangles[..]))?;
        Ok(out)
    }
}

/// A mesh from flat arrays (xyz per vertex, vertex triples), validated.
pub(super) fn mesh_from_flat(
    what: &str,
    positions: &[f64],
    triangles: &[u32],
) -> Result<TriMesh, JsError> {
    if positions.len() % 3 != 0 || triangles.len() % 3 != 0 {
        return Err(JsError::new(&format!(
            "{what}: {} coordinates and {} indices are not xyz and vertex triples",
            positions.len(),
            triangles.len()
        )));
    }
    TriMesh::new(
        positions
            .chunks_exact(3)
            .map(|p| DVec3::new(p[0], p[1], p[2]))
            .collect(),
        triangles
            .chunks_exact(3)
            .map(|t| [t[0], t[1], t[2]])
            .collect(),
    )
    .map_err(|e| JsError::new(&format!("{what}: {e}")))
}

/// What the analysis and the layout depend on: the committed loops'
/// revision and the layout-vertex moves.
type Key = (u64, Vec<(u32, DVec3)>);

impl LayoutDesigner {
    fn key(&self) -> Key {
        (self.design.revision(), self.design.moves().to_vec())
    }

    fn result<T: Default>(&mut self, r: Result<T, DesignError>) -> T {
        r.unwrap_or_else(|e| {
            self.last_error = Some(e.to_string());
            T::default()
        })
    }
}

/// Milliseconds from the worker's `performance.now()` (0 without one).
pub(super) fn now_ms() -> f64 {
    let performance = Reflect::get(&js_sys::global(), &JsValue::from_str("performance")).ok();
    let now = performance
        .as_ref()
        .and_then(|p| Reflect::get(p, &JsValue::from_str("now")).ok())
        .and_then(|f| f.dyn_into::<js_sys::Function>().ok());
    match (performance, now) {
        (Some(p), Some(f)) => f.call0(&p).ok().and_then(|v| v.as_f64()).unwrap_or(0.0),
        _ => 0.0,
    }
}

pub(super) fn to_js<T: serde::Serialize>(value: &T) -> Result<JsValue, JsError> {
    let json = serde_json::to_string(value).map_err(|e| JsError::new(&e.to_string()))?;
    js_sys::JSON::parse(&json).map_err(|_| JsError::new("could not encode a result"))
}

/// `{ available, stripes, stripeColours, regionCategory, singularities,
/// singularityColours, layoutVertices, layoutEdges, counts, sufficient,
/// status, timings }`.
pub(super) fn analysis_to_js(a: &analysis_glue::Analysis) -> Result<Object, JsError> {
    let out = Object::new();
    set(&out, "available", a.available)?;
    set(&out, "stripes", Float32Array::from(&a.stripes[..]))?;
    set(
        &out,
        "stripeColours",
        Uint8Array::from(&a.stripe_colours[..]),
    )?;
    set(
        &out,
        "regionCategory",
        Float32Array::from(&a.region_category[..]),
    )?;
    set(
        &out,
        "singularities",
        Float32Array::from(&a.singularities[..]),
    )?;
    set(
        &out,
        "singularityColours",
        Uint8Array::from(&a.singularity_colours[..]),
    )?;
    set(
        &out,
        "layoutVertices",
        Float32Array::from(&a.layout_vertices[..]),
    )?;
    set(&out, "layoutEdges", Float32Array::from(&a.layout_edges[..]))?;
    set(&out, "counts", to_js(&a.counts)?)?;
    set(&out, "sufficient", a.sufficient)?;
    set(&out, "status", a.status.as_str())?;
    set(&out, "timings", to_js(&a.timings)?)?;
    Ok(out)
}
