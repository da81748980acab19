// Benchmark (not a test): the design mode (dual strip weaving) in headless
// Chromium, wasm in the workers, driven the way a user drives it — pointer
// moves, clicks, drags and key presses through playwright. Times, from the
// input event on the page to the frame that shows its effect:
//   hover   pointer move (its handler, before the pick of the surface point) → the best loop
//           through the point drawn (the exact draw). The hover is answered progressively
//           (www/layout-worker.js): its first draw, reported apart as "hover (first draw)", is the
//           exact loop when the worker's first slice of search finished it, else a provisional
//           loop (the cheapest found so far) that the exact one replaces — or confirms, when it is
//           the same loop, whose exact draw is then its first draw; each hover point waits for its
//           exact draw before the next.
//   click   a click on the surface → the anchor and its loop drawn (first
//           and second anchor apart)
//   drag    a drag from the surface: each update of the directional anchor
//   grab    a press on the loop dragged away: each update of the inserted anchor
//   Enter   commit of the hovered loop → the strip drawn
//   undo    Ctrl+Z of that commit
// median, 95th percentile and max per action, on the torus sample and the
// bunny (designed on its 30k-face proxy). The strip analysis runs in its own
// worker and is not part of these times.
//
//   make bench-design            (builds the web app first)
//   cd tests/e2e && node bench_design.mjs [sample …]   (default: torus stanford-bunny)
//   BENCH_TRIALS=n  edit trials per sample (default 6) · BENCH_HOVERS=n hover points (default 40)
//   BENCH_BACKEND=webgl2|webgpu (default webgl2)
//   BENCH_HOVER_FIRST=n|all  g′ nodes the worker searches before a hover's first answer (default: the
//   worker's; all: every hover answered exactly at once, as before the progressive hover)
//   BENCH_HOVER_HOLD=ms  an unfinished hover search goes on for up to ms before its provisional loop is
//   posted (the page's ?hoverHold=; default: the worker's HOVER_HOLD)
//   BENCH_HOVER_BRIDGE=0  no provisional loops bridged to recent ones (the page's ?hoverBridge=0)
//   BENCH_ACTION_TIMEOUT=s  an action still unanswered after s seconds (default 30) counts as a
//   timeout (∞ in the percentiles); the layout worker is then restarted and the next trial begins.
// Writes target/bench/design.json (with each hover's latency, worker time and pick time: hoverRaw).
import { mkdirSync, writeFileSync } from 'node:fs';
import { join } from 'node:path';
import {
  root, startServer, CONFIGS, launch, open, waitForRun, settle, surfaceGrid, enterDesign, DESIGN_WAIT,
} from './harness.mjs';

const samples = process.argv.slice(2).length ? process.argv.slice(2) : ['torus', 'stanford-bunny'];
const trials = Number(process.env.BENCH_TRIALS || 6);
const hovers = Number(process.env.BENCH_HOVERS || 40);
const backend = process.env.BENCH_BACKEND || 'webgl2';
const actionTimeout = 1000 * Number(process.env.BENCH_ACTION_TIMEOUT || 30);
const hoverFirst = process.env.BENCH_HOVER_FIRST;
const hoverHold = process.env.BENCH_HOVER_HOLD;
const hoverBridge = process.env.BENCH_HOVER_BRIDGE;

const sorted = (xs) => [...xs].sort((a, b) => a - b);
// Nearest-rank percentile.
const pct = (xs, q) => { const s = sorted(xs); return s.length ? s[Math.max(0, Math.ceil(q * s.length) - 1)] : NaN; };
const summary = (xs) => ({ n: xs.length, median: pct(xs, 0.5), p95: pct(xs, 0.95), max: pct(xs, 1) });

const stats = (page) => page.evaluate(() => {
  const d = window.quadrille.design;
  return { latencies: d.actionLatencies, workerMs: d.actionMs, anchors: d.state ? d.state.anchors.length / 3 : 0,
    loops: d.state ? d.state.loops.length : 0, proposal: d.proposal ? d.proposal.length : 0 };
});

// Waits until every action sent has been answered and drawn; false after
// `timeout` ms.
async function idle(page, timeout = DESIGN_WAIT.timeout) {
  try {
    await page.waitForFunction(() => window.quadrille.design.actionsSent === window.quadrille.design.actionsAnswered, null, { timeout });
  } catch (error) {
    if (error.name === 'TimeoutError') return false;
    throw error;
  }
  await settle(page);
  return true;
}

// An action did not answer in time: the busy layout worker is replaced by
// a fresh one (what the page's restart button does; it is hidden until a
// crash, so it is clicked programmatically).
async function restart(page) {
  await page.evaluate(() => document.getElementById('design-restart').click());
  await page.waitForFunction(() => window.quadrille.design.ready && !window.quadrille.design.crashed && window.quadrille.design.state, null, { timeout: 300000 });
  await idle(page);
}

