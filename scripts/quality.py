#!/usr/bin/env python3
"""The ablation table: Instant Meshes, Quadrille in an Instant-Meshes-equivalent
configuration, that configuration plus each thesis or paper modification on
its own, and the default -- every output measured by the same code.

For each shared mesh at its default target (input vertices / 16):
  instant-meshes   pyinstantmeshes (quad-dominant, extrinsic, deterministic),
                   as scripts/compare.py drives it;
  quadriflow       pyQuadriFlow (faces requested = target vertices);
  im-equivalent    Quadrille with uniform sizing, no constraints, the input's
                   long edges split (IM's subdivision), Instant Meshes' extraction (its quad score, holes up to 6 corners,
                   no count correction, no restarts) and no post-processing
                   beyond Instant Meshes' (2 smoothing steps with reprojection);
  +<modification>  im-equivalent with one change (the overlays in ROWS);
  default          Quadrille's defaults;
  global           Quadrille's global mode (`remesh.mode` global: the
                   integer-grid map and QEx extraction, pure quads), its
                   quad mesh fitted as it is (`fit.split` non-quads: the
                   pure-quad mesh is the control mesh, no Catmull-Clark
                   split; the `control V` column says how many control
                   vertices each row's limit surface has).
Every output: `quadrille metrics OUT --reference IN` and `quadrille fit
--reference IN --mesh OUT` (the limit surface after fitting, for every tool
alike). Writes docs/QUALITY.md (the tables) and target/quality/quality.json.

Usage: scripts/quality.py [--bin target/release/quadrille] [--meshes DIR]
         [--names a,b] [--rows im-equivalent,default,...] [--out DIR] [--doc FILE]
`make quality` builds the binary and runs it on every shared mesh.
"""
import argparse
import datetime
import json
import os
import platform
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import compare  # noqa: E402  (the competitors' children, the venv, run_measured)

ROOT = compare.ROOT

# Instant Meshes' configuration in Quadrille's parameters (digest §2–5):
# one global edge length, no orientation constraints, IM's quad score, IM's
# hole filling (orbits of at most 6 corners), and only IM's final smoothing
# (2 umbrella steps projected back onto the input); IM's longest-edge-first
# bisection of input edges longer than min(s/2, 2 x mean edge) (digest §1.3).
IM_EQUIVALENT = {
    "sizing": {"method": "uniform"},
    "alignment": {"mode": "none"},
    "field": {"filtered_normals": False, "split_long_edges": True, "scale_consistency": 0},
    "extraction": {
        "thesis_quad_score": False,
        "triangulation_pairs": True,
        "keep_cap_vertices": False,
        "bridge_fragments": False,
        "max_hole": 6,
        "fan_large_holes": False,
        "vertex_count_correction": False,
        "restarts": 0,
        "post": {
            "t_vertices": False,
            "feature_quads": False,
            "flat_triangles": False,
            "pair_non_quads_degrees": 0,
            "pair_fallback_degrees": 0,
            "collapse_odd_edges": False,
            "rotate_edges_degrees": 0,
            "fix_wide_corners": False,
            "collapse_diagonals": False,
            "smoothing_iterations": 2,
            "reproject": True,
            "reopen_input_holes": False,
            "least_squares_iterations": 0,
        },
    },
}

