//! glTF 2.0: binary `.glb`, and `.gltf` JSON with buffers embedded as
//! base64 `data:` URIs. The `gltf` crate parses and validates the document
//! (and splits GLB chunks); everything that reads bytes is ours.
//!
//! What is read: the POSITION attribute and the indices of every primitive of
//! every mesh instanced by the scene's node hierarchy, with node transforms
//! applied (the default scene, or every scene if none is marked; with no
//! scenes at all, every mesh once, untransformed). Modes `TRIANGLES`,
//! `TRIANGLE_STRIP` and `TRIANGLE_FAN` become triangles; points and lines
//! are skipped with a warning. Primitives without indices use `0..n`.
//!
//! Deviations and choices:
//! - Accessors are decoded here rather than with the crate's readers, which
//!   panic (or, in debug builds, overflow) on inconsistent offsets, strides
//!   and counts. Every range is checked and reported naming the mesh and
//!   primitive. Positions may be `FLOAT` or, per `KHR_mesh_quantization`,
//!   (normalised) 8- or 16-bit integers; sparse accessors are applied on top
//!   of their buffer view (sparse accessors without one are refused).
//! - Within one node instance, primitives that share a POSITION accessor
//!   share vertices (exporters split one mesh into primitives per material
//!   over one vertex array), so the surface stays connected there.
//! - A transform with negative determinant flips triangle winding, as the
//!   glTF specification says it does.
//! - External buffers (`"uri": "mesh.bin"`) cannot be loaded from the bytes
//!   of one dropped file: that is an error only if a mesh we read uses it.
//! - Nodes must form trees (each scene visits a node at most once), which
//!   also stops cycles; the total instanced geometry is capped at
//!   [`MAX_VERTICES`] and the node visits at 2²⁴, so a small file cannot
//!   instance a mesh millions of times or list one hierarchy in many scenes.
//! - GLB headers are checked before the `gltf` crate sees them (its length
//!   arithmetic underflows on a header shorter than 12 bytes).

use std::collections::HashMap;

use glam::{DMat4, DQuat, DVec3};
use gltf::accessor::{DataType, Dimensions};
use gltf::buffer::Source;
use gltf::mesh::Mode;

use super::{IoError, RawMesh};
use crate::mesh::FaceList;

/// Most vertices the instanced scene may produce.
pub const MAX_VERTICES: usize = 1 << 27;

/// Most node visits (nodes × scenes) one file may ask for.
const MAX_NODE_VISITS: usize = 1 << 24;

pub fn read(bytes: &[u8], file: &str) -> Result<RawMesh, IoError> {
    let glb = bytes.starts_with(b"glTF");
    if glb {
        check_glb_header(bytes, file)?;
    } else if file.to_ascii_lowercase().ends_with(".glb") {
        return Err(IoError::in_file(
            file,
            "not a binary glTF file (a .glb must start with the bytes 'glTF')",
        ));
    }
    let gltf =
        gltf::Gltf::from_slice_without_validation(bytes).map_err(|e| document_error(file, e))?;
    let mut warnings = validate(&gltf.document, file)?;
    let buffers = Buffers::decode(&gltf.document, gltf.blob.as_deref());

    let mut out = Collector {
        file,
        buffers: &buffers,
        positions: Vec::new(),
        faces: FaceList::new(),
        skipped_primitives: 0,
    };
    let doc = &gltf.document;
    if doc.scenes().len() == 0 {
        for mesh in doc.meshes() {
            out.instance(&mesh, &DMat4::IDENTITY)?;
        }
    } else {
        let scenes: Vec<gltf::Scene> = match doc.default_scene() {
            Some(s) => vec![s],
            None => doc.scenes().collect(),
        };
        if scenes.len() > 1 {
            warnings.push(format!(
                "the file marks no default scene: all {} scenes were loaded together",
                scenes.len()
            ));
        }
        // Several scenes may each list a large hierarchy: bound the work.
        let mut budget = MAX_NODE_VISITS;
        for scene in scenes {
            budget = budget.checked_sub(doc.nodes().len()).ok_or_else(|| {
                IoError::in_file(
                    file,
                    format!("the scenes visit more than {MAX_NODE_VISITS} nodes in total"),
                )
            })?;
            let mut visited = vec![false; doc.nodes().len()];
            let mut stack: Vec<(gltf::Node, DMat4)> =
                scene.nodes().map(|n| (n, DMat4::IDENTITY)).collect();
            while let Some((node, parent)) = stack.pop() {
                let seen = visited.get_mut(node.index()).ok_or_else(|| {
                    IoError::at_element(file, "node", node.index(), "does not exist")
                })?;
                if *seen {
                    return Err(IoError::at_element(
                        file,
                        "node",
                        node.index(),
                        format!(
                            "reached twice from scene {} (glTF nodes must form trees, without cycles)",
                            scene.index()
                        ),
                    ));
                }
                *seen = true;
                let world = parent * local_transform(&node, file)?;
                if let Some(mesh) = node.mesh() {
                    out.instance(&mesh, &world)?;
                }
                stack.extend(node.children().map(|c| (c, world)));
            }
        }
    }
    if out.skipped_primitives > 0 {
        warnings.push(format!(
            "skipped {} primitives drawn as points or lines",
            out.skipped_primitives
        ));
    }
    Ok(RawMesh {
        positions: out.positions,
        faces: out.faces,
        welded_vertices: 0,
        warnings,
        creases: Vec::new(),
    })
}

