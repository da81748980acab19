#!/usr/bin/env python3
"""Quadrille vs Instant Meshes and QuadriFlow on the same meshes, in one run.

For each mesh, `quadrille remesh --stats` runs at its default target
(input vertices / 16), in the local mode (the default) and in the global
mode (`--mode global`: integer-grid map, pure quads, fitted by the pipeline
without the Catmull-Clark split, so its control mesh has about a quarter
of the others' control vertices: the `control V` column); then each
competitor runs at the same target vertex count (one corrective re-run if its achieved count is more than 15 % off,
since their targets are not vertex counts in the same sense: QuadriFlow asks
for faces, Instant Meshes' pure-quad mode subdivides once). Every output is
measured by the same code: `quadrille metrics OUT --reference IN` (topology,
quad quality, distances to the input) and `quadrille fit --reference IN
--mesh OUT` (the Catmull-Clark control mesh fitted by Quadrille's fitting,
limit-surface distances before and after fitting) -- the thesis' chapter 5
table.

Competitors (PyPI, installed by this script into .tools/bench-venv):
  instant-meshes       pyinstantmeshes: quad-dominant (posy 4, not pure
                       quad), extrinsic, deterministic; its own OBJ output
                       (remesh_file), which keeps its quads and pentagons.
  nano-instant-meshes  pynanoinstantmeshes (its defaults: extrinsic, pure
                       quad output).
  quadriflow           pyQuadriFlow: requested faces = target vertices
                       (a closed quad mesh has F ~ V), default flags.
Each competitor runs in its own child process (wall time of the remesh call
as measured in that child, peak RSS of the child); a competitor that cannot
be installed, crashes, times out or fails on a mesh is reported as such.

Usage: scripts/compare.py [--bin target/release/quadrille] [--meshes DIR]
         [--names a,b,...] [--out target/bench/compare] [--json FILE]
         [--tools instant-meshes,nano-instant-meshes,quadriflow] [--timeout S]
Prints a Markdown table; the JSON is what scripts/bench.py renders.
Standard library only here; the competitor children use numpy.
"""
import argparse
import json
import os
import subprocess
import sys
import time

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))
VENV = os.path.join(ROOT, ".tools", "bench-venv")
TOOLS = {
    "instant-meshes": "pyinstantmeshes",
    "nano-instant-meshes": "pynanoinstantmeshes",
    "quadriflow": "pyQuadriFlow",
}
NAMES = ["fandisk", "rocker-arm", "spot", "cow", "stanford-bunny", "beetle", "teapot", "suzanne"]


# ------------------------------------------------------------ child processes

class _Popen(subprocess.Popen):
    """Popen that reaps its child with os.wait4 and keeps the child's peak RSS."""
    rusage_maxrss = None

    def _try_wait(self, wait_flags):
        try:
            pid, sts, ru = os.wait4(self.pid, wait_flags)
        except ChildProcessError:
            return self.pid, 0
        if pid == self.pid:
            self.rusage_maxrss = ru.ru_maxrss
        return pid, sts


def run_measured(cmd, timeout=None, **kw):
    """Runs cmd; returns (returncode, stdout, stderr, wall_ms, peak_rss_kib),
    the peak RSS being this very child's (wait4's ru_maxrss, KiB on Linux).
    returncode is None on a time-out."""
    t0 = time.perf_counter()
    p = _Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, **kw)
    try:
        out, err = p.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        p.kill()
        out, err = p.communicate()
        return None, out, f"timed out after {timeout} s", (time.perf_counter() - t0) * 1e3, None
    return p.returncode, out, err, (time.perf_counter() - t0) * 1e3, p.rusage_maxrss


# ------------------------------------------------------------ the venv