// Runs `input` and returns the page-side latencies it added, per action
// (`timedOut` when the last did not answer within the action timeout).
async function measure(page, input) {
  await idle(page);
  const before = (await stats(page)).latencies;
  await input();
  const answered = await idle(page, actionTimeout);
  const after = (await stats(page)).latencies;
  const out = { timedOut: !answered };
  for (const [name, xs] of Object.entries(after)) {
    const added = xs.slice((before[name] || []).length);
    if (added.length) out[name] = added;
  }
  if (!answered) await restart(page);
  return out;
}

async function hoverAt(page, { x, y }) {
  const n = await page.evaluate(() => window.quadrille.design.hoverLatencies.length);
  await page.mouse.move(x, y);
  await page.waitForFunction((n) => window.quadrille.design.hoverLatencies.length > n, n, DESIGN_WAIT);
}

const d2 = (p, q) => (p[0] - q[0]) ** 2 + (p[1] - q[1]) ** 2 + (p[2] - q[2]) ** 2;

async function benchSample(env, sample) {
  const { page, errors } = await open(env, `sample=${sample}${hoverFirst ? `&hoverFirst=${hoverFirst}` : ''}${hoverHold ? `&hoverHold=${hoverHold}` : ''}${hoverBridge ? `&hoverBridge=${hoverBridge}` : ''}`);
  await waitForRun(page, `${sample}.obj`);
  await enterDesign(page, 300000);
  const info = await page.evaluate(() => ({ faces: window.quadrille.design.faces, inputFaces: window.quadrille.design.inputFaces,
    proxy: window.quadrille.design.proxy, readyAfterMs: window.quadrille.design.readyAfterMs }));
  const hits = await surfaceGrid(page, 16);
  if (hits.length < 2 * hovers) throw new Error(`${sample}: only ${hits.length} surface points on screen`);
  const at = (f) => hits[Math.floor(f * (hits.length - 1))];
  const runs = { hover: [], 'hover (first draw)': [], 'click (1st anchor)': [], 'click (2nd anchor)': [], drag: [], grab: [], Enter: [], undo: [] };
  const timeouts = Object.fromEntries(Object.keys(runs).map((k) => [k, 0]));
  let restarts = 0;
  // Adds a measurement's latencies to `name`; a timeout adds ∞.
  const record = (name, m, actions) => {
    for (const a of actions) runs[name].push(...(m[a] || []));
    if (m.timedOut) { runs[name].push(Infinity); timeouts[name]++; restarts++; }
    return !m.timedOut;
  };
  const worker = { hover: [], 'hover (first draw)': [] };
  // Hover: distinct points spread over the surface on screen.
  await idle(page);
  const h0 = await page.evaluate(() => window.quadrille.design.hoverLatencies.length);
  const w0 = await page.evaluate(() => window.quadrille.design.hoverWorkerMs.length);
  const p0 = await page.evaluate(() => window.quadrille.design.hoverPickMs.length);
  const f0 = await page.evaluate(() => ({ l: window.quadrille.design.hoverFirstLatencies.length,
    w: window.quadrille.design.hoverFirstWorkerMs.length, p: window.quadrille.design.hoverProvisional,
    u: window.quadrille.design.hoverUnchanged }));
  for (let i = 0; i < hovers; i++) await hoverAt(page, at((i * 0.618034) % 1));
  runs.hover = await page.evaluate((n) => window.quadrille.design.hoverLatencies.slice(n), h0);
  worker.hover = await page.evaluate((n) => window.quadrille.design.hoverWorkerMs.slice(n), w0);
  const pick = await page.evaluate((n) => window.quadrille.design.hoverPickMs.slice(n), p0);
  const first = await page.evaluate((f) => ({ latency: window.quadrille.design.hoverFirstLatencies.slice(f.l),
    worker: window.quadrille.design.hoverFirstWorkerMs.slice(f.w), provisional: window.quadrille.design.hoverProvisional - f.p,
    unchanged: window.quadrille.design.hoverUnchanged - f.u }), f0);
  runs['hover (first draw)'] = first.latency;
  worker['hover (first draw)'] = first.worker;
  for (let k = 0; k < trials; k++) {
    const u = (0.37 * k + 0.11) % 1;
    const [a, b, c] = [at(u), at((u + 0.5) % 1), at((u + 0.25) % 1)];
    // Two clicks: two positional anchors.
    await page.keyboard.press('Escape');
    await idle(page);
    await page.mouse.move(a.x, a.y);
    let m = await measure(page, () => page.mouse.click(a.x, a.y));
    if (!record('click (1st anchor)', m, ['addAnchor'])) continue;
    m = await measure(page, () => page.mouse.click(b.x, b.y));
    const second = record('click (2nd anchor)', m, ['addAnchor']);
    // Grab: press on the loop through both anchors (away from them) and drag.
    const s = await page.evaluate(() => ({ loop: [...window.quadrille.design.proposal], anchors: [...window.quadrille.design.state.anchors] }));
    const fine = await surfaceGrid(page, 8);
    const onLoop = fine.filter((h) => {
      let best = Infinity;
      for (let i = 0; i < s.loop.length; i += 3) best = Math.min(best, d2(h.p, s.loop.slice(i, i + 3)));
      const nearAnchor = [0, 3].some((i) => d2(h.p, s.anchors.slice(i, i + 3)) < 0.05 ** 2);
      return best < 0.006 ** 2 && !nearAnchor;
    });
    if (second && onLoop.length) {
      const g = onLoop[Math.floor(onLoop.length / 2)];
      m = await measure(page, async () => {
        await page.mouse.move(g.x, g.y);
        await page.mouse.down();
        for (let i = 1; i <= 5; i++) await page.mouse.move(g.x + 4 * i, g.y - 4 * i);
        await page.mouse.up();
      });
      record('grab', m, ['insertAnchorOnLoop', 'moveGrabbedAnchor']);
    }
    // Drag from the surface: a third, directional anchor.
    await page.keyboard.press('Escape');
    await idle(page);
    m = await measure(page, async () => {
      await page.mouse.move(c.x, c.y);
      await page.mouse.down();
      for (let i = 1; i <= 6; i++) await page.mouse.move(c.x + 6 * i, c.y + 3 * i);
      await page.mouse.up();
    });
    if (!record('drag', m, ['addAnchor', 'setLastAnchorDirection'])) continue;
    // Enter on the hovered loop, then undo it.
    await page.keyboard.press('Escape');
    await idle(page);
    await hoverAt(page, b);
    const before = (await stats(page)).loops;
    m = await measure(page, () => page.keyboard.press('Enter'));
    if (!record('Enter', m, ['commit'])) continue;
    if ((await stats(page)).loops !== before + 1) throw new Error(`${sample}: Enter committed nothing`);
    m = await measure(page, () => page.keyboard.press('Control+z'));
    record('undo', m, ['undo']);
  }
  const w = (await stats(page)).workerMs;
  worker['click (1st anchor)'] = worker['click (2nd anchor)'] = w.addAnchor || [];
  worker.drag = [...(w.setLastAnchorDirection || [])];
  worker.grab = [...(w.insertAnchorOnLoop || []), ...(w.moveGrabbedAnchor || [])];
  worker.Enter = w.commit || [];
  worker.undo = w.undo || [];
  if (errors.length) throw new Error(`${sample}: console errors: ${errors.join(' | ')}`);
  await page.close();
  const result = { sample, ...info, hoverFirst: hoverFirst || null, hoverHold: hoverHold || null, hoverBridge: hoverBridge || null, restarts, actions: {}, hoverProvisional: first.provisional, hoverUnchanged: first.unchanged,
    hoverRaw: { latency: runs.hover, worker: worker.hover, pick, firstLatency: first.latency, firstWorker: first.worker } };
  for (const [name, xs] of Object.entries(runs)) result.actions[name] = { ...summary(xs), timeouts: timeouts[name], workerMedian: pct(worker[name] || [], 0.5) };
  return result;
}