# One modification each, on top of IM_EQUIVALENT (None = Quadrille's defaults).
ROWS = {
    "im-equivalent": {},
    "+adaptive sizing": {"sizing": {"method": "osculating_error"}, "field": {"scale_mode": "average"}},
    "+adaptive sizing (per-vertex scale)": {"sizing": {"method": "osculating_error"},
                                           "field": {"scale_mode": "per-vertex"}},
    "+feature-vertex constraints": {"alignment": {"mode": "feature-vertices"}},
    "+smooth regions": {"alignment": {"mode": "smooth-regions"}},
    "+filtered normals": {"field": {"filtered_normals": True}},
    "-split long edges": {"field": {"split_long_edges": False}},
    "-snapping": {"extraction": {"snap": False}},
    "+thesis quad score": {"extraction": {"thesis_quad_score": True}},
    # The repair's non-manifold pairs: only non-manifold edges, not the
    # diagonals some triangulation would make non-manifold (thesis §3.6).
    "-triangulation pairs": {"extraction": {"triangulation_pairs": False}},
    # A pair's cap vertex (on only the pair's two faces) kept by a face
    # split instead of removed, where that adds no odd face.
    "+cap vertices kept": {"extraction": {"keep_cap_vertices": True}},
    # Closed fragments joined by a tube instead of dropped.
    "+fragment bridges": {"extraction": {"bridge_fragments": True}},
    "+hole filling (30 corners and fans)": {"extraction": {"max_hole": 30, "fan_large_holes": True}},
    "+count correction and restarts": {"extraction": {"vertex_count_correction": True, "restarts": 3}},
    "+T-vertices": {"extraction": {"post": {"t_vertices": True}}},
    "+feature quads": {"extraction": {"post": {"feature_quads": True}}},
    "+flat triangles": {"extraction": {"post": {"flat_triangles": True}}},
    "+odd-face pairing": {"extraction": {"post": {"pair_non_quads_degrees": 60}}},
    "+edge rotations and diagonal collapses": {"extraction": {"post": {"rotate_edges_degrees": 75,
                                                                       "collapse_diagonals": True}}},
    "+3 smoothing steps": {"extraction": {"post": {"smoothing_iterations": 3}}},
    # The last step: quads with a corner above 170° untangled (vertices
    # moved), then split within a 5 % odd-face budget.
    "+wide-corner fix": {"extraction": {"post": {"fix_wide_corners": True}}},
    # The very last step: the vertices moved so the faces, not only the
    # vertices, approximate the input (src/extract/placement.rs).
    "+least-squares placement": {"extraction": {"post": {"least_squares_iterations": 10}}},
    # The lattice spacing made consistent with the cross field (healing
    # length 5 target edges; src/field/scale_consistency.rs).
    "+scale consistency": {"field": {"scale_consistency": 5}},
    "default": None,
    # The global mode (pure quads from the integer-grid map).
    "global": ("default", {"remesh": {"mode": "global"}}),
    # The global mode at four times the target: its control mesh (the quads
    # themselves) then has about as many vertices as every other row's,
    # whose meshes the fit splits once (V + E + F, about 4 V): the limit
    # columns at equal control-vertex count (issue 19's criterion).
    "global x4": ("default", {"remesh": {"mode": "global"}}, 4),
    # The global mode's modifications, one at a time.
    "global - feature curves": ("default", {"remesh": {"mode": "global", "feature_curve_degrees": 0}}),
    "global x4 - feature curves": ("default", {"remesh": {"mode": "global", "feature_curve_degrees": 0}}, 4),
    "global - stiffening": ("default", {"remesh": {"mode": "global", "stiffening": 0}}),
    "global - conformal scale": ("default", {"remesh": {"mode": "global", "conformal_scale": 0}}),
    "global - loop separation": ("default", {"remesh": {"mode": "global", "loop_separation": 0}}),
    "global loop separation 3": ("default", {"remesh": {"mode": "global", "loop_separation": 3}}),
    "global loop separation 2": ("default", {"remesh": {"mode": "global", "loop_separation": 2}}),
    # The global mode with the thin-part cap (issue 19: the cow's legs).
    "global + thin parts (3 edges)": ("default", {"remesh": {"mode": "global"}, "sizing": {"thin_part_edges": 3}}),
    "global + thin parts (5 edges)": ("default", {"remesh": {"mode": "global"}, "sizing": {"thin_part_edges": 5}}),
    "global + thin parts (8 edges)": ("default", {"remesh": {"mode": "global"}, "sizing": {"thin_part_edges": 8}}),
    # Thin parts asked only across (the map's edge round the part capped,
    # along it kept; src/param/thin_parts.rs, off by default).
    "global + thin parts across (5 round)": ("default", {"remesh": {"mode": "global", "thin_part_across": 5}}),
    # Curvature-aligned anisotropic lengths in the map (src/param/anisotropy.rs,
    # off by default), at equal control-vertex count.
    "global x4 + curvature anisotropy 3": ("default", {"remesh": {"mode": "global", "curvature_anisotropy": 3}}, 4),
    "global + least-squares placement": ("default", {"remesh": {"mode": "global",
                                                                "least_squares_placement": True}}),
    "default - least-squares placement": ("default", {"extraction": {"post": {"least_squares_iterations": 0}}}),
    # The pairing's second round within 90° for odd faces above the budget,
    # then edges between two odd faces collapsed (both on by default).
    "default - odd-edge collapse": ("default", {"extraction": {"post": {"collapse_odd_edges": False}}}),
    "default - pairing fallback and odd-edge collapse": ("default", {"extraction": {"post": {
        "pair_fallback_degrees": 0, "collapse_odd_edges": False}}}),
    # Overlays on the defaults.
    "default - split long edges": ("default", {"field": {"split_long_edges": False}}),
    "default - scale consistency": ("default", {"field": {"scale_consistency": 0}}),
    "default with scale consistency 20 edges": ("default", {"field": {"scale_consistency": 20}}),
    "default with scale consistency 2 edges": ("default", {"field": {"scale_consistency": 2}}),
    "default + feature-vertex constraints": ("default", {"alignment": {"mode": "feature-vertices"}}),
    # Thin parts: the length capped at pi x shape diameter / edges around.
    "default + thin parts (3 edges)": ("default", {"sizing": {"thin_part_edges": 3}}),
    "default + thin parts (5 edges)": ("default", {"sizing": {"thin_part_edges": 5}}),
    "default - triangulation pairs": ("default", {"extraction": {"triangulation_pairs": False}}),
    "default - fragment bridges": ("default", {"extraction": {"bridge_fragments": False}}),
    "default - cap vertices kept": ("default", {"extraction": {"keep_cap_vertices": False}}),
    "default - diagonal collapses": ("default", {"extraction": {"post": {"collapse_diagonals": False}}}),
    "default - edge rotations and collapses": ("default", {"extraction": {"post": {"rotate_edges_degrees": 0}}}),
    "default - non-quad budget (pair all)": ("default", {"extraction": {"post": {"non_quad_budget_percent": 0}}}),
    "default - wide-corner rotations": ("default", {"extraction": {"post": {"wide_corner_degrees": 0}}}),
    "default - wide-corner fix": ("default", {"extraction": {"post": {"fix_wide_corners": False}}}),
    "default with every wide quad split": ("default", {"extraction": {"post": {
        "wide_corner_split_budget_percent": 100}}}),
    "default + regular-shape smoothing": ("default", {"extraction": {"post": {"regular_shape_smoothing": True,
                                                                           "smoothing_iterations": 10}}}),
    # Instant Meshes' own pure-quad route (extract at a quarter of the
    # count, one split), with the odd-face pairing off.
    "default + pure quad": ("default", {"extraction": {"pure_quad": True,
                                                      "post": {"pair_non_quads_degrees": 0}}}),
    # Folded quads split into triangles before the second pairing, whose
    # quads keep every corner within 10°–170°.
    "default + reflex split": ("default", {"extraction": {"post": {"split_reflex_degrees": 170,
                                                                  "pair_max_corner_deviation": 80}}}),
}


