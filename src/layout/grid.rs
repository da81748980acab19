//! The layout as a mesh (Campen & Kobbelt 2014, *Dual Strip Weaving*, §7
//! with §1's "semi-regular quad meshes … a regular refinement of a quad
//! layout"): the patches of the primal layout ([`super::primal`]) as
//! polygon faces, and each patch filled with a regular grid of quads on the
//! surface, giving a pure-quad mesh for the Catmull–Clark fit.
//!
//! Every layout edge crosses one loop arc, so it belongs to that loop's dual
//! strip; it is cut into the strip's count of segments (by arc length along
//! its route, the samples projected onto the surface). A patch is the
//! crossing of two strips and its opposite sides cross the same strip, so
//! opposite sides have equal counts and the patch's grid is regular; the
//! samples on a layout edge are shared by the patches on both sides, so the
//! mesh is watertight.
//!
//! The grid interior is a transfinite patch projected onto the input, the
//! paper's patches being "rather nonuniform" and often wrapped around the
//! object (on a torus one patch can be a half tube): a straight Coons blend
//! of the four sides in space collapses there. Instead each row is swept
//! from the previous one and projected onto the surface, either rigidly
//! moved with the frames (tangent, surface normal) of the two side curves,
//! or shifted with the side curves' moves in substeps (blended by u, the
//! projection sliding it along the surface, resampled by arc length so its
//! points follow the ends); the sweep runs from the bottom and from the top
//! side and the two are blended by v (so both are met exactly); a
//! projected point is reached by walking from the previous row's point in
//! small projected steps, so it stays on that sheet. Sweeps run along v and
//! along u, rigid and shifted; a fifth candidate halves the patch by
//! shortest surface paths (the middle column between its side midpoints,
//! then the row halves to the column's middle; recursively), which no
//! closest-point jump can fold. Of the five, the grid with the
//! fewest folded quads (normal against the surface's), then the lowest
//! Dirichlet energy (sum of squared edge lengths), is kept, and a few
//! Jacobi steps of Laplacian smoothing, each projected, even out the
//! spacing. Known limits: a protrusion inside a patch (an ear) is left
//! out by the path split and folds the sweeps; where a side winds around a
//! tube within a few rows (the torus' half-tube patches), a quad or two
//! beside it can fold; [`LayoutGrid::folded`] counts them. Deviation: the paper leaves patch
//! parametrization to the embedding optimizations it cites in §7
//! ([Tarini et al. 2011; Campen et al. 2012]); this sweep is ours.
//!
//! Open surfaces: on a boundary-aligned layout the mesh boundary is made of
//! layout edges and the grid's boundary follows it. A hole no dual curve
//! ends on (not in the paper; "trimmed" by the hole in the paper's words,
//! §5.7) is covered by the layout as if capped ([`super::primal`]), and
//! the grid is made on the input with those holes capped (each rim
//! ear-clipped in its plane), so the sweep and the smoothing run across a hole
//! as across the surface and no grid point is pressed onto its rim. Each
//! hole is then cut out along its rim: the quads over its cap go (those
//! whose centroid lies on it, the one over its centre, those around a
//! corner left on it), grown into a disc (enclosed pockets and pinches
//! added); the ring around them is laid onto the rim and the two vertex
//! rings beyond are relaxed. The hole stays a boundary loop of the
//! pure-quad mesh (never closed over), every vertex on the input. A cut
//! that touches another hole's or the boundary (grid counts too small
//! there) is an error naming the hole.

use std::collections::HashMap;

use glam::{DMat3, DVec3};

use super::OrdF64;
use super::primal::LayoutExport;
use crate::mesh::{BoundaryArcs, EAR_CLIPPING_LIMIT, FaceList, MeshError, PolyMesh, TriMesh};
use crate::spatial::SurfaceIndex;

/// The grid count a strip gets unless the user picks another.
pub const DEFAULT_COUNT: u32 = 8;
/// Largest count per strip (a patch of two such strips has 65 536 quads).
pub const MAX_COUNT: u32 = 256;

