//! Stanford PLY: `ascii`, `binary_little_endian` and `binary_big_endian`.
//!
//! The header and binary bodies are parsed with `ply-rs-bw`, one element at a
//! time so that every error names the element (kind and index) and its byte
//! offset. Accepted: a `vertex` element with scalar `x`, `y`, `z` of any type;
//! a `face` element with a `vertex_indices` or `vertex_index` list of any
//! integer count and index types; a `tristrips` element with a
//! `vertex_indices` list where `-1` restarts a strip (as the classic Stanford
//! scans ship). Other elements and properties are read past and ignored.
//!
//! Deviations from plain `ply-rs-bw` use:
//! - ASCII bodies are tokenised here, one element per line: the crate's data
//!   grammar rejects `nan`, `1.` and `.5` without saying which property is
//!   wrong, and we want the line and a clear message ("coordinate 'nan' is not
//!   finite").
//! - Declared counts never size an allocation beyond what the remaining bytes
//!   could hold, so a header claiming 4·10⁹ vertices in a 200-byte file fails
//!   when the data runs out.
//! - Strip triangles alternate winding (odd triangles swap their first two
//!   corners) and are emitted even when degenerate (strips use repeated
//!   vertices to turn): import's repair drops and counts those.
//! - Element names must be unique: `ply-rs-bw` keys elements by name, so a
//!   repeated name would silently change the body layout.

use std::fmt::Write as _;

use glam::DVec3;
use ply_rs_bw::parser::{Parser, Reader};
use ply_rs_bw::ply::{
    ElementDef, Encoding, Header, PropertyAccess, PropertyAccessResult, PropertyType, ScalarType,
};

use super::text::lines;
use super::{IoError, Location, RawMesh};
use crate::mesh::FaceList;

/// How a PLY file stores its data.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PlyEncoding {
    Ascii,
    BinaryLittleEndian,
    BinaryBigEndian,
}

/// Names of the face index list, in order of preference.
const INDEX_LISTS: [&str; 2] = ["vertex_indices", "vertex_index"];

/// What an element of the file is for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Role {
    Vertices,
    Faces,
    Strips,
    Skip,
}

impl Role {
    fn kind(self) -> &'static str {
        match self {
            Role::Vertices => "vertex",
            Role::Faces => "face",
            Role::Strips => "tristrip",
            Role::Skip => "element",
        }
    }
}

/// One element's values, as far as we use them: coordinates of scalar
/// `x`/`y`/`z`, and the integer index list.
#[derive(Debug, Default)]
struct Record {
    xyz: [f64; 3],
    list: Vec<i64>,
}

impl Record {
    fn set_scalar(&mut self, name: &str, value: f64) -> PropertyAccessResult {
        match name {
            "x" => self.xyz[0] = value,
            "y" => self.xyz[1] = value,
            "z" => self.xyz[2] = value,
            _ => return PropertyAccessResult::Ignored,
        }
        PropertyAccessResult::Set
    }

    fn set_list(&mut self, name: &str, values: impl Iterator<Item = i64>) -> PropertyAccessResult {
        if INDEX_LISTS.contains(&name) {
            self.list.clear();
            self.list.extend(values);
            PropertyAccessResult::Set
        } else {
            PropertyAccessResult::Ignored
        }
    }
}