def merged(base, overlay):
    out = json.loads(json.dumps(base))
    for k, v in overlay.items():
        if isinstance(v, dict) and isinstance(out.get(k), dict):
            out[k] = merged(out[k], v)
        else:
            out[k] = v
    return out


def measure(args, src, out, fit_params=None):
    m = compare.quadrille_json(args, ["metrics", out, "--reference", src], args.timeout)
    stem = out[:-4]
    cmd = [args.bin, "fit", "--reference", src, "--mesh", out, "-o", stem + "-control.obj",
           "--stats", stem + "-fit.json"]
    if fit_params:
        with open(stem + "-fit-params.json", "w") as f:
            json.dump(fit_params, f)
        cmd += ["--params", stem + "-fit-params.json"]
    rc, _, err, _, _ = compare.run_measured(cmd, timeout=args.timeout)
    fit = json.load(open(stem + "-fit.json")) if rc == 0 else {"error": (err or "").strip()[-200:]}
    return m, fit


def run_quadrille(args, src, stem, overlay, target):
    out, stats = stem + ".obj", stem + ".json"
    if isinstance(overlay, tuple) and len(overlay) == 3:
        target *= overlay[2]
    cmd = [args.bin, "remesh", src, "-o", out, "--stats", stats, "--vertices", str(target)]
    if overlay is not None:
        pfile = stem + "-params.json"
        # ("default", o): o on Quadrille's defaults; a dict: on IM_EQUIVALENT.
        params = overlay[1] if isinstance(overlay, tuple) else merged(IM_EQUIVALENT, overlay)
        with open(pfile, "w") as f:
            json.dump(params, f)
        cmd += ["--params", pfile]
    rc, _, err, wall, _ = compare.run_measured(cmd, timeout=args.timeout)
    if rc != 0:
        return {"error": (err or "").strip()[-300:] or f"exit {rc}"}
    s = json.load(open(stats))
    t = s["timings_ms"]
    row = {"time_ms": sum(v for k, v in t.items() if k not in ("metrics", "fit")), "process_ms": wall}
    # The global mode's pure quads are a control mesh as they are (as the
    # pipeline fits them); every other row's mesh is split once.
    fit_params = {"split": "non-quads"} if s.get("mode") == "global" else None
    row["metrics"], row["fit"] = measure(args, src, out, fit_params)
    if s.get("qex") is not None:
        row["qex"] = s["qex"]
    return row


