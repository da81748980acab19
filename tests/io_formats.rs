//! Readers and writers of every format, through the public API only.
//!
//! Expected values are computed independently of the code under test: the
//! polygon mesh, its faces and its degree histogram are written down by hand;
//! STL and glTF files are assembled byte by byte here; strip triangles and
//! node transforms are worked out by hand in the comments.

mod common;

use glam::DVec3;
use quadrille::io::{
    Format, Imported, PlyEncoding, RawMesh, Repairs, import, read_raw, write_by_extension,
    write_obj, write_off, write_ply,
};
use quadrille::mesh::FaceList;
use serde_json::{Value, json};

// ---------------------------------------------------------------------------
// A closed polygon mesh: a pentagonal prism with a pyramid on top.
// ---------------------------------------------------------------------------

/// 5 bottom, 5 top, 1 apex; irrational coordinates so exactness is tested.
fn prism_positions() -> Vec<DVec3> {
    let mut p = Vec::new();
    for z in [0.0, 1.3] {
        for k in 0..5 {
            let a = std::f64::consts::TAU * k as f64 / 5.0;
            p.push(DVec3::new(a.cos(), a.sin(), z));
        }
    }
    p.push(DVec3::new(1.0 / 3.0, -0.1, 2.1));
    p
}

/// Bottom pentagon (seen from below), five side quads, five cap triangles,
/// all counter-clockwise from outside.
fn prism_faces() -> FaceList {
    let mut f = FaceList::new();
    f.push(&[4, 3, 2, 1, 0]);
    for k in 0..5u32 {
        let n = (k + 1) % 5;
        f.push(&[k, n, 5 + n, 5 + k]);
    }
    for k in 0..5u32 {
        f.push(&[5 + k, 5 + (k + 1) % 5, 10]);
    }
    f
}

fn prism_obj() -> String {
    let mut s = String::from("# pentagonal prism with a pyramid cap\n");
    for p in prism_positions() {
        s.push_str(&format!("v {:?} {:?} {:?}\n", p.x, p.y, p.z));
    }
    for face in prism_faces().iter() {
        let corners: Vec<String> = face.iter().map(|i| (i + 1).to_string()).collect();
        s.push_str(&format!("f {}\n", corners.join(" ")));
    }
    s
}

fn raw(bytes: &[u8], name: &str) -> RawMesh {
    read_raw(bytes, name).unwrap_or_else(|e| panic!("{e}")).1
}

fn imported(bytes: &[u8], name: &str) -> Imported {
    import(bytes, name).unwrap_or_else(|e| panic!("{e}"))
}

fn check_prism_import(m: &Imported, name: &str) {
    let r = &m.report;
    assert_eq!(m.polygons, prism_faces(), "{name}");
    assert_eq!((r.vertices, r.faces), (11, 11), "{name}");
    assert_eq!(r.face_degrees, vec![[3, 5], [4, 5], [5, 1]], "{name}");
    // 5 + 5·2 + 3 triangles from pentagon, quads, cap.
    assert_eq!(r.triangles, 18, "{name}");
    assert_eq!(r.boundary_edges, 0, "{name}");
    assert_eq!(r.genus, Some(0), "{name}");
    assert_eq!(
        r.repairs,
        Repairs {
            polygons_triangulated: 6,
            ..Repairs::default()
        },
        "{name}"
    );
}

#[test]
fn polygons_and_positions_survive_every_writer_exactly() {
    let obj = prism_obj();
    let first = raw(obj.as_bytes(), "prism.obj");
    assert_eq!(first.positions, prism_positions());
    assert_eq!(first.faces, prism_faces());
    check_prism_import(&imported(obj.as_bytes(), "prism.obj"), "prism.obj");

    let (p, f) = (&first.positions, &first.faces);
    let written: Vec<(&str, Vec<u8>)> = vec![
        ("rt.obj", write_obj(p, f).into_bytes()),
        ("rt.off", write_off(p, f).into_bytes()),
        ("rt-ascii.ply", write_ply(p, f, PlyEncoding::Ascii)),
        (
            "rt-le.ply",
            write_ply(p, f, PlyEncoding::BinaryLittleEndian),
        ),
        ("rt-be.ply", write_ply(p, f, PlyEncoding::BinaryBigEndian)),
    ];
    for (name, bytes) in &written {
        let back = raw(bytes, name);
        assert_eq!(&back.positions, p, "{name}");
        assert_eq!(&back.faces, f, "{name}");
        check_prism_import(&imported(bytes, name), name);
        // And once more: what we read back writes the same bytes.
        let again = match name.rsplit('.').next() {
            Some("obj") => write_obj(&back.positions, &back.faces).into_bytes(),
            Some("off") => write_off(&back.positions, &back.faces).into_bytes(),
            _ => {
                let enc = match *name {
                    "rt-ascii.ply" => PlyEncoding::Ascii,
                    "rt-le.ply" => PlyEncoding::BinaryLittleEndian,
                    _ => PlyEncoding::BinaryBigEndian,
                };
                write_ply(&back.positions, &back.faces, enc)
            }
        };
        assert_eq!(&again, bytes, "{name}");
    }
    // The binary bodies hold the same values in opposite byte order: the
    // first vertex's x, read both ways, agrees.
    let body = |b: &[u8]| {
        let end = b.windows(11).position(|w| w == b"end_header\n").unwrap() + 11;
        b[end..].to_vec()
    };
    let (le, be) = (body(&written[3].1), body(&written[4].1));
    assert_eq!(le.len(), 11 * 24 + 11 + 4 * (5 + 5 * 4 + 5 * 3));
    assert_eq!(le.len(), be.len());
    let x_le = f64::from_le_bytes(le[..8].try_into().unwrap());
    let x_be = f64::from_be_bytes(be[..8].try_into().unwrap());
    assert_eq!((x_le, x_be), (p[0].x, p[0].x));
}

