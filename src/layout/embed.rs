//! Dual loops as curves on the triangulation (Campen & Kobbelt 2014, §6.1
//! and §4.2 need every loop as the sequence of mesh edges it crosses): the
//! shared representation of the strip field, the parametrization, the
//! regions between loops and the primal layout.
//!
//! [`embed_loop`] traces a [`DualLoop`](super::DualLoop) polyline (which runs
//! through mesh vertices) into edge crossings. Deviations from the paper
//! (which does not describe this step): the polyline is sampled finely,
//! every sample is projected to its closest triangle, and consecutive
//! triangles are joined through the dual graph; samples at a vertex are
//! skipped and the walk goes around the vertex on the shorter side of its
//! triangle fan (the curve is perturbed off the vertex; crossings next to it
//! get `t` = 0.02 or 0.98). Immediate back-and-forth across one edge is
//! removed.

use std::collections::{HashMap, VecDeque};

use glam::DVec3;

use crate::mesh::{TriMesh, VertexFaces};
use crate::spatial::SurfaceIndex;

/// Dual-graph steps within which two consecutive samples' faces are joined.
const CONNECT_DEPTH: u32 = 16;
/// A sample whose closest face is farther than that is re-snapped to the
/// closest face within this many steps of the previous sample's face.
const RESNAP_DEPTH: u32 = 8;

/// Where a loop crosses a mesh edge: the point `(1 − t)·p[a] + t·p[b]` on
/// the undirected edge `{a, b}` with `a < b`, `t` strictly inside (0, 1).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EdgeCrossing {
    pub a: u32,
    pub b: u32,
    pub t: f64,
}

impl EdgeCrossing {
    /// The crossing point in world coordinates.
    pub fn point(&self, mesh: &TriMesh) -> DVec3 {
        mesh.positions[self.a as usize].lerp(mesh.positions[self.b as usize], self.t)
    }
}

/// A dual loop (closed) or dual curve (open: from a boundary edge to a
/// boundary edge) traced on the triangulation.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct EmbeddedLoop {
    /// Consecutive edge crossings along the loop.
    pub crossings: Vec<EdgeCrossing>,
    /// `faces[i]` is the triangle holding the segment from `crossings[i]`
    /// to `crossings[i + 1]` (index taken mod n when closed): n entries when
    /// closed, n − 1 when open.
    pub faces: Vec<u32>,
    pub closed: bool,
}

impl EmbeddedLoop {
    /// The segments `(face, from, to)` of the walk.
    /// (Segments without both crossings, in a malformed loop, are skipped.)
    pub fn segments(&self) -> impl Iterator<Item = (u32, EdgeCrossing, EdgeCrossing)> + '_ {
        let n = self.crossings.len().max(1);
        self.faces.iter().enumerate().filter_map(move |(i, &f)| {
            Some((
                f,
                *self.crossings.get(i)?,
                *self.crossings.get((i + 1) % n)?,
            ))
        })
    }

    /// Checks that the loop is a valid walk on `mesh`: the face count
    /// matches, every face holds both of its crossings' edges and they are
    /// two different edges, and every `t` lies strictly inside (0, 1).
    pub fn check(&self, mesh: &TriMesh) -> Result<(), String> {
        let n = self.crossings.len();
        let expected = if self.closed { n } else { n.saturating_sub(1) };
        if self.faces.len() != expected || (self.closed && n < 2) {
            return Err(format!("{n} crossings but {} faces", self.faces.len()));
        }
        for c in &self.crossings {
            if c.a >= c.b || c.b as usize >= mesh.positions.len() || !(c.t > 0.0 && c.t < 1.0) {
                return Err(format!("bad crossing {c:?}"));
            }
        }
        for (i, (f, c0, c1)) in self.segments().enumerate() {
            let Some(t) = mesh.triangles.get(f as usize) else {
                return Err(format!("segment {i}: no face {f}"));
            };
            let has = |c: &EdgeCrossing| t.contains(&c.a) && t.contains(&c.b);
            if !has(&c0) || !has(&c1) {
                return Err(format!(
                    "segment {i}: face {f} {t:?} lacks {c0:?} or {c1:?}"
                ));
            }
            if (c0.a, c0.b) == (c1.a, c1.b) {
                return Err(format!("segment {i}: edge {}-{} crossed twice", c0.a, c0.b));
            }
        }
        Ok(())
    }
}

