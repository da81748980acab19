//! The design mode's analysis worker (`www/analysis-worker.js`): the
//! strips, regions and primal layout of Campen & Kobbelt 2014 (*Dual Strip
//! Weaving*, §4.2, §6, §7; [`layout_glue::analyze_loops`]) of the committed
//! loops, in a worker of its own so that the layout worker's hover, clicks
//! and Enter never wait for it. The layout worker hands it the design mesh
//! once ([`super::layout_api::LayoutDesigner::take_analysis_meshes`]: no
//! second import or decimation), then the committed
//! loops ([`super::layout_api::LayoutDesigner::take_analysis_input`]) and
//! applies the covered directions (§6.2) it returns when they are still
//! current.
//!
//! What is made from a finished analysis is made here too, from the newest
//! one, so that it never blocks hover or clicks either: the layout's
//! exports, its grid (§8.1) and the grid's fit.

use glam::DVec3;
use js_sys::{Float32Array, Object};
use wasm_bindgen::prelude::*;

use super::layout_api::{analysis_to_js, mesh_from_flat, now_ms, set, to_js};
use super::layout_glue::{self, Analysis};
use crate::layout::grid::LayoutGrid;
use crate::layout::primal::LayoutExport;
use crate::mesh::{Frame, TriMesh};
use crate::progress::Progress;
use crate::spatial::SurfaceIndex;

/// Pieces each gridded-layout edge is drawn in, projected onto the surface.
const GRID_EDGE_PIECES: usize = 6;

/// The design mesh (the input or its proxy, as in the layout worker), the
/// newest finished analysis and the grid of its layout.
#[wasm_bindgen]
pub struct LayoutAnalyzer {
    mesh: TriMesh,
    /// The input when the design runs on a proxy: the layout is mapped onto
    /// it before gridding and exporting, and the fit measures against it.
    original: Option<TriMesh>,
    /// Maps the local coordinates back to the file's (for exports).
    frame: Frame,
    /// The newest finished analysis.
    analysed: Option<Analysed>,
    /// The last `grid` of that analysis' layout (dropped with it).
    grid: Option<LayoutGrid>,
    /// The index of the surface the layout lies on (the input), built on
    /// first use: `grid` and the proxy's mapping share it.
    surface_index: std::cell::OnceCell<Option<SurfaceIndex>>,
}

#[wasm_bindgen]
impl LayoutAnalyzer {
    /// From the layout worker's design meshes
    /// ([`super::layout_api::LayoutDesigner::take_analysis_meshes`]): the
    /// design mesh, the input when the design runs on a proxy (empty
    /// arrays otherwise) and the file's frame (centre xyz, scale).
    #[wasm_bindgen(constructor)]
    pub fn new(
        positions: &[f64],
        triangles: &[u32],
        original_positions: &[f64],
        original_triangles: &[u32],
        frame: &[f64],
    ) -> Result<LayoutAnalyzer, JsError> {
        let mesh = mesh_from_flat("the design mesh", positions, triangles)?;
        let original = if original_positions.is_empty() && original_triangles.is_empty() {
            None
        } else {
            Some(mesh_from_flat(
                "the input mesh",
                original_positions,
                original_triangles,
            )?)
        };
        let frame = match *frame {
            [x, y, z, scale] if [x, y, z, scale].iter().all(|v| v.is_finite()) && scale > 0.0 => {
                Frame {
                    center: DVec3::new(x, y, z),
                    scale,
                }
            }
            _ => {
                return Err(JsError::new(
                    "a frame is a finite centre xyz and a positive scale",
                ));
            }
        };
        Ok(LayoutAnalyzer {
            mesh,
            original,
            frame,
            analysed: None,
            grid: None,
            surface_index: std::cell::OnceCell::new(),
        })
    }

    #[wasm_bindgen(js_name = faceCount)]
    pub fn face_count(&self) -> u32 {
        self.mesh.face_count() as u32
    }

