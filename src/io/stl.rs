//! STL, ASCII and binary, parsed with `stl_io`; corners welded here.
//!
//! STL stores every triangle's three corners separately. We weld corners
//! with exactly equal coordinates (`-0.0` equals `0.0`) into one vertex and
//! report how many corners merged (`corners − unique vertices`) in
//! [`RawMesh::welded_vertices`].
//!
//! Deviations from plain `stl_io` use:
//! - We pick the flavour ourselves. ASCII files start with `solid`, but so do
//!   many binary headers; a file is binary when its size is exactly
//!   84 + 50 × (declared triangles) ([`looks_binary`]) or when its first
//!   kilobyte holds a NUL byte. `stl_io` only checks for `"solid "`, so we
//!   hand it the bytes behind a small splice that makes its guess agree with
//!   ours (a binary header's first byte reads as NUL; an ASCII first line,
//!   even a bare `solid`, reads as `solid quadrille`).
//! - Binary sizes are checked before reading: a truncated file is reported
//!   with the declared and actual sizes; bytes after the declared triangles
//!   are ignored with a warning.
//! - Welding keys on exact `f32` values rather than bit patterns, so `-0.0`
//!   and `0.0` merge; NaN and infinite corners are errors naming the triangle.
//!   (Facet normals are ignored, so a NaN normal is harmless.)
//!
//! ASCII coordinates are `f32` by the format's definition (`stl_io` parses
//! them as such).

use std::collections::HashMap;
use std::io::{Read, Seek, SeekFrom};

use glam::DVec3;

use super::{IoError, Location, RawMesh};
use crate::mesh::FaceList;

/// A binary STL's size is 84 + 50 × (its declared triangle count).
pub fn looks_binary(bytes: &[u8]) -> bool {
    bytes.len() >= 84
        && u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as u64 * 50 + 84
            == bytes.len() as u64
}

/// ASCII unless the size or a NUL byte says binary.
fn is_ascii(bytes: &[u8]) -> bool {
    let head = &bytes[..bytes.len().min(1024)];
    let start = head
        .iter()
        .position(|b| !b.is_ascii_whitespace())
        .unwrap_or(head.len());
    head[start..].starts_with(b"solid") && !looks_binary(bytes) && !head.contains(&0)
}

pub fn read(bytes: &[u8], file: &str) -> Result<RawMesh, IoError> {
    let mut warnings = Vec::new();
    let (mut source, expected) = if is_ascii(bytes) {
        // Replace the first line (`solid [name]`) by one `stl_io` accepts.
        let end = bytes
            .iter()
            .position(|&b| b == b'\n')
            .map_or(bytes.len(), |i| i + 1);
        (Spliced::new(b"solid quadrille\n", &bytes[end..]), None)
    } else {
        if bytes.len() < 84 {
            return Err(IoError::in_file(
                file,
                format!(
                    "too short for a binary STL ({} bytes; the header alone takes 84) and not ASCII STL (no 'solid' line)",
                    bytes.len()
                ),
            ));
        }
        let declared = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as u64;
        let needed = 84 + 50 * declared;
        let have = bytes.len() as u64;
        if have < needed {
            return Err(IoError::new(
                file,
                Location::Byte(have),
                format!(
                    "binary STL is truncated: it declares {declared} triangles ({needed} bytes) but has {have} bytes"
                ),
            ));
        }
        if have > needed {
            warnings.push(format!(
                "ignored {} bytes after the {declared} declared triangles",
                have - needed
            ));
        }
        // The first header byte reads as NUL so `stl_io` never takes a
        // binary file whose header starts with "solid " for ASCII.
        (Spliced::new(&[0], &bytes[1..]), Some(declared))
    };
    let triangles = stl_io::create_stl_reader(&mut source)
        .map_err(|e| IoError::in_file(file, format!("not a readable STL file: {e}")))?;

    let capacity = expected.unwrap_or(0).min(bytes.len() as u64 / 50) as usize;
    let mut positions: Vec<DVec3> = Vec::with_capacity(capacity);
    let mut faces = FaceList::new();
    faces.indices.reserve(capacity * 3);
    let mut index_of: HashMap<[u32; 3], u32> = HashMap::with_capacity(capacity);
    let mut corners = 0usize;
    let kind = if expected.is_some() {
        "triangle"
    } else {
        "facet"
    };
    for (t, triangle) in triangles.enumerate() {
        let triangle = triangle.map_err(|e| {
            if e.kind() == std::io::ErrorKind::UnexpectedEof && expected.is_none() {
                IoError::at_element(
                    file,
                    kind,
                    t,
                    format!("the file ends inside the facet or before 'endsolid' ({e})"),
                )
            } else {
                IoError::at_element(file, kind, t, e.to_string())
            }
        })?;
        let mut face = [0u32; 3];
        for (slot, vertex) in face.iter_mut().zip(triangle.vertices.iter()) {
            let xyz: [f32; 3] = vertex.0;
            if let Some(bad) = xyz.iter().find(|c| !c.is_finite()) {
                return Err(IoError::at_element(
                    file,
                    kind,
                    t,
                    format!("corner coordinate {bad} is not finite"),
                ));
            }
            // Adding 0.0 turns -0.0 into 0.0, so equal values share a key.
            let key = xyz.map(|c| (c + 0.0).to_bits());
            let next = positions.len() as u32;
            *slot = *index_of.entry(key).or_insert(next);
            if *slot == next {
                positions.push(DVec3::new(xyz[0].into(), xyz[1].into(), xyz[2].into()));
            }
        }
        corners += 3;
        if faces.indices.len() + 3 >= u32::MAX as usize {
            return Err(IoError::at_element(file, kind, t, "too many triangles"));
        }
        faces.push(&face);
    }
    Ok(RawMesh {
        welded_vertices: corners - positions.len(),
        positions,
        faces,
        warnings,
        creases: Vec::new(),
    })
}