fn check_glb_header(bytes: &[u8], file: &str) -> Result<(), IoError> {
    let word = |at: usize| {
        bytes
            .get(at..at + 4)
            .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    };
    let (Some(version), Some(length)) = (word(4), word(8)) else {
        return Err(IoError::in_file(
            file,
            "binary glTF header is truncated (needs 12 bytes)",
        ));
    };
    if version != 2 {
        return Err(IoError::in_file(
            file,
            format!("binary glTF version {version} is not supported (only 2)"),
        ));
    }
    if (length as usize) < 20 || length as usize > bytes.len() {
        return Err(IoError::in_file(
            file,
            format!(
                "binary glTF header declares {length} bytes but the file has {}",
                bytes.len()
            ),
        ));
    }
    Ok(())
}

/// Required extensions that change how geometry is stored; anything else a
/// file requires (materials, lights, texture transforms) does not affect
/// positions and indices.
const UNDECODABLE: [&str; 2] = ["KHR_draco_mesh_compression", "EXT_meshopt_compression"];

/// The `gltf` crate's validation, minus two checks that would refuse files we
/// read correctly: the POSITION accessor's `min`/`max` (required by the
/// specification, unused here, missing from some exporters' files) and
/// required extensions that do not touch geometry. Returns warnings for the
/// extensions ignored.
fn validate(doc: &gltf::Document, file: &str) -> Result<Vec<String>, IoError> {
    use gltf::json::validation::{Error, Validate};
    let root = doc.as_json();
    if let Some(ext) = root
        .extensions_required
        .iter()
        .find(|e| UNDECODABLE.contains(&e.as_str()))
    {
        return Err(IoError::in_file(
            file,
            format!("the file's geometry is compressed with {ext}, which Quadrille cannot decode"),
        ));
    }
    // gltf-json's validation indexes the POSITION accessor without a bounds
    // check (it panics on a bad index), so check those first.
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, primitive) in mesh.primitives.iter().enumerate() {
            let position = primitive
                .attributes
                .get(&gltf::json::validation::Checked::Valid(
                    gltf::Semantic::Positions,
                ));
            if let Some(index) = position
                && index.value() >= root.accessors.len()
            {
                return Err(IoError::at_element(
                    file,
                    "mesh",
                    m,
                    format!(
                        "primitive {p}: POSITION refers to accessor {}, but the file has {}",
                        index.value(),
                        root.accessors.len()
                    ),
                ));
            }
        }
    }
    let mut errors = Vec::new();
    root.validate(root, gltf::json::Path::new, &mut |path, error| {
        let path = path().to_string();
        let harmless = (error == Error::Missing
            && (path.ends_with(".min") || path.ends_with(".max")))
            || (error == Error::Unsupported && path.starts_with("extensionsRequired"));
        if !harmless {
            errors.push((path, error));
        }
    });
    if !errors.is_empty() {
        let mut m = String::from("invalid glTF:");
        for (path, error) in errors.iter().take(3) {
            m.push_str(&format!(" {path}: {error};"));
        }
        if errors.len() > 3 {
            m.push_str(&format!(" and {} more", errors.len() - 3));
        }
        return Err(IoError::in_file(file, m));
    }
    Ok(root
        .extensions_required
        .iter()
        .filter(|e| !gltf::json::extensions::ENABLED_EXTENSIONS.contains(&e.as_str()))
        .filter(|e| e.as_str() != "KHR_mesh_quantization")
        .map(|e| format!("ignored required extension {e} (it does not change geometry)"))
        .collect())
}