const { server, url } = await startServer();
const results = [];
try {
  const context = await launch(CONFIGS[backend].flags);
  try {
    for (const sample of samples) {
      const r = await benchSample({ context, url, backend, query: CONFIGS[backend].query }, sample);
      results.push(r);
      const f = (x) => (Number.isFinite(x) ? x.toFixed(1) : x === Infinity ? `> ${actionTimeout / 1e3} s` : '—');
      console.log(`${sample} (${r.inputFaces} faces${r.proxy ? `, designed on a ${r.faces}-face proxy` : ''}; mode ready ${(r.readyAfterMs / 1e3).toFixed(1)} s after T), ${backend}:`);
      console.log('| action | n (timeouts) | median ms | p95 ms | max ms | worker median ms |');
      console.log('|---|---|---|---|---|---|');
      for (const [name, a] of Object.entries(r.actions)) console.log(`| ${name} | ${a.n} (${a.timeouts}) | ${f(a.median)} | ${f(a.p95)} | ${f(a.max)} | ${f(a.workerMedian)} |`);
      const p = summary(r.hoverRaw.pick);
      console.log(`hover's pick on the page (part of its latency): n ${p.n}, median ${f(p.median)}, p95 ${f(p.p95)}, max ${f(p.max)} ms`);
      console.log(`hovers first drawn provisionally: ${r.hoverProvisional} of ${r.hoverRaw.latency.length}, of which ${r.hoverUnchanged} were the exact loop already (its exact draw is its first draw)`);
    }
  } finally {
    await context.close();
  }
} finally {
  server.kill();
}
mkdirSync(join(root, 'target/bench'), { recursive: true });
writeFileSync(join(root, 'target/bench/design.json'), JSON.stringify({ backend, trials, hovers, actionTimeoutMs: actionTimeout, results },
  (k, v) => (v === Infinity ? 'timeout' : v), 2));
