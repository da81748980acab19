// Browser tests: the web app in Debian's headless Chromium, driven by
// playwright-core. Serves www/ with the project's own static server and runs
// every test twice: once on WebGL2 (`?backend=webgl2`) and once on WebGPU
// (SwiftShader Vulkan). Each test gets a fresh page; screenshots go to
// target/e2e/. Exits non-zero if any test fails.
//
//   node run.mjs [webgl2|webgpu]   (default: both)
import { readFileSync, mkdirSync, writeFileSync } from 'node:fs';
import { join, resolve } from 'node:path';
import { PNG } from 'pngjs';
import {
  root, startServer, CONFIGS, launch, open, waitForImport, waitForRun, settle,
  surfaceGrid, enterDesign, DESIGN_WAIT, designState, hoverLatency,
} from './harness.mjs';

const meshes = process.env.QUADRILLE_MESHES || resolve(root, '../shared/meshes');
export const artifacts = resolve(root, 'target/e2e');
mkdirSync(artifacts, { recursive: true });

// Drops `bytes` named `name` on `selector` through a synthetic DataTransfer.
async function dropFile(page, selector, name, bytes) {
  await page.evaluate(({ selector, name, data }) => {
    const dt = new DataTransfer();
    dt.items.add(new File([new Uint8Array(data)], name));
    const target = document.querySelector(selector);
    target.dispatchEvent(new DragEvent('dragenter', { dataTransfer: dt, bubbles: true, cancelable: true }));
    target.dispatchEvent(new DragEvent('dragover', { dataTransfer: dt, bubbles: true, cancelable: true }));
    target.dispatchEvent(new DragEvent('drop', { dataTransfer: dt, bubbles: true, cancelable: true }));
  }, { selector, name, data: [...bytes] });
}

// The background the viewer clears to (see gpu.rs BACKGROUND), in sRGB bytes.
const BACKGROUND = [246, 247, 249];

// Fraction of the PNG's pixels that differ clearly from the background.
function inkFraction(png) {
  const { data, width, height } = PNG.sync.read(png);
  let ink = 0;
  for (let i = 0; i < data.length; i += 4) {
    const d = Math.abs(data[i] - BACKGROUND[0]) + Math.abs(data[i + 1] - BACKGROUND[1]) + Math.abs(data[i + 2] - BACKGROUND[2]);
    if (d > 30) ink++;
  }
  return ink / (width * height);
}

// A screenshot of the canvas rectangle (what the user sees there), saved and measured.
async function canvasInk(page, file) {
  const box = await page.locator('#canvas').boundingBox();
  const png = await page.screenshot({ path: join(artifacts, file), clip: box });
  return inkFraction(png);
}

const tests = [];
const test = (name, fn) => tests.push({ name, fn });
const assert = (cond, message) => { if (!cond) throw new Error(message); };

test('page loads without console errors, runs the default sample and draws it', async (env) => {
  const { page, errors } = await open(env);
  await waitForRun(page, 'stanford-bunny.obj');
  const r = await page.evaluate(() => window.quadrille.lastImport);
  assert(r.vertices === 34834, `bunny vertices ${r.vertices}`);
  assert(r.boundary_edges === 223, `bunny boundary edges ${r.boundary_edges}`);
  assert((await page.textContent('#report')).includes('34834'), 'report table shows the vertex count');
  const backend = await page.evaluate(() => window.quadrille.backend);
  assert(backend === env.backend, `backend ${backend}, expected ${env.backend}`);
  const run = await page.evaluate(() => window.quadrille.lastRun);
  assert(run.complete && run.stages.import >= 0 && run.counts.vertices === 34834, `lastRun ${JSON.stringify(run)}`);
  const ink = await canvasInk(page, `bunny-${env.backend}.png`);
  assert(ink > 0.05, `the canvas is (nearly) blank: ${(ink * 100).toFixed(2)}% drawn`);
  await page.screenshot({ path: join(artifacts, `app-${env.backend}.png`) });
  assert(errors.length === 0, `console errors: ${errors.join(' | ')}`);
});

test('a dropped mesh runs through; a malformed file shows an error and the app still works', async (env) => {
  const { page, errors } = await open(env);
  await waitForRun(page, 'stanford-bunny.obj');
  await dropFile(page, '#view', 'fandisk.obj', readFileSync(join(meshes, 'fandisk.obj')));
  await waitForRun(page, 'fandisk.obj');
  assert(await page.evaluate(() => window.quadrille.lastImport.vertices) === 6475, 'fandisk vertex count');
  assert(await canvasInk(page, `fandisk-${env.backend}.png`) > 0.03, 'fandisk is drawn');

  await dropFile(page, '#drop', 'broken.obj', Buffer.from('v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n'));
  await page.waitForFunction(() => window.quadrille.lastError, null, { timeout: 30000 });
  const message = await page.evaluate(() => window.quadrille.lastError);
  assert(message.includes('broken.obj:4'), `error names file and line: ${message}`);
  assert((await page.textContent('#status')).includes('broken.obj:4'), 'error is shown on the page');
  await page.screenshot({ path: join(artifacts, `error-${env.backend}.png`) });

  await page.click('#sample-buttons >> text=spot');
  await waitForRun(page, 'spot.obj');
  assert(await page.evaluate(() => window.quadrille.lastImport.genus) === 0, 'spot imports after the error');
  assert(await canvasInk(page, `spot-${env.backend}.png`) > 0.03, 'spot is drawn after the error');
  assert(errors.length === 0, `console errors: ${errors.join(' | ')}`);
});

test('every stage runs and shows its layers: curvature with a legend, cross field, singularities', async (env) => {
  const { page, errors } = await open(env, 'sample=spot');
  await waitForRun(page, 'spot.obj');
  const run = await page.evaluate(() => window.quadrille.lastRun);
  for (const stage of ['import', 'analysis', 'hierarchy', 'orientation', 'position', 'extraction', 'postprocess']) {
    assert(typeof run.stages[stage] === 'number', `lastRun has ${stage} ms: ${JSON.stringify(run.stages)}`);
  }
  assert(run.counts.orientation_singularities > 0, `spot (genus 0) has singularities: ${JSON.stringify(run.counts)}`);
  // The quad mesh's faces (coloured by degree) are drawn once they exist; A goes back to the input.
  assert((await page.textContent('#legend')).includes('face degree'), 'the quad mesh faces are shown by degree');
  await page.keyboard.press('a');
  await settle(page);
  assert(!(await page.isHidden('#legend')), 'a legend is shown for the scalar');
  assert((await page.textContent('#legend')).includes('curvature'), 'the legend names the scalar');
  assert(run.counts.quad_mesh_faces > 0, `a quad mesh came out: ${JSON.stringify(run.counts)}`);
  for (const id of ['#layer-cross-field', '#layer-orientation-singularities', '#layer-feature-vertices', '#layer-quad-mesh']) {
    assert(await page.isEnabled(id), `${id} is available`);
  }
  await page.screenshot({ path: join(artifacts, `stages-${env.backend}.png`) });
  await page.selectOption('#scalar-select', 'sizing field');
  await settle(page);
  assert((await page.textContent('#legend')).includes('sizing field'), 'the legend follows the selected scalar');
  await page.keyboard.press('x');
  await page.keyboard.press('e');
  await settle(page);
  await page.screenshot({ path: join(artifacts, `sizing-${env.backend}.png`) });
  assert(errors.length === 0, `console errors: ${errors.join(' | ')}`);
});

test('layers toggle with keys, picking marks a point, the PNG export has the picture', async (env) => {
  const { page } = await open(env, 'sample=suzanne');
  await waitForRun(page, 'suzanne.obj');
  const box = await page.locator('#canvas').boundingBox();
  await page.mouse.click(box.x + box.width / 2, box.y + box.height / 2);
  await page.waitForFunction(() => window.quadrille.lastPick, null, { timeout: 10000 });
  assert(!(await page.isHidden('#pick-info')), 'pick info is shown');
  await settle(page);
  await page.screenshot({ path: join(artifacts, `picked-${env.backend}.png`) });

  const png = Buffer.from(await page.evaluate(async () => [...await window.quadrille.screenshot()]));
  assert(inkFraction(png) > 0.03, 'the exported PNG shows the mesh');

  const withSurface = await canvasInk(page, `suzanne-${env.backend}.png`);
  await page.keyboard.press('s');
  await settle(page);
  assert(!(await page.isChecked('#layer-surface')), 'S unticks the surface layer');
  const linesOnly = await canvasInk(page, `suzanne-lines-${env.backend}.png`);
  assert(linesOnly < withSurface && linesOnly > 0.005, `lines and markers alone: ${linesOnly} vs ${withSurface}`);
  for (const id of ['#layer-quad-mesh', '#layer-orientation-singularities', '#layer-non-quad-faces']) await page.uncheck(id);
  await settle(page);
  assert(!(await page.isChecked('#layer-quad-mesh')), 'Q unticks the quad mesh layer');
  const nothing = await canvasInk(page, `suzanne-nothing-${env.backend}.png`);
  assert(nothing < linesOnly, `hiding the rest leaves less: ${nothing} vs ${linesOnly}`);
});

test('cancel stops a run within half a second and the app stays usable', async (env) => {
  const { page } = await open(env);
  await waitForRun(page, 'stanford-bunny.obj');
  // A grid big enough that importing it takes well over a second; built in the page.
  await page.evaluate(() => {
    const n = 700;
    const lines = [];
    for (let i = 0; i < n; i++) for (let j = 0; j < n; j++) lines.push(`v ${i} ${j} ${Math.sin(i * 0.1) * Math.cos(j * 0.1)}`);
    for (let i = 0; i + 1 < n; i++) for (let j = 0; j + 1 < n; j++) {
      const a = i * n + j + 1;
      lines.push(`f ${a} ${a + n} ${a + n + 1} ${a + 1}`);
    }
    const dt = new DataTransfer();
    dt.items.add(new File([lines.join('\n')], 'big-grid.obj'));
    document.body.dispatchEvent(new DragEvent('drop', { dataTransfer: dt, bubbles: true, cancelable: true }));
  });
  await page.waitForFunction(() => !document.getElementById('progress').hidden);
  const started = Date.now();
  await page.click('#cancel');
  await page.waitForFunction(() => document.getElementById('status').textContent.includes('cancelled'), null, { timeout: 5000 });
  const ms = Date.now() - started;
  assert(ms < 1000, `cancel took ${ms} ms`);
  assert(await page.isHidden('#progress'), 'progress bar hidden after cancel');
  assert(await page.evaluate(() => window.quadrille.lastRun.input) === 'stanford-bunny.obj', 'the cancelled run did not complete');
  await page.click('#sample-buttons >> text=spot');
  await waitForRun(page, 'spot.obj');
});

test('a panic in the worker is shown and the app recovers', async (env) => {
  const { page } = await open(env);
  await waitForRun(page, 'stanford-bunny.obj');
  await page.evaluate(() => window.quadrille.panicForTesting());
  await page.waitForFunction(() => (window.quadrille.lastError || '').includes('deliberate panic'), null, { timeout: 10000 });
  assert((await page.textContent('#status')).includes('deliberate panic'), 'panic message on the page');
  await page.click('#sample-buttons >> text=spot');
  await waitForRun(page, 'spot.obj');
});

test('the page works at phone size', async (env) => {
  const page = await env.context.newPage();
  await page.setViewportSize({ width: 390, height: 844 });
  await page.goto(env.url + '?sample=cow' + (env.query ? `&${env.query}` : ''));
  await waitForRun(page, 'cow.obj');
  const overflow = await page.evaluate(() => document.documentElement.scrollWidth > window.innerWidth + 1);
  assert(!overflow, 'no horizontal scrolling at 390 px');
  assert(await canvasInk(page, `phone-canvas-${env.backend}.png`) > 0.03, 'the cow is drawn at phone size');
  await page.screenshot({ path: join(artifacts, `phone-${env.backend}.png`), fullPage: true });
});

// Counts of an OBJ file's vertex and face lines.
function objCounts(text) {
  let v = 0;
  let f = 0;
  for (const line of text.split('\n')) {
    if (line.startsWith('v ')) v++;
    else if (line.startsWith('f ')) f++;
  }
  return { v, f };
}

// Sets a parameter through its input in the parameter panel, as a user would.
async function setParamInput(page, path, value) {
  await page.evaluate(({ path, value }) => {
    const input = document.getElementById(`param-${path}`);
    if (!input) throw new Error(`no input for ${path}`);
    if (input.type === 'checkbox') input.checked = value;
    else input.value = String(value);
    input.dispatchEvent(new Event('change', { bubbles: true }));
  }, { path, value });
}

test('the parameter panel lists every parameter; a change re-runs only from its stage', async (env) => {
  const { page, errors } = await open(env, 'sample=spot');
  await waitForRun(page, 'spot.obj');
  const first = await page.evaluate(() => window.quadrille.lastRun);
  for (const stage of ['import', 'analysis', 'hierarchy', 'orientation', 'position', 'extraction', 'postprocess', 'fit']) {
    assert(first.stagesRun.includes(stage), `the first run ran ${stage}: ${first.stagesRun}`);
  }
  // Every leaf of the parameters has an input with its default and help.
  const leaves = await page.evaluate(() => {
    const out = [];
    const walk = (o, prefix) => {
      for (const [k, v] of Object.entries(o)) {
        const path = prefix ? `${prefix}.${k}` : k;
        if (v && typeof v === 'object' && !Array.isArray(v)) walk(v, path);
        else out.push(path);
      }
    };
    walk(window.quadrille.lastRun.parameters, '');
    return out;
  });
  assert(leaves.length > 40, `parameters: ${leaves.length}`);
  for (const path of leaves) {
    const text = await page.evaluate((p) => document.getElementById(`param-${p}`)?.closest('.param')?.textContent, path);
    assert(text && text.includes('Default:'), `${path} has an input with its default: ${text}`);
  }
  // A position-field parameter: analysis, hierarchy and orientation are kept.
  await setParamInput(page, 'field.position_iterations', 7);
  await page.waitForFunction(() => window.quadrille.lastRun.parameters.field.position_iterations === 7, null, { timeout: 60000 });
  const second = await page.evaluate(() => window.quadrille.lastRun);
  assert(second.stagesRun.join() === 'position,extraction,postprocess,fit', `position change ran ${second.stagesRun}`);
  assert(second.counts.quad_mesh_faces > 0 && second.metrics.topology.faces === second.counts.quad_mesh_faces,
    `metrics follow the new mesh: ${JSON.stringify(second.counts)}`);
  // A post-processing parameter: only post-processing and the fit.
  await setParamInput(page, 'extraction.post.smoothing_iterations', 1);
  await page.waitForFunction(() => window.quadrille.lastRun.parameters.extraction.post.smoothing_iterations === 1, null, { timeout: 60000 });
  const third = await page.evaluate(() => window.quadrille.lastRun);
  assert(third.stagesRun.join() === 'postprocess,fit', `post-processing change ran ${third.stagesRun}`);
  assert(!(await page.isHidden('#metrics-panel')), 'the metrics panel is shown');
  assert((await page.textContent('#metrics')).includes(String(third.metrics.topology.vertices)), 'the metrics panel shows the vertex count');
  await page.click('#params-panel > summary');
  await page.click('#params .group >> nth=2');
  await settle(page);
  await page.screenshot({ path: join(artifacts, `params-${env.backend}.png`), fullPage: true });
  assert(errors.length === 0, `console errors: ${errors.join(' | ')}`);
});

// Switches the page on screen to `mode` with the selector next to the target count.
async function selectMode(page, mode) {
  await page.selectOption('#remesh-mode', mode);
}
const stageBars = (page) => page.evaluate(() => [...document.querySelectorAll('#progress-stages li')].map((li) => li.id.replace('progress-', '')));
const layerLabels = (page) => page.evaluate(() => [...document.querySelectorAll('#layers li label')].map((l) => l.textContent));

