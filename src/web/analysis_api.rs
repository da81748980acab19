//! The design mode's analysis worker (`www/analysis-worker.js`): the
//! strips, regions and primal layout of Campen & Kobbelt 2014 (*Dual Strip
//! Weaving*, §4.2, §6, §7; [`layout_glue::analyze_loops`]) of the committed
//! loops, in a worker of its own so that the layout worker's hover, clicks
//! and Enter never wait for it. The layout worker hands it the committed
//! loops ([`super::layout_api::LayoutDesigner::take_analysis_input`]) and
//! applies the covered directions (§6.2) it returns when they are still
//! current.

use glam::DVec3;
use wasm_bindgen::prelude::*;

use super::layout_api::{analysis_to_js, design_meshes, now_ms, set};
use super::layout_glue;
use crate::mesh::TriMesh;
use crate::progress::Progress;

/// The design mesh (the input or its proxy, as in the layout worker).
#[wasm_bindgen]
pub struct LayoutAnalyzer {
    mesh: TriMesh,
}

#[wasm_bindgen]
impl LayoutAnalyzer {
    #[wasm_bindgen(constructor)]
    pub fn new(bytes: &[u8], name: &str) -> Result<LayoutAnalyzer, JsError> {
        let (mesh, _, _, _) = design_meshes(bytes, name)?;
        Ok(LayoutAnalyzer { mesh })
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
    /// loops stale) the analysis stops there and returns null.
    pub fn analyze(
        &self,
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
        let Ok(a) = layout_glue::analyze_loops(&self.mesh, &loops, &moves, &now_ms, &mut progress)
        else {
            return Ok(JsValue::NULL);
        };
        let out = analysis_to_js(&a)?;
        let (counts, flat) = layout_glue::flatten_covered(&a.covered);
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
        Ok(out.into())
    }
}
