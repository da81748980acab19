//! What the design mode draws after each change of the committed loops
//! (Campen & Kobbelt 2014, *Dual Strip Weaving*: §4.2 region guidance, §6
//! strips, §7 the primal layout), as flat arrays: the one place where the
//! layout analysis meets the page. Native, so it is unit-tested.
//!
//! The layout's JSON is [`QuadLayout::to_json`]; its OBJ ([`layout_obj`])
//! holds the patches as polygon faces, and [`grid_mesh`] grids them into a
//! pure-quad mesh ([`crate::layout::grid`]) for the fit; without a layout
//! (regions not all discs) the OBJ holds the committed loops as polylines
//! and the JSON is empty. OBJ text is written in the file's coordinates.

use glam::DVec3;
use serde::Serialize;

use crate::layout::design::LayoutDesign;
use crate::layout::grid::{GridError, LayoutGrid, grid_layout, patch_polygons};
use crate::layout::primal::{LayoutExport, QuadLayout};
use crate::layout::regions::{Guidance, Regions};
use crate::layout::symmetry::{MirrorPlane, detect};
use crate::layout::{EmbeddedLoop, LoopEmbedder, StripParams, strip_analysis_with};
use crate::mesh::{Frame, TriMesh};
use crate::progress::{Cancelled, Progress};
use crate::spatial::SurfaceIndex;

/// ColorBrewer Set1/Dark2-like distinct strip colours.
const STRIP_COLOURS: [u32; 10] = [
    0x1f77b4, 0xd62728, 0x2ca02c, 0x9467bd, 0xff7f0e, 0x17becf, 0x8c564b, 0xe377c2, 0x7f7f7f,
    0xbcbd22,
];

/// The colour of strip `i` (RGBA bytes).
pub fn strip_colour(i: usize) -> [u8; 4] {
    let c = STRIP_COLOURS[i % STRIP_COLOURS.len()];
    [(c >> 16) as u8, (c >> 8) as u8, c as u8, 255]
}

/// Region categories on the `categories` colormap (0 grey … 12): a region
/// that is fine, not a disc (red), several curvature extrema (orange),
/// valence mismatch (yellow).
pub const REGION_OK: f32 = 0.0;
pub const REGION_RED: f32 = 6.0;
pub const REGION_ORANGE: f32 = 8.0;
pub const REGION_YELLOW: f32 = 11.0;

#[derive(Debug, Clone, Default, Serialize)]
pub struct Counts {
    pub strips: usize,
    /// Strips the analysis could grow (a loop that fails to embed or to
    /// grow has none).
    pub strips_grown: usize,
    pub regions: usize,
    pub red: usize,
    pub orange: usize,
    pub yellow: usize,
    pub singularities: usize,
    pub layout_vertices: usize,
    pub layout_edges: usize,
    pub patches: usize,
}

#[derive(Debug, Clone, Default, Serialize)]
pub struct Timings {
    pub field_ms: f64,
    pub parametrization_ms: f64,
    pub strips_ms: f64,
    pub regions_ms: f64,
    pub layout_ms: f64,
    pub total_ms: f64,
}

/// The analysis of one revision of the design, ready to draw.
#[derive(Debug, Clone, Default)]
pub struct Analysis {
    /// Whether the strip analysis ran (false: loops only).
    pub available: bool,
    /// Stripe segments (six floats each) and one RGBA per segment.
    pub stripes: Vec<f32>,
    pub stripe_colours: Vec<u8>,
    /// Per face of the design mesh, a region category (empty: none).
    pub region_category: Vec<f32>,
    /// Singularity positions (xyz) and colours (valence 3 blue, 5 red).
    pub singularities: Vec<f32>,
    pub singularity_colours: Vec<u8>,
    /// Their indices in quarter turns.
    pub singularity_index: Vec<i32>,
    /// Layout vertices (xyz) and edges (segments).
    pub layout_vertices: Vec<f32>,
    pub layout_edges: Vec<f32>,
    pub counts: Counts,
    pub sufficient: bool,
    pub status: String,
    pub timings: Timings,
    /// The committed loops as OBJ lines (local coordinates) and the
    /// layout as JSON (empty without a layout).
    pub obj: String,
    pub json: String,
    /// The layout, and the committed strip of each of its loops.
    pub layout: Option<LayoutExport>,
    pub loop_strip: Vec<usize>,
    /// §6.2: per vertex of the mesh, the directions the strips cover (empty:
    /// none computed).
    pub covered: Vec<Vec<DVec3>>,
}

