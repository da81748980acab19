// Browser benchmark (not a test; `make bench` runs it through scripts/bench.py):
// the web app's pipeline (wasm in the Web Worker) in Debian's headless
// Chromium, per stage, on each mesh, REPEATS times with a fresh page each.
// The page's own numbers are read from `window.quadrille.lastRun` (the
// worker's per-stage milliseconds), so nothing on the page changes for this.
//
// Chromium runs with --disable-gpu --disable-software-rasterizer: the viewer
// then cannot start (the page says so and keeps working), so SwiftShader's
// CPU rendering does not compete with the worker for the machine's cores.
// The worker and the wasm module are exactly those the user gets.
//
//   node bench.mjs OUT.json REPEATS MESH...
import { spawn } from 'node:child_process';
import { mkdtempSync, writeFileSync } from 'node:fs';
import { createServer } from 'node:net';
import { tmpdir } from 'node:os';
import { basename, dirname, join, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';
import { chromium } from 'playwright-core';

const here = dirname(fileURLToPath(import.meta.url));
const root = resolve(here, '../..');
const targetDir = process.env.CARGO_TARGET_DIR ? resolve(root, process.env.CARGO_TARGET_DIR) : join(root, 'target');
const DEFAULT_SAMPLE = 'stanford-bunny';
// A run longer than this is reported as failed (the 1M-triangle mesh takes minutes).
const RUN_TIMEOUT_MS = 20 * 60 * 1000;

const [out, repeatsArg, ...meshes] = process.argv.slice(2);
const repeats = Number(repeatsArg);
if (!out || !(repeats >= 1) || !meshes.length) {
  console.error('usage: node bench.mjs OUT.json REPEATS MESH...');
  process.exit(2);
}

function freePort() {
  return new Promise((ok, fail) => {
    const s = createServer();
    s.listen(0, '127.0.0.1', () => { const { port } = s.address(); s.close(() => ok(port)); });
    s.on('error', fail);
  });
}

const port = await freePort();
const server = spawn(join(targetDir, 'release/examples/serve'), [join(root, 'www'), String(port)], { stdio: ['ignore', 'pipe', 'inherit'] });
await new Promise((ok, fail) => {
  server.stdout.once('data', ok);
  server.once('exit', (code) => fail(new Error(`server exited with ${code}`)));
});
const url = `http://127.0.0.1:${port}/`;

const context = await chromium.launchPersistentContext(mkdtempSync(join(tmpdir(), 'quadrille-bench-')), {
  executablePath: process.env.CHROMIUM || '/usr/bin/chromium',
  headless: true,
  args: ['--headless=new', '--no-sandbox', '--disable-quic', '--no-first-run', '--disable-background-networking',
    '--disable-component-update', '--disable-sync', '--disable-gpu', '--disable-software-rasterizer'],
  viewport: { width: 1280, height: 800 },
});
const browserVersion = context.browser()?.version() ?? null;

const waitForRun = (page, name) => page.waitForFunction(
  (n) => {
    const q = window.quadrille;
    // Without a GPU the page reports that the 3D view is off; any other error ends the wait.
    if (q && q.lastError && !/3D view/.test(q.lastError)) throw new Error(q.lastError);
    return q && q.lastRun && q.lastRun.input === n && q.lastRun.complete;
  },
  name, { timeout: RUN_TIMEOUT_MS, polling: 250 });

async function once(mesh) {
  const file = basename(mesh);
  const page = await context.newPage();
  const errors = [];
  page.on('pageerror', (e) => errors.push(String(e)));
  try {
    // The page opens its default sample first: that run is the warm-up (V8
    // compiles wasm with a baseline tier first and optimises hot functions
    // as they run), so every measured run is a second run in a warm page,
    // given to the page's file input like a user's file.
    await page.goto(url);
    await waitForRun(page, `${DEFAULT_SAMPLE}.obj`);
    await page.evaluate(() => { window.quadrille.lastError = null; window.quadrille.lastRun = null; });
    await page.setInputFiles('#file', resolve(mesh));
    await waitForRun(page, file);
    const run = await page.evaluate(() => ({ lastRun: window.quadrille.lastRun, backend: window.quadrille.backend }));
    return { stages: run.lastRun.stages, total_ms: run.lastRun.total_ms, counts: run.lastRun.counts, viewer: run.backend };
  } catch (error) {
    return { error: `${String(error.message || error).split('\n')[0]}${errors.length ? ` (${errors[0]})` : ''}` };
  } finally {
    await page.close();
  }
}

const results = { browser: `Chromium ${browserVersion}`, flags: '--headless=new --disable-gpu --disable-software-rasterizer', repeats, meshes: {} };
for (const mesh of meshes) {
  const runs = [];
  for (let i = 0; i < repeats; i++) {
    const r = await once(mesh);
    runs.push(r);
    console.error(`browser ${basename(mesh)} run ${i + 1}/${repeats}: ${r.error ? `error: ${r.error}` : `${r.total_ms} ms`}`);
    if (r.error) break;
  }
  results.meshes[mesh] = runs;
  writeFileSync(out, JSON.stringify(results, null, 1));
}
await context.close();
server.kill();
