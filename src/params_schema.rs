//! The one description of every pipeline parameter for user interfaces:
//! its path in [`Params`]' JSON, a one-line explanation (condensed from the
//! field's doc comment), its kind and range. Defaults are not repeated here:
//! they come from serialising [`Params::default`], so they cannot drift.
//! The web page builds its parameter panel from [`schema_json`]; a test
//! checks that every field of [`Params`] has exactly one entry.

use serde::Serialize;

use crate::pipeline::Params;

/// How a parameter is edited.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Kind {
    Bool,
    /// Whole number in `[min, max]`.
    Integer,
    /// Real number in `[min, max]`.
    Number,
    /// One of `options`.
    Choice,
    /// Any JSON value (lists).
    Json,
}

/// One parameter.
#[derive(Debug, Clone, Serialize)]
pub struct ParamDoc {
    /// Dotted path in the JSON of [`Params`], e.g. `field.seed`.
    pub path: &'static str,
    pub help: &'static str,
    pub kind: Kind,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub min: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max: Option<f64>,
    #[serde(skip_serializing_if = "<[_]>::is_empty")]
    pub options: &'static [&'static str],
    /// `null` is allowed (meaning "automatic", see the help).
    pub nullable: bool,
}

const fn p(path: &'static str, kind: Kind, help: &'static str) -> ParamDoc {
    ParamDoc {
        path,
        help,
        kind,
        min: None,
        max: None,
        options: &[],
        nullable: false,
    }
}

const fn num(path: &'static str, min: f64, max: f64, help: &'static str) -> ParamDoc {
    ParamDoc {
        min: Some(min),
        max: Some(max),
        ..p(path, Kind::Number, help)
    }
}

const fn int(path: &'static str, min: f64, max: f64, help: &'static str) -> ParamDoc {
    ParamDoc {
        min: Some(min),
        max: Some(max),
        ..p(path, Kind::Integer, help)
    }
}

const fn flag(path: &'static str, help: &'static str) -> ParamDoc {
    p(path, Kind::Bool, help)
}

const fn choice(
    path: &'static str,
    options: &'static [&'static str],
    help: &'static str,
) -> ParamDoc {
    ParamDoc {
        options,
        ..p(path, Kind::Choice, help)
    }
}

const fn nullable(doc: ParamDoc) -> ParamDoc {
    ParamDoc {
        nullable: true,
        ..doc
    }
}