test('the remeshing mode selector switches the stage list and the layers; the global map is the pipeline\u2019s', async (env) => {
  const { page, errors } = await open(env, 'sample=spot');
  await waitForRun(page, 'spot.obj');
  assert((await stageBars(page)).join() === 'import,analysis,hierarchy,orientation,position,extraction,postprocess,fit', `local stage list: ${await stageBars(page)}`);
  assert(await page.inputValue('#remesh-mode') === 'local', 'the default mode is local');
  const options = await page.evaluate(() => [...document.querySelectorAll('#remesh-mode option')].map((o) => o.textContent));
  assert(/Local/.test(options[0]) && /Global/.test(options[1]) && /integer-grid/.test(options[1]), `options: ${options}`);
  assert(await page.evaluate(() => document.getElementById('remesh-mode').closest('#target-panel') !== null), 'next to the target count');
  assert((await layerLabels(page)).includes('Cross field'), 'the local run shows its cross field');
  assert(await page.evaluate(() => window.quadrille.lastParam == null), 'no map in the local mode until asked for');
  // Global: the stage list is the global mode's, the panel's remesh.mode
  // follows, the local fields' layers go, and the parametrization stage
  // brings the map's layers (no on-demand job: it is the pipeline's).
  await selectMode(page, 'global');
  await page.waitForFunction(() => window.quadrille.lastParam, null, { timeout: 120000 });
  assert((await stageBars(page)).join() === 'import,analysis,parametrization,extraction,postprocess,fit', `global stage list: ${await stageBars(page)}`);
  assert(await page.evaluate(() => document.getElementById('param-remesh.mode').value) === 'global', 'the parameter panel follows the selector');
  assert(await page.evaluate(() => !window.quadrille.paramJobs), 'the map came with the run, not from a job of its own');
  await page.locator('#target-panel').screenshot({ path: join(artifacts, `mode-selector-${env.backend}.png`) });
  await page.waitForFunction(() => document.getElementById('progress').hidden, null, { timeout: 120000 });
  await settle(page);
  const layers = await layerLabels(page);
  assert(!layers.includes('Cross field') && !layers.includes('Position field') && !layers.includes('Orientation singularities'),
    `the local fields' layers are gone: ${layers}`);
  assert(layers.includes('Parametrization cones') && layers.includes('Parametrization'), `the map's layers: ${layers}`);
  // Its checkerboard is offered at once (I), without a second computation.
  await page.check('#layer-parametrization');
  await settle(page);
  assert(await page.evaluate(() => !window.quadrille.paramJobs), 'showing the checkerboard computes nothing');
  await page.screenshot({ path: join(artifacts, `global-map-${env.backend}.png`) });
  await page.uncheck('#layer-parametrization');
  // Back to local: the map and its cones go (a local map is computed on demand).
  await page.evaluate(() => { window.quadrille.runBefore = window.quadrille.lastRun; });
  await selectMode(page, 'local');
  await page.waitForFunction(() => window.quadrille.lastRun !== window.quadrille.runBefore, null, { timeout: 120000 });
  assert((await stageBars(page)).join() === 'import,analysis,hierarchy,orientation,position,extraction,postprocess,fit', `local again: ${await stageBars(page)}`);
  const back = await page.evaluate(() => window.quadrille.lastRun);
  assert(back.stagesRun.join() === 'hierarchy,orientation,position,extraction,postprocess,fit', `back to local ran from the kept analysis: ${back.stagesRun}`);
  assert(!(await layerLabels(page)).includes('Parametrization cones'), 'the global map\u2019s cones are gone');
  assert(errors.length === 0, `console errors: ${errors.join(' | ')}`);
});

test('the global mode remeshes spot into closed pure quads, fitted without the split, from the kept analysis', async (env) => {
  const { page, errors } = await open(env, 'sample=spot');
  await waitForRun(page, 'spot.obj');
  const before = await page.evaluate(() => window.quadrille.lastRun);
  await selectMode(page, 'global');
  await page.waitForFunction(() => document.getElementById('progress').hidden && window.quadrille.lastParam, null, { timeout: 120000 });
  await settle(page);
  const status = (await page.textContent('#status')).trim();
  const run = await page.evaluate(() => window.quadrille.lastRun);
  await page.screenshot({ path: join(artifacts, `global-mode-${env.backend}.png`) });
  console.log(`      [${env.backend}] spot, global mode: ${status}`);
  assert(run.parameters.remesh.mode === 'global' && run.counts.mode === 'global', `the run is the global mode's: ${status}`);
  assert(run.stagesRun.join() === 'parametrization,extraction,postprocess,fit', `only the global stages after the kept analysis: ${run.stagesRun}`);
  assert(run.stages.analysis === before.stages.analysis, 'the analysis is the first run\u2019s');
  assert(Object.keys(run.stages).sort().join() === 'analysis,extraction,fit,import,parametrization,postprocess',
    `the stage times are the global mode's: ${Object.keys(run.stages)}`);
  assert(/ · 100\.0 % quads · \d+ cones/.test(status), `the status line reports pure quads and the cones: ${status}`);
  const t = run.metrics.topology;
  assert(t.non_quad_percent === 0 && t.boundary_edges === 0 && t.nonmanifold_edges === 0, `closed pure quads: ${JSON.stringify(t)}`);
  assert(run.limit_surface.split === false && run.limit_surface.control_vertices === run.counts.quad_mesh_vertices,
    `fitted without the split: ${run.limit_surface.control_vertices} control vertices for ${run.counts.quad_mesh_vertices}`);
  const layers = await layerLabels(page);
  assert(layers.includes('Quad mesh') && layers.includes('Quad mesh faces'), `the extracted quads are the quad mesh layers: ${layers}`);
  assert(errors.length === 0, `console errors: ${errors.join(' | ')}`);
});

test('a run that fails takes the layers of its failed stage and the later ones off the screen', async (env) => {
  const { page, errors } = await open(env, 'sample=spot');
  await waitForRun(page, 'spot.obj');
  const before = await layerLabels(page);
  assert(before.includes('Quad mesh') && before.includes('Limit surface'), `the local run's layers: ${before}`);
  // The global mode's parametrization fails: the local quads, fit and
  // limit surface on screen are not this run's result and must go; the
  // analysis (kept from the local run, the same for both modes) stays.
  await page.evaluate(() => window.quadrille.failStageForTesting('parametrization'));
  await selectMode(page, 'global');
  await page.waitForFunction(() => document.getElementById('status').classList.contains('error'), null, { timeout: 120000 });
  await settle(page);
  const status = (await page.textContent('#status')).trim();
  const after = await layerLabels(page);
  console.log(`      [${env.backend}] failed global run: ${status} · layers ${after.join(', ')}`);
  assert(/parametrization: a failure asked for by a test/.test(status), `the status names the failure: ${status}`);
  for (const gone of ['Quad mesh', 'Quad mesh faces', 'Control cage', 'Limit surface', 'Non-quad faces', 'Extracted mesh']) {
    assert(!after.includes(gone), `${gone} is the local run's and went: ${after}`);
  }
  assert(after.includes('Principal directions'), `the analysis' layers stay: ${after}`);
  await page.screenshot({ path: join(artifacts, `failed-run-${env.backend}.png`) });
  // The next run (the failure was asked for once) shows the global quads.
  await setParamInput(page, 'remesh.stiffening', 3);
  await page.waitForFunction(() => document.getElementById('progress').hidden && window.quadrille.lastRun?.parameters.remesh.stiffening === 3, null, { timeout: 120000 });
  assert((await layerLabels(page)).includes('Quad mesh'), 'the next run brings its quads');
  assert(errors.length === 0, `console errors: ${errors.join(' | ')}`);
});

test('exported OBJ files parse and have the counts of lastRun; the limit surface shows its error', async (env) => {
  const { page, errors } = await open(env, 'sample=fandisk');
  await waitForRun(page, 'fandisk.obj');
  const run = await page.evaluate(() => window.quadrille.lastRun);
  const expected = {
    'quad-dominant': [run.counts.quad_mesh_vertices, run.counts.quad_mesh_faces],
    control: [run.counts.control_vertices, run.counts.control_faces],
    limit: [run.counts.limit_vertices, run.counts.limit_faces],
  };
  for (const [kind, [v, f]] of Object.entries(expected)) {
    const [download] = await Promise.all([
      page.waitForEvent('download'),
      page.click(`#exports button[data-kind="${kind}"][data-format="obj"]`),
    ]);
    const text = readFileSync(await download.path(), 'utf8');
    const c = objCounts(text);
    assert(c.v === v && c.f === f, `${kind} OBJ has ${c.v} v / ${c.f} f, lastRun ${v} / ${f}`);
  }
  // The pure-quad mesh: every face a quad.
  const pure = Buffer.from(await page.evaluate(async () => [...await window.quadrille.exportMesh('pure-quad', 'obj')])).toString('utf8');
  const faces = pure.split('\n').filter((l) => l.startsWith('f '));
  assert(faces.length > 0 && faces.every((l) => l.trim().split(/\s+/).length === 5), 'the pure-quad OBJ has only quads');
  // PLY: a binary file whose header has the same counts.
  const ply = Buffer.from(await page.evaluate(async () => [...await window.quadrille.exportMesh('control', 'ply')])).toString('latin1');
  assert(ply.includes(`element vertex ${run.counts.control_vertices}`) && ply.includes(`element face ${run.counts.control_faces}`),
    'the control PLY header has the counts');
  // The limit surface layer: coloured by the signed error, symmetric legend.
  await page.keyboard.press('u');
  await settle(page);
  const legend = await page.textContent('#legend');
  assert(legend.includes('limit surface error'), `legend: ${legend}`);
  const [min, max] = await page.evaluate(() => [document.querySelector('#legend .min').textContent, document.querySelector('#legend .max').textContent].map(Number));
  assert(min < 0 && Math.abs(min + max) < 1e-9, `symmetric error range: ${min} … ${max}`);
  await page.keyboard.press('w');
  await settle(page);
  assert(await canvasInk(page, `limit-${env.backend}.png`) > 0.03, 'the limit surface is drawn');
  await page.keyboard.press('u');
  await settle(page);
  assert((await page.textContent('#legend')).includes('curvature'), 'the input surface is back with its scalar');
  assert(errors.length === 0, `console errors: ${errors.join(' | ')}`);
});

test('the share link reproduces the run: same sample, parameters and counts', async (env) => {
  const { page } = await open(env, 'sample=fandisk');
  await waitForRun(page, 'fandisk.obj');
  await setParamInput(page, 'field.seed', 3);
  await page.waitForFunction(() => window.quadrille.lastRun.parameters.field.seed === 3, null, { timeout: 60000 });
  const original = await page.evaluate(() => window.quadrille.lastRun);
  await page.click('#share');
  const url = await page.inputValue('#share-url');
  assert(url.includes('sample=fandisk') && url.includes('field.seed'), `share link ${url}`);
  const fresh = await env.context.newPage();
  await fresh.goto(url);
  await waitForRun(fresh, 'fandisk.obj');
  const again = await fresh.evaluate(() => window.quadrille.lastRun);
  assert(again.parameters.field.seed === 3, 'the link carries the parameter');
  assert(JSON.stringify(again.counts) === JSON.stringify(original.counts),
    `same counts: ${JSON.stringify(again.counts)} vs ${JSON.stringify(original.counts)}`);
  assert(await fresh.evaluate(() => document.getElementById('param-field.seed').value) === '3', 'the panel shows the linked value');
  // A dropped file is not in the link: only the parameters, and the page says so.
  await dropFile(fresh, '#view', 'my-part.obj', readFileSync(join(meshes, 'fandisk.obj')));
  await waitForRun(fresh, 'my-part.obj');
  await fresh.click('#share');
  const own = await fresh.inputValue('#share-url');
  assert(!own.includes('sample=') && own.includes('field.seed'), `a dropped file's link has only the parameters: ${own}`);
  assert((await fresh.textContent('#share-note')).includes('only the parameters'), 'the page says the file is not in the link');
});

test('shortcut keys are unique and ? lists them', async (env) => {
  const { page } = await open(env, 'sample=suzanne');
  await waitForRun(page, 'suzanne.obj');
  const keys = await page.$$eval('#layers kbd', (ks) => ks.map((k) => k.textContent));
  assert(new Set(keys).size === keys.length, `duplicate keys: ${keys}`);
  await page.keyboard.press('?');
  assert(!(await page.isHidden('#shortcuts')), 'the shortcut list opens');
  assert((await page.textContent('#shortcuts')).includes('Position singularities'), 'it lists the layers');
  await page.keyboard.press('Escape');
  assert(await page.isHidden('#shortcuts'), 'Esc closes it');
});

test('smooth regions: one colour per region, discarded ones grey, significance in the pick readout', async (env) => {
  const link = `sample=fandisk&p=${encodeURIComponent(JSON.stringify({ 'alignment.mode': 'smooth-regions' }))}`;
  const { page, errors } = await open(env, link);
  await waitForRun(page, 'fandisk.obj');
  const run = await page.evaluate(() => window.quadrille.lastRun);
  assert(run.parameters.alignment.mode === 'smooth-regions', `mode from the link: ${run.parameters.alignment.mode}`);
  assert(await page.isEnabled('#layer-smooth-regions'), 'the smooth regions layer is available');
  await page.keyboard.press('r');
  await settle(page);
  assert((await page.textContent('#legend')).includes('smooth regions'), 'the legend names the regions');
  const box = await page.locator('#canvas').boundingBox();
  await page.mouse.click(box.x + box.width / 2, box.y + box.height / 2);
  await page.waitForFunction(() => window.quadrille.lastPick, null, { timeout: 10000 });
  const info = await page.textContent('#pick-info');
  assert(/significance [0-9.]+°|no smooth region/.test(info), `pick readout: ${info}`);
  assert(await canvasInk(page, `smooth-regions-${env.backend}.png`) > 0.03, 'the regions are drawn');
  assert(errors.length === 0, `console errors: ${errors.join(' | ')}`);
});

test('cancelling a parameter re-run keeps the cached stages when the worker stops in time', async (env) => {
  const { page } = await open(env);
  await waitForRun(page, 'stanford-bunny.obj');
  assert(await page.evaluate(() => self.crossOriginIsolated), 'the server makes the page cross-origin isolated (shared cancel flag)');
  // A fit that never converges: long enough to cancel in the middle.
  await setParamInput(page, 'fit.tolerance', 0);
  await setParamInput(page, 'fit.max_iterations', 100);
  await page.waitForFunction(() => document.querySelector('#progress .progress-text').textContent.includes('fit'), null, { timeout: 60000 });
  await page.click('#cancel');
  await page.waitForFunction(() => document.getElementById('status').textContent.includes('cancelled'), null, { timeout: 5000 });
  const status = await page.textContent('#status');
  await setParamInput(page, 'fit.max_iterations', 4);
  await page.waitForFunction(() => window.quadrille.lastRun.parameters.fit.max_iterations === 4, null, { timeout: 60000 });
  const run = await page.evaluate(() => window.quadrille.lastRun);
  // Stopped at a progress report: the worker and its cache live on, so only
  // the fit runs; terminated as the last resort: everything runs again.
  const expected = status.includes('restarted') ? 'import,analysis,hierarchy,orientation,position,extraction,postprocess,fit' : 'fit';
  assert(run.stagesRun.join() === expected, `after "${status}" the re-run ran ${run.stagesRun}`);
  assert(run.complete && run.limit_surface.iterations <= 4, `the fit ran with the new parameter: ${JSON.stringify(run.limit_surface?.iterations)}`);
});

// ---------------------------------------------------------------- design mode (dual strip weaving)