    /// The analysis of committed loops (`points` xyz, `lengths[i]` points
    /// of loop i, `closed[i]`) with the layout-vertex `moves` (vertex, x, y,
    /// z): the page's analysis object plus `coveredCounts: Uint32Array`
    /// and `coveredDirections: Float64Array` (§6.2, see
    /// [`layout_glue::flatten_covered`]). `go_on()` is asked between the
    /// analysis' steps; when it returns false (a newer action made these
    /// loops stale) the analysis stops there and returns null. A finished
    /// analysis replaces the one [`Self::export`], [`Self::grid`] and
    /// [`Self::fit`] read, and drops its grid.
    pub fn analyze(
        &mut self,
        points: &[f64],
        lengths: &[u32],
        closed: &[u8],
        moves: &[f64],
        go_on: &js_sys::Function,
    ) -> Result<JsValue, JsError> {
        let total: usize = lengths.iter().map(|&n| n as usize).sum();
        if points.len() != 3 * total || closed.len() != lengths.len() || moves.len() % 4 != 0 {
            return Err(JsError::new("malformed analysis input"));
        }
        let positions: Vec<DVec3> = points
            .chunks_exact(3)
            .map(|p| DVec3::new(p[0], p[1], p[2]))
            .collect();
        let mut loops: Vec<(&[DVec3], bool)> = Vec::with_capacity(lengths.len());
        let mut start = 0;
        for (&n, &c) in lengths.iter().zip(closed) {
            let end = start + n as usize;
            loops.push((&positions[start..end], c != 0));
            start = end;
        }
        let moves: Vec<(u32, DVec3)> = moves
            .chunks_exact(4)
            .map(|m| (m[0] as u32, DVec3::new(m[1], m[2], m[3])))
            .collect();
        let mut sink = |_: &str, _: f32, _: &str| {
            go_on
                .call0(&JsValue::NULL)
                .is_ok_and(|v| v.as_bool() != Some(false))
        };
        let mut progress = Progress::new(&mut sink, "design analysis");
        let Ok(mut a) =
            layout_glue::analyze_loops(&self.mesh, &loops, &moves, &now_ms, &mut progress)
        else {
            return Ok(JsValue::NULL);
        };
        let out = analysis_to_js(&a)?;
        // The covered directions are the layout worker's (§6.2).
        let (counts, flat) = layout_glue::flatten_covered(&std::mem::take(&mut a.covered));
        set(
            &out,
            "coveredCounts",
            js_sys::Uint32Array::from(&counts[..]),
        )?;
        set(
            &out,
            "coveredDirections",
            js_sys::Float64Array::from(&flat[..]),
        )?;
        let loops = loops.iter().map(|&(p, c)| (p.to_vec(), c)).collect();
        self.analysed = Some(Analysed { analysis: a, loops });
        self.grid = None;
        Ok(out.into())
    }

    /// The layout as "obj" (the patches as polygon faces; the loops as
    /// lines while there is no layout), "json", or "grid-obj" (the last
    /// gridded mesh, pure quad). OBJ coordinates are the input file's; on a
    /// proxy the layout is mapped onto the input first.
    pub fn export(&self, format: &str) -> Result<String, JsError> {
        let Analysed { analysis: a, loops } = self
            .analysed
            .as_ref()
            .ok_or_else(|| JsError::new("nothing designed yet"))?;
        let js = |e: crate::layout::grid::GridError| JsError::new(&e.to_string());
        match format {
            "obj" => match self.input_layout() {
                Some(l) => layout_glue::layout_obj(&l, &self.frame).map_err(js),
                None => {
                    let loops: Vec<(&[DVec3], bool)> =
                        loops.iter().map(|(p, c)| (&p[..], *c)).collect();
                    Ok(layout_glue::loops_obj(&loops, &self.frame))
                }
            },
            "grid-obj" => {
                let g = self
                    .grid
                    .as_ref()
                    .ok_or_else(|| JsError::new("grid the layout first"))?;
                let world: Vec<DVec3> = self.frame.points_to_world(&g.mesh.positions);
                Ok(format!(
                    "# gridded quad layout (Quadrille): {} vertices, {} quads\n{}",
                    world.len(),
                    g.mesh.face_count(),
                    crate::io::write_obj(&world, &g.mesh.to_face_list())
                ))
            }
            "json" if a.json.is_empty() => Err(JsError::new(
                "there is no layout yet: every region must be a disc (no red)",
            )),
            "json" => Ok(a.json.clone()),
            _ => Err(JsError::new(&format!("unknown layout format {format}"))),
        }
    }

