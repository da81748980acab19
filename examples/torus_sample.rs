//! Writes the synthetic torus sample of the web app (`www/samples/torus.obj`,
//! committed): `crate::mesh::generate::torus` with major radius 2, minor
//! radius 0.7, 96 × 40 segments (7680 triangles), coordinates rounded to
//! five decimals so the file stays small. It is the design mode's test mesh
//! (Campen & Kobbelt 2014, dual strip weaving: three loops on a torus give a
//! valid layout) and a sample for teachers.
//!
//! `cargo run --release --example torus_sample [-- OUT]`

use std::fmt::Write as _;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let out = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "www/samples/torus.obj".into());
    let mesh = quadrille::mesh::generate::torus(2.0, 0.7, 96, 40);
    let mut text = String::from(
        "# torus: major radius 2, minor radius 0.7, 96 x 40 segments (Quadrille examples/torus_sample.rs)\n",
    );
    for p in &mesh.positions {
        writeln!(text, "v {:.5} {:.5} {:.5}", p.x, p.y, p.z)?;
    }
    for t in &mesh.triangles {
        writeln!(text, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1)?;
    }
    if let Some(dir) = std::path::Path::new(&out).parent() {
        std::fs::create_dir_all(dir)?;
    }
    std::fs::write(&out, text)?;
    println!(
        "{out}: {} vertices, {} triangles",
        mesh.positions.len(),
        mesh.triangles.len()
    );
    Ok(())
}
