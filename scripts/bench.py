#!/usr/bin/env python3
"""`make bench`: Quadrille's speed and quality, measured, into
target/bench/results.json, docs/RESULTS.md and the README's headline block.

1. Native: `quadrille remesh IN -o OUT --stats S.json` on every mesh in the
   shared meshes and on the Stanford bunny subdivided 1-to-4 once and twice
   (~278k and ~1.1M triangles, made by `examples/subdivide.rs` under
   target/bench/), each run a fresh process, REPEATS times: per-stage
   milliseconds (the CLI's `timings_ms`), wall time and peak RSS (wait4's
   ru_maxrss of that process); medians. The shared meshes are also run with
   RAYON_NUM_THREADS=1, the fair partner of the single-threaded wasm build,
   and in the global mode (`--mode global`: analysis, parametrization, QEx
   extraction; `--skip-global` leaves it out).
2. Browser: tests/e2e/bench.mjs runs the web app in headless Chromium (wasm
   in the worker) on the same meshes; the page's per-stage milliseconds.
3. Competitors: scripts/compare.py (Quadrille local and global, Instant
   Meshes, QuadriFlow).
4. The global path: `quadrille param IN -o OUT.obj --stats S.json` (the
   integer-grid map, issue 18) on the bunny, fandisk, rocker-arm and spot at
   the default target, PARAM_REPEATS fresh processes each: per-stage
   milliseconds (the stats' `timings`), wall time, peak RSS; medians.
5. Renders docs/RESULTS.md and the README block between the
   `<!-- results:begin -->` / `<!-- results:end -->` markers.

Usage: scripts/bench.py [--repeats N] [--large-repeats N] [--largest-repeats N] [--browser-repeats N]
         [--large-browser-repeats N] [--param-repeats N] [--skip-native] [--skip-large]
         [--skip-browser] [--skip-global] [--skip-compare] [--skip-param] [--only-param] [--render-only]
`--only-param` measures the parametrization alone (step 4) and rewrites
only its section of docs/RESULTS.md, keeping the rest as it was measured.
Per mesh, the native, one-thread and browser runs follow each other (similar
machine load for the ratio). Each step writes its JSON under target/bench/; a
skipped step keeps the JSON of its last run, so `--render-only` re-renders from what was measured.
Standard library only.
"""
import argparse
import datetime
import json
import os
import platform
import statistics
import subprocess
import sys

sys.dont_write_bytecode = True  # no scripts/__pycache__ in the work tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from compare import HEADER as COMPARE_HEADER, ROOT, run_measured, table_rows  # noqa: E402

BENCH = os.path.join(ROOT, "target", "bench")
BIN = os.path.join(ROOT, "target", "release", "quadrille")
SUBDIVIDE = os.path.join(ROOT, "target", "release", "examples", "subdivide")
SHARED = ["stanford-bunny", "fandisk", "rocker-arm", "spot", "cow", "teapot", "suzanne", "beetle"]
LARGE = [("stanford-bunny-x4", 1), ("stanford-bunny-x16", 2)]  # subdivision levels
STAGES = ["import", "analysis", "hierarchy", "orientation", "position", "extraction", "postprocess"]
GLOBAL_STAGES = ["import", "analysis", "parametrization", "extraction", "postprocess"]
EXTRA = ["fit", "metrics"]
PARAM_MESHES = ["stanford-bunny", "fandisk", "rocker-arm", "spot"]
# The stats' `timings` keys (without `_ms`), in pipeline order.
PARAM_STAGES = ["analysis", "filtered_normals", "cross_field", "cut", "seamless", "rounding", "measures"]
PARAM_HEADING = "## Parametrization (global path)"
RESULTS_JSON = os.path.join(BENCH, "results.json")
PARAM_JSON = os.path.join(BENCH, "param.json")
BROWSER_JSON = os.path.join(BENCH, "browser.json")
COMPARE_JSON = os.path.join(BENCH, "compare.json")
RESULTS_MD = os.path.join(ROOT, "docs", "RESULTS.md")
README = os.path.join(ROOT, "README.md")


def die(message):
    sys.exit(f"bench: {message}")


def median(xs):
    xs = [x for x in xs if x is not None]
    return statistics.median(xs) if xs else None


# ------------------------------------------------------------ inputs

