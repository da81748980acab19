//! Times the pipeline stages through the field optimisation on a mesh
//! (default: the Stanford bunny at the default target), median of N runs.
//! `cargo run --release --example bench_fields -- [MESH] [RUNS]`
//! Set RAYON_NUM_THREADS=1 for a single-threaded figure.

use std::time::Instant;

use quadrille::pipeline::{Params, Pipeline, Stage};

fn main() {
    let mut args = std::env::args().skip(1);
    let path = args
        .next()
        .unwrap_or_else(|| "../shared/meshes/stanford-bunny.obj".into());
    let runs: usize = args.next().and_then(|r| r.parse().ok()).unwrap_or(5);
    let bytes = std::fs::read(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
    let input = quadrille::io::import(&bytes, &path).unwrap_or_else(|e| panic!("{e}"));
    let start = Instant::now();
    let clock = move || start.elapsed().as_secs_f64() * 1e3;
    let mut times: Vec<Vec<f64>> = vec![Vec::new(); Stage::LOCAL.len()];
    let mut singularities = 0;
    for _ in 0..runs {
        let mut p = Pipeline::new(input.clone(), Params::default());
        p.run(&mut |_, _, _| true, &mut |_, _| {}, &clock).unwrap();
        for (stage, ms) in &p.timings {
            times[Stage::LOCAL.iter().position(|s| s == stage).unwrap()].push(*ms);
        }
        singularities = p.orientation.as_ref().unwrap().singularities.len();
    }
    println!(
        "{path}: {} vertices, {runs} runs, {singularities} orientation singularities",
        input.mesh.vertex_count()
    );
    for (stage, mut t) in Stage::LOCAL.into_iter().zip(times) {
        t.sort_by(f64::total_cmp);
        println!("{:>12}: median {:8.1} ms", stage.name(), t[t.len() / 2]);
    }
}
