//! Smooth regions, their significance and cyclic regions: Campen et al.
//! 2016, *Scale-Invariant Directional Alignment of Surface
//! Parametrizations* (`../shared/seeds/001_…`), sections 3.1–3.2.
//!
//! Per face we take principal directions `a_min`, `a_max` and the curvature
//! `κ_max` of larger magnitude; a face is *smooth* when the maximum
//! geodesic curvature `κ^g` of the direction field across its edges stays
//! below `|κ_max|` (Eq. 2); smooth regions are the connected components of
//! smooth faces; a region's *significance* (Eq. 3) is the largest
//! normal-turning range along streamlines of `a_max` traced from its
//! boundary vertices; a region around which `a_max` has turning number zero
//! (a boundary loop or a vertex) is *cyclic* and gets 360°.
//!
//! Deviations, and why:
//! - The per-face curvature tensor is the mean of the three corners'
//!   tensors (from [`super::curvature`]) projected into the face plane,
//!   rather than Alliez et al.'s integrated tensor; the face normal is then
//!   orthogonal to `a_min` by construction (the paper's `n = a_min × n' ×
//!   a_min` step).
//! - Umbilic and flat faces (`|κ_max − κ_min| ≤ 1e-3 |κ_max|` or
//!   `κ_max = 0`) have no principal directions: `κ^g = ∞`, never smooth;
//!   and the derivative of a neighbour is not taken across an edge to such a
//!   face (its direction is noise), so a fillet's region reaches the flat
//!   faces around it instead of stopping a row short.
//! - Cyclic by a vertex: besides boundary loops, an interior vertex where
//!   `a_max` has index ±1 (curvature lines circling it, as at a needle's
//!   tip) makes a region cyclic.
//! - Either test counts only for regions whose normals spread more than 45°
//!   from their mean: a region wrapping around a part of the model always
//!   does, while a small region around an index-±1 spot of umbilic noise (a
//!   sphere is full of them) does not, and no streamline in it can turn the
//!   normal far.
//! - A streamline stops after `4 ×` the region's face count steps (a cyclic
//!   streamline never reaches a boundary; cyclic regions get 360° anyway).

use std::collections::HashMap;

use glam::DVec3;
use serde::{Deserialize, Serialize};

use super::PrincipalCurvature;
use crate::mesh::TriMesh;

/// Faces whose principal curvatures differ by at most this fraction of
/// `|κ_max|` are umbilic: their directions are noise.
const UMBILIC: f64 = 1e-3;

/// Parameters of the smooth-region detection.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct SmoothRegionParams {
    /// Regions whose significance is below this angle (degrees) are
    /// discarded. Default 70° (the paper's setting for all models).
    pub significance_threshold: f64,
}

impl Default for SmoothRegionParams {
    fn default() -> Self {
        SmoothRegionParams {
            significance_threshold: 70.0,
        }
    }
}

/// Principal curvature data of one face.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FaceCurvature {
    /// Unit face normal.
    pub normal: DVec3,
    /// Curvature of larger magnitude, and the other.
    pub kappa_max: f64,
    pub kappa_min: f64,
    /// Unit tangent directions (line fields: the sign is arbitrary).
    pub a_max: DVec3,
    pub a_min: DVec3,
}

/// The smooth regions of a mesh.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SmoothRegions {
    /// Region of each face, or `None` for non-smooth faces.
    pub region_of_face: Vec<Option<u32>>,
    /// Per region: significance in degrees (360 for cyclic regions).
    pub significance: Vec<f64>,
    /// Per region: contains a loop around which `a_max` turns zero times.
    pub cyclic: Vec<bool>,
    /// The region boundary loops with turning number zero (Campen §3.2),
    /// each as `(region, faces)`: the region's faces along the loop in
    /// walking order, consecutive ones sharing an edge, closed (the last
    /// shares an edge with the first). Campen §4.3 closes the
    /// parametrization's isolines around them.
    pub zero_turning_loops: Vec<(u32, Vec<u32>)>,
    /// Per region: significance ≥ threshold.
    pub filtered: Vec<bool>,
    /// Per face: `a_min`, `a_max`, curvatures.
    pub faces: Vec<FaceCurvature>,
    /// Per face: the maximum geodesic curvature κ^g (∞ where undefined).
    pub geodesic_curvature: Vec<f64>,
}

