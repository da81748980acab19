//! Least-squares vertex placement: the output mesh's vertices move so that
//! its faces, not only its vertices, approximate the input. Deviation from
//! the thesis and Instant Meshes, which put every vertex on the input (IM
//! digest §5.12; Kloiber 2018 §3.7.4): a face whose corners lie on a curved
//! surface is a chord of it, inside where the surface is convex and
//! outside where it is concave, so such a mesh is off to one side by about
//! the sagitta of its edges.
//!
//! The energy is two-sided: Hoppe et al. 1993's distance energy with the
//! connectivity fixed (the squared distances of the input's points to the
//! mesh, [`InputSide`]) plus the squared distances of the mesh's points
//! to the input, weighted [`INPUT_SHARE`] to 1, plus a spring that holds
//! each vertex's tangential position. The mesh's points are its vertices,
//! edge midpoints and face centroids (its points after one linear
//! subdivision, whose weights on the vertices are the bilinear hat
//! weights, the exact basis of a bilinear mesh); an input point weighs on
//! the corners of the triangle it is closest to by its barycentric
//! coordinates. It is minimised by the LSPIA iteration of the control-mesh
//! fit's finish ([`crate::subdivision::fit`], Deng and Lin 2014): every
//! sample's offset to its closest point on the other surface, each vertex
//! moved by the weighted mean of its samples' offsets; then
//! [`TANGENT_ANCHOR`] of the vertex's tangential drift since the start is
//! taken back. Without that anchor the drift never settles (it slides the
//! vertices towards where the input curves most and distorts the quads).
//!
//! Kept in place: boundary vertices (on the input's boundary), vertices on
//! the input's feature curves (where the extraction and the smoothing put
//! them on the crease), and any move that would open a quad corner beyond
//! [`WIDE_CORNER`] or turn a face over ([`keep_shapes`]). Every move is
//! clamped to a quarter of the vertex's mean edge, so the mesh cannot jump
//! across a thin part of the input.

use glam::DVec3;

use super::postprocess::widest_quad_corner;
use crate::mesh::{PolyMesh, TriMesh, face_newell_normal};
use crate::spatial::{CurveIndex, SurfaceIndex};
use crate::subdivision::fit::{hat_weights, lspia_move, mean_edge_lengths};

/// A move is clamped to this share of the vertex's mean edge length.
const MAX_MOVE_EDGES: f64 = 0.25;

/// The share of a vertex's tangential drift since the start taken back
/// after every step (the spring's stiffness relative to the distance
/// term). Measured with the mesh's side of the energy alone (`make
/// quality`'s 8 meshes, medians over 5 vertex orders at the default
/// target; mean distance output → input, mean corner deviation): 0.2
/// lowers the mean distance on 7 of them by 7–19 % (fandisk +2 %) for
/// 0.1–6 % more corner deviation; 0.5 keeps the corners within 1 % but
/// gains only 2–16 %; without the anchor the drift does not settle: 10
/// steps gain 19–44 % but cost 15–67 % in corner deviation (bunny 4.32°
/// → 6.85°, single runs), and 20 steps cost more.
const TANGENT_ANCHOR: f64 = 0.2;

/// A move may not open a quad corner beyond this many degrees (the quality
/// issue's bar) and beyond its width before the move.
const WIDE_CORNER: f64 = 170.0;

