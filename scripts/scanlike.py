#!/usr/bin/env python3
"""Scan-like probes: the shared meshes made to look like raw scans, remeshed
at their default targets and checked against the quality issue's bars.

The acceptance of the remeshing issues is also checked on held-out scans
that are not in this repository; these probes stand in for them (not part
of `make test`). Each shared mesh named gets, deterministically (seeded):
  noise   every vertex moved along its normal by a Gaussian of 0.3 mean
          input edges (scanner noise);
  holes   the faces with a corner within 6 mean input edges (about 1.5
          target edges) of 6 random vertices at least 18 edges apart
          removed (occlusion holes with ragged rims);
  scale   ×1000 and moved far from the origin (units and placement).
Each copy goes through `quadrille remesh --stats` at its default target
(imported vertices / 16) and the output's own metrics (the same code as
scripts/quality.py's) are checked:
  manifold    no non-manifold or inconsistently oriented edge;
  count       the vertex count within 10 % of the target;
  odd         non-quad faces at most 5 %;
  corner      no quad corner above 170°;
  kept        no input boundary loop closed over, no part of two output
              faces' worth of input triangles or more lost.
Loops too small for the target (shorter than two output edges) are
reported, not counted as failures.

Instant Meshes and QuadriFlow run on the same probes at the same target
(scripts/compare.py installs and drives them) and are checked the same way.

Usage: scripts/scanlike.py [--bin target/release/quadrille]
         [--meshes DIR] [--names spot,cow,...] [--kinds noise,holes,scale]
         [--out target/scanlike] [--mode local|global] [--timeout S]
         [--tools instant-meshes,quadriflow]
Prints a Markdown table; the exit status is 0 whatever the bars say.
Standard library only (the competitors run in scripts/compare.py's venv).
"""
import argparse
import json
import math
import os
import random
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import compare  # noqa: E402
DEFAULT_MESHES = os.path.join(HERE, "..", "..", "shared", "meshes")
KINDS = ("noise", "holes", "scale")


def save(path, verts, tris):
    used = sorted({i for t in tris for i in t})
    new = {v: k for k, v in enumerate(used)}
    with open(path, "w") as out:
        for v in used:
            out.write("v %.9g %.9g %.9g\n" % tuple(verts[v]))
        for t in tris:
            out.write("f %d %d %d\n" % tuple(new[i] + 1 for i in t))


def sub(a, b):
    return [a[0] - b[0], a[1] - b[1], a[2] - b[2]]


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def norm(a):
    return math.sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2])


def mean_edge(verts, tris):
    total = sum(norm(sub(verts[t[k]], verts[t[(k + 1) % 3]])) for t in tris for k in range(3))
    return total / max(1, 3 * len(tris))


def make(src, dst, kind, seed):
    """Writes the `kind` probe of `src` to `dst` (seeded)."""
    rng = random.Random(seed)
    verts, tris = compare.obj_triangles(src)
    edge = mean_edge(verts, tris)
    if kind == "noise":
        normals = [[0.0, 0.0, 0.0] for _ in verts]
        for t in tris:
            n = cross(sub(verts[t[1]], verts[t[0]]), sub(verts[t[2]], verts[t[0]]))
            for i in t:
                for k in range(3):
                    normals[i][k] += n[k]
        for v, n in zip(verts, normals):
            length = norm(n) or 1.0
            d = rng.gauss(0.0, 0.3 * edge)
            for k in range(3):
                v[k] += d * n[k] / length
    elif kind == "holes":
        # 1.5 target edges (the target is a sixteenth of the vertices, so
        # its edges are about 4 input edges), the centres 3 radii apart.
        radius = 6.0 * edge
        centres = []
        for _ in range(1000):
            c = verts[rng.randrange(len(verts))]
            if all(norm(sub(c, d)) > 3.0 * radius for d in centres):
                centres.append(c)
                if len(centres) == 6:
                    break
        tris = [t for t in tris if all(norm(sub(verts[i], c)) > radius for i in t for c in centres)]
    elif kind == "scale":
        offset = (12345.0, -678.0, 90.0)
        verts = [[v[k] * 1000.0 + offset[k] for k in range(3)] for v in verts]
    else:
        raise ValueError(kind)
    save(dst, verts, tris)


def remesh(args, src, stem):
    cmd = [args.bin, "remesh", src, "-o", stem + ".obj", "--stats", stem + ".json"]
    if args.mode:
        cmd += ["--mode", args.mode]
    try:
        r = subprocess.run(cmd, capture_output=True, text=True, timeout=args.timeout)
    except subprocess.TimeoutExpired:
        return None, f"timed out after {args.timeout} s"
    if r.returncode != 0:
        lines = (r.stderr or r.stdout).strip().splitlines()
        return None, lines[-1] if lines else f"exit {r.returncode}"
    with open(stem + ".json") as f:
        return json.load(f), None