/// Smoothing steps: one per grid segment of the patch's longer side, at
/// most this many.
const MAX_SMOOTHING_STEPS: usize = 16;

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum GridError {
    #[error("{0}")]
    Invalid(String),
    #[error("the gridded layout is not a valid mesh: {0}")]
    Mesh(#[from] MeshError),
}

/// The gridded layout: a pure-quad mesh and, per patch, its faces.
#[derive(Debug, Clone)]
pub struct LayoutGrid {
    pub mesh: PolyMesh,
    /// Faces of patch `p`: `patch_faces[p]..patch_faces[p + 1]`.
    pub patch_faces: Vec<u32>,
    /// Quads whose normal points against the surface's at their centroid
    /// (the sweep does not always follow a side that winds around a tube;
    /// see the module notes).
    pub folded: usize,
}

/// The patches as polygon faces: the layout vertices and the inner points
/// of every edge route (shared by the patches on both sides), each patch
/// one polygon running counter-clockwise along its four routes. A patch
/// whose sides share a route (a torus patch glued to itself) repeats its
/// points, which OBJ allows but a half-edge mesh does not: this is for
/// export.
pub fn patch_polygons(layout: &LayoutExport) -> Result<(Vec<DVec3>, FaceList), GridError> {
    let mut positions: Vec<DVec3> = layout.vertices.iter().map(|v| v.position).collect();
    // Per edge, the ids of its route's points, ends included.
    let mut route_ids: Vec<Vec<u32>> = Vec::with_capacity(layout.edges.len());
    for (e, edge) in layout.edges.iter().enumerate() {
        let [a, b] = edge.ends;
        if a as usize >= layout.vertices.len() || b as usize >= layout.vertices.len() {
            return Err(GridError::Invalid(format!(
                "layout edge {e} joins a vertex that does not exist"
            )));
        }
        let n = edge.polyline.len();
        let mut ids = vec![a];
        for p in edge.polyline.iter().take(n.saturating_sub(1)).skip(1) {
            ids.push(positions.len() as u32);
            positions.push(*p);
        }
        ids.push(b);
        route_ids.push(ids);
    }
    let mut faces = FaceList::new();
    for (p, patch) in layout.patches.iter().enumerate() {
        check_patch(layout, p)?;
        let mut face = Vec::new();
        for s in 0..4 {
            let ids = &route_ids[patch.edges[s] as usize];
            let mut side: Vec<u32> = ids.clone();
            if patch.reversed[s] {
                side.reverse();
            }
            face.extend_from_slice(&side[..side.len() - 1]);
        }
        faces.push(&face);
    }
    Ok((positions, faces))
}

/// The patch's edges exist and join its corners in its order.
fn check_patch(layout: &LayoutExport, p: usize) -> Result<(), GridError> {
    let patch = &layout.patches[p];
    for s in 0..4 {
        let Some(edge) = layout.edges.get(patch.edges[s] as usize) else {
            return Err(GridError::Invalid(format!(
                "patch {p} has no layout edge on side {s}"
            )));
        };
        let (from, to) = (patch.corners[s], patch.corners[(s + 1) % 4]);
        let ends = if patch.reversed[s] {
            [to, from]
        } else {
            [from, to]
        };
        if edge.ends != ends {
            return Err(GridError::Invalid(format!(
                "patch {p}: side {s} does not join its corners"
            )));
        }
    }
    Ok(())
}

/// `n + 1` points along `polyline` at equal arc-length steps, the ends
/// exactly its ends.
pub fn resample(polyline: &[DVec3], n: usize) -> Vec<DVec3> {
    let (Some(&first), Some(&last)) = (polyline.first(), polyline.last()) else {
        return Vec::new();
    };
    let mut cumulative = vec![0.0];
    for w in polyline.windows(2) {
        cumulative.push(cumulative[cumulative.len() - 1] + w[0].distance(w[1]));
    }
    let total = cumulative[cumulative.len() - 1];
    let mut out = Vec::with_capacity(n + 1);
    out.push(first);
    let mut seg = 0usize;
    for k in 1..n {
        let target = total * k as f64 / n as f64;
        while seg + 2 < cumulative.len() && cumulative[seg + 1] < target {
            seg += 1;
        }
        let length = cumulative[seg + 1] - cumulative[seg];
        let t = if length > 0.0 {
            ((target - cumulative[seg]) / length).clamp(0.0, 1.0)
        } else {
            0.0
        };
        out.push(polyline[seg].lerp(polyline[(seg + 1).min(polyline.len() - 1)], t));
    }
    if n > 0 {
        out.push(last);
    }
    out
}

/// Grids every patch of `layout` with `counts[l]` segments across the
/// strip of loop `l` (the edges crossing loop `l`), every vertex on the
/// surface of `index`. The result is pure quad; closed when the layout
/// covers a closed surface.
pub fn grid_layout(
    layout: &LayoutExport,
    counts: &[u32],
    mesh: &TriMesh,
    index: &SurfaceIndex,
) -> Result<LayoutGrid, GridError> {
    if layout.patches.is_empty() {
        return Err(GridError::Invalid("the layout has no patches".into()));
    }
    let capped = if layout.holes.is_empty() {
        None
    } else {
        Some(Capped::new(&layout.holes, mesh, index)?)
    };
    let index = capped.as_ref().map_or(index, |c| &c.index);
    let mut paths = SurfacePaths::new(capped.as_ref().map_or(mesh, |c| &c.mesh), index);
    // Per edge: its count and the ids of its samples, ends included.
    let mut positions: Vec<DVec3> = layout.vertices.iter().map(|v| v.position).collect();
    let mut samples: Vec<Vec<u32>> = Vec::with_capacity(layout.edges.len());
    for (e, edge) in layout.edges.iter().enumerate() {
        let n = counts
            .get(edge.loop_index as usize)
            .copied()
            .ok_or_else(|| {
                GridError::Invalid(format!(
                    "no grid count for strip {} (edge {e})",
                    edge.loop_index
                ))
            })?;
        if n == 0 || n > MAX_COUNT {
            return Err(GridError::Invalid(format!(
                "grid count {n} for strip {} is not in 1..={MAX_COUNT}",
                edge.loop_index
            )));
        }
        let [a, b] = edge.ends;
        if a as usize >= layout.vertices.len() || b as usize >= layout.vertices.len() {
            return Err(GridError::Invalid(format!(
                "layout edge {e} joins a vertex that does not exist"
            )));
        }
        let points = resample(&edge.polyline, n as usize);
        if points.len() != n as usize + 1 {
            return Err(GridError::Invalid(format!("layout edge {e} has no route")));
        }
        let mut ids = vec![a];
        for p in &points[1..n as usize] {
            ids.push(positions.len() as u32);
            positions.push(index.closest(*p).point);
        }
        ids.push(b);
        samples.push(ids);
    }
    let mut faces = FaceList::new();
    let mut patch_faces = vec![0u32];
    for p in 0..layout.patches.len() {
        check_patch(layout, p)?;
        let patch = &layout.patches[p];
        let side = |s: usize| -> Vec<u32> {
            let mut ids = samples[patch.edges[s] as usize].clone();
            if patch.reversed[s] {
                ids.reverse();
            }
            ids
        };
        let (bottom, right, mut top, mut left) = (side(0), side(1), side(2), side(3));
        // Top and left run against u and v.
        top.reverse();
        left.reverse();
        let (nu, nv) = (bottom.len() - 1, right.len() - 1);
        if top.len() != nu + 1 || left.len() != nv + 1 {
            return Err(GridError::Invalid(format!(
                "patch {p}: opposite sides have different counts"
            )));
        }
        let w = nu + 1;
        let mut ids = vec![u32::MAX; w * (nv + 1)];
        for i in 0..=nu {
            ids[i] = bottom[i];
            ids[i + nv * w] = top[i];
        }
        for j in 0..=nv {
            ids[j * w] = left[j];
            ids[nu + j * w] = right[j];
        }
        let boundary: Vec<DVec3> = ids
            .iter()
            .map(|&v| {
                if v == u32::MAX {
                    DVec3::ZERO
                } else {
                    positions[v as usize]
                }
            })
            .collect();
        let filled = fill_patch(&boundary, nu, nv, &mut paths);
        for j in 1..nv {
            for i in 1..nu {
                ids[i + j * w] = positions.len() as u32;
                positions.push(filled[i + j * w]);
            }
        }
        for j in 0..nv {
            for i in 0..nu {
                let at = |i: usize, j: usize| ids[i + j * w];
                faces.push(&[at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)]);
            }
        }
        patch_faces.push(faces.len() as u32);
    }
    let (positions, faces, patch_faces) = match &capped {
        Some(capped) => cut_holes(capped, positions, &faces, &patch_faces)?,
        None => (positions, faces, patch_faces),
    };
    let folded = folded_faces(&positions, &faces, index);
    let mesh = PolyMesh::from_faces(positions, &faces)?;
    Ok(LayoutGrid {
        mesh,
        patch_faces,
        folded,
    })
}

