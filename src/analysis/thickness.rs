//! Thin parts: the local thickness of a closed surface and the edge-length
//! cap it implies.
//!
//! Not from the seeds. The thesis' sizing (Kloiber §3.2) follows curvature,
//! and the default is Instant Meshes' uniform scale; neither sees that a
//! part thinner than a few target edges (a teapot's handle, a cow's legs at
//! a coarse target) cannot be sampled by them: it gets two to six traced
//! faces and is lost, which is the Hausdorff distance docs/QUALITY.md
//! measured on those meshes. Here the thickness is the shape diameter (Shapira
//! et al. 2008): the median length of rays cast into the solid, in a cone
//! around the inward normal, to where they leave it. A part of thickness d
//! has a cross-section of circumference about π d; `edges_around` edges
//! around it give the cap `x ≤ π d / edges_around`. The cap is graded: from
//! each capped vertex it grows by `gradation` per unit of surface distance
//! (Dijkstra over the mesh edges), so lengths change by a bounded factor
//! over a bounded distance instead of jumping.
//!
//! Where no ray leaves the solid (open sheets, inward-facing normals, holes)
//! there is no cap, so the field is unchanged there.
//!
//! The second local feature size here is the width of the surface between
//! two boundary loops ([`boundary_loop_gap`]), for the global mode's map
//! (Ebke et al. 2014 §5, `../shared/seeds/000_…`: boundary edges lie on
//! integer isolines). Two holes whose strip is narrower than an edge put
//! their isolines less than a unit apart, the rounding gives them one
//! integer, and the strip collapses: the holes merge (the bunny's two
//! bottom holes, perimeters 13 and 14 target edges, 1.04 edges apart). The
//! cap asks for the strip to be `separation` target edges wide in the
//! map; each of its two isolines moves by at most half a unit in the
//! rounding, so 2 would keep them a unit apart if the map followed the
//! cap exactly (it follows it only in part: the default is 4,
//! `param::Params::loop_separation` has the figures). The same graded
//! Dijkstra ([`graded_cap`]) spreads it.

use std::cmp::Reverse;
use std::collections::BinaryHeap;

use glam::DVec3;

use crate::mesh::{BoundaryArcs, OrdF64, TriMesh, VertexAdjacency, VertexFaces};
use crate::spatial::SurfaceIndex;

/// The cap never goes below this multiple of the field's own length: at a
/// coarse target a part can be too thin for any budget (a cow's legs at
/// 181 vertices), and the calibration would take the vertices from the
/// rest of the surface. 0.35 allows about 8× the surrounding density.
pub const FLOOR: f64 = 0.35;

/// Boundary loops shorter than this many target edges get no loop-gap
/// cap ([`loop_gap_cap`]): a quad's perimeter, the shortest hole a quad
/// mesh keeps.
pub const MIN_LOOP_EDGES: f64 = 4.0;

/// Rays per vertex: the inward normal and a ring around it.
const RING: usize = 6;
/// The ring's angle from the inward normal (Shapira et al. use a 120° cone;
/// a narrower one keeps the rays on the cross-section of a tube).
const RING_DEGREES: f64 = 20.0;

/// The shape diameter per vertex (`f64::INFINITY` where at least half of
/// the rays do not leave the solid through an outward-facing triangle).
pub fn shape_diameter(mesh: &TriMesh, normals: &[DVec3], index: &SurfaceIndex) -> Vec<f64> {
    let extent = mesh.bbox().map_or(1.0, |b| b.largest_axis());
    let offset = 1e-7 * extent;
    let max_t = 2.0 * extent;
    let incident = VertexFaces::new(mesh);
    mesh.positions
        .iter()
        .zip(normals)
        .enumerate()
        .map(|(v, (&p, &n))| {
            let n = n.normalize_or_zero();
            if n == DVec3::ZERO {
                return f64::INFINITY;
            }
            let inward = -n;
            let (a, b) = inward.any_orthonormal_pair();
            let (sin, cos) = RING_DEGREES.to_radians().sin_cos();
            let mut lengths: Vec<f64> = Vec::with_capacity(RING + 1);
            let rays = std::iter::once(inward).chain((0..RING).map(|k| {
                let phi = std::f64::consts::TAU * k as f64 / RING as f64;
                cos * inward + sin * (phi.cos() * a + phi.sin() * b)
            }));
            for d in rays {
                let origin = p + offset * d;
                if let Some(hit) = index.ray(origin, d, max_t) {
                    let face = index.closest(hit.point).face;
                    // Leaving the solid: the far wall faces along the ray,
                    // and it is not the vertex's own fan (a ray from a
                    // concave vertex grazes its neighbours at once).
                    if index.face_normal(face).dot(d) > 0.0 && !incident.faces(v).contains(&face) {
                        lengths.push(hit.t + offset);
                    }
                }
            }
            if 2 * lengths.len() < RING + 1 {
                return f64::INFINITY;
            }
            lengths.sort_by(f64::total_cmp);
            lengths[lengths.len() / 2]
        })
        .collect()
}

