//! Quad mesh extraction from an integer-grid map in the manner of QEx
//! (Ebke, Bommes, Campen & Kobbelt 2013, as Ebke et al. 2014 §6 uses it;
//! `../shared/reference/integer-grid-maps-digest.md` §4):
//!
//! 1. *Sanitize*: every corner's (u, v) is put on a fixed-point lattice
//!    (2⁻²⁰), propagated around each vertex through the seam transitions
//!    with their translations rounded to integers, so that all wedges of a
//!    vertex agree exactly and every orientation decision below is exact
//!    (integer arithmetic, `i128` cross products).
//! 2. *Grid vertices*: the integer points of every triangle of positive
//!    parametric area, each found once: inside a face, on an edge (shared
//!    by two faces, keyed in the lower face's chart) or at a mesh vertex.
//!    Its 3D position is the barycentric interpolation.
//! 3. *Local edges*: from each grid vertex, the directions ±u, ±v that
//!    enter each incident triangle's half-open sector, in counter-clockwise
//!    order (at a cone their number is its valence).
//! 4. *Tracing*: each local edge follows its isoline across triangles
//!    (applying the transitions at seams, passing through mesh vertices by
//!    their sectors) until the integer point one unit away; two local
//!    edges whose traces meet each other form one quad-mesh edge.
//! 5. *Faces*: walking the half-edges (next = the edge just clockwise of
//!    the twin at the target) gives the faces; walks that run into a
//!    boundary are the boundary.
//!
//! Fold-overs (Ebke §6): first, the fold-overs that Tutte's embedding of
//! their neighbourhood removes are removed ([`unfold`]; cones and the
//! boundary stay). What is left is counted with its sign, as QEx does: a
//! grid point's local edges are the directions its star of triangles
//! covers a net positive number of times (a flipped triangle covers its
//! sector −1 times), so a grid point on a fold's crease has none and is no
//! vertex; traces cross flipped triangles as any other and pass points that
//! are no vertex, so a fold below the target scale is passed over.
//!
//! 6. *Holes*: the half-edge mesh keeps the manifold part; holes the
//!    extraction left away from the input's boundary (where a fold around
//!    a cone still broke a trace) are closed with quads
//!    ([`fill_extraction_holes`]); odd ones cannot be and are reported.

use std::collections::HashMap;

use glam::{DVec2, DVec3};

use crate::mesh::{FaceList, PolyMesh, TriMesh};
use crate::param::{Fan, GridMap, vertex_fans};
use crate::progress::{Cancelled, Progress};

/// What the extraction found and what it had to drop.
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize)]
pub struct QexReport {
    /// Integer points of the map that became vertices.
    pub grid_vertices: usize,
    /// Quad-mesh edges (pairs of traced local edges that met).
    pub edges: usize,
    /// Faces of the output.
    pub faces: usize,
    /// Triangles of negative or zero parametric area.
    pub flipped_triangles: usize,
    /// Local edges whose trace left the surface, or met no grid vertex.
    pub dead_traces: usize,
    /// Local edges whose trace met a grid vertex that traced elsewhere.
    pub unmatched_traces: usize,
    /// Closed half-edge walks that were not quads (dropped).
    pub non_quads_dropped: usize,
    /// Quads dropped to keep the mesh manifold.
    pub non_manifold_dropped: usize,
    /// Grid vertices left without a face (dropped).
    pub isolated_vertices: usize,
    /// Holes the extraction left (dropped or missing faces, away from the
    /// input's boundary) that were closed with quads.
    pub holes_filled: usize,
    /// Quads added to close them (and vertices added at the centres of
    /// the long ones).
    pub fill_quads: usize,
    pub fill_vertices: usize,
    /// Holes of odd length, which quads cannot close: left open.
    pub holes_left_open: usize,
    /// Holes around an input hole (an input boundary vertex within the
    /// hole's circumscribed ball): left open, as the input is.
    pub holes_at_input_boundary: usize,
    /// Parts of one to three quads next to a larger part (left where the
    /// map collapsed a small hole), removed.
    pub specks_removed: usize,
    /// V − E + F of the input and of the output: they differ where the
    /// map ironed over a handle below the target scale (Ebke §6) — or
    /// where folds the extraction could not resolve cut the surface.
    pub euler_characteristic: [i64; 2],
}

/// The extracted quad mesh, in the coordinates of the map's mesh.
#[derive(Debug, Clone)]
pub struct Quadrangulation {
    pub mesh: PolyMesh,
    pub report: QexReport,
}

/// Why no quad mesh came out.
#[derive(Debug, Clone, PartialEq)]
pub enum QexError {
    Cancelled,
    /// The map has no integer point (the target is too coarse for it).
    Empty,
    /// What was extracted could not be built into a manifold mesh.
    Invalid(String),
}

impl From<Cancelled> for QexError {
    fn from(_: Cancelled) -> QexError {
        QexError::Cancelled
    }
}

impl std::fmt::Display for QexError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            QexError::Cancelled => write!(f, "cancelled"),
            QexError::Empty => write!(
                f,
                "the integer-grid map has no quad (is the target vertex count too small?)"
            ),
            QexError::Invalid(m) => write!(f, "quad extraction failed: {m}"),
        }
    }
}

/// A point of the fixed-point parameter lattice: (u, v) · 2²⁰.
type P = [i64; 2];

const SCALE: i64 = 1 << 20;
/// Unit vectors of the four isoline directions +u, +v, −u, −v.
const DIRS: [P; 4] = [[SCALE, 0], [0, SCALE], [-SCALE, 0], [0, -SCALE]];

fn sub(a: P, b: P) -> P {
    [a[0] - b[0], a[1] - b[1]]
}

fn add(a: P, b: P) -> P {
    [a[0] + b[0], a[1] + b[1]]
}

fn cross(a: P, b: P) -> i128 {
    a[0] as i128 * b[1] as i128 - a[1] as i128 * b[0] as i128
}

fn dot(a: P, b: P) -> i128 {
    a[0] as i128 * b[0] as i128 + a[1] as i128 * b[1] as i128
}

fn orient(a: P, b: P, c: P) -> i128 {
    cross(sub(b, a), sub(c, a))
}

/// [`crate::param::rotate`] on lattice points.
fn rot(k: u8, x: P) -> P {
    match k % 4 {
        0 => x,
        1 => [x[1], -x[0]],
        2 => [-x[0], -x[1]],
        _ => [-x[1], x[0]],
    }
}

/// Direction index `d` rotated as [`rot`] rotates vectors.
fn rot_dir(k: u8, d: u8) -> u8 {
    (d + 4 - k % 4) % 4
}

/// x ↦ rot(k, x) + t, with t on the integer lattice.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Tr {
    k: u8,
    t: P,
}

impl Tr {
    fn apply(&self, x: P) -> P {
        add(rot(self.k, x), self.t)
    }
}

fn quantize(x: f64) -> i64 {
    let r = x.round();
    if (x - r).abs() < 1e-6 {
        r as i64 * SCALE
    } else {
        (x * SCALE as f64).round() as i64
    }
}

