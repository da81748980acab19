//! Benchmarks the dual-strip-weaving loop engine (Campen & Kobbelt 2014 §5):
//! graph build time and memory, then the hover query (best loop through one
//! positional anchor) at 200 random vertices, single threaded:
//! `cargo run --release --example bench_layout [mesh-file[@faces] …]`
//! (default: stanford-bunny, stanford-bunny decimated to ~30k faces,
//! fandisk and rocker-arm from `../shared/meshes/`). `file@N` decimates the mesh to about N
//! faces with the design tool's proxy (`layout::proxy::decimate`, manifold
//! edge collapse).
//!
//! Each query is timed three times and the fastest kept (the machine is
//! shared; the query is deterministic). `BENCH_REPEATS=1` times each query
//! once instead, as the design tool meets them: a new vertex each time,
//! after the previous one's query. `BENCH_VERBOSE=1` lists the slowest
//! queries with their cost and settled-node count. `BENCH_IDLE=1` settles
//! first, untimed, what the design tool settles in idle time before the
//! first hover (`LoopEngine::prepare_fields`: the distances from ∂, and on
//! a closed mesh the loops through spread vertices that provisional answers
//! are made of);
//! `BENCH_QUERIES=n` queries n vertices instead of 200.
//! `BENCH_NO_BRIDGE=1` shows no provisional loop bridged to a recent one
//! (`LoopEngine::bridge`).
//! `BENCH_PROGRESSIVE=n` answers each hover progressively, as the design
//! tool does (`LoopEngine::hover_begin` and `hover_resume` by slices of n
//! settled g′ nodes), and reports the time to the first answer (the
//! provisional loop, or the exact one when the first slice finished) and
//! how often and by how much the provisional one is worse; the costs
//! (`BENCH_COSTS`) are the exact answers.

use std::time::Instant;