/// The graded cap: `max(π d_i / edges_around, floor · edge_length_i)` at
/// the vertices where it is below `edge_length`, grown by `gradation` per unit of distance along the mesh
/// edges. `None` when no vertex is capped (the field stays as it is).
pub fn thin_part_cap(
    mesh: &TriMesh,
    adjacency: &VertexAdjacency,
    diameter: &[f64],
    edge_length: &[f64],
    edges_around: f64,
    floor: f64,
    gradation: f64,
) -> Option<Vec<f64>> {
    let seeds: Vec<f64> = diameter
        .iter()
        .zip(edge_length)
        .map(|(&d, &s)| {
            let c = (std::f64::consts::PI * d / edges_around).max(floor * s);
            if c < s { c } else { f64::INFINITY }
        })
        .collect();
    graded_cap(mesh, adjacency, seeds, gradation)
}

/// The cap from per-vertex seed values (`f64::INFINITY`: no cap there),
/// grown by `gradation` per unit of distance along the mesh edges; `None`
/// when no vertex has a seed.
pub fn graded_cap(
    mesh: &TriMesh,
    adjacency: &VertexAdjacency,
    mut cap: Vec<f64>,
    gradation: f64,
) -> Option<Vec<f64>> {
    if cap.iter().all(|c| !c.is_finite()) {
        return None;
    }
    // Dijkstra from every capped vertex at once.
    let mut heap: BinaryHeap<(Reverse<OrdF64>, usize)> = cap
        .iter()
        .enumerate()
        .filter(|(_, c)| c.is_finite())
        .map(|(v, &c)| (Reverse(OrdF64(c)), v))
        .collect();
    let gradation = gradation.max(0.0);
    while let Some((Reverse(OrdF64(c)), v)) = heap.pop() {
        if c > cap[v] {
            continue;
        }
        for &w in adjacency.neighbors(v) {
            let w = w as usize;
            let next = c + gradation * mesh.positions[v].distance(mesh.positions[w]);
            if next < cap[w] {
                cap[w] = next;
                heap.push((Reverse(OrdF64(next)), w));
            }
        }
    }
    Some(cap)
}

/// Per vertex, the width of the surface between two boundary loops there:
/// d₁ + d₂, the distances along the mesh edges to the nearest boundary
/// loop and to the nearest other loop (Dijkstra from every boundary vertex
/// at once, each vertex keeping its two nearest distinct loops). Inside a
/// strip between two loops it is the strip's width; it grows away from the
/// strip. `f64::INFINITY` where fewer than two loops are reachable.
pub fn boundary_loop_gap(
    mesh: &TriMesh,
    adjacency: &VertexAdjacency,
    arcs: &BoundaryArcs,
) -> Vec<f64> {
    const NO_LOOP: u32 = u32::MAX;
    let n = mesh.positions.len();
    // The two nearest distinct loops per vertex, nearest first.
    let mut best = vec![[(f64::INFINITY, NO_LOOP); 2]; n];
    fn offer(slot: &mut [(f64, u32); 2], d: f64, l: u32) -> bool {
        if slot[0].1 == l {
            if d < slot[0].0 {
                slot[0].0 = d;
                return true;
            }
            return false;
        }
        if slot[1].1 == l {
            if d < slot[1].0 {
                slot[1].0 = d;
                if slot[1].0 < slot[0].0 {
                    slot.swap(0, 1);
                }
                return true;
            }
            return false;
        }
        if d < slot[0].0 {
            slot[1] = slot[0];
            slot[0] = (d, l);
            true
        } else if d < slot[1].0 {
            slot[1] = (d, l);
            true
        } else {
            false
        }
    }
    let mut heap: BinaryHeap<(Reverse<OrdF64>, usize, u32)> = BinaryHeap::new();
    for (v, &l) in arcs.loop_of.iter().enumerate().take(n) {
        if l != NO_LOOP && offer(&mut best[v], 0.0, l) {
            heap.push((Reverse(OrdF64(0.0)), v, l));
        }
    }
    while let Some((Reverse(OrdF64(d)), v, l)) = heap.pop() {
        if !best[v].contains(&(d, l)) {
            continue;
        }
        for &w in adjacency.neighbors(v) {
            let w = w as usize;
            let next = d + mesh.positions[v].distance(mesh.positions[w]);
            if offer(&mut best[w], next, l) {
                heap.push((Reverse(OrdF64(next)), w, l));
            }
        }
    }
    best.iter().map(|b| b[0].0 + b[1].0).collect()
}