/// Where a grid vertex lies: its key in the vertex table.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
enum Loc {
    Face(u32),
    /// On local edge `.1` of face `.0` (the lower face of the edge).
    Edge(u32, u8),
    Vertex(u32),
}

/// A local edge: direction `dir` in the chart of `face`, leaving the grid
/// vertex at `at` (in that chart).
#[derive(Debug, Clone, Copy)]
struct Slot {
    face: u32,
    dir: u8,
    at: P,
    /// Unrolled quarter turn around the grid vertex.
    m: i64,
}

struct GridVertex {
    position: DVec3,
    /// Counter-clockwise.
    slots: Vec<Slot>,
    star: Star,
}

impl GridVertex {
    /// The slots go all the way round (no boundary).
    fn closed(&self) -> bool {
        self.star.period > 0
    }
}

/// Where a trace entered the current triangle.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Entry {
    Inside,
    Edge(u8),
    Corner(u8),
}

struct Extractor<'a> {
    mesh: &'a TriMesh,
    map: &'a GridMap,
    uv: Vec<[P; 3]>,
    /// Per face and local edge: the transition into the neighbour's chart.
    tr: Vec<[Option<Tr>; 3]>,
    /// Sign of each face's parametric area.
    sign: Vec<i8>,
    fans: Vec<Option<Fan>>,
    vertices: Vec<GridVertex>,
    table: HashMap<(Loc, P), u32>,
}

/// Extracts the quad mesh of `map` on `mesh` (the mesh the map was
/// computed on).
pub fn extract(
    mesh: &TriMesh,
    map: &GridMap,
    progress: &mut Progress<'_>,
) -> Result<Quadrangulation, QexError> {
    progress.report(0.0, "sanitizing the map")?;
    let mut x = Extractor::new(mesh, map);
    let mut report = QexReport {
        flipped_triangles: x.sign.iter().filter(|&&s| s <= 0).count(),
        ..QexReport::default()
    };
    progress.report(0.1, "grid vertices")?;
    x.find_grid_vertices();
    if x.vertices.is_empty() {
        return Err(QexError::Empty);
    }
    progress.report(0.3, "tracing isolines")?;
    // Per grid vertex and slot: where its trace ends.
    let mut ends: Vec<Vec<Option<(u32, u32)>>> = Vec::with_capacity(x.vertices.len());
    for g in 0..x.vertices.len() {
        if g % 4096 == 0 {
            progress.report(
                0.3 + 0.5 * g as f32 / x.vertices.len() as f32,
                "tracing isolines",
            )?;
        }
        let n = x.vertices[g].slots.len();
        ends.push((0..n).map(|s| x.trace(g as u32, s)).collect());
    }
    progress.report(0.8, "faces")?;
    // Half-edges: slots whose traces meet each other.
    let mut half_edge: Vec<Vec<u32>> = ends.iter().map(|e| vec![u32::MAX; e.len()]).collect();
    let mut he_from: Vec<(u32, u32)> = Vec::new();
    let mut he_to: Vec<(u32, u32)> = Vec::new();
    for g in 0..ends.len() {
        for s in 0..ends[g].len() {
            match ends[g][s] {
                None => report.dead_traces += 1,
                Some((h, t)) => {
                    if ends[h as usize][t as usize] == Some((g as u32, s as u32)) {
                        half_edge[g][s] = he_from.len() as u32;
                        he_from.push((g as u32, s as u32));
                        he_to.push((h, t));
                    } else {
                        report.unmatched_traces += 1;
                    }
                }
            }
        }
    }
    report.edges = he_from.len() / 2;
    // The rotation system: per grid vertex its paired slots in order.
    let paired: Vec<Vec<u32>> = half_edge
        .iter()
        .map(|hs| {
            (0..hs.len() as u32)
                .filter(|&s| hs[s as usize] != u32::MAX)
                .collect()
        })
        .collect();
    let next = |he: usize| -> Option<u32> {
        let (g, s) = he_to[he];
        let list = &paired[g as usize];
        let i = list.iter().position(|&t| t == s)?;
        let j = if i > 0 {
            i - 1
        } else if x.vertices[g as usize].closed() {
            list.len() - 1
        } else {
            return None;
        };
        Some(half_edge[g as usize][list[j] as usize])
    };
    let mut seen = vec![false; he_from.len()];
    let mut faces: Vec<[u32; 4]> = Vec::new();
    for start in 0..he_from.len() {
        if seen[start] {
            continue;
        }
        let mut orbit = vec![start];
        seen[start] = true;
        let mut closed = false;
        let mut at = start;
        while let Some(n) = next(at) {
            let n = n as usize;
            if n == start {
                closed = true;
                break;
            }
            if seen[n] || orbit.len() > 64 {
                break;
            }
            seen[n] = true;
            orbit.push(n);
            at = n;
        }
        if !closed {
            continue;
        }
        let corners: Vec<u32> = orbit.iter().map(|&h| he_from[h].0).collect();
        let distinct = {
            let mut c = corners.clone();
            c.sort_unstable();
            c.dedup();
            c.len()
        };
        if corners.len() == 4 && distinct == 4 {
            faces.push([corners[0], corners[1], corners[2], corners[3]]);
        } else {
            report.non_quads_dropped += 1;
        }
    }
    progress.report(0.9, "half-edge mesh")?;
    let positions: Vec<DVec3> = x.vertices.iter().map(|v| v.position).collect();
    let (out, dropped, kept) = manifold_mesh(positions, faces)?;
    report.non_manifold_dropped = dropped;
    report.isolated_vertices = x.vertices.len() - kept.len();
    let on_input_boundary: Vec<bool> = kept
        .iter()
        .map(|&g| x.vertices[g as usize].star.period == 0)
        .collect();
    let input_boundary: Vec<DVec3> = (0..mesh.triangles.len())
        .flat_map(|f| (0..3).map(move |e| (f, e)))
        .filter(|&(f, e)| map.topology.across(f, e).is_none())
        .map(|(f, e)| mesh.positions[mesh.triangles[f][e] as usize])
        .collect();
    let out = fill_extraction_holes(out, &on_input_boundary, &input_boundary, mesh, &mut report);
    let out = drop_specks(out, &mut report)?;
    report.grid_vertices = out.vertex_count();
    report.faces = out.face_count();
    report.euler_characteristic = [
        crate::mesh::Topology::of(
            mesh.positions.len(),
            &FaceList::from_triangles(&mesh.triangles),
        )
        .euler_characteristic,
        out.euler_characteristic(),
    ];
    progress.report(1.0, "done")?;
    Ok(Quadrangulation { mesh: out, report })
}