#[test]
fn write_by_extension_picks_the_writer() {
    let (p, f) = (prism_positions(), prism_faces());
    assert_eq!(
        write_by_extension("a.OBJ", &p, &f).unwrap(),
        write_obj(&p, &f).into_bytes()
    );
    assert_eq!(
        write_by_extension("a.off", &p, &f).unwrap(),
        write_off(&p, &f).into_bytes()
    );
    assert_eq!(
        write_by_extension("a.ply", &p, &f).unwrap(),
        write_ply(&p, &f, PlyEncoding::BinaryLittleEndian)
    );
    let e = write_by_extension("a.stl", &p, &f).unwrap_err();
    assert!(e.to_string().starts_with("a.stl: "), "{e}");
}

#[test]
fn ply_header_declares_doubles_and_wide_counts_only_when_needed() {
    let header = |bytes: &[u8]| {
        let end = bytes.windows(10).position(|w| w == b"end_header").unwrap();
        String::from_utf8(bytes[..end].to_vec()).unwrap()
    };
    let h = header(&write_ply(
        &prism_positions(),
        &prism_faces(),
        PlyEncoding::BinaryBigEndian,
    ));
    assert!(h.contains("format binary_big_endian 1.0"), "{h}");
    assert!(
        h.contains("element vertex 11\nproperty double x\nproperty double y\nproperty double z\n"),
        "{h}"
    );
    assert!(
        h.contains("element face 11\nproperty list uchar int vertex_indices\n"),
        "{h}"
    );

    // A 300-gon needs more than a uchar count.
    let n = 300u32;
    let ring: Vec<DVec3> = (0..n)
        .map(|k| {
            let a = std::f64::consts::TAU * k as f64 / n as f64;
            DVec3::new(a.cos(), a.sin(), 0.0)
        })
        .collect();
    let mut disk = FaceList::new();
    disk.push(&(0..n).collect::<Vec<_>>());
    for enc in [
        PlyEncoding::Ascii,
        PlyEncoding::BinaryLittleEndian,
        PlyEncoding::BinaryBigEndian,
    ] {
        let bytes = write_ply(&ring, &disk, enc);
        assert!(header(&bytes).contains("property list int int vertex_indices"));
        let back = raw(&bytes, "disk.ply");
        assert_eq!(back.positions, ring, "{enc:?}");
        assert_eq!(back.faces, disk, "{enc:?}");
    }
}

// ---------------------------------------------------------------------------
// PLY variants written by other programs.
// ---------------------------------------------------------------------------