def ensure_venv(tools):
    """Creates .tools/bench-venv and installs numpy and the competitors.
    Returns {tool: None if usable, else the reason}."""
    py = os.path.join(VENV, "bin", "python")
    if not os.path.exists(py):
        print(f"compare: creating {VENV}", file=sys.stderr)
        r = subprocess.run([sys.executable, "-m", "venv", VENV], capture_output=True, text=True)
        if r.returncode != 0:
            return {t: f"could not create a venv: {r.stderr.strip()[-300:]}" for t in tools}
    status = {}
    need = ["numpy"] + [TOOLS[t] for t in tools]
    for pkg in need:
        r = subprocess.run([py, "-c", f"import {pkg}"], capture_output=True, text=True)
        if r.returncode == 0:
            continue
        pip_name = "pyquadriflow" if pkg == "pyQuadriFlow" else pkg
        print(f"compare: pip install {pip_name}", file=sys.stderr)
        r = subprocess.run([py, "-m", "pip", "install", "-q", pip_name], capture_output=True, text=True)
        if r.returncode != 0:
            reason = f"pip install {pip_name} failed: {r.stderr.strip().splitlines()[-1] if r.stderr.strip() else r.returncode}"
            if pkg == "numpy":
                return {t: reason for t in tools}
            status[[t for t in tools if TOOLS[t] == pkg][0]] = reason
    for t in tools:
        if t in status:
            continue
        r = subprocess.run([py, "-c", f"import {TOOLS[t]}"], capture_output=True, text=True)
        status[t] = None if r.returncode == 0 else f"import {TOOLS[t]} failed: {r.stderr.strip().splitlines()[-1]}"
    return status


def versions():
    py = os.path.join(VENV, "bin", "python")
    code = ("import importlib.metadata as m, json\n"
            "out = {}\n"
            "for p in ['numpy', 'pyinstantmeshes', 'pynanoinstantmeshes', 'pyquadriflow']:\n"
            "    try: out[p] = m.version(p)\n"
            "    except Exception: out[p] = None\n"
            "print(json.dumps(out))")
    r = subprocess.run([py, "-c", code], capture_output=True, text=True)
    return json.loads(r.stdout) if r.returncode == 0 else {}


# ------------------------------------------------------------ competitor child (runs in the venv)

def obj_triangles(path):
    """The OBJ's vertices and its faces fanned into triangles, as lists
    (0-based, negative indices resolved)."""
    v, f = [], []
    with open(path) as src:
        for line in src:
            p = line.split()
            if not p:
                continue
            if p[0] == "v":
                v.append([float(x) for x in p[1:4]])
            elif p[0] == "f":
                idx = [int(x.split("/")[0]) for x in p[1:]]
                idx = [i - 1 if i > 0 else len(v) + i for i in idx]
                for k in range(1, len(idx) - 1):
                    f.append([idx[0], idx[k], idx[k + 1]])
    return v, f


def read_obj_triangles(path):
    import numpy as np
    v, f = obj_triangles(path)
    return np.array(v, np.float32), np.array(f, np.int32)


def read_obj_polygons(path):
    v, f = [], []
    with open(path) as src:
        for line in src:
            p = line.split()
            if p and p[0] == "v":
                v.append([float(x) for x in p[1:4]])
            elif p and p[0] == "f":
                f.append([int(x.split("/")[0]) - 1 for x in p[1:]])
    return v, f


def write_obj(path, v, faces):
    """Writes the OBJ; returns how many degenerate faces (a corner repeated
    other than as the array padding of a triangle, e.g. [a, b, a, c]) were
    left out: they have no area and Quadrille's reader rejects them."""
    dropped = 0
    with open(path, "w") as o:
        for p in v:
            o.write("v %.9g %.9g %.9g\n" % tuple(p))
        for face in faces:
            face = [int(i) for i in face]
            # Quad arrays mark a triangle by repeating an index.
            face = [x for k, x in enumerate(face) if x != face[k - 1]] or face
            if len(set(face)) < max(3, len(face)):
                dropped += 1
                continue
            o.write("f " + " ".join(str(i + 1) for i in face) + "\n")
    return dropped


