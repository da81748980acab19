//! Validation and repair shared by every reader, and the import report.

use std::collections::HashSet;

use glam::DVec3;
use serde::{Deserialize, Serialize};

use super::{Format, Imported, IoError, RawMesh};
use crate::mesh::{Aabb, FaceList, Frame, Topology, TriMesh, face_newell_normal};

/// What import changed. Nothing is changed silently: every count here is in
/// `quadrille info`'s output and the web app's import panel.
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Repairs {
    /// Faces with fewer than three distinct corners, or zero area.
    pub degenerate_faces_removed: usize,
    /// Faces with the same corner set as an earlier face (either orientation).
    pub duplicate_faces_removed: usize,
    /// Consecutive repeated corners dropped from faces that stayed valid.
    pub repeated_corners_removed: usize,
    /// Vertices no face uses.
    pub unreferenced_vertices_removed: usize,
    /// Vertices merged into an earlier vertex with identical coordinates:
    /// STL's corners, and in every format the copies along unwelded seams
    /// (patch-modelled meshes such as the Utah teapot), unless merging
    /// them would add non-manifold edges or vertices (parts touching at a
    /// point) or inconsistently oriented edges; then none is merged and a
    /// warning says so.
    pub welded_vertices: usize,
    /// Faces with more than three corners, split into triangles for the
    /// triangle mesh (the polygons themselves are kept for export).
    pub polygons_triangulated: usize,
}

/// What `quadrille info` prints: counts after repair, in file coordinates.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ImportReport {
    pub file: String,
    pub format: Format,
    pub vertices: usize,
    /// Faces as stored (polygons count once), after repair.
    pub faces: usize,
    /// Triangles of the triangulated surface the pipeline reads.
    pub triangles: usize,
    /// Number of faces per degree: `[degree, count]` pairs.
    pub face_degrees: Vec<[usize; 2]>,
    pub edges: usize,
    pub boundary_edges: usize,
    pub nonmanifold_edges: usize,
    pub nonmanifold_vertices: usize,
    /// Two-face edges whose faces disagree in orientation.
    pub inconsistent_edges: usize,
    pub components: usize,
    pub euler_characteristic: i64,
    /// Σ genus over components; `null` unless closed, manifold and oriented.
    pub genus: Option<i64>,
    pub bbox: Aabb,
    pub repairs: Repairs,
    pub warnings: Vec<String>,
}

/// Zero-area threshold in local coordinates (largest box axis 1): far below
/// any triangle a scanner or modeller produces on purpose.
const ZERO_AREA: f64 = 1e-14;

pub(super) fn import_raw(raw: RawMesh, file: &str, format: Format) -> Result<Imported, IoError> {
    let RawMesh {
        positions,
        faces,
        welded_vertices,
        mut warnings,
        creases,
    } = raw;
    if !creases.is_empty() {
        warnings.push(format!(
            "{} crease tags (t crease) read and not used: remeshing and fitting find sharp features from the surface itself",
            creases.len()
        ));
    }
    if let Some(v) = positions.iter().position(|p| !p.is_finite()) {
        return Err(IoError::at_element(
            file,
            "vertex",
            v,
            "coordinate is not finite",
        ));
    }
    let n = positions.len();
    for (f, face) in faces.iter().enumerate() {
        if let Some(&i) = face.iter().find(|&&i| i as usize >= n) {
            return Err(IoError::at_element(
                file,
                "face",
                f,
                format!("vertex index {i} is out of range (the file has {n} vertices)"),
            ));
        }
    }
    if faces.is_empty() {
        return Err(IoError::in_file(file, "the file contains no faces"));
    }
    let mut repairs = Repairs {
        welded_vertices,
        ..Repairs::default()
    };

    // Normalise first so the zero-area test is relative to the model's size.
    let frame = Frame::fit(&positions);
    let local: Vec<DVec3> = positions.iter().map(|&p| frame.to_local(p)).collect();

    let unwelded = clean_faces(&faces, &local);
    let welded_before = repairs.welded_vertices;
    let (mut kept, cleaning) = match weld_coincident(&positions, &faces) {
        None => unwelded,
        Some((welded_faces, welded)) => {
            let merged = clean_faces(&welded_faces, &local);
            let (before, after) = (Topology::of(n, &unwelded.0), Topology::of(n, &merged.0));
            if after.nonmanifold_edges <= before.nonmanifold_edges
                && after.nonmanifold_vertices <= before.nonmanifold_vertices
                && after.inconsistent_edges <= before.inconsistent_edges
                && !merged.0.is_empty()
            {
                repairs.welded_vertices += welded;
                merged
            } else {
                warnings.push(format!(
                    "{welded} vertices share their coordinates with an earlier vertex and were \
                     left unwelded: merging them would add non-manifold edges or vertices or \
                     inconsistently oriented edges"
                ));
                unwelded
            }
        }
    };
    repairs.degenerate_faces_removed = cleaning.degenerate_faces_removed;
    repairs.repeated_corners_removed = cleaning.repeated_corners_removed;
    repairs.duplicate_faces_removed = cleaning.duplicate_faces_removed;
    if kept.is_empty() {
        return Err(IoError::in_file(
            file,
            "every face is degenerate (no area or repeated corners)",
        ));
    }

    // Drop unreferenced vertices, keeping the file's order.
    let mut remap = vec![u32::MAX; n];
    let mut used = 0u32;
    for &i in &kept.indices {
        if remap[i as usize] == u32::MAX {
            remap[i as usize] = 0;
        }
    }
    let mut world_kept = Vec::new();
    for (v, slot) in remap.iter_mut().enumerate() {
        if *slot == 0 {
            *slot = used;
            used += 1;
            world_kept.push(positions[v]);
        }
    }
    // Copies welded here are no longer referenced; they count as welded only.
    repairs.unreferenced_vertices_removed =
        n - used as usize - (repairs.welded_vertices - welded_before);
    for i in &mut kept.indices {
        *i = remap[*i as usize];
    }
    // Refit: dropped vertices must not stretch the normalisation.
    let frame = Frame::fit(&world_kept);
    let local: Vec<DVec3> = world_kept.iter().map(|&p| frame.to_local(p)).collect();

    let triangles = kept.triangulate(&local);
    repairs.polygons_triangulated = kept.iter().filter(|f| f.len() > 3).count();
    let mesh = TriMesh {
        positions: local,
        triangles,
    };
    mesh.validate().map_err(|e| {
        IoError::in_file(
            file,
            format!("internal validation failed after repair: {e}"),
        )
    })?;

    let topology = Topology::of(mesh.vertex_count(), &kept);
    let bbox = Aabb::of(&world_kept).expect("at least one face, so at least three vertices");
    let face_degrees = kept
        .degree_histogram()
        .into_iter()
        .enumerate()
        .filter(|&(_, c)| c > 0)
        .map(|(d, c)| [d, c])
        .collect();
    let report = ImportReport {
        file: file.to_string(),
        format,
        vertices: mesh.vertex_count(),
        faces: kept.len(),
        triangles: mesh.face_count(),
        face_degrees,
        edges: topology.edges,
        boundary_edges: topology.boundary_edges,
        nonmanifold_edges: topology.nonmanifold_edges,
        nonmanifold_vertices: topology.nonmanifold_vertices,
        inconsistent_edges: topology.inconsistent_edges,
        components: topology.components,
        euler_characteristic: topology.euler_characteristic,
        genus: topology.genus(),
        bbox,
        repairs,
        warnings,
    };
    Ok(Imported {
        name: file.to_string(),
        format,
        frame,
        mesh,
        polygons: kept,
        report,
    })
}