const polylineLength = (p) => {
  let s = 0;
  for (let i = 3; i < p.length; i += 3) s += Math.hypot(p[i] - p[i - 3], p[i + 1] - p[i - 2], p[i + 2] - p[i - 1]);
  return s;
};

// Waits for the analysis of the current design revision.
const waitForAnalysis = (page) => page.waitForFunction(() => {
  const d = window.quadrille.design;
  return d.analysis && d.state && d.analysis.revision === d.state.revision;
}, null, { timeout: 120000 });

// Hovers at a grid point and commits the proposal with Enter.
async function hoverAndCommit(page, hit) {
  const before = await page.evaluate(() => window.quadrille.design.state.loops.length);
  const n = await page.evaluate(() => window.quadrille.design.hoverLatencies.length);
  await page.mouse.move(hit.x, hit.y);
  await page.waitForFunction((n) => window.quadrille.design.hoverLatencies.length > n, n, DESIGN_WAIT);
  await page.keyboard.press('Enter');
  await page.waitForFunction((b) => window.quadrille.design.state.loops.length > b, before, DESIGN_WAIT);
}

test('design mode: hovering draws the best loop fast; wheel, click, drag and grab edit it', async (env) => {
  const { page, errors } = await open(env, 'sample=torus');
  await waitForRun(page, 'torus.obj');
  await enterDesign(page);
  assert(!(await page.isHidden('#design-panel')), 'the design panel is shown');
  const hits = await surfaceGrid(page);
  assert(hits.length > 50, `the torus is under the pointer: ${hits.length} grid hits`);
  const path = hits.filter((_, i) => i % Math.max(1, Math.floor(hits.length / 25)) === 0).slice(0, 25);
  const latency = await hoverLatency(page, path);
  console.log(`      [${env.backend}] torus (7680 faces): hover-to-draw median ${latency.median.toFixed(1)} ms (max ${latency.max.toFixed(1)}), loop query in the worker ${latency.workerMedian.toFixed(1)} ms`);
  const hovered = await designState(page);
  assert(hovered.proposal.length >= 9, 'a loop is drawn under the pointer');
  assert(hovered.loops.length === 0 && hovered.anchors === 0, 'nothing committed by hovering');
  // The wheel: the next alternative through the same point.
  await page.mouse.wheel(0, 120);
  await page.waitForFunction(() => window.quadrille.design.state.browse[0] === 1, null, DESIGN_WAIT);
  const browsed = await designState(page);
  assert(browsed.browse[1] >= 2, `several alternatives: ${browsed.browse}`);
  assert(JSON.stringify(browsed.proposal) !== JSON.stringify(hovered.proposal), 'the wheel changed the proposal');
  // A click: an anchor; the loop through it is drawn.
  const last = path[path.length - 1];
  await page.mouse.click(last.x, last.y);
  await page.waitForFunction(() => window.quadrille.design.state.anchors.length === 3, null, DESIGN_WAIT);
  const clicked = await designState(page);
  assert(clicked.anchors === 1 && clicked.proposal.length >= 9 && clicked.canUndo, `one anchor and its loop: ${clicked.anchors}`);
  // A drag from the surface: a directional anchor whose direction follows the pointer.
  const from = path[Math.floor(path.length / 3)];
  await page.mouse.move(from.x, from.y);
  await page.mouse.down();
  for (let k = 1; k <= 6; k++) await page.mouse.move(from.x + 6 * k, from.y + 3 * k);
  await page.mouse.up();
  await page.waitForFunction(() => window.quadrille.design.state.anchors.length === 6, null, DESIGN_WAIT);
  const dragged = await page.evaluate(() => [...window.quadrille.design.state.anchorDirections]);
  assert(Math.hypot(dragged[3], dragged[4], dragged[5]) > 0.5, `the dragged anchor is directional: ${dragged}`);
  assert(Math.hypot(dragged[0], dragged[1], dragged[2]) === 0, 'the clicked anchor is positional');
  // Grab: press on the loop through the anchors and drag it: an anchor is inserted there.
  await page.waitForFunction(() => window.quadrille.design.proposal.length >= 9, null, DESIGN_WAIT);
  const loop = await page.evaluate(() => [...window.quadrille.design.proposal]);
  const anchorsNow = await page.evaluate(() => [...window.quadrille.design.state.anchors]);
  const fine = await surfaceGrid(page, 8);
  const d2 = (p, q) => (p[0] - q[0]) ** 2 + (p[1] - q[1]) ** 2 + (p[2] - q[2]) ** 2;
  const onLoop = fine.filter((h) => {
    let best = Infinity;
    for (let i = 0; i < loop.length; i += 3) best = Math.min(best, d2(h.p, loop.slice(i, i + 3)));
    const nearAnchor = [0, 3].some((i) => d2(h.p, anchorsNow.slice(i, i + 3)) < 0.05 ** 2);
    return best < 0.006 ** 2 && !nearAnchor;
  });
  assert(onLoop.length > 0, 'some pixels lie on the drawn loop');
  const grab = onLoop[Math.floor(onLoop.length / 2)];
  await page.mouse.move(grab.x, grab.y);
  await page.mouse.down();
  for (let k = 1; k <= 5; k++) await page.mouse.move(grab.x + 4 * k, grab.y - 4 * k);
  await page.mouse.up();
  await page.waitForFunction(() => window.quadrille.design.state.anchors.length === 9, null, DESIGN_WAIT);
  const grabbed = await designState(page);
  assert(grabbed.proposal.length >= 9, 'the loop through three anchors exists');
  // Escape clears them (undoably).
  await page.keyboard.press('Escape');
  await page.waitForFunction(() => window.quadrille.design.state.anchors.length === 0, null, DESIGN_WAIT);
  assert((await page.textContent('#shortcuts-close')) && !(await page.isHidden('#design-panel')), 'still in the mode');
  assert(errors.length === 0, `console errors: ${errors.join(' | ')}`);
});

// §8.1: four anchors on the torus clicked in bow-tie order (the loop through
// them must cross itself): the crossing is reported, drawn and named in the
// status line. Checked independently: at each reported point two
// non-neighbouring segments of the drawn proposal pass, and it lies on the
// torus (major radius 2, minor 0.7 in the file; the page's coordinates are
// centred with the largest axis, 5.4, scaled to 1).
test('design mode: a self-crossing loop through anchors is detected and shown', async (env) => {
  const { page, errors } = await open(env, 'sample=torus');
  await waitForRun(page, 'torus.obj');
  await enterDesign(page);
  const hits = await surfaceGrid(page, 6);
  const k = 1 / 5.4;
  const at = (a, b) => { const ring = 2 + 0.7 * Math.cos(b); return [k * ring * Math.cos(a), k * ring * Math.sin(a), k * 0.7 * Math.sin(b)]; };
  const d2 = (p, q) => (p[0] - q[0]) ** 2 + (p[1] - q[1]) ** 2 + (p[2] - q[2]) ** 2;
  const nearest = (q) => hits.reduce((best, h) => (d2(h.p, q) < d2(best.p, q) ? h : best), hits[0]);
  // The bow tie around an angle of the torus that the view shows.
  let clicks = null;
  for (const b0 of [0, Math.PI / 2, -Math.PI / 2]) {
    for (let a0 = 0; a0 < 2 * Math.PI && !clicks; a0 += Math.PI / 4) {
      const targets = [[-0.2, 0.4], [0.2, -0.4], [0.2, 0.4], [-0.2, -0.4]].map(([da, db]) => at(a0 + da, b0 + db));
      const found = targets.map(nearest);
      if (found.every((h, i) => d2(h.p, targets[i]) < (0.08 * k) ** 2)) clicks = found;
    }
  }
  assert(clicks, 'the view shows a bow tie of anchors on the torus');
  for (const [i, c] of clicks.entries()) {
    await page.mouse.click(c.x, c.y);
    await page.waitForFunction((n) => window.quadrille.design.state.anchors.length === 3 * n, i + 1, DESIGN_WAIT);
  }
  await page.waitForFunction(() => window.quadrille.design.actionsSent === window.quadrille.design.actionsAnswered, null, DESIGN_WAIT);
  const s = await page.evaluate(() => ({ crossings: [...window.quadrille.design.state.selfCrossings],
    angles: [...window.quadrille.design.state.selfCrossingAngles], proposal: [...window.quadrille.design.proposal],
    status: document.getElementById('status').textContent }));
  const n = s.crossings.length / 3;
  console.log(`      [${env.backend}] torus bow tie: ${n} self-crossing(s), angles ${s.angles.map((a) => a.toFixed(1)).join(', ')}°`);
  assert(n >= 1, 'the bow-tie loop crosses itself');
  assert(/crosses itself/.test(s.status), `the status asks to adjust: ${s.status}`);
  const seg = (i) => [s.proposal.slice(3 * i, 3 * i + 3), s.proposal.slice(3 * i + 3, 3 * i + 6)];
  const segDist2 = ([a, b], p) => {
    const ab = [0, 1, 2].map((k) => b[k] - a[k]);
    const len2 = ab.reduce((t, x) => t + x * x, 0);
    const t = len2 > 0 ? Math.max(0, Math.min(1, [0, 1, 2].reduce((u, k) => u + (p[k] - a[k]) * ab[k], 0) / len2)) : 0;
    return d2(p, [0, 1, 2].map((k) => a[k] + ab[k] * t));
  };
  const segments = s.proposal.length / 3 - 1;
  for (let c = 0; c < n; c++) {
    const p = s.crossings.slice(3 * c, 3 * c + 3);
    const onTorus = Math.hypot(Math.hypot(p[0], p[1]) / k - 2, p[2] / k) - 0.7;
    assert(Math.abs(onTorus) < 0.05, `crossing ${c} lies on the torus (off by ${onTorus})`);
    const close = [];
    for (let i = 0; i < segments; i++) if (segDist2(seg(i), p) < (0.03 * k) ** 2) close.push(i);
    const apart = close.some((i) => close.some((j) => Math.min(Math.abs(i - j), segments - Math.abs(i - j)) > 3));
    assert(apart, `two separate passes of the loop meet at crossing ${c} (segments ${close})`);
  }
  // Escape drops the anchors, and with them the crossings.
  await page.keyboard.press('Escape');
  await page.waitForFunction(() => window.quadrille.design.state.anchors.length === 0 && window.quadrille.design.state.selfCrossings.length === 0, null, DESIGN_WAIT);
  assert(errors.length === 0, `console errors: ${errors.join(' | ')}`);
});

test('design mode: three loops on the torus give strips and a valid layout; undo restores; a vertex drags; the export parses', async (env) => {
  const { page, errors } = await open(env, 'sample=torus');
  await waitForRun(page, 'torus.obj');
  await enterDesign(page);
  const hits = await surfaceGrid(page);
  // Two meridians (the best loops) far apart, then the longest alternative (around the hole).
  const byX = [...hits].sort((a, b) => a.p[0] - b.p[0]);
  await hoverAndCommit(page, byX[Math.floor(byX.length * 0.05)]);
  await hoverAndCommit(page, byX[Math.floor(byX.length * 0.95)]);
  const two = await designState(page);
  assert(two.loops.length === 2, `two strips: ${two.loops.length}`);
  const meridian = polylineLength(two.loops[0]);
  const mid = byX[Math.floor(byX.length * 0.5)];
  await page.mouse.move(mid.x, mid.y);
  await page.waitForFunction(() => window.quadrille.design.proposal.length > 0, null, DESIGN_WAIT);
  let found = false;
  for (let k = 0; k < 8 && !found; k++) {
    await page.mouse.wheel(0, 120);
    await page.waitForFunction((k) => window.quadrille.design.state.browse[0] !== k, k, DESIGN_WAIT);
    const s = await designState(page);
    found = polylineLength(s.proposal) > 1.6 * meridian;
  }
  assert(found, 'the wheel offers a loop around the hole');
  await page.keyboard.press('Enter');
  await page.waitForFunction(() => window.quadrille.design.state.loops.length === 3, null, DESIGN_WAIT);
  const three = await designState(page);
  await waitForAnalysis(page);
  const a = await page.evaluate(() => window.quadrille.design.analysis);
  console.log(`      [${env.backend}] torus, 3 strips: ${JSON.stringify(a.counts)} · ${a.status} · timings ${JSON.stringify(a.timings)}`);
  await page.mouse.move(0, 0);
  await settle(page);
  await page.screenshot({ path: join(artifacts, `design-torus-${env.backend}.png`) });
  assert(a.available, `the strip analysis ran: ${a.status}`);
  assert(a.counts.strips === 3 && a.counts.red === 0 && a.sufficient, `no red regions: ${JSON.stringify(a.counts)}`);
  assert(a.stripes.length > 0, 'stripes are drawn');
  const { layout_vertices: V, layout_edges: E, patches: F } = a.counts;
  assert(V - E + F === 0, `V − E + F = ${V} − ${E} + ${F} = 0 on the torus`);
  assert((await page.textContent('#design-status')).includes('topologically sufficient'), 'the status line says sufficient');
  // Undo: the previous loops exactly, and the analysis follows.
  await page.keyboard.press('Control+z');
  await page.waitForFunction(() => window.quadrille.design.state.loops.length === 2, null, DESIGN_WAIT);
  const undone = await designState(page);
  assert(JSON.stringify(undone.loops) === JSON.stringify(two.loops), 'undo restores the previous loops');
  await waitForAnalysis(page);
  assert(await page.evaluate(() => window.quadrille.design.analysis.counts.strips) === 2, 'the analysis follows the undo');
  await page.keyboard.press('Control+Shift+z');
  await page.waitForFunction(() => window.quadrille.design.state.loops.length === 3, null, DESIGN_WAIT);
  assert(JSON.stringify((await designState(page)).loops) === JSON.stringify(three.loops), 'redo restores the third loop');
  await waitForAnalysis(page);
  // Delete from the list, then undo.
  await page.click('#design-strips li:nth-child(1) button');
  await page.waitForFunction(() => window.quadrille.design.state.loops.length === 2, null, DESIGN_WAIT);
  await page.click('#design-undo');
  await page.waitForFunction(() => window.quadrille.design.state.loops.length === 3, null, DESIGN_WAIT);
  await waitForAnalysis(page);
  // Dragging a layout vertex moves it (its edges re-routed); undo puts it back.
  const before = await page.evaluate(() => [...window.quadrille.design.analysis.layoutVertices]);
  let target = null;
  for (let turn = 0; turn < 6 && !target; turn++) {
    const grid = await surfaceGrid(page, 8);
    for (let v = 0; v < before.length / 3 && !target; v++) {
      const q = before.slice(3 * v, 3 * v + 3);
      const near = grid.filter((h) => Math.hypot(h.p[0] - q[0], h.p[1] - q[1], h.p[2] - q[2]) < 0.02).sort((a, b) => Math.hypot(a.p[0] - q[0], a.p[1] - q[1], a.p[2] - q[2]) - Math.hypot(b.p[0] - q[0], b.p[1] - q[1], b.p[2] - q[2]));
      if (near.length) target = { v, hit: near[0] };
    }
    if (!target) { // turn the view (right-drag) and look again
      const box = await page.locator('#canvas').boundingBox();
      await page.mouse.move(box.x + box.width / 2, box.y + box.height / 2);
      await page.mouse.down({ button: 'right' });
      await page.mouse.move(box.x + box.width / 2 + 120, box.y + box.height / 2, { steps: 4 });
      await page.mouse.up({ button: 'right' });
      await settle(page);
    }
  }
  assert(target, 'a layout vertex is visible');
  const analyses = await page.evaluate(() => window.quadrille.design.analyses);
  await page.mouse.move(target.hit.x, target.hit.y);
  await page.mouse.down();
  for (let k = 1; k <= 5; k++) await page.mouse.move(target.hit.x + 5 * k, target.hit.y + 2 * k);
  await page.mouse.up();
  await page.waitForFunction((n) => window.quadrille.design.analyses > n, analyses, { timeout: 60000 });
  const moved = await page.evaluate(() => [...window.quadrille.design.analysis.layoutVertices]);
  const shift = Math.hypot(...[0, 1, 2].map((k) => moved[3 * target.v + k] - before[3 * target.v + k]));
  assert(shift > 0.005, `the vertex moved by ${shift}: ${await page.textContent('#design-status')}`);
  await page.keyboard.press('Control+z');
  await page.waitForFunction((n) => window.quadrille.design.analyses > n + 1, analyses, { timeout: 60000 });
  const back = await page.evaluate(() => [...window.quadrille.design.analysis.layoutVertices]);
  assert(JSON.stringify(back) === JSON.stringify(before), 'undo puts the vertex back');
  // The JSON export parses and has the counts shown.
  const [download] = await Promise.all([page.waitForEvent('download'), page.click('#design-export-json')]);
  const json = JSON.parse(readFileSync(await download.path(), 'utf8'));
  const shown = await page.evaluate(() => window.quadrille.design.analysis.counts);
  assert(json.patches.length === shown.patches && json.vertices.length === shown.layout_vertices && json.edges.length === shown.layout_edges,
    `exported ${json.vertices.length} / ${json.edges.length} / ${json.patches.length}, shown ${JSON.stringify(shown)}`);
  // Every patch: 4 corners, and its i-th edge joins corners i and i + 1.
  for (const p of json.patches) {
    assert(p.corners.length === 4 && p.edges.length === 4, `a patch with ${p.corners.length} corners`);
    for (let i = 0; i < 4; i++) {
      const ends = json.edges[p.edges[i]].ends;
      const [x, y] = [p.corners[i], p.corners[(i + 1) % 4]];
      assert((ends[0] === x && ends[1] === y) || (ends[0] === y && ends[1] === x), `patch edge ${i} joins its corners`);
    }
  }
  assert((await page.textContent('#design-counts')).includes(String(shown.patches)), 'the panel shows the patch count');
  const obj = await page.evaluate(() => window.quadrille.exportLayout('obj'));
  assert(/^f /m.test(obj) && /^v /m.test(obj), 'the OBJ export has vertices and the patches as faces');
  assert(obj.split('\n').filter((l) => l.startsWith('f ')).length === shown.patches, 'one OBJ face per patch');
  assert(errors.length === 0, `console errors: ${errors.join(' | ')}`);
});