/// The input with the layout's holes capped: the grid is swept, projected
/// and smoothed on it, so no grid point is pressed onto a rim, and cut
/// along the rims afterwards ([`cut_holes`]).
struct Capped<'a> {
    mesh: TriMesh,
    index: SurfaceIndex,
    input: &'a SurfaceIndex,
    /// Faces of the input; face `input_faces + i` caps hole `cap_of[i]`.
    input_faces: usize,
    cap_of: Vec<usize>,
    /// Per hole, the input's boundary loop it lies on (the surface on its
    /// left), the cap's point nearest the rim's centroid, and how far from
    /// the input a point on its cap must lie to be off the input.
    rims: Vec<Vec<DVec3>>,
    centres: Vec<DVec3>,
    on_surface: Vec<f64>,
}

impl<'a> Capped<'a> {
    /// Caps each of `holes` (rims of the layout, [`LayoutExport::holes`])
    /// on `mesh`: the input's boundary loop most of the rim's points are
    /// nearest to, closed by [`cap`]. A rim that lies on no boundary loop,
    /// or on one another rim took, is an error naming it. `input_index` is
    /// `mesh`'s surface.
    fn new(
        holes: &[Vec<DVec3>],
        mesh: &TriMesh,
        input_index: &'a SurfaceIndex,
    ) -> Result<Capped<'a>, GridError> {
        let arcs = BoundaryArcs::new(mesh);
        let mut loops: Vec<Vec<u32>> = vec![Vec::new(); arcs.length.len()];
        for v in 0..mesh.positions.len() {
            if arcs.is_boundary(v) {
                loops[arcs.loop_of[v] as usize].push(v as u32);
            }
        }
        for l in &mut loops {
            l.sort_by(|&a, &b| arcs.arc[a as usize].total_cmp(&arcs.arc[b as usize]));
        }
        let on_boundary: Vec<u32> = loops.iter().flatten().copied().collect();
        let positions = mesh.positions.clone();
        let mut triangles = mesh.triangles.clone();
        let (mut cap_of, mut rims, mut on_surface) = (Vec::new(), Vec::new(), Vec::new());
        let mut taken: Vec<Option<usize>> = vec![None; loops.len()];
        for (k, hole) in holes.iter().enumerate() {
            let mut votes = vec![0usize; loops.len()];
            for &p in hole {
                let nearest = on_boundary.iter().min_by(|&&a, &&b| {
                    let (a, b) = (positions[a as usize], positions[b as usize]);
                    a.distance_squared(p).total_cmp(&b.distance_squared(p))
                });
                if let Some(&v) = nearest {
                    votes[arcs.loop_of[v as usize] as usize] += 1;
                }
            }
            let best = (0..loops.len())
                .filter(|&l| votes[l] > 0)
                .max_by_key(|&l| (votes[l], std::cmp::Reverse(l)));
            let Some(best) = best.filter(|&l| loops[l].len() >= 3) else {
                return Err(GridError::Invalid(format!(
                    "hole {k} lies on no boundary loop of the surface"
                )));
            };
            if let Some(other) = taken[best] {
                return Err(GridError::Invalid(format!(
                    "holes {other} and {k} lie on the same boundary loop of the surface"
                )));
            }
            taken[best] = Some(k);
            let rim = &loops[best];
            let points: Vec<DVec3> = rim.iter().map(|&v| positions[v as usize]).collect();
            let first = triangles.len();
            triangles.extend(cap(rim, &positions));
            cap_of.extend(std::iter::repeat_n(k, triangles.len() - first));
            let spacing = (0..points.len())
                .map(|i| points[i].distance(points[(i + 1) % points.len()]))
                .sum::<f64>()
                / points.len() as f64;
            on_surface.push(ON_SURFACE * spacing);
            rims.push(points);
        }
        let capped = TriMesh::new(positions, triangles)?;
        let index = SurfaceIndex::new(&capped)
            .ok_or_else(|| GridError::Invalid("the surface has no triangles".into()))?;
        let centres = rims
            .iter()
            .map(|r| {
                index
                    .closest(r.iter().sum::<DVec3>() / r.len() as f64)
                    .point
            })
            .collect();
        Ok(Capped {
            mesh: capped,
            index,
            input: input_index,
            input_faces: mesh.face_count(),
            cap_of,
            rims,
            centres,
            on_surface,
        })
    }

    /// The hole whose cap `p` lies on (nearest), if any: a point on a cap
    /// that lies on the input too (a cap overlapping the surface beside a
    /// concave rim) is on the input.
    fn hole_at(&self, p: DVec3) -> Option<usize> {
        let f = self.index.closest(p).face as usize;
        let k = f
            .checked_sub(self.input_faces)
            .and_then(|i| self.cap_of.get(i).copied())?;
        (self.input.distance(p) > self.on_surface[k]).then_some(k)
    }
}

/// Farthest a point lies from the input and still counts as on it, in
/// units of the rim's mean edge length.
const ON_SURFACE: f64 = 1e-3;

/// Triangles closing the boundary loop `rim` (vertex ids, the surface on
/// its left), oriented with the surface: the polygon ear-clipped
/// ([`FaceList::triangulate`]) in its Newell plane, a rim longer than
/// [`EAR_CLIPPING_LIMIT`] as a coarser polygon of every s-th rim vertex
/// plus the slivers between it and the rim.
fn cap(rim: &[u32], positions: &[DVec3]) -> Vec<[u32; 3]> {
    let reversed: Vec<u32> = rim.iter().rev().copied().collect();
    let n = reversed.len();
    let step = n.div_ceil(EAR_CLIPPING_LIMIT).max(1);
    let mut polygons = FaceList::new();
    let corners: Vec<usize> = (0..n).step_by(step).collect();
    let coarse: Vec<u32> = corners.iter().map(|&i| reversed[i]).collect();
    if coarse.len() >= 3 {
        polygons.push(&coarse);
    }
    for (j, &from) in corners.iter().enumerate() {
        let to = corners.get(j + 1).copied().unwrap_or(n);
        if to - from >= 2 {
            let sliver: Vec<u32> = (from..=to).map(|i| reversed[i % n]).collect();
            polygons.push(&sliver);
        }
    }
    polygons.triangulate(positions)
}