impl PropertyAccess for Record {
    fn new() -> Self {
        Record::default()
    }
    fn set_char(&mut self, name: &str, value: i8) -> PropertyAccessResult {
        self.set_scalar(name, value.into())
    }
    fn set_uchar(&mut self, name: &str, value: u8) -> PropertyAccessResult {
        self.set_scalar(name, value.into())
    }
    fn set_short(&mut self, name: &str, value: i16) -> PropertyAccessResult {
        self.set_scalar(name, value.into())
    }
    fn set_ushort(&mut self, name: &str, value: u16) -> PropertyAccessResult {
        self.set_scalar(name, value.into())
    }
    fn set_int(&mut self, name: &str, value: i32) -> PropertyAccessResult {
        self.set_scalar(name, value.into())
    }
    fn set_uint(&mut self, name: &str, value: u32) -> PropertyAccessResult {
        self.set_scalar(name, value.into())
    }
    fn set_float(&mut self, name: &str, value: f32) -> PropertyAccessResult {
        self.set_scalar(name, value.into())
    }
    fn set_double(&mut self, name: &str, value: f64) -> PropertyAccessResult {
        self.set_scalar(name, value)
    }
    fn set_list_char(&mut self, name: &str, value: Vec<i8>) -> PropertyAccessResult {
        self.set_list(name, value.into_iter().map(i64::from))
    }
    fn set_list_uchar(&mut self, name: &str, value: Vec<u8>) -> PropertyAccessResult {
        self.set_list(name, value.into_iter().map(i64::from))
    }
    fn set_list_short(&mut self, name: &str, value: Vec<i16>) -> PropertyAccessResult {
        self.set_list(name, value.into_iter().map(i64::from))
    }
    fn set_list_ushort(&mut self, name: &str, value: Vec<u16>) -> PropertyAccessResult {
        self.set_list(name, value.into_iter().map(i64::from))
    }
    fn set_list_int(&mut self, name: &str, value: Vec<i32>) -> PropertyAccessResult {
        self.set_list(name, value.into_iter().map(i64::from))
    }
    fn set_list_uint(&mut self, name: &str, value: Vec<u32>) -> PropertyAccessResult {
        self.set_list(name, value.into_iter().map(i64::from))
    }
    // Float lists (texture coordinates and the like) are ignored; the header
    // check rejects float index lists before the body is read.
    fn set_list_float(&mut self, _: &str, _: Vec<f32>) -> PropertyAccessResult {
        PropertyAccessResult::Ignored
    }
    fn set_list_double(&mut self, _: &str, _: Vec<f64>) -> PropertyAccessResult {
        PropertyAccessResult::Ignored
    }
}

/// Everything read from the body, and how to name places in it.
struct Body<'a> {
    file: &'a str,
    vertex_count: usize,
    positions: Vec<DVec3>,
    faces: FaceList,
    corners: Vec<u32>,
}

impl Body<'_> {
    /// Adds element `index` of `role` (already parsed into `record`).
    /// `at` names the place for error messages.
    fn take(
        &mut self,
        role: Role,
        record: &Record,
        at: &dyn Fn(String) -> IoError,
    ) -> Result<(), IoError> {
        match role {
            Role::Skip => {}
            Role::Vertices => {
                if let Some(axis) = record.xyz.iter().position(|c| !c.is_finite()) {
                    return Err(at(format!(
                        "coordinate {} = {} is not finite",
                        ["x", "y", "z"][axis],
                        record.xyz[axis]
                    )));
                }
                self.positions.push(DVec3::from_array(record.xyz));
            }
            Role::Faces => {
                if record.list.len() < 3 {
                    return Err(at(format!(
                        "face has {} corners, needs at least 3",
                        record.list.len()
                    )));
                }
                self.corners.clear();
                for &i in &record.list {
                    let v = self.check_index(i, at)?;
                    self.corners.push(v);
                }
                self.push_face(at)?;
            }
            Role::Strips => {
                // Runs between -1 markers; in each run, triangle k is
                // (k, k+1, k+2), with the first two swapped for odd k so
                // every triangle keeps the strip's orientation.
                let mut run: Vec<u32> = Vec::new();
                for &i in record.list.iter().chain(std::iter::once(&-1)) {
                    if i == -1 {
                        for k in 0..run.len().saturating_sub(2) {
                            let (a, b, c) = (run[k], run[k + 1], run[k + 2]);
                            self.corners.clear();
                            if k % 2 == 0 {
                                self.corners.extend_from_slice(&[a, b, c]);
                            } else {
                                self.corners.extend_from_slice(&[b, a, c]);
                            }
                            self.push_face(at)?;
                        }
                        run.clear();
                    } else {
                        run.push(self.check_index(i, at)?);
                    }
                }
            }
        }
        Ok(())
    }

    fn check_index(&self, i: i64, at: &dyn Fn(String) -> IoError) -> Result<u32, IoError> {
        if i < 0 {
            return Err(at(format!("negative vertex index {i}")));
        }
        if i as u64 >= self.vertex_count as u64 {
            return Err(at(format!(
                "vertex index {i} is out of range (the file has {} vertices)",
                self.vertex_count
            )));
        }
        Ok(i as u32)
    }

    fn push_face(&mut self, at: &dyn Fn(String) -> IoError) -> Result<(), IoError> {
        if self.faces.indices.len() + self.corners.len() >= u32::MAX as usize {
            return Err(at("too many face corners".to_string()));
        }
        self.faces.push(&self.corners);
        Ok(())
    }
}