impl SmoothRegions {
    /// Faces in regions that passed the significance filter.
    pub fn selected_faces(&self) -> Vec<bool> {
        self.region_of_face
            .iter()
            .map(|r| r.is_some_and(|r| self.filtered[r as usize]))
            .collect()
    }

    pub fn region_count(&self) -> usize {
        self.significance.len()
    }
}

/// Per-face principal curvatures from the vertices' (see module docs).
pub fn face_curvatures(mesh: &TriMesh, vertex: &[PrincipalCurvature]) -> Vec<FaceCurvature> {
    (0..mesh.face_count())
        .map(|f| {
            let n = mesh.face_normal_unnormalized(f).normalize_or_zero();
            let (e1, e2) = n.any_orthonormal_pair();
            // Mean corner tensor in the face's (e1, e2) basis.
            let (mut xx, mut xy, mut yy) = (0.0, 0.0, 0.0);
            for &v in &mesh.triangles[f] {
                let c = vertex
                    .get(v as usize)
                    .copied()
                    .unwrap_or(PrincipalCurvature::flat(n));
                for (k, d) in [(c.k1, c.d1), (c.k2, c.d2)] {
                    let (x, y) = (d.dot(e1), d.dot(e2));
                    xx += k * x * x / 3.0;
                    xy += k * x * y / 3.0;
                    yy += k * y * y / 3.0;
                }
            }
            // Eigen-decomposition of [[xx, xy], [xy, yy]].
            let mean = 0.5 * (xx + yy);
            let radius = (0.25 * (xx - yy) * (xx - yy) + xy * xy).sqrt();
            let (l1, l2) = (mean + radius, mean - radius);
            let angle = 0.5 * (2.0 * xy).atan2(xx - yy);
            let d1 = e1 * angle.cos() + e2 * angle.sin();
            let d2 = n.cross(d1);
            let (kappa_max, a_max, kappa_min, a_min) = if l1.abs() >= l2.abs() {
                (l1, d1, l2, d2)
            } else {
                (l2, d2, l1, d1)
            };
            FaceCurvature {
                normal: n,
                kappa_max,
                kappa_min,
                a_max,
                a_min,
            }
        })
        .collect()
}

/// Directed edge `(a, b)` → the face containing it (manifold, consistently
/// oriented parts only: an edge used by more than two faces or twice in the
/// same direction links nothing).
struct DirectedEdges {
    face_of: HashMap<(u32, u32), u32>,
}

impl DirectedEdges {
    fn new(mesh: &TriMesh) -> DirectedEdges {
        let mut count: HashMap<(u32, u32), u32> = HashMap::with_capacity(mesh.face_count() * 3);
        for t in &mesh.triangles {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                *count.entry((a.min(b), a.max(b))).or_insert(0) += 1;
            }
        }
        let mut face_of = HashMap::with_capacity(mesh.face_count() * 3);
        for (f, t) in mesh.triangles.iter().enumerate() {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                if count[&(a.min(b), a.max(b))] <= 2 {
                    face_of.insert((a, b), f as u32);
                }
            }
        }
        DirectedEdges { face_of }
    }

    /// The face across edge `a → b` of a face containing it (the face
    /// containing `b → a`).
    fn across(&self, a: u32, b: u32) -> Option<u32> {
        self.face_of.get(&(b, a)).copied()
    }
}

