//! A small wasm entry for timing the dual-strip-weaving loop engine
//! (Campen & Kobbelt 2014, §5.2–§5.7; [`crate::layout`]) in a JS engine:
//! build g and g′ for one mesh, then answer hover queries (the best loop
//! through one vertex). `tests/e2e/bench_layout.mjs` times it under Node.

use wasm_bindgen::prelude::*;

use crate::layout::{ElasticaParams, LoopEngine};
use crate::mesh::TriMesh;

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