/// Cuts every hole of the layout out of the grid made on the capped
/// surface: the quads over its cap go — those whose centroid lies on it,
/// the one over its centre, and those around a corner on the cap that no
/// cut quad has — together with the kept pockets they enclose and the
/// quads around a vertex where they pinch, so that they form a disc; the
/// ring around them is laid onto the rim (at the ring's arc-length
/// proportions; a ring corner moves by less than a quad) and the two rings
/// of vertices beyond it are relaxed. A cut that touches the grid's
/// boundary or another hole's is an error naming the hole. Returns the
/// positions (vertices only in cut quads dropped), faces and per-patch face
/// ranges.
fn cut_holes(
    capped: &Capped,
    positions: Vec<DVec3>,
    faces: &FaceList,
    patch_faces: &[u32],
) -> Result<(Vec<DVec3>, FaceList, Vec<u32>), GridError> {
    let mut positions = positions;
    let n = positions.len();
    // Directed edges → face, and vertex → faces.
    let mut edge_face: HashMap<(u32, u32), usize> = HashMap::new();
    let mut vertex_faces: Vec<Vec<usize>> = vec![Vec::new(); n];
    for (f, face) in faces.iter().enumerate() {
        for k in 0..face.len() {
            edge_face.insert((face[k], face[(k + 1) % face.len()]), f);
            vertex_faces[face[k] as usize].push(f);
        }
    }
    // Per vertex: on the grid's boundary, or the hole whose cut it borders.
    const BOUNDARY: usize = usize::MAX - 1;
    let mut taken = vec![usize::MAX; n];
    for &(a, b) in edge_face.keys() {
        if !edge_face.contains_key(&(b, a)) {
            taken[a as usize] = BOUNDARY;
            taken[b as usize] = BOUNDARY;
        }
    }
    // The quad a point on the grid lies in: the nearest of its triangles.
    let triangles: Vec<[u32; 3]> = faces
        .iter()
        .flat_map(|f| [[f[0], f[1], f[2]], [f[0], f[2], f[3]]])
        .collect();
    let grid_index = TriMesh::new(positions.clone(), triangles)
        .ok()
        .and_then(|m| SurfaceIndex::new(&m))
        .ok_or_else(|| GridError::Invalid("the grid has no quads".into()))?;
    let hole_of: Vec<Option<usize>> = positions.iter().map(|&p| capped.hole_at(p)).collect();
    let mut removed = vec![false; faces.len()];
    let mut rings: Vec<Vec<u32>> = Vec::new();
    for (k, rim) in capped.rims.iter().enumerate() {
        let first = rim[0];
        let cannot = |why: &str| {
            GridError::Invalid(format!(
                "hole {k} (at {:.3}, {:.3}, {:.3}) cannot be cut out of the grid: {why}",
                first.x, first.y, first.z
            ))
        };
        // The quads whose centroid lies on the cap, and the one over its
        // centre (a hole inside one quad).
        let mut cut: Vec<bool> = (0..faces.len())
            .map(|f| {
                let q: Vec<DVec3> = faces
                    .face(f)
                    .iter()
                    .map(|&v| positions[v as usize])
                    .collect();
                capped.hole_at(centroid(&q)) == Some(k)
            })
            .collect();
        cut[grid_index.closest(capped.centres[k]).face as usize / 2] = true;
        // A corner on the cap must end up inside the cut or on its ring.
        loop {
            let mut grown = connect_cut(faces, &edge_face, &removed, &mut cut);
            close_cut(faces, &edge_face, &vertex_faces, &removed, &mut cut);
            for (v, hole) in hole_of.iter().enumerate() {
                if *hole == Some(k) && !vertex_faces[v].iter().any(|&f| cut[f]) {
                    for &f in &vertex_faces[v] {
                        grown |= !removed[f];
                        cut[f] |= !removed[f];
                    }
                }
            }
            if !grown {
                break;
            }
        }
        let over: Vec<usize> = (0..faces.len()).filter(|&f| cut[f]).collect();
        if over.iter().any(|&f| removed[f]) {
            return Err(cannot(
                "its grid quads are another hole's too; raise the grid counts",
            ));
        }
        let ring = ring_around(faces, &over).map_err(|why| cannot(&why))?;
        if let Some(&w) = ring.iter().find(|&&w| taken[w as usize] != usize::MAX) {
            return Err(cannot(&match taken[w as usize] {
                BOUNDARY => "its grid quads touch the mesh boundary; raise the grid counts".into(),
                other => format!("its grid quads touch hole {other}'s; raise the grid counts"),
            }));
        }
        for &f in &over {
            removed[f] = true;
            for &w in faces.face(f) {
                taken[w as usize] = k;
            }
        }
        lay_on_rim(&ring, rim, &mut positions);
        rings.push(ring);
    }
    let mut kept = FaceList::new();
    let mut kept_ranges = vec![0u32];
    for p in 0..patch_faces.len() - 1 {
        for f in patch_faces[p] as usize..patch_faces[p + 1] as usize {
            if !removed[f] {
                kept.push(faces.face(f));
            }
        }
        kept_ranges.push(kept.len() as u32);
    }
    relax_near_rims(capped, &rings, &kept, &mut positions);
    let (positions, kept) = crate::mesh::drop_unused(positions, &kept);
    Ok((positions, kept, kept_ranges))
}

/// Joins the first piece of `cut` (faces connected through shared edges)
/// to the nearest other piece by the shortest chain of faces between them
/// (faces `removed` by other cuts are absent); returns whether it did.
fn connect_cut(
    faces: &FaceList,
    edge_face: &HashMap<(u32, u32), usize>,
    removed: &[bool],
    cut: &mut [bool],
) -> bool {
    let neighbours = |f: usize| {
        let face = faces.face(f);
        (0..face.len()).filter_map(move |k| {
            edge_face
                .get(&(face[(k + 1) % face.len()], face[k]))
                .copied()
        })
    };
    let Some(start) = (0..faces.len()).find(|&f| cut[f]) else {
        return false;
    };
    // The first piece.
    let mut piece = vec![false; faces.len()];
    piece[start] = true;
    let mut stack = vec![start];
    while let Some(f) = stack.pop() {
        for g in neighbours(f) {
            if cut[g] && !piece[g] {
                piece[g] = true;
                stack.push(g);
            }
        }
    }
    if (0..faces.len()).all(|f| !cut[f] || piece[f]) {
        return false;
    }
    // Breadth-first from the piece to the nearest other cut face.
    let mut parent = vec![usize::MAX; faces.len()];
    let mut queue: std::collections::VecDeque<usize> =
        (0..faces.len()).filter(|&f| piece[f]).collect();
    for &f in &queue {
        parent[f] = f;
    }
    while let Some(f) = queue.pop_front() {
        for g in neighbours(f) {
            if removed[g] || parent[g] != usize::MAX {
                continue;
            }
            parent[g] = f;
            if cut[g] {
                let mut at = parent[g];
                while !piece[at] {
                    cut[at] = true;
                    at = parent[at];
                }
                return true;
            }
            queue.push_back(g);
        }
    }
    false
}