def competitor_child(tool, src, out, target):
    """Remeshes src to out with `tool`; prints {"time_ms": ...} as JSON."""
    import contextlib
    log = open(out + ".log", "w")
    dropped = 0
    with contextlib.redirect_stdout(log):
        if tool == "instant-meshes":
            import pyinstantmeshes
            t0 = time.perf_counter()
            # remesh_file writes IM's own polygon OBJ (quads, triangles,
            # pentagons); remesh() returns a re-triangulated reload of it.
            pyinstantmeshes.remesh_file(src, out, target_vertex_count=target, extrinsic=True,
                                        pure_quad=False, deterministic=True)
            ms = (time.perf_counter() - t0) * 1e3
            v, faces = read_obj_polygons(out)
            dropped = write_obj(out, v, faces)
        elif tool == "nano-instant-meshes":
            import numpy as np
            import pynanoinstantmeshes
            v, f = read_obj_triangles(src)
            t0 = time.perf_counter()
            nv, nf = pynanoinstantmeshes.remesh(v, f.astype(np.uint32), target)
            ms = (time.perf_counter() - t0) * 1e3
            dropped = write_obj(out, nv, nf)
        elif tool == "quadriflow":
            from pyQuadriFlow import pyQuadriFlow
            v, f = read_obj_triangles(src)
            v, f = v.tolist(), f.tolist()
            t0 = time.perf_counter()
            m = pyQuadriFlow.pyquadriflow(target, 0, v, f, False, False, False, False, False)
            ms = (time.perf_counter() - t0) * 1e3
            if not m or not m["faces"]:
                raise RuntimeError("QuadriFlow returned no faces")
            dropped = write_obj(out, m["vertices"], m["faces"])
        else:
            raise SystemExit(f"unknown tool {tool}")
    print(json.dumps({"time_ms": ms, "degenerate_faces_dropped": dropped}))


# ------------------------------------------------------------ measuring

def quadrille_json(args, cmd, timeout):
    rc, out, err, _, _ = run_measured([args.bin] + cmd, timeout=timeout)
    if rc != 0:
        return {"error": (err or "").strip()[-300:] or f"exit {rc}"}
    return json.loads(out) if out.strip() else {}


def measure_output(args, name, tool, src, out):
    """The same metrics and the same fitting for any tool's output."""
    m = quadrille_json(args, ["metrics", out, "--reference", src], args.timeout)
    control = out[:-4] + "-control.obj"
    fit_stats = out[:-4] + "-fit.json"
    rc, _, err, _, _ = run_measured([args.bin, "fit", "--reference", src, "--mesh", out, "-o", control,
                                     "--stats", fit_stats], timeout=args.timeout)
    fit = json.load(open(fit_stats))["fit"] if rc == 0 else {"error": (err or "").strip()[-300:]}
    return m, fit


def vertex_count(metrics):
    if "metrics" in metrics:
        return metrics["metrics"]["topology"]["vertices"]
    return metrics.get("vertices")


def run_competitor(args, tool, src, out, target):
    py = os.path.join(VENV, "bin", "python")
    cmd = [py, os.path.abspath(__file__), "--child", tool, src, out, str(target)]
    rc, so, se, wall, rss = run_measured(cmd, timeout=args.timeout)
    if rc != 0:
        reason = (se or "").strip().splitlines()[-1] if (se or "").strip() else f"exit status {rc}"
        if rc is not None and rc < 0:
            reason = f"crashed (signal {-rc})"
        return {"error": reason, "requested": target}
    child = json.loads(so.strip().splitlines()[-1])
    return {"time_ms": child["time_ms"], "degenerate_faces_dropped": child["degenerate_faces_dropped"], "process_ms": wall,
            "peak_rss_mib": rss / 1024 if rss else None, "requested": target}


def run_global(args, src, stem):
    """Quadrille's global mode at the default target: its own fit (no
    split: the pure-quad mesh is the control mesh)."""
    out, stats = stem + "-quadrille-global.obj", stem + "-quadrille-global.json"
    rc, _, err, wall, rss = run_measured([args.bin, "remesh", src, "-o", out, "--stats", stats, "--mode", "global"],
                                         timeout=args.timeout)
    if rc != 0:
        print(f"compare: quadrille global failed: {(err or '').strip()[-200:]}", file=sys.stderr)
        return {"error": (err or "").strip()[-300:] or f"exit {rc}"}
    s = json.load(open(stats))
    t = s["timings_ms"]
    remesh_ms = sum(v for k, v in t.items() if k not in ("metrics", "fit"))
    m = quadrille_json(args, ["metrics", out, "--reference", src], args.timeout)
    print(f"compare: quadrille global {remesh_ms:.0f} ms, {s['achieved_vertices']} V", file=sys.stderr)
    return {"time_ms": remesh_ms, "fit_ms": t.get("fit"), "process_ms": wall,
            "peak_rss_mib": rss / 1024 if rss else None, "requested": s["target_vertices"],
            "metrics": m, "fit": s.get("limit_surface"), "qex": s.get("qex")}


