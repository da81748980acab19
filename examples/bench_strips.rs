//! Benchmarks §6 of dual strip weaving (Campen & Kobbelt 2014): the strip
//! cross field, the global parametrization and the strips
//! (`quadrille::layout::strip_analysis`) as loops are committed one by one,
//! the way the design tool does it: a hover loop (`LoopEngine::best_loop`)
//! at a pseudo-random vertex, embedded on the triangulation, committed; the
//! analysis rerun with all loops; its covered directions handed back to the
//! engine (§6.2) so the next loops cross transversally.
//! `cargo run --release --example bench_strips [mesh-file[@faces] …]`
//! (default: stanford-bunny decimated to ~30k faces and rocker-arm from
//! `../shared/meshes/`; `file@N` decimates to about N faces with the design
//! tool's proxy, `layout::proxy::decimate`). `BENCH_LOOPS=n` commits n loops (default 6).

use std::time::Instant;

use quadrille::layout::proxy::decimate;
use quadrille::layout::{ElasticaParams, LoopEmbedder, LoopEngine, StripParams, strip_analysis};
use rand_core::{RngCore, SeedableRng};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut specs: Vec<String> = std::env::args().skip(1).collect();
    if specs.is_empty() {
        let dir = format!("{}/../shared/meshes", env!("CARGO_MANIFEST_DIR"));
        specs = vec![
            format!("{dir}/stanford-bunny.obj@30000"),
            format!("{dir}/rocker-arm.obj"),
        ];
    }
    let loops_wanted: usize = std::env::var("BENCH_LOOPS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(6);
    for spec in specs {
        let (path, target) = match spec.rsplit_once('@') {
            Some((p, n)) => (p.to_string(), Some(n.parse::<usize>()?)),
            None => (spec.clone(), None),
        };
        let bytes = std::fs::read(&path)?;
        let name = path.rsplit('/').next().unwrap_or(&path).to_string();
        let imported = quadrille::io::import(&bytes, &name)?;
        let mesh = match target {
            Some(n) => decimate(&imported.mesh, n),
            None => imported.mesh,
        };
        println!(
            "{name}: {} vertices, {} faces",
            mesh.vertex_count(),
            mesh.face_count()
        );
        let started = Instant::now();
        let mut engine = LoopEngine::new(&mesh, &ElasticaParams::default());
        let embedder = LoopEmbedder::new(&mesh)?;
        println!(
            "  engine + embedder built in {:.0} ms",
            started.elapsed().as_secs_f64() * 1e3
        );
        let mut rng = rand_pcg::Pcg64::seed_from_u64(11);
        let mut loops = Vec::new();
        let mut tries = 0;
        while loops.len() < loops_wanted && tries < 10 * loops_wanted {
            tries += 1;
            let v = (rng.next_u64() % mesh.vertex_count() as u64) as usize;
            let t0 = Instant::now();
            let Some(l) = engine.best_loop(mesh.positions[v]) else {
                continue;
            };
            let loop_ms = t0.elapsed().as_secs_f64() * 1e3;
            let t1 = Instant::now();
            let embedded = match embedder.embed(&l.points, l.closed) {
                Ok(e) => e,
                Err(e) => {
                    println!("  loop at vertex {v}: not embedded ({e})");
                    continue;
                }
            };
            let embed_ms = t1.elapsed().as_secs_f64() * 1e3;
            loops.push(embedded);
            let t2 = Instant::now();
            let a = strip_analysis(&mesh, &loops, &StripParams::default());
            let total_ms = t2.elapsed().as_secs_f64() * 1e3;
            engine.set_covered(&a.covered);
            let strip_faces: Vec<usize> = a.strips.iter().map(|s| s.faces.len()).collect();
            let folded = a.folded.iter().filter(|&&x| x).count();
            let index_sum: i32 = a.singularities.iter().map(|s| s.index).sum();
            println!(
                "  {} loop(s): loop {loop_ms:.1} ms, embed {embed_ms:.1} ms ({} crossings) | field {:.1} ms, parametrization {:.1} ms, strips {:.1} ms, total {total_ms:.1} ms | {} singularities (Σ {index_sum}), {folded} folded faces, strip faces {strip_faces:?}{}",
                loops.len(),
                loops.last().map_or(0, |l| l.crossings.len()),
                a.field_ms,
                a.parametrization_ms,
                a.strips_ms,
                a.singularities.len(),
                if a.notes.is_empty() {
                    String::new()
                } else {
                    format!(", notes {:?}", a.notes)
                }
            );
        }
    }
    Ok(())
}