/// Grows `cut` (faces) until it is a disc: the faces of every pocket it
/// encloses (a component of the other faces, through shared edges, but the
/// largest; faces `removed` by other cuts count as absent), and the faces
/// around every vertex where its boundary passes twice.
fn close_cut(
    faces: &FaceList,
    edge_face: &HashMap<(u32, u32), usize>,
    vertex_faces: &[Vec<usize>],
    removed: &[bool],
    cut: &mut [bool],
) {
    for _ in 0..MAX_CLOSING_ROUNDS {
        let mut changed = false;
        // Pockets.
        let mut component = vec![usize::MAX; faces.len()];
        let mut sizes = Vec::new();
        for start in 0..faces.len() {
            if cut[start] || removed[start] || component[start] != usize::MAX {
                continue;
            }
            let c = sizes.len();
            let mut stack = vec![start];
            component[start] = c;
            let mut size = 0;
            while let Some(f) = stack.pop() {
                size += 1;
                let face = faces.face(f);
                for k in 0..face.len() {
                    if let Some(&g) = edge_face.get(&(face[(k + 1) % face.len()], face[k])) {
                        if !cut[g] && !removed[g] && component[g] == usize::MAX {
                            component[g] = c;
                            stack.push(g);
                        }
                    }
                }
            }
            sizes.push(size);
        }
        let largest = (0..sizes.len()).max_by_key(|&c| (sizes[c], std::cmp::Reverse(c)));
        for f in 0..faces.len() {
            if component[f] != usize::MAX && Some(component[f]) != largest {
                cut[f] = true;
                changed = true;
            }
        }
        // Pinches: a vertex the cut's boundary leaves more than once.
        let mut leaving: HashMap<u32, u32> = HashMap::new();
        for f in (0..faces.len()).filter(|&f| cut[f]) {
            let face = faces.face(f);
            for k in 0..face.len() {
                let (a, b) = (face[k], face[(k + 1) % face.len()]);
                if edge_face.get(&(b, a)).is_none_or(|&g| !cut[g]) {
                    *leaving.entry(a).or_insert(0) += 1;
                }
            }
        }
        for (&v, &count) in &leaving {
            if count > 1 {
                for &f in &vertex_faces[v as usize] {
                    if !cut[f] && !removed[f] {
                        cut[f] = true;
                        changed = true;
                    }
                }
            }
        }
        if !changed {
            return;
        }
    }
}

/// Most rounds of [`close_cut`] (each adds faces; a cut that keeps growing
/// fails the ring test after).
const MAX_CLOSING_ROUNDS: usize = 32;

/// Vertex rings beyond a hole's ring that [`relax_near_rims`] moves.
const RELAXED_RINGS: usize = 2;
/// Its Jacobi steps.
const RELAXING_STEPS: usize = 12;

/// Evens out the quads next to the cut holes: Jacobi steps of Laplacian
/// smoothing (half steps, projected onto the capped surface) on the
/// vertices within [`RELAXED_RINGS`] edges of a ring, the rings and the
/// grid's boundary fixed; a step that would land on a cap is not taken.
fn relax_near_rims(capped: &Capped, rings: &[Vec<u32>], faces: &FaceList, positions: &mut [DVec3]) {
    if rings.is_empty() {
        return;
    }
    let n = positions.len();
    let mut neighbours: Vec<Vec<u32>> = vec![Vec::new(); n];
    let mut directed = std::collections::HashSet::new();
    for face in faces.iter() {
        for k in 0..face.len() {
            let (a, b) = (face[k], face[(k + 1) % face.len()]);
            directed.insert((a, b));
            neighbours[a as usize].push(b);
            neighbours[b as usize].push(a);
        }
    }
    for l in &mut neighbours {
        l.sort_unstable();
        l.dedup();
    }
    let mut depth = vec![usize::MAX; n];
    let mut frontier: Vec<u32> = rings.iter().flatten().copied().collect();
    for &v in &frontier {
        depth[v as usize] = 0;
    }
    for d in 1..=RELAXED_RINGS {
        let mut next = Vec::new();
        for &v in &frontier {
            for &w in &neighbours[v as usize] {
                if depth[w as usize] == usize::MAX {
                    depth[w as usize] = d;
                    next.push(w);
                }
            }
        }
        frontier = next;
    }
    let on_boundary = |v: u32| {
        neighbours[v as usize]
            .iter()
            .any(|&w| directed.contains(&(v, w)) != directed.contains(&(w, v)))
    };
    let moving: Vec<u32> = (0..n as u32)
        .filter(|&v| (1..=RELAXED_RINGS).contains(&depth[v as usize]) && !on_boundary(v))
        .collect();
    for _ in 0..RELAXING_STEPS {
        let prev = positions.to_vec();
        for &v in &moving {
            let around = &neighbours[v as usize];
            let mean =
                around.iter().map(|&w| prev[w as usize]).sum::<DVec3>() / around.len() as f64;
            let p = capped.index.closest(0.5 * (prev[v as usize] + mean)).point;
            if capped.hole_at(p).is_none() {
                positions[v as usize] = p;
            }
        }
    }
}

/// The boundary of the union of faces `cut` as one loop with the other
/// faces on its left, or why it is not one simple loop (the cut is no
/// disc).
fn ring_around(faces: &FaceList, cut: &[usize]) -> Result<Vec<u32>, String> {
    let mut edges: Vec<(u32, u32)> = Vec::new();
    for &f in cut {
        let face = faces.face(f);
        for k in 0..face.len() {
            edges.push((face[k], face[(k + 1) % face.len()]));
        }
    }
    // Edges two cut faces share are inside the cut.
    let set: std::collections::HashSet<(u32, u32)> = edges.iter().copied().collect();
    edges.retain(|&(a, b)| !set.contains(&(b, a)));
    let mut next: std::collections::HashMap<u32, u32> = Default::default();
    for &(a, b) in &edges {
        if next.insert(a, b).is_some() {
            return Err("the grid quads over it pinch at a vertex".into());
        }
    }
    let Some(&(start, _)) = edges.first() else {
        return Err("the grid quads over it have no boundary".into());
    };
    let mut ring = vec![start];
    let mut at = next[&start];
    while at != start {
        if ring.len() > edges.len() {
            return Err("the grid quads over it do not close around it".into());
        }
        ring.push(at);
        at = *next
            .get(&at)
            .ok_or("the grid quads over it do not close around it")?;
    }
    if ring.len() != edges.len() {
        return Err("the grid quads over it leave more than one loop".into());
    }
    // The cut lies on the ring's left: reversed, the kept faces do.
    ring.reverse();
    Ok(ring)
}