/// The boundary-loop cap: `max(gap / separation, floor · edge_length)`
/// where that is below `edge_length` ([`boundary_loop_gap`] between the
/// loops at least [`MIN_LOOP_EDGES`] long), graded as [`thin_part_cap`].
/// `None` when no vertex is capped.
pub fn loop_gap_cap(
    mesh: &TriMesh,
    adjacency: &VertexAdjacency,
    edge_length: &[f64],
    separation: f64,
    floor: f64,
    gradation: f64,
) -> Option<Vec<f64>> {
    if !(separation.is_finite() && separation > 0.0) {
        return None;
    }
    // Only loops at least one quad's perimeter long (4 target edges, by
    // the field's mean length on them): a shorter one is below the
    // target scale, and refining around it would spend the budget on
    // detail the quads cannot keep.
    let mut arcs = BoundaryArcs::new(mesh);
    let mut sum = vec![(0.0, 0usize); arcs.length.len()];
    for (v, &l) in arcs.loop_of.iter().enumerate() {
        if let (Some(acc), Some(&s)) = (sum.get_mut(l as usize), edge_length.get(v)) {
            acc.0 += s;
            acc.1 += 1;
        }
    }
    let short: Vec<bool> = arcs
        .length
        .iter()
        .zip(&sum)
        .map(|(&len, &(s, k))| k == 0 || len * k as f64 / s < MIN_LOOP_EDGES)
        .collect();
    for l in &mut arcs.loop_of {
        if short.get(*l as usize).copied().unwrap_or(false) {
            *l = u32::MAX;
        }
    }
    let gap = boundary_loop_gap(mesh, adjacency, &arcs);
    let seeds: Vec<f64> = gap
        .iter()
        .zip(edge_length)
        .map(|(&g, &s)| {
            let c = (g / separation).max(floor * s);
            if c < s { c } else { f64::INFINITY }
        })
        .collect();
    graded_cap(mesh, adjacency, seeds, gradation)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::{NormalWeighting, vertex_normals};

    /// A closed cylinder of radius `r` and length `len` along x, capped by
    /// fans, with outward normals.
    fn capped_cylinder(r: f64, len: f64, ring: usize, rows: usize) -> TriMesh {
        let mut positions = Vec::new();
        for i in 0..=rows {
            let x = len * i as f64 / rows as f64;
            for k in 0..ring {
                let phi = std::f64::consts::TAU * k as f64 / ring as f64;
                positions.push(DVec3::new(x, r * phi.cos(), r * phi.sin()));
            }
        }
        let (c0, c1) = (positions.len() as u32, positions.len() as u32 + 1);
        positions.push(DVec3::new(0.0, 0.0, 0.0));
        positions.push(DVec3::new(len, 0.0, 0.0));
        let id = |i: usize, k: usize| (i * ring + k % ring) as u32;
        let mut triangles = Vec::new();
        for i in 0..rows {
            for k in 0..ring {
                let (a, b, c, d) = (id(i, k), id(i, k + 1), id(i + 1, k + 1), id(i + 1, k));
                triangles.push([a, b, c]);
                triangles.push([a, c, d]);
            }
        }
        for k in 0..ring {
            triangles.push([c0, id(0, k + 1), id(0, k)]);
            triangles.push([c1, id(rows, k), id(rows, k + 1)]);
        }
        let mesh = TriMesh::new(positions, triangles).expect("valid mesh");
        // Outward: the side walls' normals point away from the axis.
        let n = mesh.face_normal_unnormalized(0);
        assert!(n.dot(mesh.positions[0] - DVec3::ZERO) > 0.0);
        mesh
    }

    #[test]
    fn a_cylinders_diameter_is_measured_and_caps_its_edges() {
        let (r, len) = (0.1, 4.0);
        let mesh = capped_cylinder(r, len, 32, 80);
        let normals = vertex_normals(&mesh, NormalWeighting::Area);
        let index = SurfaceIndex::new(&mesh).expect("index");
        let d = shape_diameter(&mesh, &normals, &index);
        // Side vertices away from the caps: a ray at θ = 20° from the inward
        // normal crosses the tube in 2r cos θ (tilted within the
        // cross-section) to 2r / cos θ (tilted along the axis); the far wall
        // is a chord of the 32-gon, at most cos(π/32) nearer.
        let theta = RING_DEGREES.to_radians();
        let lo = 2.0 * r * theta.cos() * (std::f64::consts::PI / 32.0).cos() - 1e-9;
        let hi = 2.0 * r / theta.cos() + 1e-9;
        for i in 10..70 {
            for k in 0..32 {
                let v = i * 32 + k;
                assert!(
                    d[v] >= lo && d[v] <= hi,
                    "vertex {v}: {} not in [{lo}, {hi}]",
                    d[v]
                );
            }
        }
        let adjacency = VertexAdjacency::new(&mesh);
        let s = vec![1.0; mesh.vertex_count()];
        let cap = thin_part_cap(&mesh, &adjacency, &d, &s, 5.0, 0.0, 0.5).expect("capped");
        let pi = std::f64::consts::PI;
        for v in 10 * 32..70 * 32 {
            assert!(
                cap[v] <= pi * hi / 5.0 && cap[v] >= pi * lo / 5.0,
                "{}",
                cap[v]
            );
        }
        // The floor: no cap below floor × the field's length.
        let floored = thin_part_cap(&mesh, &adjacency, &d, &s, 5.0, 0.5, 0.5).expect("capped");
        assert!(floored.iter().all(|&c| c >= 0.5));
        // Graded: neighbouring caps differ by at most gradation × edge length.
        for v in 0..mesh.vertex_count() {
            for &w in adjacency.neighbors(v) {
                let gap = (cap[v] - cap[w as usize]).abs();
                let edge = mesh.positions[v].distance(mesh.positions[w as usize]);
                assert!(gap <= 0.5 * edge + 1e-12);
            }
        }
        // A cap above the field changes nothing.
        let small = vec![0.01; mesh.vertex_count()];
        assert!(thin_part_cap(&mesh, &adjacency, &d, &small, 5.0, 0.0, 0.5).is_none());
    }

    /// Two square holes in a unit grid, two cells apart: along the strip's
    /// middle column the gap is the strip's width, 2 (d₁ = d₂ = 1 along
    /// grid edges); it grows away from the strip; a mesh with one loop
    /// has no gap.
    #[test]
    fn the_gap_between_two_holes_is_the_strips_width() {
        let hole = |i: usize, j: usize| {
            (8..12).contains(&j) && ((5..8).contains(&i) || (10..13).contains(&i))
        };
        let mesh = crate::mesh::generate::grid_cells(20, |i, j| !hole(i, j));
        let adjacency = VertexAdjacency::new(&mesh);
        let arcs = BoundaryArcs::new(&mesh);
        assert_eq!(arcs.length.len(), 3, "outer square and two holes");
        let gap = boundary_loop_gap(&mesh, &adjacency, &arcs);
        let at = |i: usize, j: usize| gap[j * 21 + i];
        for j in 8..=12 {
            assert!((at(9, j) - 2.0).abs() < 1e-12, "({j}): {}", at(9, j));
        }
        // On a hole's rim facing the strip: 0 + 2.
        assert!((at(8, 10) - 2.0).abs() < 1e-12);
        // Farther along the strip's axis, wider.
        assert!(at(9, 14) > 2.0 + 1.0);
        // The cap: below 1 (the field) only near the strip, gap / 2 there.
        let s = vec![1.5; mesh.positions.len()];
        let cap = loop_gap_cap(&mesh, &adjacency, &s, 2.0, 0.0, 0.5).expect("capped");
        assert!((cap[10 * 21 + 9] - 1.0).abs() < 1e-12);
        assert!(cap[2 * 21 + 2] >= 1.5 || cap[2 * 21 + 2].is_infinite());
        // Holes shorter than a quad's perimeter (14 units at a field of
        // 5: 2.8 edges) are no sources: only the outer loop is left.
        let coarse = vec![5.0; mesh.positions.len()];
        assert!(loop_gap_cap(&mesh, &adjacency, &coarse, 2.0, 0.0, 0.5).is_none());
        // One loop: no gap anywhere.
        let sheet = crate::mesh::generate::grid_cells(6, |_, _| true);
        let adjacency = VertexAdjacency::new(&sheet);
        let arcs = BoundaryArcs::new(&sheet);
        assert!(
            boundary_loop_gap(&sheet, &adjacency, &arcs)
                .iter()
                .all(|g| g.is_infinite())
        );
        assert!(loop_gap_cap(&sheet, &adjacency, &vec![1.0; 49], 2.0, 0.0, 0.5).is_none());
    }

    #[test]
    fn an_open_sheet_has_no_thickness() {
        let mut positions = Vec::new();
        for j in 0..5 {
            for i in 0..5 {
                positions.push(DVec3::new(i as f64, j as f64, 0.0));
            }
        }
        let mut triangles = Vec::new();
        for j in 0..4u32 {
            for i in 0..4u32 {
                let a = j * 5 + i;
                triangles.push([a, a + 1, a + 6]);
                triangles.push([a, a + 6, a + 5]);
            }
        }
        let mesh = TriMesh::new(positions, triangles).expect("valid mesh");
        let normals = vertex_normals(&mesh, NormalWeighting::Area);
        let index = SurfaceIndex::new(&mesh).expect("index");
        let d = shape_diameter(&mesh, &normals, &index);
        assert!(d.iter().all(|x| x.is_infinite()));
    }
}