pub fn read(bytes: &[u8], file: &str) -> Result<RawMesh, IoError> {
    if !bytes.starts_with(b"ply") {
        return Err(IoError::at_line(
            file,
            1,
            "not a PLY file (it must start with 'ply')",
        ));
    }
    let parser = Parser::<Record>::new();
    let mut reader = Reader::new(bytes);
    let header = parser
        .read_header(&mut reader)
        .map_err(|e| header_error(bytes, file, e.line(), &e.to_string()))?;
    let body: &[u8] = reader.into_inner();
    let body_start = bytes.len() - body.len();
    check_unique_elements(&bytes[..body_start], &header, file)?;
    let roles = plan(&header, file)?;

    let vertex_count = header.elements.get("vertex").map(|e| e.count).unwrap_or(0);
    let mut out = Body {
        file,
        vertex_count,
        // Every vertex takes at least three bytes (or one line), so the body's
        // length bounds the allocation whatever the header claims.
        positions: Vec::with_capacity(vertex_count.min(body.len() / 3)),
        faces: FaceList::new(),
        corners: Vec::new(),
    };
    // Elements after the last one we need are never read.
    let last_needed = roles.iter().rposition(|&r| r != Role::Skip).unwrap_or(0);
    let elements: Vec<(&ElementDef, Role)> = header
        .elements
        .values()
        .zip(roles)
        .take(last_needed + 1)
        .collect();
    match header.encoding {
        Encoding::Ascii => {
            let first_line = bytes[..body_start].iter().filter(|&&b| b == b'\n').count() + 1;
            read_ascii(body, first_line, &elements, &mut out)?;
        }
        Encoding::BinaryLittleEndian | Encoding::BinaryBigEndian => {
            read_binary(
                &parser,
                body,
                body_start,
                header.encoding == Encoding::BinaryBigEndian,
                &elements,
                &mut out,
            )?;
        }
    }
    Ok(RawMesh {
        positions: out.positions,
        faces: out.faces,
        welded_vertices: 0,
        warnings: Vec::new(),
        creases: Vec::new(),
    })
}

/// Turns a `ply-rs-bw` header error into ours, quoting the offending line.
fn header_error(bytes: &[u8], file: &str, line: Option<usize>, message: &str) -> IoError {
    let first = message.lines().next().unwrap_or("");
    match line {
        Some(n) => {
            let first = first
                .strip_prefix(&format!("Line {n}: "))
                .unwrap_or(first)
                .trim();
            let text = bytes
                .split(|&b| b == b'\n')
                .nth(n.saturating_sub(1))
                .map(|l| String::from_utf8_lossy(l).trim().chars().take(60).collect())
                .unwrap_or_else(String::new);
            IoError::at_line(
                file,
                n,
                format!("invalid PLY header: {first} (line '{text}')"),
            )
        }
        None => IoError::in_file(file, format!("invalid PLY header: {first}")),
    }
}

/// `ply-rs-bw` keys elements by name; a repeated name would replace the
/// earlier definition and silently change the body layout.
fn check_unique_elements(header_bytes: &[u8], header: &Header, file: &str) -> Result<(), IoError> {
    let text = String::from_utf8_lossy(header_bytes);
    let mut names = std::collections::HashSet::new();
    let mut properties = 0usize;
    for (n, line) in text.lines().enumerate() {
        let mut t = line.split_ascii_whitespace();
        match t.next() {
            Some("element") => {
                let name = t.next().unwrap_or("");
                if !names.insert(name) {
                    return Err(IoError::at_line(
                        file,
                        n + 1,
                        format!(
                            "element '{}' is declared twice",
                            name.chars().take(40).collect::<String>()
                        ),
                    ));
                }
            }
            Some("property") => properties += 1,
            _ => {}
        }
    }
    let parsed: usize = header.elements.values().map(|e| e.properties.len()).sum();
    if properties != parsed {
        return Err(IoError::in_file(
            file,
            "invalid PLY header: a property name is repeated within an element",
        ));
    }
    Ok(())
}