def cells(metrics):
    """The figures of an output's `quadrille metrics`, manifold or not (a
    non-manifold output's report has its face soup's counts and shape, not
    its boundaries: `preservation` is None)."""
    if "metrics" in metrics:
        m = metrics["metrics"]
        topo = m["topology"]
        return {
            "manifold": not (topo["nonmanifold_edges"] or topo["nonmanifold_vertices"]
                             or topo["inconsistent_edges"]),
            "vertices": topo["vertices"], "input_vertices": topo["input_vertices"],
            "ev": topo["extraordinary_vertex_percent"], "odd": topo["non_quad_percent"],
            "quads": m["quads"], "hausdorff": m["distance"]["hausdorff"], "preservation": m["preservation"],
        }
    return {
        "manifold": False, "why": metrics.get("why", ""), "vertices": metrics["vertices"],
        "ev": metrics["extraordinary_vertex_percent"], "odd": metrics["non_quad_percent"],
        "quads": metrics["quads"], "hausdorff": metrics["hausdorff"], "preservation": None,
    }


def check(c, target):
    """The bars an output's `cells` miss at `target` vertices."""
    missed = []
    if not c["manifold"]:
        missed.append("manifold (%s)" % c["why"] if c.get("why") else "manifold")
    error = 100.0 * (c["vertices"] - target) / max(1, target)
    if abs(error) > 10:
        missed.append("count %+.1f %%" % error)
    if c["odd"] > 5:
        missed.append("odd %.1f %%" % c["odd"])
    if c["quads"]["max_corner_angle_degrees"] > 170:
        missed.append("corner %.0f°" % c["quads"]["max_corner_angle_degrees"])
    pres = c["preservation"]
    if pres is not None:
        if pres["loops_closed"]:
            missed.append("%d loops closed" % len(pres["loops_closed"]))
        # Parts lost are listed by their input triangles; a part of fewer
        # than two output faces' worth (a closed mesh has about 2 triangles
        # per vertex) is below the target scale.
        per_face = 2.0 * c["input_vertices"] / max(1, target)
        big = [n for n in pres["components_lost"] if n >= 2.0 * per_face]
        if big:
            missed.append("parts lost %s" % big)
    return missed


def row(label, metrics, target):
    c = cells(metrics)
    q, pres = c["quads"], c["preservation"]
    loops = "–" if pres is None else f"{pres['loops_kept']} of {pres['input_loops']} / {pres['loops_too_small']}"
    missed = check(c, target)
    return (
        f"| {label} | {c['vertices']} / {target} | {c['ev']:.1f} | {q['corner_angle_deviation_degrees']:.1f} "
        f"| {c['odd']:.1f} | {q['max_corner_angle_degrees']:.0f} | {c['hausdorff']:.4f} | {loops} "
        f"| {', '.join(missed) if missed else 'none'} |"
    )


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--bin", default=os.path.join(HERE, "..", "target", "release", "quadrille"))
    ap.add_argument("--meshes", default=os.environ.get("QUADRILLE_MESHES", DEFAULT_MESHES))
    ap.add_argument("--names", default="spot,cow,stanford-bunny,rocker-arm")
    ap.add_argument("--kinds", default=",".join(KINDS))
    ap.add_argument("--out", default=os.path.join(HERE, "..", "target", "scanlike"))
    ap.add_argument("--mode", default=None, choices=["local", "global"])
    ap.add_argument("--timeout", type=float, default=900)
    ap.add_argument("--tools", default="instant-meshes,quadriflow",
                    help="competitors run on the same probes at the same target ('' for none)")
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)
    tools = [t for t in args.tools.split(",") if t]
    status = compare.ensure_venv(tools) if tools else {}
    for t, reason in status.items():
        if reason:
            print(f"scanlike: {t} left out: {reason}", file=sys.stderr)
    tools = [t for t in tools if not status.get(t)]
    print("| probe | V / target | EV % | corner dev ° | non-quad % | widest corner ° | Hausdorff | input loops kept / too small | bars missed |")
    print("|---|---|---|---|---|---|---|---|---|")
    for name in args.names.split(","):
        src = os.path.join(args.meshes, name + ".obj")
        for kind in args.kinds.split(","):
            seed = KINDS.index(kind) + 1
            probe = os.path.join(args.out, f"{name}-{kind}.obj")
            make(src, probe, kind, seed)
            label = f"{name} {kind}"
            stem = os.path.join(args.out, f"{name}-{kind}-out")
            stats, error = remesh(args, probe, stem)
            if error:
                print(f"| {label}, Quadrille | – | – | – | – | – | – | – | **failed: {error}** |", flush=True)
                continue
            target = stats["target_vertices"]
            print(row(f"{label}, Quadrille", stats, target), flush=True)
            for tool in tools:
                out = os.path.join(args.out, f"{name}-{kind}-{tool}.obj")
                r = compare.run_competitor(args, tool, probe, out, target)
                measure = ["metrics", out, "--reference", probe]
                metrics = None if "error" in r else compare.quadrille_json(args, measure, args.timeout)
                # One corrective run when the count is more than 15 % off,
                # as scripts/quality.py does (their targets are not vertex
                # counts in the same sense).
                got = compare.vertex_count(metrics) if metrics else None
                if got and abs(got - target) > 0.15 * target:
                    r2 = compare.run_competitor(args, tool, probe, out, max(4, round(target * target / got)))
                    if "error" not in r2:
                        r, metrics = r2, compare.quadrille_json(args, measure, args.timeout)
                if metrics is None or "error" in metrics:
                    reason = r.get("error") or metrics.get("error")
                    print(f"| {label}, {tool} | – | – | – | – | – | – | – | **failed: {reason}** |", flush=True)
                    continue
                print(row(f"{label}, {tool}", metrics, target), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
