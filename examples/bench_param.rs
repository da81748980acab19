//! Times the integer-grid map's stages — analysis (with the filtered
//! normals), cross field, parametrization with integer rounding — on the
//! shared meshes and prints cones, flips and Campen §5's measures:
//! `cargo run --release --example bench_param [MESH…]` (default: the bunny).

use std::time::Instant;

fn main() {
    let dir = std::env::var("QUADRILLE_MESHES").unwrap_or_else(|_| "../shared/meshes".into());
    let names: Vec<String> = std::env::args().skip(1).collect();
    let names = if names.is_empty() {
        vec![format!("{dir}/stanford-bunny.obj")]
    } else {
        names
    };
    for name in names {
        let Ok(bytes) = std::fs::read(&name) else {
            eprintln!("{name}: cannot read");
            continue;
        };
        let imported = match quadrille::io::import(&bytes, &name) {
            Ok(i) => i,
            Err(e) => {
                eprintln!("{e}");
                continue;
            }
        };
        let start = Instant::now();
        let clock = move || start.elapsed().as_secs_f64() * 1e3;
        let params = quadrille::param::Params::default();
        match quadrille::param::run(&imported.mesh, &params, &clock) {
            Ok(r) => {
                let (t, m) = (r.timings, &r.measures);
                println!(
                    "{name}: {} faces | analysis {:.0} ms, cross field {:.0} ms, parametrization + rounding {:.0} ms ({} re-solves, {} symbolic analyses) | {} cones {:?} (Σ {}), {} flipped, stretch {:.3}, shear {:.1}°, misalignment {:.1}°",
                    m.faces,
                    t.analysis_ms,
                    t.cross_field_ms,
                    t.parametrization_ms,
                    r.map.rounding_steps,
                    r.map.symbolic_analyses,
                    m.cones,
                    m.cones_by_quarters,
                    m.cone_index_sum,
                    m.flipped_triangles,
                    m.stretch,
                    m.shear_degrees,
                    m.misalignment_degrees
                );
            }
            Err(e) => eprintln!("{name}: {e}"),
        }
    }
}
