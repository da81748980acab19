//! Benchmarks §6 of dual strip weaving (Campen & Kobbelt 2014): the strip
//! cross field, the global parametrization and the strips
//! (`quadrille::layout::strip_analysis`) as loops are committed one by one,
//! the way the design tool does it: a hover loop (`LoopEngine::best_loop`)
//! at a pseudo-random vertex, embedded on the triangulation, committed; the
//! analysis rerun with all loops; its covered directions handed back to the
//! engine (§6.2) so the next loops cross transversally.
//! `cargo run --release --example bench_strips [mesh-file[@faces] …]`
//! (default: stanford-bunny decimated to ~30k faces and rocker-arm from
//! `../shared/meshes/`; `file@N` decimates by vertex clustering, copied
//! from `bench_layout.rs`). `BENCH_LOOPS=n` commits n loops (default 6).

use std::collections::HashMap;
use std::time::Instant;

use glam::DVec3;
use quadrille::layout::{ElasticaParams, LoopEmbedder, LoopEngine, StripParams, strip_analysis};
use quadrille::mesh::TriMesh;
use rand_core::{RngCore, SeedableRng};

/// Vertex clustering on a grid of cell size `h`.
fn cluster(mesh: &TriMesh, h: f64) -> TriMesh {
    let Some(b) = mesh.bbox() else {
        return mesh.clone();
    };
    let mut cell_of: HashMap<(i64, i64, i64), u32> = HashMap::new();
    let mut sum: Vec<(DVec3, f64)> = Vec::new();
    let mut remap = Vec::with_capacity(mesh.vertex_count());
    for p in &mesh.positions {
        let c = ((*p - b.min) / h).floor();
        let id = *cell_of
            .entry((c.x as i64, c.y as i64, c.z as i64))
            .or_insert_with(|| {
                sum.push((DVec3::ZERO, 0.0));
                sum.len() as u32 - 1
            });
        sum[id as usize].0 += *p;
        sum[id as usize].1 += 1.0;
        remap.push(id);
    }
    let positions: Vec<DVec3> = sum.iter().map(|(s, n)| *s / *n).collect();
    let mut seen = std::collections::HashSet::new();
    let mut triangles = Vec::new();
    for t in &mesh.triangles {
        let [a, b, c] = t.map(|v| remap[v as usize]);
        if a == b || b == c || a == c {
            continue;
        }
        let mut key = [a, b, c];
        key.sort_unstable();
        if seen.insert(key) {
            triangles.push([a, b, c]);
        }
    }
    // Drop vertices no triangle uses.
    let mut used = vec![u32::MAX; positions.len()];
    let mut kept = Vec::new();
    for t in &mut triangles {
        for v in t.iter_mut() {
            if used[*v as usize] == u32::MAX {
                used[*v as usize] = kept.len() as u32;
                kept.push(positions[*v as usize]);
            }
            *v = used[*v as usize];
        }
    }
    TriMesh::new(kept, triangles).unwrap_or_else(|_| mesh.clone())
}

/// Vertex clustering with the cell size bisected to about `faces` faces.
fn decimate(mesh: &TriMesh, faces: usize) -> TriMesh {
    if mesh.face_count() <= faces {
        return mesh.clone();
    }
    let diag = mesh.bbox().map_or(1.0, |b| b.diagonal());
    let (mut lo, mut hi) = (1e-5 * diag, 0.1 * diag);
    let mut best = mesh.clone();
    for _ in 0..30 {
        let h = (lo * hi).sqrt();
        let m = cluster(mesh, h);
        if m.face_count() > faces {
            lo = h;
        } else {
            hi = h;
        }
        if best.face_count() > faces
            || m.face_count().abs_diff(faces) < best.face_count().abs_diff(faces)
        {
            best = m;
        }
        if best.face_count().abs_diff(faces) * 100 < faces {
            break;
        }
    }
    best
}

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