/// Decides each element's role and checks the header declares what we need.
fn plan(header: &Header, file: &str) -> Result<Vec<Role>, IoError> {
    let mut roles = Vec::with_capacity(header.elements.len());
    let (mut vertices, mut faces) = (false, false);
    for element in header.elements.values() {
        let role = match element.name.as_str() {
            "vertex" => Role::Vertices,
            "face" => Role::Faces,
            "tristrips" => Role::Strips,
            _ => Role::Skip,
        };
        if role != Role::Skip && element.count >= u32::MAX as usize {
            return Err(IoError::in_file(
                file,
                format!(
                    "the header declares {} {} elements, more than 32-bit indices allow",
                    element.count, element.name
                ),
            ));
        }
        match role {
            Role::Vertices => {
                vertices = true;
                for axis in ["x", "y", "z"] {
                    match element.properties.get(axis).map(|p| &p.data_type) {
                        Some(PropertyType::Scalar(_)) => {}
                        Some(PropertyType::List(..)) => {
                            return Err(IoError::in_file(
                                file,
                                format!("vertex property '{axis}' is a list, expected a number"),
                            ));
                        }
                        None => {
                            return Err(IoError::in_file(
                                file,
                                format!("the vertex element has no '{axis}' property"),
                            ));
                        }
                    }
                }
            }
            Role::Faces | Role::Strips => {
                faces = true;
                let names: &[&str] = if role == Role::Faces {
                    &INDEX_LISTS
                } else {
                    &INDEX_LISTS[..1]
                };
                let Some(property) = names.iter().find_map(|n| element.properties.get(*n)) else {
                    return Err(IoError::in_file(
                        file,
                        format!(
                            "the {} element has no '{}' list property",
                            element.name,
                            names.join("' or '")
                        ),
                    ));
                };
                match &property.data_type {
                    PropertyType::List(count, index) if is_integer(count) && is_integer(index) => {}
                    PropertyType::List(count, index) => {
                        return Err(IoError::in_file(
                            file,
                            format!(
                                "{} property '{}' is a list of {} with {} counts; indices and counts must be integers",
                                element.name,
                                property.name,
                                scalar_name(index),
                                scalar_name(count)
                            ),
                        ));
                    }
                    PropertyType::Scalar(_) => {
                        return Err(IoError::in_file(
                            file,
                            format!(
                                "{} property '{}' is a single number, expected a list",
                                element.name, property.name
                            ),
                        ));
                    }
                }
            }
            Role::Skip => {}
        }
        roles.push(role);
    }
    if !vertices {
        return Err(IoError::in_file(
            file,
            "the header declares no 'vertex' element",
        ));
    }
    if !faces {
        return Err(IoError::in_file(
            file,
            "the header declares no 'face' or 'tristrips' element (point clouds cannot be remeshed)",
        ));
    }
    Ok(roles)
}

fn is_integer(t: &ScalarType) -> bool {
    !matches!(t, ScalarType::Float | ScalarType::Double)
}

fn scalar_name(t: &ScalarType) -> &'static str {
    match t {
        ScalarType::Char => "char",
        ScalarType::UChar => "uchar",
        ScalarType::Short => "short",
        ScalarType::UShort => "ushort",
        ScalarType::Int => "int",
        ScalarType::UInt => "uint",
        ScalarType::Float => "float",
        ScalarType::Double => "double",
    }
}

fn read_ascii(
    body: &[u8],
    first_line: usize,
    elements: &[(&ElementDef, Role)],
    out: &mut Body<'_>,
) -> Result<(), IoError> {
    let file = out.file;
    let mut lines = lines(body, file).filter_map(|item| match item {
        Ok((n, line)) => (!line.trim().is_empty()).then_some(Ok((n + first_line - 1, line))),
        Err(e) => Some(Err(IoError::new(
            file,
            match e.location {
                Location::Line(n) => Location::Line(n + first_line - 1),
                other => other,
            },
            e.message,
        ))),
    });
    let mut record = Record::default();
    for &(element, role) in elements {
        if element.properties.is_empty() {
            continue;
        }
        for index in 0..element.count {
            let (n, line) = lines.next().ok_or_else(|| {
                IoError::in_file(
                    file,
                    format!(
                        "the file ends before {} {index} of the {} declared",
                        element.name, element.count
                    ),
                )
            })??;
            let at = |message: String| {
                IoError::at_line(file, n, format!("{} {index}: {message}", role.kind()))
            };
            parse_ascii_element(line, element, &mut record).map_err(at)?;
            out.take(role, &record, &at)?;
        }
    }
    Ok(())
}