def run_tool(args, tool, src, stem, target):
    out = stem + ".obj"
    r = compare.run_competitor(args, tool, src, out, target)
    if "error" in r:
        return r
    m = compare.quadrille_json(args, ["metrics", out, "--reference", src], args.timeout)
    got = compare.vertex_count(m)
    if got and abs(got - target) > 0.15 * target:
        r2 = compare.run_competitor(args, tool, src, out, max(4, round(target * target / got)))
        if "error" not in r2:
            r = r2
    r["metrics"], r["fit"] = measure(args, src, out)
    return r


# The rows run again on re-ordered copies of each input: one sample of a
# field-guided remesher is a draw from a distribution (its random start
# and its coarsening follow the vertex order), so the reproduction and
# acceptance ratios are also read off medians over the same re-orderings
# for every tool.
ORDER_ROWS = ("instant-meshes", "im-equivalent", "+scale consistency", "default", "global", "global x4",
              "global - feature curves", "global x4 - feature curves", "global - conformal scale",
              "default - scale consistency", "default + feature-vertex constraints",
              "default + thin parts (5 edges)", "default - wide-corner fix", "default - fragment bridges",
              "default - cap vertices kept", "default - least-squares placement", "default - odd-edge collapse",
              "default - pairing fallback and odd-edge collapse",
              "global + least-squares placement", "global - loop separation", "global loop separation 3",
              "global loop separation 2", "global + thin parts (5 edges)", "global + thin parts (8 edges)",
              "global + thin parts across (5 round)", "global x4 + curvature anisotropy 3")