def meshes(args):
    out = []
    for name in args.names.split(","):
        path = os.path.abspath(os.path.join(args.meshes, name + ".obj"))
        if not os.path.exists(path):
            die(f"{path} does not exist (set QUADRILLE_MESHES or --meshes)")
        out.append({"name": name, "path": path, "large": False})
    if not args.skip_large:
        for name, levels in LARGE:
            path = os.path.join(BENCH, name + ".obj")
            if not os.path.exists(path):
                if not os.path.exists(SUBDIVIDE):
                    die(f"{SUBDIVIDE} is missing: cargo build --release --example subdivide")
                src = os.path.join(args.meshes, "stanford-bunny.obj")
                print(f"bench: making {path} ({levels}x 1-to-4 subdivision of the bunny)", file=sys.stderr)
                r = subprocess.run([SUBDIVIDE, src, str(levels), path], capture_output=True, text=True)
                if r.returncode != 0:
                    die(f"subdivide failed: {r.stderr.strip()}")
            out.append({"name": name, "path": path, "large": True, "made_by": f"examples/subdivide.rs, {levels}x 1-to-4 midpoint subdivision of stanford-bunny.obj"})
    for m in out:
        r = subprocess.run([BIN, "info", "--compact", m["path"]], capture_output=True, text=True)
        if r.returncode != 0:
            die(f"quadrille info {m['path']}: {r.stderr.strip()}")
        info = json.loads(r.stdout)
        m["vertices"], m["triangles"] = info["vertices"], info["triangles"]
    return out


# ------------------------------------------------------------ native

def native_runs(mesh, repeats, threads=None, mode="local"):
    env = dict(os.environ)
    if threads:
        env["RAYON_NUM_THREADS"] = str(threads)
    suffix = "" if mode == "local" else "-" + mode
    out = os.path.join(BENCH, "native", mesh["name"] + suffix + ".obj")
    stats = os.path.join(BENCH, "native", mesh["name"] + suffix + ".json")
    os.makedirs(os.path.dirname(out), exist_ok=True)
    runs = []
    for i in range(repeats):
        rc, _, err, wall, rss = run_measured([BIN, "remesh", mesh["path"], "-o", out, "--stats", stats,
                                              "--mode", mode], env=env)
        if rc != 0:
            runs.append({"error": (err or "").strip()[-300:]})
            print(f"bench: native {mode} {mesh['name']} failed: {err.strip()[-300:]}", file=sys.stderr)
            break
        s = json.load(open(stats))
        runs.append({"timings_ms": s["timings_ms"], "wall_ms": wall, "peak_rss_mib": rss / 1024,
                     "target_vertices": s["target_vertices"], "achieved_vertices": s["achieved_vertices"]})
        print(f"bench: native{'' if not threads else f' ({threads} thread)'}{suffix} {mesh['name']} "
              f"run {i + 1}/{repeats}: {wall:.0f} ms, {rss / 1024:.0f} MiB", file=sys.stderr)
    return runs


def summarize_native(runs, stage_names=STAGES):
    ok = [r for r in runs if "error" not in r]
    if not ok:
        return {"error": runs[0]["error"] if runs else "no runs"}
    stages = {k: median([r["timings_ms"].get(k) for r in ok]) for k in stage_names + EXTRA}
    return {
        "repeats": len(ok),
        "stages_ms": stages,
        "pipeline_ms": median([sum(r["timings_ms"].get(k, 0) for k in stage_names) for r in ok]),
        "wall_ms": median([r["wall_ms"] for r in ok]),
        "peak_rss_mib": median([r["peak_rss_mib"] for r in ok]),
        "target_vertices": ok[0]["target_vertices"],
        "achieved_vertices": ok[0]["achieved_vertices"],
    }


def loadavg():
    try:
        return open("/proc/loadavg").read().split()[:3]
    except OSError:
        return None


def measure(args, ms):
    """Per mesh, back to back so that they see the same machine load:
    native runs, native one-thread runs, browser runs."""
    results = load(RESULTS_JSON) if args.skip_native else None
    results = results or {"meshes": {}}
    browser_s = load(BROWSER_JSON) if args.skip_browser else None
    browser_s = browser_s or {"meshes": {}}
    if not args.skip_browser:
        for pkg in ["www/pkg/quadrille.js", "www/pkg/quadrille_bg.wasm", "target/release/examples/serve"]:
            if not os.path.exists(os.path.join(ROOT, pkg)):
                die(f"{pkg} is missing: run `make web` and `cargo build --release --example serve` (make bench does)")
    for m in ms:
        if not args.skip_native:
            reps = args.repeats if not m["large"] else args.largest_repeats if m["name"] == LARGE[-1][0] else args.large_repeats
            entry = {k: m[k] for k in m if k != "path"}
            entry["path"] = os.path.relpath(m["path"], ROOT)
            entry["load_average_at_start"] = loadavg()
            entry["native"] = summarize_native(native_runs(m, reps))
            if not m["large"]:
                entry["native_1_thread"] = summarize_native(native_runs(m, reps, threads=1))
            if not m["large"] and not args.skip_global:
                entry["native_global"] = summarize_native(native_runs(m, reps, mode="global"), GLOBAL_STAGES)
            results["meshes"][m["name"]] = entry
            write_json(RESULTS_JSON, results)
        if not args.skip_browser:
            reps = args.large_browser_repeats if m["large"] else args.browser_repeats
            if reps >= 1:
                browser_one(m, reps, browser_s)
                write_json(BROWSER_JSON, browser_s)
    return results