/// Detects smooth regions, their significance and cyclicity.
pub fn smooth_regions(
    mesh: &TriMesh,
    vertex: &[PrincipalCurvature],
    params: &SmoothRegionParams,
) -> SmoothRegions {
    let faces = face_curvatures(mesh, vertex);
    let edges = DirectedEdges::new(mesh);
    let centroid = |f: usize| {
        let [a, b, c] = mesh.corners(f);
        (a + b + c) / 3.0
    };

    // κ^g across each edge: the parallel-transported difference of a_min.
    let defined: Vec<bool> = faces
        .iter()
        .map(|fc| {
            fc.kappa_max != 0.0
                && (fc.kappa_max - fc.kappa_min).abs() > UMBILIC * fc.kappa_max.abs()
        })
        .collect();
    let geodesic_curvature: Vec<f64> = (0..mesh.face_count())
        .map(|f| {
            let fc = &faces[f];
            if !defined[f] {
                return f64::INFINITY;
            }
            let t = mesh.triangles[f];
            let mut worst = 0.0f64;
            for k in 0..3 {
                let Some(g) = edges.across(t[k], t[(k + 1) % 3]) else {
                    continue;
                };
                let g = g as usize;
                if !defined[g] {
                    continue;
                }
                let transported = transport(faces[g].a_min, faces[g].normal, fc.normal);
                let d = centroid(f).distance(centroid(g)).max(1e-300);
                let diff = (fc.a_min - transported)
                    .length()
                    .min((fc.a_min + transported).length());
                worst = worst.max(diff / d);
            }
            worst
        })
        .collect();
    let smooth: Vec<bool> = (0..mesh.face_count())
        .map(|f| geodesic_curvature[f] < faces[f].kappa_max.abs())
        .collect();

    // Connected components of smooth faces.
    let mut region_of_face: Vec<Option<u32>> = vec![None; mesh.face_count()];
    let mut regions: Vec<Vec<u32>> = Vec::new();
    for start in 0..mesh.face_count() {
        if !smooth[start] || region_of_face[start].is_some() {
            continue;
        }
        let id = regions.len() as u32;
        let mut members = vec![start as u32];
        region_of_face[start] = Some(id);
        let mut i = 0;
        while i < members.len() {
            let f = members[i] as usize;
            i += 1;
            let t = mesh.triangles[f];
            for k in 0..3 {
                if let Some(g) = edges.across(t[k], t[(k + 1) % 3]) {
                    if smooth[g as usize] && region_of_face[g as usize].is_none() {
                        region_of_face[g as usize] = Some(id);
                        members.push(g);
                    }
                }
            }
        }
        regions.push(members);
    }

    let in_region =
        |f: Option<u32>, id: u32| f.is_some_and(|g| region_of_face[g as usize] == Some(id));
    let mut significance = Vec::with_capacity(regions.len());
    let mut cyclic = Vec::with_capacity(regions.len());
    let mut zero_turning_loops = Vec::new();
    for (id, members) in regions.iter().enumerate() {
        let id = id as u32;
        let walker = FanWalker {
            mesh,
            faces: &faces,
            edges: &edges,
            inside: &|f: Option<u32>| in_region(f, id),
        };
        let (is_cyclic, loops) = walker.zero_turning_loops(members);
        zero_turning_loops.extend(loops.into_iter().map(|l| (id, l)));
        let angle = if is_cyclic {
            360.0
        } else {
            streamline_significance(mesh, &faces, &edges, members, &|f| in_region(f, id))
        };
        cyclic.push(is_cyclic);
        significance.push(angle);
    }
    let filtered = significance
        .iter()
        .map(|&s| s >= params.significance_threshold)
        .collect();
    SmoothRegions {
        region_of_face,
        significance,
        cyclic,
        zero_turning_loops,
        filtered,
        faces,
        geodesic_curvature,
    }
}

/// Rotates tangent vector `v` of the plane with normal `from` into the
/// plane with normal `to` about `from × to` (discrete Levi-Civita transport).
fn transport(v: DVec3, from: DVec3, to: DVec3) -> DVec3 {
    let axis = from.cross(to);
    let s = axis.length();
    let c = from.dot(to);
    if s < 1e-12 {
        return v;
    }
    let k = axis / s;
    v * c + k.cross(v) * s + k * k.dot(v) * (1.0 - c)
}