#[test]
fn ply_reads_any_scalar_and_list_types_and_skips_other_elements() {
    // Big-endian: a leading "material" element, vertices with int16 x,
    // double y, uint8 z and extra properties around them, faces with a
    // ushort count and uint indices named vertex_index, and a trailing
    // element that is never needed.
    let mut b = b"ply\nformat binary_big_endian 1.0\ncomment from elsewhere\n\
element material 1\nproperty uchar red\nproperty list uchar float weights\n\
element vertex 4\nproperty float nx\nproperty short x\nproperty double y\nproperty uchar z\n\
property list uchar int neighbours\n\
element face 2\nproperty uchar flags\nproperty list ushort uint vertex_index\n\
element edge 1\nproperty int vertex1\nproperty int vertex2\nend_header\n"
        .to_vec();
    b.push(200);
    b.push(2);
    b.extend(1.5f32.to_be_bytes());
    b.extend(2.5f32.to_be_bytes());
    for (x, y, z) in [
        (-3i16, 0.25f64, 0u8),
        (4, 0.25, 0),
        (4, 7.5, 9),
        (-3, 7.5, 9),
    ] {
        b.extend(0.5f32.to_be_bytes());
        b.extend(x.to_be_bytes());
        b.extend(y.to_be_bytes());
        b.push(z);
        b.push(1);
        b.extend(7i32.to_be_bytes());
    }
    b.push(0);
    b.extend(3u16.to_be_bytes());
    for i in [0u32, 1, 2] {
        b.extend(i.to_be_bytes());
    }
    b.push(1);
    b.extend(3u16.to_be_bytes());
    for i in [0u32, 2, 3] {
        b.extend(i.to_be_bytes());
    }
    // The edge element is cut short: it is after everything we need.
    b.extend([0, 0]);
    let m = raw(&b, "typed.ply");
    assert_eq!(
        m.positions,
        vec![
            DVec3::new(-3.0, 0.25, 0.0),
            DVec3::new(4.0, 0.25, 0.0),
            DVec3::new(4.0, 7.5, 9.0),
            DVec3::new(-3.0, 7.5, 9.0),
        ]
    );
    assert_eq!(m.faces, FaceList::from_triangles(&[[0, 1, 2], [0, 2, 3]]));
}

#[test]
fn ply_tristrips_restart_at_minus_one_and_alternate_winding() {
    // Strip A zigzags over a unit square: 0 (0,0) 1 (0,1) 2 (1,0) 3 (1,1).
    // Strip B turns with a repeated vertex: 4 5 6 6 7 8.
    let positions = [
        (0.0, 0.0),
        (0.0, 1.0),
        (1.0, 0.0),
        (1.0, 1.0),
        (3.0, 0.0),
        (3.0, 1.0),
        (4.0, 0.0),
        (4.0, 1.0),
        (5.0, 0.0),
    ];
    let strip: [i32; 11] = [0, 1, 2, 3, -1, 4, 5, 6, 6, 7, 8];
    // Triangle k of a run is (k, k+1, k+2), first two swapped when k is odd:
    // A: (0 1 2), (2 1 3). B: (4 5 6), (6 5 6), (6 6 7), (7 6 8).
    let expected = FaceList::from_triangles(&[
        [0, 1, 2],
        [2, 1, 3],
        [4, 5, 6],
        [6, 5, 6],
        [6, 6, 7],
        [7, 6, 8],
    ]);
    let header = |format: &str| {
        format!(
            "ply\nformat {format} 1.0\nelement vertex 9\nproperty float x\nproperty float y\n\
property float z\nelement tristrips 1\nproperty list int int vertex_indices\nend_header\n"
        )
    };
    let mut ascii = header("ascii");
    for (x, y) in positions {
        ascii.push_str(&format!("{x} {y} 0\n"));
    }
    ascii.push_str(&format!("{}", strip.len()));
    for i in strip {
        ascii.push_str(&format!(" {i}"));
    }
    ascii.push('\n');
    let mut binary = header("binary_little_endian").into_bytes();
    for (x, y) in positions {
        for c in [x as f32, y as f32, 0.0] {
            binary.extend(c.to_le_bytes());
        }
    }
    binary.extend((strip.len() as i32).to_le_bytes());
    for i in strip {
        binary.extend(i.to_le_bytes());
    }
    for (name, bytes) in [
        ("strips.ply", ascii.into_bytes()),
        ("strips-bin.ply", binary),
    ] {
        assert_eq!(raw(&bytes, name).faces, expected, "{name}");
        let m = imported(&bytes, name);
        assert_eq!(m.report.faces, 4, "{name}");
        assert_eq!(m.report.repairs.degenerate_faces_removed, 2, "{name}");
        // Alternating winding keeps strip A consistently oriented across
        // its shared edge 1-2.
        assert_eq!(m.report.inconsistent_edges, 0, "{name}");
        assert_eq!(m.report.format, Format::Ply);
    }
}

// ---------------------------------------------------------------------------
// STL: a tetrahedron, every corner stored three times.
// ---------------------------------------------------------------------------

const TETRA: [[[f32; 3]; 3]; 4] = [
    [[0.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]],
    [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]],
    [[0.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, 1.0, 0.0]],
    [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
];

fn binary_stl(header: &[u8], triangles: &[[[f32; 3]; 3]]) -> Vec<u8> {
    let mut b = header.to_vec();
    b.resize(80, b' ');
    b.extend((triangles.len() as u32).to_le_bytes());
    for t in triangles {
        for c in [0.0f32, 0.0, 0.0] {
            b.extend(c.to_le_bytes());
        }
        for corner in t {
            for c in corner {
                b.extend(c.to_le_bytes());
            }
        }
        b.extend([0, 0]);
    }
    b
}

