//! Benchmarks the loop through anchors of dual strip weaving (Campen &
//! Kobbelt 2014, §5.4: the metagraph of shortest paths between consecutive
//! anchors) as the design mode uses it, single threaded:
//! `cargo run --release --example bench_anchors [mesh-file[@faces] …]`
//! (default: the torus sample, rocker-arm, fandisk and stanford-bunny
//! decimated to ~30k faces, the design mode's proxy).
//!
//! Per mesh, at `BENCH_TRIALS` (default 4) anchor vertices v (PCG32, seed 11):
//! 1. a click: one positional anchor at v;
//! 2. a drag: a second, directional anchor at the point one third along the
//!    hover loop at v, across it (tangent turned by 90°);
//! 3. a grab: three positional anchors, at v and at the points one third and
//!    two thirds along the hover loop, the last moved off the loop by a few
//!    rings;
//! 4. two anchors apart (as the page's two clicks): v and an independent
//!    random vertex;
//! 5. three anchors apart: those two and a third random vertex;
//! 6. the page's grab: on the loop through the two anchors apart, an anchor
//!    inserted halfway from the first to the second, moved off the loop by a
//!    few rings (what `tests/e2e/bench_design.mjs` times in the browser);
//! 7. the drag that follows it: the inserted anchor moved further off the
//!    loop in four steps, each a query (`move2`; it runs `grab2` first).
//!
//! Prints each case's time and loop cost; `BENCH_COSTS=file` writes one line
//! per case (mesh, trial, case, cost) for comparing loop energies between
//! versions; `BENCH_EFFORT=1` also prints the g′ states settled per case;
//! `BENCH_IDLE=1` gives `grab2` and `move2` the layout worker's idle time
//! before each query (the previous anchors' fields settled, untimed);
//! `BENCH_CASES=apart2,apart3` runs only the named cases (the anchors are
//! placed as in a full run).

use std::time::Instant;

use glam::DVec3;
use quadrille::layout::proxy::decimate;
use quadrille::layout::{Anchor, DualLoop, ElasticaParams, LoopEngine};
use quadrille::mesh::TriMesh;
use rand_core::{RngCore, SeedableRng};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut specs: Vec<String> = std::env::args().skip(1).collect();
    let root = env!("CARGO_MANIFEST_DIR");
    if specs.is_empty() {
        let dir = format!("{root}/../shared/meshes");
        specs = vec![
            format!("{root}/www/samples/torus.obj"),
            format!("{dir}/rocker-arm.obj"),
            format!("{dir}/fandisk.obj"),
            format!("{dir}/stanford-bunny.obj@30000"),
        ];
    }
    let trials: usize = std::env::var("BENCH_TRIALS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(4);
    let mut lines = String::new();
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
        let label = match target {
            Some(n) => format!("{name}@{n}"),
            None => name.clone(),
        };
        let t = Instant::now();
        let mut engine = LoopEngine::new(&mesh, &ElasticaParams::default());
        println!(
            "{label}: {} faces, g′ {} nodes, built in {:.2} s",
            mesh.face_count(),
            engine.graph.node_count(),
            t.elapsed().as_secs_f64()
        );
        let mut rng = rand_pcg::Pcg32::seed_from_u64(11);
        let mut times: [Vec<f64>; 7] = Default::default();
        let cases = std::env::var("BENCH_CASES").ok();
        let wanted = |case: &str| {
            cases
                .as_ref()
                .is_none_or(|c| c.split(',').any(|x| x == case))
        };
        for trial in 0..trials {
            let v = rng.next_u32() as usize % mesh.vertex_count().max(1);
            let p = mesh.positions[v];
            let click = [Anchor::positional(p)];
            if wanted("click") {
                let (first, ms) = timed(&mut engine, &click);
                report(
                    &mut lines,
                    &label,
                    trial,
                    "click",
                    &first,
                    ms,
                    &mut times[0],
                );
            }
            // Later anchors are placed along the hover loop (the same code in
            // every version), so the cases compare across versions.
            let Some(first) = engine.best_loop(p) else {
                continue;
            };
            let (q, tq) = along(&first, 1.0 / 3.0);
            let n = normal_at(&mesh, &engine, q);
            let across = n.cross(tq).normalize_or_zero();
            let drag = [click[0], Anchor::directional(q, across)];
            if wanted("drag") {
                let (l, ms) = timed(&mut engine, &drag);
                report(&mut lines, &label, trial, "drag", &l, ms, &mut times[1]);
            }
            let (r, tr) = along(&first, 2.0 / 3.0);
            let n = normal_at(&mesh, &engine, r);
            let off = r + n.cross(tr).normalize_or_zero() * 0.03 * engine.graph.g.diagonal;
            let grab = [
                click[0],
                Anchor::positional(q),
                Anchor::positional(snap(&engine, off)),
            ];
            if wanted("grab") {
                let (l, ms) = timed(&mut engine, &grab);
                report(&mut lines, &label, trial, "grab", &l, ms, &mut times[2]);
            }
            // Anchors apart, as the page's clicks place them: a second and a
            // third anchor at independent random vertices.
            let w = rng.next_u32() as usize % mesh.vertex_count().max(1);
            let two = [click[0], Anchor::positional(mesh.positions[w])];
            let mut through_two = None;
            if wanted("apart2") || wanted("grab2") || wanted("move2") {
                let (l, ms) = timed(&mut engine, &two);
                if wanted("apart2") {
                    report(&mut lines, &label, trial, "apart2", &l, ms, &mut times[3]);
                }
                through_two = l;
            }
            let u = rng.next_u32() as usize % mesh.vertex_count().max(1);
            let three = [two[0], two[1], Anchor::positional(mesh.positions[u])];
            if wanted("apart3") {
                let (l, ms) = timed(&mut engine, &three);
                report(&mut lines, &label, trial, "apart3", &l, ms, &mut times[4]);
            }
            if let Some(l2) = through_two.filter(|_| wanted("grab2") || wanted("move2")) {
                // The loop starts at the first anchor: halfway to the second.
                let (s1, s2) = (arc_of(&l2, two[0].position), arc_of(&l2, two[1].position));
                let half = if s2 >= s1 {
                    0.5 * (s1 + s2)
                } else {
                    0.5 * (s1 + s2 + l2.length())
                };
                let (g, tg) = along(&l2, (half / l2.length().max(f64::MIN_POSITIVE)).fract());
                let n = normal_at(&mesh, &engine, g);
                let off = g + n.cross(tg).normalize_or_zero() * 0.03 * engine.graph.g.diagonal;
                let grab2 = [two[0], Anchor::positional(snap(&engine, off)), two[1]];
                idle(&mut engine, &two);
                let (l, ms) = timed(&mut engine, &grab2);
                report(&mut lines, &label, trial, "grab2", &l, ms, &mut times[5]);
                if wanted("move2") {
                    // The drag after that grab: the anchor moved further off
                    // the loop, one step at a time (each its own query).
                    let step = n.cross(tg).normalize_or_zero() * 0.01 * engine.graph.g.diagonal;
                    let mut before = grab2;
                    for i in 1..=4 {
                        let moved = [
                            two[0],
                            Anchor::positional(snap(&engine, off + step * i as f64)),
                            two[1],
                        ];
                        idle(&mut engine, &before);
                        let (l, ms) = timed(&mut engine, &moved);
                        report(&mut lines, &label, trial, "move2", &l, ms, &mut times[6]);
                        before = moved;
                    }
                }
            }
        }
        print_medians(&mut times);
    }
    if let Some(file) = std::env::var_os("BENCH_COSTS") {
        std::fs::write(file, lines)?;
    }
    Ok(())
}

