//! Mesh files in and out.
//!
//! Each reader turns a file's bytes into a [`RawMesh`] (positions as stored,
//! polygons as stored) and reports malformed input as an [`IoError`] naming
//! the file and the line, byte offset or element. [`import`] then validates
//! and repairs the raw mesh the same way for every format ([`repair`]),
//! normalises coordinates ([`Frame`]) and produces the triangle mesh the
//! pipeline reads, plus an [`ImportReport`] of everything it found and fixed.
//!
//! Readers never trust declared counts for allocation: a header that claims
//! 10⁹ vertices in a 100-byte file fails when the data runs out, without
//! reserving gigabytes first.

mod gltf;
mod obj;
mod off;
mod ply;
mod repair;
mod stl;
mod text;

use glam::DVec3;
use serde::{Deserialize, Serialize};

use crate::mesh::{FaceList, Frame, TriMesh};

pub use ply::PlyEncoding;
pub use repair::{ImportReport, Repairs};

/// Where in a file something went wrong.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Location {
    /// Nowhere in particular (empty file, unknown format, …).
    File,
    /// 1-based line of a text format.
    Line(usize),
    /// Byte offset into a binary format.
    Byte(u64),
    /// The `index`-th (0-based) element of a kind, e.g. vertex 17 or face 3.
    Element { kind: &'static str, index: usize },
}

/// A file that could not be read, with the file name and the place.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{}", self.describe())]
pub struct IoError {
    pub file: String,
    pub location: Location,
    pub message: String,
}

impl IoError {
    pub fn new(file: &str, location: Location, message: impl Into<String>) -> IoError {
        IoError {
            file: file.to_string(),
            location,
            message: message.into(),
        }
    }

    pub fn at_line(file: &str, line: usize, message: impl Into<String>) -> IoError {
        IoError::new(file, Location::Line(line), message)
    }

    pub fn in_file(file: &str, message: impl Into<String>) -> IoError {
        IoError::new(file, Location::File, message)
    }

    pub fn at_element(
        file: &str,
        kind: &'static str,
        index: usize,
        message: impl Into<String>,
    ) -> IoError {
        IoError::new(file, Location::Element { kind, index }, message)
    }

    fn describe(&self) -> String {
        match &self.location {
            Location::File => format!("{}: {}", self.file, self.message),
            Location::Line(l) => format!("{}:{}: {}", self.file, l, self.message),
            Location::Byte(b) => format!("{}: byte {}: {}", self.file, b, self.message),
            Location::Element { kind, index } => {
                format!("{}: {} {}: {}", self.file, kind, index, self.message)
            }
        }
    }
}

/// The file formats Quadrille reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Format {
    Obj,
    Ply,
    Stl,
    Off,
    /// glTF 2.0, JSON (`.gltf`, buffers embedded as data URIs) or binary (`.glb`).
    Gltf,
}

impl Format {
    /// From a file name's extension (case-insensitive).
    pub fn from_extension(name: &str) -> Option<Format> {
        let ext = name.rsplit_once('.')?.1.to_ascii_lowercase();
        Some(match ext.as_str() {
            "obj" => Format::Obj,
            "ply" => Format::Ply,
            "stl" => Format::Stl,
            "off" => Format::Off,
            "gltf" | "glb" => Format::Gltf,
            _ => return None,
        })
    }

    /// From the first bytes of a file, for names without a known extension.
    pub fn sniff(bytes: &[u8]) -> Option<Format> {
        let head = &bytes[..bytes.len().min(512)];
        let text = String::from_utf8_lossy(head);
        let first = text.trim_start();
        if head.starts_with(b"glTF") || first.starts_with('{') {
            Some(Format::Gltf)
        } else if head.starts_with(b"ply") {
            Some(Format::Ply)
        } else if first.starts_with("OFF")
            || first.starts_with("COFF")
            || first.starts_with("NOFF")
            || first.starts_with("CNOFF")
        {
            Some(Format::Off)
        } else if first.starts_with("solid") || stl::looks_binary(bytes) {
            Some(Format::Stl)
        } else if text
            .lines()
            .any(|l| l.starts_with("v ") || l.starts_with("f ") || l.starts_with('#'))
        {
            Some(Format::Obj)
        } else {
            None
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Format::Obj => "obj",
            Format::Ply => "ply",
            Format::Stl => "stl",
            Format::Off => "off",
            Format::Gltf => "gltf",
        }
    }
}