fn ascii_stl(triangles: &[[[f32; 3]; 3]]) -> String {
    let mut s = String::from("solid tetra\r\n");
    for t in triangles {
        s.push_str("  facet normal 0 0 0\r\n    outer loop\r\n");
        for c in t {
            s.push_str(&format!("      vertex {:e} {} {}\r\n", c[0], c[1], c[2]));
        }
        s.push_str("    endloop\r\n  endfacet\r\n");
    }
    s.push_str("endsolid tetra\r\n");
    s
}

fn check_tetra(bytes: &[u8], name: &str) {
    let m = raw(bytes, name);
    // First appearances: (0,0,0), (0,1,0), (1,0,0), (0,0,1).
    assert_eq!(
        m.positions,
        vec![DVec3::ZERO, DVec3::Y, DVec3::X, DVec3::Z],
        "{name}"
    );
    assert_eq!(
        m.faces,
        FaceList::from_triangles(&[[0, 1, 2], [0, 2, 3], [0, 3, 1], [2, 1, 3]]),
        "{name}"
    );
    // 12 corners, 4 distinct.
    assert_eq!(m.welded_vertices, 8, "{name}");
    let r = imported(bytes, name).report;
    assert_eq!((r.vertices, r.faces), (4, 4), "{name}");
    assert_eq!(r.repairs.welded_vertices, 8, "{name}");
    assert_eq!(r.genus, Some(0), "{name}");
    assert_eq!(r.inconsistent_edges, 0, "{name}");
    assert_eq!(r.format, Format::Stl);
}

#[test]
fn stl_binary_and_ascii_weld_to_four_vertices() {
    check_tetra(&binary_stl(b"tetra", &TETRA), "tetra.stl");
    check_tetra(ascii_stl(&TETRA).as_bytes(), "tetra-ascii.stl");
    // Many exporters start binary headers with "solid": the size decides.
    let solid = binary_stl(b"solid tetra exported by a CAD tool", &TETRA);
    check_tetra(&solid, "solid-header.stl");
    // Without an extension the content is sniffed.
    check_tetra(&solid, "no-extension");
}

#[test]
fn stl_negative_zero_welds_and_trailing_bytes_warn() {
    let mut tris = TETRA;
    tris[1][0] = [-0.0, 0.0, -0.0];
    let mut bytes = binary_stl(b"", &tris);
    bytes.extend([0u8; 7]);
    let m = raw(&bytes, "padded.stl");
    assert_eq!(m.positions.len(), 4);
    assert_eq!(m.welded_vertices, 8);
    assert_eq!(m.warnings.len(), 1, "{:?}", m.warnings);
    assert!(m.warnings[0].contains("7 bytes"), "{:?}", m.warnings);
}

// ---------------------------------------------------------------------------
// glTF: documents assembled here.
// ---------------------------------------------------------------------------

fn base64(bytes: &[u8]) -> String {
    const ABC: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut s = String::new();
    for chunk in bytes.chunks(3) {
        let b = [
            chunk[0],
            chunk.get(1).copied().unwrap_or(0),
            chunk.get(2).copied().unwrap_or(0),
        ];
        let n = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
        for k in 0..4 {
            if k <= chunk.len() {
                s.push(ABC[(n >> (18 - 6 * k) & 63) as usize] as char);
            } else {
                s.push('=');
            }
        }
    }
    s
}

fn glb(doc: &Value, bin: &[u8]) -> Vec<u8> {
    let mut js = serde_json::to_vec(doc).unwrap();
    while js.len() % 4 != 0 {
        js.push(b' ');
    }
    let mut bin = bin.to_vec();
    while bin.len() % 4 != 0 {
        bin.push(0);
    }
    let total = 12 + 8 + js.len() + 8 + bin.len();
    let mut out = b"glTF".to_vec();
    out.extend(2u32.to_le_bytes());
    out.extend((total as u32).to_le_bytes());
    out.extend((js.len() as u32).to_le_bytes());
    out.extend(b"JSON");
    out.extend(js);
    out.extend((bin.len() as u32).to_le_bytes());
    out.extend(b"BIN\0");
    out.extend(bin);
    out
}

/// Bytes of f32 triples followed by u16 indices (padded to 4 bytes).
fn buffer(points: &[[f32; 3]], indices: &[u16]) -> Vec<u8> {
    let mut b = Vec::new();
    for p in points {
        for c in p {
            b.extend(c.to_le_bytes());
        }
    }
    for i in indices {
        b.extend(i.to_le_bytes());
    }
    while b.len() % 4 != 0 {
        b.push(0);
    }
    b
}

