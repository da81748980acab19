// Benchmark (not a test): the dual-strip-weaving loop engine in wasm under
// Node — graph build time and memory, then the hover query (best loop
// through one vertex) at the same 200 random vertices as
// `cargo run --release --example bench_layout`, each timed three times and
// the fastest kept. Needs the web build in www/pkg (`make web`, or
// `cargo build --release --lib --target wasm32-unknown-unknown` and
// `.tools/bin/wasm-bindgen --target web --no-typescript --out-dir www/pkg …`).
//
//   node tests/e2e/bench_layout.mjs [mesh-file …]
//   (default: stanford-bunny and fandisk from ../shared/meshes/)
import { readFileSync } from 'node:fs';
import { basename, dirname, join, resolve } from 'node:path';
import { performance } from 'node:perf_hooks';
import { fileURLToPath, pathToFileURL } from 'node:url';

const here = dirname(fileURLToPath(import.meta.url));
const root = resolve(here, '../..');
const meshes = process.env.QUADRILLE_MESHES || resolve(root, '../shared/meshes');
const pkg = process.env.QUADRILLE_PKG || join(root, 'www/pkg');

const glue = await import(pathToFileURL(join(pkg, 'quadrille.js')).href);
await glue.default({ module_or_path: readFileSync(join(pkg, 'quadrille_bg.wasm')) });
const { LayoutEngine } = glue;

let files = process.argv.slice(2);
if (files.length === 0) {
  files = [join(meshes, 'stanford-bunny.obj'), join(meshes, 'fandisk.obj')];
}
const pct = (sorted, q) => sorted[Math.round((sorted.length - 1) * q)];
for (const file of files) {
  const bytes = readFileSync(file);
  const name = basename(file);
  const t0 = performance.now();
  const engine = new LayoutEngine(bytes, name);
  const build = (performance.now() - t0) / 1e3;
  console.log(
    `${name}: ${engine.vertexCount()} vertices, ${engine.faceCount()} faces; g′ ${engine.nodeCount()} nodes; ` +
      `import + build ${build.toFixed(2)} s; g+g′ ${(engine.graphBytes() / 1e6).toFixed(1)} MB, ` +
      `with query buffers ${(engine.engineBytes() / 1e6).toFixed(1)} MB`,
  );
  const times = [];
  const settled = [];
  const nontrivial = [];
  let closed = 0;
  let found = 0;
  for (const v of engine.benchVertices(200, 7n)) {
    let best = Infinity;
    let cost = NaN;
    let before = 0;
    for (let r = 0; r < 3; r++) {
      before = engine.settledNodes();
      const t = performance.now();
      cost = engine.bestLoopAtVertex(v);
      best = Math.min(best, performance.now() - t);
    }
    settled.push(engine.settledNodes() - before);
    times.push(best);
    if (!Number.isNaN(cost)) {
      found++;
      if (engine.lastWasClosed()) closed++;
      if (cost > 0) nontrivial.push(best);
    }
  }
  nontrivial.sort((a, b) => a - b);
  times.sort((a, b) => a - b);
  settled.sort((a, b) => a - b);
  console.log(
    `  wasm hover best loop, 200 anchors: median ${pct(times, 0.5).toFixed(2)} ms, ` +
      `p95 ${pct(times, 0.95).toFixed(2)} ms, max ${pct(times, 1).toFixed(2)} ms; ` +
      `${found} found (${closed} closed loops); settled g′ nodes per query: median ${pct(settled, 0.5)}, ` +
      `p95 ${pct(settled, 0.95)}, max ${pct(settled, 1)}`,
  );
  if (nontrivial.length > 0) {
    console.log(
      `  without the ${times.length - nontrivial.length} zero-cost dual curves (anchor within k rings of the ` +
        `boundary): median ${pct(nontrivial, 0.5).toFixed(2)} ms, p95 ${pct(nontrivial, 0.95).toFixed(2)} ms`,
    );
  }
  engine.free();
}