fn document_error(file: &str, e: gltf::Error) -> IoError {
    let message = match e {
        gltf::Error::Binary(b) => format!("invalid binary glTF: {b}"),
        gltf::Error::Deserialize(d) => format!("invalid glTF JSON: {d}"),
        other => format!("invalid glTF: {other}"),
    };
    IoError::in_file(file, message)
}

/// A node's own transform in `f64` (TRS composed here, not in `f32`).
fn local_transform(node: &gltf::Node, file: &str) -> Result<DMat4, IoError> {
    let m = match node.transform() {
        gltf::scene::Transform::Matrix { matrix } => {
            DMat4::from_cols_array_2d(&matrix.map(|c| c.map(f64::from)))
        }
        gltf::scene::Transform::Decomposed {
            translation,
            rotation,
            scale,
        } => {
            let r = DQuat::from_array(rotation.map(f64::from));
            if r.length().is_nan() || r.length() <= 1e-12 {
                return Err(IoError::at_element(
                    file,
                    "node",
                    node.index(),
                    "rotation quaternion has zero length",
                ));
            }
            DMat4::from_scale_rotation_translation(
                DVec3::from_array(scale.map(f64::from)),
                r.normalize(),
                DVec3::from_array(translation.map(f64::from)),
            )
        }
    };
    if !m.is_finite() {
        return Err(IoError::at_element(
            file,
            "node",
            node.index(),
            "transform is not finite",
        ));
    }
    Ok(m)
}

/// Each buffer's bytes, or why they are unavailable.
struct Buffers<'a> {
    data: Vec<Result<std::borrow::Cow<'a, [u8]>, String>>,
}

