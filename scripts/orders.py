"""orders.py BIN TAG PARAMSJSON MESH... — Quadrille (defaults + a params
overlay, e.g. '{"remesh":{"mode":"global"}}') on each shared mesh and on
re-ordered copies of it (scripts/quality.py's orders), at the default
target (times TARGET_X, as scripts/quality.py's "global x4" row asks 4×
it); prints per-order metrics and their medians (the cells of
scripts/quality.py). Env: ORDERS (5), FIT (1; 0 skips the control-mesh
fit), OUT (run directory, /tmp/quadrille-orders), TARGET_X (1),
QUADRILLE_MESHES."""
import json, os, statistics, sys, types

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import compare, quality  # noqa: E402

BIN, TAG, P = sys.argv[1], sys.argv[2], json.loads(sys.argv[3])
ORD = int(os.environ.get("ORDERS", "5"))
FIT = os.environ.get("FIT", "1") == "1"
OUT = os.environ.get("OUT", "/tmp/quadrille-orders")
TARGET_X = float(os.environ.get("TARGET_X", "1"))
MESHES = os.environ.get("QUADRILLE_MESHES", os.path.join(HERE, "..", "..", "shared", "meshes"))
args = types.SimpleNamespace(bin=BIN, timeout=1200)
os.makedirs(OUT, exist_ok=True)
if not FIT:
    quality.measure = lambda a, src, out, fp=None: (
        compare.quadrille_json(a, ["metrics", out, "--reference", src], 1200),
        {},
    )
keys = ["V", "controlV", "nonquad", "ev", "corner", "maxcorner", "hausdorff", "out_in", "in_out", "limit", "limit2"]
for name in sys.argv[4:]:
    src = os.path.join(MESHES, f"{name}.obj")
    # The default target as quality.py asks it: the imported vertices / 16
    # (a messy file's duplicate vertices are merged on import).
    target, _ = quality.default_target(args, src)
    rows = []
    for o in range(ORD):
        s = src
        if o > 0:
            s = os.path.join(OUT, f"{name}-o{o}.obj")
            if not os.path.exists(s):
                quality.reordered_copy(src, s, o)
        stem = os.path.join(OUT, f"{name}-{TAG}-o{o}")
        # The target times TARGET_X, as quality.py's ("default", P, 4) rows.
        r = quality.run_quadrille(args, s, stem, ("default", P), round(target * TARGET_X))
        if "error" in r:
            print(name, o, "ERROR", r["error"], flush=True)
            continue
        c = quality.cells(r)
        rows.append(c)
        print(name, o, " ".join(f"{k}={c.get(k):.4g}" if isinstance(c.get(k), (int, float)) else f"{k}={c.get(k)}" for k in keys), flush=True)
    med = {
        k: statistics.median([r[k] for r in rows if isinstance(r.get(k), (int, float))])
        for k in keys
        if any(isinstance(r.get(k), (int, float)) for r in rows)
    }
    print("MED", TAG, name, " ".join(f"{k}={v:.4g}" for k, v in med.items()), flush=True)