/// Runs the analysis of the committed loops on `mesh`: embeds them (§6.1
/// needs them on the triangulation), runs §6 ([`strip_analysis`]) and feeds
/// its covered directions back to the engine (§6.2), then finds the regions
/// (§4.2) and, when they are all discs, the primal layout (§7) with the
/// user's vertex moves. `clock` gives milliseconds.
pub fn analyze(mesh: &TriMesh, design: &mut LayoutDesign, clock: &dyn Fn() -> f64) -> Analysis {
    let loops: Vec<(&[DVec3], bool)> = design
        .committed()
        .iter()
        .map(|c| (&c.dual.points[..], c.dual.closed))
        .collect();
    // A sink that never cancels: never `Cancelled`.
    let a = crate::progress::silently("design analysis", |p| {
        analyze_loops(mesh, &loops, design.moves(), clock, p)
    })
    .unwrap_or_default();
    if !a.covered.is_empty() {
        design.apply_covered(design.revision(), &a.covered);
    }
    a
}

/// [`analyze`] of committed loops given as (polyline, closed) with the
/// layout-vertex moves, without a design session: what the analysis worker
/// runs. The covered directions of §6.2 are returned in
/// [`Analysis::covered`] for the session to apply. Reports to `progress`
/// between its steps (each loop's embedding, §6's steps, the regions, the
/// layout) and returns `Cancelled` as soon as the sink says stop: the
/// analysis worker's sink does when a newer action made the loops stale.
pub fn analyze_loops(
    mesh: &TriMesh,
    loops: &[(&[DVec3], bool)],
    moves: &[(u32, DVec3)],
    clock: &dyn Fn() -> f64,
    progress: &mut Progress<'_>,
) -> Result<Analysis, Cancelled> {
    let mut a = Analysis {
        counts: Counts {
            strips: loops.len(),
            ..Counts::default()
        },
        ..Analysis::default()
    };
    a.obj = loops_obj(loops, &Frame::IDENTITY);
    let mut notes = Vec::new();
    // Committed loop index of each embedded loop.
    let mut embedded: Vec<EmbeddedLoop> = Vec::new();
    let mut committed_of: Vec<usize> = Vec::new();
    if !loops.is_empty() {
        match LoopEmbedder::new(mesh) {
            Ok(embedder) => {
                for (i, &(points, closed)) in loops.iter().enumerate() {
                    progress.report(0.0, "embedding the loops")?;
                    match embedder.embed(points, closed) {
                        Ok(l) => {
                            embedded.push(l);
                            committed_of.push(i);
                        }
                        Err(e) => notes.push(format!("strip {}: {e}", i + 1)),
                    }
                }
            }
            Err(e) => notes.push(e.to_string()),
        }
    }
    let strips = strip_analysis_with(mesh, &embedded, &StripParams::default(), progress)?;
    a.available = true;
    a.timings.field_ms = strips.field_ms;
    a.timings.parametrization_ms = strips.parametrization_ms;
    a.timings.strips_ms = strips.strips_ms;
    for s in &strips.strips {
        let colour = strip_colour(committed_of.get(s.loop_index).copied().unwrap_or(0));
        for [p, q] in s.stripe_segments(mesh, strips.spacing) {
            push_segment(&mut a.stripes, p, q);
            a.stripe_colours.extend(colour);
        }
    }
    for s in &strips.singularities {
        if let Some(&p) = mesh.positions.get(s.vertex as usize) {
            push_point(&mut a.singularities, p);
            a.singularity_index.push(s.index);
            // Index +1 (valence-3-like corner) blue, −1 (valence 5) red.
            a.singularity_colours.extend(if s.index > 0 {
                SINGULARITY_3
            } else {
                SINGULARITY_5
            });
        }
    }
    a.counts.singularities = strips.singularities.len();
    a.covered = strips.covered.clone();
    notes.extend(strips.notes.iter().cloned());
    a.counts.strips_grown = strips.strips.len();

    // §4.2: the regions between the loops and their guidance colours.
    progress.report(0.8, "regions")?;
    let started = clock();
    let mut layout = None;
    let mut regions_failed = None;
    // Before the first strip the mode is neutral (§4.2 colours regions
    // *enclosed by loops*; there are none yet): no region colours, no red.
    let regions = if embedded.is_empty() {
        Err(None)
    } else {
        Regions::compute(mesh, &embedded, &strips.singularities).map_err(Some)
    };
    match regions {
        Ok(regions) => {
            a.counts.regions = regions.regions.len();
            for r in &regions.regions {
                match r.guidance {
                    Guidance::NonDisc => a.counts.red += 1,
                    Guidance::CurvatureExtrema => a.counts.orange += 1,
                    Guidance::ValenceMismatch => a.counts.yellow += 1,
                    Guidance::Ok => {}
                }
            }
            a.region_category = regions
                .face_region
                .iter()
                .map(
                    |&r| match regions.regions.get(r as usize).map(|r| r.guidance) {
                        Some(Guidance::NonDisc) => REGION_RED,
                        Some(Guidance::CurvatureExtrema) => REGION_ORANGE,
                        Some(Guidance::ValenceMismatch) => REGION_YELLOW,
                        _ => REGION_OK,
                    },
                )
                .collect();
            notes.extend(boundary_blockers(&regions));
            a.sufficient = regions.sufficient && !embedded.is_empty();
            a.timings.regions_ms = clock() - started;
            // §7: the primal layout, with the user's vertex moves.
            if a.sufficient {
                progress.report(0.9, "layout")?;
                let started = clock();
                match QuadLayout::build(mesh, &embedded, &regions, &strips.singularities) {
                    Ok(mut l) => {
                        for &(v, p) in moves {
                            if let Err(e) = l.move_vertex(v as usize, p) {
                                notes.push(format!("vertex {v} not moved: {e}"));
                            }
                        }
                        layout = Some(l);
                    }
                    Err(e) => notes.push(format!("no layout: {e}")),
                }
                a.timings.layout_ms = clock() - started;
            }
        }
        Err(e) => regions_failed = e.map(|e| e.to_string()),
    }
    if let Some(l) = &layout {
        for v in &l.vertices {
            push_point(&mut a.layout_vertices, v.position);
        }
        for e in &l.edges {
            for w in e.polyline.windows(2) {
                push_segment(&mut a.layout_edges, w[0], w[1]);
            }
        }
        a.counts.layout_vertices = l.vertices.len();
        a.counts.layout_edges = l.edges.len();
        a.counts.patches = l.patches.len();
        if l.patches.is_empty() {
            // §7: a patch is a crossing of two loops; the regions' disc test
            // (§4.2) passes with one loop on a sphere, which lays out nothing.
            notes.push(
                "no patches yet: a strip no other strip crosses lays out nothing; add a crossing \
                 strip"
                    .into(),
            );
        }
        a.json = l.to_json().unwrap_or_default();
        a.layout = Some(l.export());
        a.loop_strip = committed_of.clone();
    }
    a.status = if a.counts.strips == 0 {
        "no strips yet: hover over the surface and press Enter".to_string()
    } else if let Some(e) = regions_failed {
        format!("the regions could not be found ({e}): no guidance and no layout")
    } else {
        status_line(&a.counts)
    };
    if !notes.is_empty() {
        a.status += &format!(" · {}", notes.join("; "));
    }
    a.timings.total_ms = a.timings.field_ms
        + a.timings.parametrization_ms
        + a.timings.strips_ms
        + a.timings.regions_ms
        + a.timings.layout_ms;
    Ok(a)
}