    /// Grids the layout with `counts[i]` segments across committed strip
    /// `i` (missing: the default). Returns `{ edges: Float32Array
    /// (segments), vertices, faces, folded, ms }`, positions in the page's
    /// coordinates.
    pub fn grid(&mut self, counts: Vec<u32>) -> Result<Object, JsError> {
        let started = now_ms();
        let layout = self.input_layout().ok_or_else(|| {
            JsError::new("there is no layout yet: every region must be a disc (no red)")
        })?;
        let loop_strip = self
            .analysed
            .as_ref()
            .map(|a| a.analysis.loop_strip.clone())
            .unwrap_or_default();
        let index = self
            .surface_index()
            .ok_or_else(|| JsError::new("the surface is empty"))?;
        let mesh = self.original.as_ref().unwrap_or(&self.mesh);
        let g = layout_glue::grid_mesh(&layout, &loop_strip, &counts, mesh, index)
            .map_err(|e| JsError::new(&e.to_string()))?;
        let out = Object::new();
        let mut segments = Vec::new();
        for h in 0..g.mesh.halfedge_count() as u32 {
            let (a, b) = (g.mesh.origin(h), g.mesh.tip(h));
            if a < b || g.mesh.is_boundary_halfedge(g.mesh.twin(h)) {
                // Drawn on the surface: a coarse grid's chords would dip
                // below it and hide.
                let (p, q) = (g.mesh.positions[a as usize], g.mesh.positions[b as usize]);
                let mut prev = p;
                for k in 1..=GRID_EDGE_PIECES {
                    let t = k as f64 / GRID_EDGE_PIECES as f64;
                    let next = if k == GRID_EDGE_PIECES {
                        q
                    } else {
                        index.closest(p.lerp(q, t)).point
                    };
                    layout_glue::push_segment(&mut segments, prev, next);
                    prev = next;
                }
            }
        }
        set(&out, "edges", Float32Array::from(&segments[..]))?;
        set(&out, "vertices", g.mesh.vertex_count() as u32)?;
        set(&out, "faces", g.mesh.face_count() as u32)?;
        set(&out, "folded", g.folded as u32)?;
        set(&out, "ms", now_ms() - started)?;
        self.grid = Some(g);
        Ok(out)
    }

    /// Fits a Catmull–Clark control mesh to the input from the gridded
    /// layout (as remeshing does, [`crate::subdivision::fit_control_mesh`]).
    /// Returns `{ surface: { positions, triangles, normals, scalar }, summary,
    /// ms }`: the limit surface coloured by its signed error.
    pub fn fit(&self) -> Result<Object, JsError> {
        let started = now_ms();
        let g = self
            .grid
            .as_ref()
            .ok_or_else(|| JsError::new("grid the layout first"))?;
        let reference = self.original.as_ref().unwrap_or(&self.mesh);
        let f = crate::progress::silently("fit", |p| {
            crate::subdivision::fit_control_mesh(&g.mesh, reference, &Default::default(), p)
        })
        .map_err(|_| JsError::new("the fit was cancelled"))?;
        let out = Object::new();
        set(
            &out,
            "surface",
            super::worker_api::limit_surface_object(&f)?,
        )?;
        set(&out, "summary", to_js(&f.summary)?)?;
        set(&out, "ms", now_ms() - started)?;
        Ok(out)
    }
}

/// A finished analysis and the committed loops it analysed.
struct Analysed {
    analysis: Analysis,
    loops: Vec<(Vec<DVec3>, bool)>,
}

impl LayoutAnalyzer {
    /// The layout of the newest analysis on the input: mapped onto the
    /// input when the design runs on a proxy.
    fn input_layout(&self) -> Option<LayoutExport> {
        let mut l = self.analysed.as_ref()?.analysis.layout.clone()?;
        if self.original.is_some()
            && let Some(index) = self.surface_index()
        {
            l.project_onto(index);
        }
        Some(l)
    }

    /// The input's surface index (the proxy's original when there is one).
    fn surface_index(&self) -> Option<&SurfaceIndex> {
        self.surface_index
            .get_or_init(|| SurfaceIndex::new(self.original.as_ref().unwrap_or(&self.mesh)))
            .as_ref()
    }
}