const SQUARE: [[f32; 3]; 4] = [
    [0.0, 0.0, 0.0],
    [1.0, 0.0, 0.0],
    [1.0, 1.0, 0.0],
    [0.0, 1.0, 0.0],
];

/// A buffer view + accessor pair for `count` positions at `offset`, and one
/// for `n` u16 indices after them.
fn square_accessors(index_count: usize) -> (Value, Value) {
    let views = json!([
        {"buffer": 0, "byteOffset": 0, "byteLength": 48},
        {"buffer": 0, "byteOffset": 48, "byteLength": 2 * index_count},
    ]);
    let accessors = json!([
        {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
         "min": [0, 0, 0], "max": [1, 1, 0]},
        {"bufferView": 1, "componentType": 5123, "count": index_count, "type": "SCALAR"},
    ]);
    (views, accessors)
}

fn positions_of(m: &RawMesh) -> Vec<[f64; 3]> {
    m.positions.iter().map(|p| p.to_array()).collect()
}

#[test]
fn glb_instances_meshes_through_the_node_hierarchy() {
    let indices = [0u16, 1, 2, 0, 2, 3];
    let bin = buffer(&SQUARE, &indices);
    let (views, accessors) = square_accessors(6);
    let doc = json!({
        "asset": {"version": "2.0"},
        "buffers": [{"byteLength": bin.len()}],
        "bufferViews": views,
        "accessors": accessors,
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
        "nodes": [
            {"mesh": 0, "translation": [10, 0, 0], "scale": [2, 2, 2], "children": [1]},
            {"mesh": 0, "translation": [0, 5, 0]},
            {"mesh": 0, "translation": [99, 99, 99]}
        ],
        "scenes": [{"nodes": [0]}, {"nodes": [2]}],
        "scene": 0
    });
    let m = raw(&glb(&doc, &bin), "scene.glb");
    // Node 0: 2p + (10,0,0). Node 1 under it: 2(p + (0,5,0)) + (10,0,0).
    // Node 2 belongs to scene 1, which is not the default: not loaded.
    let mut expected = Vec::new();
    for offset in [[0.0, 0.0], [0.0, 5.0]] {
        for p in SQUARE {
            expected.push([
                2.0 * (f64::from(p[0]) + offset[0]) + 10.0,
                2.0 * (f64::from(p[1]) + offset[1]),
                0.0,
            ]);
        }
    }
    assert_eq!(positions_of(&m), expected);
    assert_eq!(
        m.faces,
        FaceList::from_triangles(&[[0, 1, 2], [0, 2, 3], [4, 5, 6], [4, 6, 7]])
    );
    assert!(m.warnings.is_empty(), "{:?}", m.warnings);
    let r = imported(&glb(&doc, &bin), "scene.glb").report;
    assert_eq!((r.vertices, r.faces, r.components), (8, 4, 2));
    assert_eq!(r.format, Format::Gltf);
}

#[test]
fn gltf_data_uri_strips_fans_points_and_unindexed_primitives() {
    // Positions 0..5 on a zigzag; strip indices 0 1 2 3 4, fan 0 1 2 3.
    let points = [
        [0.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [2.0, 0.0, 0.0],
    ];
    let strip: [u16; 5] = [0, 1, 2, 3, 4];
    let fan: [u16; 4] = [0, 1, 2, 3];
    let mut bin = buffer(&points, &strip); // 60 + 10 (+2 padding) bytes
    bin.extend(buffer(&[], &fan)); // 8 bytes at 72
    let doc = json!({
        "asset": {"version": "2.0"},
        "buffers": [{"byteLength": bin.len(),
                     "uri": format!("data:application/octet-stream;base64,{}", base64(&bin))}],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": 60},
            {"buffer": 0, "byteOffset": 60, "byteLength": 10},
            {"buffer": 0, "byteOffset": 72, "byteLength": 8}
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 5, "type": "VEC3"},
            {"bufferView": 1, "componentType": 5123, "count": 5, "type": "SCALAR"},
            {"bufferView": 2, "componentType": 5123, "count": 4, "type": "SCALAR"},
            {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3"}
        ],
        "meshes": [
            {"primitives": [
                {"attributes": {"POSITION": 0}, "indices": 1, "mode": 5},
                {"attributes": {"POSITION": 0}, "indices": 2, "mode": 6},
                {"attributes": {"POSITION": 0}, "mode": 0},
                {"attributes": {"POSITION": 0}, "indices": 1, "mode": 1}
            ]},
            {"primitives": [{"attributes": {"POSITION": 3}}]}
        ]
    });
    let text = serde_json::to_vec_pretty(&doc).unwrap();
    let m = raw(&text, "modes.gltf");
    // No scenes: each mesh once, untransformed. Mesh 0's primitives share
    // accessor 0 (vertices 0-4); mesh 1 appends its 3 vertices (5-7).
    assert_eq!(m.positions.len(), 8);
    assert_eq!(&m.positions[5..], &m.positions[..3]);
    // Strip: (0 1 2), odd (1 3 2), (2 3 4). Fan: (0 1 2), (0 2 3).
    // Unindexed triangles: 0 1 2 of mesh 1, i.e. 5 6 7.
    assert_eq!(
        m.faces,
        FaceList::from_triangles(&[
            [0, 1, 2],
            [1, 3, 2],
            [2, 3, 4],
            [0, 1, 2],
            [0, 2, 3],
            [5, 6, 7]
        ])
    );
    assert_eq!(
        m.warnings,
        vec!["skipped 2 primitives drawn as points or lines"]
    );
    // The reader's warnings reach the import report.
    let r = imported(&text, "modes.gltf").report;
    assert!(r.warnings.iter().any(|w| w.contains("points or lines")));
}