// Two meridians far apart, then the wheel's loop around the hole: the
// torus layout of two patches.
// `beforeThird` runs before the third strip is committed (its analysis is
// not awaited when it is given).
async function placeThreeTorusStrips(page, beforeThird = null) {
  const hits = await surfaceGrid(page);
  const byX = [...hits].sort((a, b) => a.p[0] - b.p[0]);
  await hoverAndCommit(page, byX[Math.floor(byX.length * 0.05)]);
  await hoverAndCommit(page, byX[Math.floor(byX.length * 0.95)]);
  const meridian = polylineLength((await designState(page)).loops[0]);
  const mid = byX[Math.floor(byX.length * 0.5)];
  await page.mouse.move(mid.x, mid.y);
  await page.waitForFunction(() => window.quadrille.design.proposal.length > 0, null, DESIGN_WAIT);
  let found = false;
  for (let k = 0; k < 8 && !found; k++) {
    await page.mouse.wheel(0, 120);
    await page.waitForFunction((k) => window.quadrille.design.state.browse[0] !== k, k, DESIGN_WAIT);
    found = polylineLength((await designState(page)).proposal) > 1.6 * meridian;
  }
  assert(found, 'the wheel offers a loop around the hole');
  if (beforeThird) await beforeThird();
  await page.keyboard.press('Enter');
  await page.waitForFunction(() => window.quadrille.design.state.loops.length === 3, null, DESIGN_WAIT);
  if (!beforeThird) await waitForAnalysis(page);
  return byX;
}

// OBJ text → { positions: [[x, y, z]], faces: [[i…]] } (0-based).
function parseObj(text) {
  const positions = [];
  const faces = [];
  for (const line of text.split('\n')) {
    const w = line.trim().split(/\s+/);
    if (w[0] === 'v') positions.push(w.slice(1, 4).map(Number));
    else if (w[0] === 'f') faces.push(w.slice(1).map((x) => parseInt(x, 10) - 1));
  }
  return { positions, faces };
}

function bbox(positions) {
  const min = [Infinity, Infinity, Infinity];
  const max = [-Infinity, -Infinity, -Infinity];
  for (const p of positions) for (let k = 0; k < 3; k++) { min[k] = Math.min(min[k], p[k]); max[k] = Math.max(max[k], p[k]); }
  return { min, max };
}

test('design mode: three strips on the torus grid into quads, fit, and export in the file\u2019s units', async (env) => {
  const { page, errors } = await open(env, 'sample=torus');
  await waitForRun(page, 'torus.obj');
  await enterDesign(page);
  await placeThreeTorusStrips(page);
  const a = await page.evaluate(() => window.quadrille.design.analysis);
  assert(a.sufficient, `a layout: ${a.status}`);
  await page.fill('#design-grid-count', '8');
  await page.click('#design-grid');
  await page.waitForFunction(() => window.quadrille.design.grid, null, DESIGN_WAIT);
  const g = await page.evaluate(() => { const g = window.quadrille.design.grid; return { vertices: g.vertices, faces: g.faces, folded: g.folded, ms: g.ms }; });
  assert(g.faces === 64 * a.counts.patches, `8 × 8 quads per patch: ${g.faces} for ${a.counts.patches} patches`);
  await page.mouse.move(0, 0);
  await settle(page);
  await page.screenshot({ path: join(artifacts, `design-torus-grid-${env.backend}.png`) });
  await page.click('#design-fit');
  await page.waitForFunction(() => window.quadrille.design.fit, null, DESIGN_WAIT);
  const fit = await page.evaluate(() => window.quadrille.design.fit.summary);
  console.log(`      [${env.backend}] torus grid 8: ${g.vertices} vertices, ${g.faces} quads, ${g.folded} folded, ${g.ms.toFixed(1)} ms; fit: ${fit.control_faces} control quads, limit Hausdorff ${fit.before.hausdorff.toPrecision(3)} → ${fit.after.hausdorff.toPrecision(3)}`);
  assert(Number.isFinite(fit.after.hausdorff) && fit.after.hausdorff > 0, `the fit reports a limit error: ${fit.after.hausdorff}`);
  assert((await page.textContent('#design-grid-status')).includes('limit error'), 'the panel shows the limit error');
  await page.mouse.move(0, 0);
  await settle(page);
  await page.screenshot({ path: join(artifacts, `design-torus-grid-fit-${env.backend}.png`) });
  // Leaving the mode and coming back shows the grid and the fit again.
  await page.keyboard.press('t');
  await page.waitForFunction(() => !window.quadrille.design.active, null, DESIGN_WAIT);
  await page.keyboard.press('t');
  await page.waitForFunction(() => window.quadrille.design.active, null, DESIGN_WAIT);
  const back = await page.evaluate(() => ({ grid: window.quadrille.design.segments['layout grid'], strips: window.quadrille.design.segments.strips,
    surface: window.quadrille.design.shownSurface, drawn: window.quadrille.drawnSurface() }));
  assert(back.grid > 0 && back.strips === 0, `back in the mode, the grid is drawn in the stripes' place: ${JSON.stringify(back)}`);
  assert(back.surface === 'Limit surface (design)' && back.drawn === 'layout regions', `back in the mode, the limit surface is shown: ${JSON.stringify(back)}`);
  // The gridded mesh: quads only, closed torus (V − E + F = 0), in the file's units.
  const obj = parseObj(await page.evaluate(() => window.quadrille.exportLayout('grid-obj')));
  assert(obj.faces.length === g.faces && obj.faces.every((f) => f.length === 4), 'the OBJ has quad faces only');
  const edges = new Set();
  for (const f of obj.faces) for (let k = 0; k < 4; k++) { const [x, y] = [f[k], f[(k + 1) % 4]]; edges.add(x < y ? `${x} ${y}` : `${y} ${x}`); }
  const [V, E, F] = [obj.positions.length, edges.size, obj.faces.length];
  assert(V - E + F === 0, `V − E + F = ${V} − ${E} + ${F} = 0`);
  const input = bbox(parseObj(readFileSync(join(root, 'www/samples/torus.obj'), 'utf8')).positions);
  const out = bbox(obj.positions);
  // The grid's vertices lie on the surface: its box is the input's to
  // within the grid's spacing (its longest edge), in the file's units.
  let longest = 0;
  for (const e of edges) { const [x, y] = e.split(' ').map(Number); longest = Math.max(longest, Math.hypot(...[0, 1, 2].map((k) => obj.positions[x][k] - obj.positions[y][k]))); }
  for (let k = 0; k < 3; k++) {
    for (const side of ['min', 'max']) {
      assert(Math.abs(out[side][k] - input[side][k]) <= longest, `bbox ${side}[${k}]: ${out[side][k]} vs the file's ${input[side][k]} (grid edge ${longest})`);
    }
  }
  // The layout OBJ: the patches as faces, in the same units.
  const layout = parseObj(await page.evaluate(() => window.quadrille.exportLayout('obj')));
  assert(layout.faces.length === a.counts.patches, `one face per patch: ${layout.faces.length}`);
  const lb = bbox(layout.positions);
  for (let k = 0; k < 3; k++) assert(lb.max[k] <= input.max[k] + 1e-6 && lb.min[k] >= input.min[k] - 1e-6, `the layout lies within the file's box on axis ${k}`);
  // Moving a layout vertex changes the layout: the grid and the fit go
  // (drawn and exported) until the layout is gridded again.
  const analyses = await page.evaluate(() => window.quadrille.design.analyses);
  const hitsNow = await surfaceGrid(page, 8);
  const v0 = await page.evaluate(() => [...window.quadrille.design.analysis.layoutVertices.slice(0, 3)]);
  const away = hitsNow.map((h) => ({ h, d: Math.hypot(h.p[0] - v0[0], h.p[1] - v0[1], h.p[2] - v0[2]) })).filter((e) => e.d > 0.01).sort((x, y) => x.d - y.d)[0].h;
  await page.evaluate((p) => window.quadrille.designAction('moveLayoutVertex', [0, p]), away.p);
  await page.waitForFunction((n) => window.quadrille.design.analyses > n, analyses, DESIGN_WAIT);
  const moved = await page.evaluate(() => ({ grid: window.quadrille.design.grid, fit: window.quadrille.design.fit, segments: window.quadrille.design.segments['layout grid'],
    surface: window.quadrille.design.shownSurface }));
  assert(moved.grid === null && moved.fit === null && moved.segments === 0 && moved.surface !== 'Limit surface (design)', `after a vertex move the grid is gone: ${JSON.stringify({ ...moved, grid: !!moved.grid, fit: !!moved.fit })}`);
  const refused = await page.evaluate(() => window.quadrille.exportLayout('grid-obj').then(() => null, (e) => e.message));
  assert(refused && refused.includes('grid the layout first'), `the stale grid is not exported: ${refused}`);
  assert(errors.length === 0, `console errors: ${errors.join(' | ')}`);
});

// The progressive hover (www/layout-worker.js): on the bunny's proxy most
// hovers are first drawn with a provisional loop; the loop drawn last for
// each hover must be the one a page answering every hover exactly at once
// (`?hoverFirst=all`) draws at the same screen point, and Enter pressed in
// the same task as the pointer move (so before the exact loop can arrive)
// commits that exact loop, also when the hover's first answer was not exact.
test('design mode: a progressive hover ends with the exact loop, and Enter while it is provisional commits the exact loop', async (env) => {
  const polyline = (page) => page.evaluate(() => [...window.quadrille.design.proposal]);
  const hoverAndRead = async (page, h) => {
    const n = await page.evaluate(() => window.quadrille.design.hoverLatencies.length);
    await page.mouse.move(h.x, h.y);
    await page.waitForFunction((n) => window.quadrille.design.hoverLatencies.length > n, n, DESIGN_WAIT);
    return polyline(page);
  };
  const same = (a, b) => a.length === b.length && a.every((x, i) => Math.abs(x - b[i]) <= 1e-6 * (1 + Math.abs(b[i])));
  // The reference: every hover answered exactly at once.
  const ref = await open(env, 'sample=stanford-bunny&hoverFirst=all');
  await waitForRun(ref.page, 'stanford-bunny.obj');
  await enterDesign(ref.page, 300000);
  const hits = await surfaceGrid(ref.page, 16);
  const points = Array.from({ length: 14 }, (_, i) => hits[Math.floor(((i * 0.618034) % 1) * (hits.length - 1))]);
  const expected = [];
  for (const h of points) expected.push(await hoverAndRead(ref.page, h));
  assert(await ref.page.evaluate(() => window.quadrille.design.hoverProvisional) === 0, 'the reference drew nothing provisionally');
  assert(ref.errors.length === 0, `console errors: ${ref.errors.join(' | ')}`);
  await ref.page.close();

  const { page, errors } = await open(env, 'sample=stanford-bunny');
  await waitForRun(page, 'stanford-bunny.obj');
  await enterDesign(page, 300000);
  for (let i = 0; i < 8; i++) {
    const got = await hoverAndRead(page, points[i]);
    assert(got.length > 0 && same(got, expected[i]), `hover ${i}: the loop drawn last is the exact one (${got.length / 3} against ${expected[i].length / 3} points)`);
  }
  const first = await page.evaluate(() => ({ provisional: window.quadrille.design.hoverProvisional, n: window.quadrille.design.hoverFirstLatencies.length }));
  assert(first.provisional > 0, `some hovers were first drawn provisionally: ${JSON.stringify(first)}`);
  // Enter in the same task as the move, at points not hovered on this page.
  let whileProvisional = 0;
  for (let i = 8; i < points.length; i++) {
    const before = await page.evaluate(() => ({ unfinished: window.quadrille.design.hoverUnfinished, loops: window.quadrille.design.state.loops.length }));
    await page.evaluate(({ x, y }) => {
      document.getElementById('canvas').dispatchEvent(new PointerEvent('pointermove', { clientX: x, clientY: y, pointerId: 1, bubbles: true }));
      document.body.dispatchEvent(new KeyboardEvent('keydown', { key: 'Enter', bubbles: true }));
    }, points[i]);
    await page.waitForFunction((b) => window.quadrille.design.state.loops.length > b, before.loops, DESIGN_WAIT);
    const s = await page.evaluate(() => ({ loop: [...window.quadrille.design.state.loops.at(-1).points], unfinished: window.quadrille.design.hoverUnfinished }));
    whileProvisional += s.unfinished > before.unfinished ? 1 : 0;
    assert(same(s.loop, expected[i]), `Enter at point ${i}: the committed loop is the exact one (${s.loop.length / 3} against ${expected[i].length / 3} points)`);
    await page.keyboard.press('Control+z');
    await page.waitForFunction((b) => window.quadrille.design.state.loops.length === b, before.loops, DESIGN_WAIT);
  }
  console.log(`      [${env.backend}] bunny: ${first.provisional} of 8 hovers first drawn provisionally; ${whileProvisional} of ${points.length - 8} Enter presses came while the hover's search was unfinished`);
  assert(whileProvisional > 0, 'no Enter came while a hover search was unfinished');
  assert(errors.length === 0, `console errors: ${errors.join(' | ')}`);
});