# ------------------------------------------------------------ parametrization

def param_runs(path, name, repeats):
    """`quadrille param` on one mesh, each run a fresh process."""
    out = os.path.join(BENCH, "param", name + ".obj")
    stats = os.path.join(BENCH, "param", name + ".json")
    os.makedirs(os.path.dirname(out), exist_ok=True)
    runs = []
    for i in range(repeats):
        rc, _, err, wall, rss = run_measured([BIN, "param", path, "-o", out, "--stats", stats])
        if rc != 0:
            runs.append({"error": (err or "").strip()[-300:]})
            print(f"bench: param {name} failed: {err.strip()[-300:]}", file=sys.stderr)
            break
        s = json.load(open(stats))
        m = s["measures"]
        runs.append({"timings_ms": {k[:-3]: v for k, v in s["timings"].items()}, "import_ms": s.get("import_ms"),
                     "total_ms": s["total_ms"], "wall_ms": wall, "peak_rss_mib": rss / 1024,
                     "faces": m["faces"], "cones": m["cones"], "flipped_triangles": m["flipped_triangles"],
                     "degenerate_triangles": m.get("degenerate_triangles"),
                     "rounding_steps": s["rounding_steps"], "e_orient": s["e_orient"]})
        print(f"bench: param {name} run {i + 1}/{repeats}: {wall:.0f} ms, {rss / 1024:.0f} MiB", file=sys.stderr)
    return runs


def summarize_param(runs):
    ok = [r for r in runs if "error" not in r]
    if not ok:
        return {"error": runs[0]["error"] if runs else "no runs"}
    out = {"repeats": len(ok),
           "stages_ms": {k: median([r["timings_ms"].get(k) for r in ok]) for k in PARAM_STAGES + ["parametrization"]},
           "cross_field_with_normals_ms": median([r["timings_ms"]["filtered_normals"] + r["timings_ms"]["cross_field"] for r in ok]),
           "map_ms": median([sum(r["timings_ms"][k] for k in ["filtered_normals", "cross_field", "parametrization"]) for r in ok]),
           "import_ms": median([r["import_ms"] for r in ok]),
           "total_ms": median([r["total_ms"] for r in ok]),
           "wall_ms": median([r["wall_ms"] for r in ok]),
           "peak_rss_mib": median([r["peak_rss_mib"] for r in ok])}
    # The map is deterministic: every run gives the same counts.
    out.update({k: ok[0][k] for k in ["faces", "cones", "flipped_triangles", "degenerate_triangles", "rounding_steps", "e_orient"]})
    return out


def measure_param(args):
    summary = {"meshes": {}}
    for name in PARAM_MESHES:
        path = os.path.abspath(os.path.join(args.meshes, name + ".obj"))
        if not os.path.exists(path):
            die(f"{path} does not exist (set QUADRILLE_MESHES or --meshes)")
        start = loadavg()
        entry = summarize_param(param_runs(path, name, args.param_repeats))
        entry["load_average_at_start"] = start
        summary["meshes"][name] = entry
        write_json(PARAM_JSON, summary)
    summary["meta"] = {"date": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"),
                       "machine": machine()}
    write_json(PARAM_JSON, summary)
    return summary