/// Every parameter, in the order of [`Params`]' fields (one line each:
/// kept as a table).
#[rustfmt::skip]
pub fn schema() -> Vec<ParamDoc> {
    vec![
        // remesh
        choice("remesh.mode", &["local", "global"], "Remeshing path: local (Instant Meshes' fields as in the thesis; quad-dominant) or global (integer-grid map, Ebke et al. 2014, quads extracted as in QEx; pure quads)."),
        num("remesh.feature_curve_degrees", 0.0, 180.0, "Global mode: sharp edges whose face normals differ by more than this, and that are still creases at the target scale, lie on integer isolines (feature curves, Bommes et al. 2009 §4); 0 turns them off."),
        int("remesh.stiffening", 0.0, 20.0, "Global mode: MIQ's stiffening re-solves after the rounding (faces flipped against an unflipped cross weigh more); 0 turns it off."),
        num("remesh.conformal_scale", 0.0, 10.0, "Global mode: the map's target edge follows the conformal scale of the flat metric whose only curvature is the cross field's cones (square quads away from them), within this factor of the sizing; 0 turns it off."),
        flag("remesh.least_squares_placement", "Global mode: the quads also get the least-squares vertex placement (extraction.post.least_squares_iterations); off by default (it costs the regular quads more shape than it gains in distance)."),
        num("remesh.loop_separation", 0.0, 10.0, "Global mode: target edges across the narrowest strip between two boundary loops (the map's edge is capped there so the loops stay apart); 0 turns it off."),
        num("remesh.thin_part_across", 0.0, 16.0, "Global mode: target edges round a part thinner than this many target edges round (its shape diameter), asked across the part only (the map's edge across it is capped, along it kept); 0 = off."),
        num("remesh.thin_part_loops", 0.0, 8.0, "Global mode: around every part between one and this many target edges round (its shortest plane section), the map's translation round the part is at least this many units (a constraint of the integer rounding), so the part is not folded flat and keeps its quads; 0 = off."),
        num("remesh.curvature_anisotropy", 0.0, 4.0, "Global mode: curvature-aligned anisotropic quads: the map's edge along the direction of largest curvature shorter, across it longer (equal sagittas at the same quad area), their ratio capped at this; 1 or less = off."),
        flag("remesh.curvature_anisotropy_cross", "Global mode, with curvature_anisotropy: the cross field follows the direction of largest curvature (a soft constraint) where the ratio reaches the cap."),
        flag("remesh.close_small_holes", "Global mode: before the map, split the input's non-manifold vertices (one per fan) and close its boundary loops shorter than two target edges (too small to keep), round which the map would fold (Ebke et al. 2014 §6: what is below the target scale leaves no trace)."),
        flag("remesh.count_correction", "Global mode: when the quads' vertex count is more than 10 % off the target, compute the map again (up to four times) for a target from the power law through the last two counts and keep the closest result."),
        // analysis
        choice("analysis.normal_weighting", &["angle", "area"], "How incident faces are weighted in a vertex normal."),
        choice("analysis.curvature.estimator", &["cubic_fit", "discrete_sums"], "Curvature estimator: cubic surface fit (Goldfeather & Interrante) or the faster discrete sums (Dong & Wang)."),
        int("analysis.curvature.rings", 1.0, 5.0, "Neighbourhood of the curvature fit in rings (thesis §3.1.1: 2)."),
        choice("analysis.selection", &["max_abs", "mean", "directional"], "Curvature the sizing field is computed from: max(|κ1|,|κ2|), |mean|, or per principal direction."),
        choice("analysis.averaging.method", &["none", "simple", "similarity_based", "expand_high_curvature"], "Curvature averaging weights (thesis Eq. 3.4/3.5)."),
        int("analysis.averaging.iterations", 0.0, 20.0, "Rounds of curvature averaging."),
        num("analysis.averaging.damping", 0.0, 1.0, "Self-weight λ of the averaging."),
        int("analysis.averaging.rings", 1.0, 5.0, "Averaging neighbourhood in rings."),
        num("analysis.averaging.similarity_k", 0.0, 100.0, "k of Eq. 3.4 (similarity-based averaging)."),
        num("analysis.averaging.expand_breakpoint", 0.0, 1.0, "Breakpoint B of Eq. 3.5, in normalised curvature."),
        num("analysis.averaging.expand_constant", 0.0, 1.0, "Constant weight C of Eq. 3.5 below the breakpoint."),
        flag("analysis.features.enabled", "Classify feature vertices (anisotropic, strongly curved local maxima)."),
        num("analysis.features.anisotropy_threshold", 0.0, 1.0, "Feature candidates need anisotropy κ3 below this."),
        choice("analysis.filtered_normals.mode", &["off", "global", "sizing_aware"], "Normal filter (Ebke et al. 2014): off, σ from the global edge length, or from the sizing field."),
        num("analysis.filtered_normals.sigma_factor", 0.0, 10.0, "Filter width σ as a fraction of the edge length (Ebke: 1/2)."),
        num("analysis.filtered_normals.truncation", 0.1, 10.0, "Filter kernel truncated at this many σ."),
        // sizing
        nullable(int("sizing.target_vertex_count", 4.0, 1e7, "Target vertex count of the output; empty = input vertices / 16.")),
        nullable(num("sizing.edge_length", 0.0, 1.0, "Explicit global edge length (fraction of the largest bounding-box axis); overrides the vertex count. Empty = off.")),
        choice("sizing.method", &["osculating_error", "osculating_radius", "transfer_function", "uniform"], "How curvature becomes an edge length."),
        num("sizing.epsilon", 0.0001, 0.5, "Allowed error ε of the osculating-error method, fraction of the largest axis."),
        num("sizing.radius_factor", 0.01, 10.0, "Edge length = factor × osculating radius (osculating_radius method)."),
        p("sizing.transfer_function", Kind::Json, "Control points [c, T(c)] of the transfer function (c: normalised curvature 0–100, T: × global edge length)."),
        num("sizing.min_factor", 0.01, 100.0, "Shortest edge, × global edge length."),
        num("sizing.max_factor", 0.01, 100.0, "Longest edge, × global edge length."),
        num("sizing.thin_part_edges", 0.0, 64.0, "Edges around a thin part's cross-section: the length is capped at π × shape diameter / this; 0 = off."),
        num("sizing.thin_part_gradation", 0.0, 10.0, "Growth of the thin-part cap per unit of distance away from the thin part."),
        // field
        int("field.orientation_iterations", 0.0, 100.0, "Gauss–Seidel sweeps per level of the orientation field (Instant Meshes: 6)."),
        int("field.position_iterations", 0.0, 100.0, "Sweeps per level of the position field (thesis §3.4: 10–15)."),
        choice("field.scale_mode", &["average", "reference-point", "per-vertex"], "How neighbouring lattices of different spacing are compared (thesis §3.4)."),
        choice("field.level_sizing", &["per-level", "summation"], "Sizing on coarse levels: estimated again per level, or summed from the children."),
        flag("field.filtered_normals", "Solve the fields in the tangent planes of the filtered normals."),
        num("field.scale_consistency", 0.0, 1000.0, "Healing length (target edges) over which the lattice spacing follows the cross field's turning, so the grid closes; 0 = off."),
        flag("field.split_long_edges", "Split input edges longer than half a target edge before the fields (Instant Meshes)."),
        int("field.seed", 0.0, 4294967295.0, "Seed of the random initialisation."),
        // alignment
        choice("alignment.mode", &["none", "feature-vertices", "smooth-regions", "both"], "What aligns the fields to principal directions: feature vertices (thesis), smooth regions (Campen et al. 2016), both or none."),
        nullable(num("alignment.feature_weight", 0.0, 1e6, "Weight of the feature-vertex constraints; empty = fixed (infinite).")),
        num("alignment.smooth_regions.significance_threshold", 0.0, 180.0, "Smooth regions less significant than this angle (degrees) are discarded (paper: 70)."),
        nullable(num("alignment.region_weight", 0.0, 1e6, "Weight of the a_min constraints inside filtered smooth regions; empty = fixed (infinite, the paper).")),
        num("alignment.position_weight", 0.0, 100.0, "Alignment weight of the position field inside filtered smooth regions."),
        // extraction
        num("extraction.min_cluster_fraction", 0.0, 1.0, "Clusters smaller than this fraction of the average are dropped (thesis: 1/10–1/20)."),
        flag("extraction.snap", "Snap thin triangles during extraction (thesis §3.5.2)."),
        flag("extraction.thesis_quad_score", "Split long faces by the thesis' quad score (the quad's own corners) instead of Instant Meshes'."),
        flag("extraction.triangulation_pairs", "The non-manifold repair also removes face diagonals that another face uses (thesis §3.6), not only non-manifold edges."),
        flag("extraction.keep_cap_vertices", "The pair repair keeps a vertex on only the pair's two faces (a horn tip) by splitting one of them, where that adds no odd face."),
        flag("extraction.bridge_fragments", "Join closed fragments of the face tracing (a thin part's tip) to the mesh by a tube instead of dropping them."),
        int("extraction.max_hole", 3.0, 1000.0, "Holes up to this many corners are filled."),
        flag("extraction.fan_large_holes", "Close larger holes that are not the input's with a centroid fan."),
        flag("extraction.vertex_count_correction", "Solve position + extraction again with corrected spacing when the vertex count misses the target."),
        num("extraction.count_tolerance", 0.0, 1.0, "Allowed relative miss of the target vertex count."),
        int("extraction.restarts", 0.0, 20.0, "Extra attempts from the next position-field seeds while the result misses the gate (count within 10 %, at most 10 % non-quads)."),
        flag("extraction.post.t_vertices", "Remove T-vertices."),
        num("extraction.post.t_vertex_plane_degrees", 0.0, 90.0, "T-vertex faces are coplanar within this normal angle."),
        num("extraction.post.t_vertex_line_degrees", 0.0, 90.0, "T-vertex edges are collinear within 180° ± this."),
        flag("extraction.post.feature_quads", "Remove or split quads that fold over a feature."),
        flag("extraction.post.flat_triangles", "Merge flat triangle pairs into quads."),
        num("extraction.post.flat_triangle_degrees", 0.0, 90.0, "Triangle pairs are flat within this normal angle."),
        num("extraction.post.pair_non_quads_degrees", 0.0, 180.0, "Merge neighbouring odd faces into quads within this normal angle; 0 = off."),
        num("extraction.post.pair_max_corner_deviation", 0.0, 90.0, "Odd-face pairing makes only quads whose corners lie within 90° ± this."),
        num("extraction.post.pair_fallback_degrees", 0.0, 180.0, "A second pairing round within this normal angle for the odd faces still above the budget; 0 = off."),
        flag("extraction.post.collapse_odd_edges", "Collapse edges between two odd faces (folded tips of thin parts) while the odd faces are above the budget."),
        int("extraction.post.pair_max_quads", 0.0, 100.0, "Odd faces pair across strips of at most this many quads."),
        num("extraction.post.non_quad_budget_percent", 0.0, 100.0, "The odd-face pairing stops, shortest chains first, once at most this percentage of faces is odd (0 = pair all it can)."),
        num("extraction.post.split_reflex_degrees", 0.0, 360.0, "Quads with a corner above this are split into two triangles before the pairing; 0 = off."),
        num("extraction.post.rotate_edges_degrees", 0.0, 90.0, "Valence-improving edge rotations between quads, making only quads with corners within 90° ± this; 0 = off."),
        num("extraction.post.wide_corner_degrees", 0.0, 180.0, "Edge rotations also open quad corners wider than this (0 = off)."),
        flag("extraction.post.fix_wide_corners", "Last step: quads still wider than the wide-corner angle are untangled (vertices moved) or split into triangles."),
        num("extraction.post.wide_corner_split_budget_percent", 0.0, 100.0, "Wide-corner splits whose triangles found no other odd face to pair with are taken back while the odd faces exceed this percentage."),
        flag("extraction.post.collapse_diagonals", "Collapse quads between two valence-3 corners when that evens out the valences."),
        int("extraction.post.smoothing_iterations", 0.0, 100.0, "Tangential smoothing iterations."),
        num("extraction.post.smoothing_feature_degrees", 0.0, 180.0, "Smoothing keeps vertices whose dihedral angle exceeds this (features)."),
        flag("extraction.post.regular_shape_smoothing", "Smooth towards each face's best-fitting regular polygon (square for quads) instead of the neighbours' mean."),
        flag("extraction.post.reproject", "Project the vertices onto the input at the end."),
        int("extraction.post.least_squares_iterations", 0.0, 100.0, "Last step (local mode; global with remesh.least_squares_placement): least-squares steps moving the vertices so the faces, not only the vertices, approximate the input (0 = vertices on the input)."),
        flag("extraction.post.reopen_input_holes", "Remove the faces over an input hole (at least two edges around) that the output closed over."),
        flag("extraction.pure_quad", "One Catmull–Clark split at the end: an all-quad mesh."),
        // fit
        int("fit.max_iterations", 0.0, 200.0, "Most control-mesh fitting iterations (Thaller et al. 2016: 20)."),
        num("fit.tolerance", 0.0, 0.1, "Stop when the largest move is below this fraction of the largest axis."),
        num("fit.ray_length", 0.0, 100.0, "Normal lines are searched this many local edge lengths each way; also the largest move."),
        choice("fit.boundary", &["fixed", "crease"], "Boundary rule of subdivision: fixed (thesis) or B-spline crease."),
        num("fit.crease_degrees", 0.0, 180.0, "Input edges whose normals differ by more than this many degrees are feature curves; control edges along them become sharp creases. 0 turns creases off."),
        int("fit.error_levels", 0.0, 5.0, "Subdivision levels of the limit mesh the error is measured and shown on."),
        flag("fit.measure_before", "Also measure the limit error of the unfitted control mesh."),
        int("fit.lspia_iterations", 0.0, 100.0, "Most least-squares steps after the normal offsets (LSPIA, Deng and Lin 2014): the limit surface's samples pull their control vertices onto the input; 0 keeps the thesis' fit."),
        choice("fit.split", &["auto", "always", "non-quads"], "One Catmull–Clark split before fitting: auto (in the local mode; the global mode's pure quads are fitted as they are), always, or only when a face is not a quad."),
    ]
}