test('design mode: Grid waits for its analysis in the analysis worker; hover and clicks answer meanwhile', async (env) => {
  const { page, errors } = await open(env, 'sample=torus');
  await waitForRun(page, 'torus.obj');
  await enterDesign(page);
  // The third strip's analysis is held at its first step (a test hook), so
  // that a Grid pressed now needs an analysis that is not done.
  const byX = await placeThreeTorusStrips(page, async () => {
    await waitForAnalysis(page);
    await page.evaluate(() => window.quadrille.holdDesignAnalysis(true));
  });
  const committed = await page.evaluate(() => window.quadrille.design.state.revision);
  await page.waitForFunction((r) => window.quadrille.design.heldAnalysis === r, committed, DESIGN_WAIT);
  await page.evaluate(() => {
    window.gridded = null;
    window.quadrille.gridLayout([8, 8, 8]).then((g) => { window.gridded = { faces: g.faces, serial: g.serial }; }, (e) => { window.gridded = { error: e.message }; });
  });
  const hovers = await page.evaluate(() => window.quadrille.design.hoverLatencies.length);
  const h = byX[Math.floor(byX.length * 0.3)];
  await page.mouse.move(h.x, h.y);
  await page.waitForFunction((n) => window.quadrille.design.hoverLatencies.length > n, hovers, DESIGN_WAIT);
  const clicks = await page.evaluate(() => (window.quadrille.design.actionLatencies.addAnchor || []).length);
  await page.mouse.click(h.x, h.y);
  await page.waitForFunction((n) => (window.quadrille.design.actionLatencies.addAnchor || []).length > n, clicks, DESIGN_WAIT);
  const during = await page.evaluate(() => ({ gridded: window.gridded, anchors: window.quadrille.design.state.anchors.length / 3,
    ms: window.quadrille.design.actionLatencies.addAnchor.at(-1) }));
  console.log(`      [${env.backend}] torus: a click while Grid waited for the (held) analysis answered in ${during.ms.toFixed(1)} ms`);
  assert(during.gridded === null && during.anchors === 1, `hover and the click answered while Grid waited: ${JSON.stringify(during)}`);
  await page.evaluate(() => window.quadrille.holdDesignAnalysis(false));
  await page.waitForFunction(() => window.gridded, null, DESIGN_WAIT);
  const g = await page.evaluate(() => window.gridded);
  const a = await page.evaluate(() => window.quadrille.design.analysis);
  assert(a.revision === committed && a.sufficient, `the third strip's analysis: ${a.revision} (${a.status})`);
  assert(g.faces === 64 * a.counts.patches, `the grid of the three strips' layout, 8 × 8 quads per patch: ${JSON.stringify(g)} for ${a.counts.patches} patches`);
  assert(await page.evaluate(() => window.quadrille.design.segments['layout grid']) > 0, 'the grid is drawn');
  assert(errors.length === 0, `console errors: ${errors.join(' | ')}`);
});

test('design mode: grid counts stay with their strip when an earlier strip is deleted and restored', async (env) => {
  const { page, errors } = await open(env, 'sample=torus');
  await waitForRun(page, 'torus.obj');
  await enterDesign(page);
  await placeThreeTorusStrips(page);
  await page.fill('#design-grid-count', '8');
  const countOf = (i) => page.inputValue(`#design-strips li:nth-child(${i}) .design-strip-count`);
  await page.fill('#design-strips li:nth-child(2) .design-strip-count', '4');
  await page.dispatchEvent('#design-strips li:nth-child(2) .design-strip-count', 'change');
  const ids = await page.evaluate(() => window.quadrille.design.state.loops.map((l) => l.id));
  assert(new Set(ids).size === 3, `three strip ids: ${ids}`);
  // Deleting strip 1: the second strip (now the first) keeps its 4.
  await page.click('#design-strips li:nth-child(1) .design-delete');
  await page.waitForFunction(() => window.quadrille.design.state.loops.length === 2, null, DESIGN_WAIT);
  const afterDelete = [await countOf(1), await countOf(2)];
  assert(JSON.stringify(afterDelete) === '["4","8"]', `after deleting strip 1 the counts follow their strips: ${afterDelete}`);
  // Undo: all three back, the 4 on the second again; the grid uses it.
  await page.keyboard.press('Control+z');
  await page.waitForFunction(() => window.quadrille.design.state.loops.length === 3, null, DESIGN_WAIT);
  await waitForAnalysis(page);
  const afterUndo = [await countOf(1), await countOf(2), await countOf(3)];
  assert(JSON.stringify(afterUndo) === '["8","4","8"]', `after the undo: ${afterUndo}`);
  const a = await page.evaluate(() => window.quadrille.design.analysis.counts);
  const g = await page.evaluate(async () => { const g = await window.quadrille.gridLayout(); return { faces: g.faces }; });
  // Two patches, one per crossing of a meridian strip with the strip
  // around the hole: 8 × 8 and 4 × 8 quads.
  assert(a.patches === 2 && g.faces === 64 + 32, `the grid with counts 8, 4, 8: ${g.faces} quads for ${a.patches} patches`);
  assert(errors.length === 0, `console errors: ${errors.join(' | ')}`);
});

test('design mode: a newer action cancels a stale analysis; its result is never shown; the last analysis is the latest state\u2019s', async (env) => {
  const { page, errors } = await open(env, 'sample=torus');
  await waitForRun(page, 'torus.obj');
  await enterDesign(page);
  const hits = await surfaceGrid(page);
  const byX = [...hits].sort((a, b) => a.p[0] - b.p[0]);
  await hoverAndCommit(page, byX[Math.floor(byX.length * 0.05)]);
  await waitForAnalysis(page);
  // The analyses wait at their first step while held (a test hook), so
  // that the commit's analysis is surely running when the undo comes.
  await page.evaluate(() => window.quadrille.holdDesignAnalysis(true));
  await hoverAndCommit(page, byX[Math.floor(byX.length * 0.5)]);
  const committed = await page.evaluate(() => window.quadrille.design.state.revision);
  await page.waitForFunction((r) => window.quadrille.design.heldAnalysis === r, committed, DESIGN_WAIT);
  await page.keyboard.press('Control+z');
  await page.waitForFunction(() => window.quadrille.design.state.loops.length === 1, null, DESIGN_WAIT);
  // A click meanwhile answers (it does not wait for the analysis).
  const clicks = await page.evaluate(() => (window.quadrille.design.actionLatencies.addAnchor || []).length);
  const p = byX[Math.floor(byX.length * 0.3)];
  await page.mouse.click(p.x, p.y);
  await page.waitForFunction((n) => (window.quadrille.design.actionLatencies.addAnchor || []).length > n, clicks, DESIGN_WAIT);
  const during = await page.evaluate(() => ({ anchors: window.quadrille.design.state.anchors.length / 3, drawn: [...window.quadrille.design.analysisRevisions] }));
  assert(during.anchors === 1 && !during.drawn.includes(committed), `the click answered while the analysis ran: ${JSON.stringify(during)}`);
  await page.evaluate(() => window.quadrille.holdDesignAnalysis(false));
  await waitForAnalysis(page);
  const d = await page.evaluate(() => { const d = window.quadrille.design; return { cancelled: d.cancelledAnalyses, drawn: d.analysisRevisions,
    revision: d.state.revision, loops: d.state.loops.length, analysis: { revision: d.analysis.revision, strips: d.analysis.counts.strips } }; });
  console.log(`      [${env.backend}] torus: analyses given up ${JSON.stringify(d.cancelled)}; drawn revisions ${d.drawn}`);
  assert(d.cancelled.some((c) => c.revision === committed && c.started), `the running analysis of the undone commit (revision ${committed}) was stopped: ${JSON.stringify(d.cancelled)}`);
  for (const c of d.cancelled) assert(!d.drawn.includes(c.revision), `the stale analysis of revision ${c.revision} was never drawn: ${d.drawn}`);
  assert(d.analysis.revision === d.revision && d.analysis.strips === d.loops && d.loops === 1, `the last analysis is the latest state's: ${JSON.stringify(d)}`);
  assert(errors.length === 0, `console errors: ${errors.join(' | ')}`);
});

test('design mode: a click while the analysis runs answers without it; an Enter during an action commits that action\u2019s loop', async (env) => {
  const { page, errors } = await open(env, 'sample=torus');
  await waitForRun(page, 'torus.obj');
  await enterDesign(page);
  const hits = await surfaceGrid(page);
  const byX = [...hits].sort((a, b) => a.p[0] - b.p[0]);
  // The commit's analysis then runs in its worker. It is held at its first
  // step (a test hook) so that it surely runs when the click comes; racing
  // it (up to four commits) lost every race on a loaded machine. The
  // mode's first analysis ends first: a held earlier analysis would block
  // the worker before the commit's could start.
  await waitForAnalysis(page);
  await page.evaluate(() => window.quadrille.holdDesignAnalysis(true));
  const analyses = await page.evaluate(() => window.quadrille.design.analyses);
  await hoverAndCommit(page, byX[Math.floor(byX.length * 0.05)]);
  const committed = await page.evaluate(() => window.quadrille.design.state.revision);
  await page.waitForFunction((r) => window.quadrille.design.heldAnalysis === r, committed, DESIGN_WAIT);
  const p = byX[Math.floor(byX.length * 0.6)];
  const clicks = await page.evaluate(() => (window.quadrille.design.actionLatencies.addAnchor || []).length);
  await page.mouse.click(p.x, p.y);
  await page.waitForFunction((n) => (window.quadrille.design.actionLatencies.addAnchor || []).length > n, clicks, DESIGN_WAIT);
  const click = await page.evaluate((n) => ({ ms: window.quadrille.design.actionLatencies.addAnchor.at(-1), stillRunning: window.quadrille.design.analyses === n,
    anchors: window.quadrille.design.state.anchors.length / 3 }), analyses);
  await page.evaluate(() => window.quadrille.holdDesignAnalysis(false));
  await page.waitForFunction((n) => window.quadrille.design.analyses > n, analyses, DESIGN_WAIT);
  const analysisMs = await page.evaluate(() => window.quadrille.design.analysisMs);
  console.log(`      [${env.backend}] torus: click during the (held) analysis answered (drawn) in ${click.ms.toFixed(1)} ms; the analysis took ${analysisMs.toFixed(0)} ms once let go`);
  assert(click.stillRunning, 'the click was answered while the analysis ran');
  assert(click.anchors === 1, `the click placed an anchor: ${click.anchors}`);
  // A second click and Enter at once: the Enter waits for the click's
  // answer, then commits the loop through both anchors.
  const q = byX[Math.floor(byX.length * 0.8)];
  const before = await page.evaluate(() => ({ loops: window.quadrille.design.state.loops.length, queued: window.quadrille.design.queuedEnters,
    dropped: window.quadrille.design.droppedEnters, commits: (window.quadrille.design.actionLatencies.commit || []).length }));
  await page.mouse.click(q.x, q.y);
  await page.keyboard.press('Enter');
  await page.waitForFunction((b) => window.quadrille.design.state.loops.length > b, before.loops, DESIGN_WAIT);
  await page.waitForFunction((n) => (window.quadrille.design.actionLatencies.commit || []).length > n, before.commits, DESIGN_WAIT);
  const after = await page.evaluate(() => { const d = window.quadrille.design; return { loops: d.state.loops.map((l) => [...l.points]), anchors: d.state.anchors.length,
    queued: d.queuedEnters, dropped: d.droppedEnters, shown: d.queuedEnterProposal ? [...d.queuedEnterProposal] : null, ms: d.actionLatencies.commit.at(-1) }; });
  console.log(`      [${env.backend}] torus: Enter pressed during the second click's answer committed ${after.ms.toFixed(0)} ms after the press`);
  assert(after.queued === before.queued + 1 && after.dropped === before.dropped, `the Enter was queued, not dropped: ${JSON.stringify({ before, queued: after.queued, dropped: after.dropped })}`);
  assert(after.loops.length === before.loops + 1 && after.anchors === 0, `one strip committed: ${after.loops.length}`);
  assert(after.shown && after.shown.length >= 9 && JSON.stringify(after.loops.at(-1)) === JSON.stringify(after.shown),
    'the committed strip is the loop through both anchors, drawn before the commit');
  assert(errors.length === 0, `console errors: ${errors.join(' | ')}`);
});

test('design mode: with the mirror plane detected, a committed strip gets its mirror image', async (env) => {
  const { page, errors } = await open(env, 'sample=torus');
  await waitForRun(page, 'torus.obj');
  await enterDesign(page);
  await page.selectOption('#design-mirror', 'auto');
  await page.waitForFunction(() => window.quadrille.design.actionMs.setMirror, null, DESIGN_WAIT);
  const hits = await surfaceGrid(page);
  // Off every axis plane: a point whose mirror images are elsewhere.
  const off = hits.filter((h) => Math.abs(h.p[0]) > 0.15 && Math.abs(h.p[1]) > 0.15);
  assert(off.length > 0, 'a point away from the symmetry planes');
  await hoverAndCommit(page, off[0]);
  const s = await page.evaluate(() => window.quadrille.design.state.loops.map((l) => ({ mirrored: l.mirrored, n: l.points.length })));
  assert(s.length === 2 && !s[0].mirrored && s[1].mirrored, `the strip and its mirror image: ${JSON.stringify(s)}`);
  assert((await page.textContent('#design-strips')).includes('mirror image'), 'the list names the mirror image');
  // Deleting the copy deletes the pair; undo brings both back.
  await page.click('#design-strips li:nth-child(2) button');
  await page.waitForFunction(() => window.quadrille.design.state.loops.length === 0, null, DESIGN_WAIT);
  await page.keyboard.press('Control+z');
  await page.waitForFunction(() => window.quadrille.design.state.loops.length === 2, null, DESIGN_WAIT);
  assert(errors.length === 0, `console errors: ${errors.join(' | ')}`);
});

test('design mode: the page survives a crashed layout worker and the mode restarts', async (env) => {
  const { page } = await open(env, 'sample=torus');
  await waitForRun(page, 'torus.obj');
  await enterDesign(page);
  await page.evaluate(() => window.quadrille.crashLayoutWorker());
  await page.waitForFunction(() => !document.getElementById('design-crash').hidden, null, DESIGN_WAIT);
  assert((await page.textContent('#design-crash')).includes('crashed'), 'the page says the worker crashed');
  await page.click('#design-restart');
  await page.waitForFunction(() => window.quadrille.design.ready && !window.quadrille.design.crashed, null, { timeout: 60000 });
  const hits = await surfaceGrid(page, 48);
  await hoverLatency(page, hits.slice(0, 3));
  assert(await page.evaluate(() => window.quadrille.design.proposal.length) > 0, 'hovering works after the restart');
  // The rest of the page still works.
  await page.keyboard.press('t');
  await page.click('#sample-buttons >> text=spot');
  await waitForRun(page, 'spot.obj');
});