impl<'a> Buffers<'a> {
    fn decode(doc: &gltf::Document, blob: Option<&'a [u8]>) -> Buffers<'a> {
        let data = doc
            .buffers()
            .map(|buffer| match buffer.source() {
                Source::Bin => blob
                    .map(std::borrow::Cow::Borrowed)
                    .ok_or_else(|| "refers to the binary chunk, but the file has none".to_string()),
                Source::Uri(uri) => decode_data_uri(uri).map(std::borrow::Cow::Owned),
            })
            .collect();
        Buffers { data }
    }

    fn get(&self, index: usize) -> Result<&[u8], String> {
        match self.data.get(index) {
            Some(Ok(bytes)) => Ok(bytes),
            Some(Err(why)) => Err(format!("buffer {index} {why}")),
            None => Err(format!("buffer {index} does not exist")),
        }
    }
}

fn decode_data_uri(uri: &str) -> Result<Vec<u8>, String> {
    let Some(rest) = uri.strip_prefix("data:") else {
        let shown: String = uri.chars().take(60).collect();
        return Err(format!(
            "refers to the external file '{shown}', which cannot be loaded from a single \
             dropped file: use a .glb, or embed the buffer as a base64 data URI"
        ));
    };
    let Some((media, payload)) = rest.split_once(',') else {
        return Err("is a data URI without a ',' before its data".to_string());
    };
    if !media.ends_with(";base64") {
        return Err("is a data URI that is not base64-encoded".to_string());
    }
    decode_base64(payload).map_err(|e| format!("has a malformed base64 data URI: {e}"))
}

/// Standard or URL-safe base64, padding optional, ASCII whitespace ignored.
fn decode_base64(text: &str) -> Result<Vec<u8>, String> {
    let mut out = Vec::with_capacity(text.len() / 4 * 3 + 3);
    let (mut acc, mut bits) = (0u32, 0u32);
    let mut padded = false;
    for (i, c) in text.bytes().enumerate() {
        let value = match c {
            b'A'..=b'Z' => c - b'A',
            b'a'..=b'z' => c - b'a' + 26,
            b'0'..=b'9' => c - b'0' + 52,
            b'+' | b'-' => 62,
            b'/' | b'_' => 63,
            b'=' => {
                padded = true;
                continue;
            }
            b' ' | b'\t' | b'\r' | b'\n' => continue,
            _ => return Err(format!("character {i} is not base64")),
        };
        if padded {
            return Err(format!("data after '=' padding at character {i}"));
        }
        acc = (acc << 6) | u32::from(value);
        bits += 6;
        if bits >= 8 {
            bits -= 8;
            out.push((acc >> bits) as u8);
            acc &= (1 << bits) - 1;
        }
    }
    Ok(out)
}

/// Gathers instanced primitives into one raw mesh.
struct Collector<'a, 'b> {
    file: &'a str,
    buffers: &'a Buffers<'b>,
    positions: Vec<DVec3>,
    faces: FaceList,
    skipped_primitives: usize,
}

impl Collector<'_, '_> {
    fn instance(&mut self, mesh: &gltf::Mesh, transform: &DMat4) -> Result<(), IoError> {
        let flip = transform.determinant() < 0.0;
        // POSITION accessor → index of its first vertex in this instance.
        let mut placed: HashMap<usize, (u32, usize)> = HashMap::new();
        for primitive in mesh.primitives() {
            let at = |message: String| {
                IoError::at_element(
                    self.file,
                    "mesh",
                    mesh.index(),
                    format!("primitive {}: {message}", primitive.index()),
                )
            };
            let mode = primitive.mode();
            if !matches!(
                mode,
                Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan
            ) {
                self.skipped_primitives += 1;
                continue;
            }
            let accessor = primitive
                .get(&gltf::Semantic::Positions)
                .ok_or_else(|| at("has no POSITION attribute".to_string()))?;
            let (first, count) = match placed.get(&accessor.index()) {
                Some(&known) => known,
                None => {
                    let local = read_positions(&accessor, self.buffers)
                        .map_err(|e| at(format!("POSITION accessor {}: {e}", accessor.index())))?;
                    if self.positions.len() + local.len() > MAX_VERTICES {
                        return Err(at(format!(
                            "the scene instances more than {MAX_VERTICES} vertices"
                        )));
                    }
                    let first = self.positions.len() as u32;
                    for (k, p) in local.iter().enumerate() {
                        let world = transform.transform_point3(*p);
                        if !world.is_finite() {
                            return Err(at(format!(
                                "position {k} is not finite after the node transforms"
                            )));
                        }
                        self.positions.push(world);
                    }
                    placed.insert(accessor.index(), (first, local.len()));
                    (first, local.len())
                }
            };
            let indices: Vec<u32> = match primitive.indices() {
                Some(a) => read_indices(&a, self.buffers)
                    .map_err(|e| at(format!("indices accessor {}: {e}", a.index())))?,
                None => (0..count as u32).collect(),
            };
            if let Some((k, &bad)) = indices
                .iter()
                .enumerate()
                .find(|&(_, &i)| i as usize >= count)
            {
                return Err(at(format!(
                    "index {k} is vertex {bad}, but POSITION has only {count} vertices"
                )));
            }
            let n = indices.len();
            let mut triangles: Vec<[u32; 3]> = Vec::with_capacity(n);
            match mode {
                Mode::Triangles => {
                    if n % 3 != 0 {
                        return Err(at(format!(
                            "{n} indices do not make whole triangles (not a multiple of 3)"
                        )));
                    }
                    triangles.extend(indices.chunks_exact(3).map(|t| [t[0], t[1], t[2]]));
                }
                Mode::TriangleStrip => {
                    for k in 0..n.saturating_sub(2) {
                        let (a, b, c) = (indices[k], indices[k + 1], indices[k + 2]);
                        triangles.push(if k % 2 == 0 { [a, b, c] } else { [a, c, b] });
                    }
                }
                _ => {
                    for k in 1..n.saturating_sub(1) {
                        triangles.push([indices[0], indices[k], indices[k + 1]]);
                    }
                }
            }
            if self.faces.indices.len() + 3 * triangles.len() >= 3 * MAX_VERTICES {
                return Err(at(format!(
                    "the scene instances more than {MAX_VERTICES} triangles"
                )));
            }
            for t in triangles {
                let [a, b, c] = t.map(|i| first + i);
                self.faces.push(&if flip { [a, c, b] } else { [a, b, c] });
            }
        }
        Ok(())
    }
}

/// Where an accessor's elements live: `count` elements of `size` bytes,
/// `stride` apart from the start of `bytes` (all checked to be in range).
struct Elements<'a> {
    bytes: &'a [u8],
    stride: usize,
    size: usize,
    count: usize,
}

