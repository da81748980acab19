#!/usr/bin/env python3
"""Times Instant Meshes (pyinstantmeshes) on a mesh at the default target
(input vertices / 16), quad-dominant, extrinsic: median of N runs.
Usage: scripts/bench_instant_meshes.py [MESH] [RUNS]"""
import statistics, sys, time
import numpy as np
import pyinstantmeshes

path = sys.argv[1] if len(sys.argv) > 1 else "../shared/meshes/stanford-bunny.obj"
runs = int(sys.argv[2]) if len(sys.argv) > 2 else 5
v, f = [], []
for line in open(path):
    t = line.split()
    if t and t[0] == "v":
        v.append([float(x) for x in t[1:4]])
    elif t and t[0] == "f":
        f.append([int(x.split("/")[0]) - 1 for x in t[1:4]])
v = np.array(v, dtype=np.float32)
f = np.array(f, dtype=np.int32)
used = np.unique(f)
target = len(used) // 16
times = []
for _ in range(runs):
    t0 = time.perf_counter()
    nv, nf = pyinstantmeshes.remesh(v, f, target_vertex_count=target, extrinsic=True, deterministic=True)
    times.append((time.perf_counter() - t0) * 1e3)
print(f"{path}: Instant Meshes, target {target}, got {len(nv)} vertices / {len(nf)} faces; "
      f"median {statistics.median(times):.1f} ms over {runs} runs (whole pipeline incl. extraction)")