test('design mode on real meshes: hover latency and a designed layout', async (env) => {
  for (const [sample, commits] of [['rocker-arm', 3], ['stanford-bunny', 3]]) {
    const { page, errors } = await open(env, `sample=${sample}`);
    await waitForRun(page, `${sample}.obj`);
    const started = Date.now();
    await enterDesign(page, 300000);
    const d = await page.evaluate(() => ({ faces: window.quadrille.design.faces, inputFaces: window.quadrille.design.inputFaces, proxy: window.quadrille.design.proxy, buildMs: window.quadrille.design.buildMs,
      wasmMs: window.quadrille.design.wasmMs, readyAfterMs: window.quadrille.design.readyAfterMs }));
    const hits = await surfaceGrid(page);
    const path = hits.filter((_, i) => i % Math.max(1, Math.floor(hits.length / 25)) === 0).slice(0, 25);
    const latency = await hoverLatency(page, path);
    console.log(`      [${env.backend}] ${sample} (${d.inputFaces} faces${d.proxy ? `, proxy ${d.faces}` : ''}): engine built in ${d.buildMs.toFixed(0)} ms (worker's wasm ready in ${d.wasmMs.toFixed(0)} ms, mode ready ${d.readyAfterMs.toFixed(0)} ms after T); hover-to-draw median ${latency.median.toFixed(1)} ms (max ${latency.max.toFixed(1)}), loop query in the worker ${latency.workerMedian.toFixed(1)} ms`);
    if (d.proxy) assert((await page.textContent('#design-note')).includes('proxy'), 'the panel says the design runs on a proxy');
    if (commits) {
      const byY = [...hits].sort((a, b) => a.y - b.y);
      for (let k = 0; k < commits; k++) await hoverAndCommit(page, byY[Math.floor(byY.length * (k + 0.5) / commits)]);
      await waitForAnalysis(page);
      const a = await page.evaluate(() => window.quadrille.design.analysis);
      const commitMs = await page.evaluate(() => window.quadrille.design.actionMs.commit.map((x) => Math.round(x)));
      console.log(`      [${env.backend}] ${sample}, ${commits} strips: ${JSON.stringify(a.counts)} · ${a.status} · timings ${JSON.stringify(a.timings)} · commit ${commitMs} ms · analysis ${Math.round(await page.evaluate(() => window.quadrille.design.analysisMs))} ms`);
      await page.mouse.move(0, 0);
      await settle(page);
      await page.screenshot({ path: join(artifacts, `design-${sample}-${env.backend}.png`) });
    }
    assert(errors.length === 0, `console errors: ${errors.join(' | ')}`);
    await page.close();
  }
});

// ---------------------------------------------------------------- page as a teaching tool (issue 22)

test('a loading indicator shows until the module and the first sample are ready', async (env) => {
  const page = await env.context.newPage();
  // Hold the wasm module back: until it arrives the indicator must be up.
  let release;
  const held = new Promise((r) => { release = r; });
  await page.route('**/quadrille_bg.wasm', async (route) => { await held; await route.continue(); });
  await page.goto(env.url + (env.query ? `?${env.query}` : ''));
  await page.waitForSelector('#loading');
  assert(!(await page.isHidden('#loading')), 'the loading indicator is shown while the module loads');
  assert((await page.textContent('#loading')).includes('Loading'), 'it says what is loading');
  release();
  await waitForRun(page, 'stanford-bunny.obj');
  assert(await page.isHidden('#loading'), 'the indicator is gone once the sample is shown');
  await page.close();
});

test('the status line ends with the result summary; stage times are in their own details', async (env) => {
  const { page, errors } = await open(env, 'sample=fandisk');
  await waitForRun(page, 'fandisk.obj');
  const run = await page.evaluate(() => window.quadrille.lastRun);
  const status = (await page.textContent('#status')).trim();
  const share = (100 * run.metrics.quads.quads / run.metrics.topology.faces).toFixed(1);
  const expected = `${run.counts.quad_mesh_vertices.toLocaleString('en-US')} vertices · ${share} % quads · `
    + `${run.counts.orientation_singularities} singularities · limit error ${Number((100 * run.limit_surface.after.hausdorff).toPrecision(2))} % of the size`;
  assert(status.endsWith(expected), `status "${status}" ends with "${expected}"`);
  assert(!/\d ms/.test(status), `no stage milliseconds in the status: ${status}`);
  assert((await page.textContent('#timings')).includes('orientation'), 'the stage times are listed apart');
  assert(errors.length === 0, `console errors: ${errors.join(' | ')}`);
});

test('a part the output loses is said in the status line, not dropped silently', async (env) => {
  // A 20 × 20 plane and, apart from it, one triangle far smaller than an
  // output edge: no quad can hold it, so the run must say it was lost.
  const n = 20;
  let obj = '';
  for (let j = 0; j <= n; j++) for (let i = 0; i <= n; i++) obj += `v ${i / n} ${j / n} 0\n`;
  for (let j = 0; j < n; j++) for (let i = 0; i < n; i++) {
    const a = j * (n + 1) + i + 1, b = a + 1, c = a + n + 2, d = a + n + 1;
    obj += `f ${a} ${b} ${c}\nf ${a} ${c} ${d}\n`;
  }
  const m = (n + 1) * (n + 1);
  obj += `v 0.5 0.5 0.5\nv 0.51 0.5 0.5\nv 0.5 0.51 0.5\nf ${m + 1} ${m + 2} ${m + 3}\n`;
  const { page, errors } = await open(env);
  await waitForRun(page, 'stanford-bunny.obj');
  const bunny = (await page.textContent('#status')).trim();
  assert(!/lost|closed over/.test(bunny), `the bunny keeps its holes and its part: ${bunny}`);
  await dropFile(page, '#view', 'plane-and-speck.obj', Buffer.from(obj));
  await waitForRun(page, 'plane-and-speck.obj');
  const run = await page.evaluate(() => window.quadrille.lastRun);
  assert(run.metrics.preservation.input_components === 2, `two input parts: ${JSON.stringify(run.metrics.preservation)}`);
  assert(run.metrics.preservation.components_lost.length === 1, `the speck is lost: ${JSON.stringify(run.metrics.preservation)}`);
  const status = (await page.textContent('#status')).trim();
  assert(/1 input part lost/.test(status), `the status says so: ${status}`);
  assert(errors.length === 0, `console errors: ${errors.join(' | ')}`);
});

test('a one-triangle file says that no quads came out', async (env) => {
  const { page } = await open(env);
  await waitForRun(page, 'stanford-bunny.obj');
  await dropFile(page, '#view', 'one-triangle.obj', Buffer.from('v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n'));
  await page.waitForFunction(() => /one-triangle/.test(document.getElementById('status').textContent) && document.getElementById('progress').hidden, null, { timeout: 30000 });
  const status = await page.textContent('#status');
  assert(/no quads came out of one-triangle\.obj/i.test(status), `the status says no quads came out: ${status}`);
  await page.screenshot({ path: join(artifacts, `no-quads-${env.backend}.png`) });
});

test('the target vertex count is the first control: slider and number, invalid values explained next to it', async (env) => {
  const { page } = await open(env, 'sample=spot');
  await waitForRun(page, 'spot.obj');
  const target = await page.locator('#target-panel').boundingBox();
  const layers = await page.locator('#layers-panel').boundingBox();
  assert(target.y < layers.y, 'the target control is above the layers');
  // Too many for spot (2,930 vertices): explained next to the field, kept, not run.
  await page.fill('#target-count', '5000');
  await page.dispatchEvent('#target-count', 'change');
  const error = await page.textContent('#target-error');
  assert(!(await page.isHidden('#target-error')) && error.includes('976'), `the error names the limit: ${error}`);
  assert(await page.inputValue('#target-count') === '5000', 'the invalid value is not reverted');
  const field = await page.locator('#target-count').boundingBox();
  const message = await page.locator('#target-error').boundingBox();
  assert(Math.abs(message.y - (field.y + field.height)) < 40, 'the message sits right under the field');
  assert(await page.evaluate(() => window.quadrille.params().sizing.target_vertex_count) === null, 'the invalid value is not used');
  // A valid value runs; the parameter panel follows.
  await page.fill('#target-count', '500');
  await page.dispatchEvent('#target-count', 'change');
  await page.waitForFunction(() => window.quadrille.lastRun.parameters.sizing.target_vertex_count === 500, null, { timeout: 60000 });
  assert(await page.isHidden('#target-error'), 'the error is gone');
  assert(await page.inputValue('#param-sizing\\.target_vertex_count') === '500', 'the parameter panel shows the value');
  const slider = Number(await page.inputValue('#target-slider'));
  assert(slider > 0 && slider < 1000, `the slider follows: ${slider}`);
  // The parameter search opens the groups with matches and hides the rest.
  await page.fill('#param-search', 'seed');
  const rows = await page.$$eval('#params .param', (rs) => rs.filter((r) => r.offsetParent !== null).map((r) => r.textContent.toLowerCase()));
  const total = await page.$$eval('#params .param', (rs) => rs.length);
  assert(rows.some((t) => t.includes('field.seed') || t.startsWith('seed')) && rows.length < total, `search shows ${rows.length} of ${total}`);
  assert(rows.every((t) => t.includes('seed')), 'only matching rows are shown');
  await page.screenshot({ path: join(artifacts, `target-${env.backend}.png`) });
});

// The pixels of a PNG inside a rectangle (PNG pixels) near an sRGB colour.
function countNear(png, [x0, y0, w, h], [r, g, b], tolerance = 24) {
  const { data, width } = PNG.sync.read(png);
  let n = 0;
  for (let y = Math.max(0, Math.floor(y0)); y < y0 + h; y++) {
    for (let x = Math.max(0, Math.floor(x0)); x < x0 + w; x++) {
      const i = 4 * (y * width + x);
      if (Math.abs(data[i] - r) + Math.abs(data[i + 1] - g) + Math.abs(data[i + 2] - b) <= tolerance) n++;
    }
  }
  return n;
}

test('legends name the singularity valences; colour-by and the pick readout say what is shown; the PNG has the legends', async (env) => {
  const { page, errors } = await open(env, 'sample=fandisk');
  await waitForRun(page, 'fandisk.obj');
  const legend = await page.textContent('#layer-legend');
  assert(!(await page.isHidden('#layer-legend')), 'the layer legend is shown');
  assert(legend.includes('valence 3') && legend.includes('valence 5') && legend.includes('+¼') && legend.includes('−¼'), `legend: ${legend}`);
  // Position singularities: explained when shown, gone when hidden.
  await page.keyboard.press('k');
  await settle(page);
  assert((await page.textContent('#layer-legend')).includes('Position singularities'), 'position singularities are explained');
  await page.keyboard.press('k');
  await settle(page);
  assert(!(await page.textContent('#layer-legend')).includes('Position singularities'), 'the legend follows the layers');
  // The quad mesh's faces are shown: "Colour by" says face degree, and so does a pick.
  const selected = await page.$eval('#scalar-select', (s) => s.options[s.selectedIndex].textContent);
  assert(selected.includes('face degree'), `Colour by shows ${selected}`);
  const box = await page.locator('#canvas').boundingBox();
  await page.mouse.click(box.x + box.width / 2, box.y + box.height / 2);
  await page.waitForFunction(() => window.quadrille.lastPick, null, { timeout: 10000 });
  const info = await page.textContent('#pick-info');
  assert(/face degree \d \((triangle|quad|pentagon|\d sides)\)/.test(info) && !info.includes('triangle 0 ·'), `pick readout: ${info}`);
  await page.keyboard.press('a');
  await settle(page);
  assert((await page.$eval('#scalar-select', (s) => s.value)) === 'curvature', 'Colour by follows back to the input');
  // The PNG carries the legend: its swatch colours at the legend's place.
  await page.keyboard.press('a');
  await settle(page);
  const png = Buffer.from(await page.evaluate(async () => [...await window.quadrille.screenshot()]));
  const rect = await page.evaluate(() => {
    const c = document.getElementById('canvas').getBoundingClientRect();
    const r = document.getElementById('layer-legend').getBoundingClientRect();
    const k = document.getElementById('canvas').width / c.width;
    return [(r.left - c.left) * k, (r.top - c.top) * k, r.width * k, r.height * k];
  });
  const blue = countNear(png, rect, [0x1f, 0x6f, 0xdd], 12);
  const red = countNear(png, rect, [0xd8, 0x34, 0x2c], 12);
  const white = countNear(png, rect, [255, 255, 255], 6);
  assert(blue > 10 && red > 10 && white > 0.3 * rect[2] * rect[3], `legend in the PNG: blue ${blue}, red ${red}, white ${white}`);
  writeFileSync(join(artifacts, `snapshot-legend-${env.backend}.png`), png);
  assert(errors.length === 0, `console errors: ${errors.join(' | ')}`);
});

test('markers stay visible over the quad faces', async (env) => {
  const { page } = await open(env, 'sample=stanford-bunny');
  await waitForRun(page, 'stanford-bunny.obj');
  const markerPixels = async (file) => {
    const box = await page.locator('#canvas').boundingBox();
    const png = await page.screenshot({ path: join(artifacts, file), clip: box });
    const { width, height } = PNG.sync.read(png);
    return countNear(png, [0, 0, width, height], [0x1f, 0x6f, 0xdd], 40) + countNear(png, [0, 0, width, height], [0xd8, 0x34, 0x2c], 40);
  };
  for (const id of ['#layer-quad-mesh', '#layer-non-quad-faces']) await page.uncheck(id);
  await settle(page);
  const onFaces = await markerPixels(`markers-faces-${env.backend}.png`);
  await page.keyboard.press('a');
  await settle(page);
  await page.uncheck('#layer-scalar');
  await settle(page);
  const onInput = await markerPixels(`markers-input-${env.backend}.png`);
  assert(onInput > 50 && onFaces > 0.8 * onInput, `marker pixels over the quad faces ${onFaces} vs over the input ${onInput}`);
});

test('the wheel zooms toward the cursor point', async (env) => {
  const { page } = await open(env, 'sample=spot');
  await waitForRun(page, 'spot.obj');
  const box = await page.locator('#canvas').boundingBox();
  // A surface point away from the centre.
  const hits = await surfaceGrid(page, 16);
  const cx = box.x + box.width / 2;
  const cy = box.y + box.height / 2;
  const far = hits.sort((a, b) => Math.hypot(b.x - cx, b.y - cy) - Math.hypot(a.x - cx, a.y - cy))
    .find((h) => Math.hypot(h.x - cx, h.y - cy) > 120);
  assert(far, 'a surface point away from the centre');
  const before = await page.evaluate(() => window.quadrille.camera());
  await page.mouse.move(far.x, far.y);
  for (let i = 0; i < 4; i++) await page.mouse.wheel(0, -120);
  await settle(page);
  const after = await page.evaluate(() => window.quadrille.camera());
  assert(after[2] < 0.7 * before[2], `the camera moved closer: ${before[2]} → ${after[2]}`);
  const under = await page.evaluate(({ x, y }) => window.quadrille.surfacePoint(x, y), far);
  const moved = Math.hypot(...[0, 1, 2].map((k) => under[k] - far.p[k]));
  assert(moved < 0.01, `the point under the cursor stays: moved ${moved}`);
  // The target moved toward that point (a zoom to the centre keeps it).
  const toPoint = (cam) => Math.hypot(...[0, 1, 2].map((k) => cam[3 + k] - far.p[k]));
  assert(toPoint(after) < 0.8 * toPoint(before), `the target approached the point: ${toPoint(before)} → ${toPoint(after)}`);
});

test('the share link restores the camera; view presets and flat shading change the picture', async (env) => {
  const { page } = await open(env, 'sample=spot');
  await waitForRun(page, 'spot.obj');
  const box = await page.locator('#canvas').boundingBox();
  await page.mouse.move(box.x + box.width / 2, box.y + box.height / 2);
  await page.mouse.down();
  await page.mouse.move(box.x + box.width / 2 + 150, box.y + box.height / 2 + 60, { steps: 5 });
  await page.mouse.up();
  await page.mouse.wheel(0, -240);
  await settle(page);
  const camera = await page.evaluate(() => window.quadrille.camera());
  const picture = await page.screenshot({ clip: box });
  await page.click('#share');
  const url = await page.inputValue('#share-url');
  assert(url.includes('cam='), `the link has the camera: ${url}`);
  const fresh = await env.context.newPage();
  await fresh.goto(url);
  await waitForRun(fresh, 'spot.obj');
  const restored = await fresh.evaluate(() => window.quadrille.camera());
  assert(restored.every((x, i) => Math.abs(x - camera[i]) < 1e-3), `camera ${restored} vs ${camera}`);
  const again = await fresh.screenshot({ clip: await fresh.locator('#canvas').boundingBox() });
  const a = PNG.sync.read(picture);
  const b = PNG.sync.read(again);
  let diff = 0;
  for (let i = 0; i < a.data.length; i += 4) if (Math.abs(a.data[i] - b.data[i]) + Math.abs(a.data[i + 1] - b.data[i + 1]) > 40) diff++;
  assert(diff / (a.width * a.height) < 0.02, `the restored view looks the same: ${(100 * diff / (a.width * a.height)).toFixed(2)} % differ`);
  // Presets: top looks down the y axis.
  await fresh.click('#view-top');
  const top = await fresh.evaluate(() => window.quadrille.camera());
  assert(top[1] > 1.5, `top view pitch ${top[1]}`);
  await fresh.click('#view-front');
  const front = await fresh.evaluate(() => window.quadrille.camera());
  assert(Math.abs(front[0]) < 1e-6 && Math.abs(front[1]) < 1e-6, `front view ${front}`);
  const smooth = await canvasInk(fresh, `spot-smooth-${env.backend}.png`);
  await fresh.check('#flat-shading');
  await settle(fresh);
  const flatPng = await fresh.screenshot({ path: join(artifacts, `spot-flat-${env.backend}.png`), clip: await fresh.locator('#canvas').boundingBox() });
  const smoothPng = PNG.sync.read(await fresh.screenshot({ clip: await fresh.locator('#canvas').boundingBox() }));
  assert(smooth > 0.03 && PNG.sync.read(flatPng).data.length === smoothPng.data.length, 'both shadings draw');
});