/// `iterations` steps of least-squares placement on `mesh` (module docs),
/// with the vertices within a tenth of an edge of `curves` kept. Returns
/// the number of steps taken.
pub fn least_squares_placement(
    mesh: &mut PolyMesh,
    surface: &SurfaceIndex,
    input: &[DVec3],
    iterations: usize,
    curves: Option<&CurveIndex>,
) -> usize {
    let weights = hat_weights(mesh);
    let edge_length = mean_edge_lengths(mesh);
    let on_curve = |v: u32| {
        let p = mesh.positions[v as usize];
        curves.is_some_and(|c| c.closest(p).1 < 0.1 * edge_length[v as usize])
    };
    let movable: Vec<u32> = (0..mesh.vertex_count() as u32)
        .filter(|&v| !mesh.is_boundary_vertex(v) && !on_curve(v))
        .collect();
    let faces: Vec<Vec<u32>> = (0..mesh.face_count() as u32)
        .map(|f| mesh.face_vertices(f).collect())
        .collect();
    let input_side = InputSide::new(&faces, input, mesh.vertex_count(), weights.len());
    let mut all_weights = weights.clone();
    let start = mesh.positions.clone();
    let mut previous = vec![DVec3::ZERO; mesh.vertex_count()];
    let (mut samples, mut offsets) = (Vec::new(), Vec::new());
    for _ in 0..iterations {
        let before = mesh.positions.clone();
        samples.clear();
        samples.extend(weights.iter().map(|w| {
            w.iter()
                .map(|&(v, x)| x * before[v as usize])
                .sum::<DVec3>()
        }));
        crate::parallel::map_into(&samples, &mut offsets, |&p| surface.closest(p).point - p);
        all_weights.truncate(weights.len());
        input_side.pulls(&before, &mut all_weights, &mut offsets);
        let normals = vertex_normals(&before, &faces);
        lspia_move(
            &mut mesh.positions,
            &all_weights,
            &offsets,
            &movable,
            &|v| MAX_MOVE_EDGES * edge_length[v],
            &mut previous,
        );
        for &v in &movable {
            let v = v as usize;
            let (n, drift) = (normals[v], mesh.positions[v] - start[v]);
            let back = TANGENT_ANCHOR * (drift - drift.dot(n) * n);
            mesh.positions[v] -= back;
            previous[v] -= back;
        }
        keep_shapes(&mut mesh.positions, &before, &faces, &mut previous);
    }
    iterations
}

/// Unit vertex normals: the sum of the faces' Newell normals
/// (area-weighted).
fn vertex_normals(pos: &[DVec3], faces: &[Vec<u32>]) -> Vec<DVec3> {
    let mut normals = vec![DVec3::ZERO; pos.len()];
    for f in faces {
        let n = face_newell_normal(pos, f);
        for &v in f {
            normals[v as usize] += n;
        }
    }
    normals.iter().map(|n| n.normalize_or_zero()).collect()
}

/// Undoes the last step's moves at every face it spoiled: a quad whose
/// widest corner opened beyond [`WIDE_CORNER`] and beyond its width
/// before, or any face whose normal turned over. Repeats until no face is
/// spoiled (undoing can only bring a face back to how it was). The
/// vertices undone lose their momentum.
fn keep_shapes(pos: &mut [DVec3], before: &[DVec3], faces: &[Vec<u32>], previous: &mut [DVec3]) {
    let limit = WIDE_CORNER.to_radians();
    let width: Vec<f64> = faces
        .iter()
        .map(|f| widest_quad_corner(before, f))
        .collect();
    let normal: Vec<DVec3> = faces
        .iter()
        .map(|f| face_newell_normal(before, f))
        .collect();
    loop {
        let mut undone = false;
        for (i, f) in faces.iter().enumerate() {
            let w = widest_quad_corner(pos, f);
            let flipped = face_newell_normal(pos, f).dot(normal[i]) < 0.0;
            if flipped || (w > limit && w > width[i]) {
                for &v in f {
                    let v = v as usize;
                    if pos[v] != before[v] {
                        pos[v] = before[v];
                        previous[v] = DVec3::ZERO;
                        undone = true;
                    }
                }
            }
        }
        if !undone {
            break;
        }
    }
}

/// The input's side of the distance energy ([`Self::pulls`]): the
/// output's faces as fan triangles, every `stride`-th input point (at most
/// [`INPUT_SAMPLES_PER_VERTEX`] per output vertex) and the weight of each,
/// so that all of them together weigh [`INPUT_SHARE`] × the output's
/// samples. Built once; the connectivity does not change.
struct InputSide {
    triangles: Vec<[u32; 3]>,
    points: Vec<DVec3>,
    scale: f64,
}