/// The half-edge mesh of `faces`, dropping faces that would make an edge
/// or a vertex non-manifold (later ones first) and unused vertices: the
/// mesh, the faces dropped, and per vertex its index in `positions`.
fn manifold_mesh(
    positions: Vec<DVec3>,
    faces: Vec<[u32; 4]>,
) -> Result<(PolyMesh, usize, Vec<u32>), QexError> {
    // An edge used twice in one direction or more than twice: keep the
    // first face.
    let mut directed: HashMap<(u32, u32), u32> = HashMap::new();
    let mut keep = vec![true; faces.len()];
    let mut dropped = 0;
    for (f, q) in faces.iter().enumerate() {
        let clash = (0..4).any(|i| directed.contains_key(&(q[i], q[(i + 1) % 4])));
        if clash {
            keep[f] = false;
            dropped += 1;
            continue;
        }
        for i in 0..4 {
            directed.insert((q[i], q[(i + 1) % 4]), f as u32);
        }
    }
    loop {
        let kept: Vec<[u32; 4]> = faces
            .iter()
            .zip(&keep)
            .filter(|&(_, &k)| k)
            .map(|(q, _)| *q)
            .collect();
        let mut used = vec![u32::MAX; positions.len()];
        let mut compact = Vec::new();
        for q in &kept {
            for &v in q {
                if used[v as usize] == u32::MAX {
                    used[v as usize] = compact.len() as u32;
                    compact.push(positions[v as usize]);
                }
            }
        }
        if kept.is_empty() {
            return Err(QexError::Empty);
        }
        let mut list = FaceList::new();
        for q in &kept {
            list.push(&q.map(|v| used[v as usize]));
        }
        let mut kept_vertices = vec![0u32; compact.len()];
        for (old, &new) in used.iter().enumerate() {
            if new != u32::MAX {
                kept_vertices[new as usize] = old as u32;
            }
        }
        match PolyMesh::from_faces(compact, &list) {
            Ok(mesh) => return Ok((mesh, dropped, kept_vertices)),
            Err(crate::mesh::MeshError::NonManifoldVertex { vertex }) => {
                // Drop the faces of the smaller fans at that vertex: here,
                // simply the last face using it.
                let original = used.iter().position(|&u| u == vertex).unwrap() as u32;
                let last = (0..faces.len())
                    .rev()
                    .find(|&f| keep[f] && faces[f].contains(&original))
                    .unwrap();
                keep[last] = false;
                dropped += 1;
            }
            Err(e) => return Err(QexError::Invalid(e.to_string())),
        }
    }
}