/// §6.2's covered directions as they cross between the workers: the
/// number per vertex and the directions' xyz in one flat array.
pub fn flatten_covered(covered: &[Vec<DVec3>]) -> (Vec<u32>, Vec<f64>) {
    let counts = covered.iter().map(|c| c.len() as u32).collect();
    let flat = covered
        .iter()
        .flatten()
        .flat_map(|d| [d.x, d.y, d.z])
        .collect();
    (counts, flat)
}

/// The inverse of [`flatten_covered`]; `None` when the lengths disagree.
pub fn unflatten_covered(counts: &[u32], flat: &[f64]) -> Option<Vec<Vec<DVec3>>> {
    let total: usize = counts.iter().map(|&c| c as usize).sum();
    if flat.len() != 3 * total {
        return None;
    }
    let mut k = 0;
    Some(
        counts
            .iter()
            .map(|&c| {
                (0..c)
                    .map(|_| {
                        let d = DVec3::new(flat[k], flat[k + 1], flat[k + 2]);
                        k += 3;
                        d
                    })
                    .collect()
            })
            .collect(),
    )
}

/// Most red regions touching the mesh boundary more than once that the
/// status names.
const BLOCKERS_NAMED: usize = 3;

/// What blocks the red regions that are discs (holes capped) but touch the
/// mesh boundary along several stretches, for the status: the status
/// line's "not a disc" does not say it.
fn boundary_blockers(regions: &Regions) -> Vec<String> {
    let blocked: Vec<String> = regions
        .regions
        .iter()
        .enumerate()
        .filter(|(_, r)| r.guidance == Guidance::NonDisc && r.is_capped_disc())
        .filter_map(|(i, r)| r.layout_blocker(i))
        .collect();
    let mut notes: Vec<String> = blocked.iter().take(BLOCKERS_NAMED).cloned().collect();
    if blocked.len() > BLOCKERS_NAMED {
        let more = blocked.len() - BLOCKERS_NAMED;
        notes.push(format!("{more} more such region{}", plural(more)));
    }
    notes
}

