//! Benchmarks the dual-strip-weaving loop engine (Campen & Kobbelt 2014 §5):
//! graph build time and memory, then the hover query (best loop through one
//! positional anchor) at 200 random vertices, single threaded:
//! `cargo run --release --example bench_layout [mesh-file …]`
//! (default: stanford-bunny and fandisk from `../shared/meshes/`).

use std::time::Instant;

use quadrille::layout::{ElasticaParams, LoopEngine};
use rand_core::{RngCore, SeedableRng};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut paths: Vec<String> = std::env::args().skip(1).collect();
    if paths.is_empty() {
        let dir = format!("{}/../shared/meshes", env!("CARGO_MANIFEST_DIR"));
        paths = vec![
            format!("{dir}/stanford-bunny.obj"),
            format!("{dir}/fandisk.obj"),
        ];
    }
    for path in paths {
        let bytes = std::fs::read(&path)?;
        let name = path.rsplit('/').next().unwrap_or(&path).to_string();
        let imported = quadrille::io::import(&bytes, &name)?;
        let mesh = &imported.mesh;
        let t = Instant::now();
        let mut engine = LoopEngine::new(mesh, &ElasticaParams::default());
        let build = t.elapsed().as_secs_f64();
        println!(
            "{name}: {} vertices, {} faces; g′ {} nodes; build {:.2} s; {:.1} MB",
            mesh.vertex_count(),
            mesh.face_count(),
            engine.graph.node_count(),
            build,
            engine.memory_bytes() as f64 / 1e6
        );
        let mut rng = rand_pcg::Pcg32::seed_from_u64(7);
        let mut times = Vec::new();
        let mut lengths = Vec::new();
        for _ in 0..200 {
            let v = (rng.next_u32() as usize) % mesh.vertex_count().max(1);
            let p = mesh.positions[v];
            let t = Instant::now();
            let l = engine.best_loop(p);
            times.push(t.elapsed().as_secs_f64() * 1e3);
            if let Some(l) = l {
                lengths.push(l.length());
            }
        }
        times.sort_by(f64::total_cmp);
        let pct = |q: f64| times[((times.len() - 1) as f64 * q).round() as usize];
        println!(
            "  hover best loop, 200 anchors: median {:.1} ms, p95 {:.1} ms, max {:.1} ms; {} loops found",
            pct(0.5),
            pct(0.95),
            pct(1.0),
            lengths.len()
        );
    }
    Ok(())
}
