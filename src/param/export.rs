//! The input mesh with the integer-grid map as per-corner texture
//! coordinates: one `vt` per wedge, so the coordinates split exactly at
//! the cut graph's seams.

// Parallel per-face arrays read best indexed.
#![allow(clippy::needless_range_loop)]

use std::fmt::Write;

use glam::DVec3;

use super::seamless::GridMap;

/// Wavefront OBJ text: `v` per position, `vt` per wedge, `f v/vt` per
/// triangle of `triangles`.
pub fn obj_with_uv(positions: &[DVec3], triangles: &[[u32; 3]], map: &GridMap) -> String {
    let mut out = String::with_capacity(64 * (positions.len() + 2 * triangles.len()));
    out.push_str("# quadrille param: integer-grid map, one unit = one target edge\n");
    for p in positions {
        let _ = writeln!(out, "v {} {} {}", p.x, p.y, p.z);
    }
    let mut uv = vec![glam::DVec2::ZERO; map.cut.wedge_count];
    for (f, w) in map.cut.wedge.iter().enumerate() {
        for i in 0..3 {
            if let Some(slot) = uv.get_mut(w[i] as usize) {
                *slot = map.uv[f][i];
            }
        }
    }
    for t in &uv {
        let _ = writeln!(out, "vt {} {}", t.x, t.y);
    }
    for (f, t) in triangles.iter().enumerate() {
        let w = map.cut.wedge.get(f).copied().unwrap_or_default();
        let _ = writeln!(
            out,
            "f {}/{} {}/{} {}/{}",
            t[0] + 1,
            w[0] + 1,
            t[1] + 1,
            w[1] + 1,
            t[2] + 1,
            w[2] + 1
        );
    }
    out
}