const SINGULARITY_3: [u8; 4] = [31, 111, 221, 255];
const SINGULARITY_5: [u8; 4] = [216, 52, 44, 255];

/// A reflection plane detected on the mesh (the "auto" symmetry option).
pub fn detect_mirror(mesh: &TriMesh) -> Option<MirrorPlane> {
    detect(mesh).map(|(plane, _)| plane)
}

/// The layout gridded with `strip_counts[i]` segments across committed
/// strip `i` (a strip without a count gets [`crate::layout::grid::DEFAULT_COUNT`]),
/// on `mesh`, whose surface `index` is.
pub fn grid_mesh(
    layout: &LayoutExport,
    loop_strip: &[usize],
    strip_counts: &[u32],
    mesh: &TriMesh,
    index: &SurfaceIndex,
) -> Result<LayoutGrid, GridError> {
    let counts: Vec<u32> = loop_strip
        .iter()
        .map(|&s| {
            strip_counts
                .get(s)
                .copied()
                .unwrap_or(crate::layout::grid::DEFAULT_COUNT)
        })
        .collect();
    grid_layout(layout, &counts, mesh, index)
}

/// The layout's patches as OBJ polygon faces, in the coordinates `frame`
/// maps to.
pub fn layout_obj(layout: &LayoutExport, frame: &Frame) -> Result<String, GridError> {
    let (positions, faces) = patch_polygons(layout)?;
    let world: Vec<DVec3> = frame.points_to_world(&positions);
    Ok(format!(
        "# quad layout (dual strip weaving): {} vertices, {} edges, {} patches as faces\n{}",
        layout.vertices.len(),
        layout.edges.len(),
        layout.patches.len(),
        crate::io::write_obj(&world, &faces)
    ))
}

/// The committed loops as OBJ polylines (`v` and `l` lines), in the
/// coordinates `frame` maps to.
pub fn loops_obj(loops: &[(&[DVec3], bool)], frame: &Frame) -> String {
    let mut out = String::from("# dual loops of a quad layout design (Quadrille)\n");
    let mut next = 1usize;
    for &(points, _) in loops {
        for p in points.iter().map(|&p| frame.to_world(p)) {
            out += &format!("v {} {} {}\n", p.x, p.y, p.z);
        }
        let n = points.len();
        if n >= 2 {
            out += "l";
            for k in 0..n {
                out += &format!(" {}", next + k);
            }
            out += "\n";
        }
        next += n;
    }
    out
}

