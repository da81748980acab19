//! Object File Format (OFF, and its COFF / NOFF / CNOFF variants): a header
//! keyword, `nV nF nE`, then vertices (`x y z` plus optional normal or colour)
//! and faces (`n i₁ … iₙ` plus an optional colour). Whitespace-separated
//! tokens with `#` comments. Written here: it is a few dozen lines and every
//! error names its line.

use glam::DVec3;

use super::text::{coordinate, lines};
use super::{IoError, RawMesh};
use crate::mesh::FaceList;

pub fn read(bytes: &[u8], file: &str) -> Result<RawMesh, IoError> {
    let mut lines = lines(bytes, file).filter_map(|item| match item {
        Ok((n, line)) => {
            let content = line.split('#').next().unwrap_or("").trim();
            (!content.is_empty()).then_some(Ok((n, content)))
        }
        Err(e) => Some(Err(e)),
    });
    let eof = |what: &str| IoError::in_file(file, format!("the file ends before {what}"));

    let (header_line, header) = lines.next().ok_or_else(|| eof("the OFF header"))??;
    let mut tokens = header.split_ascii_whitespace();
    let keyword = tokens.next().unwrap_or("");
    if keyword.contains("BINARY") || tokens.clone().any(|t| t == "BINARY") {
        return Err(IoError::at_line(
            file,
            header_line,
            "binary OFF is not supported",
        ));
    }
    match keyword {
        "OFF" | "COFF" | "NOFF" | "CNOFF" | "STOFF" => {}
        _ if keyword.ends_with("OFF") => {
            return Err(IoError::at_line(
                file,
                header_line,
                format!("unsupported OFF variant '{keyword}'"),
            ));
        }
        _ => return Err(IoError::at_line(file, header_line, "missing 'OFF' header")),
    }
    let mut rest: Vec<&str> = tokens.collect();
    let mut counts_line = header_line;
    if rest.is_empty() {
        let (n, line) = lines
            .next()
            .ok_or_else(|| eof("the vertex and face counts"))??;
        counts_line = n;
        rest = line.split_ascii_whitespace().collect();
    }
    if rest.len() < 2 {
        return Err(IoError::at_line(
            file,
            counts_line,
            "expected 'vertices faces [edges]' counts",
        ));
    }
    let count = |t: &str, what: &str| {
        t.parse::<u64>().map_err(|_| {
            IoError::at_line(
                file,
                counts_line,
                format!("{what} count '{t}' is not a non-negative integer"),
            )
        })
    };
    let nv = count(rest[0], "vertex")?;
    let nf = count(rest[1], "face")?;
    if nv >= u32::MAX as u64 || nf >= u32::MAX as u64 {
        return Err(IoError::at_line(
            file,
            counts_line,
            "declared counts exceed 32-bit indices",
        ));
    }
    // Each vertex needs at least 6 bytes ("0 0 0\n"), each face 8: cap the
    // allocation by what the file could possibly hold.
    let cap = |declared: u64, min_bytes: usize| (declared as usize).min(bytes.len() / min_bytes);

    let mut positions = Vec::with_capacity(cap(nv, 6));
    for i in 0..nv {
        let (n, line) = lines
            .next()
            .ok_or_else(|| eof(&format!("vertex {i} of the {nv} declared")))??;
        let mut t = line.split_ascii_whitespace();
        let mut xyz = [0.0; 3];
        for (axis, slot) in xyz.iter_mut().enumerate() {
            let token = t.next().ok_or_else(|| {
                IoError::at_line(file, n, format!("vertex has {axis} coordinates, needs 3"))
            })?;
            *slot = coordinate(token, file, n)?;
        }
        positions.push(DVec3::from_array(xyz));
    }
    let mut faces = FaceList::new();
    let mut corners = Vec::new();
    for i in 0..nf {
        let (n, line) = lines
            .next()
            .ok_or_else(|| eof(&format!("face {i} of the {nf} declared")))??;
        let mut t = line.split_ascii_whitespace();
        let degree_text = t.next().unwrap_or("");
        let degree: usize = degree_text.parse().map_err(|_| {
            IoError::at_line(
                file,
                n,
                format!("face size '{degree_text}' is not a non-negative integer"),
            )
        })?;
        if degree < 3 {
            return Err(IoError::at_line(
                file,
                n,
                format!("face has {degree} corners, needs at least 3"),
            ));
        }
        corners.clear();
        for k in 0..degree {
            let token = t.next().ok_or_else(|| {
                IoError::at_line(
                    file,
                    n,
                    format!("face declares {degree} corners but lists {k}"),
                )
            })?;
            let index: u64 = token.parse().map_err(|_| {
                IoError::at_line(file, n, format!("'{token}' is not a vertex index"))
            })?;
            if index >= nv {
                return Err(IoError::at_line(
                    file,
                    n,
                    format!("vertex index {index} is out of range (the file has {nv} vertices)"),
                ));
            }
            corners.push(index as u32);
        }
        if faces.indices.len() + corners.len() >= u32::MAX as usize {
            return Err(IoError::at_line(file, n, "too many face corners"));
        }
        faces.push(&corners);
    }
    Ok(RawMesh {
        positions,
        faces,
        welded_vertices: 0,
        warnings: Vec::new(),
        creases: Vec::new(),
    })
}

/// OFF text for a polygon mesh.
pub fn write(positions: &[DVec3], faces: &FaceList) -> String {
    use std::fmt::Write as _;
    let mut out = format!("OFF\n{} {} 0\n", positions.len(), faces.len());
    for p in positions {
        let _ = writeln!(out, "{} {} {}", p.x, p.y, p.z);
    }
    for face in faces.iter() {
        let _ = write!(out, "{}", face.len());
        for &i in face {
            let _ = write!(out, " {i}");
        }
        out.push('\n');
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_a_quad_and_names_bad_lines() {
        let m = read(
            b"OFF\n# c\n4 1 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n",
            "q.off",
        )
        .unwrap();
        assert_eq!(m.faces.face(0), &[0, 1, 2, 3]);
        let e = read(b"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n", "q.off").unwrap_err();
        assert!(e.to_string().starts_with("q.off:6:"), "{e}");
    }

    #[test]
    fn huge_declared_counts_fail_without_allocating() {
        let e = read(b"OFF\n4294967295 1 0\n", "h.off").unwrap_err();
        assert!(e.to_string().contains("32-bit"), "{e}");
        let e = read(b"OFF\n400000000 400000000 0\n0 0 0\n", "h.off").unwrap_err();
        assert!(e.to_string().contains("ends before vertex 1"), "{e}");
    }
}