/// A mesh as a file stores it: positions in file coordinates and polygons of
/// any degree. Readers guarantee nothing beyond what they parsed; [`import`]
/// validates.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct RawMesh {
    pub positions: Vec<DVec3>,
    pub faces: FaceList,
    /// Vertices merged because they had identical coordinates (STL stores
    /// every triangle's corners separately).
    pub welded_vertices: usize,
    /// Things the reader skipped on purpose (e.g. OBJ line elements), for the report.
    pub warnings: Vec<String>,
    /// Subdivision crease tags (OBJ `t crease`, OpenSubdiv's convention):
    /// an edge's two vertices (0-based file indices) and its sharpness.
    pub creases: Vec<([u32; 2], f64)>,
}

/// A validated, repaired, normalised mesh ready for the pipeline.
#[derive(Debug, Clone)]
pub struct Imported {
    pub name: String,
    pub format: Format,
    /// Maps the local coordinates below back to the file's coordinates.
    pub frame: Frame,
    /// Triangulated surface in local coordinates (largest box axis 1, centred).
    pub mesh: TriMesh,
    /// The file's polygons after repair, over `mesh.positions`.
    pub polygons: FaceList,
    pub report: ImportReport,
}

/// Parses `bytes` with the reader for `name`'s extension (or, failing that,
/// the sniffed format) without validation or repair.
pub fn read_raw(bytes: &[u8], name: &str) -> Result<(Format, RawMesh), IoError> {
    if bytes.is_empty() {
        return Err(IoError::in_file(name, "the file is empty"));
    }
    let format = Format::from_extension(name)
        .or_else(|| Format::sniff(bytes))
        .ok_or_else(|| {
            IoError::in_file(
                name,
                "unknown mesh format (expected .obj, .ply, .stl, .off, .gltf or .glb)",
            )
        })?;
    let raw = match format {
        Format::Obj => obj::read(bytes, name)?,
        Format::Ply => ply::read(bytes, name)?,
        Format::Stl => stl::read(bytes, name)?,
        Format::Off => off::read(bytes, name)?,
        Format::Gltf => gltf::read(bytes, name)?,
    };
    Ok((format, raw))
}

/// Reads, validates, repairs and normalises a mesh file.
///
/// Errors (with file and place): unreadable syntax, non-finite coordinates,
/// out-of-range indices, no faces left. Repairs (counted in the report):
/// degenerate and duplicate faces removed, unreferenced vertices dropped,
/// polygons triangulated for the triangle mesh.
pub fn import(bytes: &[u8], name: &str) -> Result<Imported, IoError> {
    let (format, raw) = read_raw(bytes, name)?;
    repair::import_raw(raw, name, format)
}

/// Writes polygons as OBJ text (`v` and `f` lines; polygons kept as they are).
pub fn write_obj(positions: &[DVec3], faces: &FaceList) -> String {
    obj::write(positions, faces)
}

/// [`write_obj`] plus an infinitely sharp crease tag per edge in
/// `creases` (vertex pairs, 0-based), as OpenSubdiv reads them.
pub fn write_obj_with_creases(
    positions: &[DVec3],
    faces: &FaceList,
    creases: &[[u32; 2]],
) -> String {
    obj::write_with_creases(positions, faces, creases)
}

/// Writes polygons as PLY (`vertex_indices` lists of any degree).
pub fn write_ply(positions: &[DVec3], faces: &FaceList, encoding: PlyEncoding) -> Vec<u8> {
    ply::write(positions, faces, encoding)
}

/// Writes polygons as OFF text.
pub fn write_off(positions: &[DVec3], faces: &FaceList) -> String {
    off::write(positions, faces)
}

/// Writes a mesh in the format implied by `name`'s extension (OBJ, OFF, or
/// binary little-endian PLY).
pub fn write_by_extension(
    name: &str,
    positions: &[DVec3],
    faces: &FaceList,
) -> Result<Vec<u8>, IoError> {
    match Format::from_extension(name) {
        Some(Format::Obj) => Ok(write_obj(positions, faces).into_bytes()),
        Some(Format::Off) => Ok(write_off(positions, faces).into_bytes()),
        Some(Format::Ply) => Ok(write_ply(positions, faces, PlyEncoding::BinaryLittleEndian)),
        _ => Err(IoError::in_file(
            name,
            "can only write .obj, .ply and .off files",
        )),
    }
}