/// Moves the ring's vertices onto `rim` (closed, the surface on its left,
/// as the ring), at the ring's own arc-length proportions, starting at the
/// rim point nearest the ring's first vertex.
fn lay_on_rim(ring: &[u32], rim: &[DVec3], positions: &mut [DVec3]) {
    let closed = |points: &[DVec3]| -> Vec<f64> {
        let mut c = vec![0.0];
        for k in 0..points.len() {
            let d = points[k].distance(points[(k + 1) % points.len()]);
            c.push(c[k] + d);
        }
        c
    };
    let ring_points: Vec<DVec3> = ring.iter().map(|&v| positions[v as usize]).collect();
    let (along_ring, along_rim) = (closed(&ring_points), closed(rim));
    let (ring_length, rim_length) = (along_ring[ring.len()], along_rim[rim.len()]);
    // Arc length of the rim point at `s` (mod its length).
    let at = |s: f64| -> DVec3 {
        let s = s.rem_euclid(rim_length.max(f64::MIN_POSITIVE));
        let k = along_rim.partition_point(|&x| x <= s).clamp(1, rim.len()) - 1;
        let length = along_rim[k + 1] - along_rim[k];
        let t = if length > 0.0 {
            (s - along_rim[k]) / length
        } else {
            0.0
        };
        rim[k].lerp(rim[(k + 1) % rim.len()], t)
    };
    // The rim point nearest the ring's first vertex.
    let first = ring_points[0];
    let mut start = (f64::INFINITY, 0.0);
    for k in 0..rim.len() {
        let (a, b) = (rim[k], rim[(k + 1) % rim.len()]);
        let ab = b - a;
        let t = if ab.length_squared() > 0.0 {
            ((first - a).dot(ab) / ab.length_squared()).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let d = first.distance_squared(a + t * ab);
        if d < start.0 {
            start = (d, along_rim[k] + t * (along_rim[k + 1] - along_rim[k]));
        }
    }
    for (k, &v) in ring.iter().enumerate() {
        let share = if ring_length > 0.0 {
            along_ring[k] / ring_length
        } else {
            k as f64 / ring.len() as f64
        };
        positions[v as usize] = at(start.1 + share * rim_length);
    }
}

/// The interior of one patch grid (`(nu + 1) × (nv + 1)` points, row-major
/// in v, boundary given): of the sweeps along v and along u, each rigid
/// (rows moved with the side curves' frames) or translated (rows shifted,
/// projection sliding them along the surface), the one with the fewest
/// folded quads and then the least Dirichlet energy, smoothed. A fifth
/// candidate, [`split_geodesically`], keeps every grid line on the surface
/// (no closest-point jump to another sheet), which the sweeps' projected
/// rows need not on patches that wrap around a protrusion.
fn fill_patch(boundary: &[DVec3], nu: usize, nv: usize, paths: &mut SurfacePaths) -> Vec<DVec3> {
    let index = paths.index;
    let w = nu + 1;
    let mut candidates = Vec::with_capacity(5);
    let mut split = boundary.to_vec();
    split_geodesically(&mut split, w, [0, nu], [0, nv], paths);
    candidates.push(split);
    for rigid in [true, false] {
        candidates.push(sweep_blend(boundary, [nu, nv], [1, w], rigid, index));
        candidates.push(sweep_blend(boundary, [nv, nu], [w, 1], rigid, index));
    }
    let score = |p: &[DVec3]| (folded_quads(p, nu, nv, index), dirichlet(p, nu, nv));
    let mut best = candidates
        .into_iter()
        .map(|c| (score(&c), c))
        .min_by(|a, b| a.0.0.cmp(&b.0.0).then(a.0.1.total_cmp(&b.0.1)))
        .map(|(_, c)| c)
        .unwrap_or_else(|| boundary.to_vec());
    smooth(&mut best, nu, nv, index);
    best
}

/// Fills the interior of the sub-grid `[i0, i1] × [j0, j1]` of `p` (row
/// stride `w`, its border given) by halving it: the middle column is the
/// shortest surface path between its two border ends, the middle row the
/// paths from its border ends to the column's middle point, each cut into
/// equal arc lengths; then the four quarters alike.
fn split_geodesically(
    p: &mut [DVec3],
    w: usize,
    [i0, i1]: [usize; 2],
    [j0, j1]: [usize; 2],
    paths: &mut SurfacePaths,
) {
    if i1 - i0 < 2 || j1 - j0 < 2 {
        return;
    }
    let (im, jm) = ((i0 + i1) / 2, (j0 + j1) / 2);
    let column = resample(&paths.path(p[im + j0 * w], p[im + j1 * w]), j1 - j0);
    for j in j0 + 1..j1 {
        p[im + j * w] = column[j - j0];
    }
    let middle = p[im + jm * w];
    let left = resample(&paths.path(p[i0 + jm * w], middle), im - i0);
    let right = resample(&paths.path(middle, p[i1 + jm * w]), i1 - im);
    for i in i0 + 1..im {
        p[i + jm * w] = left[i - i0];
    }
    for i in im + 1..i1 {
        p[i + jm * w] = right[i - im];
    }
    for (is, js) in [
        ([i0, im], [j0, jm]),
        ([im, i1], [j0, jm]),
        ([i0, im], [jm, j1]),
        ([im, i1], [jm, j1]),
    ] {
        split_geodesically(p, w, is, js, paths);
    }
}

/// Shortest paths on the surface the grid lies on: A* over its mesh edges
/// between the mesh vertices nearest two surface points, the points put at
/// the ends, straightened by [`PATH_SMOOTHING_STEPS`] projected Laplacian
/// steps (ends fixed). The search's scratch is kept between calls.
struct SurfacePaths<'a> {
    mesh: &'a TriMesh,
    index: &'a SurfaceIndex,
    adjacency: crate::mesh::VertexAdjacency,
    distance: Vec<f64>,
    parent: Vec<u32>,
    stamp: Vec<u32>,
    generation: u32,
}