use quadrille::layout::proxy::decimate;
use quadrille::layout::{DualLoop, ElasticaParams, HoverStep, LoopEngine};
use rand_core::{RngCore, SeedableRng};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut specs: Vec<String> = std::env::args().skip(1).collect();
    if specs.is_empty() {
        let dir = format!("{}/../shared/meshes", env!("CARGO_MANIFEST_DIR"));
        specs = vec![
            format!("{dir}/stanford-bunny.obj"),
            format!("{dir}/stanford-bunny.obj@30000"),
            format!("{dir}/fandisk.obj"),
            format!("{dir}/rocker-arm.obj"),
        ];
    }
    for spec in specs {
        let (path, target) = match spec.rsplit_once('@') {
            Some((p, n)) => (p.to_string(), Some(n.parse::<usize>()?)),
            None => (spec.clone(), None),
        };
        let (name, mesh) = load(&path, target)?;
        let mesh = &mesh;
        let boundary_edges = boundary_edge_count(mesh);
        println!("{name}: {boundary_edges} boundary edges");
        let t = Instant::now();
        let mut engine = new_engine(mesh);
        let build = t.elapsed().as_secs_f64();
        println!(
            "{name}: {} vertices, {} faces; g′ {} nodes; build {:.2} s; g+g′ {:.1} MB, with query buffers {:.1} MB",
            mesh.vertex_count(),
            mesh.face_count(),
            engine.graph.node_count(),
            build,
            engine.graph.memory_bytes() as f64 / 1e6,
            engine.memory_bytes() as f64 / 1e6
        );
        let repeats = env_count("BENCH_REPEATS", 3);
        if std::env::var_os("BENCH_IDLE").is_some() {
            let t = Instant::now();
            while engine.prepare_fields(&[], u64::MAX) {}
            println!(
                "{name}: idle-time fields {:.2} s (untimed in the queries)",
                t.elapsed().as_secs_f64()
            );
        }
        let queries = env_count("BENCH_QUERIES", 200);
        let mut rng = rand_pcg::Pcg32::seed_from_u64(7);
        let mut times = Vec::new();
        let mut costs = Vec::new();
        let mut rows = Vec::new();
        let mut settled_all = Vec::new();
        let mut anchors = Vec::new();
        let mut results = Vec::new();
        let progressive = std::env::var("BENCH_PROGRESSIVE")
            .ok()
            .and_then(|s| s.parse::<u64>().ok());
        let (mut first, mut provisional) = (Vec::new(), Vec::new());
        for _ in 0..queries {
            let v = (rng.next_u32() as usize) % mesh.vertex_count().max(1);
            let p = mesh.positions[v];
            let mut ms = f64::INFINITY;
            let mut l = None;
            let mut settled = 0;
            for _ in 0..repeats {
                let before = engine.settled_nodes();
                let t = Instant::now();
                l = query(&mut engine, p, progressive, &mut first, &mut provisional);
                ms = ms.min(t.elapsed().as_secs_f64() * 1e3);
                settled = engine.settled_nodes() - before;
            }
            times.push(ms);
            settled_all.push(settled);
            anchors.push(v);
            results.push(l.as_ref().map(|l| (l.cost, l.closed)));
            if let Some(l) = l {
                costs.push(l.cost);
                rows.push((ms, l.cost, l.closed, settled));
            }
        }
        // `BENCH_COSTS=dir`: one line per anchor (vertex, cost, closed) for
        // comparing loop quality between versions.
        if let Some(dir) = std::env::var_os("BENCH_COSTS") {
            let stem = name
                .split(' ')
                .next()
                .unwrap_or(&name)
                .trim_end_matches(".obj");
            // A decimated copy gets its own file (`stem-30000.costs`).
            let stem = match target {
                Some(n) => format!("{stem}-{n}"),
                None => stem.to_string(),
            };
            let text: String = anchors
                .iter()
                .zip(&results)
                .map(|(v, r)| match r {
                    Some((c, closed)) => format!("{v} {c} {closed}\n"),
                    None => format!("{v} none\n"),
                })
                .collect();
            std::fs::write(
                std::path::Path::new(&dir).join(format!("{stem}.costs")),
                text,
            )?;
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
        let mut nontrivial: Vec<f64> = rows.iter().filter(|r| r.1 > 0.0).map(|r| r.0).collect();
        nontrivial.sort_by(f64::total_cmp);
        costs.sort_by(f64::total_cmp);
        settled_all.sort_unstable();
        times.sort_by(f64::total_cmp);
        let pct = |q: f64| times[((times.len() - 1) as f64 * q).round() as usize];
        println!(
            "  hover best loop, {} anchors: median {:.2} ms, p95 {:.2} ms, max {:.2} ms; {} found ({} closed loops, the rest dual curves)",
            queries,
            pct(0.5),
            pct(0.95),
            pct(1.0),
            costs.len(),
            rows.iter().filter(|r| r.2).count()
        );
        let zero_cost = rows.iter().filter(|r| r.1 <= 0.0).count();
        println!(
            "  zero-cost results: {zero_cost}; no result: {}",
            times.len() - rows.len()
        );
        if zero_cost > 0 && !nontrivial.is_empty() {
            let q = |p: f64| nontrivial[((nontrivial.len() - 1) as f64 * p).round() as usize];
            println!(
                "  without the {zero_cost} zero-cost results: median {:.2} ms, p95 {:.2} ms",
                q(0.5),
                q(0.95)
            );
        }
        if progressive.is_some() && !first.is_empty() {
            print_progressive(&first, &mut provisional);
        }
        if !costs.is_empty() {
            let total: f64 = costs.iter().sum();
            println!(
                "  loop cost (normalised units): mean {:.4}, median {:.4}; settled g′ nodes per query: median {}, p95 {}, max {}",
                total / costs.len() as f64,
                costs[costs.len() / 2],
                settled_all[settled_all.len() / 2],
                settled_all[(settled_all.len() - 1) * 95 / 100],
                settled_all[settled_all.len() - 1]
            );
        }
    }
    Ok(())
}

/// The loop engine of `mesh`; `BENCH_NO_BRIDGE=1`: without bridged
/// provisional loops (`LoopEngine::bridge`, for before/after comparisons).
fn new_engine(mesh: &quadrille::mesh::TriMesh) -> LoopEngine {
    let mut engine = LoopEngine::new(mesh, &ElasticaParams::default());
    engine.bridge = std::env::var_os("BENCH_NO_BRIDGE").is_none();
    engine
}

/// The positive count in environment variable `name`, else `default`.
fn env_count(name: &str, default: usize) -> usize {
    std::env::var(name)
        .ok()
        .and_then(|r| r.parse().ok())
        .unwrap_or(default)
        .max(1)
}