impl<'a> Extractor<'a> {
    fn new(mesh: &'a TriMesh, map: &'a GridMap) -> Extractor<'a> {
        let nf = mesh.triangles.len();
        let top = &map.topology;
        let mut tr = vec![[None; 3]; nf];
        for (f, row) in tr.iter_mut().enumerate() {
            for (e, slot) in row.iter_mut().enumerate() {
                if let Some((t, _)) = map.transition(f, e) {
                    *slot = Some(Tr {
                        k: t.k % 4,
                        t: [t.t.x.round() as i64 * SCALE, t.t.y.round() as i64 * SCALE],
                    });
                }
            }
        }
        // Make each transition the exact inverse of its twin's.
        for f in 0..nf {
            for e in 0..3 {
                if let (Some(t), Some((g, ge))) = (tr[f][e], top.across(f, e))
                    && g < f
                {
                    let k = (4 - t.k) % 4;
                    tr[g][ge] = Some(Tr {
                        k,
                        t: rot(k, [-t.t[0], -t.t[1]]),
                    });
                }
            }
        }
        let fans = vertex_fans(mesh, top);
        let mut relaxed = map.uv.clone();
        unfold(mesh, map, &tr, &fans, &mut relaxed);
        let map_uv = &relaxed;
        let mut uv = vec![[[0i64; 2]; 3]; nf];
        let mut done = vec![[false; 3]; nf];
        for fan in fans.iter().flatten() {
            let mut prev: Option<(u32, u8)> = None;
            for &(f, i) in &fan.corners {
                let (f, i) = (f as usize, i as usize);
                let value = match prev {
                    None => {
                        let w = map_uv[f][i];
                        [quantize(w.x), quantize(w.y)]
                    }
                    Some((pf, pi)) => {
                        // Across local edge pi + 2 of the previous face.
                        let (pf, pi) = (pf as usize, pi as usize);
                        match tr[pf][(pi + 2) % 3] {
                            Some(t) => t.apply(uv[pf][pi]),
                            None => {
                                let w = map_uv[f][i];
                                [quantize(w.x), quantize(w.y)]
                            }
                        }
                    }
                };
                uv[f][i] = value;
                done[f][i] = true;
                prev = Some((f as u32, i as u8));
            }
        }
        for f in 0..nf {
            for i in 0..3 {
                if !done[f][i] {
                    let w = map_uv[f][i];
                    uv[f][i] = [quantize(w.x), quantize(w.y)];
                }
            }
        }
        let sign = uv
            .iter()
            .map(|q| orient(q[0], q[1], q[2]).signum() as i8)
            .collect();
        Extractor {
            mesh,
            map,
            uv,
            tr,
            sign,
            fans,
            vertices: Vec::new(),
            table: HashMap::new(),
        }
    }

    fn corner_position(&self, f: usize, i: usize) -> DVec3 {
        self.mesh.positions[self.mesh.triangles[f][i] as usize]
    }

    /// The table key of the point `q` at `entry` of face `f`.
    fn key(&self, f: usize, q: P, entry: Entry) -> (Loc, P) {
        match entry {
            Entry::Inside => (Loc::Face(f as u32), q),
            Entry::Edge(e) => match self.map.topology.across(f, e as usize) {
                Some((g, ge)) if g < f => {
                    let t = self.tr[f][e as usize].expect("interior edge");
                    (Loc::Edge(g as u32, ge as u8), t.apply(q))
                }
                _ => (Loc::Edge(f as u32, e), q),
            },
            Entry::Corner(c) => (Loc::Vertex(self.mesh.triangles[f][c as usize]), [0, 0]),
        }
    }

    fn positive(&self, f: usize) -> bool {
        self.sign[f] > 0
    }

    fn find_grid_vertices(&mut self) {
        for f in 0..self.mesh.triangles.len() {
            if !self.positive(f) {
                continue;
            }
            let t = self.uv[f];
            let lo = |c: usize| t.iter().map(|p| p[c]).min().unwrap().div_euclid(SCALE);
            let hi = |c: usize| t.iter().map(|p| p[c]).max().unwrap().div_euclid(SCALE);
            for i in lo(0)..=hi(0) {
                for j in lo(1)..=hi(1) {
                    let q = [i * SCALE, j * SCALE];
                    let Some(entry) = self.locate_signed(f, q) else {
                        continue;
                    };
                    let key = self.key(f, q, entry);
                    if self.table.contains_key(&key) {
                        continue;
                    }
                    if let Some(v) = self.grid_vertex(f, q, entry) {
                        self.table.insert(key, self.vertices.len() as u32);
                        self.vertices.push(v);
                    }
                }
            }
        }
    }

    fn position(&self, f: usize, q: P) -> DVec3 {
        let t = &self.uv[f];
        let area = orient(t[0], t[1], t[2]) as f64;
        let b = [
            orient(t[1], t[2], q) as f64 / area,
            orient(t[2], t[0], q) as f64 / area,
            orient(t[0], t[1], q) as f64 / area,
        ];
        self.corner_position(f, 0) * b[0]
            + self.corner_position(f, 1) * b[1]
            + self.corner_position(f, 2) * b[2]
    }

    /// The star of a point: the wedges of the triangles around it, each
    /// with its sign, for the point inside face `f`, on its local edge, or
    /// at its corner. `None` at a non-manifold vertex.
    fn star(&self, f: usize, q: P, at: Entry) -> Option<Star> {
        let top = &self.map.topology;
        match at {
            Entry::Inside => Some(Star {
                wedges: vec![Wedge {
                    face: f as u32,
                    at: q,
                    r0: DIRS[0],
                    r1: DIRS[0],
                    phi: 0.0,
                    sign: self.sign[f],
                    kind: WedgeKind::Full,
                    include_end: true,
                }],
                period: 4,
                base: 0,
            }),
            Entry::Edge(e) => {
                let e = e as usize;
                let t = &self.uv[f];
                let ab = sub(t[(e + 1) % 3], t[e]);
                let ba = [-ab[0], -ab[1]];
                let phi = (ab[1] as f64).atan2(ab[0] as f64);
                let pi = std::f64::consts::PI;
                let other = top.across(f, e);
                let open = other.is_none();
                let mut wedges = vec![Wedge {
                    face: f as u32,
                    at: q,
                    r0: if self.sign[f] > 0 { ab } else { ba },
                    r1: if self.sign[f] > 0 { ba } else { ab },
                    phi: if self.sign[f] > 0 { phi } else { phi + pi },
                    sign: self.sign[f],
                    kind: WedgeKind::Half,
                    include_end: open,
                }];
                if let Some((g, ge)) = other {
                    let tg = &self.uv[g];
                    // g's edge runs from b to a.
                    let ba_g = sub(tg[(ge + 1) % 3], tg[ge]);
                    let ab_g = [-ba_g[0], -ba_g[1]];
                    wedges.push(Wedge {
                        face: g as u32,
                        at: self.tr[f][e]?.apply(q),
                        r0: if self.sign[g] > 0 { ba_g } else { ab_g },
                        r1: if self.sign[g] > 0 { ab_g } else { ba_g },
                        phi: if self.sign[g] > 0 { phi + pi } else { phi },
                        sign: self.sign[g],
                        kind: WedgeKind::Half,
                        include_end: false,
                    });
                }
                Some(Star {
                    wedges,
                    period: if open { 0 } else { 4 },
                    base: quarter_floor(phi),
                })
            }
            Entry::Corner(c) => {
                let v = self.mesh.triangles[f][c as usize];
                let fan = self.fans[v as usize].as_ref()?;
                let n = fan.corners.len();
                let mut wedges = Vec::with_capacity(n);
                let (h0, c0) = (fan.corners[0].0 as usize, fan.corners[0].1 as usize);
                let r = sub(self.uv[h0][(c0 + 1) % 3], self.uv[h0][c0]);
                let phi0 = (r[1] as f64).atan2(r[0] as f64);
                let mut phi = phi0;
                for (j, &(h, hc)) in fan.corners.iter().enumerate() {
                    let (h, hc) = (h as usize, hc as usize);
                    let t = &self.uv[h];
                    let r1 = sub(t[(hc + 1) % 3], t[hc]);
                    let r2 = sub(t[(hc + 2) % 3], t[hc]);
                    let theta = (cross(r1, r2) as f64).atan2(dot(r1, r2) as f64);
                    let end_open = !fan.closed;
                    match self.sign[h] {
                        1 => wedges.push(Wedge {
                            face: h as u32,
                            at: t[hc],
                            r0: r1,
                            r1: r2,
                            phi,
                            sign: 1,
                            kind: WedgeKind::Sector,
                            include_end: end_open && j + 1 == n,
                        }),
                        -1 => wedges.push(Wedge {
                            face: h as u32,
                            at: t[hc],
                            r0: r2,
                            r1,
                            phi: phi + theta,
                            sign: -1,
                            kind: WedgeKind::Sector,
                            include_end: end_open && j == 0,
                        }),
                        _ => {}
                    }
                    phi += theta;
                }
                let period = if fan.closed {
                    ((phi - phi0) / std::f64::consts::FRAC_PI_2).round() as i64
                } else {
                    0
                };
                Some(Star {
                    wedges,
                    period,
                    base: quarter_floor(phi0),
                })
            }
        }
    }

    fn grid_vertex(&self, f: usize, q: P, at: Entry) -> Option<GridVertex> {
        let star = self.star(f, q, at)?;
        // Winding count per unrolled quarter turn.
        let mut count: std::collections::BTreeMap<i64, (i32, Option<Slot>)> = Default::default();
        for w in &star.wedges {
            for dir in 0..4u8 {
                if !w.contains(DIRS[dir as usize], false) {
                    continue;
                }
                let m = star.normalize(w.quarter(DIRS[dir as usize]));
                let entry = count.entry(m).or_insert((0, None));
                entry.0 += w.sign as i32;
                if w.sign > 0 && entry.1.is_none() {
                    entry.1 = Some(Slot {
                        face: w.face,
                        dir,
                        at: w.at,
                        m,
                    });
                }
            }
        }
        let slots: Vec<Slot> = count
            .into_values()
            .filter(|(c, _)| *c > 0)
            .filter_map(|(_, s)| s)
            .collect();
        if slots.is_empty() {
            return None;
        }
        let position = match at {
            Entry::Corner(c) => self.corner_position(f, c as usize),
            _ => self.position(f, q),
        };
        Some(GridVertex {
            position,
            slots,
            star,
        })
    }

    /// Where `q` lies in the closed face `f` (either orientation, not
    /// degenerate).
    fn locate_signed(&self, f: usize, q: P) -> Option<Entry> {
        if self.sign[f] == 0 {
            return None;
        }
        let t = &self.uv[f];
        let s = self.sign[f] as i128;
        let o = [
            s * orient(t[0], t[1], q),
            s * orient(t[1], t[2], q),
            s * orient(t[2], t[0], q),
        ];
        if o.iter().any(|&x| x < 0) {
            return None;
        }
        let zeros: Vec<usize> = (0..3).filter(|&e| o[e] == 0).collect();
        Some(match zeros.as_slice() {
            [] => Entry::Inside,
            [e] => Entry::Edge(*e as u8),
            [a, b] => Entry::Corner(if (a + 2) % 3 == *b { *a } else { *b } as u8),
            _ => return None,
        })
    }

    /// Follows slot `s` of grid vertex `g` along its isoline to the next
    /// integer point that is a grid vertex: that vertex and its slot
    /// pointing back.
    fn trace(&self, g: u32, s: usize) -> Option<(u32, u32)> {
        let top = &self.map.topology;
        let slot = self.vertices[g as usize].slots[s];
        let mut f = slot.face as usize;
        let mut d = slot.dir;
        let start = slot.at;
        let mut q = add(start, DIRS[d as usize]);
        let mut entry = self.locate_signed(f, start)?;
        for _ in 0..self.mesh.triangles.len().min(100_000) {
            if let Some(at) = self.locate_signed(f, q)
                && let Some(&target) = self.table.get(&self.key(f, q, at))
            {
                return self.slot_back(target, f, d);
            }
            // The isoline: coordinate `a` constant, moving along `m`.
            let a = if d % 2 == 0 { 1 } else { 0 };
            let m = 1 - a;
            let forward = if d < 2 { 1.0 } else { -1.0 };
            let c = q[a];
            let t = &self.uv[f];
            let side = [
                (t[0][a] - c).signum(),
                (t[1][a] - c).signum(),
                (t[2][a] - c).signum(),
            ];
            // The isoline's features in this face with their moving
            // coordinate: corners on it and edges it crosses.
            let mut features: Vec<(Entry, f64)> = Vec::with_capacity(3);
            for i in 0..3 {
                if side[i] == 0 {
                    features.push((Entry::Corner(i as u8), t[i][m] as f64));
                }
            }
            for e in 0..3 {
                let (i, j) = (e, (e + 1) % 3);
                if side[i] * side[j] < 0 {
                    let (pi, pj) = (t[i], t[j]);
                    let w = (c - pi[a]) as f64 / (pj[a] - pi[a]) as f64;
                    let x = pi[m] as f64 + w * (pj[m] - pi[m]) as f64;
                    features.push((Entry::Edge(e as u8), x));
                }
            }
            let exit = match entry {
                Entry::Inside => features
                    .iter()
                    .filter(|(_, x)| (x - start[m] as f64) * forward > 0.0)
                    .max_by(|p, q| (p.1 * forward).total_cmp(&(q.1 * forward)))
                    .map(|p| p.0),
                _ => features
                    .iter()
                    .filter(|(e, _)| *e != entry)
                    .max_by(|p, q| (p.1 * forward).total_cmp(&(q.1 * forward)))
                    .map(|p| p.0),
            }?;
            match exit {
                Entry::Edge(e) => {
                    let (h, he) = top.across(f, e as usize)?;
                    let t = self.tr[f][e as usize]?;
                    q = t.apply(q);
                    d = rot_dir(t.k, d);
                    f = h;
                    entry = Entry::Edge(he as u8);
                }
                Entry::Corner(i) => {
                    let i = i as usize;
                    if self.uv[f][i] == q {
                        let key = (Loc::Vertex(self.mesh.triangles[f][i]), [0, 0]);
                        if let Some(&target) = self.table.get(&key) {
                            return self.slot_back(target, f, d);
                        }
                    }
                    let (h, hc, t) = self.through_vertex(f, i, d)?;
                    q = t.apply(q);
                    d = rot_dir(t.k, d);
                    f = h;
                    entry = Entry::Corner(hc as u8);
                }
                Entry::Inside => return None,
            }
        }
        None
    }

    /// The face around the vertex at corner `i` of `f` into which the
    /// direction `d` (in `f`'s chart) continues (a positive one where
    /// there is one), its corner of the vertex, and the transition from
    /// `f`'s chart to its chart.
    fn through_vertex(&self, f: usize, i: usize, d: u8) -> Option<(usize, usize, Tr)> {
        let v = self.mesh.triangles[f][i];
        let fan = self.fans[v as usize].as_ref()?;
        let star = self.star(f, self.uv[f][i], Entry::Corner(i as u8))?;
        let n = fan.corners.len();
        let start = fan.corners.iter().position(|&(h, _)| h as usize == f)?;
        // Transitions from f's chart into each fan face's, walking
        // counter-clockwise, then clockwise where the fan is open.
        let mut charts: Vec<Option<Tr>> = vec![None; n];
        charts[start] = Some(Tr { k: 0, t: [0, 0] });
        let mut walk = |step: isize| {
            let mut j = start;
            let mut acc = Tr { k: 0, t: [0, 0] };
            for _ in 1..n {
                let next = (j as isize + step).rem_euclid(n as isize) as usize;
                if !fan.closed && ((step > 0 && next <= j) || (step < 0 && next >= j)) {
                    break;
                }
                let (h, hc) = (fan.corners[j].0 as usize, fan.corners[j].1 as usize);
                // Counter-clockwise crosses local edge hc + 2, clockwise hc.
                let e = if step > 0 { (hc + 2) % 3 } else { hc };
                let Some(t) = self.tr[h][e] else { break };
                acc = Tr {
                    k: (t.k + acc.k) % 4,
                    t: add(rot(t.k, acc.t), t.t),
                };
                if charts[next].is_none() {
                    charts[next] = Some(acc);
                }
                j = next;
            }
        };
        walk(1);
        walk(-1);
        let mut negative = None;
        for w in &star.wedges {
            let Some(j) = fan.corners.iter().position(|&(h, _)| h == w.face) else {
                continue;
            };
            let Some(t) = charts[j] else { continue };
            let dh = rot_dir(t.k, d);
            if !w.contains(DIRS[dh as usize], false) {
                continue;
            }
            let hc = fan.corners[j].1 as usize;
            if w.sign > 0 {
                return Some((w.face as usize, hc, t));
            }
            negative.get_or_insert((w.face as usize, hc, t));
        }
        negative
    }

    /// Grid vertex `target`'s slot pointing back along direction `d`
    /// (in the chart of face `f`, which the trace arrived through).
    fn slot_back(&self, target: u32, f: usize, d: u8) -> Option<(u32, u32)> {
        let back = DIRS[((d + 2) % 4) as usize];
        let v = &self.vertices[target as usize];
        for w in v.star.wedges.iter().filter(|w| w.face as usize == f) {
            if w.contains(back, true) {
                let m = v.star.normalize(w.quarter(back));
                if let Some(s) = v.slots.iter().position(|s| s.m == m) {
                    return Some((target, s as u32));
                }
            }
        }
        None
    }
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum WedgeKind {
    /// A triangle's corner: less than a half-turn.
    Sector,
    /// A triangle's side of an edge.
    Half,
    /// Inside a triangle.
    Full,
}