#[test]
fn gltf_matrix_rotation_mirror_sparse_and_quantized_positions() {
    let bin = buffer(&SQUARE, &[0, 1, 2]);
    let mut bin = bin; // 48 + 6 + 2 = 56 bytes
    // Sparse: replace vertex 1 by (3, 0, 0).
    bin.extend(1u16.to_le_bytes()); // indices at 56
    bin.extend([0, 0]);
    for c in [3.0f32, 0.0, 0.0] {
        bin.extend(c.to_le_bytes()); // values at 60
    }
    // Quantized: normalised u16 (65535, 0, 32768) at 72, stride 8.
    for c in [65535u16, 0, 32768, 0, 0, 65535, 0, 0, 0, 0, 0, 0] {
        bin.extend(c.to_le_bytes());
    }
    let uri = format!("data:application/gltf-buffer;base64,{}", base64(&bin));
    let half = std::f64::consts::FRAC_1_SQRT_2;
    let doc = json!({
        "asset": {"version": "2.0"},
        "extensionsRequired": ["KHR_mesh_quantization"],
        "extensionsUsed": ["KHR_mesh_quantization"],
        "buffers": [{"byteLength": bin.len(), "uri": uri}],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": 48},
            {"buffer": 0, "byteOffset": 48, "byteLength": 6},
            {"buffer": 0, "byteOffset": 56, "byteLength": 2},
            {"buffer": 0, "byteOffset": 60, "byteLength": 12},
            {"buffer": 0, "byteOffset": 72, "byteLength": 24, "byteStride": 8}
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3"},
            {"bufferView": 1, "componentType": 5123, "count": 3, "type": "SCALAR"},
            {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
             "sparse": {"count": 1,
                        "indices": {"bufferView": 2, "componentType": 5123},
                        "values": {"bufferView": 3}}},
            {"bufferView": 4, "componentType": 5123, "normalized": true, "count": 3, "type": "VEC3"}
        ],
        "meshes": [
            {"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]},
            {"primitives": [{"attributes": {"POSITION": 2}, "indices": 1}]},
            {"primitives": [{"attributes": {"POSITION": 3}, "indices": 1}]}
        ],
        "nodes": [
            // Column-major matrix: translate by (0, 0, 7).
            {"mesh": 0, "matrix": [1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,7,1]},
            // 90° about z: (x, y) → (−y, x).
            {"mesh": 0, "rotation": [0, 0, half, half]},
            // Mirror in x: winding flips.
            {"mesh": 0, "scale": [-1, 1, 1]},
            {"mesh": 1},
            {"mesh": 2}
        ],
        "scenes": [{"nodes": [0, 1, 2, 3, 4]}]
    });
    let m = raw(&serde_json::to_vec(&doc).unwrap(), "transforms.gltf");
    assert!(m.warnings.is_empty(), "{:?}", m.warnings);
    // Nodes are visited depth-first from the scene's roots; compare as sets
    // of triangles, each a list of corner positions.
    let mut got: Vec<Vec<[i64; 3]>> = m
        .faces
        .iter()
        .map(|f| {
            f.iter()
                .map(|&i| {
                    (m.positions[i as usize] * 1e6)
                        .round()
                        .as_i64vec3()
                        .to_array()
                })
                .collect()
        })
        .collect();
    let s = |v: [f64; 3]| (DVec3::from_array(v) * 1e6).round().as_i64vec3().to_array();
    let mut expected = vec![
        vec![s([0., 0., 7.]), s([1., 0., 7.]), s([1., 1., 7.])],
        vec![s([0., 0., 0.]), s([0., 1., 0.]), s([-1., 1., 0.])],
        vec![s([0., 0., 0.]), s([-1., 1., 0.]), s([-1., 0., 0.])],
        vec![s([0., 0., 0.]), s([3., 0., 0.]), s([1., 1., 0.])],
        vec![
            s([1., 0., 32768. / 65535.]),
            s([0., 1., 0.]),
            s([0., 0., 0.]),
        ],
    ];
    got.sort();
    expected.sort();
    assert_eq!(got, expected);
}