def default_target(args, src, divisor=16):
    """The target vertex count for `src` (its imported vertices / divisor)
    and its topology as `quadrille metrics` reports it."""
    info = compare.quadrille_json(args, ["metrics", src, "--reference", src], args.timeout)
    topo = info.get("metrics", info).get("topology", {})
    nv = topo.get("vertices") or info.get("vertices")
    return max(1, nv // divisor), topo


def reordered_copy(src, dst, seed):
    """src with its vertices and faces shuffled (seeded): the same surface,
    the coordinates copied as written."""
    import random
    verts, faces = [], []
    with open(src) as f:
        for line in f:
            p = line.split()
            if p and p[0] == "v":
                verts.append(p[1:4])
            elif p and p[0] == "f":
                faces.append([int(x.split("/")[0]) for x in p[1:]])
    n = len(verts)
    new = list(range(n))
    random.Random(seed).shuffle(new)
    old = [0] * n
    for i, k in enumerate(new):
        old[k] = i
    random.Random(seed + 1).shuffle(faces)
    with open(dst, "w") as out:
        for k in range(n):
            out.write("v " + " ".join(verts[old[k]]) + "\n")
        for face in faces:
            out.write("f " + " ".join(str(new[(i - 1) if i > 0 else n + i] + 1) for i in face) + "\n")


def limit_in(after):
    """The fitted limit surface's other direction (input vertices → limit
    surface) and the two-sided mean (the mean of both directions' means).
    Limit → input alone does not see input parts the limit surface leaves
    out (a dropped handle, a rounded crease): a surface covering half the
    input can have a small one-sided mean."""
    a, b = after.get("stats", {}).get("mean"), after.get("reference_to_limit", {}).get("mean")
    return {"limit_in": b, "limit2": 0.5 * (a + b) if a is not None and b is not None else None}


def cells(row):
    """The table cells of one measured row (None where not measured)."""
    m = row.get("metrics", {})
    fit = row.get("fit", {}).get("fit", {})
    after = fit.get("after", {}) if fit else {}
    if "metrics" in m:
        M = m["metrics"]
        tp, q, d = M["topology"], M["quads"], M["distance"]
        kept = M.get("preservation")
        return {
            "closed": len(kept["loops_closed"]) if kept else None,
            "lost": len(kept["components_lost"]) if kept else None,
            "V": tp["vertices"], "nonquad": tp["non_quad_percent"], "ev": tp["extraordinary_vertex_percent"],
            "corner": q["corner_angle_deviation_degrees"], "distorted": q.get("distorted_quad_percent"),
            "maxcorner": q.get("max_corner_angle_degrees"),
            "hausdorff": d["hausdorff"], "out_in": d["output_to_input_mean"], "in_out": d["input_to_output_mean"],
            "limit": after.get("stats", {}).get("mean"), **limit_in(after), "loops": tp["boundary_loops"],
            "controlV": fit.get("control_vertices") if fit else None,
            "manifold": tp["nonmanifold_edges"] == 0 and tp["nonmanifold_vertices"] == 0,
            "genus": tp.get("genus"), "time": row.get("time_ms"),
        }
    if "topology" in m:  # a non-manifold output: counts only
        tp = m["topology"]
        q = m.get("quads", {})
        return {"V": m.get("vertices"), "nonquad": m.get("non_quad_percent"), "hausdorff": m.get("hausdorff"),
                "ev": m.get("extraordinary_vertex_percent"), "corner": q.get("corner_angle_deviation_degrees"),
                "distorted": q.get("distorted_quad_percent"), "maxcorner": q.get("max_corner_angle_degrees"),
                "limit": after.get("stats", {}).get("mean"), **limit_in(after), "manifold": False,
                "controlV": fit.get("control_vertices") if fit else None,
                "time": row.get("time_ms"),
                "loops": None}
    return None


def f(x, spec):
    return "–" if x is None or x != x else format(x, spec)


HEADER = ("| configuration | V | non-quad % | EV % | corner dev ° | quads outside 45–135° % | max corner ° "
          "| Hausdorff | mean out→in | mean in→out | limit mean after fit | limit in→out | control V "
          "| boundary loops in/out | loops closed over / parts lost | time ms |\n"
          "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")


def mesh_table(name, entry):
    lines = [f"### {name} (target {entry['target']} V, input boundary loops {entry['input_loops']})", "", HEADER]
    for label, row in entry["rows"].items():
        if "error" in row:
            lines.append(f"| {label} | not run: {row['error'][:140]} |" + " – |" * 14)
            continue
        c = cells(row)
        if c is None:
            lines.append(f"| {label} | metrics failed |" + " – |" * 14)
            continue
        note = "" if c.get("manifold", True) else " (non-manifold)"
        lines.append(
            f"| {label}{note} | {f(c['V'], 'd')} | {f(c['nonquad'], '.1f')} | {f(c.get('ev'), '.1f')} "
            f"| {f(c.get('corner'), '.1f')} | {f(c.get('distorted'), '.1f')} | {f(c.get('maxcorner'), '.0f')} "
            f"| {f(c['hausdorff'], '.2e')} | {f(c.get('out_in'), '.2e')} | {f(c.get('in_out'), '.2e')} "
            f"| {f(c['limit'], '.2e')} | {f(c.get('limit_in'), '.2e')} | {f(c.get('controlV'), 'd')} "
            f"| {entry['input_loops']}/{f(c['loops'], 'd')} "
            f"| {f(c.get('closed'), 'd')} / {f(c.get('lost'), 'd')} | {f(c['time'], '.0f')} |")
    return lines


def ratio_table(results):
    """Default and im-equivalent against Instant Meshes, per mesh: the
    acceptance ratios of the quality issue."""
    lines = ["| mesh | configuration | EV % / IM | corner dev / IM | mean out→in / IM | Hausdorff / IM "
             "| limit after fit / IM | two-sided limit / IM | non-quad % |", "|---|---|---|---|---|---|---|---|---|"]
    for name, entry in results["meshes"].items():
        im = cells(entry["rows"].get("instant-meshes", {})) or {}
        for label in ("im-equivalent", "default", "global", "global x4", "global - feature curves",
                      "global x4 - feature curves", "global - stiffening", "global - conformal scale",
                      "global x4 + curvature anisotropy 3"):
            row = entry["rows"].get(label)
            c = cells(row) if row and "error" not in row else None
            if not c:
                continue

            def r(k):
                a, b = c.get(k), im.get(k)
                return f"{a / b:.2f}" if a is not None and b else "–"
            lines.append(f"| {name} | {label} | {r('ev')} | {r('corner')} | {r('out_in')} | {r('hausdorff')} "
                         f"| {r('limit')} | {r('limit2')} | {f(c['nonquad'], '.1f')} |")
    return lines


def median(xs):
    xs = sorted(x for x in xs if x is not None and x == x)
    if not xs:
        return None
    k = len(xs) // 2
    return xs[k] if len(xs) % 2 else 0.5 * (xs[k - 1] + xs[k])


ORDER_KEYS = (("ev", "EV %", ".1f"), ("corner", "corner dev °", ".2f"), ("nonquad", "non-quad %", ".1f"),
              ("out_in", "mean out→in", ".2e"), ("hausdorff", "Hausdorff", ".2e"), ("limit", "limit after fit", ".2e"),
              ("limit2", "two-sided limit", ".2e"))


def order_table(results):
    """Medians over the re-ordered inputs, and their ratios to Instant
    Meshes' median."""
    lines = ["| mesh | row | runs | " + " | ".join(f"{h} (min–max)" for _, h, _ in ORDER_KEYS)
             + " | EV / IM | corner / IM | mean out→in / IM | Hausdorff / IM | limit / IM | two-sided limit / IM |",
             "|---|---|---|" + "---|" * (len(ORDER_KEYS) + 6)]
    for name, entry in results["meshes"].items():
        samples = entry.get("orders", {})
        med = {label: {k: median([c.get(k) for c in cs]) for k, _, _ in ORDER_KEYS} for label, cs in samples.items()}
        im = med.get("instant-meshes", {})
        for label in ORDER_ROWS:
            cs = samples.get(label)
            if not cs:
                continue
            row = [name, label, str(len(cs))]
            for k, _, spec in ORDER_KEYS:
                vals = [c.get(k) for c in cs if c.get(k) is not None]
                row.append(f"{f(med[label][k], spec)} ({f(min(vals), spec)}–{f(max(vals), spec)})" if vals else "–")
            for k in ("ev", "corner", "out_in", "hausdorff", "limit", "limit2"):
                a, b = med[label].get(k), im.get(k)
                row.append(f"{a / b:.2f}" if label != "instant-meshes" and a is not None and b else "–")
            lines.append("| " + " | ".join(row) + " |")
    return lines


def stamp():
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT, capture_output=True,
                            text=True).stdout.strip()
    now = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    return now, commit