/// Significance of a region (Eq. 3): streamlines of `a_max` from (next to)
/// every boundary vertex, each scored by the range of its accumulated signed
/// normal turning; the maximum in degrees.
fn streamline_significance(
    mesh: &TriMesh,
    faces: &[FaceCurvature],
    edges: &DirectedEdges,
    members: &[u32],
    inside: &dyn Fn(Option<u32>) -> bool,
) -> f64 {
    let max_steps = 4 * members.len() + 8;
    let mut started = std::collections::HashSet::new();
    let mut best = 0.0f64;
    for &f in members {
        let t = mesh.triangles[f as usize];
        for k in 0..3 {
            // Boundary vertices: corners of region faces on a region edge.
            let (a, b) = (t[k], t[(k + 1) % 3]);
            if inside(edges.across(a, b)) {
                continue;
            }
            for v in [a, b] {
                if !started.insert(v) {
                    continue;
                }
                // Start a third of the way from the vertex to the face's
                // centroid: curvature lines often run exactly along mesh
                // edges (a fillet meshed by a grid), and a streamline through
                // vertices would hinge on rounding.
                let [x, y, z] = mesh.corners(f as usize);
                let p = (2.0 * mesh.positions[v as usize] + (x + y + z) / 3.0) / 3.0;
                let range = trace(mesh, faces, edges, f, p, max_steps, inside);
                best = best.max(range);
            }
        }
    }
    best.to_degrees()
}

/// Traces the streamline of `a_max` from point `p` in face `f` (the
/// direction pointing into the face) until it leaves the region; returns
/// max − min of the prefix sums of signed normal turning.
fn trace(
    mesh: &TriMesh,
    faces: &[FaceCurvature],
    edges: &DirectedEdges,
    start: u32,
    p: DVec3,
    max_steps: usize,
    inside: &dyn Fn(Option<u32>) -> bool,
) -> f64 {
    let mut f = start as usize;
    let mut p = p;
    // Into the face: toward the centroid.
    let [a, b, c] = mesh.corners(f);
    let centre = (a + b + c) / 3.0;
    let mut d = faces[f].a_max;
    if d.dot(centre - p) < 0.0 {
        d = -d;
    }
    let (mut sum, mut lo, mut hi) = (0.0f64, 0.0f64, 0.0f64);
    let mut previous_edge: Option<(u32, u32)> = None;
    for _ in 0..max_steps {
        let t = mesh.triangles[f];
        let corners = mesh.corners(f);
        // Exit edge: the edge the ray p + s d crosses first (s > 0).
        let n = faces[f].normal;
        let mut exit: Option<(f64, usize)> = None;
        for k in 0..3 {
            let (ea, eb) = (t[k], t[(k + 1) % 3]);
            if previous_edge == Some((eb, ea)) {
                continue;
            }
            let (qa, qb) = (corners[k], corners[(k + 1) % 3]);
            // Solve p + s d = qa + u (qb − qa) in the face plane.
            let e = qb - qa;
            let denom = n.dot(d.cross(e));
            if denom.abs() < 1e-300 {
                continue;
            }
            let w = qa - p;
            let s = n.dot(w.cross(e)) / denom;
            let u = n.dot(w.cross(d)) / denom;
            if s > 1e-12
                && (-1e-9..=1.0 + 1e-9).contains(&u)
                && exit.is_none_or(|(best, _)| s < best)
            {
                exit = Some((s, k));
            }
        }
        let Some((s, k)) = exit else { break };
        p += s * d;
        let (ea, eb) = (t[k], t[(k + 1) % 3]);
        let next = edges.across(ea, eb);
        if !inside(next) {
            break;
        }
        let g = next.expect("inside implies a face") as usize;
        let (n1, n2) = (faces[f].normal, faces[g].normal);
        // Signed turning: positive when the normal tips forward along d.
        let beta = n1.dot(n2).clamp(-1.0, 1.0).acos();
        let sign = if n1.cross(n2).dot(n1.cross(d)) >= 0.0 {
            1.0
        } else {
            -1.0
        };
        sum += sign * beta;
        lo = lo.min(sum);
        hi = hi.max(sum);
        let transported = transport(d, n1, n2);
        d = faces[g].a_max;
        if d.dot(transported) < 0.0 {
            d = -d;
        }
        previous_edge = Some((ea, eb));
        f = g;
    }
    hi - lo
}