def render_param(param):
    L = [PARAM_HEADING, ""]
    if not param:
        return L + ["Not measured in this run (`--skip-param`).", ""]
    meta = param.get("meta", {})
    mach = meta.get("machine", {})
    L += [f"`quadrille param IN -o OUT.obj --stats S.json` (the integer-grid map of issue 18: Ebke et al. 2014, "
          f"Campen et al. 2016) at the default target (input vertices / 16) and default parameters, each run a fresh "
          f"process; measured on {meta.get('date', '?')} at commit `{mach.get('commit', '?')}` "
          f"(load average at the end: {', '.join(mach.get('load_average_at_end') or ['?'])}). "
          "Stage times are the stats' `timings` (median over the runs): analysis = curvature, features, calibrated "
          "sizing and topology; normals = Ebke §3's filtered normals (σ = S(f)/2); cross field = the field, its period "
          "jumps and cones (§4); cut = combing and the cut graph through the cones; seamless = constraints, E_orient, the "
          "sparse factorization and condensation onto the integer unknowns, Campen §4.3's loop constraints; rounding = "
          "the greedy rounding's re-solves and the back-substitution; **map** = normals + cross field + cut + seamless + "
          "rounding; total = the CLI's clock from before reading the OBJ to after writing it; wall = the whole process; "
          "flipped = triangles of non-positive parametric area, in brackets those of zero area (collapsed, e.g. small holes). "
          "Single-threaded (the sparse solves run sequentially). The DSW paper reports ~400 ms for the parametrization "
          "of 30k faces.", ""]
    L.append("| mesh | faces | runs | import | analysis | normals | cross field | cut | seamless | rounding (steps) "
             "| **map** | measures | total | wall | peak MiB | cones | flipped (zero area) | load avg |")
    L.append("|---|---|---|" + "---|" * 15)
    for name, e in param.get("meshes", {}).items():
        if "error" in e:
            L.append(f"| {name} | failed: {e['error'][:100]} |")
            continue
        s = e["stages_ms"]
        L.append(f"| {name} | {f0(e['faces'])} | {e['repeats']} | {f0(e['import_ms'])} | {f0(s['analysis'])} "
                 f"| {f0(s['filtered_normals'])} | {f0(s['cross_field'])} | {f0(s['cut'])} | {f0(s['seamless'])} "
                 f"| {f0(s['rounding'])} ({e['rounding_steps']}) | **{f0(e['map_ms'])}** | {f0(s['measures'])} "
                 f"| {f0(e['total_ms'])} | {f0(e['wall_ms'])} | {f0(e['peak_rss_mib'])} | {e['cones']} "
                 f"| {e['flipped_triangles']} ({e.get('degenerate_triangles', '–')}) "
                 f"| {(e.get('load_average_at_start') or ['?'])[0]} |")
    L += ["", "Times in milliseconds; `load avg` is the 1-minute load average when that mesh's runs began (2 cores).", ""]
    return L


def splice_param(text, section):
    """`text` (docs/RESULTS.md) with its parametrization section replaced
    by `section`, or `section` inserted before the design-mode sections."""
    at = text.find("\n" + PARAM_HEADING)
    if at >= 0:
        end = text.find("\n## ", at + 1)
        return text[:at + 1] + section + (text[end + 1:] if end >= 0 else "")
    at = text.find("\n## Design mode")
    if at >= 0:
        return text[:at + 1] + section + text[at + 1:]
    return text.rstrip("\n") + "\n\n" + section


# ------------------------------------------------------------ browser

def browser_one(m, reps, summary):
    """tests/e2e/bench.mjs on one mesh; its medians into summary."""
    out = os.path.join(BENCH, "browser-run.json")
    if os.path.exists(out):
        os.remove(out)
    r = subprocess.run(["node", "bench.mjs", out, str(reps), m["path"]], cwd=os.path.join(ROOT, "tests", "e2e"))
    if r.returncode != 0 or not os.path.exists(out):
        summary["meshes"][m["name"]] = {"error": f"the browser benchmark exited with {r.returncode}"}
        return
    part = json.load(open(out))
    summary.update({k: v for k, v in part.items() if k not in ("meshes", "repeats")})
    runs = part["meshes"].get(m["path"], [])
    ok = [x for x in runs if "error" not in x]
    if not ok:
        summary["meshes"][m["name"]] = {"error": runs[0]["error"] if runs else "no runs"}
        return
    summary["meshes"][m["name"]] = {
        "repeats": len(ok),
        "stages_ms": {k: median([x["stages"].get(k) for x in ok]) for k in STAGES},
        # The same stages as the native pipeline figure (the page's
        # `total_ms` also holds the control-mesh fit).
        "pipeline_ms": median([sum(x["stages"].get(k) or 0 for k in STAGES) for x in ok]),
        "achieved_vertices": ok[0]["counts"]["quad_mesh_vertices"] if ok[0].get("counts") else None,
    }


# ------------------------------------------------------------ rendering

def write_json(path, data):
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "w") as f:
        json.dump(data, f, indent=1)