def write_doc(args, results, rewritten=None):
    now, commit = results.get("generated") or stamp()
    lines = [
        "# Remeshing quality: the ablation table",
        "",
        f"Generated by `make quality` (`scripts/quality.py`) on {now} at commit `{commit}` "
        f"({platform.machine()}); every number below was measured by that run. Regenerate with `make quality`.",
        "",
    ]
    if rewritten:
        lines += [f"Rewritten from that run's files by `scripts/quality.py --redoc` on {rewritten[0]} at commit "
                  f"`{rewritten[1]}` (columns added since are read from the same runs' fit files).", ""]
    lines += [
        f"Each mesh at {'its default target (input vertices / 16)' if args.divisor == 16 else f'input vertices / {args.divisor}'}. Rows: Instant Meshes (pyinstantmeshes, "
        "quad-dominant, extrinsic, deterministic) and QuadriFlow (pyQuadriFlow), then Quadrille in an "
        "**Instant-Meshes-equivalent configuration** (uniform sizing, no orientation constraints, the input's "
        "long edges bisected as Instant Meshes does, Instant Meshes' quad score and hole filling up to 6 corners, no count correction or restarts, no "
        "post-processing but 2 smoothing steps with reprojection), then that configuration plus **one** "
        "modification per row, and Quadrille's defaults; *global* is Quadrille's global mode (integer-grid "
        "map, QEx extraction: pure quads), whose quad mesh is fitted as it is (no Catmull–Clark split, so its "
        "limit surface has a quarter of the others' control vertices: the *control V* column). The "
        "configuration overlays are `ROWS` in scripts/quality.py.",
        "",
        "Every output is measured by the same code: `quadrille metrics OUT --reference IN` and `quadrille fit "
        "--reference IN --mesh OUT` (limit surface of the fitted Catmull–Clark control mesh, 2 levels; the fit "
        "is the thesis' normal offsets and then up to 10 least-squares steps, `fit.lspia_iterations`). "
        "Distances are fractions of the input's largest bounding-box axis; Hausdorff is two-sided; "
        "EV = interior vertices of valence ≠ 4 and boundary vertices of valence ≠ 3; corner dev = mean "
        "|interior angle − 90°| over quad corners; a reflex corner reads above 180°. Loops closed over / "
        "parts lost: input boundary loops at least 2 output edges long that the output closed (not along a "
        "gap narrower than an edge) and input parts with no output within an edge (metrics.rs, "
        "`PreservationMetrics`). Non-manifold outputs "
        "(marked) get what the non-manifold path of `quadrille metrics` gives: counts, EV (valence = distinct "
        "edge neighbours), quad shape and Hausdorff distance, no mean distances. Time = import through "
        "post-processing (Quadrille's `timings_ms`) or the competitor's remesh call; single runs.",
        "",
        "## Against Instant Meshes (ratios; the quality issue asks EV ≤ 2×, corner ≤ 1.5×, distances ≤ 1×, "
        "limit ≤ 0.8×, non-quad ≤ 5 %)",
        "",
        "The limit surface is measured both ways: *limit after fit* is the mean distance of the limit "
        "surface's samples to the input (the issue's figure), *limit in→out* the mean distance of the input's "
        "vertices to the limit surface, and the *two-sided limit* the mean of the two. The first alone does not "
        "see input parts the limit surface leaves out (a dropped handle, a rounded-off crease, a hole).",
        "",
    ]
    lines += ratio_table(results)
    if any(entry.get("orders") for entry in results["meshes"].values()):
        lines += ["", f"## Over {args.orders} vertex orders (medians)", "",
                  "One run of a field-guided remesher is one draw: its random start and its coarsening follow "
                  "the vertex order. Here Instant Meshes, the Instant-Meshes-equivalent configuration and the "
                  "defaults run on the input and on re-ordered copies of it (vertices and faces shuffled with "
                  "seeds 1, 2, …; the same surface), and each cell is the median (min–max) over those runs; "
                  "the ratios are medians against Instant Meshes' median. Non-manifold outputs have no mean "
                  "distances, so those medians are over fewer runs.", ""]
        lines += order_table(results)
    lines += ["", "## Per mesh", ""]
    for name, entry in results["meshes"].items():
        lines += mesh_table(name, entry) + [""]
    with open(args.doc, "w") as out:
        out.write("\n".join(lines))