impl InputSide {
    fn new(faces: &[Vec<u32>], input: &[DVec3], vertices: usize, output_samples: usize) -> Self {
        let triangles: Vec<[u32; 3]> = faces
            .iter()
            .flat_map(|f| (1..f.len() - 1).map(move |k| [f[0], f[k], f[k + 1]]))
            .collect();
        let stride = input
            .len()
            .div_ceil((INPUT_SAMPLES_PER_VERTEX * vertices).max(1))
            .max(1);
        let points: Vec<DVec3> = input.iter().step_by(stride).copied().collect();
        let scale = INPUT_SHARE * output_samples as f64 / points.len().max(1) as f64;
        InputSide {
            triangles,
            points,
            scale,
        }
    }

    /// For every input point, the offset from its closest point on the
    /// output at `pos` (a fan triangle) to it, weighing on that triangle's
    /// corners by the closest point's barycentric coordinates. Appended to
    /// `weights` and `offsets`; nothing when the output's triangles make
    /// no index.
    fn pulls(&self, pos: &[DVec3], weights: &mut Vec<Vec<(u32, f64)>>, offsets: &mut Vec<DVec3>) {
        let Some(index) = TriMesh::new(pos.to_vec(), self.triangles.clone())
            .ok()
            .and_then(|t| SurfaceIndex::new(&t))
        else {
            return;
        };
        let mut pulls: Vec<(Vec<(u32, f64)>, DVec3)> = Vec::new();
        crate::parallel::map_into(&self.points, &mut pulls, |&x| {
            let c = index.closest(x);
            let t = self.triangles[c.face as usize];
            let b = barycentric(
                c.point,
                [pos[t[0] as usize], pos[t[1] as usize], pos[t[2] as usize]],
            );
            let w = (0..3).map(|i| (t[i], self.scale * b[i])).collect();
            (w, x - c.point)
        });
        for (w, offset) in pulls {
            weights.push(w);
            offsets.push(offset);
        }
    }
}

/// The input's side of the energy weighs this much against the output's.
/// Measured (medians over 5 vertex orders on `make quality`'s 8 meshes,
/// 16 input points per output vertex, change against no placement; mean
/// distance output → input, input → output): 0.3 lowers the first on 7 of them by 4–17 % (fandisk +3 %)
/// and the second on all by 4–37 %; 1 lowers the second by 4–41 % but the
/// first on only 5 (fandisk +6 %, suzanne +3 %); 0 (the output's side
/// alone) lowers the first most, 7–19 %, but lets spot's horn tips retract
/// 0.69 target edges from the output, which the input's side prevents.
const INPUT_SHARE: f64 = 0.3;

/// Input points per output vertex the input's side of the energy reads
/// at most (every input vertex up to that). 16 gave the same distances
/// within 2 % (medians over 5 vertex orders; rocker-arm, spot, cow,
/// bunny) for 2.4 times the closest-point queries on the bunny.
const INPUT_SAMPLES_PER_VERTEX: usize = 4;

/// Barycentric coordinates of `p` (a point of the triangle) in `t`,
/// clamped to non-negative and summing to 1; the centre for a degenerate
/// triangle.
fn barycentric(p: DVec3, t: [DVec3; 3]) -> [f64; 3] {
    let (e1, e2, d) = (t[1] - t[0], t[2] - t[0], p - t[0]);
    let (d11, d12, d22) = (e1.dot(e1), e1.dot(e2), e2.dot(e2));
    let det = d11 * d22 - d12 * d12;
    if det <= 1e-300 {
        return [1.0 / 3.0; 3];
    }
    let (d1, d2) = (d.dot(e1), d.dot(e2));
    let v = ((d22 * d1 - d12 * d2) / det).max(0.0);
    let w = ((d11 * d2 - d12 * d1) / det).max(0.0);
    let u = (1.0 - v - w).max(0.0);
    let sum = u + v + w;
    [u / sum, v / sum, w / sum]
}