def load(path):
    return json.load(open(path)) if os.path.exists(path) else None


def machine():
    cpu = "unknown"
    try:
        for line in open("/proc/cpuinfo"):
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    mem = None
    try:
        for line in open("/proc/meminfo"):
            if line.startswith("MemTotal"):
                mem = int(line.split()[1]) / 1024 / 1024
    except OSError:
        pass
    rustc = subprocess.run(["rustc", "--version"], capture_output=True, text=True).stdout.strip()
    node = subprocess.run(["node", "--version"], capture_output=True, text=True).stdout.strip()
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True, cwd=ROOT).stdout.strip()
    return {"load_average_at_end": loadavg(), "cpu": cpu, "cores": os.cpu_count(), "memory_gib": round(mem, 1) if mem else None,
            "os": f"{platform.system()} {platform.release()}", "rustc": rustc, "node": node,
            "python": platform.python_version(), "commit": commit}


def f0(x):
    return "–" if x is None else f"{x:,.0f}"


def ratio(a, b):
    return "–" if a is None or not b else f"{a / b:.2f}×"


def render(results, browser_s, compare, param=None):
    meta = results.get("meta", {})
    mach = meta.get("machine", {})
    L = ["# Quadrille benchmark results", "",
         f"Generated by `make bench` (`scripts/bench.py`) on {meta.get('date', '?')} at commit `{mach.get('commit', '?')}`; "
         "every number below was measured by that run (nothing typed in by hand). Regenerate with `make bench`.", "",
         "## Machine", "",
         f"- CPU: {mach.get('cpu')} ({mach.get('cores')} cores visible), memory {mach.get('memory_gib')} GiB, {mach.get('os')}",
         f"- {mach.get('rustc')}, node {mach.get('node')}, Python {mach.get('python')}" +
         (f", {browser_s.get('browser')}" if browser_s else ""),
         "- The machine is shared (other builds ran at the same time): times are noisy, so every figure is the median "
         "of the repeats shown, and ratios compare numbers measured in the same run. "
         f"Load average (1, 5, 15 min) when the native runs ended: {', '.join(mach.get('load_average_at_end') or ['?'])}.", ""]
    meshes = results.get("meshes", {})
    L += ["## Native pipeline, per stage", "",
          "`quadrille remesh IN -o OUT --stats S.json` at the default target (input vertices / 16), each run a fresh "
          "process; stage times from the CLI's `timings_ms` (median over the runs), `pipeline` = import through "
          "post-processing, `fit` = Catmull–Clark control-mesh fitting, `metrics` = the quality metrics; wall = the "
          "whole process; peak memory = the process's peak RSS (wait4 `ru_maxrss`), which includes fitting and metrics. "
          "Native uses all cores (rayon); the `1 thread` column is the same run with `RAYON_NUM_THREADS=1`. "
          "Per mesh, the native runs, the one-thread runs and the browser runs follow each other, so they see "
          "similar machine load; `load avg` is the 1-minute load average when that mesh's runs began "
          "(2 cores: above 2 means other work was waiting for the CPU).", ""]
    L.append("| mesh | input V / triangles | runs | " + " | ".join(STAGES) + " | **pipeline** | 1 thread | fit | metrics | wall | peak MiB | output V | load avg |")
    L.append("|---|---|---|" + "---|" * (len(STAGES) + 8))
    for name, e in meshes.items():
        n = e.get("native", {})
        if "error" in n:
            L.append(f"| {name} | {f0(e['vertices'])} / {f0(e['triangles'])} | failed: {n['error'][:100]} |")
            continue
        one = e.get("native_1_thread", {})
        s = n["stages_ms"]
        L.append(f"| {name} | {f0(e['vertices'])} / {f0(e['triangles'])} | {n['repeats']} | " +
                 " | ".join(f0(s.get(k)) for k in STAGES) +
                 f" | **{f0(n['pipeline_ms'])}** | {f0(one.get('pipeline_ms'))} | {f0(s.get('fit'))} | {f0(s.get('metrics'))} "
                 f"| {f0(n['wall_ms'])} | {f0(n['peak_rss_mib'])} | {f0(n['achieved_vertices'])} | {(e.get('load_average_at_start') or ['?'])[0]} |")
    large = [e for e in meshes.values() if e.get("large")]
    if large:
        L += ["", "Larger meshes: " + "; ".join(f"`{e['name']}` = {e.get('made_by')}" for e in large) +
              " (no smoothing or projection: the same surface with more triangles; made under target/bench/, never committed)."]
    L += ["", "Times in milliseconds.", ""]

    glob = {name: e["native_global"] for name, e in meshes.items() if e.get("native_global")}
    if glob:
        L += ["### Global mode", "",
              "The shared meshes again with `--mode global` (the integer-grid map and its QEx extraction: pure quads; "
              "`fit` = the pure-quad mesh fitted without the Catmull–Clark split).", "",
              "| mesh | runs | " + " | ".join(GLOBAL_STAGES) + " | **pipeline** | fit | wall | peak MiB | output V |",
              "|---|---|" + "---|" * (len(GLOBAL_STAGES) + 5)]
        for name, g in glob.items():
            if "error" in g:
                L.append(f"| {name} | failed: {g['error'][:120]} |")
                continue
            s = g["stages_ms"]
            L.append(f"| {name} | {g['repeats']} | " + " | ".join(f0(s.get(k)) for k in GLOBAL_STAGES) +
                     f" | **{f0(g['pipeline_ms'])}** | {f0(s.get('fit'))} | {f0(g['wall_ms'])} "
                     f"| {f0(g['peak_rss_mib'])} | {f0(g['achieved_vertices'])} |")
        L.append("")

    L += ["## Browser (wasm in the Web Worker) vs native", ""]
    if not browser_s:
        L += ["Not measured in this run (`--skip-browser`, or the browser benchmark failed).", ""]
    else:
        L += [f"The web app in headless {browser_s.get('browser')} (`tests/e2e/bench.mjs`, flags `{browser_s.get('flags')}`: "
              "no GPU, so the viewer stays off and SwiftShader rendering does not compete with the worker for the cores), "
              "each run a fresh page that first runs its default sample (the warm-up: V8 optimises hot wasm functions "
              "as they run) and is then given the mesh through its file input; stage times are the worker's own "
              "(`window.quadrille.lastRun.stages`). "
              "The wasm build is single-threaded, so the ratio is against native with one thread "
              "(`RAYON_NUM_THREADS=1`) where measured, else against native on all cores (marked *). "
              "Stage ratios are left out (–) where the native stage took under 5 ms.", ""]
        L.append("| mesh | runs | " + " | ".join(f"{k} wasm/native" for k in STAGES) + " | wasm pipeline ms | native ms | **wasm/native** |")
        L.append("|---|---|" + "---|" * (len(STAGES) + 3))
        for name, b in browser_s.get("meshes", {}).items():
            e = meshes.get(name, {})
            n = e.get("native_1_thread") or e.get("native") or {}
            star = "" if e.get("native_1_thread") else "*"
            if "error" in b:
                L.append(f"| {name} | failed: {b['error'][:120]} |")
                continue
            ns = n.get("stages_ms", {})
            L.append(f"| {name} | {b['repeats']} | " + " | ".join(ratio(b["stages_ms"].get(k), ns.get(k)) if (ns.get(k) or 0) >= 5 else "–" for k in STAGES) +
                     f" | {f0(b['pipeline_ms'])} | {f0(n.get('pipeline_ms'))}{star} | **{ratio(b['pipeline_ms'], n.get('pipeline_ms'))}**{star} |")
        L += ["", "Browser import includes building the page's render arrays; native import does not."]
        below = [name for name, b in browser_s.get("meshes", {}).items()
                 if b.get("pipeline_ms") and (meshes.get(name, {}).get("native_1_thread") or {}).get("pipeline_ms")
                 and b["pipeline_ms"] < meshes[name]["native_1_thread"]["pipeline_ms"]]
        if below:
            L += ["", f"wasm was faster than one-thread native on {len(below)} of "
                  f"{sum(1 for n in browser_s.get('meshes', {}) if meshes.get(n, {}).get('native_1_thread'))} meshes "
                  f"({', '.join(below)}; the output vertex counts of wasm and native agree on "
                  f"{sum(browser_s['meshes'][n].get('achieved_vertices') == meshes[n]['native_1_thread'].get('achieved_vertices') for n in below)} "
                  f"of them). Why is not established "
                  "here. One candidate: native runs every parallel loop through rayon (with `RAYON_NUM_THREADS=1` the "
                  "work still moves to the pool's thread and back, once per loop and iteration), and on a loaded "
                  "machine each hand-off waits for the scheduler, while the wasm build runs the same loops inline; "
                  "the memory allocators also differ. Timing on an idle machine would settle it."]
        L.append("")

    L += ["## Quadrille vs Instant Meshes and QuadriFlow", ""]
    if not compare:
        L += ["Not measured in this run (`--skip-compare`).", ""]
    else:
        v = compare.get("versions", {})
        L += ["`scripts/compare.py`: each tool at the same target vertex count as Quadrille (its default, input/16), "
              "one corrective re-run when a competitor's achieved count is >15 % off; every output measured by the same "
              "code (`quadrille metrics OUT --reference IN`, and `quadrille fit` for the limit surface: the competitors' "
              "meshes are fitted by Quadrille's own control-mesh fitting, as in the thesis' chapter 5 table). "
              f"Packages: pyinstantmeshes {v.get('pyinstantmeshes')} (quad-dominant, extrinsic, deterministic; its own polygon OBJ), "
              f"pynanoinstantmeshes {v.get('pynanoinstantmeshes')} (its defaults: pure quad), pyquadriflow {v.get('pyquadriflow')} "
              "(faces requested = target vertices).", "",
              "- time: Quadrille = import through post-processing (`timings_ms`, fitting and metrics excluded); competitors = "
              "the remesh call in a fresh child (Instant Meshes' includes reading the OBJ and writing its output; "
              "QuadriFlow's includes its Python wrapper's ctypes conversion). Single runs, not medians. "
              "Instant Meshes uses all cores (TBB), Quadrille all cores (rayon).",
              "- peak MiB: the process's peak RSS (for competitors: Python + numpy + the library).",
              "- distances are fractions of the input's largest bounding-box axis; Hausdorff is two-sided; "
              "mean dist = output samples → input; centroid dist = mean face centroid → input; "
              "limit = mean distance of the Catmull–Clark limit surface (2 levels) to the input before → after fitting "
              "the control mesh, and its Hausdorff distance after.",
              "- non-manifold outputs only get the counts the non-manifold path of `quadrille metrics` gives (– elsewhere).", "",
              COMPARE_HEADER]
        for name, entry in compare.get("meshes", {}).items():
            L += table_rows(name, entry.get("target"), entry.get("rows", {}))
        bad = {t: s["unavailable"] for t, s in compare.get("tools", {}).items() if s.get("unavailable")}
        for t, why in bad.items():
            L.append(f"\n{t} could not run: {why}")
        L.append("")
    L += render_param(param)
    return "\n".join(L) + "\n"