/// A singularity of a cross field at a mesh vertex: `index` in quarter
/// turns (+1: the field turns by +π/2 around the vertex, a valence-3-like
/// corner; −1: valence 5).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Singularity {
    pub vertex: u32,
    pub index: i32,
}

/// Why a polyline could not be embedded.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum EmbedError {
    #[error("the mesh has no triangles")]
    EmptyMesh,
    #[error("the polyline has fewer than two distinct points")]
    TooShort,
    #[error("the polyline jumps between faces {0} and {1}, which are not close on the mesh")]
    Gap(u32, u32),
    #[error("the polyline has a non-finite point")]
    NotFinite,
    #[error("the walk collapsed to fewer than two crossings")]
    Degenerate,
}

pub(crate) use crate::param::topology::EdgeTopology;

/// Traces polylines on one mesh (builds the closest-point index once).
pub struct LoopEmbedder<'a> {
    mesh: &'a TriMesh,
    index: SurfaceIndex,
    topology: EdgeTopology,
    vertex_faces: VertexFaces,
    /// Sampling step (a quarter of the mean edge length).
    step: f64,
}

impl<'a> LoopEmbedder<'a> {
    pub fn new(mesh: &'a TriMesh) -> Result<LoopEmbedder<'a>, EmbedError> {
        let index = SurfaceIndex::new(mesh).ok_or(EmbedError::EmptyMesh)?;
        let mut total = 0.0;
        for t in &mesh.triangles {
            for i in 0..3 {
                total +=
                    mesh.positions[t[i] as usize].distance(mesh.positions[t[(i + 1) % 3] as usize]);
            }
        }
        let mean_edge = total / (3 * mesh.triangles.len()) as f64;
        Ok(LoopEmbedder {
            mesh,
            index,
            topology: EdgeTopology::new(mesh),
            vertex_faces: VertexFaces::new(mesh),
            step: (0.25 * mean_edge).max(f64::MIN_POSITIVE),
        })
    }

    /// See [`embed_loop`].
    pub fn embed(&self, points: &[DVec3], closed: bool) -> Result<EmbeddedLoop, EmbedError> {
        let mesh = self.mesh;
        if points.iter().any(|p| !p.is_finite()) {
            return Err(EmbedError::NotFinite);
        }
        // 1. Faces of fine samples, skipping samples at vertices.
        let near_vertex = 1e-3 * self.step;
        let mut visits: Vec<(u32, DVec3)> = Vec::new();
        let sample = |p: DVec3, visits: &mut Vec<(u32, DVec3)>| {
            let c = self.index.closest(p);
            let t = mesh.triangles[c.face as usize];
            if t.iter()
                .any(|&v| mesh.positions[v as usize].distance(c.point) < near_vertex)
            {
                return;
            }
            if visits.last().is_none_or(|l| l.0 != c.face) {
                visits.push((c.face, c.point));
            }
        };
        for w in points.windows(2) {
            let n = ((w[0].distance(w[1]) / self.step).ceil() as usize).clamp(1, 100_000);
            for k in 0..n {
                sample(w[0].lerp(w[1], k as f64 / n as f64), &mut visits);
            }
        }
        if let Some(&last) = points.last() {
            sample(last, &mut visits);
        }
        if closed && visits.len() > 1 && visits[0].0 == visits[visits.len() - 1].0 {
            visits.pop();
        }
        if visits.len() < 2 {
            return Err(EmbedError::TooShort);
        }
        // 2. A face path through the dual graph; 3. without back-and-forth.
        // Each entry: (face, start, end) of the polyline piece it stands for:
        // a sample point twice, or for faces inserted between two samples
        // the segment between them.
        let mut path: Vec<(u32, DVec3, DVec3)> = Vec::with_capacity(visits.len() * 2);
        let push = |path: &mut Vec<(u32, DVec3, DVec3)>, item: (u32, DVec3, DVec3)| {
            if path.last().is_some_and(|l| l.0 == item.0) {
                return;
            }
            if path.len() >= 2 && path[path.len() - 2].0 == item.0 {
                path.pop();
                return;
            }
            path.push(item);
        };
        let m = visits.len();
        let links = if closed { m } else { m - 1 };
        push(&mut path, (visits[0].0, visits[0].1, visits[0].1));
        for i in 0..links {
            let (f, p) = visits[i];
            let (mut g, q) = visits[(i + 1) % m];
            let between = match self.connect(f, g) {
                Ok(between) => between,
                // The sample's closest face lies across a thin part of the
                // surface (the chord passed through it): take the closest
                // face near the previous one instead.
                Err(e) if (i + 1) % m != 0 => {
                    g = self.nearest_face_near(f, q).ok_or(e)?;
                    visits[i + 1].0 = g;
                    self.connect(f, g)?
                }
                Err(e) => return Err(e),
            };
            for h in between {
                push(&mut path, (h, p, q));
            }
            push(&mut path, (g, q, q));
        }
        if closed {
            loop {
                let n = path.len();
                if n >= 2 && path[0].0 == path[n - 1].0 {
                    path.pop();
                } else if n >= 3 && path[1].0 == path[n - 1].0 {
                    path.remove(0);
                    path.pop();
                } else {
                    break;
                }
            }
        }
        // An open curve starts and ends at a boundary vertex; the samples
        // next to it may lie in a face of its fan without a boundary edge:
        // walk the fan to the nearest boundary edge at that vertex.
        if !closed && !path.is_empty() {
            let (first, last) = (points[0], points[points.len() - 1]);
            let head = self.fan_to_boundary(path[0].0, first);
            let tail = self.fan_to_boundary(path[path.len() - 1].0, last);
            if !head.is_empty() || !tail.is_empty() {
                let middle = std::mem::take(&mut path);
                for h in head {
                    push(&mut path, (h, first, first));
                }
                for item in middle {
                    push(&mut path, item);
                }
                for h in tail.into_iter().rev() {
                    push(&mut path, (h, last, last));
                }
            }
        }
        if path.len() < 2 {
            return Err(EmbedError::Degenerate);
        }
        // 4. Crossings on the shared edges.
        let n = path.len();
        let pairs = if closed { n } else { n - 1 };
        let mut crossings = Vec::with_capacity(pairs + 2);
        if !closed && let Some(c) = self.boundary_crossing(path[0].0, points[0]) {
            crossings.push(c);
        }
        for j in 0..pairs {
            let (f, p, _) = path[j];
            let (g, _, q) = path[(j + 1) % n];
            let e = self
                .topology
                .shared_edge(f, g)
                .ok_or(EmbedError::Gap(f, g))?;
            let t = mesh.triangles[f as usize];
            crossings.push(self.crossing(t[e], t[(e + 1) % 3], p, q));
        }
        let mut faces: Vec<u32> = if closed {
            (0..n).map(|j| path[(j + 1) % n].0).collect()
        } else {
            path[1..n - 1].iter().map(|x| x.0).collect()
        };
        if !closed {
            if crossings.len() > pairs {
                faces.insert(0, path[0].0);
            }
            if let Some(c) = self.boundary_crossing(path[n - 1].0, points[points.len() - 1]) {
                crossings.push(c);
                faces.push(path[n - 1].0);
            }
        }
        let l = EmbeddedLoop {
            crossings,
            faces,
            closed,
        };
        if l.crossings.len() < 2 {
            return Err(EmbedError::Degenerate);
        }
        Ok(l)
    }

    /// Faces strictly between `f` and `g` on a short dual path (empty when
    /// they share an edge): around a shared vertex on the side with fewer
    /// faces, else a breadth-first search of depth ≤ 8.
    fn connect(&self, f: u32, g: u32) -> Result<Vec<u32>, EmbedError> {
        let mesh = self.mesh;
        if f == g || self.topology.shared_edge(f, g).is_some() {
            return Ok(Vec::new());
        }
        let (tf, tg) = (mesh.triangles[f as usize], mesh.triangles[g as usize]);
        if let Some(&v) = tf.iter().find(|v| tg.contains(v)) {
            if let Some(fan) = self.fan_path(v, f, g) {
                return Ok(fan);
            }
        }
        // Breadth-first search in the dual graph.
        let mut parent: HashMap<u32, u32> = HashMap::from([(f, f)]);
        let mut queue = VecDeque::from([(f, 0)]);
        while let Some((h, depth)) = queue.pop_front() {
            if depth >= CONNECT_DEPTH {
                continue;
            }
            for &k in &self.topology.opposite[h as usize] {
                if k == u32::MAX || parent.contains_key(&k) {
                    continue;
                }
                parent.insert(k, h);
                if k == g {
                    let mut out = Vec::new();
                    let mut cur = h;
                    while cur != f {
                        out.push(cur);
                        cur = parent.get(&cur).copied().unwrap_or(f);
                    }
                    out.reverse();
                    return Ok(out);
                }
                queue.push_back((k, depth + 1));
            }
        }
        Err(EmbedError::Gap(f, g))
    }

    /// The face closest to `q` among the faces within `RESNAP_DEPTH` dual
    /// steps of `f`.
    fn nearest_face_near(&self, f: u32, q: DVec3) -> Option<u32> {
        use parry3d_f64::query::PointQuery;
        let mut seen: HashMap<u32, ()> = HashMap::from([(f, ())]);
        let mut queue = VecDeque::from([(f, 0)]);
        let mut best: Option<(f64, u32)> = None;
        while let Some((h, depth)) = queue.pop_front() {
            let [a, b, c] = self.mesh.corners(h as usize);
            let d = parry3d_f64::shape::Triangle::new(a, b, c).distance_to_local_point(q, true);
            if best.is_none_or(|(bd, _)| d < bd) {
                best = Some((d, h));
            }
            if depth >= RESNAP_DEPTH {
                continue;
            }
            for &k in &self.topology.opposite[h as usize] {
                if k != u32::MAX && seen.insert(k, ()).is_none() {
                    queue.push_back((k, depth + 1));
                }
            }
        }
        best.map(|(_, h)| h)
    }

    /// Faces strictly between `f` and `g` around vertex `v`, the shorter
    /// way round (None if the fan is broken between them both ways).
    fn fan_path(&self, v: u32, f: u32, g: u32) -> Option<Vec<u32>> {
        let around = self.vertex_faces.faces(v as usize);
        let mut best: Option<Vec<u32>> = None;
        for first in self.neighbours_in_fan(f, v) {
            let mut way = Vec::new();
            let (mut prev, mut cur) = (f, first);
            while cur != g && way.len() <= around.len() {
                way.push(cur);
                let Some(next) = self
                    .neighbours_in_fan(cur, v)
                    .into_iter()
                    .find(|&h| h != prev)
                else {
                    way.clear();
                    break;
                };
                (prev, cur) = (cur, next);
            }
            if cur == g && best.as_ref().is_none_or(|b| way.len() < b.len()) {
                best = Some(way);
            }
        }
        best
    }

    /// For an open curve ending in face `f` whose end point `p` is a mesh
    /// vertex on the boundary: when `f` has no boundary edge at that vertex,
    /// the faces from a face of the vertex's fan that has one up to
    /// (without) `f`, boundary face first; empty otherwise.
    fn fan_to_boundary(&self, f: u32, p: DVec3) -> Vec<u32> {
        let mesh = self.mesh;
        let opposite = &self.topology.opposite;
        let boundary_edge_at = |h: u32, v: u32| {
            let t = mesh.triangles[h as usize];
            (0..3)
                .any(|i| (t[i] == v || t[(i + 1) % 3] == v) && opposite[h as usize][i] == u32::MAX)
        };
        // The end vertex: the corner of the face closest to p nearest to p.
        let c = self.index.closest(p);
        let Some(&v) = mesh.triangles[c.face as usize].iter().min_by(|&&a, &&b| {
            let d = |x: u32| mesh.positions[x as usize].distance_squared(p);
            d(a).total_cmp(&d(b))
        }) else {
            return Vec::new();
        };
        if boundary_edge_at(f, v) || opposite[f as usize].contains(&u32::MAX) {
            return Vec::new();
        }
        let around = self.vertex_faces.faces(v as usize);
        let Some(&start) = around.iter().find(|&&h| boundary_edge_at(h, v)) else {
            return Vec::new();
        };
        let mut way = vec![start];
        way.extend(self.connect(start, f).unwrap_or_default());
        if way.len() > 1 || self.topology.shared_edge(start, f).is_some() {
            way
        } else {
            Vec::new()
        }
    }

    /// The (up to two) faces across the edges of `f` at vertex `v`.
    fn neighbours_in_fan(&self, f: u32, v: u32) -> Vec<u32> {
        let t = self.mesh.triangles[f as usize];
        (0..3)
            .filter(|&i| t[i] == v || t[(i + 1) % 3] == v)
            .map(|i| self.topology.opposite[f as usize][i])
            .filter(|&h| h != u32::MAX)
            .collect()
    }

    /// The crossing of edge {a, b} closest to the segment p–q.
    fn crossing(&self, a: u32, b: u32, p: DVec3, q: DVec3) -> EdgeCrossing {
        let (a, b) = (a.min(b), a.max(b));
        let (pa, pb) = (
            self.mesh.positions[a as usize],
            self.mesh.positions[b as usize],
        );
        let t = segment_parameter(pa, pb, p, q);
        EdgeCrossing {
            a,
            b,
            t: t.clamp(0.02, 0.98),
        }
    }

    /// For an open curve starting or ending in face `f` near `p`: the
    /// crossing on the boundary edge of `f` closest to `p`, if any.
    fn boundary_crossing(&self, f: u32, p: DVec3) -> Option<EdgeCrossing> {
        let t = self.mesh.triangles[f as usize];
        (0..3)
            .filter(|&i| self.topology.opposite[f as usize][i] == u32::MAX)
            .map(|i| self.crossing(t[i], t[(i + 1) % 3], p, p))
            .min_by(|x, y| {
                let d = |c: &EdgeCrossing| c.point(self.mesh).distance(p);
                d(x).total_cmp(&d(y))
            })
    }
}

/// Parameter s of the point `a + s·(b − a)` of segment a–b closest to the
/// segment p–q.
fn segment_parameter(a: DVec3, b: DVec3, p: DVec3, q: DVec3) -> f64 {
    let (d1, d2, r) = (b - a, q - p, a - p);
    let (aa, ee, f) = (d1.dot(d1), d2.dot(d2), d2.dot(r));
    if aa <= f64::MIN_POSITIVE {
        return 0.5;
    }
    let c = d1.dot(r);
    if ee <= f64::MIN_POSITIVE {
        return (-c / aa).clamp(0.0, 1.0);
    }
    let bb = d1.dot(d2);
    let denom = aa * ee - bb * bb;
    let mut s = if denom > 1e-12 * aa * ee {
        ((bb * f - c * ee) / denom).clamp(0.0, 1.0)
    } else {
        0.5
    };
    let t = (bb * s + f) / ee;
    if t < 0.0 {
        s = (-c / aa).clamp(0.0, 1.0);
    } else if t > 1.0 {
        s = ((bb - c) / aa).clamp(0.0, 1.0);
    }
    s
}

/// Traces a polyline on the surface (e.g. [`DualLoop::points`](super::DualLoop):
/// through mesh vertices and face points; a closed loop repeats its first
/// point last) into the sequence of edges it crosses. See the module docs.
pub fn embed_loop(
    mesh: &TriMesh,
    points: &[DVec3],
    closed: bool,
) -> Result<EmbeddedLoop, EmbedError> {
    LoopEmbedder::new(mesh)?.embed(points, closed)
}
