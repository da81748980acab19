// Shared by the browser tests (run.mjs) and the design-mode benchmark
// (bench_design.mjs): the static server, headless Chromium, opening the app
// and the design-mode helpers.
import { spawn } from 'node:child_process';
import { mkdtempSync } from 'node:fs';
import { createServer } from 'node:net';
import { tmpdir } from 'node:os';
import { dirname, join, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';
import { chromium } from 'playwright-core';

const here = dirname(fileURLToPath(import.meta.url));
export const root = resolve(here, '../..');
const targetDir = process.env.CARGO_TARGET_DIR ? resolve(root, process.env.CARGO_TARGET_DIR) : join(root, 'target');

function freePort() {
  return new Promise((ok, fail) => {
    const s = createServer();
    s.listen(0, '127.0.0.1', () => { const { port } = s.address(); s.close(() => ok(port)); });
    s.on('error', fail);
  });
}

export async function startServer() {
  const port = await freePort();
  const server = spawn(join(targetDir, 'release/examples/serve'), [join(root, 'www'), String(port)], { stdio: ['ignore', 'pipe', 'inherit'] });
  await new Promise((ok, fail) => {
    server.stdout.once('data', ok);
    server.once('exit', (code) => fail(new Error(`server exited with ${code}`)));
  });
  return { server, url: `http://127.0.0.1:${port}/` };
}

const BASE_FLAGS = ['--no-sandbox', '--disable-quic', '--no-first-run', '--disable-background-networking',
  '--disable-component-update', '--disable-sync'];
// Without SwiftShader Vulkan the WebGPU adapter works but the canvas stays blank in screenshots.
const WEBGPU_FLAGS = ['--enable-unsafe-webgpu', '--enable-features=Vulkan', '--use-vulkan=swiftshader', '--use-angle=swiftshader'];

export const CONFIGS = {
  webgl2: { flags: [], query: 'backend=webgl2' },
  webgpu: { flags: WEBGPU_FLAGS, query: '' },
};

export async function launch(extraFlags = []) {
  return chromium.launchPersistentContext(mkdtempSync(join(tmpdir(), 'quadrille-chromium-')), {
    executablePath: process.env.CHROMIUM || '/usr/bin/chromium',
    headless: true,
    args: ['--headless=new', ...BASE_FLAGS, ...extraFlags],
    viewport: { width: 1280, height: 800 },
  });
}

// Opens the app and collects console errors and page errors (the worker's too).
export async function open(env, query = '') {
  const page = await env.context.newPage();
  const errors = [];
  page.on('console', (m) => { if (m.type() === 'error') errors.push(m.text()); });
  page.on('pageerror', (e) => errors.push(String(e)));
  page.on('worker', (w) => w.on('console', (m) => { if (m.type() === 'error') errors.push(`worker: ${m.text()}`); }));
  const q = [env.query, query].filter(Boolean).join('&');
  await page.goto(env.url + (q ? `?${q}` : ''));
  return { page, errors };
}

export const waitForImport = (page, name) => page.waitForFunction(
  (n) => window.quadrille && window.quadrille.lastImport && window.quadrille.lastImport.file === n, name, { timeout: 60000 });

// Waits until a run of `name` is complete and two more animation frames have passed.
export async function waitForRun(page, name) {
  await page.waitForFunction(
    (n) => window.quadrille && window.quadrille.lastRun && window.quadrille.lastRun.input === n, name, { timeout: 60000 });
  await settle(page);
}
export const settle = (page) => page.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r))));

// ---------------------------------------------------------------- design mode (dual strip weaving)

// Client positions over the canvas where the surface is hit, on a grid.
export async function surfaceGrid(page, step = 24) {
  const box = await page.locator('#canvas').boundingBox();
  return page.evaluate(({ box, step }) => {
    const hits = [];
    for (let y = box.y + step / 2; y < box.y + box.height; y += step) {
      for (let x = box.x + step / 2; x < box.x + box.width; x += step) {
        const p = window.quadrille.surfacePoint(x, y);
        if (p) hits.push({ x, y, p });
      }
    }
    return hits;
  }, { box, step });
}

// Enters the design mode (T) on the sample on screen and waits for the loop engine.
export async function enterDesign(page, timeout = 120000) {
  await page.keyboard.press('t');
  await page.waitForFunction(() => window.quadrille.design.ready && window.quadrille.design.state, null, { timeout });
}

// How long a design-mode step may take to answer. These waits bound a
// hang, they do not test speed (the latencies are logged here and measured
// by the layout benchmark, `examples/bench_anchors.rs`: the first click on
// the torus now takes about half a millisecond natively); the generous
// bound covers the strip analysis and the fit on a loaded machine (a 20 s
// bound failed there once).
export const DESIGN_WAIT = { timeout: 120000 };

export const designState = (page) => page.evaluate(() => {
  const s = window.quadrille.design.state;
  return { revision: s.revision, anchors: s.anchors.length / 3, browse: s.browse, canUndo: s.canUndo, canRedo: s.canRedo,
    loops: s.loops.map((l) => [...l.points]), proposal: [...window.quadrille.design.proposal] };
});

// Moves the pointer over `points` one by one, waiting for each hover's loop
// to be drawn; returns the median pointer-move → drawn latency (ms).
export async function hoverLatency(page, points) {
  for (const { x, y } of points) {
    const before = await page.evaluate(() => window.quadrille.design.hoverLatencies.length);
    await page.mouse.move(x, y);
    await page.waitForFunction((n) => window.quadrille.design.hoverLatencies.length > n, before, DESIGN_WAIT);
  }
  return page.evaluate((n) => {
    const xs = window.quadrille.design.hoverLatencies.slice(-n).sort((a, b) => a - b);
    return { median: xs[Math.floor(xs.length / 2)], max: xs[xs.length - 1],
      workerMedian: [...window.quadrille.design.hoverWorkerMs].sort((a, b) => a - b)[Math.floor(window.quadrille.design.hoverWorkerMs.length / 2)] };
  }, points.length);
}