// ---------------------------------------------------------------------------
// Normalisation at extreme scales and offsets.
// ---------------------------------------------------------------------------

#[test]
fn extreme_scales_and_offsets_normalise_and_restore() {
    let base = prism_positions();
    let reference = imported(prism_obj().as_bytes(), "prism.obj");
    for (scale, offset) in [
        (1e-8, DVec3::ZERO),
        (1e8, DVec3::ZERO),
        (1.0, DVec3::splat(1e8)),
        (1e8, DVec3::splat(1e8)),
        (1e-3, DVec3::new(-1e5, 2e5, 3e4)),
    ] {
        // (A 1e-8 mesh 1e8 from the origin is not representable: f64 spacing
        // there is 1.5e-8.) Local coordinates can be no more precise than the
        // world coordinates' spacing, relative to the model's size.
        let world: Vec<DVec3> = base.iter().map(|&p| p * scale + offset).collect();
        let magnitude = world
            .iter()
            .map(|p| p.abs().max_element())
            .fold(0.0, f64::max);
        let local_tol = 1e-12 + 8.0 * f64::EPSILON * magnitude / scale;
        for (name, bytes) in [
            (
                "scaled.ply",
                write_ply(&world, &prism_faces(), PlyEncoding::BinaryLittleEndian),
            ),
            ("scaled.obj", write_obj(&world, &prism_faces()).into_bytes()),
        ] {
            let what = format!("{name} ×{scale:e} +{offset}");
            let m = imported(&bytes, name);
            let bbox = m.mesh.bbox().unwrap();
            assert!(
                (bbox.largest_axis() - 1.0).abs() < local_tol,
                "{what}: {bbox:?}"
            );
            assert!(bbox.center().length() < local_tol, "{what}: {bbox:?}");
            // Local coordinates do not depend on scale or offset.
            for (a, b) in m.mesh.positions.iter().zip(&reference.mesh.positions) {
                assert!((*a - *b).length() < local_tol, "{what}: {a} vs {b}");
            }
            // Export restores world coordinates.
            let restored: Vec<DVec3> = m.frame.points_to_world(&m.mesh.positions);
            let out = write_by_extension("out.ply", &restored, &m.polygons).unwrap();
            let back = raw(&out, "out.ply");
            assert_eq!(back.faces, prism_faces(), "{what}");
            for (a, b) in back.positions.iter().zip(&world) {
                assert!(
                    (*a - *b).abs().max_element() <= 1e-9 * magnitude,
                    "{what}: {a} vs {b}"
                );
            }
        }
    }
}

// ---------------------------------------------------------------------------
// The repair report.
// ---------------------------------------------------------------------------

#[test]
fn repairs_are_counted() {
    let obj = "\
v 0 0 0
v 1 0 0
v 0 1 0
v 0 0 1
v 5 5 5
v 2 0 0
f 1 3 2
f 2 3 1
f 1 2 2
f 1 2 6
f 1 2 4 4
f 1 4 3
";
    // f 2 3 1 repeats f 1 3 2's corners (other orientation): duplicate.
    // f 1 2 2 has two distinct corners, f 1 2 6 is collinear: degenerate.
    // f 1 2 4 4 loses one repeated corner and stays.
    // v 5 is never used; v 6 only by the removed collinear face.
    let m = imported(obj.as_bytes(), "repairs.obj");
    assert_eq!(
        m.report.repairs,
        Repairs {
            degenerate_faces_removed: 2,
            duplicate_faces_removed: 1,
            repeated_corners_removed: 1,
            unreferenced_vertices_removed: 2,
            welded_vertices: 0,
            polygons_triangulated: 0,
        }
    );
    assert_eq!((m.report.vertices, m.report.faces), (4, 3));
    assert_eq!(
        m.polygons,
        FaceList::from_triangles(&[[0, 2, 1], [0, 1, 3], [0, 3, 2]])
    );
}