test('phone: the panel opens as a drawer over the view; a layer toggle shows its effect', async (env) => {
  const page = await env.context.newPage();
  await page.setViewportSize({ width: 390, height: 844 });
  await page.goto(env.url + '?sample=fandisk' + (env.query ? `&${env.query}` : ''));
  await waitForRun(page, 'fandisk.obj');
  await page.click('#panel-toggle');
  await page.waitForFunction(() => document.getElementById('panel').getBoundingClientRect().bottom <= window.innerHeight + 1
    && getComputedStyle(document.getElementById('panel')).transform === 'none');
  const panel = await page.locator('#panel').boundingBox();
  const layers = await page.locator('#layers-panel').boundingBox();
  const canvas = await page.locator('#canvas').boundingBox();
  assert(layers.y >= panel.y && layers.y < 844, `the layers are in the open panel: ${layers.y} (panel ${panel.y})`);
  const visible = panel.y - canvas.y;
  assert(visible > 0.4 * 844, `the view stays visible above the panel: ${visible} px`);
  const clip = { x: canvas.x, y: canvas.y, width: canvas.width, height: visible };
  const before = PNG.sync.read(await page.screenshot({ clip }));
  await page.click('#layer-surface');
  await settle(page);
  const after = PNG.sync.read(await page.screenshot({ path: join(artifacts, `phone-drawer-${env.backend}.png`) , clip }));
  let diff = 0;
  for (let i = 0; i < before.data.length; i += 4) if (Math.abs(before.data[i] - after.data[i]) > 30) diff++;
  assert(diff / (before.width * before.height) > 0.02, `the toggle changes the visible view: ${diff} pixels`);
  await page.screenshot({ path: join(artifacts, `phone-open-${env.backend}.png`) });
  await page.close();
});

// Brightness jumps along the middle rows of the drawn mesh: a run of
// pixels between two jumps of more than 18 % is one checker square or
// isoline. Returns the largest number of jumps on one of five rows.
function checkerJumps(png) {
  const { data, width, height } = PNG.sync.read(png);
  const lum = (x, y) => { const i = 4 * (y * width + x); return 0.3 * data[i] + 0.59 * data[i + 1] + 0.11 * data[i + 2]; };
  const ink = (x, y) => { const i = 4 * (y * width + x); return Math.abs(data[i] - BACKGROUND[0]) + Math.abs(data[i + 1] - BACKGROUND[1]) + Math.abs(data[i + 2] - BACKGROUND[2]) > 30; };
  let top = height, bottom = 0;
  for (let y = 0; y < height; y++) for (let x = 0; x < width; x += 4) if (ink(x, y)) { top = Math.min(top, y); bottom = Math.max(bottom, y); }
  let best = 0;
  for (const f of [0.35, 0.42, 0.5, 0.58, 0.65]) {
    const y = Math.round(top + f * (bottom - top));
    let jumps = 0;
    let last = -10;
    for (let x = 2; x < width - 2; x++) {
      if (!ink(x - 2, y) || !ink(x + 2, y)) continue;
      const a = lum(x - 2, y), b = lum(x + 2, y);
      if (Math.abs(a - b) > 0.18 * Math.max(a, b) && x - last > 3) { jumps++; last = x; }
    }
    best = Math.max(best, jumps);
  }
  return best;
}

test('the parametrization layer draws the integer-grid map as a checkerboard, with cones and a legend', async (env) => {
  const { page, errors } = await open(env);
  await waitForRun(page, 'stanford-bunny.obj');
  // Only the surface: the line and marker layers would add edges of their own.
  const only = async () => {
    for (const box of await page.locator('#layers input[type=checkbox]').all()) {
      const id = await box.getAttribute('id');
      if (!['layer-surface', 'layer-parametrization'].includes(id) && await box.isChecked() && await box.isEnabled()) await box.uncheck();
    }
    await settle(page);
  };
  await only();
  const clip = await page.locator('#canvas').boundingBox();
  const plain = await page.screenshot({ path: join(process.env.SHOTS || artifacts, `plain-${env.backend}.png`), clip });
  const plainJumps = checkerJumps(plain);
  assert(await page.isEnabled('#layer-parametrization'), 'the layer is offered before it is computed');
  assert(await page.evaluate(() => window.quadrille.lastParam == null), 'nothing is computed before the layer is asked for');
  await page.check('#layer-parametrization');
  await page.waitForFunction(() => window.quadrille.lastParam && /parametrization ·/.test(document.getElementById('status').textContent), null, { timeout: 400000 });
  await only();
  const p = await page.evaluate(() => window.quadrille.lastParam);
  const shot = await page.screenshot({ path: join(process.env.SHOTS || artifacts, `param-${env.backend}.png`), clip });
  const jumps = checkerJumps(shot);
  console.log(`      [${env.backend}] parametrization ${p.ms.toFixed(0)} ms in the page (${JSON.stringify(p.timings)}), ${p.measures.cones} cones, ${p.measures.flipped_triangles} flipped; jumps along a row: ${plainJumps} plain, ${jumps} with the map`);
  assert(jumps >= 8 && jumps > 3 * Math.max(plainJumps, 1), `checkerboard: ${jumps} brightness jumps along a row (plain surface ${plainJumps})`);
  const triangles = await page.evaluate(() => window.quadrille.lastRun.counts.triangles);
  assert(p.measures.cones > 0 && p.measures.faces === triangles, `cones ${p.measures.cones}, faces ${p.measures.faces} of ${triangles}`);
  const legend = await page.textContent('#layer-legend');
  assert(legend.includes('one square = one target edge') && legend.includes('flipped triangles'), `legend: ${legend}`);
  // The cones as markers, coloured by index, with their legend line.
  await page.check('#layer-parametrization-cones');
  await settle(page);
  const withCones = (await page.textContent('#layer-legend'));
  assert(withCones.includes('Cones of the map') && withCones.includes('+¼') && withCones.includes('−¼'), `legend: ${withCones}`);
  await page.screenshot({ path: join(process.env.SHOTS || artifacts, `param-cones-${env.backend}.png`), clip });
  // Switching it off brings the input surface back, plain.
  await page.uncheck('#layer-parametrization');
  await settle(page);
  assert(!(await page.textContent('#layer-legend')).includes('one square'), 'the legend follows the layer');
  assert(errors.length === 0, `console errors: ${errors.join(' | ')}`);
});

test('the parametrization layer follows the alignment mode and is kept across changes it does not depend on', async (env) => {
  const { page, errors } = await open(env, 'sample=fandisk');
  await waitForRun(page, 'fandisk.obj');
  await page.check('#layer-parametrization');
  await page.waitForFunction(() => window.quadrille.lastParam, null, { timeout: 120000 });
  const first = await page.evaluate(() => ({ p: window.quadrille.lastParam, jobs: window.quadrille.paramJobs }));
  assert(first.p.alignment === 'none', `the page's default mode: ${first.p.alignment}`);
  // A position-field parameter: the map does not read it.
  await setParamInput(page, 'field.position_iterations', 7);
  await page.waitForFunction(() => window.quadrille.lastRun.parameters.field.position_iterations === 7, null, { timeout: 60000 });
  await settle(page);
  const kept = await page.evaluate(() => ({ p: window.quadrille.lastParam, jobs: window.quadrille.paramJobs, on: document.getElementById('layer-parametrization').checked }));
  assert(kept.p && kept.p.ms === first.p.ms && kept.jobs === first.jobs && kept.on, `kept: ${JSON.stringify({ jobs: kept.jobs, on: kept.on, same: kept.p && kept.p.ms === first.p.ms })}`);
  // The alignment mode: the map is computed again, with smooth regions.
  await setParamInput(page, 'alignment.mode', 'smooth-regions');
  await page.waitForFunction(() => window.quadrille.lastParam && window.quadrille.lastParam.alignment === 'smooth-regions', null, { timeout: 120000 });
  const second = await page.evaluate(() => ({ p: window.quadrille.lastParam, jobs: window.quadrille.paramJobs }));
  console.log(`      [${env.backend}] fandisk map: no alignment ${first.p.measures.cones} cones, misalignment ${first.p.measures.misalignment_degrees.toFixed(2)}°; smooth regions ${second.p.measures.cones} cones, ${second.p.measures.misalignment_degrees.toFixed(2)}°`);
  assert(second.jobs === first.jobs + 1, `one new parametrization job: ${first.jobs} → ${second.jobs}`);
  assert(second.p.measures.misalignment_degrees !== first.p.measures.misalignment_degrees, 'a different map');
  assert(errors.length === 0, `console errors: ${errors.join(' | ')}`);
});

test('the parametrization stage shows its progress, Cancel stops it and the page goes on', async (env) => {
  const { page, errors } = await open(env, 'sample=spot');
  await waitForRun(page, 'spot.obj');
  // On spot the stage can begin and end between two frames: it is held
  // (worker.js) after its first progress report until the job's cancel flag
  // is set, so Cancel always meets it running. Without a working Cancel the
  // stage goes on after 20 s and finishes, and the checks below fail.
  await page.evaluate(() => window.quadrille.holdStageForTesting('parametrization'));
  await page.check('#layer-parametrization');
  // Running: the worker's own progress report of the stage is on screen.
  await page.waitForFunction(() => !document.getElementById('progress').hidden
    && /parametrization — /.test(document.querySelector('#progress .progress-text').textContent)
    && document.getElementById('status').textContent.includes('integer-grid map'), null, { timeout: 60000 });
  assert(await page.isVisible('#progress-parametrization'), 'a progress bar for the stage');
  await page.click('#cancel');
  await page.waitForFunction(() => document.getElementById('status').textContent.includes('cancelled'), null, { timeout: 5000 });
  console.log(`      [${env.backend}] ${(await page.textContent('#status')).trim()}`);
  assert(!(await page.isChecked('#layer-parametrization')), 'the layer is off again after a cancel');
  assert(await page.evaluate(() => window.quadrille.lastParam == null), 'no map was kept');
  await page.click('#sample-buttons >> text=fandisk');
  await waitForRun(page, 'fandisk.obj');
  assert(errors.length === 0, `console errors: ${errors.join(' | ')}`);
});

// Kinks of the luminance along rows and columns where three pixels two
// apart are drawn: |l(x−2) − 2 l(x) + l(x+2)| of 3–20 levels (facets of
// flat shading break the smooth gradient there) are `facet`, larger ones
// (creases, occluding contours) `strong`.
function shadingSteps(png) {
  const { data, width, height } = PNG.sync.read(png);
  const lum = (i) => 0.3 * data[i] + 0.59 * data[i + 1] + 0.11 * data[i + 2];
  const ink = (i) => Math.abs(data[i] - BACKGROUND[0]) + Math.abs(data[i + 1] - BACKGROUND[1]) + Math.abs(data[i + 2] - BACKGROUND[2]) > 30;
  let facet = 0, strong = 0, pairs = 0;
  for (let y = 2; y < height - 2; y++) {
    for (let x = 2; x < width - 2; x++) {
      const i = 4 * (y * width + x);
      if (!ink(i)) continue;
      for (const step of [8, 8 * width]) {
        if (!ink(i - step) || !ink(i + step)) continue;
        pairs++;
        const d = Math.abs(lum(i - step) - 2 * lum(i) + lum(i + step));
        if (d >= 20) strong++;
        else if (d >= 3) facet++;
      }
    }
  }
  return { facet, strong, pairs };
}

// Hides every layer but the surface (lines and markers draw steps of their own).
async function surfaceOnly(page) {
  for (const box of await page.locator('#layers input[type=checkbox]').all()) {
    const id = await box.getAttribute('id');
    if (id !== 'layer-surface' && await box.isChecked() && await box.isEnabled()) await box.uncheck();
  }
  await settle(page);
}

// Fraction of pixels whose luminance differs by more than 12 levels.
function lumDiff(pngA, pngB) {
  const a = PNG.sync.read(pngA).data, b = PNG.sync.read(pngB).data;
  const lum = (d, i) => 0.3 * d[i] + 0.59 * d[i + 1] + 0.11 * d[i + 2];
  let n = 0;
  for (let i = 0; i < a.length; i += 4) if (Math.abs(lum(a, i) - lum(b, i)) > 12) n++;
  return n / (a.length / 4);
}

test('smooth shading is smooth on curved parts and keeps fandisk\u2019s creases sharp', async (env) => {
  const { page, errors } = await open(env, 'sample=spot');
  await waitForRun(page, 'spot.obj');
  await surfaceOnly(page);
  const clip = await page.locator('#canvas').boundingBox();
  const shot = (name) => page.screenshot({ path: join(artifacts, `${name}-${env.backend}.png`), clip });
  const setFlat = async (on) => { await (on ? page.check('#flat-shading') : page.uncheck('#flat-shading')); await settle(page); };
  const setCrease = async (deg) => { await page.fill('#crease-angle', String(deg)); await page.dispatchEvent('#crease-angle', 'change'); await settle(page); };
  // Spot's curved surface: flat shading shows the facets as faint steps, smooth does not.
  const spotSmooth = shadingSteps(await shot('spot-smooth'));
  await setFlat(true);
  const spotFlat = shadingSteps(await shot('spot-flat'));
  await setFlat(false);
  console.log(`      [${env.backend}] spot faint steps: smooth ${spotSmooth.facet}, flat ${spotFlat.facet} of ${spotSmooth.pairs} pairs`);
  assert(spotFlat.facet > 1.5 * spotSmooth.facet, `flat shading shows the facets: ${spotFlat.facet} faint steps vs ${spotSmooth.facet} smooth`);
  // Fandisk: at its creases the smooth picture keeps the flat one's steps;
  // smoothing across every edge (180°) smears them into gradients.
  await page.click('#sample-buttons >> text=fandisk');
  await waitForRun(page, 'fandisk.obj');
  await surfaceOnly(page);
  await page.evaluate(() => { window.quadrille.setCamera([0.7, 0.45]); });
  await settle(page);
  const smooth = await shot('fandisk-smooth');
  await setFlat(true);
  const flat = await shot('fandisk-flat');
  await setFlat(false);
  await setCrease(180);
  const smeared = await shot('fandisk-smeared');
  await setCrease(30);
  const again = await shot('fandisk-smooth-again');
  const [kept, lost, same] = [lumDiff(smooth, flat), lumDiff(smeared, flat), lumDiff(again, smooth)];
  console.log(`      [${env.backend}] fandisk pixels differing from flat shading: smooth ${(100 * kept).toFixed(2)} %, smoothed across creases ${(100 * lost).toFixed(2)} %`);
  assert(lost > 0.01, `smoothing across the creases changes the picture: ${(100 * lost).toFixed(2)} %`);
  assert(kept < 0.25 * lost, `the creases stay sharp steps in smooth mode: ${(100 * kept).toFixed(2)} % of pixels differ from flat (${(100 * lost).toFixed(2)} % without the split)`);
  assert(same === 0, `the default angle gives the same picture again: ${(100 * same).toFixed(2)} % differ`);
  assert(errors.length === 0, `console errors: ${errors.join(' | ')}`);
});

