//! Makes larger benchmark meshes: 1-to-4 midpoint subdivision of every
//! triangle (each edge split at its midpoint, each triangle replaced by four),
//! `LEVELS` times, so the triangle count grows 4× per level while the
//! surface stays the input's piecewise-linear surface (no smoothing, no
//! projection). Used by `scripts/bench.py` to make the ~300k and ~1M
//! triangle bunnies under target/bench/ (never committed).
//!
//! `cargo run --release --example subdivide -- IN LEVELS OUT.obj`

use std::collections::HashMap;

use glam::DVec3;

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
    let mut positions: Vec<DVec3> = imported
        .mesh
        .positions
        .iter()
        .map(|&p| frame.to_world(p))
        .collect();
    let mut triangles = imported.mesh.triangles.clone();
    for _ in 0..levels {
        triangles = split_1_to_4(&mut positions, &triangles);
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

/// One level of 1-to-4 midpoint subdivision: appends one midpoint per edge
/// to `positions` (shared by the edge's triangles) and returns the new
/// triangles, each keeping its parent's orientation.
fn split_1_to_4(positions: &mut Vec<DVec3>, triangles: &[[u32; 3]]) -> Vec<[u32; 3]> {
    let mut midpoint: HashMap<(u32, u32), u32> = HashMap::with_capacity(triangles.len() * 2);
    let mut next = Vec::with_capacity(triangles.len() * 4);
    for t in triangles {
        let mut m = [0u32; 3];
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            m[k] = *midpoint.entry((a.min(b), a.max(b))).or_insert_with(|| {
                positions.push(0.5 * (positions[a as usize] + positions[b as usize]));
                positions.len() as u32 - 1
            });
        }
        // m[k] lies on edge (t[k], t[k+1]).
        next.push([t[0], m[0], m[2]]);
        next.push([t[1], m[1], m[0]]);
        next.push([t[2], m[2], m[1]]);
        next.push([m[0], m[1], m[2]]);
    }
    next
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A closed tetrahedron: V' = V + E, F' = 4F, still closed and
    /// consistently oriented (every directed edge once, its reverse once),
    /// the same total area, and every new vertex an edge midpoint.
    #[test]
    fn split_keeps_a_closed_oriented_surface() {
        let mut p = vec![
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(0.0, 1.0, 0.0),
            DVec3::new(0.0, 0.0, 1.0),
        ];
        let t = vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]];
        let area = |p: &[DVec3], t: &[[u32; 3]]| -> f64 {
            t.iter()
                .map(|f| {
                    let [a, b, c] = f.map(|i| p[i as usize]);
                    0.5 * (b - a).cross(c - a).length()
                })
                .sum()
        };
        let before = area(&p, &t);
        let t2 = split_1_to_4(&mut p, &t);
        assert_eq!(p.len(), 4 + 6);
        assert_eq!(t2.len(), 16);
        let mut directed = std::collections::HashSet::new();
        for f in &t2 {
            for k in 0..3 {
                assert!(
                    directed.insert((f[k], f[(k + 1) % 3])),
                    "directed edge twice"
                );
            }
        }
        for &(a, b) in &directed {
            assert!(directed.contains(&(b, a)), "edge ({a}, {b}) has one side");
        }
        assert!((area(&p, &t2) - before).abs() < 1e-12);
        for v in &p[4..] {
            let on_edge =
                (0..4).any(|i| (0..4).any(|j| (0.5 * (p[i] + p[j]) - *v).length() < 1e-15));
            assert!(on_edge, "{v} is no edge midpoint");
        }
    }
}