/// The faces that survive cleaning: consecutive repeated corners dropped,
/// faces with fewer than three distinct corners or no area removed, and
/// faces with the corner set of an earlier face removed; with the counts
/// (only the three cleaning fields of [`Repairs`] are set).
fn clean_faces(faces: &FaceList, local: &[DVec3]) -> (FaceList, Repairs) {
    let mut repairs = Repairs::default();
    let mut kept = FaceList::new();
    let mut seen: HashSet<Vec<u32>> = HashSet::with_capacity(faces.len());
    let mut corners: Vec<u32> = Vec::new();
    for face in faces.iter() {
        corners.clear();
        for (k, &i) in face.iter().enumerate() {
            if face[(k + face.len() - 1) % face.len()] != i {
                corners.push(i);
            }
        }
        if corners.is_empty() {
            corners.push(face[0]);
        }
        let mut key = corners.clone();
        key.sort_unstable();
        key.dedup();
        if corners.len() < 3
            || key.len() != corners.len()
            || polygon_area(local, &corners) <= ZERO_AREA
        {
            repairs.degenerate_faces_removed += 1;
            continue;
        }
        repairs.repeated_corners_removed += face.len() - corners.len();
        if !seen.insert(key) {
            repairs.duplicate_faces_removed += 1;
            continue;
        }
        kept.push(&corners);
    }
    (kept, repairs)
}

/// `faces` with every vertex replaced by the first vertex of identical
/// coordinates, and how many vertices that merged; `None` when no two
/// vertices share their coordinates.
fn weld_coincident(positions: &[DVec3], faces: &FaceList) -> Option<(FaceList, usize)> {
    let mut first: std::collections::HashMap<[u64; 3], u32> =
        std::collections::HashMap::with_capacity(positions.len());
    let mut to = Vec::with_capacity(positions.len());
    for (v, p) in positions.iter().enumerate() {
        let key = [p.x, p.y, p.z].map(|x| if x == 0.0 { 0 } else { x.to_bits() });
        to.push(*first.entry(key).or_insert(v as u32));
    }
    let mut referenced = vec![false; positions.len()];
    for &i in &faces.indices {
        referenced[i as usize] = true;
    }
    let welded = (0..to.len())
        .filter(|&v| referenced[v] && to[v] as usize != v)
        .count();
    if welded == 0 {
        return None;
    }
    let mut out = faces.clone();
    for i in &mut out.indices {
        *i = to[*i as usize];
    }
    Some((out, welded))
}

/// Area of a planar-ish polygon by Newell's vector area.
fn polygon_area(positions: &[DVec3], corners: &[u32]) -> f64 {
    0.5 * face_newell_normal(positions, corners).length()
}