def stem_of(out, name, label, order=0):
    clean = "".join(ch if ch.isalnum() else "_" for ch in (label if order else label.strip("+-")))
    return os.path.join(out, f"{name}-order{order}-{clean}" if order else f"{name}-{clean}")


def redoc(args):
    """The doc again from a finished run's files: the rows' cells are
    recomputed from quality.json, the re-ordered runs' cells gain what
    their fit files hold (so a new column needs no new run)."""
    results = json.load(open(os.path.join(args.out, "quality.json")))
    for name, entry in results["meshes"].items():
        for label, cs in entry.get("orders", {}).items():
            base = cells(entry["rows"][label])
            fixed = [base] if base else []
            for k, c in enumerate(cs[1:], start=1):
                try:
                    fit = json.load(open(stem_of(args.out, name, label, k) + "-fit.json")).get("fit", {})
                except (OSError, ValueError):
                    fit = {}
                after = fit.get("after", {})
                got = after.get("stats", {}).get("mean")
                if c.get("limit") is not None and got is not None and abs(got - c["limit"]) > 1e-12:
                    sys.exit(f"quality: {name} order {k} {label}: the fit file is from another run")
                fixed.append({**c, **limit_in(after)})
            entry["orders"][label] = fixed
    if "generated" not in results:
        # A run from before the stamp was kept: the old doc's header says.
        import re
        old = re.search(r"on (\S+ \S+ UTC) at commit `(\w+)`", open(args.doc).read()) if os.path.exists(args.doc) else None
        if not old:
            sys.exit(f"quality: {args.out}/quality.json does not say which run made it")
        results["generated"] = (old.group(1), old.group(2))
    write_doc(args, results, rewritten=stamp())
    print(f"quality: rewrote {args.doc} from {args.out}", file=sys.stderr)