/// The status line of §4.2: sufficient or how many regions are red, with
/// the orange and yellow hints.
pub fn status_line(c: &Counts) -> String {
    let mut s = if c.red > 0 {
        format!(
            "{} region{} {} not {} (red): add strips to split {}",
            c.red,
            plural(c.red),
            if c.red == 1 { "is" } else { "are" },
            if c.red == 1 { "a disc" } else { "discs" },
            if c.red == 1 { "it" } else { "them" },
        )
    } else {
        format!(
            "{} strip{} · {} region{} · topologically sufficient",
            c.strips,
            plural(c.strips),
            c.regions,
            plural(c.regions)
        )
    };
    if c.orange > 0 {
        s += &format!(" · {} orange (curvature extrema)", c.orange);
    }
    if c.yellow > 0 {
        s += &format!(" · {} yellow (valence)", c.yellow);
    }
    s
}

pub fn plural(n: usize) -> &'static str {
    if n == 1 { "" } else { "s" }
}

pub fn push_point(out: &mut Vec<f32>, p: DVec3) {
    out.extend([p.x as f32, p.y as f32, p.z as f32]);
}

pub fn push_segment(out: &mut Vec<f32>, a: DVec3, b: DVec3) {
    push_point(out, a);
    push_point(out, b);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::layout::{ElasticaParams, LoopEngine};
    use crate::mesh::generate::torus;

    #[test]
    fn status_line_says_sufficient_or_counts_red() {
        let mut c = Counts {
            strips: 3,
            regions: 2,
            ..Counts::default()
        };
        assert_eq!(
            status_line(&c),
            "3 strips · 2 regions · topologically sufficient"
        );
        c.red = 2;
        assert_eq!(
            status_line(&c),
            "2 regions are not discs (red): add strips to split them"
        );
        c.red = 1;
        c.yellow = 1;
        assert!(status_line(&c).starts_with("1 region is not a disc (red)"));
        assert!(status_line(&c).ends_with("1 yellow (valence)"));
    }

    fn torus_design() -> (TriMesh, LayoutDesign) {
        let mesh = torus(2.0, 0.7, 48, 20);
        let d = LayoutDesign::new(LoopEngine::new(&mesh, &ElasticaParams::default()));
        (mesh, d)
    }

    /// A point on the torus at angles (u, v) (see `generate::torus`).
    fn on_torus(u: f64, v: f64) -> DVec3 {
        let ring = 2.0 + 0.7 * v.cos();
        DVec3::new(ring * u.cos(), ring * u.sin(), 0.7 * v.sin())
    }

    fn commit_through(d: &mut LayoutDesign, p: DVec3, direction: DVec3) {
        d.add_anchor(p, Some(direction));
        d.commit().expect("a loop through the anchor");
    }

    #[test]
    fn one_loop_on_a_sphere_says_it_lays_out_nothing() {
        let mesh = crate::mesh::generate::icosphere(1.0, 3);
        let mut d = LayoutDesign::new(LoopEngine::new(&mesh, &ElasticaParams::default()));
        commit_through(&mut d, DVec3::X, DVec3::Y);
        let a = analyze(&mesh, &mut d, &|| 0.0);
        // Two discs: sufficient by §4.2, but no crossing, so no patch.
        assert_eq!((a.counts.regions, a.counts.red), (2, 0));
        assert_eq!(a.counts.patches, 0);
        assert!(a.status.contains("no patches yet"), "{}", a.status);
    }

    #[test]
    fn the_mode_opens_neutral_without_region_colours() {
        let (mesh, mut d) = torus_design();
        let a = analyze(&mesh, &mut d, &|| 0.0);
        assert_eq!(a.counts.strips, 0);
        assert!(
            a.region_category.is_empty(),
            "no region colours before a strip"
        );
        assert_eq!((a.counts.regions, a.counts.red), (0, 0));
        assert!(!a.sufficient);
        assert_eq!(
            a.status,
            "no strips yet: hover over the surface and press Enter"
        );
        // After the first strip the guidance appears (the annulus is red).
        commit_through(&mut d, on_torus(0.0, 0.0), DVec3::Z);
        let a = analyze(&mesh, &mut d, &|| 0.0);
        assert_eq!(a.counts.red, 1, "{}", a.status);
        assert_eq!(a.region_category.len(), mesh.face_count());
    }

    #[test]
    fn one_meridian_on_the_torus_gives_a_strip_and_a_red_annulus() {
        let (mesh, mut d) = torus_design();
        commit_through(&mut d, on_torus(0.0, 0.0), DVec3::Z);
        let a = analyze(&mesh, &mut d, &|| 0.0);
        assert!(a.available);
        assert_eq!(a.counts.strips, 1);
        assert_eq!(a.counts.strips_grown, 1, "{}", a.status);
        assert!(!a.stripes.is_empty());
        assert_eq!(a.stripes.len() / 6, a.stripe_colours.len() / 4);
        assert!(a.stripe_colours.chunks(4).all(|c| c == strip_colour(0)));
        // Poincaré–Hopf: the indices sum to 4χ quarter turns, 0 on a torus.
        assert_eq!(a.singularity_index.iter().sum::<i32>(), 0);
        // Cut once, the torus is an annulus: one region, not a disc.
        assert_eq!((a.counts.regions, a.counts.red), (1, 1), "{}", a.status);
        assert!(!a.sufficient && a.json.is_empty());
        assert!(a.region_category.iter().all(|&c| c == REGION_RED));
        assert_eq!(a.region_category.len(), mesh.face_count());
        let n = d.committed()[0].dual.points.len();
        assert_eq!(a.obj.lines().filter(|l| l.starts_with("v ")).count(), n);
        assert!(
            a.status.starts_with("1 region is not a disc (red)"),
            "{}",
            a.status
        );
    }

    #[test]
    fn two_meridians_and_a_longitude_give_a_valid_torus_layout() {
        let (mesh, mut d) = torus_design();
        commit_through(&mut d, on_torus(0.0, 0.0), DVec3::Z);
        commit_through(&mut d, on_torus(std::f64::consts::PI, 0.0), DVec3::Z);
        let u = std::f64::consts::FRAC_PI_2;
        commit_through(&mut d, on_torus(u, 0.0), DVec3::new(-u.sin(), u.cos(), 0.0));
        let a = analyze(&mesh, &mut d, &|| 0.0);
        assert_eq!(a.counts.strips, 3);
        assert_eq!(a.counts.red, 0, "{}", a.status);
        assert!(a.sufficient, "{}", a.status);
        let c = &a.counts;
        // Two crossings: two patches; two disc regions; four loop arcs.
        assert_eq!(
            (c.layout_vertices, c.layout_edges, c.patches),
            (2, 4, 2),
            "{c:?}"
        );
        assert_eq!(
            c.layout_vertices as i64 - c.layout_edges as i64 + c.patches as i64,
            0,
            "Euler characteristic of the torus"
        );
        let json = crate::layout::primal::LayoutExport::from_json(&a.json).unwrap();
        for p in &json.patches {
            for i in 0..4 {
                let e = &json.edges[p.edges[i] as usize];
                let (x, y) = (p.corners[i], p.corners[(i + 1) % 4]);
                assert!(
                    e.ends == [x, y] || e.ends == [y, x],
                    "patch edge {i} joins its corners"
                );
            }
        }
        assert!(
            a.status.contains("topologically sufficient"),
            "{}",
            a.status
        );
        assert_eq!(a.layout_vertices.len(), 3 * c.layout_vertices);
        assert!(!a.layout_edges.is_empty());
    }

    /// A sink that says stop stops the analysis at its next report, at
    /// every step from the first embedding to the layout; a sink that
    /// never stops gets the whole analysis (the same as `analyze`'s).
    #[test]
    fn a_cancelled_analysis_stops_at_its_next_report() {
        let (mesh, mut d) = torus_design();
        commit_through(&mut d, on_torus(0.0, 0.0), DVec3::Z);
        commit_through(&mut d, on_torus(std::f64::consts::PI, 0.0), DVec3::Z);
        let u = std::f64::consts::FRAC_PI_2;
        commit_through(&mut d, on_torus(u, 0.0), DVec3::new(-u.sin(), u.cos(), 0.0));
        let loops: Vec<(&[DVec3], bool)> = d
            .committed()
            .iter()
            .map(|c| (&c.dual.points[..], c.dual.closed))
            .collect();
        let run = |stop_after: usize| {
            let mut steps = Vec::new();
            let mut sink = |_: &str, _: f32, message: &str| {
                steps.push(message.to_string());
                steps.len() <= stop_after
            };
            let mut progress = Progress::new(&mut sink, "design analysis");
            let r = analyze_loops(&mesh, &loops, &[], &|| 0.0, &mut progress);
            (r, steps)
        };
        let (whole, steps) = run(usize::MAX);
        let whole = whole.expect("not cancelled");
        assert!(whole.sufficient, "{}", whole.status);
        // Three embeddings, field, parametrization, three strips, regions, layout.
        assert_eq!(steps.len(), 10, "{steps:?}");
        assert_eq!(steps.last().map(String::as_str), Some("layout"));
        for k in 0..steps.len() {
            let (r, seen) = run(k);
            assert_eq!(
                r.err(),
                Some(Cancelled),
                "stopped at step {k} ({})",
                steps[k]
            );
            assert_eq!(seen.len(), k + 1, "nothing reported after the stop");
        }
        assert_eq!(whole.json, analyze(&mesh, &mut d, &|| 0.0).json);
    }

    #[test]
    fn the_torus_layout_grids_fits_and_exports_faces_in_file_coordinates() {
        let (mesh, mut d) = torus_design();
        commit_through(&mut d, on_torus(0.0, 0.0), DVec3::Z);
        commit_through(&mut d, on_torus(std::f64::consts::PI, 0.0), DVec3::Z);
        let u = std::f64::consts::FRAC_PI_2;
        commit_through(&mut d, on_torus(u, 0.0), DVec3::new(-u.sin(), u.cos(), 0.0));
        let a = analyze(&mesh, &mut d, &|| 0.0);
        let layout = a.layout.as_ref().expect("a layout");
        let index = SurfaceIndex::new(&mesh).unwrap();
        let started = std::time::Instant::now();
        let g = grid_mesh(layout, &a.loop_strip, &[8, 8, 8], &mesh, &index).unwrap();
        let ms = started.elapsed().as_secs_f64() * 1e3;
        let m = &g.mesh;
        println!(
            "torus design, grid 8: {} vertices, {} quads, {} folded, {ms:.2} ms",
            m.vertex_count(),
            m.face_count(),
            g.folded
        );
        assert!(m.boundary_loops().is_empty());
        assert!((0..m.face_count() as u32).all(|f| m.degree(f) == 4));
        assert_eq!(m.euler_characteristic(), 0);
        // Two patches of 8 × 8.
        assert_eq!(m.face_count(), a.counts.patches * 64);
        let fit = crate::progress::silently("fit", |p| {
            crate::subdivision::fit_control_mesh(m, &mesh, &Default::default(), p)
        })
        .unwrap();
        println!(
            "torus design, grid 8: limit error {:?} → {:?} (Hausdorff)",
            fit.before.hausdorff, fit.after.hausdorff
        );
        assert!(fit.after.hausdorff.is_finite() && fit.after.hausdorff > 0.0);
        assert!(fit.after.hausdorff < 0.1, "{}", fit.after.hausdorff);
        // The patches as faces, in the file's coordinates.
        let frame = Frame {
            center: DVec3::new(1.0, 2.0, 3.0),
            scale: 10.0,
        };
        let obj = layout_obj(layout, &frame).unwrap();
        assert_eq!(
            obj.lines().filter(|l| l.starts_with("f ")).count(),
            a.counts.patches
        );
        let xs: Vec<f64> = obj
            .lines()
            .filter_map(|l| l.strip_prefix("v "))
            .map(|l| l.split_whitespace().next().unwrap().parse().unwrap())
            .collect();
        let local = layout.vertices[0].position.x;
        assert!(xs.iter().any(|&x| (x - (1.0 + 10.0 * local)).abs() < 1e-9));
    }
}