/// The schema with each parameter's default, as JSON:
/// `[{ path, help, kind, min?, max?, options?, nullable, default }]`.
pub fn schema_json() -> serde_json::Value {
    let defaults = serde_json::to_value(Params::default()).expect("parameters serialise");
    serde_json::Value::Array(
        schema()
            .into_iter()
            .map(|doc| {
                let mut value = serde_json::to_value(&doc).expect("a schema entry serialises");
                let default = doc
                    .path
                    .split('.')
                    .try_fold(&defaults, |v, k| v.get(k))
                    .cloned()
                    .unwrap_or(serde_json::Value::Null);
                value["default"] = default;
                value
            })
            .collect(),
    )
}

/// The dotted paths of every leaf of a parameter JSON (arrays are leaves).
pub fn leaf_paths(value: &serde_json::Value) -> Vec<String> {
    fn walk(prefix: &str, v: &serde_json::Value, out: &mut Vec<String>) {
        match v {
            serde_json::Value::Object(map) => {
                for (k, v) in map {
                    let path = if prefix.is_empty() {
                        k.clone()
                    } else {
                        format!("{prefix}.{k}")
                    };
                    walk(&path, v, out);
                }
            }
            _ => out.push(prefix.to_string()),
        }
    }
    let mut out = Vec::new();
    walk("", value, &mut out);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_parameter_has_exactly_one_entry() {
        let defaults = serde_json::to_value(Params::default()).unwrap();
        let mut leaves = leaf_paths(&defaults);
        let mut documented: Vec<String> = schema().iter().map(|d| d.path.to_string()).collect();
        leaves.sort();
        documented.sort();
        assert_eq!(documented, leaves);
    }

    #[test]
    fn defaults_are_in_range_and_choices_round_trip() {
        let defaults = serde_json::to_value(Params::default()).unwrap();
        for entry in schema_json().as_array().unwrap() {
            let path = entry["path"].as_str().unwrap();
            let default = &entry["default"];
            if default.is_null() {
                assert!(entry["nullable"].as_bool().unwrap(), "{path}: null default");
                continue;
            }
            if let (Some(min), Some(max), Some(x)) = (
                entry["min"].as_f64(),
                entry["max"].as_f64(),
                default.as_f64(),
            ) {
                assert!(
                    min <= x && x <= max,
                    "{path}: default {x} outside [{min}, {max}]"
                );
            }
            // Every listed option deserialises into the parameters.
            for option in entry["options"].as_array().into_iter().flatten() {
                let mut changed = defaults.clone();
                let mut slot = &mut changed;
                for key in path.split('.') {
                    slot = slot.get_mut(key).unwrap();
                }
                *slot = option.clone();
                serde_json::from_value::<Params>(changed)
                    .unwrap_or_else(|e| panic!("{path} = {option}: {e}"));
            }
        }
    }
}