def compare_mesh(args, name, src, status):
    # The input itself, measured the same way: the boundary and non-manifold
    # counts every output is read against (holes introduced or closed).
    rows = {"input": {"metrics": quadrille_json(args, ["metrics", src, "--reference", src], args.timeout)}}
    stem = os.path.join(args.out, name)
    ours, stats = stem + "-quadrille.obj", stem + "-quadrille.json"
    rc, _, err, wall, rss = run_measured([args.bin, "remesh", src, "-o", ours, "--stats", stats],
                                         timeout=args.timeout)
    if rc != 0:
        rows["quadrille"] = {"error": (err or "").strip()[-300:]}
        return None, rows
    s = json.load(open(stats))
    target = s["target_vertices"]
    t = s["timings_ms"]
    remesh_ms = sum(v for k, v in t.items() if k not in ("metrics", "fit"))
    m = quadrille_json(args, ["metrics", ours, "--reference", src], args.timeout)
    rows["quadrille"] = {"time_ms": remesh_ms, "fit_ms": t.get("fit"), "process_ms": wall,
                         "peak_rss_mib": rss / 1024 if rss else None, "requested": target,
                         "metrics": m, "fit": s.get("limit_surface")}
    print(f"compare {name}: quadrille {remesh_ms:.0f} ms, {s['achieved_vertices']} V", file=sys.stderr)
    rows["quadrille global"] = run_global(args, src, stem)
    for tool in args.tools:
        if status.get(tool):
            rows[tool] = {"error": status[tool]}
            continue
        out = f"{stem}-{tool}.obj"
        r = run_competitor(args, tool, src, out, target)
        if "error" not in r:
            m = quadrille_json(args, ["metrics", out, "--reference", src], args.timeout)
            got = vertex_count(m)
            if got and abs(got - target) > 0.15 * target:
                retry = max(4, round(target * target / got))
                r2 = run_competitor(args, tool, src, out, retry)
                if "error" not in r2:
                    r2["first_try"] = {"requested": target, "vertices": got}
                    r = r2
        if "error" not in r:
            r["metrics"], r["fit"] = measure_output(args, name, tool, src, out)
            print(f"compare {name}: {tool} {r['time_ms']:.0f} ms, {vertex_count(r['metrics'])} V",
                  file=sys.stderr)
        else:
            print(f"compare {name}: {tool} failed: {r['error']}", file=sys.stderr)
        rows[tool] = r
    return target, rows


# ------------------------------------------------------------ table

def fmt(x, spec):
    return "–" if x is None or x != x else format(x, spec)


