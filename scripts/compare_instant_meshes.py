#!/usr/bin/env python3
"""Quadrille vs Instant Meshes at the same vertex count on the shared meshes.

For each mesh: `quadrille remesh` at the default target (input/16), then
Instant Meshes (pyinstantmeshes; quad-dominant, extrinsic, deterministic)
with target_vertex_count = Quadrille's target; both measured by
`quadrille metrics` against the input. Prints a Markdown table.

Usage: scripts/compare_instant_meshes.py [QUADRILLE_BIN] [OUT_DIR]
"""
import json, os, subprocess, sys
import numpy as np
import pyinstantmeshes

BIN = sys.argv[1] if len(sys.argv) > 1 else "target/release/quadrille"
OUT = sys.argv[2] if len(sys.argv) > 2 else "/tmp/quadrille-compare"
MESHES = os.path.join(os.path.dirname(__file__), "..", "..", "shared", "meshes")
NAMES = ["fandisk", "rocker-arm", "spot", "cow", "stanford-bunny", "beetle", "teapot", "suzanne"]
os.makedirs(OUT, exist_ok=True)

def read_obj(path):
    v, f = [], []
    for line in open(path):
        p = line.split()
        if not p: continue
        if p[0] == "v": v.append([float(x) for x in p[1:4]])
        elif p[0] == "f":
            idx = [int(x.split("/")[0]) for x in p[1:]]
            idx = [i - 1 if i > 0 else len(v) + i for i in idx]
            for k in range(1, len(idx) - 1): f.append([idx[0], idx[k], idx[k + 1]])
    return np.array(v, np.float32), np.array(f, np.int32)

def write_obj(path, v, f):
    with open(path, "w") as o:
        for p in v: o.write("v %.9g %.9g %.9g\n" % tuple(p))
        for face in f:
            face = [int(i) for i in face]
            # IM marks triangles in quad output by repeating the last index.
            dedup = [x for k, x in enumerate(face) if x != face[k - 1]] if len(face) > 3 else face
            o.write("f " + " ".join(str(i + 1) for i in dedup) + "\n")

def metrics(mesh, ref):
    r = subprocess.run([BIN, "metrics", mesh, "--reference", ref], capture_output=True, text=True)
    return json.loads(r.stdout) if r.returncode == 0 else {"error": r.stderr}

def row(name, tool, m, target):
    if "metrics" in m:
        M = m["metrics"]; t = M["topology"]
        return f"| {name} | {tool} | {target} | {t['vertices']} | {t['non_quad_percent']:.1f} | {t['extraordinary_vertex_percent']:.1f} | {t['boundary_edges']} | {t['nonmanifold_edges']}/{t['nonmanifold_vertices']} | {t['genus']} | {M['distance']['hausdorff']:.4f} | {M['distance']['face_centroid_mean']:.4f} | {M['quads']['quad_quality']:.2f} | {M['quads']['corner_angle_deviation_degrees']:.1f} | {M['edges']['mean']:.4f}±{M['edges']['std_dev']:.4f} |"
    if "topology" in m:
        t = m["topology"]
        return f"| {name} | {tool} | {target} | {m['vertices']} | {m['non_quad_percent']:.1f} | – | {t['boundary_edges']} | {t['nonmanifold_edges']}/{t['nonmanifold_vertices']} | non-manifold | {m['hausdorff']:.4f} | – | – | – | – |"
    return f"| {name} | {tool} | {target} | error: {m.get('error','')[:60]} |"

print("| mesh | tool | target V | V | non-quad % | EV % | boundary edges | non-manifold e/v | genus | Hausdorff | centroid mean | quad quality | corner dev ° | edge length |")
print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
for name in NAMES:
    src = os.path.join(MESHES, name + ".obj")
    ours, stats = os.path.join(OUT, name + "-quadrille.obj"), os.path.join(OUT, name + "-quadrille.json")
    subprocess.run([BIN, "remesh", src, "-o", ours, "--stats", stats], check=True)
    target = json.load(open(stats))["target_vertices"]
    print(row(name, "Quadrille", metrics(ours, src), target))
    v, f = read_obj(src)
    iv, jf = pyinstantmeshes.remesh(v, f, target_vertex_count=target, extrinsic=True, pure_quad=False, deterministic=True)
    im = os.path.join(OUT, name + "-instant-meshes.obj")
    write_obj(im, iv, jf)
    print(row(name, "Instant Meshes", metrics(im, src), target))
    sys.stdout.flush()