/// The part of a star one triangle covers: from ray `r0` counter-clockwise
/// to ray `r1` (in the triangle's chart), `r0` included, `r1` only when
/// `include_end` (on the boundary), counted with the triangle's sign;
/// `phi` is the unrolled angle of `r0` around the point.
#[derive(Debug, Clone, Copy)]
struct Wedge {
    face: u32,
    /// The point in the triangle's chart.
    at: P,
    r0: P,
    r1: P,
    phi: f64,
    sign: i8,
    kind: WedgeKind,
    include_end: bool,
}

impl Wedge {
    /// Whether direction `w` lies in the wedge (the end ray too when
    /// `closed`).
    fn contains(&self, w: P, closed: bool) -> bool {
        if self.kind == WedgeKind::Full {
            return true;
        }
        let c0 = cross(self.r0, w);
        let c1 = cross(w, self.r1);
        let on_start = c0 == 0 && dot(self.r0, w) > 0;
        let on_end = c1 == 0 && dot(self.r1, w) > 0;
        let inside = match self.kind {
            WedgeKind::Half => c0 > 0,
            _ => c0 > 0 && c1 > 0,
        };
        inside || on_start || ((self.include_end || closed) && on_end)
    }

    /// The unrolled quarter turn of direction `w` (an axis direction in
    /// the wedge).
    fn quarter(&self, w: P) -> i64 {
        let mut a = (cross(self.r0, w) as f64).atan2(dot(self.r0, w) as f64);
        if a < 0.0 {
            a += std::f64::consts::TAU;
        }
        ((self.phi + a) / std::f64::consts::FRAC_PI_2).round() as i64
    }
}

