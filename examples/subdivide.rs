//! Makes larger benchmark meshes: 1-to-4 midpoint subdivision of every
//! triangle (each edge split at its midpoint, each triangle replaced by four),
//! `LEVELS` times, so the triangle count grows 4× per level while the
//! surface stays the input's piecewise-linear surface (no smoothing, no
//! projection). Used by `scripts/bench.py` to make the ~300k and ~1M
//! triangle bunnies under target/bench/ (never committed).
//!
//! `cargo run --release --example subdivide -- IN LEVELS OUT.obj`

use std::collections::HashMap;

fn main() -> std::process::ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [input, levels, output] = &args[..] else {
        eprintln!("usage: subdivide IN LEVELS OUT.obj");
        return std::process::ExitCode::FAILURE;
    };
    match run(input, levels, output) {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(message) => {
            eprintln!("subdivide: {message}");
            std::process::ExitCode::FAILURE
        }
    }
}

fn run(input: &str, levels: &str, output: &str) -> Result<(), String> {
    let levels: u32 = levels
        .parse()
        .map_err(|_| format!("LEVELS must be a small non-negative integer, got {levels:?}"))?;
    if levels > 6 {
        return Err(format!(
            "{levels} levels would make over 4^6 times the triangles"
        ));
    }
    let bytes = std::fs::read(input).map_err(|e| format!("{input}: {e}"))?;
    let imported = quadrille::io::import(&bytes, input).map_err(|e| e.to_string())?;
    let frame = imported.frame;
    let mut positions: Vec<_> = imported
        .mesh
        .positions
        .iter()
        .map(|&p| frame.to_world(p))
        .collect();
    let mut triangles = imported.mesh.triangles.clone();
    for _ in 0..levels {
        let mut midpoint: HashMap<(u32, u32), u32> = HashMap::with_capacity(triangles.len() * 2);
        let mut next = Vec::with_capacity(triangles.len() * 4);
        for t in &triangles {
            let mut m = [0u32; 3];
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                let key = (a.min(b), a.max(b));
                m[k] = *midpoint.entry(key).or_insert_with(|| {
                    positions.push(0.5 * (positions[a as usize] + positions[b as usize]));
                    positions.len() as u32 - 1
                });
            }
            // Corners keep their orientation; m[k] lies on edge (t[k], t[k+1]).
            next.push([t[0], m[0], m[2]]);
            next.push([t[1], m[1], m[0]]);
            next.push([t[2], m[2], m[1]]);
            next.push([m[0], m[1], m[2]]);
        }
        triangles = next;
    }
    let mut faces = quadrille::mesh::FaceList::new();
    for t in &triangles {
        faces.push(t);
    }
    let bytes =
        quadrille::io::write_by_extension(output, &positions, &faces).map_err(|e| e.to_string())?;
    std::fs::write(output, bytes).map_err(|e| format!("{output}: {e}"))?;
    eprintln!(
        "{output}: {} vertices, {} triangles",
        positions.len(),
        triangles.len()
    );
    Ok(())
}
