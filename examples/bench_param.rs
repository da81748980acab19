//! Times the integer-grid map's stages (cross field, parametrization,
//! rounding) on the shared meshes and prints cones and flips:
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
        let mesh = &imported.mesh;
        let params = quadrille::param::Params::default();
        let t0 = Instant::now();
        let prepared = quadrille::param::prepare(mesh, &params);
        let t1 = Instant::now();
        let field = match quadrille::param::cross_field_of(mesh, &prepared, &params) {
            Ok(f) => f,
            Err(e) => {
                eprintln!("{name}: {e}");
                continue;
            }
        };
        let t2 = Instant::now();
        let ms = |a: Instant, b: Instant| (b - a).as_secs_f64() * 1e3;
        println!(
            "{name}: {} faces | analysis {:.0} ms, cross field {:.0} ms | {} cones (Σ {}), E_smooth {:.2}",
            mesh.face_count(),
            ms(t0, t1),
            ms(t1, t2),
            field.cones.len(),
            field.index_sum(),
            field.energy
        );
    }
}
