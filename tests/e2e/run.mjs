// Browser tests: the web app in Debian's headless Chromium, driven by
// playwright-core. Serves www/ with the project's own static server, runs
// each test in a fresh page, and exits non-zero if any test fails.
import { spawn } from 'node:child_process';
import { mkdtempSync, readFileSync, mkdirSync } from 'node:fs';
import { createServer } from 'node:net';
import { tmpdir } from 'node:os';
import { dirname, join, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';
import { chromium } from 'playwright-core';

const here = dirname(fileURLToPath(import.meta.url));
const root = resolve(here, '../..');
const meshes = process.env.QUADRILLE_MESHES || resolve(root, '../shared/meshes');
export const artifacts = resolve(root, 'target/e2e');
mkdirSync(artifacts, { recursive: true });

function freePort() {
  return new Promise((ok, fail) => {
    const s = createServer();
    s.listen(0, '127.0.0.1', () => { const { port } = s.address(); s.close(() => ok(port)); });
    s.on('error', fail);
  });
}

async function startServer() {
  const port = await freePort();
  const server = spawn(join(root, 'target/release/examples/serve'), [join(root, 'www'), String(port)], { stdio: ['ignore', 'pipe', 'inherit'] });
  await new Promise((ok, fail) => {
    server.stdout.once('data', ok);
    server.once('exit', (code) => fail(new Error(`server exited with ${code}`)));
  });
  return { server, url: `http://127.0.0.1:${port}/` };
}

const BASE_FLAGS = ['--no-sandbox', '--disable-quic', '--no-first-run', '--disable-background-networking',
  '--disable-component-update', '--disable-sync'];
const WEBGPU_FLAGS = ['--enable-unsafe-webgpu', '--enable-features=Vulkan', '--use-vulkan=swiftshader', '--use-angle=swiftshader'];

async function launch(extraFlags = []) {
  return chromium.launchPersistentContext(mkdtempSync(join(tmpdir(), 'quadrille-chromium-')), {
    executablePath: process.env.CHROMIUM || '/usr/bin/chromium',
    headless: true,
    args: ['--headless=new', ...BASE_FLAGS, ...extraFlags],
    viewport: { width: 1280, height: 800 },
  });
}

// Opens the app and collects console errors and page errors.
async function open(context, url) {
  const page = await context.newPage();
  const errors = [];
  page.on('console', (m) => { if (m.type() === 'error') errors.push(m.text()); });
  page.on('pageerror', (e) => errors.push(String(e)));
  await page.goto(url);
  return { page, errors };
}

// Drops `bytes` named `name` on `selector` through a synthetic DataTransfer.
async function dropFile(page, selector, name, bytes) {
  await page.evaluate(({ selector, name, data }) => {
    const dt = new DataTransfer();
    dt.items.add(new File([new Uint8Array(data)], name));
    const target = document.querySelector(selector);
    target.dispatchEvent(new DragEvent('dragover', { dataTransfer: dt, bubbles: true, cancelable: true }));
    target.dispatchEvent(new DragEvent('drop', { dataTransfer: dt, bubbles: true, cancelable: true }));
  }, { selector, name, data: [...bytes] });
}

const waitForImport = (page, name) => page.waitForFunction(
  (n) => window.quadrille && window.quadrille.lastImport && window.quadrille.lastImport.file === n, name, { timeout: 60000 });

const tests = [];
const test = (name, fn) => tests.push({ name, fn });
const assert = (cond, message) => { if (!cond) throw new Error(message); };

test('page loads without console errors and imports the default sample in the worker', async ({ context, url }) => {
  const { page, errors } = await open(context, url);
  await waitForImport(page, 'stanford-bunny.obj');
  const r = await page.evaluate(() => window.quadrille.lastImport);
  assert(r.vertices === 34834, `bunny vertices ${r.vertices}`);
  assert(r.boundary_edges === 223, `bunny boundary edges ${r.boundary_edges}`);
  assert((await page.textContent('#report')).includes('34834'), 'report table shows the vertex count');
  await page.screenshot({ path: join(artifacts, 'import-bunny.png'), fullPage: true });
  assert(errors.length === 0, `console errors: ${errors.join(' | ')}`);
});

test('a dropped mesh runs through; a malformed file shows an error and the app still works', async ({ context, url }) => {
  const { page } = await open(context, url);
  await waitForImport(page, 'stanford-bunny.obj');
  await dropFile(page, '#drop', 'fandisk.obj', readFileSync(join(meshes, 'fandisk.obj')));
  await waitForImport(page, 'fandisk.obj');
  assert(await page.evaluate(() => window.quadrille.lastImport.vertices) === 6475, 'fandisk vertex count');

  await dropFile(page, '#drop', 'broken.obj', Buffer.from('v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n'));
  await page.waitForFunction(() => window.quadrille.lastError, null, { timeout: 30000 });
  const message = await page.evaluate(() => window.quadrille.lastError);
  assert(message.includes('broken.obj:4'), `error names file and line: ${message}`);
  assert((await page.textContent('#status')).includes('broken.obj:4'), 'error is shown on the page');
  await page.screenshot({ path: join(artifacts, 'import-error.png'), fullPage: true });

  await page.click('text=spot');
  await waitForImport(page, 'spot.obj');
  assert(await page.evaluate(() => window.quadrille.lastImport.genus) === 0, 'spot imports after the error');
});

test('the page works at phone size', async ({ context, url }) => {
  const page = await context.newPage();
  await page.setViewportSize({ width: 390, height: 844 });
  await page.goto(url + '?sample=cow');
  await waitForImport(page, 'cow.obj');
  const overflow = await page.evaluate(() => document.documentElement.scrollWidth > window.innerWidth + 1);
  assert(!overflow, 'no horizontal scrolling at 390 px');
  await page.screenshot({ path: join(artifacts, 'phone.png'), fullPage: true });
});

const { server, url } = await startServer();
let failed = 0;
const context = await launch();
try {
  for (const { name, fn } of tests) {
    const started = Date.now();
    try {
      await fn({ context, url });
      console.log(`ok    ${name} (${Date.now() - started} ms)`);
    } catch (error) {
      failed++;
      console.log(`FAIL  ${name}\n      ${String(error.stack || error).split('\n').join('\n      ')}`);
    }
  }
} finally {
  await context.close();
  server.kill();
}
console.log(`${tests.length - failed} passed, ${failed} failed`);
process.exit(failed ? 1 : 0);
