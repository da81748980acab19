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
//! side and the two are blended by v (so both are met exactly). Sweeps run
//! along v and along u, rigid and shifted; of the four, the grid with the
//! fewest folded quads (normal against the surface's), then the lowest
//! Dirichlet energy (sum of squared edge lengths), is kept, and a few
//! Jacobi steps of Laplacian smoothing, each projected, even out the
//! spacing. Known limit: where a side winds around a tube within a few
//! rows (the torus' half-tube patches), a quad or two beside it can fold;
//! [`LayoutGrid::folded`] counts them. Deviation: the paper leaves patch
//! parametrization to the embedding optimizations it cites in §7
//! ([Tarini et al. 2011; Campen et al. 2012]); this sweep is ours.
//!
//! Open surfaces: on a boundary-aligned layout the mesh boundary is made of
//! layout edges and the grid's boundary follows it. A hole no dual curve
//! ends on (not in the paper; "trimmed" by the hole in the paper's words,
//! §5.7) is covered by the layout as if capped ([`super::primal`]); the
//! grid then cuts it out: the grid quads over the hole — the one nearest
//! it and those the sweep's projection pressed onto its rim — are removed
//! and the boundary of their union is laid onto the hole's rim, so the
//! hole stays a boundary loop of the pure-quad mesh (never closed over).
//! A hole whose quads are no disc, or touch another hole's or the boundary
//! (grid counts too small there), is an error naming it. Known limit:
//! quads partly over a hole stay, pressed against its rim.

use glam::{DMat3, DVec3};

use super::primal::LayoutExport;
use crate::mesh::{FaceList, MeshError, PolyMesh};
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
    index: &SurfaceIndex,
) -> Result<LayoutGrid, GridError> {
    if layout.patches.is_empty() {
        return Err(GridError::Invalid("the layout has no patches".into()));
    }
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
    let mut folded = 0;
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
        let (filled, folded_here) = fill_patch(&boundary, nu, nv, index);
        folded += folded_here;
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
    let (positions, faces, patch_faces) = cut_holes(layout, positions, &faces, &patch_faces)?;
    let mesh = PolyMesh::from_faces(positions, &faces)?;
    Ok(LayoutGrid {
        mesh,
        patch_faces,
        folded,
    })
}

/// Cuts every hole of the layout ([`LayoutExport::holes`]) out of the grid:
/// the quads over it go (the nearest by centroid, and those with every
/// corner on its rim) and the boundary of their union is laid onto the
/// hole's rim (its points at the boundary's arc-length proportions, from
/// the rim point nearest its first). Returns the positions, faces and
/// per-patch face ranges.
fn cut_holes(
    layout: &LayoutExport,
    mut positions: Vec<DVec3>,
    faces: &FaceList,
    patch_faces: &[u32],
) -> Result<(Vec<DVec3>, FaceList, Vec<u32>), GridError> {
    if layout.holes.is_empty() {
        return Ok((positions, faces.clone(), patch_faces.to_vec()));
    }
    // Vertices on the grid's boundary (the mesh boundary along stretches).
    let mut directed = std::collections::HashSet::new();
    for face in faces.iter() {
        for k in 0..face.len() {
            directed.insert((face[k], face[(k + 1) % face.len()]));
        }
    }
    // Per vertex: on the grid's boundary, or the hole whose cut it borders.
    const BOUNDARY: usize = usize::MAX - 1;
    let mut taken = vec![usize::MAX; positions.len()];
    for &(a, b) in &directed {
        if !directed.contains(&(b, a)) {
            taken[a as usize] = BOUNDARY;
            taken[b as usize] = BOUNDARY;
        }
    }
    let mut removed = vec![false; faces.len()];
    for (k, rim) in layout.holes.iter().enumerate() {
        let Some(&first) = rim.first() else {
            continue;
        };
        let centre = rim.iter().sum::<DVec3>() / rim.len() as f64;
        let cannot = |why: &str| {
            GridError::Invalid(format!(
                "hole {k} (at {:.3}, {:.3}, {:.3}) cannot be cut out of the grid: {why}",
                first.x, first.y, first.z
            ))
        };
        // The quads over the hole: the nearest to it, and those whose
        // corners all lie on its rim (the sweep's projection pressed them
        // there).
        let centroid = |f: usize| {
            let face = faces.face(f);
            face.iter().map(|&v| positions[v as usize]).sum::<DVec3>() / face.len() as f64
        };
        let nearest = (0..faces.len())
            .min_by(|&a, &b| {
                centroid(a)
                    .distance_squared(centre)
                    .total_cmp(&centroid(b).distance_squared(centre))
            })
            .ok_or_else(|| cannot("the grid has no quads"))?;
        let reach = rim.iter().map(|p| p.distance(centre)).fold(0.0, f64::max) + ON_RIM;
        let size = faces
            .face(nearest)
            .iter()
            .map(|&v| positions[v as usize].distance(centroid(nearest)))
            .fold(0.0, f64::max);
        if centroid(nearest).distance(centre) > reach + size {
            return Err(cannot(
                "no grid quad lies over it (the grid does not reach it)",
            ));
        }
        let on_rim: Vec<bool> = positions
            .iter()
            .map(|&p| p.distance(centre) <= reach && distance_to_closed(rim, p) <= ON_RIM)
            .collect();
        let over: Vec<usize> = (0..faces.len())
            .filter(|&f| f == nearest || faces.face(f).iter().all(|&v| on_rim[v as usize]))
            .collect();
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
        }
        for &f in &over {
            for &w in faces.face(f) {
                taken[w as usize] = k;
            }
        }
        lay_on_rim(&ring, rim, &mut positions);
    }
    // Keep the other faces; every vertex still has one (no cut touches
    // another or the boundary).
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
    Ok((positions, kept, kept_ranges))
}

/// Farthest a grid vertex pressed onto a hole's rim lies from it.
const ON_RIM: f64 = 1e-9;

/// Distance from `p` to the closed polyline `rim`.
fn distance_to_closed(rim: &[DVec3], p: DVec3) -> f64 {
    (0..rim.len())
        .map(|k| crate::spatial::segment_distance(p, rim[k], rim[(k + 1) % rim.len()]))
        .fold(f64::INFINITY, f64::min)
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
/// folded quads and then the least Dirichlet energy, smoothed.
fn fill_patch(
    boundary: &[DVec3],
    nu: usize,
    nv: usize,
    index: &SurfaceIndex,
) -> (Vec<DVec3>, usize) {
    let w = nu + 1;
    let mut candidates = Vec::with_capacity(4);
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
    let folded = folded_quads(&best, nu, nv, index);
    (best, folded)
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
            let mut normal = DVec3::ZERO;
            for k in 0..4 {
                normal += q[k].cross(q[(k + 1) % 4]);
            }
            let centroid = 0.25 * (q[0] + q[1] + q[2] + q[3]);
            let n = index.face_normal(index.closest(centroid).face);
            if normal.dot(n) <= 0.0 {
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
                    out[i] = index.closest(p0.lerp(p1, u)).point;
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
            out[at(i, j)] = index.closest(up[j][i].lerp(down[j][i], v)).point;
        }
    }
    out
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