impl<'a> Elements<'a> {
    fn get(&self, k: usize) -> Option<&'a [u8]> {
        let start = k.checked_mul(self.stride)?;
        self.bytes.get(start..start.checked_add(self.size)?)
    }
}

/// The bytes of `count` elements of `size` bytes starting `offset` bytes
/// into buffer view `view`, with an optional stride.
fn locate<'a>(
    view: &gltf::buffer::View,
    offset: usize,
    count: usize,
    size: usize,
    stride: Option<usize>,
    buffers: &'a Buffers,
) -> Result<Elements<'a>, String> {
    let buffer = buffers.get(view.buffer().index())?;
    let view_end = view.offset().checked_add(view.length());
    let view_bytes = view_end
        .and_then(|end| buffer.get(view.offset()..end))
        .ok_or_else(|| {
            format!(
                "buffer view {} covers bytes {}..{} of buffer {}, which has {} bytes",
                view.index(),
                view.offset(),
                view.offset() as u128 + view.length() as u128,
                view.buffer().index(),
                buffer.len()
            )
        })?;
    let stride = stride.unwrap_or(size);
    if stride < size {
        return Err(format!(
            "byte stride {stride} is smaller than the element size {size}"
        ));
    }
    let needed = if count == 0 {
        Some(offset)
    } else {
        (count - 1)
            .checked_mul(stride)
            .and_then(|s| s.checked_add(size))
            .and_then(|s| s.checked_add(offset))
    };
    match needed {
        Some(end) if end <= view_bytes.len() => Ok(Elements {
            bytes: &view_bytes[offset..end],
            stride,
            size,
            count,
        }),
        _ => Err(format!(
            "{count} elements of {size} bytes (stride {stride}) from byte {offset} run past \
             the end of buffer view {} ({} bytes)",
            view.index(),
            view_bytes.len()
        )),
    }
}

/// All components of an accessor as `f64`, `count × components` values,
/// with sparse substitutions applied.
fn read_components(
    accessor: &gltf::Accessor,
    dimensions: Dimensions,
    buffers: &Buffers,
) -> Result<Vec<f64>, String> {
    if accessor.dimensions() != dimensions {
        return Err(format!(
            "has type {:?}, expected {dimensions:?}",
            accessor.dimensions()
        ));
    }
    let ty = accessor.data_type();
    let normalized = accessor.normalized();
    let components = dimensions.multiplicity();
    let size = ty.size() * components;
    let view = accessor.view().ok_or_else(|| {
        "has no buffer view (sparse-only accessors are not supported)".to_string()
    })?;
    let elements = locate(
        &view,
        accessor.offset(),
        accessor.count(),
        size,
        view.stride(),
        buffers,
    )?;
    let decode = |bytes: &[u8], out: &mut Vec<f64>| {
        for c in 0..components {
            let at = c * ty.size();
            let b = bytes.get(at..at + ty.size()).unwrap_or(&[]);
            out.push(component(ty, normalized, b));
        }
    };
    let mut values = Vec::with_capacity(elements.count * components);
    for k in 0..elements.count {
        let bytes = elements
            .get(k)
            .ok_or_else(|| format!("element {k} is out of range"))?;
        decode(bytes, &mut values);
    }
    if let Some(sparse) = accessor.sparse() {
        let n = sparse.count();
        let indices = sparse.indices();
        let index_size = match indices.index_type() {
            gltf::accessor::sparse::IndexType::U8 => 1,
            gltf::accessor::sparse::IndexType::U16 => 2,
            gltf::accessor::sparse::IndexType::U32 => 4,
        };
        let where_ = locate(
            &indices.view(),
            indices.offset(),
            n,
            index_size,
            None,
            buffers,
        )
        .map_err(|e| format!("sparse indices: {e}"))?;
        let what = locate(
            &sparse.values().view(),
            sparse.values().offset(),
            n,
            size,
            None,
            buffers,
        )
        .map_err(|e| format!("sparse values: {e}"))?;
        let mut replacement = Vec::with_capacity(components);
        for s in 0..n {
            let (Some(ib), Some(vb)) = (where_.get(s), what.get(s)) else {
                return Err(format!("sparse element {s} is out of range"));
            };
            let target = le_uint(ib) as usize;
            replacement.clear();
            decode(vb, &mut replacement);
            let slot = target
                .checked_mul(components)
                .and_then(|start| values.get_mut(start..start.checked_add(components)?))
                .ok_or_else(|| {
                    format!(
                        "sparse index {target} is out of range ({} elements)",
                        elements.count
                    )
                })?;
            slot.copy_from_slice(&replacement);
        }
    }
    Ok(values)
}