/// The triangles around a grid point.
#[derive(Debug, Clone)]
struct Star {
    wedges: Vec<Wedge>,
    /// Quarter turns once round (0 where the star is open).
    period: i64,
    /// Start of the window quarter turns are reduced to.
    base: i64,
}

impl Star {
    fn normalize(&self, m: i64) -> i64 {
        if self.period > 0 {
            self.base + (m - self.base).rem_euclid(self.period)
        } else {
            m
        }
    }
}

fn quarter_floor(phi: f64) -> i64 {
    (phi / std::f64::consts::FRAC_PI_2).floor() as i64
}

/// Fan transforms of a vertex: from the chart of its fan's first face into
/// each fan face's chart (f64 form of the exact transitions).
fn fan_charts(fan: &Fan, tr: &[[Option<Tr>; 3]]) -> Option<Vec<(u8, DVec2)>> {
    let mut out = Vec::with_capacity(fan.corners.len());
    let (mut k, mut t) = (0u8, DVec2::ZERO);
    for j in 0..fan.corners.len() {
        if j > 0 {
            let (ph, pc) = fan.corners[j - 1];
            let step = tr[ph as usize][(pc as usize + 2) % 3]?;
            let st = DVec2::new(step.t[0] as f64, step.t[1] as f64) / SCALE as f64;
            t = crate::param::rotate(step.k, t) + st;
            k = (k + step.k) % 4;
        }
        out.push((k, t));
    }
    Some(out)
}

/// Removes the fold-overs of the map where it can: the interior vertices
/// (not cones, not on the boundary) of flipped triangles and of up to
/// three rings around them are moved, by Gauss–Seidel sweeps of the
/// uniform Laplacian in their own chart, to the mean of their neighbours
/// (Tutte's embedding of the fold's neighbourhood, the rest of the map
/// fixed). Corners of one vertex stay related by the exact transitions.
fn unfold(
    mesh: &TriMesh,
    map: &GridMap,
    tr: &[[Option<Tr>; 3]],
    fans: &[Option<Fan>],
    uv: &mut [[DVec2; 3]],
) {
    let flipped = |uv: &[[DVec2; 3]], f: usize| {
        let q = uv[f];
        (q[1] - q[0]).perp_dot(q[2] - q[0]) <= 0.0
    };
    let nv = mesh.positions.len();
    let mut fixed = vec![false; nv];
    for c in &map.cones {
        fixed[c.vertex as usize] = true;
    }
    let charts: Vec<Option<Vec<(u8, DVec2)>>> = fans
        .iter()
        .map(|fan| {
            fan.as_ref()
                .filter(|f| f.closed)
                .and_then(|f| fan_charts(f, tr))
        })
        .collect();
    for rings in 1..=3 {
        let mut region = vec![false; nv];
        let mut any = false;
        for (f, t) in mesh.triangles.iter().enumerate() {
            if flipped(uv, f) {
                for &v in t {
                    region[v as usize] = true;
                    any = true;
                }
            }
        }
        if !any {
            return;
        }
        for _ in 0..rings {
            let mut grown = region.clone();
            for t in &mesh.triangles {
                if t.iter().any(|&v| region[v as usize]) {
                    for &v in t {
                        grown[v as usize] = true;
                    }
                }
            }
            region = grown;
        }
        let free: Vec<usize> = (0..nv)
            .filter(|&v| region[v] && !fixed[v] && charts[v].is_some())
            .collect();
        if free.is_empty() {
            return;
        }
        for _ in 0..50 {
            for &v in &free {
                let fan = fans[v].as_ref().unwrap();
                let chart = charts[v].as_ref().unwrap();
                let mut sum = DVec2::ZERO;
                for (&(h, c), &(k, t)) in fan.corners.iter().zip(chart) {
                    let (h, c) = (h as usize, c as usize);
                    for x in [uv[h][(c + 1) % 3], uv[h][(c + 2) % 3]] {
                        // Into the first face's chart: rotate back.
                        sum += crate::param::rotate((4 - k) % 4, x - t);
                    }
                }
                let mean = sum / (2 * fan.corners.len()) as f64;
                for (&(h, c), &(k, t)) in fan.corners.iter().zip(chart) {
                    uv[h as usize][c as usize] = crate::param::rotate(k, mean) + t;
                }
            }
        }
    }
}