/// Each case's median and maximum time.
fn print_medians(times: &mut [Vec<f64>; 7]) {
    for (case, t) in [
        "click", "drag", "grab", "apart2", "apart3", "grab2", "move2",
    ]
    .iter()
    .zip(times)
    {
        t.sort_by(f64::total_cmp);
        if t.is_empty() {
            continue;
        }
        println!(
            "  {case}: median {:.1} ms, max {:.1} ms over {}",
            t[t.len() / 2],
            t[t.len() - 1],
            t.len()
        );
    }
}

/// With `BENCH_IDLE` set: the idle time the layout worker has after an
/// action (untimed), in which it settles the fields of that action's
/// anchors (`LoopEngine::prepare_fields`, here to the end).
fn idle(engine: &mut LoopEngine, anchors: &[Anchor]) {
    if std::env::var_os("BENCH_IDLE").is_some() {
        let e0 = engine.settled_nodes();
        while engine.prepare_fields(anchors, u64::MAX) {}
        if std::env::var_os("BENCH_EFFORT").is_some() {
            println!("    idle: settled {}", engine.settled_nodes() - e0);
        }
    }
}

fn timed(engine: &mut LoopEngine, anchors: &[Anchor]) -> (Option<DualLoop>, f64) {
    let t = Instant::now();
    let e0 = engine.settled_nodes();
    let l = engine.constrained_loop(anchors);
    let ms = t.elapsed().as_secs_f64() * 1e3;
    if std::env::var_os("BENCH_EFFORT").is_some() {
        println!("    settled {}", engine.settled_nodes() - e0);
    }
    (l, ms)
}

fn report(
    lines: &mut String,
    mesh: &str,
    trial: usize,
    case: &str,
    l: &Option<DualLoop>,
    ms: f64,
    times: &mut Vec<f64>,
) {
    times.push(ms);
    let cost = l.as_ref().map_or(f64::NAN, |l| l.cost);
    let closed = l.as_ref().is_some_and(|l| l.closed);
    println!("  trial {trial} {case}: {ms:.1} ms, cost {cost:.6}, closed {closed}");
    *lines += &format!("{mesh} {trial} {case} {cost}\n");
}

/// The arc length along `l` of its point nearest to `p`.
fn arc_of(l: &DualLoop, p: DVec3) -> f64 {
    let (mut best, mut at, mut walked) = (f64::INFINITY, 0.0, 0.0);
    for w in l.points.windows(2) {
        let d = w[1] - w[0];
        let len = d.length();
        let t = if len > 0.0 {
            ((p - w[0]).dot(d) / (len * len)).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let dist = p.distance(w[0] + d * t);
        if dist < best {
            (best, at) = (dist, walked + t * len);
        }
        walked += len;
    }
    at
}

/// The point at fraction `s` of a polyline's length, and the unit tangent.
fn along(l: &DualLoop, s: f64) -> (DVec3, DVec3) {
    let total = l.length();
    let mut walked = 0.0;
    for w in l.points.windows(2) {
        let len = w[0].distance(w[1]);
        if len > 0.0 && walked + len >= s * total {
            let t = (s * total - walked) / len;
            return (w[0].lerp(w[1], t), (w[1] - w[0]) / len);
        }
        walked += len;
    }
    (l.points[0], DVec3::X)
}

/// The normal of the vertex nearest to `p` (world units).
fn normal_at(mesh: &TriMesh, engine: &LoopEngine, p: DVec3) -> DVec3 {
    let _ = mesh;
    engine
        .nearest_vertex(p)
        .map_or(DVec3::Z, |v| engine.graph.g.normals[v])
}

/// The nearest vertex's world position.
fn snap(engine: &LoopEngine, p: DVec3) -> DVec3 {
    engine
        .nearest_vertex(p)
        .map_or(p, |v| engine.vertex_position(v))
}