test('one control switches the view between the input and the result, and back', async (env) => {
  const { page, errors } = await open(env, 'sample=spot');
  await waitForRun(page, 'spot.obj');
  const clip = await page.locator('#canvas').boundingBox();
  const state = () => page.evaluate(() => ({ surface: window.quadrille.drawnSurface(), quads: document.getElementById('layer-quad-mesh').checked, legend: document.getElementById('legend').textContent, button: document.getElementById('compare').textContent }));
  const result = await state();
  assert(result.surface === 'quad mesh faces' && result.quads && result.button.includes('input'), `the result is shown first: ${JSON.stringify(result)}`);
  const resultPng = await page.screenshot({ path: join(artifacts, `compare-result-${env.backend}.png`), clip });
  await page.click('#compare');
  await settle(page);
  const input = await state();
  assert(input.surface === 'input' && !input.quads && input.button.includes('result') && !input.legend.includes('face degree'), `the input alone: ${JSON.stringify(input)}`);
  const inputPng = await page.screenshot({ path: join(artifacts, `compare-input-${env.backend}.png`), clip });
  const changed = lumDiff(resultPng, inputPng);
  assert(changed > 0.02, `the picture changes: ${(100 * changed).toFixed(2)} % of pixels`);
  await page.keyboard.press('h');
  await settle(page);
  const back = await state();
  assert(back.surface === 'quad mesh faces' && back.quads && back.button.includes('input'), `the key brings the result back: ${JSON.stringify(back)}`);
  const backPng = await page.screenshot({ path: join(artifacts, `compare-back-${env.backend}.png`), clip });
  assert(lumDiff(backPng, resultPng) < 0.001, `the same result picture again: ${(100 * lumDiff(backPng, resultPng)).toFixed(3)} % differ`);
  assert(errors.length === 0, `console errors: ${errors.join(' | ')}`);
});

test('field glyphs keep their screen spacing when zooming, and the spacing control sets it', async (env) => {
  const { page, errors } = await open(env);
  // Thinned to the screen, the bunny's 34 834 crosses are legible: the layer is shown when the
  // orientation stage brings it, as on small meshes (the finished quad mesh then takes its place).
  await page.waitForFunction(() => document.querySelector('#layer-cross-field')?.checked, null, { timeout: 60000, polling: 'raf' });
  await waitForRun(page, 'stanford-bunny.obj');
  assert(!(await page.isChecked('#layer-cross-field')), 'the finished result hides the cross field');
  await surfaceOnly(page);
  await page.check('#layer-cross-field');
  await page.evaluate(() => window.quadrille.setCamera([0, 0]));
  await settle(page);
  const base = await page.evaluate(() => window.quadrille.camera()[2]);
  const clip = await page.locator('#canvas').boundingBox();
  // Glyphs per 10 000 pixels covered by the bunny (drawing-buffer pixels).
  const density = async (distance, file) => {
    await page.evaluate((d) => window.quadrille.setCamera([0, 0, d]), distance);
    await settle(page);
    const count = await page.evaluate(() => window.quadrille.glyphCount('cross field'));
    const covered = inkFraction(await page.screenshot({ path: join(artifacts, `${file}-${env.backend}.png`), clip }));
    const pixels = covered * clip.width * clip.height * (await page.evaluate(() => window.devicePixelRatio)) ** 2;
    return { count, covered, per10k: 1e4 * count / pixels };
  };
  const mid = await density(base, 'glyphs-mid');
  const near = await density(base * 0.6, 'glyphs-near');
  const far = await density(base * 1.8, 'glyphs-far');
  const sites = await page.evaluate(() => window.quadrille.lastRun.counts.vertices);
  console.log(`      [${env.backend}] cross-field glyphs (of ${sites} sites) per 10k covered px: near ${near.count} → ${near.per10k.toFixed(1)}, mid ${mid.count} → ${mid.per10k.toFixed(1)}, far ${far.count} → ${far.per10k.toFixed(1)}`);
  assert(mid.count > 50 && mid.count < sites / 4, `thinned to the screen: ${mid.count} of ${sites}`);
  for (const [name, d] of [['near', near], ['far', far]]) {
    assert(d.per10k > 0.6 * mid.per10k && d.per10k < 1.6 * mid.per10k, `${name}: ${d.per10k.toFixed(1)} glyphs per 10k px vs ${mid.per10k.toFixed(1)}`);
  }
  assert(near.covered > 2 * far.covered, `the zoom changed the picture: ${near.covered} vs ${far.covered} covered`);
  // Twice the spacing: about a quarter of the glyphs.
  await page.evaluate((d) => window.quadrille.setCamera([0, 0, d]), base);
  await page.locator('#glyph-spacing').fill('48');
  await settle(page);
  const sparse = await page.evaluate(() => window.quadrille.glyphCount('cross field'));
  await page.screenshot({ path: join(artifacts, `glyphs-sparse-${env.backend}.png`), clip });
  assert(sparse > 0.15 * mid.count && sparse < 0.4 * mid.count, `spacing 48 px: ${sparse} glyphs vs ${mid.count} at 24 px`);
  // The principal directions follow the same spacing.
  await page.check('#layer-principal-directions');
  await settle(page);
  const principal = await page.evaluate(() => window.quadrille.glyphCount('principal directions'));
  assert(principal > 0.6 * sparse && principal < 1.6 * sparse, `principal directions: ${principal} glyphs vs ${sparse} crosses`);
  assert(errors.length === 0, `console errors: ${errors.join(' | ')}`);
});

test('field glyphs keep their spacing zoomed far into a coarse mesh (sites on the faces)', async (env) => {
  const { page, errors } = await open(env, 'sample=spot');
  await waitForRun(page, 'spot.obj');
  await surfaceOnly(page);
  await page.check('#layer-cross-field');
  await page.evaluate(() => window.quadrille.setCamera([0.4, 0.2]));
  const base = await page.evaluate(() => window.quadrille.camera()[2]);
  const clip = await page.locator('#canvas').boundingBox();
  const dpr = await page.evaluate(() => window.devicePixelRatio);
  // One glyph per cell of the spacing: 10 000 / spacing² per 10k covered drawing-buffer pixels.
  const spacing = Number(await page.inputValue('#glyph-spacing')) * dpr;
  const ideal = 1e4 / spacing ** 2;
  const density = async (file, layer = 'cross field') => {
    await settle(page);
    const count = await page.evaluate((l) => window.quadrille.glyphCount(l), layer);
    const covered = inkFraction(await page.screenshot({ path: join(artifacts, `${file}-${env.backend}.png`), clip }));
    return { count, covered, per10k: 1e4 * count / (covered * clip.width * clip.height * dpr ** 2) };
  };
  const mid = await density('glyphs-spot-mid');
  // The wheel zooms toward the surface point under the cursor, to an eighth of the distance:
  // the mesh's vertices then lie several glyph spacings apart on screen.
  await page.mouse.move(clip.x + clip.width * 0.5, clip.y + clip.height * 0.5);
  for (let k = 0; k < 7; k++) await page.mouse.wheel(0, -200);
  const zoomed = await page.evaluate(() => window.quadrille.camera()[2]);
  const near = await density('glyphs-spot-near');
  const sites = await page.evaluate(() => window.quadrille.lastRun.counts.vertices);
  console.log(`      [${env.backend}] spot (${sites} sites) cross-field glyphs per 10k covered px (one per cell: ${ideal.toFixed(1)}): mid ${mid.count} → ${mid.per10k.toFixed(1)}, near (distance ×${(zoomed / base).toFixed(2)}) ${near.count} → ${near.per10k.toFixed(1)}`);
  assert(zoomed < 0.2 * base, `the wheel zoomed in: distance ${zoomed} of ${base}`);
  assert(near.covered > 0.5, `zoomed in, the surface fills the view: ${(100 * near.covered).toFixed(1)} %`);
  for (const [name, d] of [['mid', mid], ['near', near]]) {
    assert(d.per10k > 0.6 * ideal && d.per10k < 1.6 * ideal, `${name}: ${d.per10k.toFixed(1)} glyphs per 10k px, one per cell would be ${ideal.toFixed(1)}`);
  }
  await page.uncheck('#layer-cross-field');
  await page.check('#layer-principal-directions');
  const principal = await density('glyphs-spot-principal', 'principal directions');
  assert(principal.per10k > 0.6 * ideal && principal.per10k < 1.6 * ideal, `principal directions near: ${principal.per10k.toFixed(1)} glyphs per 10k px`);
  assert(errors.length === 0, `console errors: ${errors.join(' | ')}`);
});

test('parameters cross to the worker as objects: the run echoes them, nulls included; a wrong type is a clear error', async (env) => {
  const { page, errors } = await open(env, 'sample=spot');
  await waitForRun(page, 'spot.obj');
  const leaves = (o, prefix = '', out = {}) => {
    for (const [k, v] of Object.entries(o)) {
      const path = prefix ? `${prefix}.${k}` : k;
      if (v && typeof v === 'object' && !Array.isArray(v)) leaves(v, path, out);
      else out[path] = v;
    }
    return out;
  };
  const { page: mine, run } = await page.evaluate(() => ({ page: window.quadrille.params(), run: window.quadrille.lastRun.parameters }));
  const [a, b] = [leaves(mine), leaves(run)];
  const nulls = Object.keys(a).filter((k) => a[k] === null);
  assert(nulls.length > 0, 'some parameters are null (auto) by default');
  for (const [k, v] of Object.entries(a)) {
    assert(JSON.stringify(b[k]) === JSON.stringify(v) && (v !== null || b[k] === null), `${k}: page ${JSON.stringify(v)}, worker ${b[k] === undefined ? 'undefined' : JSON.stringify(b[k])}`);
  }
  await page.evaluate(() => window.quadrille.setParam('field.position_iterations', 'many'));
  await page.waitForFunction(() => window.quadrille.lastError && window.quadrille.lastError.includes('parameters'), null, { timeout: 30000 });
  const message = await page.evaluate(() => window.quadrille.lastError);
  assert(message.includes('invalid type') && message.includes('many'), `the error says what is wrong: ${message}`);
  assert((await page.textContent('#status')).includes('parameters'), 'the error is on the page');
  // NaN reaches the worker only as a JS value: JSON text would have made it null
  // ("invalid type: null, expected f32"), which names neither the field nor NaN.
  await page.evaluate(() => window.quadrille.setParam('field.position_iterations', 7));
  await page.evaluate(() => window.quadrille.setParam('alignment.position_weight', NaN));
  await page.waitForFunction(() => window.quadrille.lastError && window.quadrille.lastError.includes('position_weight'), null, { timeout: 30000 });
  const nan = await page.evaluate(() => window.quadrille.lastError);
  assert(nan.includes('parameters: alignment.position_weight is NaN, not a finite number'), `the worker saw NaN itself: ${nan}`);
  await page.evaluate(() => window.quadrille.setParam('alignment.position_weight', 5));
  await page.waitForFunction(() => window.quadrille.lastRun.parameters.field.position_iterations === 7 && window.quadrille.lastRun.complete, null, { timeout: 60000 });
  const counts = await page.evaluate(() => window.quadrille.lastRun.counts);
  assert(counts.quad_mesh_faces > 0 && counts.vertices === 2930, `the run goes on: ${JSON.stringify(counts)}`);
  assert(errors.length === 0, `console errors: ${errors.join(' | ')}`);
});

test('touch: one finger orbits, a pinch zooms, two fingers pan', async (env) => {
  const { page, errors } = await open(env, 'sample=spot');
  await waitForRun(page, 'spot.obj');
  const cdp = await page.context().newCDPSession(page);
  await cdp.send('Emulation.setTouchEmulationEnabled', { enabled: true, maxTouchPoints: 5 });
  const box = await page.locator('#canvas').boundingBox();
  const [cx, cy] = [box.x + box.width / 2, box.y + box.height / 2];
  // A gesture: fingers from `from` to `to` (page pixels) in ten moves.
  const gesture = async (from, to) => {
    const at = (t) => from.map(([x, y], id) => ({ x: x + (to[id][0] - x) * t, y: y + (to[id][1] - y) * t, id }));
    await cdp.send('Input.dispatchTouchEvent', { type: 'touchStart', touchPoints: at(0) });
    for (let k = 1; k <= 10; k++) await cdp.send('Input.dispatchTouchEvent', { type: 'touchMove', touchPoints: at(k / 10) });
    await cdp.send('Input.dispatchTouchEvent', { type: 'touchEnd', touchPoints: [] });
    await settle(page);
    return page.evaluate(() => window.quadrille.camera());
  };
  const start = await page.evaluate(() => window.quadrille.camera());
  const orbited = await gesture([[cx, cy]], [[cx + 160, cy + 40]]);
  assert(Math.abs(orbited[0] - start[0]) > 0.3 && Math.abs(orbited[1] - start[1]) > 0.02, `one finger turns the view: ${start} → ${orbited}`);
  assert(Math.abs(orbited[2] - start[2]) < 1e-6, `an orbit keeps the distance: ${start[2]} → ${orbited[2]}`);
  const pinched = await gesture([[cx - 40, cy], [cx + 40, cy]], [[cx - 160, cy], [cx + 160, cy]]);
  assert(pinched[2] < 0.6 * orbited[2], `spreading two fingers zooms in: distance ${orbited[2]} → ${pinched[2]}`);
  assert(Math.abs(pinched[0] - orbited[0]) < 1e-6, 'a pinch does not turn the view');
  const panned = await gesture([[cx - 60, cy], [cx + 60, cy]], [[cx - 60, cy + 150], [cx + 60, cy + 150]]);
  const moved = Math.hypot(panned[3] - pinched[3], panned[4] - pinched[4], panned[5] - pinched[5]);
  assert(moved > 0.05 * pinched[2] && Math.abs(panned[0] - pinched[0]) < 1e-6, `two fingers moving together pan: target moved ${moved} (distance ${pinched[2]})`);
  assert(await page.evaluate(() => window.quadrille.lastPick == null), 'no gesture was taken for a tap');
  await page.screenshot({ path: join(artifacts, `touch-${env.backend}.png`) });
  assert(errors.length === 0, `console errors: ${errors.join(' | ')}`);
});

const only = process.env.TEST_FILTER ? new RegExp(process.env.TEST_FILTER) : null;
const wanted = process.argv.slice(2).length ? process.argv.slice(2) : Object.keys(CONFIGS);
const { server, url } = await startServer();
let failed = 0;
let passed = 0;
try {
  for (const backend of wanted) {
    const config = CONFIGS[backend];
    if (!config) throw new Error(`unknown configuration ${backend}`);
    const context = await launch(config.flags);
    try {
      for (const { name, fn } of tests) {
        if (only && !only.test(name)) continue;
        const started = Date.now();
        try {
          await fn({ context, url, backend, query: config.query });
          passed++;
          console.log(`ok    [${backend}] ${name} (${Date.now() - started} ms)`);
        } catch (error) {
          failed++;
          console.log(`FAIL  [${backend}] ${name}\n      ${String(error.stack || error).split('\n').join('\n      ')}`);
        }
      }
    } finally {
      await context.close();
    }
  }
} finally {
  server.kill();
}
console.log(`${passed} passed, ${failed} failed`);
process.exit(failed ? 1 : 0);