/// Reads as `head` followed by `tail`, without copying `tail`.
struct Spliced<'a> {
    head: &'a [u8],
    tail: &'a [u8],
    pos: u64,
}

impl<'a> Spliced<'a> {
    fn new(head: &'a [u8], tail: &'a [u8]) -> Self {
        Spliced { head, tail, pos: 0 }
    }

    fn len(&self) -> u64 {
        (self.head.len() + self.tail.len()) as u64
    }
}

impl Read for Spliced<'_> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let pos = self.pos.min(self.len()) as usize;
        let src = if pos < self.head.len() {
            &self.head[pos..]
        } else {
            &self.tail[pos - self.head.len()..]
        };
        let n = src.len().min(buf.len());
        buf[..n].copy_from_slice(&src[..n]);
        self.pos += n as u64;
        Ok(n)
    }
}

impl Seek for Spliced<'_> {
    fn seek(&mut self, to: SeekFrom) -> std::io::Result<u64> {
        let target = match to {
            SeekFrom::Start(p) => Some(p),
            SeekFrom::End(d) => self.len().checked_add_signed(d),
            SeekFrom::Current(d) => self.pos.checked_add_signed(d),
        };
        let target = target.ok_or_else(|| {
            std::io::Error::new(std::io::ErrorKind::InvalidInput, "seek out of range")
        })?;
        self.pos = target;
        Ok(target)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spliced_reads_and_seeks() {
        let mut s = Spliced::new(b"ab", b"cde");
        let mut all = Vec::new();
        s.read_to_end(&mut all).unwrap();
        assert_eq!(all, b"abcde");
        s.seek(SeekFrom::Start(1)).unwrap();
        let mut two = [0u8; 2];
        s.read_exact(&mut two).unwrap();
        assert_eq!(&two, b"bc");
        assert!(s.seek(SeekFrom::Current(-10)).is_err());
    }

    #[test]
    fn bare_solid_line_and_negative_zero_weld() {
        let text = b"solid\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n\
vertex 0 1 0\nendloop\nendfacet\nfacet normal 0 0 1\nouter loop\nvertex -0 0 0\n\
vertex 0 1 0\nvertex -1 0 0\nendloop\nendfacet\nendsolid\n";
        let m = read(text, "t.stl").unwrap();
        assert_eq!(m.positions.len(), 4);
        assert_eq!(m.welded_vertices, 2);
        assert_eq!(m.faces.face(1), &[0, 2, 3]);
    }
}