/// Reads one element line into `record` (coordinates and index list only).
fn parse_ascii_element(
    line: &str,
    element: &ElementDef,
    record: &mut Record,
) -> Result<(), String> {
    let mut tokens = line.split_ascii_whitespace();
    for property in element.properties.values() {
        let name = property.name.as_str();
        let missing = || format!("the line ends before property '{name}'");
        match &property.data_type {
            PropertyType::Scalar(_) => {
                let token = tokens.next().ok_or_else(missing)?;
                let value: f64 = token
                    .parse()
                    .map_err(|_| format!("'{token}' is not a number (property '{name}')"))?;
                if ["x", "y", "z"].contains(&name) && !value.is_finite() {
                    return Err(format!("coordinate '{token}' is not finite"));
                }
                record.set_scalar(name, value);
            }
            PropertyType::List(_, item) => {
                let token = tokens.next().ok_or_else(missing)?;
                let count: usize = token.parse().map_err(|_| {
                    format!("list size '{token}' is not a non-negative integer (property '{name}')")
                })?;
                let wanted = INDEX_LISTS.contains(&name) && is_integer(item);
                if wanted {
                    record.list.clear();
                }
                for _ in 0..count {
                    let token = tokens.next().ok_or_else(missing)?;
                    if wanted {
                        let value: i64 = token
                            .parse()
                            .map_err(|_| format!("'{token}' is not a vertex index"))?;
                        record.list.push(value);
                    } else if token.parse::<f64>().is_err() {
                        return Err(format!("'{token}' is not a number (property '{name}')"));
                    }
                }
            }
        }
    }
    if let Some(extra) = tokens.next() {
        return Err(format!(
            "unexpected value '{}' after the declared properties",
            extra.chars().take(40).collect::<String>()
        ));
    }
    Ok(())
}

fn read_binary(
    parser: &Parser<Record>,
    body: &[u8],
    body_start: usize,
    big_endian: bool,
    elements: &[(&ElementDef, Role)],
    out: &mut Body<'_>,
) -> Result<(), IoError> {
    let file = out.file;
    let mut rest = body;
    for &(element, role) in elements {
        // Zero-property elements occupy no bytes: nothing to loop over.
        if element.properties.is_empty() {
            continue;
        }
        for index in 0..element.count {
            let offset = (body_start + body.len() - rest.len()) as u64;
            let parsed = if big_endian {
                parser.read_big_endian_element(&mut rest, element)
            } else {
                parser.read_little_endian_element(&mut rest, element)
            };
            let record = parsed.map_err(|e| {
                let message = if e.kind() == std::io::ErrorKind::UnexpectedEof {
                    format!(
                        "the file ends inside {} {index} of the {} declared",
                        element.name, element.count
                    )
                } else {
                    format!(
                        "{} {index}: {}",
                        element.name,
                        e.to_string().lines().next().unwrap_or("")
                    )
                };
                IoError::new(file, Location::Byte(offset), message)
            })?;
            let kind = role.kind();
            let at = |message: String| {
                IoError::at_element(file, kind, index, format!("{message} (at byte {offset})"))
            };
            out.take(role, &record, &at)?;
        }
    }
    Ok(())
}

/// Shortest decimal that reads back as the same `f64`, in exponent form for
/// very large or small magnitudes (plain `{}` would spell out 300 zeros).
fn push_number(out: &mut String, v: f64) {
    let a = v.abs();
    if a == 0.0 || (1e-5..1e15).contains(&a) {
        let _ = write!(out, "{v}");
    } else {
        let _ = write!(out, "{v:e}");
    }
}