def headline(results, browser_s, compare):
    meshes = results.get("meshes", {})
    out = []
    b = meshes.get("stanford-bunny", {}).get("native", {})
    if b.get("pipeline_ms"):
        out.append(f"- Stanford bunny ({f0(meshes['stanford-bunny']['vertices'])} vertices → {f0(b['achieved_vertices'])}): "
                   f"{b['pipeline_ms'] / 1000:.2f} s native pipeline, +{b['stages_ms']['fit'] / 1000:.2f} s control-mesh fit, "
                   f"peak {b['peak_rss_mib']:.0f} MiB.")
    big = meshes.get("stanford-bunny-x16", {}).get("native", {})
    if big.get("pipeline_ms"):
        out.append(f"- {f0(meshes['stanford-bunny-x16']['triangles'])}-triangle bunny: {big['pipeline_ms'] / 1000:.1f} s native "
                   f"pipeline, peak {big['peak_rss_mib']:.0f} MiB.")
    if browser_s and "stanford-bunny" in browser_s.get("meshes", {}):
        w = browser_s["meshes"]["stanford-bunny"]
        n = meshes.get("stanford-bunny", {}).get("native_1_thread", {})
        if w.get("pipeline_ms") and n.get("pipeline_ms"):
            out.append(f"- In the browser (wasm, one thread) the bunny takes {w['pipeline_ms'] / 1000:.2f} s: "
                       f"{w['pipeline_ms'] / n['pipeline_ms']:.2f}× native on one thread.")
    if compare and "stanford-bunny" in compare.get("meshes", {}):
        rows = compare["meshes"]["stanford-bunny"]["rows"]
        parts = []
        for tool, label in [("quadrille", "Quadrille"), ("quadrille global", "Quadrille global"),
                            ("instant-meshes", "Instant Meshes"), ("quadriflow", "QuadriFlow")]:
            r = rows.get(tool, {})
            fit = r.get("fit") or {}
            if "time_ms" in r and "after" in fit:
                parts.append(f"{label} {r['time_ms'] / 1000:.2f} s, limit mean {fit['after']['stats']['mean']:.2e}"
                             + (f" ({fit['control_vertices']:,} control vertices)" if fit.get("control_vertices") else ""))
        if parts:
            out.append("- Bunny at the same vertex count (time; limit-surface mean distance after fitting): " + "; ".join(parts) + ".")
    if out:
        out.append("- Measured on a shared 2-core machine under load from other work (load averages in the tables): "
                   "read the ratios, not the absolute times.")
    return "\n".join(out)