/// Odd holes in pairs: a quad mesh's hole can only be closed with quads
/// when its ring is even, and two odd holes change parity together along
/// a path of faces between them (the usual parity fix: a quad crossed
/// between opposite edges splits into two quads, one crossed between
/// adjacent edges into three around a new vertex). The path is the
/// cheapest chain of edges from a rim edge of one hole to a rim edge of
/// the other through shared faces (a straight crossing costs 1, a turn 3,
/// since it adds a valence-3 and a valence-5 vertex); every edge on it
/// gets its midpoint, so each rim gains a vertex and both rings become
/// even. The first odd hole left pairs with the one its cheapest path
/// reaches, until fewer than two are left; an odd hole without a partner
/// (or whose path would cross a face twice) stays open and is counted in
/// `QexReport::holes_left_open`. A hole left open on a closed input is a
/// hole in the output where the input has none, which is why both are
/// filled rather than left.
fn pair_odd_holes(
    faces: &mut Vec<Vec<u32>>,
    positions: &mut Vec<DVec3>,
    rings: &mut [Vec<u32>],
    report: &mut QexReport,
) {
    use crate::mesh::edge_key as key;
    use std::cmp::Reverse;
    use std::collections::{BinaryHeap, HashMap};
    loop {
        let odd: Vec<usize> = (0..rings.len())
            .filter(|&r| rings[r].len() % 2 == 1)
            .collect();
        if odd.len() < 2 {
            report.holes_left_open += odd.len();
            return;
        }
        // Faces per edge, and each odd rim edge's ring.
        let edge_faces = crate::mesh::edge_faces(faces);
        let mut rim: HashMap<(u32, u32), usize> = HashMap::new();
        for &r in &odd {
            let ring = &rings[r];
            for i in 0..ring.len() {
                rim.insert(key(ring[i], ring[(i + 1) % ring.len()]), r);
            }
        }
        // Dijkstra over edges from the first odd hole's rim to any other's.
        let source = odd[0];
        // Per edge: the path cost and the edge and face it came from.
        type Edge = (u32, u32);
        let mut best: HashMap<Edge, (u32, Option<(Edge, usize)>)> = HashMap::new();
        let mut heap = BinaryHeap::new();
        for (&e, &r) in &rim {
            if r == source {
                best.insert(e, (0, None));
                heap.push(Reverse((0u32, e)));
            }
        }
        let mut found = None;
        while let Some(Reverse((cost, e))) = heap.pop() {
            if best.get(&e).is_some_and(|&(c, _)| c < cost) {
                continue;
            }
            if let Some(&r) = rim.get(&e)
                && r != source
            {
                found = Some((e, r));
                break;
            }
            for &fi in edge_faces.get(&e).map_or(&[][..], |v| v) {
                let f = &faces[fi];
                if f.len() != 4 || best[&e].1.is_some_and(|(_, from)| from == fi) {
                    continue;
                }
                let i = (0..4).find(|&i| key(f[i], f[(i + 1) % 4]) == e).unwrap();
                for j in 1..4 {
                    let k = (i + j) % 4;
                    let next = key(f[k], f[(k + 1) % 4]);
                    let step = if j == 2 { 1 } else { 3 };
                    let c = cost + step;
                    // Rim edges of the source hole only start paths.
                    if rim.get(&next) == Some(&source) {
                        continue;
                    }
                    if best.get(&next).is_none_or(|&(b, _)| c < b) {
                        best.insert(next, (c, Some((e, fi))));
                        heap.push(Reverse((c, next)));
                    }
                }
            }
        }
        let Some((end, partner)) = found else {
            report.holes_left_open += odd.len();
            return;
        };
        // The path: edges and the face between each consecutive pair.
        let mut path = vec![end];
        let mut between = Vec::new();
        while let Some((prev, fi)) = best[path.last().unwrap()].1 {
            between.push(fi);
            path.push(prev);
        }
        let mut seen = between.clone();
        seen.sort_unstable();
        seen.dedup();
        if seen.len() != between.len() {
            // A face crossed twice: no clean split; leave both open.
            report.holes_left_open += odd.len();
            return;
        }
        let mut mid: HashMap<(u32, u32), u32> = HashMap::new();
        for &(a, b) in &path {
            positions.push(0.5 * (positions[a as usize] + positions[b as usize]));
            mid.insert((a, b), positions.len() as u32 - 1);
        }
        let mut dead = vec![false; faces.len()];
        let mut added: Vec<Vec<u32>> = Vec::new();
        for &fi in &between {
            let f = faces[fi].clone();
            let cut: Vec<usize> = (0..4)
                .filter(|&i| mid.contains_key(&key(f[i], f[(i + 1) % 4])))
                .collect();
            let [i, j] = cut[..] else {
                report.holes_left_open += odd.len();
                return;
            };
            let m = |i: usize| mid[&key(f[i], f[(i + 1) % 4])];
            dead[fi] = true;
            if j == i + 2 {
                // Opposite edges i and i + 2.
                added.push(vec![f[i], m(i), m(j), f[(j + 1) % 4]]);
                added.push(vec![m(i), f[i + 1], f[j], m(j)]);
            } else {
                // Adjacent edges: rotate so they are 0 and 1 (or 3 and 0).
                let (a, b) = if j == i + 1 { (i, j) } else { (j, i) };
                let r = |k: usize| f[(a + k) % 4];
                positions.push(0.25 * (0..4).map(|k| positions[f[k] as usize]).sum::<DVec3>());
                let o = positions.len() as u32 - 1;
                let (m1, m2) = (m(a), m(b));
                added.push(vec![r(0), m1, o, r(3)]);
                added.push(vec![m1, r(1), m2, o]);
                added.push(vec![m2, r(2), r(3), o]);
            }
        }
        let mut k = 0;
        faces.retain(|_| {
            k += 1;
            !dead[k - 1]
        });
        faces.extend(added);
        // Both rims gain their edge's midpoint.
        for (r, e) in [(source, path[path.len() - 1]), (partner, end)] {
            let ring = &mut rings[r];
            let n = ring.len();
            let i = (0..n)
                .find(|&i| key(ring[i], ring[(i + 1) % n]) == e)
                .unwrap();
            ring.insert(i + 1, mid[&e]);
        }
    }
}

/// Closes each boundary loop of `mesh` that is not (mostly) on the input's
/// boundary with quads: the best quadrangulation of the loop's ring
/// ([`super::faces::best_quadrangulation`], Kloiber's quad score, no chord
/// that is already an edge) when it has an even length up to 16, else
/// quads around a new vertex at its centroid (every other ring vertex);
/// odd loops stay open (quads cannot close them) and are reported.
fn fill_extraction_holes(
    mesh: PolyMesh,
    on_input_boundary: &[bool],
    input_boundary: &[DVec3],
    input: &TriMesh,
    report: &mut QexReport,
) -> PolyMesh {
    let mut rings: Vec<Vec<u32>> = Vec::new();
    for h in mesh.boundary_loops() {
        let ring: Vec<u32> = mesh.loop_from(h).map(|g| mesh.origin(g)).collect();
        let on = ring
            .iter()
            .filter(|&&v| on_input_boundary[v as usize])
            .count();
        if 2 * on >= ring.len() {
            continue;
        }
        // A hole around an input hole the map collapsed (its rim on no
        // isoline of its own) is that input hole: kept open.
        let centre = ring
            .iter()
            .map(|&v| mesh.positions[v as usize])
            .sum::<DVec3>()
            / ring.len() as f64;
        let radius = ring
            .iter()
            .map(|&v| mesh.positions[v as usize].distance(centre))
            .fold(0.0, f64::max);
        if input_boundary.iter().any(|p| p.distance(centre) <= radius) {
            report.holes_at_input_boundary += 1;
            continue;
        }
        rings.push(ring);
    }
    let mut positions = mesh.positions.clone();
    let mut faces: Vec<Vec<u32>> = mesh.to_face_list().iter().map(<[u32]>::to_vec).collect();
    let before = positions.len();
    pair_odd_holes(&mut faces, &mut positions, &mut rings, report);
    let mut surface: Option<Option<crate::spatial::SurfaceIndex>> = None;
    if positions.len() > before {
        let index = surface.get_or_insert_with(|| crate::spatial::SurfaceIndex::new(input));
        if let Some(index) = index {
            for p in &mut positions[before..] {
                *p = index.closest(*p).point;
            }
        }
    }
    rings.retain(|r| r.len() % 2 == 0);
    if rings.is_empty() && positions.len() == mesh.positions.len() {
        return mesh;
    }
    let mut list = crate::mesh::FaceList::new();
    for f in &faces {
        list.push(f);
    }
    let edges = crate::mesh::edge_faces(&faces);
    let (mut quads, mut added, mut filled) = (0, 0, 0);
    for ring in &rings {
        let n = ring.len();
        let fill = if n == 4 {
            Some(vec![[ring[0], ring[1], ring[2], ring[3]]])
        } else if n <= 16 {
            let pos = &positions;
            super::faces::best_quadrangulation(ring, &mut |q: [u32; 4]| {
                let chord = |a: u32, b: u32| edges.contains_key(&crate::mesh::edge_key(a, b));
                // A quad's chords are its edges between non-consecutive
                // ring corners; consecutive ones are boundary edges.
                let consecutive = |a: u32, b: u32| {
                    let i = ring.iter().position(|&v| v == a).unwrap();
                    ring[(i + 1) % n] == b
                };
                let bad = (0..4).any(|i| {
                    let (a, b) = (q[i], q[(i + 1) % 4]);
                    !consecutive(a, b) && chord(a, b)
                });
                (!bad).then(|| super::faces::quad_score(pos, q))
            })
        } else {
            None
        };
        let fill = fill.unwrap_or_else(|| {
            let c = positions.len() as u32;
            let centre = ring.iter().map(|&v| positions[v as usize]).sum::<DVec3>() / n as f64;
            let index = surface.get_or_insert_with(|| crate::spatial::SurfaceIndex::new(input));
            positions.push(index.as_ref().map_or(centre, |s| s.closest(centre).point));
            added += 1;
            (0..n / 2)
                .map(|i| [ring[2 * i], ring[2 * i + 1], ring[(2 * i + 2) % n], c])
                .collect()
        });
        for q in &fill {
            list.push(q);
        }
        quads += fill.len();
        filled += 1;
    }
    match PolyMesh::from_faces(positions, &list) {
        Ok(filled_mesh) => {
            report.holes_filled += filled;
            report.fill_quads += quads;
            report.fill_vertices += added;
            filled_mesh
        }
        Err(_) => {
            report.holes_left_open += filled;
            mesh
        }
    }
}