def table_rows(name, target, rows):
    lines = []
    for tool, r in rows.items():
        if r.get("degenerate_faces_dropped"):
            tool = f"{tool} ({r['degenerate_faces_dropped']} degenerate faces left out)"
        if "error" in r:
            lines.append(f"| {name} | {tool} | {fmt(target, 'd')} | – | – | not run: {r['error'][:120]} |" + " – |" * 11)
            continue
        m = r.get("metrics", {})
        time_ms = fmt(r.get("time_ms"), ".0f")
        fit = r.get("fit") or {}
        before = fit.get("before", {}) if "error" not in fit else {}
        after = fit.get("after", {}) if "error" not in fit else {}
        lim = (f"{fmt(before.get('stats', {}).get('mean'), '.2e')} → {fmt(after.get('stats', {}).get('mean'), '.2e')}"
               if after else f"fit failed: {fit.get('error', '')[:60]}" if "error" in fit else "–")
        limh = f"{fmt(after.get('hausdorff'), '.2e')}" if after else "–"
        control = fmt(fit.get("control_vertices"), "d") if "error" not in fit else "–"
        if "metrics" in m:
            M = m["metrics"]
            tp, q, d = M["topology"], M["quads"], M["distance"]
            if tool == "input":
                # Its own counts are the reference line; distances to itself are not a result.
                d = {k: None for k in d}
            lines.append(
                f"| {name} | {tool} | {target} | {time_ms} | {fmt(r.get('peak_rss_mib'), '.0f')} | {tp['vertices']} "
                f"| {tp['non_quad_percent']:.1f} | {tp['extraordinary_vertex_percent']:.1f} | {q['quad_quality']:.3f} "
                f"| {tp['boundary_edges']} ({tp['boundary_loops']}) | {tp['nonmanifold_edges']}/{tp['nonmanifold_vertices']} "
                f"| {fmt(d['hausdorff'], '.2e')} | {fmt(d['output_to_input_mean'], '.2e')} | {fmt(d['face_centroid_mean'], '.2e')} | {lim} | {limh} | {control} |")
        elif "topology" in m:
            tp = m["topology"]
            if tool == "input":
                m = dict(m, hausdorff=None)
            lines.append(
                f"| {name} | {tool} | {target} | {time_ms} | {fmt(r.get('peak_rss_mib'), '.0f')} | {m['vertices']} "
                f"| {m['non_quad_percent']:.1f} | – | – | {tp['boundary_edges']} | {tp['nonmanifold_edges']}/{tp['nonmanifold_vertices']} "
                f"| {fmt(m['hausdorff'], '.2e')} | – | – | {lim} | {limh} | {control} |")
        else:
            lines.append(f"| {name} | {tool} | {target} | {time_ms} | – | metrics failed: {m.get('error', '')[:80]} |" + " – |" * 11)
    return lines


HEADER = ("| mesh | tool | target V | time ms | peak MiB | V | non-quad % | EV % | quad quality (0 best) "
          "| boundary edges (loops) | non-manifold e/v | Hausdorff | mean dist | centroid dist | limit mean: before → after fit | limit Hausdorff after "
          "| control V |\n"
          "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")


def markdown(results):
    lines = [HEADER]
    for name, entry in results["meshes"].items():
        lines += table_rows(name, entry["target"], entry["rows"])
    return "\n".join(lines)


def main():
    if len(sys.argv) > 1 and sys.argv[1] == "--child":
        competitor_child(sys.argv[2], sys.argv[3], sys.argv[4], int(sys.argv[5]))
        return
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--bin", default=os.path.join(ROOT, "target", "release", "quadrille"))
    ap.add_argument("--meshes", default=os.environ.get("QUADRILLE_MESHES", os.path.join(ROOT, "..", "shared", "meshes")))
    ap.add_argument("--names", default=",".join(NAMES))
    ap.add_argument("--out", default=os.path.join(ROOT, "target", "bench", "compare"))
    ap.add_argument("--json", default=os.path.join(ROOT, "target", "bench", "compare.json"))
    ap.add_argument("--tools", default=",".join(TOOLS))
    ap.add_argument("--timeout", type=float, default=1200, help="seconds per child process")
    args = ap.parse_args()
    args.tools = [t for t in args.tools.split(",") if t]
    for t in args.tools:
        if t not in TOOLS:
            ap.error(f"unknown tool {t!r} (known: {', '.join(TOOLS)})")
    if not os.path.exists(args.bin):
        sys.exit(f"compare: {args.bin} does not exist: run `cargo build --release` first")
    os.makedirs(args.out, exist_ok=True)
    status = ensure_venv(args.tools)
    for t, why in status.items():
        if why:
            print(f"compare: {t} cannot run: {why}", file=sys.stderr)
    results = {"tools": {t: {"package": TOOLS[t], "unavailable": status.get(t)} for t in args.tools},
               "versions": versions(), "meshes": {}}
    for name in args.names.split(","):
        src = os.path.join(args.meshes, name + ".obj")
        if not os.path.exists(src):
            sys.exit(f"compare: {src} does not exist (set --meshes or QUADRILLE_MESHES)")
        target, rows = compare_mesh(args, name, os.path.abspath(src), status)
        results["meshes"][name] = {"input": src, "target": target, "rows": rows}
        with open(args.json, "w") as f:
            json.dump(results, f, indent=1)
    print(markdown(results))


if __name__ == "__main__":
    main()