def update_readme(text):
    s = open(README).read()
    begin, end = "<!-- results:begin -->", "<!-- results:end -->"
    if begin not in s or end not in s:
        print("bench: README.md has no results markers; not updated", file=sys.stderr)
        return
    a, b = s.index(begin) + len(begin), s.index(end)
    new = s[:a] + "\n" + text + "\n" + s[b:]
    if new != s:
        open(README, "w").write(new)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--meshes", default=os.environ.get("QUADRILLE_MESHES", os.path.join(ROOT, "..", "shared", "meshes")))
    ap.add_argument("--names", default=",".join(SHARED), help="which shared meshes (default: all)")
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--large-repeats", type=int, default=3, help="runs of the ~278k-triangle bunny")
    ap.add_argument("--largest-repeats", type=int, default=2, help="runs of the ~1.1M-triangle bunny (minutes each)")
    ap.add_argument("--browser-repeats", type=int, default=3)
    ap.add_argument("--large-browser-repeats", type=int, default=1)
    ap.add_argument("--param-repeats", type=int, default=5, help="runs of `quadrille param` per mesh")
    ap.add_argument("--skip-native", action="store_true")
    ap.add_argument("--skip-large", action="store_true")
    ap.add_argument("--skip-browser", action="store_true")
    ap.add_argument("--skip-global", action="store_true", help="no native runs in the global mode")
    ap.add_argument("--skip-compare", action="store_true")
    ap.add_argument("--skip-param", action="store_true")
    ap.add_argument("--only-param", action="store_true",
                    help="measure the parametrization alone; rewrite only its section of docs/RESULTS.md")
    ap.add_argument("--render-only", action="store_true")
    args = ap.parse_args()
    os.makedirs(BENCH, exist_ok=True)
    if args.only_param:
        if not os.path.exists(BIN):
            die(f"{BIN} is missing: cargo build --release (make bench does)")
        section = "\n".join(render_param(measure_param(args))) + "\n"
        old = open(RESULTS_MD).read() if os.path.exists(RESULTS_MD) else "# Quadrille benchmark results\n"
        with open(RESULTS_MD, "w") as f:
            f.write(splice_param(old, section))
        print(f"bench: wrote the parametrization section of {os.path.relpath(RESULTS_MD, ROOT)}", file=sys.stderr)
        return
    if not args.render_only:
        if not os.path.exists(BIN):
            die(f"{BIN} is missing: cargo build --release (make bench does)")
        ms = meshes(args)
        results = measure(args, ms)
        if not args.skip_native:
            results["meta"] = {"date": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"),
                               "machine": machine()}
            write_json(RESULTS_JSON, results)
        if not args.skip_param:
            measure_param(args)
        if not args.skip_compare:
            r = subprocess.run([sys.executable, os.path.join(ROOT, "scripts", "compare.py"), "--bin", BIN,
                                "--meshes", args.meshes, "--json", COMPARE_JSON], stdout=subprocess.DEVNULL)
            if r.returncode != 0:
                print(f"bench: the comparison failed (exit {r.returncode})", file=sys.stderr)
    results = load(RESULTS_JSON)
    if results is None:
        die(f"{RESULTS_JSON} does not exist: run without --render-only first")
    browser_s, compare, param = load(BROWSER_JSON), load(COMPARE_JSON), load(PARAM_JSON)
    os.makedirs(os.path.dirname(RESULTS_MD), exist_ok=True)
    # The design-mode sections come from their own benchmarks
    # (examples/bench_anchors.rs, `make bench-design`): kept as they are.
    kept = ""
    if os.path.exists(RESULTS_MD):
        with open(RESULTS_MD) as f:
            old = f.read()
        at = old.find("\n## Design mode")
        if at >= 0:
            kept = old[at:]
    with open(RESULTS_MD, "w") as f:
        f.write(render(results, browser_s, compare, param).rstrip("\n") + "\n" + kept)
    update_readme((headline(results, browser_s, compare) + "\n\n").lstrip() + "Full tables, machine and date: [docs/RESULTS.md](docs/RESULTS.md).")
    print(f"bench: wrote {os.path.relpath(RESULTS_MD, ROOT)} and the README's results block", file=sys.stderr)


if __name__ == "__main__":
    main()