/// Copies of a vertex along an unwelded seam (patch-modelled meshes such
/// as the Utah teapot) are merged: two squares written as separate patches
/// that share an edge's coordinates become one strip of four triangles
/// with six vertices, one boundary loop and one component. The teapot: its
/// patches' 403 copies merge and its boundary edges fall from 1,036 to 160.
#[test]
fn vertices_copied_along_a_seam_are_welded() {
    let obj = "\
v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
v 1 0 0
v 2 0 0
v 2 1 0
v 1 1 0
f 1 2 3
f 1 3 4
f 5 6 7
f 5 7 8
";
    let m = imported(obj.as_bytes(), "seam.obj");
    assert_eq!(m.report.repairs.welded_vertices, 2);
    assert_eq!(m.report.repairs.unreferenced_vertices_removed, 0);
    assert_eq!(
        (
            m.report.vertices,
            m.report.boundary_edges,
            m.report.components
        ),
        (6, 6, 1)
    );
    assert!(m.report.warnings.is_empty(), "{:?}", m.report.warnings);
    let teapot = imported(&common::bytes("teapot.obj"), "teapot.obj");
    assert_eq!(teapot.report.repairs.welded_vertices, 403);
    assert_eq!(teapot.report.boundary_edges, 160);
    assert_eq!(teapot.report.nonmanifold_edges, 0);
}

/// Parts that only touch at a point stay apart: welding them would make a
/// bow-tie (non-manifold) vertex, so nothing is welded and a warning says
/// why.
#[test]
fn parts_touching_at_a_point_are_not_welded() {
    let obj = "\
v 0 0 0
v 1 0 0
v 0 1 0
v 0 0 0
v -1 0 0
v 0 -1 0
f 1 2 3
f 4 5 6
";
    let m = imported(obj.as_bytes(), "touching.obj");
    assert_eq!(m.report.repairs.welded_vertices, 0);
    assert_eq!((m.report.vertices, m.report.components), (6, 2));
    assert_eq!(m.report.nonmanifold_vertices, 0);
    assert!(
        m.report
            .warnings
            .iter()
            .any(|w| w.contains("left unwelded")),
        "{:?}",
        m.report.warnings
    );
}

// ---------------------------------------------------------------------------
// A real mesh through every format.
// ---------------------------------------------------------------------------

#[test]
fn a_shared_mesh_reads_the_same_in_every_format() {
    let bytes = common::bytes("spot.obj");
    let obj = imported(&bytes, "spot.obj");
    let world: Vec<DVec3> = obj.frame.points_to_world(&obj.mesh.positions);
    let tris = &obj.mesh.triangles;
    let f32s: Vec<[[f32; 3]; 3]> = tris
        .iter()
        .map(|t| t.map(|i| world[i as usize].as_vec3().to_array()))
        .collect();
    let mut bin = Vec::new();
    for p in &world {
        for c in p.as_vec3().to_array() {
            bin.extend(c.to_le_bytes());
        }
    }
    let positions_len = bin.len();
    for t in tris {
        for i in t {
            bin.extend(i.to_le_bytes());
        }
    }
    let doc = json!({
        "asset": {"version": "2.0"},
        "buffers": [{"byteLength": bin.len()}],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": positions_len},
            {"buffer": 0, "byteOffset": positions_len, "byteLength": bin.len() - positions_len}
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": world.len(), "type": "VEC3"},
            {"bufferView": 1, "componentType": 5125, "count": 3 * tris.len(), "type": "SCALAR"}
        ],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
        "nodes": [{"mesh": 0}],
        "scenes": [{"nodes": [0]}]
    });
    for (name, bytes) in [
        (
            "spot.ply",
            write_ply(&world, &obj.polygons, PlyEncoding::BinaryBigEndian),
        ),
        ("spot.off", write_off(&world, &obj.polygons).into_bytes()),
        ("spot.stl", binary_stl(b"spot", &f32s)),
        ("spot.glb", glb(&doc, &bin)),
    ] {
        let m = imported(&bytes, name);
        let (a, b) = (&m.report, &obj.report);
        assert_eq!(
            (
                a.vertices,
                a.faces,
                a.triangles,
                a.genus,
                a.boundary_edges,
                a.components
            ),
            (
                b.vertices,
                b.faces,
                b.triangles,
                b.genus,
                b.boundary_edges,
                b.components
            ),
            "{name}"
        );
        if name.ends_with("stl") {
            assert_eq!(a.repairs.welded_vertices, 3 * tris.len() - world.len());
        } else {
            assert_eq!(m.mesh.triangles, obj.mesh.triangles, "{name}");
        }
    }
}