/// A PLY file of `positions` (as doubles, so round trips are exact) and
/// `faces` kept as polygons.
pub fn write(positions: &[glam::DVec3], faces: &FaceList, encoding: PlyEncoding) -> Vec<u8> {
    let max_degree = faces.iter().map(<[u32]>::len).max().unwrap_or(0);
    let (count_type, count_bytes) = if max_degree <= u8::MAX as usize {
        ("uchar", 1)
    } else {
        ("int", 4)
    };
    let index_type = if positions.len() <= i32::MAX as usize {
        "int"
    } else {
        "uint"
    };
    let format = match encoding {
        PlyEncoding::Ascii => "ascii",
        PlyEncoding::BinaryLittleEndian => "binary_little_endian",
        PlyEncoding::BinaryBigEndian => "binary_big_endian",
    };
    let mut header = String::new();
    let _ = write!(
        header,
        "ply\nformat {format} 1.0\ncomment written by quadrille\n\
         element vertex {}\nproperty double x\nproperty double y\nproperty double z\n\
         element face {}\nproperty list {count_type} {index_type} vertex_indices\nend_header\n",
        positions.len(),
        faces.len()
    );
    match encoding {
        PlyEncoding::Ascii => {
            let mut out = header;
            out.reserve(positions.len() * 48 + faces.indices.len() * 8);
            for p in positions {
                push_number(&mut out, p.x);
                out.push(' ');
                push_number(&mut out, p.y);
                out.push(' ');
                push_number(&mut out, p.z);
                out.push('\n');
            }
            for face in faces.iter() {
                let _ = write!(out, "{}", face.len());
                for &i in face {
                    let _ = write!(out, " {i}");
                }
                out.push('\n');
            }
            out.into_bytes()
        }
        PlyEncoding::BinaryLittleEndian | PlyEncoding::BinaryBigEndian => {
            let big = encoding == PlyEncoding::BinaryBigEndian;
            let mut out = header.into_bytes();
            out.reserve(positions.len() * 24 + faces.len() * count_bytes + faces.indices.len() * 4);
            for p in positions {
                for c in p.to_array() {
                    out.extend_from_slice(&if big {
                        c.to_be_bytes()
                    } else {
                        c.to_le_bytes()
                    });
                }
            }
            for face in faces.iter() {
                if count_bytes == 1 {
                    out.push(face.len() as u8);
                } else {
                    let n = face.len() as u32;
                    out.extend_from_slice(&if big {
                        n.to_be_bytes()
                    } else {
                        n.to_le_bytes()
                    });
                }
                for &i in face {
                    out.extend_from_slice(&if big {
                        i.to_be_bytes()
                    } else {
                        i.to_le_bytes()
                    });
                }
            }
            out
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const QUAD_ASCII: &[u8] = b"ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\n\
property float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\n\
end_header\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n";

    #[test]
    fn reads_ascii_quad() {
        let m = read(QUAD_ASCII, "q.ply").unwrap();
        assert_eq!(m.positions.len(), 4);
        assert_eq!(m.positions[2], DVec3::new(1.0, 1.0, 0.0));
        assert_eq!(m.faces.face(0), &[0, 1, 2, 3]);
    }

    #[test]
    fn ascii_errors_name_the_line() {
        let text = String::from_utf8_lossy(QUAD_ASCII).replace("1 1 0\n", "1 nan 0\n");
        let e = read(text.as_bytes(), "q.ply").unwrap_err();
        assert_eq!(e.location, Location::Line(12), "{e}");
        assert!(e.message.contains("vertex 2"), "{e}");
        let text = String::from_utf8_lossy(QUAD_ASCII).replace("4 0 1 2 3", "4 0 1 2 4");
        let e = read(text.as_bytes(), "q.ply").unwrap_err();
        assert_eq!(e.location, Location::Line(14), "{e}");
    }

    #[test]
    fn strips_alternate_winding() {
        let text = b"ply\nformat ascii 1.0\nelement vertex 5\nproperty float x\nproperty float y\n\
property float z\nelement tristrips 1\nproperty list int int vertex_indices\nend_header\n\
0 0 0\n1 0 0\n0 1 0\n1 1 0\n2 1 0\n6 0 1 2 3 -1 4\n";
        let m = read(text, "s.ply").unwrap();
        // Run 0 1 2 3 gives (0 1 2) and (2 1 3); the single-vertex run gives nothing.
        let faces: Vec<&[u32]> = m.faces.iter().collect();
        assert_eq!(faces, vec![&[0, 1, 2][..], &[2, 1, 3][..]]);
    }

    #[test]
    fn writer_reads_back_in_every_encoding() {
        let p = vec![
            DVec3::new(0.1, -2.5e-300, 3e20),
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(0.0, 1.0, 1.0 / 3.0),
        ];
        let f = FaceList::from_triangles(&[[0, 1, 2]]);
        for enc in [
            PlyEncoding::Ascii,
            PlyEncoding::BinaryLittleEndian,
            PlyEncoding::BinaryBigEndian,
        ] {
            let m = read(&write(&p, &f, enc), "w.ply").unwrap();
            assert_eq!(m.positions, p, "{enc:?}");
            assert_eq!(m.faces, f, "{enc:?}");
        }
    }
}