/// Laplacian steps straightening a surface path.
const PATH_SMOOTHING_STEPS: usize = 8;

impl<'a> SurfacePaths<'a> {
    fn new(mesh: &'a TriMesh, index: &'a SurfaceIndex) -> SurfacePaths<'a> {
        let n = mesh.positions.len();
        SurfacePaths {
            mesh,
            index,
            adjacency: crate::mesh::VertexAdjacency::new(mesh),
            distance: vec![f64::INFINITY; n],
            parent: vec![u32::MAX; n],
            stamp: vec![0; n],
            generation: 0,
        }
    }

    /// The mesh vertex of the triangle under `p` nearest to it.
    /// `None` when the index is not the mesh's (no such triangle).
    fn vertex_near(&self, p: DVec3) -> Option<u32> {
        let t = self
            .mesh
            .triangles
            .get(self.index.closest(p).face as usize)?;
        t.iter().copied().min_by(|&a, &b| {
            let (a, b) = (
                self.mesh.positions[a as usize],
                self.mesh.positions[b as usize],
            );
            a.distance_squared(p).total_cmp(&b.distance_squared(p))
        })
    }

    /// The path from `a` to `b` (both on the surface) as a polyline; the
    /// segment between them walked onto the surface when the mesh does not
    /// join them.
    fn path(&mut self, a: DVec3, b: DVec3) -> Vec<DVec3> {
        let ends = self.vertex_near(a).zip(self.vertex_near(b));
        let mut points = vec![a];
        match ends.and_then(|(from, to)| self.vertices_between(from, to)) {
            Some(vertices) => {
                points.extend(vertices.iter().map(|&v| self.mesh.positions[v as usize]))
            }
            None => {
                let n = WALK_STEPS;
                let mut at = a;
                for k in 1..n {
                    at = walk(self.index, at, a.lerp(b, k as f64 / n as f64));
                    points.push(at);
                }
            }
        }
        points.push(b);
        let last = points.len() - 1;
        for _ in 0..PATH_SMOOTHING_STEPS {
            let prev = points.clone();
            for k in 1..last {
                let mean = 0.5 * (prev[k - 1] + prev[k + 1]);
                points[k] = self.index.closest(0.5 * (prev[k] + mean)).point;
            }
        }
        points
    }

    /// Mesh vertices of a shortest edge path from `from` to `to` (A*,
    /// straight-line distance as the heuristic), or `None`.
    fn vertices_between(&mut self, from: u32, to: u32) -> Option<Vec<u32>> {
        use std::cmp::Reverse;
        self.generation = self.generation.wrapping_add(1);
        if self.generation == 0 {
            self.stamp.fill(0);
            self.generation = 1;
        }
        let positions = &self.mesh.positions;
        let goal = positions[to as usize];
        let g = self.generation;
        let mut heap = std::collections::BinaryHeap::new();
        self.stamp[from as usize] = g;
        self.distance[from as usize] = 0.0;
        self.parent[from as usize] = u32::MAX;
        heap.push(Reverse((
            OrdF64(positions[from as usize].distance(goal)),
            from,
        )));
        while let Some(Reverse((OrdF64(estimate), v))) = heap.pop() {
            let d = self.distance[v as usize];
            if estimate > d + positions[v as usize].distance(goal) + 1e-12 {
                continue;
            }
            if v == to {
                let mut out = vec![to];
                let mut at = to;
                while self.parent[at as usize] != u32::MAX {
                    at = self.parent[at as usize];
                    out.push(at);
                }
                out.reverse();
                return Some(out);
            }
            for &u in self.adjacency.neighbors(v as usize) {
                let du = d + positions[v as usize].distance(positions[u as usize]);
                let seen = self.stamp[u as usize] == g;
                if !seen || du < self.distance[u as usize] {
                    self.stamp[u as usize] = g;
                    self.distance[u as usize] = du;
                    self.parent[u as usize] = v;
                    heap.push(Reverse((
                        OrdF64(du + positions[u as usize].distance(goal)),
                        u,
                    )));
                }
            }
        }
        None
    }
}

/// Faces whose normal (Newell) points against the surface normal at their
/// centroid.
fn folded_faces(positions: &[DVec3], faces: &FaceList, index: &SurfaceIndex) -> usize {
    faces
        .iter()
        .filter(|face| {
            let q: Vec<DVec3> = face.iter().map(|&v| positions[v as usize]).collect();
            let n = index.face_normal(index.closest(centroid(&q)).face);
            newell(&q).dot(n) <= 0.0
        })
        .count()
}

fn centroid(points: &[DVec3]) -> DVec3 {
    points.iter().sum::<DVec3>() / points.len().max(1) as f64
}

/// The polygon's Newell normal (twice its vector area).
fn newell(points: &[DVec3]) -> DVec3 {
    (0..points.len())
        .map(|k| points[k].cross(points[(k + 1) % points.len()]))
        .sum()
}

/// Grid quads whose normal (Newell) points against the surface normal at
/// their centroid.
fn folded_quads(p: &[DVec3], nu: usize, nv: usize, index: &SurfaceIndex) -> usize {
    let w = nu + 1;
    let mut folded = 0;
    for j in 0..nv {
        for i in 0..nu {
            let q = [
                p[i + j * w],
                p[i + 1 + j * w],
                p[i + 1 + (j + 1) * w],
                p[i + (j + 1) * w],
            ];
            let n = index.face_normal(index.closest(centroid(&q)).face);
            if newell(&q).dot(n) <= 0.0 {
                folded += 1;
            }
        }
    }
    folded
}

/// Sum of squared grid edge lengths.
fn dirichlet(p: &[DVec3], nu: usize, nv: usize) -> f64 {
    let w = nu + 1;
    let mut e = 0.0;
    for j in 0..=nv {
        for i in 0..=nu {
            let q = p[i + j * w];
            if i < nu {
                e += q.distance_squared(p[i + 1 + j * w]);
            }
            if j < nv {
                e += q.distance_squared(p[i + (j + 1) * w]);
            }
        }
    }
    e
}