/// Walks region boundaries and vertex fans, measuring how `a_max` turns.
struct FanWalker<'a> {
    mesh: &'a TriMesh,
    faces: &'a [FaceCurvature],
    edges: &'a DirectedEdges,
    inside: &'a dyn Fn(Option<u32>) -> bool,
}

/// The angle of line field `a` relative to direction `e` in the plane with
/// normal `n`, counter-clockwise.
fn angle_in_plane(a: DVec3, e: DVec3, n: DVec3) -> f64 {
    n.dot(e.cross(a)).atan2(e.dot(a))
}

/// `x + kπ` closest to `target`.
fn lift(x: f64, target: f64) -> f64 {
    x + ((target - x) / std::f64::consts::PI).round() * std::f64::consts::PI
}

impl FanWalker<'_> {
    fn corner(&self, f: usize, v: u32) -> Option<usize> {
        self.mesh.triangles[f].iter().position(|&x| x == v)
    }

    /// True if a boundary loop of the region, or one of its interior
    /// vertices, has turning number zero; and the boundary loops that do,
    /// as their faces in walking order.
    fn zero_turning_loops(&self, members: &[u32]) -> (bool, Vec<Vec<u32>>) {
        let mean = members
            .iter()
            .map(|&f| self.faces[f as usize].normal)
            .sum::<DVec3>()
            .normalize_or_zero();
        let wide = members
            .iter()
            .any(|&f| self.faces[f as usize].normal.dot(mean) < std::f64::consts::FRAC_1_SQRT_2);
        let mut visited = std::collections::HashSet::new();
        let mut interior_checked = std::collections::HashSet::new();
        let mut loops = Vec::new();
        let mut cyclic = false;
        for &f in members {
            let t = self.mesh.triangles[f as usize];
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                if (self.inside)(self.edges.across(a, b)) {
                    continue;
                }
                if visited.contains(&(a, b)) {
                    continue;
                }
                let mut faces = Vec::new();
                if let Some(r) =
                    self.boundary_loop_rotation(f as usize, a, b, &mut visited, &mut faces)
                {
                    if wide && r.abs() < std::f64::consts::FRAC_PI_2 {
                        cyclic = true;
                        loops.push(faces);
                    }
                }
            }
            for &v in &t {
                // Around an interior vertex the loop tangent turns once; the
                // field turns with it (turning number zero relative to the
                // loop) exactly where its index is ±1 — the tip of a needle
                // with circular curvature lines around it.
                if !cyclic
                    && wide
                    && interior_checked.insert(v)
                    && self
                        .vertex_index(f as usize, v)
                        .is_some_and(|index| (index.abs() - 1.0).abs() < 0.25)
                {
                    cyclic = true;
                }
            }
        }
        (cyclic, loops)
    }

    /// Total rotation of `a_max` relative to the tangent of the region
    /// boundary loop through half-edge `a → b` (of region face `f`, region on
    /// its left); `2π ×` the turning number. `None` if the loop cannot be
    /// followed (non-manifold spots). `faces` receives the region faces
    /// walked, in order, each once per visit (consecutive ones share an edge).
    fn boundary_loop_rotation(
        &self,
        f: usize,
        a: u32,
        b: u32,
        visited: &mut std::collections::HashSet<(u32, u32)>,
        faces: &mut Vec<u32>,
    ) -> Option<f64> {
        let (start_f, start_a, start_b) = (f, a, b);
        let (mut f, mut a, mut b) = (f, a, b);
        let mut total = 0.0;
        let mut psi_prev: Option<f64> = None;
        let mut first_psi: Option<f64> = None;
        for _ in 0..4 * self.mesh.face_count() + 4 {
            visited.insert((a, b));
            if faces.last() != Some(&(f as u32)) {
                faces.push(f as u32);
            }
            // Relative angle at the start of vertex b: field in f against the
            // direction a → b.
            let pa = self.mesh.positions[a as usize];
            let pb = self.mesh.positions[b as usize];
            let n = self.faces[f].normal;
            // Fan coordinates at b: direction b → a at 0, clockwise negative.
            let field0 = angle_in_plane(self.faces[f].a_max, pa - pb, n);
            // The incoming tangent a → b points opposite b → a; walking
            // clockwise, its representative is −π (a straight boundary then
            // leaves at −Σα = −π: no turn).
            let psi_in_raw = field0 + std::f64::consts::PI;
            let psi_in = match psi_prev {
                Some(prev) => lift(psi_in_raw, prev),
                None => psi_in_raw,
            };
            if let Some(prev) = psi_prev {
                total += psi_in - prev;
            }
            if first_psi.is_none() {
                first_psi = Some(psi_in);
            }
            // Walk clockwise around b through region faces.
            let mut reference = 0.0;
            let mut field = field0;
            let mut face = f;
            let mut from = a;
            let next_edge;
            let mut guard = 0;
            loop {
                guard += 1;
                if guard > 64 {
                    return None;
                }
                let k = self.corner(face, b)?;
                let t = self.mesh.triangles[face];
                let c = t[(k + 1) % 3];
                debug_assert_eq!(t[(k + 2) % 3], from);
                let pc = self.mesh.positions[c as usize];
                let alpha = (pa_of(self.mesh, from) - pb).angle_between(pc - pb);
                reference -= alpha;
                // Crossing edge b → c.
                let across = self.edges.across(b, c);
                if !(self.inside)(across) {
                    next_edge = (b, c);
                    break;
                }
                let g = across.expect("inside implies a face") as usize;
                faces.push(g as u32);
                // Field of g relative to its edge b → c, at fan angle `reference`.
                let fg =
                    reference + angle_in_plane(self.faces[g].a_max, pc - pb, self.faces[g].normal);
                field = lift(fg, field);
                face = g;
                from = c;
            }
            let psi_out = field - reference;
            total += psi_out - psi_in;
            psi_prev = Some(psi_out);
            // Next boundary half-edge b → c in `face`.
            let (nb, nc) = next_edge;
            f = face;
            a = nb;
            b = nc;
            if f == start_f && a == start_a && b == start_b {
                if faces.len() > 1 && faces.last() == faces.first() {
                    faces.pop();
                }
                let closing = lift(first_psi?, psi_out);
                total += closing - psi_out;
                return Some(total);
            }
        }
        None
    }

    /// Index of the `a_max` line field at interior vertex `v` (all incident
    /// faces in the region), in turns; `None` on region boundaries.
    fn vertex_index(&self, f: usize, v: u32) -> Option<f64> {
        let k = self.corner(f, v)?;
        let t = self.mesh.triangles[f];
        let first_from = t[(k + 2) % 3];
        let pv = self.mesh.positions[v as usize];
        let (mut face, mut from) = (f, first_from);
        let mut reference = 0.0;
        let mut field = angle_in_plane(
            self.faces[f].a_max,
            pa_of(self.mesh, from) - pv,
            self.faces[f].normal,
        );
        let mut steps = 0.0;
        let mut angle_sum = 0.0;
        for _ in 0..64 {
            let k = self.corner(face, v)?;
            let t = self.mesh.triangles[face];
            let c = t[(k + 1) % 3];
            let pc = self.mesh.positions[c as usize];
            let alpha = (pa_of(self.mesh, from) - pv).angle_between(pc - pv);
            angle_sum += alpha;
            reference -= alpha;
            let across = self.edges.across(v, c);
            if !(self.inside)(across) {
                return None;
            }
            let g = across.expect("inside implies a face") as usize;
            let fg = reference + angle_in_plane(self.faces[g].a_max, pc - pv, self.faces[g].normal);
            let lifted = lift(fg, field);
            steps += lifted - field;
            field = lifted;
            face = g;
            from = c;
            if g == f {
                let defect = 2.0 * std::f64::consts::PI - angle_sum;
                return Some((steps - defect) / std::f64::consts::TAU);
            }
        }
        None
    }
}

fn pa_of(mesh: &TriMesh, v: u32) -> DVec3 {
    mesh.positions[v as usize]
}