def main():
    if len(sys.argv) > 1 and sys.argv[1] == "--child":
        compare.competitor_child(sys.argv[2], sys.argv[3], sys.argv[4], int(sys.argv[5]))
        return
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--bin", default=os.path.join(ROOT, "target", "release", "quadrille"))
    ap.add_argument("--meshes", default=os.environ.get("QUADRILLE_MESHES",
                                                       os.path.join(ROOT, "..", "shared", "meshes")))
    ap.add_argument("--names", default=",".join(compare.NAMES))
    ap.add_argument("--rows", default=",".join(["instant-meshes", "quadriflow"] + list(ROWS)))
    ap.add_argument("--out", default=os.path.join(ROOT, "target", "quality"))
    ap.add_argument("--doc", default=os.path.join(ROOT, "docs", "QUALITY.md"))
    ap.add_argument("--timeout", type=float, default=1200)
    ap.add_argument("--divisor", type=int, default=16,
                    help="target = input vertices / DIVISOR (16 is the default target)")
    ap.add_argument("--orders", type=int, default=5,
                    help="runs of instant-meshes, im-equivalent and default on re-ordered inputs (1 = input only)")
    ap.add_argument("--redoc", action="store_true",
                    help="rewrite the doc from OUT/quality.json and the runs' files in OUT without running anything")
    args = ap.parse_args()
    if args.redoc:
        redoc(args)
        return
    rows = [r for r in args.rows.split(",") if r]
    for r in rows:
        if r not in ROWS and r not in compare.TOOLS:
            ap.error(f"unknown row {r!r}")
    if not os.path.exists(args.bin):
        sys.exit(f"quality: {args.bin} does not exist: run `cargo build --release` first")
    os.makedirs(args.out, exist_ok=True)
    tools = [r for r in rows if r in compare.TOOLS]
    status = compare.ensure_venv(tools) if tools else {}
    results = {"meshes": {}, "generated": stamp()}
    for name in args.names.split(","):
        src = os.path.abspath(os.path.join(args.meshes, name + ".obj"))
        if not os.path.exists(src):
            sys.exit(f"quality: {src} does not exist (set --meshes or QUADRILLE_MESHES)")
        target, topo = default_target(args, src, args.divisor)
        entry = {"target": target, "input_loops": topo.get("boundary_loops", "–"), "rows": {}}
        for label in rows:
            stem = stem_of(args.out, name, label)
            if label in compare.TOOLS:
                row = {"error": status[label]} if status.get(label) else run_tool(args, label, src, stem, target)
            else:
                row = run_quadrille(args, src, stem, ROWS[label], target)
            c = cells(row) if "error" not in row else None
            print(f"quality {name} {label}: " + (json.dumps({k: v for k, v in c.items()}) if c else str(row.get("error"))),
                  file=sys.stderr)
            entry["rows"][label] = row
        entry["orders"] = {label: [c for c in [cells(entry["rows"][label])] if c]
                           for label in ORDER_ROWS if label in entry["rows"] and "error" not in entry["rows"][label]}
        for k in range(1, args.orders):
            copy = os.path.join(args.out, f"{name}-order{k}-input.obj")
            reordered_copy(src, copy, k)
            for label in entry["orders"]:
                stem = stem_of(args.out, name, label, k)
                if label in compare.TOOLS:
                    row = run_tool(args, label, copy, stem, target)
                else:
                    row = run_quadrille(args, copy, stem, ROWS[label], target)
                c = cells(row) if "error" not in row else None
                print(f"quality {name} order {k} {label}: " + (json.dumps(c) if c else str(row.get("error"))),
                      file=sys.stderr)
                if c:
                    entry["orders"][label].append(c)
        results["meshes"][name] = entry
        with open(os.path.join(args.out, "quality.json"), "w") as out:
            json.dump(results, out, indent=1)
        write_doc(args, results)
    print(f"quality: wrote {args.doc}", file=sys.stderr)


if __name__ == "__main__":
    main()