/// Imports `path`, decimated to about `target` faces when given; returns
/// the name to print and the mesh.
fn load(
    path: &str,
    target: Option<usize>,
) -> Result<(String, quadrille::mesh::TriMesh), Box<dyn std::error::Error>> {
    let bytes = std::fs::read(path)?;
    let mut name = path.rsplit('/').next().unwrap_or(path).to_string();
    let imported = quadrille::io::import(&bytes, &name)?;
    let mesh = match target {
        Some(n) => {
            let m = decimate(&imported.mesh, n);
            // `BENCH_WRITE_DIR=dir` keeps the decimated mesh as OBJ (for
            // tests/e2e/bench_layout.mjs, the same mesh in wasm).
            if let Some(dir) = std::env::var_os("BENCH_WRITE_DIR") {
                let stem = name.trim_end_matches(".obj");
                let out = std::path::Path::new(&dir).join(format!("{stem}-{n}.obj"));
                let mut text = String::new();
                for p in &m.positions {
                    text += &format!("v {} {} {}\n", p.x, p.y, p.z);
                }
                for t in &m.triangles {
                    text += &format!("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1);
                }
                std::fs::write(&out, text)?;
                println!("wrote {}", out.display());
            }
            name = format!("{name} (decimated to ~{n} faces)");
            m
        }
        None => imported.mesh,
    };
    Ok((name, mesh))
}

/// Edges with exactly one triangle.
fn boundary_edge_count(mesh: &quadrille::mesh::TriMesh) -> usize {
    let mut e: Vec<(u32, u32)> = mesh
        .triangles
        .iter()
        .flat_map(|t| (0..3).map(move |i| (t[i].min(t[(i + 1) % 3]), t[i].max(t[(i + 1) % 3]))))
        .collect();
    e.sort_unstable();
    let mut count = 0;
    let mut i = 0;
    while i < e.len() {
        let mut j = i;
        while j < e.len() && e[j] == e[i] {
            j += 1;
        }
        count += usize::from(j - i == 1);
        i = j;
    }
    count
}

/// One hover query at `p`: [`LoopEngine::best_loop`], or with `progressive`
/// (a slice of settled g′ nodes) `hover_begin` and `hover_resume`,
/// recording the time to the first answer and whether it was exact
/// (`first`) and the provisional / exact cost ratio (`provisional`).
fn query(
    engine: &mut LoopEngine,
    p: glam::DVec3,
    progressive: Option<u64>,
    first: &mut Vec<(f64, bool)>,
    provisional: &mut Vec<f64>,
) -> Option<DualLoop> {
    let Some(slice) = progressive else {
        return engine.best_loop(p);
    };
    let t = Instant::now();
    match engine.hover_begin(p, slice) {
        HoverStep::Exact(exact) => {
            first.push((t.elapsed().as_secs_f64() * 1e3, true));
            exact
        }
        HoverStep::Provisional(shown) => {
            first.push((t.elapsed().as_secs_f64() * 1e3, false));
            let exact = loop {
                if let Some(exact) = engine.hover_resume(slice) {
                    break exact;
                }
            };
            let c = |x: &Option<DualLoop>| x.as_ref().map_or(f64::INFINITY, |x| x.cost);
            provisional.push(c(&shown) / c(&exact));
            exact
        }
    }
}

/// The progressive hover's summary line.
fn print_progressive(first: &[(f64, bool)], provisional: &mut [f64]) {
    let mut t: Vec<f64> = first.iter().map(|f| f.0).collect();
    t.sort_by(f64::total_cmp);
    let q = |p: f64| t[((t.len() - 1) as f64 * p).round() as usize];
    provisional.sort_by(f64::total_cmp);
    let worse = provisional.iter().filter(|&&r| r > 1.0 + 1e-6).count();
    let cheaper = provisional.iter().filter(|&&r| r < 1.0 - 1e-6).count();
    println!(
        "  progressive: first answer median {:.2} ms, p95 {:.2} ms, max {:.2} ms; exact at once {} of {}; provisional {} (none shown {}, worse than exact {}, cheaper than exact {cheaper}, ratio median {:.3}, p95 {:.3})",
        q(0.5),
        q(0.95),
        q(1.0),
        first.iter().filter(|f| f.1).count(),
        first.len(),
        provisional.len(),
        provisional.iter().filter(|r| r.is_infinite()).count(),
        worse,
        provisional
            .get(provisional.len() / 2)
            .copied()
            .unwrap_or(f64::NAN),
        provisional
            .get((provisional.len().max(1) - 1) * 95 / 100)
            .copied()
            .unwrap_or(f64::NAN),
    );
}