/// A right-handed frame at `p` on a side curve: tangent along `d`, surface
/// normal from the closest triangle.
fn frame(index: &SurfaceIndex, p: DVec3, d: DVec3) -> DMat3 {
    let n = index.face_normal(index.closest(p).face);
    let n = if n == DVec3::ZERO { DVec3::Z } else { n };
    let t = (d - n * n.dot(d)).normalize_or_zero();
    let t = if t == DVec3::ZERO {
        n.any_orthonormal_vector()
    } else {
        t
    };
    DMat3::from_cols(t, n.cross(t), n)
}

/// Frames along a side curve (`points[k]`, k = 0..=n).
fn frames(index: &SurfaceIndex, points: &[DVec3]) -> Vec<DMat3> {
    let n = points.len() - 1;
    (0..=n)
        .map(|k| {
            let d = points[(k + 1).min(n)] - points[k.saturating_sub(1)];
            frame(index, points[k], d)
        })
        .collect()
}

/// The swept patch: rows `j` along `a` (`w + 1` points, index step
/// `step[0]`), `h + 1` rows (step `step[1]`); each row moved rigidly from
/// the previous one with the two side curves' frames, blended, projected;
/// from the first and from the last row, the two blended by row.
fn sweep_blend(
    boundary: &[DVec3],
    [w, h]: [usize; 2],
    step: [usize; 2],
    rigid: bool,
    index: &SurfaceIndex,
) -> Vec<DVec3> {
    let at = |i: usize, j: usize| i * step[0] + j * step[1];
    let side = |i: usize| -> Vec<DVec3> { (0..=h).map(|j| boundary[at(i, j)]).collect() };
    let (first, last) = (side(0), side(w));
    let (f0, f1) = (frames(index, &first), frames(index, &last));
    let row = |j: usize| -> Vec<DVec3> { (0..=w).map(|i| boundary[at(i, j)]).collect() };
    // From row `from` towards row `to` (exclusive of both).
    let sweep = |from: usize, to: usize| -> Vec<Vec<DVec3>> {
        let mut rows = vec![Vec::new(); h + 1];
        rows[from] = row(from);
        let mut j = from;
        while j != to {
            let next = if to > from { j + 1 } else { j - 1 };
            if next == to {
                break;
            }
            let prev = &rows[j];
            let out = if rigid {
                let r0 = f0[next] * f0[j].transpose();
                let r1 = f1[next] * f1[j].transpose();
                let mut out = vec![first[next]; w + 1];
                out[w] = last[next];
                for i in 1..w {
                    let u = i as f64 / w as f64;
                    let p0 = first[next] + r0 * (prev[i] - first[j]);
                    let p1 = last[next] + r1 * (prev[i] - last[j]);
                    out[i] = walk(index, prev[i], p0.lerp(p1, u));
                }
                out
            } else {
                shift_row(prev, [first[j], last[j]], [first[next], last[next]], index)
            };
            rows[next] = out;
            j = next;
        }
        rows
    };
    let up = sweep(0, h);
    let down = sweep(h, 0);
    let mut out = boundary.to_vec();
    for j in 1..h {
        let v = j as f64 / h as f64;
        for i in 1..w {
            out[at(i, j)] = walk(index, up[j][i], up[j][i].lerp(down[j][i], v));
        }
    }
    out
}

/// Steps of [`walk`].
const WALK_STEPS: usize = 8;

/// The surface point reached from `from` (on the surface) towards `to` in
/// [`WALK_STEPS`] projected steps: it stays on the sheet `from` lies on
/// where the closest point of `to` may lie on another (across a thin part
/// or a concave bend).
fn walk(index: &SurfaceIndex, from: DVec3, to: DVec3) -> DVec3 {
    let step = (to - from) / WALK_STEPS as f64;
    let mut at = from;
    for _ in 0..WALK_STEPS {
        at = index.closest(at + step).point;
    }
    at
}

/// Substeps of a shifted sweep between two rows.
const SHIFT_SUBSTEPS: usize = 4;

/// A row shifted with its two ends from `from` to `to`, in substeps: each
/// point moves by the ends' moves blended by u and is projected, then the
/// row is resampled by arc length, so that its points follow the ends
/// along the surface instead of bunching where the move is normal to it.
fn shift_row(row: &[DVec3], from: [DVec3; 2], to: [DVec3; 2], index: &SurfaceIndex) -> Vec<DVec3> {
    let w = row.len() - 1;
    let mut cur = row.to_vec();
    let mut ends = from;
    for s in 1..=SHIFT_SUBSTEPS {
        let t = s as f64 / SHIFT_SUBSTEPS as f64;
        let next = if s == SHIFT_SUBSTEPS {
            to
        } else {
            [0, 1].map(|k| index.closest(from[k].lerp(to[k], t)).point)
        };
        let d = [next[0] - ends[0], next[1] - ends[1]];
        let mut moved = vec![next[0]; w + 1];
        moved[w] = next[1];
        for i in 1..w {
            let u = i as f64 / w as f64;
            moved[i] = index.closest(cur[i] + d[0].lerp(d[1], u)).point;
        }
        cur = resample(&moved, w);
        for p in cur.iter_mut().take(w).skip(1) {
            *p = index.closest(*p).point;
        }
        ends = next;
    }
    cur
}

/// Jacobi steps of Laplacian smoothing on the interior, each projected.
fn smooth(p: &mut [DVec3], nu: usize, nv: usize, index: &SurfaceIndex) {
    let w = nu + 1;
    for _ in 0..nu.max(nv).min(MAX_SMOOTHING_STEPS) {
        let prev = p.to_vec();
        for j in 1..nv {
            for i in 1..nu {
                let k = i + j * w;
                let mean = 0.25 * (prev[k - 1] + prev[k + 1] + prev[k - w] + prev[k + w]);
                p[k] = index.closest(0.5 * (prev[k] + mean)).point;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn resample_cuts_a_polyline_into_equal_lengths() {
        let line = [
            DVec3::ZERO,
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(1.0, 3.0, 0.0),
        ];
        let s = resample(&line, 4);
        assert_eq!(s.len(), 5);
        assert_eq!(s[0], line[0]);
        assert_eq!(s[4], line[2]);
        for w in s.windows(2) {
            // Each step is 1 along the polyline; the one across the corner
            // is shorter in space.
            assert!(w[0].distance(w[1]) <= 1.0 + 1e-12);
        }
        assert!((s[1] - DVec3::new(1.0, 0.0, 0.0)).length() < 1e-12);
        assert!((s[2] - DVec3::new(1.0, 1.0, 0.0)).length() < 1e-12);
    }
}