/// Little-endian unsigned integer of 1, 2 or 4 bytes.
fn le_uint(b: &[u8]) -> u32 {
    match *b {
        [a] => a.into(),
        [a, b] => u16::from_le_bytes([a, b]).into(),
        [a, b, c, d] => u32::from_le_bytes([a, b, c, d]),
        _ => 0,
    }
}

/// One component as `f64`, normalised integers mapped as glTF specifies.
fn component(ty: DataType, normalized: bool, b: &[u8]) -> f64 {
    let raw = match (ty, b) {
        (DataType::I8, &[a]) => f64::from(a as i8),
        (DataType::U8, &[a]) => f64::from(a),
        (DataType::I16, &[a, c]) => f64::from(i16::from_le_bytes([a, c])),
        (DataType::U16, &[a, c]) => f64::from(u16::from_le_bytes([a, c])),
        (DataType::U32, &[a, c, d, e]) => f64::from(u32::from_le_bytes([a, c, d, e])),
        (DataType::F32, &[a, c, d, e]) => f64::from(f32::from_le_bytes([a, c, d, e])),
        _ => f64::NAN,
    };
    if !normalized {
        return raw;
    }
    match ty {
        DataType::I8 => (raw / 127.0).max(-1.0),
        DataType::U8 => raw / 255.0,
        DataType::I16 => (raw / 32767.0).max(-1.0),
        DataType::U16 => raw / 65535.0,
        DataType::U32 => raw / 4294967295.0,
        DataType::F32 => raw,
    }
}

fn read_positions(accessor: &gltf::Accessor, buffers: &Buffers) -> Result<Vec<DVec3>, String> {
    if accessor.data_type() == DataType::U32 {
        return Err("POSITION cannot have unsigned int components".to_string());
    }
    let values = read_components(accessor, Dimensions::Vec3, buffers)?;
    let mut out = Vec::with_capacity(values.len() / 3);
    for (k, p) in values.chunks_exact(3).enumerate() {
        let p = DVec3::new(p[0], p[1], p[2]);
        if !p.is_finite() {
            return Err(format!("position {k} is not finite"));
        }
        out.push(p);
    }
    Ok(out)
}

fn read_indices(accessor: &gltf::Accessor, buffers: &Buffers) -> Result<Vec<u32>, String> {
    if !matches!(
        accessor.data_type(),
        DataType::U8 | DataType::U16 | DataType::U32
    ) || accessor.normalized()
    {
        return Err(format!(
            "indices must be unsigned integers, not {:?}",
            accessor.data_type()
        ));
    }
    let values = read_components(accessor, Dimensions::Scalar, buffers)?;
    Ok(values.into_iter().map(|v| v as u32).collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_decodes_with_and_without_padding() {
        assert_eq!(decode_base64("TWFu").unwrap(), b"Man");
        assert_eq!(decode_base64("TWE=").unwrap(), b"Ma");
        assert_eq!(decode_base64("TQ==").unwrap(), b"M");
        assert_eq!(decode_base64("TQ").unwrap(), b"M");
        assert!(decode_base64("TQ=x").is_err());
        assert!(decode_base64("T!").is_err());
    }

    #[test]
    fn external_buffers_are_named() {
        let e = decode_data_uri("mesh.bin").unwrap_err();
        assert!(e.contains("'mesh.bin'") && e.contains("data URI"), "{e}");
    }
}
