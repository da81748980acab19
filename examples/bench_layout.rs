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
        let mut costs = Vec::new();
        let mut rows = Vec::new();
        for _ in 0..200 {
            let v = (rng.next_u32() as usize) % mesh.vertex_count().max(1);
            let p = mesh.positions[v];
            let before = engine.settled_nodes();
            let t = Instant::now();
            let l = engine.best_loop(p);
            let ms = t.elapsed().as_secs_f64() * 1e3;
            times.push(ms);
            let settled = engine.settled_nodes() - before;
            if let Some(l) = l {
                lengths.push(l.length());
                costs.push(l.cost);
                rows.push((ms, l.cost, l.closed, settled));
            }
        }
        if std::env::var_os("BENCH_VERBOSE").is_some() {
            rows.sort_by(|a, b| a.0.total_cmp(&b.0));
            for r in rows.iter().rev().take(8) {
                println!(
                    "  slow: {:.1} ms, cost {:.3}, closed {}, settled {}",
                    r.0, r.1, r.2, r.3
                );
            }
        }
        costs.sort_by(f64::total_cmp);
        let total: f64 = costs.iter().sum();
        if !costs.is_empty() {
            println!(
                "  loop cost (normalised units): mean {:.4}, median {:.4}",
                total / costs.len() as f64,
                costs[costs.len() / 2]
            );
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
