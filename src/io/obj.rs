//! Wavefront OBJ: `v` and `f` statements; everything else is skipped.
//!
//! Written here rather than with `tobj`: `tobj` splits `o`/`g` groups into
//! separate models with their own vertex numbering (we must ignore groups and
//! keep one connected surface) and reports errors without line numbers (we
//! must name the line).
//!
//! Accepted: `v x y z [w | r g b]`; faces `f a b c …` whose corners are `v`,
//! `v/vt`, `v//vn` or `v/vt/vn`, with 1-based or negative (relative)
//! indices; forward references to vertices defined later; comments; line
//! continuations (`\` at the end of a line). `l`, `p` and free-form
//! statements are skipped with a warning in the report.
//!
//! Subdivision tags as OpenSubdiv writes them into OBJ files: `t crease
//! n/1/0 v0 … vn-1 s` (a chain of edges, 0-based vertex indices, one
//! sharpness; `n/(n-1)/0` gives one per edge) is read into
//! [`RawMesh::creases`]; other `t` tags are skipped with a warning.
//! [`write_with_creases`] writes the control mesh's creases that way.

use std::fmt::Write as _;

use glam::DVec3;

use super::text::{coordinate, lines};
use super::{IoError, RawMesh};
use crate::mesh::FaceList;

pub fn read(bytes: &[u8], file: &str) -> Result<RawMesh, IoError> {
    let mut positions: Vec<DVec3> = Vec::new();
    let mut faces = FaceList::new();
    // Line of each face, to name it if an index turns out out of range.
    let mut face_lines: Vec<u32> = Vec::new();
    let mut skipped: Vec<(&'static str, usize)> = Vec::new();
    let mut corners: Vec<u32> = Vec::new();
    // Crease edges and the line of each, to name it if out of range.
    let mut creases: Vec<([u32; 2], f64)> = Vec::new();
    let mut crease_lines: Vec<u32> = Vec::new();
    let mut pending = String::new();
    let mut pending_line = 0;

    for item in lines(bytes, file) {
        let (number, raw_line) = item?;
        // Line continuation: join with the next line, report the first line.
        let line: &str = if !pending.is_empty() || raw_line.trim_end().ends_with('\\') {
            if pending.is_empty() {
                pending_line = number;
            }
            let trimmed = raw_line.trim_end();
            if let Some(head) = trimmed.strip_suffix('\\') {
                pending.push_str(head);
                pending.push(' ');
                continue;
            }
            pending.push_str(trimmed);
            &pending
        } else {
            pending_line = number;
            raw_line
        };
        let number = pending_line;
        let content = line.split('#').next().unwrap_or("");
        let mut tokens = content.split_ascii_whitespace();
        let Some(keyword) = tokens.next() else {
            pending.clear();
            continue;
        };
        match keyword {
            "v" => {
                let p = vertex(tokens, file, number)?;
                if positions.len() >= u32::MAX as usize - 1 {
                    return Err(IoError::at_line(file, number, "too many vertices"));
                }
                positions.push(p);
            }
            "f" | "fo" => {
                face_corners(tokens, positions.len(), file, number, &mut corners)?;
                if corners.len() < 3 {
                    return Err(IoError::at_line(
                        file,
                        number,
                        format!("face has {} corners, needs at least 3", corners.len()),
                    ));
                }
                if faces.indices.len() + corners.len() >= u32::MAX as usize {
                    return Err(IoError::at_line(file, number, "too many face corners"));
                }
                faces.push(&corners);
                face_lines.push(number as u32);
            }
            "l" => skipped_count(&mut skipped, "line (l) elements"),
            "t" => {
                if !tag(tokens, file, number, &mut creases)? {
                    skipped_count(&mut skipped, "subdivision tags (t) other than crease");
                }
                crease_lines.resize(creases.len(), number as u32);
            }
            "p" => skipped_count(&mut skipped, "point (p) elements"),
            "curv" | "curv2" | "surf" | "bmat" | "cstype" | "deg" | "step" | "parm" | "trim"
            | "hole" | "sp" | "end" | "con" => {
                skipped_count(&mut skipped, "free-form geometry statements")
            }
            "vt" | "vn" | "vp" | "g" | "o" | "s" | "mg" | "usemtl" | "mtllib" | "usemap"
            | "maplib" | "lod" | "shadow_obj" | "trace_obj" | "bevel" | "c_interp" | "d_interp"
            | "ctech" | "stech" | "call" | "csh" => {}
            other => {
                return Err(IoError::at_line(
                    file,
                    number,
                    format!(
                        "unknown OBJ statement '{}'",
                        other.chars().take(40).collect::<String>()
                    ),
                ));
            }
        }
        pending.clear();
    }
    if !pending.is_empty() {
        return Err(IoError::at_line(
            file,
            pending_line,
            "the file ends inside a line continuation",
        ));
    }

    let count = positions.len();
    for (f, face) in faces.iter().enumerate() {
        if let Some(&bad) = face.iter().find(|&&i| i as usize >= count) {
            return Err(IoError::at_line(
                file,
                face_lines[f] as usize,
                format!(
                    "vertex index {} is out of range (the file has {count} vertices)",
                    bad as u64 + 1
                ),
            ));
        }
    }
    for (c, (edge, _)) in creases.iter().enumerate() {
        if let Some(&bad) = edge.iter().find(|&&i| i as usize >= count) {
            return Err(IoError::at_line(
                file,
                crease_lines[c] as usize,
                format!(
                    "crease vertex index {bad} is out of range (0-based; the file has {count} vertices)"
                ),
            ));
        }
    }
    let warnings = skipped
        .into_iter()
        .map(|(what, n)| format!("skipped {n} {what}"))
        .collect();
    Ok(RawMesh {
        positions,
        faces,
        welded_vertices: 0,
        warnings,
        creases,
    })
}

/// A `t` statement (after the keyword): a `crease` tag's edges are pushed
/// to `creases` (true); any other tag is left alone (false).
fn tag<'a>(
    mut tokens: impl Iterator<Item = &'a str>,
    file: &str,
    number: usize,
    creases: &mut Vec<([u32; 2], f64)>,
) -> Result<bool, IoError> {
    if tokens.next() != Some("crease") {
        return Ok(false);
    }
    let bad = |what: String| IoError::at_line(file, number, what);
    let counts: Vec<usize> = tokens
        .next()
        .map(|c| {
            c.split('/')
                .map(|n| n.parse::<usize>())
                .collect::<Result<_, _>>()
        })
        .transpose()
        .ok()
        .flatten()
        .filter(|c: &Vec<usize>| c.len() == 3)
        .ok_or_else(|| {
            bad("crease tag needs its argument counts, as in 't crease 2/1/0 a b s'".into())
        })?;
    let (ints, floats) = (counts[0], counts[1]);
    if ints < 2 || (floats != 1 && floats != ints - 1) || counts[2] != 0 {
        return Err(bad(format!(
            "crease tag with {ints}/{floats}/{} arguments: needs n ≥ 2 vertices and 1 or n − 1 sharpness values",
            counts[2]
        )));
    }
    let mut vertices = Vec::with_capacity(ints);
    for _ in 0..ints {
        let token = tokens
            .next()
            .ok_or_else(|| bad(format!("crease tag has fewer than {ints} vertex indices")))?;
        let v: u32 = token.parse().map_err(|_| {
            bad(format!(
                "crease vertex index '{token}' is not a non-negative integer"
            ))
        })?;
        vertices.push(v);
    }
    let mut sharpness = Vec::with_capacity(floats);
    for _ in 0..floats {
        let token = tokens.next().ok_or_else(|| {
            bad(format!(
                "crease tag has fewer than {floats} sharpness values"
            ))
        })?;
        let s: f64 = token
            .parse()
            .ok()
            .filter(|s: &f64| s.is_finite() && *s >= 0.0)
            .ok_or_else(|| {
                bad(format!(
                    "crease sharpness '{token}' is not a non-negative number"
                ))
            })?;
        sharpness.push(s);
    }
    for (i, pair) in vertices.windows(2).enumerate() {
        creases.push(([pair[0], pair[1]], sharpness[i.min(floats - 1)]));
    }
    Ok(true)
}

