//! What the design mode draws after each change of the committed loops
//! (Campen & Kobbelt 2014, *Dual Strip Weaving*: §4.2 region guidance, §6
//! strips, §7 the primal layout), as flat arrays: the one place where the
//! layout analysis meets the page. Native, so it is unit-tested.
//!
//! Deviation: until the regions and the primal layout exist there is no
//! region colouring or layout.

use glam::DVec3;
use serde::Serialize;

use crate::layout::design::{LayoutDesign, Mirror};
use crate::layout::{EmbeddedLoop, LoopEmbedder, StripParams, strip_analysis};
use crate::mesh::TriMesh;

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
    /// The layout as OBJ lines and as JSON (empty without a layout).
    pub obj: String,
    pub json: String,
}

/// Runs the analysis of the committed loops on `mesh`: embeds them (§6.1
/// needs them on the triangulation), runs §6 ([`strip_analysis`]) and feeds
/// its covered directions back to the engine (§6.2). `_clock` gives
/// milliseconds (the analysis times itself).
pub fn analyze(mesh: &TriMesh, design: &mut LayoutDesign, _clock: &dyn Fn() -> f64) -> Analysis {
    let mut a = Analysis {
        counts: Counts {
            strips: design.committed().len(),
            ..Counts::default()
        },
        ..Analysis::default()
    };
    let mut notes = Vec::new();
    // Committed loop index of each embedded loop.
    let mut embedded: Vec<EmbeddedLoop> = Vec::new();
    let mut committed_of: Vec<usize> = Vec::new();
    if !design.committed().is_empty() {
        match LoopEmbedder::new(mesh) {
            Ok(embedder) => {
                for (i, c) in design.committed().iter().enumerate() {
                    match embedder.embed(&c.dual.points, c.dual.closed) {
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
    let strips = strip_analysis(mesh, &embedded, &StripParams::default());
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
    if !strips.covered.is_empty() {
        design.apply_covered(design.revision(), &strips.covered);
    }
    notes.extend(strips.notes.iter().cloned());
    a.counts.strips_grown = strips.strips.len();
    a.status = format!(
        "{} strip{} · regions and layout are not available in this build",
        a.counts.strips,
        plural(a.counts.strips)
    );
    if !notes.is_empty() {
        a.status += &format!(" · {}", notes.join("; "));
    }
    a.timings.total_ms = a.timings.field_ms + a.timings.parametrization_ms + a.timings.strips_ms;
    a.obj = loops_obj(design);
    a.json = serde_json::json!({
        "strips": a.counts.strips,
        "loops": design.committed().iter().map(|c| c.dual.points.iter().map(|p| [p.x, p.y, p.z]).collect::<Vec<_>>()).collect::<Vec<_>>(),
    })
    .to_string();
    a
}

const SINGULARITY_3: [u8; 4] = [31, 111, 221, 255];
const SINGULARITY_5: [u8; 4] = [216, 52, 44, 255];

/// A reflection plane detected on the mesh (the "auto" symmetry option).
pub fn detect_mirror(_mesh: &TriMesh) -> Option<Mirror> {
    None
}

/// The committed loops as OBJ polylines (`v` and `l` lines).
pub fn loops_obj(design: &LayoutDesign) -> String {
    let mut out = String::from("# dual loops of a quad layout design (Quadrille)\n");
    let mut next = 1usize;
    for c in design.committed() {
        for p in &c.dual.points {
            out += &format!("v {} {} {}\n", p.x, p.y, p.z);
        }
        let n = c.dual.points.len();
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

    #[test]
    fn one_meridian_on_the_torus_gives_one_strip_with_stripes() {
        let mesh = torus(2.0, 0.7, 30, 12);
        let mut d = LayoutDesign::new(LoopEngine::new(&mesh, &ElasticaParams::default()));
        d.hover(DVec3::new(2.7, 0.0, 0.0));
        d.commit().unwrap();
        let a = analyze(&mesh, &mut d, &|| 0.0);
        assert!(a.available);
        assert_eq!(a.counts.strips, 1);
        assert_eq!(a.counts.strips_grown, 1, "{}", a.status);
        assert!(!a.stripes.is_empty());
        assert_eq!(a.stripes.len() / 6, a.stripe_colours.len() / 4);
        assert!(a.stripe_colours.chunks(4).all(|c| c == strip_colour(0)));
        // Poincaré–Hopf: the indices sum to 4χ quarter turns, 0 on a torus.
        assert_eq!(a.singularity_index.iter().sum::<i32>(), 0);
        let n = d.committed()[0].dual.points.len();
        let v = a.obj.lines().filter(|l| l.starts_with("v ")).count();
        assert_eq!(v, n);
        let json: serde_json::Value = serde_json::from_str(&a.json).unwrap();
        assert_eq!(json["strips"], 1);
    }
}