/// Removes the parts of fewer than four quads when a larger part exists:
/// what remains of a collapsed small hole's rim, not a part of the input
/// (the preservation metrics report an input part that is lost).
fn drop_specks(mesh: PolyMesh, report: &mut QexReport) -> Result<PolyMesh, QexError> {
    let faces: Vec<Vec<u32>> = (0..mesh.face_count() as u32)
        .map(|f| mesh.face_vertices(f).collect())
        .collect();
    let (roots, sizes) = super::repair::face_components(&faces);
    let largest = sizes.values().copied().max().unwrap_or(0);
    let speck = |f: usize| sizes[&roots[f]] < 4 && largest >= 4;
    let specks: std::collections::HashSet<u32> = (0..faces.len())
        .filter(|&f| speck(f))
        .map(|f| roots[f])
        .collect();
    if specks.is_empty() {
        return Ok(mesh);
    }
    report.specks_removed = specks.len();
    let kept: Vec<[u32; 4]> = (0..faces.len())
        .filter(|&f| !speck(f))
        .map(|f| [faces[f][0], faces[f][1], faces[f][2], faces[f][3]])
        .collect();
    let (out, _, _) = manifold_mesh(mesh.positions.clone(), kept)?;
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A flat 7 × 5 grid of unit quads with the quads at (1, 2) and (5, 2)
    /// removed, and a vertex added on each hole's outer rim edge (x = 1
    /// and x = 6), so both rings have five edges; the quads beyond them
    /// become pentagons.
    fn grid_with_two_odd_holes() -> (Vec<Vec<u32>>, Vec<DVec3>, Vec<Vec<u32>>) {
        let id = |x: u32, y: u32| y * 8 + x;
        let mut positions: Vec<DVec3> = (0..6)
            .flat_map(|y| (0..8).map(move |x| DVec3::new(x as f64, y as f64, 0.0)))
            .collect();
        positions.push(DVec3::new(1.0, 2.5, 0.0)); // 48
        positions.push(DVec3::new(6.0, 2.5, 0.0)); // 49
        let mut faces = Vec::new();
        for y in 0..5 {
            for x in 0..7 {
                let q = vec![id(x, y), id(x + 1, y), id(x + 1, y + 1), id(x, y + 1)];
                match (x, y) {
                    (1, 2) | (5, 2) => {}
                    (0, 2) => faces.push(vec![q[0], q[1], 48, q[2], q[3]]),
                    (6, 2) => faces.push(vec![q[0], q[1], q[2], q[3], 49]),
                    _ => faces.push(q),
                }
            }
        }
        let rings = vec![
            vec![id(1, 2), 48, id(1, 3), id(2, 3), id(2, 2)],
            vec![id(5, 2), id(5, 3), id(6, 3), 49, id(6, 2)],
        ];
        (faces, positions, rings)
    }

    #[test]
    fn two_odd_holes_become_even_along_the_quads_between_them() {
        let (mut faces, mut positions, mut rings) = grid_with_two_odd_holes();
        let before = faces.len();
        let mut report = QexReport::default();
        pair_odd_holes(&mut faces, &mut positions, &mut rings, &mut report);
        assert_eq!(report.holes_left_open, 0);
        assert_eq!(rings.iter().map(Vec::len).collect::<Vec<_>>(), [6, 6]);
        // The cheapest path runs straight along row 2, through the quads
        // at x = 2, 3, 4: the four vertical edges x = 2…5 get their
        // midpoints and each quad crossed splits into two.
        let mut added: Vec<DVec3> = positions[50..].to_vec();
        added.sort_by(|a, b| a.x.total_cmp(&b.x));
        let expected: Vec<DVec3> = (2..6).map(|x| DVec3::new(x as f64, 2.5, 0.0)).collect();
        assert_eq!(added, expected);
        assert_eq!(faces.len(), before + 3);
        assert_eq!(
            faces.iter().filter(|f| f.len() != 4).count(),
            2,
            "the two pentagons"
        );
        let mut list = crate::mesh::FaceList::new();
        for f in &faces {
            list.push(f);
        }
        let mesh = PolyMesh::from_faces(positions, &list).expect("a valid mesh");
        let mut lengths: Vec<usize> = mesh
            .boundary_loops()
            .iter()
            .map(|&h| mesh.loop_from(h).count())
            .collect();
        lengths.sort_unstable();
        assert_eq!(
            lengths,
            [6, 6, 24],
            "the two even holes and the outer boundary"
        );
    }

    #[test]
    fn one_odd_hole_stays_open_and_is_counted() {
        let (mut faces, mut positions, mut rings) = grid_with_two_odd_holes();
        rings.truncate(1);
        let mut report = QexReport::default();
        pair_odd_holes(&mut faces, &mut positions, &mut rings, &mut report);
        assert_eq!(report.holes_left_open, 1);
        assert_eq!(rings[0].len(), 5);
        assert_eq!(positions.len(), 50);
    }
}