/// A `v` statement's position (after the keyword); a fourth coordinate or
/// a colour must still be numbers.
fn vertex<'a>(
    mut tokens: impl Iterator<Item = &'a str>,
    file: &str,
    number: usize,
) -> Result<DVec3, IoError> {
    let mut xyz = [0.0; 3];
    for (axis, slot) in xyz.iter_mut().enumerate() {
        let token = tokens.next().ok_or_else(|| {
            IoError::at_line(
                file,
                number,
                format!("vertex has {axis} coordinates, needs 3"),
            )
        })?;
        *slot = coordinate(token, file, number)?;
    }
    for extra in tokens {
        // w or a colour: must still be numbers.
        if extra.parse::<f64>().is_err() {
            return Err(IoError::at_line(
                file,
                number,
                format!("'{extra}' is not a number"),
            ));
        }
    }
    Ok(DVec3::from_array(xyz))
}

/// A face statement's corners (after the keyword) as 0-based vertex
/// indices into `corners`, relative indices resolved against the
/// `defined` vertices so far.
fn face_corners<'a>(
    tokens: impl Iterator<Item = &'a str>,
    defined: usize,
    file: &str,
    number: usize,
    corners: &mut Vec<u32>,
) -> Result<(), IoError> {
    corners.clear();
    for token in tokens {
        let index_text = token.split('/').next().unwrap_or("");
        let index: i64 = index_text.parse().map_err(|_| {
            IoError::at_line(
                file,
                number,
                format!("'{token}' is not a face corner (v, v/vt, v//vn or v/vt/vn)"),
            )
        })?;
        let resolved = if index > 0 {
            index - 1
        } else if index < 0 {
            defined as i64 + index
        } else {
            return Err(IoError::at_line(
                file,
                number,
                "vertex index 0 (OBJ indices start at 1)",
            ));
        };
        if resolved < 0 {
            return Err(IoError::at_line(
                file,
                number,
                format!(
                    "relative index {index} points before the first vertex (only {} defined so far)",
                    defined
                ),
            ));
        }
        if resolved >= u32::MAX as i64 {
            return Err(IoError::at_line(
                file,
                number,
                format!("vertex index {index} is out of range"),
            ));
        }
        corners.push(resolved as u32);
    }
    Ok(())
}

fn skipped_count(skipped: &mut Vec<(&'static str, usize)>, what: &'static str) {
    match skipped.iter_mut().find(|(w, _)| *w == what) {
        Some((_, n)) => *n += 1,
        None => skipped.push((what, 1)),
    }
}

/// Shortest round-trip decimal form of each coordinate, so reading back
/// gives the same `f64`s.
pub fn write(positions: &[DVec3], faces: &FaceList) -> String {
    let mut out = String::with_capacity(positions.len() * 40 + faces.indices.len() * 8);
    out.push_str("# written by quadrille\n");
    for p in positions {
        let _ = writeln!(out, "v {} {} {}", p.x, p.y, p.z);
    }
    for face in faces.iter() {
        out.push('f');
        for &i in face {
            let _ = write!(out, " {}", i as u64 + 1);
        }
        out.push('\n');
    }
    out
}

/// [`write`] plus one `t crease 2/1/0 a b 10` tag per edge of `creases`
/// (0-based vertex indices; 10 is OpenSubdiv's infinite sharpness), so a
/// subdivision tool that reads them (OpenSubdiv, or [`read`]) gets the
/// fitted control mesh's infinitely sharp creases with it.
pub fn write_with_creases(positions: &[DVec3], faces: &FaceList, creases: &[[u32; 2]]) -> String {
    let mut out = write(positions, faces);
    if !creases.is_empty() {
        out.push_str("# infinitely sharp creases (OpenSubdiv tags; sharpness 10 is infinite)\n");
    }
    for [a, b] in creases {
        let _ = writeln!(out, "t crease 2/1/0 {a} {b} 10");
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn corner_forms_and_negative_indices() {
        let text = b"v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1/1 2/2/2 3//3 4\nf -4 -2 -1\n";
        let m = read(text, "t.obj").unwrap();
        assert_eq!(m.positions.len(), 4);
        assert_eq!(m.faces.face(0), &[0, 1, 2, 3]);
        assert_eq!(m.faces.face(1), &[0, 2, 3]);
    }

    #[test]
    fn errors_name_the_line() {
        let e = read(b"v 0 0 0\nv 1 0 0\n\nf 1 2 9\n", "x.obj").unwrap_err();
        assert_eq!(e.location, super::super::Location::Line(4));
        assert!(e.to_string().starts_with("x.obj:4:"), "{e}");
        let e = read(b"v 0 0 0\nv nan 0 0\n", "x.obj").unwrap_err();
        assert!(e.to_string().starts_with("x.obj:2:"), "{e}");
    }

    #[test]
    fn crease_tags_are_read_and_written() {
        let text = b"v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n\
            t crease 2/1/0 0 1 10\nt crease 3/2/0 1 2 3 2.5 4\nt corner 1/1/0 0 3\n";
        let m = read(text, "t.obj").unwrap();
        assert_eq!(
            m.creases,
            vec![([0, 1], 10.0), ([1, 2], 2.5), ([2, 3], 4.0)]
        );
        assert_eq!(
            m.warnings,
            vec!["skipped 1 subdivision tags (t) other than crease"]
        );
        let written = write_with_creases(&m.positions, &m.faces, &[[3, 0], [0, 1]]);
        let back = read(written.as_bytes(), "w.obj").unwrap();
        assert_eq!(back.positions, m.positions);
        assert_eq!(back.faces, m.faces);
        assert_eq!(back.creases, vec![([3, 0], 10.0), ([0, 1], 10.0)]);
        let bad = |text: &[u8]| read(text, "c.obj").unwrap_err().to_string();
        assert!(bad(b"v 0 0 0\nv 1 0 0\nt crease 2/1/0 0 5 10\n").starts_with("c.obj:3:"));
        assert!(bad(b"v 0 0 0\nt crease 1/1/0 0 10\n").starts_with("c.obj:2:"));
        assert!(bad(b"v 0 0 0\nt crease 2/1/0 0 x 10\n").starts_with("c.obj:2:"));
        assert!(bad(b"v 0 0 0\nt crease 2/1/0 0 0 -1\n").starts_with("c.obj:2:"));
        assert!(bad(b"v 0 0 0\nt crease\n").starts_with("c.obj:2:"));
    }

    #[test]
    fn continuation_lines_join() {
        let m = read(b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 \\\n 2 3\n", "t.obj").unwrap();
        assert_eq!(m.faces.face(0), &[0, 1, 2]);
    }
}
