// Page wiring: the worker that runs the pipeline, the viewer (Rust + wgpu on
// this thread), file input, drag and drop, samples, layers, keys. No mesh
// work happens here, and the user's mesh is never sent anywhere.
import init, { Viewer } from './pkg/quadrille.js';

const SAMPLES = ['stanford-bunny', 'fandisk', 'rocker-arm', 'spot', 'cow', 'teapot', 'suzanne', 'beetle'];
const DEFAULT_SAMPLE = 'stanford-bunny';
// A step that overruns this after Cancel gets its worker terminated.
const CANCEL_DEADLINE_MS = 400;


const $ = (id) => document.getElementById(id);
const canvas = $('canvas');
const params = new URLSearchParams(location.search);

window.quadrille = { lastImport: null, lastError: null, lastRun: null, backend: null, frames: 0 };

// ---------------------------------------------------------------- status

function setStatus(text, isError = false) {
  $('status').textContent = text;
  $('status').classList.toggle('error', isError);
}

function showError(message) {
  window.quadrille.lastError = message;
  setStatus(message, true);
}

const progressEl = $('progress');
function showProgress(text, fraction) {
  progressEl.hidden = false;
  progressEl.querySelector('.progress-text').textContent = text;
  progressEl.querySelector('.progress-fill').style.width = `${Math.round(fraction * 100)}%`;
}
const hideProgress = () => { progressEl.hidden = true; };

// ---------------------------------------------------------------- viewer

let viewer = null;
let renderQueued = false;

function requestRender() {
  if (!viewer || renderQueued) return;
  renderQueued = true;
  requestAnimationFrame(() => {
    renderQueued = false;
    renderNow();
  });
}

function renderNow() {
  try {
    viewer.render();
    window.quadrille.frames++;
  } catch (error) {
    showError(`drawing failed: ${error.message}`);
  }
}

function resizeCanvas() {
  const dpr = window.devicePixelRatio || 1;
  const w = Math.max(1, Math.round(canvas.clientWidth * dpr));
  const h = Math.max(1, Math.round(canvas.clientHeight * dpr));
  if (canvas.width !== w || canvas.height !== h) {
    canvas.width = w;
    canvas.height = h;
  }
  if (viewer) {
    viewer.resize(w, h);
    viewer.set_line_width(1.25 * dpr);
    requestRender();
  }
}

async function startViewer() {
  resizeCanvas();
  const backend = params.get('backend') === 'webgl2' ? 'webgl2' : 'auto';
  try {
    viewer = await Viewer.create(canvas, backend, canvas.width, canvas.height);
  } catch (error) {
    showError(`The 3D view is not available: ${error.message}. Import still works.`);
    return;
  }
  window.quadrille.backend = viewer.backend;
  $('backend-badge').textContent = `${viewer.backend === 'webgpu' ? 'WebGPU' : 'WebGL2'} · ${viewer.tier}`;
  new ResizeObserver(resizeCanvas).observe(canvas);
  resizeCanvas();
  attachInput();
}

// ---------------------------------------------------------------- layers

// The page's layers, in panel order. `available` flips on when a stage has
// provided the data. Line and point layers from later stages are added by
// name when their results arrive; STYLES gives them a key, swatch and size.
const BASE_LAYERS = [
  { name: 'surface', label: 'Surface', key: 's', color: '#c8cdd8', visible: true },
  { name: 'scalar', label: 'Colour by scalar', key: 'c', visible: true },
  { name: 'polygon edges', label: 'Polygon edges', key: 'e', color: '#2b3240', visible: true },
  { name: 'boundary', label: 'Boundary edges', key: 'b', color: '#d8342c', visible: true },
  { name: 'picked', label: 'Picked point', color: '#ff7a1a', visible: true, size: 11 },
];
const STYLES = {
  'principal directions': { key: 'd', color: '#c0392b', color2: '#1f5fbf', hidden: true },
  'cross field': { key: 'x', color: '#33415c', dense: true },
  'extracted mesh': { key: 'm', color: '#111111', hidden: true },
  'quad mesh': { key: 'q', color: '#111111' },
  'non-quad faces': { key: 'n', color: '#f28e2b', color2: '#8e44ad', size: 5 },
  'feature vertices': { key: 'v', color: '#e68a00', size: 6, hidden: true },
  'orientation singularities': { key: 'g', color: '#1f6fdd', color2: '#d8342c', size: 10 },
  'position field': { key: 'l', color: '#6a3d9a', size: 3, hidden: true },
  'position singularities': { key: 'g', color: '#1b9e4b', size: 8, hidden: true },
};
// Meshes with more segments than this open with the layer hidden.
const DENSE = 30000;
let LAYERS = BASE_LAYERS.map((l) => ({ ...l }));
const available = new Set();
let scalars = {}; // name → { values, min, max, colormap }
let scalarName = null;

function addLayer(name, kind, count) {
  const style = STYLES[name] || { color: '#555555' };
  const visible = !style.hidden && !(style.dense && count > DENSE);
  LAYERS = LAYERS.filter((l) => l.name !== name);
  LAYERS.push({ name, label: name[0].toUpperCase() + name.slice(1), kind, ...style, visible });
  available.add(name);
  if (viewer) viewer.set_layer_visible(name, visible);
}

function setLayerVisible(name, visible) {
  const layer = LAYERS.find((l) => l.name === name);
  if (!layer) return;
  layer.visible = visible;
  if (viewer) viewer.set_layer_visible(name, visible);
  updateLayersPanel();
  requestRender();
}

function setScalar(name) {
  scalarName = name in scalars ? name : null;
  if (viewer) {
    try {
      if (scalarName) {
        const s = scalars[scalarName];
        viewer.set_scalar(scalarName, s.values, s.min, s.max, s.colormap);
      } else {
        viewer.clear_scalar();
      }
    } catch (error) {
      showError(`could not colour by ${name}: ${error.message}`);
    }
  }
  updateLayersPanel();
  requestRender();
}

function updateLayersPanel() {
  $('layers').replaceChildren(...LAYERS.map((layer) => {
    const li = document.createElement('li');
    const box = document.createElement('input');
    box.type = 'checkbox';
    box.id = `layer-${layer.name.replace(/\s+/g, '-')}`;
    box.checked = layer.visible;
    box.disabled = !available.has(layer.name);
    box.addEventListener('change', () => setLayerVisible(layer.name, box.checked));
    const label = document.createElement('label');
    label.htmlFor = box.id;
    label.textContent = layer.name === 'scalar' ? 'Colour by' : layer.label;
    li.append(box);
    if (layer.color) {
      const swatch = document.createElement('span');
      swatch.className = 'swatch';
      swatch.style.background = layer.color2 ? `linear-gradient(135deg, ${layer.color} 50%, ${layer.color2} 50%)` : layer.color;
      li.append(swatch);
    }
    li.append(label);
    if (layer.name === 'scalar') {
      const select = document.createElement('select');
      select.id = 'scalar-select';
      select.disabled = !Object.keys(scalars).length;
      for (const name of ['none', ...Object.keys(scalars)]) {
        const option = document.createElement('option');
        option.value = option.textContent = name;
        option.selected = (scalarName || 'none') === name;
        select.append(option);
      }
      select.addEventListener('change', () => setScalar(select.value));
      li.append(select);
    }
    if (layer.key) {
      const key = document.createElement('kbd');
      key.className = 'key';
      key.textContent = layer.key.toUpperCase();
      li.append(key);
    }
    li.classList.toggle('disabled', box.disabled);
    return li;
  }));
  updateLegend();
}

function updateLegend() {
  const legend = viewer && viewer.legend();
  const el = $('legend');
  el.hidden = !legend;
  if (!legend) return;
  el.querySelector('.legend-name').textContent = legend.name;
  el.querySelector('.legend-bar').style.background = `linear-gradient(to right, ${legend.stops.join(', ')})`;
  el.querySelector('.min').textContent = formatNumber(legend.min);
  el.querySelector('.max').textContent = formatNumber(legend.max);
}

const formatNumber = (x) => Number(x.toPrecision(3)).toString();
const rgba = (hex) => new Uint8Array([1, 3, 5].map((i) => parseInt(hex.slice(i, i + 2), 16)).concat(255));
const layerColor = (name) => rgba(LAYERS.find((l) => l.name === name).color);
const dpr = () => window.devicePixelRatio || 1;

// ---------------------------------------------------------------- results

let meshInfo = null; // { name, vertices } of the mesh on screen

function showMesh(name, mesh) {
  available.clear();
  LAYERS = BASE_LAYERS.map((l) => ({ ...l, visible: LAYERS.find((x) => x.name === l.name)?.visible ?? l.visible }));
  scalars = {};
  scalarName = null;
  $('pick-info').hidden = true;
  if (!viewer) return;
  try {
    viewer.set_mesh(mesh.positions, mesh.triangles, mesh.normals);
    viewer.set_edges('polygon edges', mesh.polygonEdges, layerColor('polygon edges'));
    viewer.set_edges('boundary', mesh.boundaryEdges, layerColor('boundary'));
    // Dense meshes are a solid mass of edges at first sight; show their edges on demand (E).
    LAYERS.find((l) => l.name === 'polygon edges').visible = mesh.polygonEdges.length / 2 <= DENSE;
    for (const layer of LAYERS) viewer.set_layer_visible(layer.name, layer.visible);
    available.add('surface').add('polygon edges').add('picked');
    if (mesh.boundaryEdges.length) available.add('boundary');
    meshInfo = { name, vertices: mesh.positions.length / 3 };
  } catch (error) {
    showError(`could not show ${name}: ${error.message}`);
  }
  updateLayersPanel();
  requestRender();
}

// Each stage's result as soon as the worker has it: the import brings the
// mesh; later stages bring scalars, line layers and point layers by name.
function onStage(job, result) {
  job.stages[result.stage] = result.ms;
  if (result.stage === 'import') {
    window.quadrille.lastImport = result.report;
    window.quadrille.lastError = null;
    showReport(result.report);
    showMesh(job.name, result.mesh);
    return;
  }
  if (!viewer) return;
  for (const [name, s] of Object.entries(result.scalars || {})) {
    scalars[name] = s;
    available.add('scalar');
  }
  for (const [name, l] of Object.entries(result.lines || {})) {
    viewer.set_lines(name, l.segments, l.colors);
    addLayer(name, 'lines', l.segments.length / 6);
  }
  for (const [name, p] of Object.entries(result.points || {})) {
    viewer.set_points(name, p.positions, p.colors, (STYLES[name]?.size || 6) * dpr());
    addLayer(name, 'points', p.positions.length / 3);
  }
  if (result.scalars && !scalarName) setScalar(Object.keys(result.scalars)[0]);
  // The result is what matters once it exists: the input's edges and the field recede.
  if (result.lines && result.lines['quad mesh']) {
    for (const name of ['polygon edges', 'cross field']) {
      const layer = LAYERS.find((l) => l.name === name);
      if (layer) { layer.visible = false; viewer.set_layer_visible(name, false); }
    }
  }
  updateLayersPanel();
  requestRender();
}

function showReport(r) {
  const rows = [
    ['format', r.format],
    ['vertices', r.vertices],
    ['faces', r.faces + (r.triangles !== r.faces ? ` (${r.triangles} triangles)` : '')],
    ['face degrees', r.face_degrees.map(([d, n]) => `${n}×${d}`).join(', ')],
    ['edges', r.edges],
    ['boundary edges', r.boundary_edges],
    ['non-manifold edges', r.nonmanifold_edges],
    ['non-manifold vertices', r.nonmanifold_vertices],
    ['inconsistently oriented edges', r.inconsistent_edges],
    ['components', r.components],
    ['Euler characteristic', r.euler_characteristic],
    ['genus', r.genus ?? '— (not a closed manifold)'],
    ['bounding box', `${fmt(r.bbox.min)} … ${fmt(r.bbox.max)}`],
    ...Object.entries(r.repairs).map(([k, v]) => [k.replaceAll('_', ' '), v]),
    ...r.warnings.map((w) => ['warning', w]),
  ];
  $('report').replaceChildren(...rows.map(([k, v]) => {
    const tr = document.createElement('tr');
    for (const text of [k, v]) {
      const td = document.createElement('td');
      td.textContent = String(text);
      tr.append(td);
    }
    return tr;
  }));
  $('report-title').textContent = r.file;
  $('report-panel').hidden = false;
}

const fmt = (v) => `(${v.map((x) => Number(x.toPrecision(4))).join(', ')})`;

// ---------------------------------------------------------------- worker

let worker = null;
let nextJob = 1;
let current = null; // { job, name, started, stages, flag, deadline }

function startWorker() {
  worker = new Worker(new URL('./worker.js', import.meta.url), { type: 'module' });
  worker.onmessage = (event) => onWorkerMessage(event.data);
  // A worker that fails to load or crashes outside a job is replaced.
  worker.onerror = (event) => {
    event.preventDefault();
    replaceWorker();
    if (current) finishJob(`${current.name}: the worker crashed (${event.message || 'unknown error'})`, true);
  };
}

function replaceWorker() {
  worker.terminate();
  startWorker();
}

function onWorkerMessage(m) {
  if (m.type === 'error' && m.fatal) replaceWorker();
  if (!current || m.job !== current.job) return;
  const job = current;
  switch (m.type) {
    case 'progress':
      showProgress(`${job.name}: ${m.stage} — ${m.text}`, m.fraction);
      break;
    case 'stage':
      try {
        onStage(job, m);
      } catch (error) {
        finishJob(`${job.name}: ${error.message}`, true);
      }
      break;
    case 'done':
      window.quadrille.lastRun = m.summary;
      finishJob(`${job.name}: ${Object.entries(job.stages).map(([s, ms]) => `${s} ${ms.toFixed(0)} ms`).join(', ')}.`);
      break;
    case 'cancelled':
      finishJob(`${job.name}: cancelled.`);
      break;
    case 'error':
      finishJob(m.message, true);
      break;
  }
}

function finishJob(message, isError = false) {
  if (current) clearTimeout(current.deadline);
  current = null;
  hideProgress();
  if (isError) showError(message);
  else setStatus(message);
}

function run(name, bytes) {
  if (current) cancel({ quiet: true });
  const flag = self.crossOriginIsolated ? new SharedArrayBuffer(4) : null;
  current = { job: nextJob++, name, started: performance.now(), stages: {}, flag, deadline: 0 };
  showProgress(`${name}: reading ${(bytes.byteLength / 1024).toFixed(0)} KiB…`, 0);
  setStatus(`Reading ${name}…`);
  worker.postMessage({ type: 'run', job: current.job, name, bytes, cancelFlag: flag }, [bytes]);
}

// Cancel: ask the worker (it checks between stages, and the shared flag in
// stage loops when available); terminate it if it does not answer in time.
function cancel({ quiet = false } = {}) {
  if (!current) return;
  const job = current;
  if (job.flag) Atomics.store(new Int32Array(job.flag), 0, 1);
  worker.postMessage({ type: 'cancel', job: job.job });
  if (quiet) {
    current = null;
    return;
  }
  showProgress(`${job.name}: cancelling…`, 1);
  job.deadline = setTimeout(() => {
    if (current !== job) return;
    replaceWorker();
    finishJob(`${job.name}: cancelled (the worker was restarted).`);
  }, CANCEL_DEADLINE_MS);
}

// ---------------------------------------------------------------- input files

async function loadSample(name) {
  try {
    const response = await fetch(`samples/${name}.obj`);
    if (!response.ok) throw new Error(`sample ${name} is not available (${response.status})`);
    run(`${name}.obj`, await response.arrayBuffer());
  } catch (error) {
    showError(error.message);
  }
}

async function loadFile(file) {
  try {
    run(file.name, await file.arrayBuffer());
  } catch (error) {
    showError(`${file.name}: ${error.message}`);
  }
}

// ---------------------------------------------------------------- picking, camera input

function pickAt(clientX, clientY) {
  if (!viewer) return;
  const rect = canvas.getBoundingClientRect();
  const hit = viewer.pick((clientX - rect.left) * (canvas.width / rect.width), (clientY - rect.top) * (canvas.height / rect.height));
  const info = $('pick-info');
  if (!hit) {
    viewer.set_points('picked', new Float32Array(0), layerColor('picked'), 1);
    info.hidden = true;
  } else {
    const p = hit.point;
    viewer.set_points('picked', new Float32Array(p), layerColor('picked'), 11 * dpr());
    const value = viewer.scalar_at(hit.vertex);
    info.textContent = `vertex ${hit.vertex} · triangle ${hit.triangle} · (${[...p].map((x) => x.toFixed(3)).join(', ')})`
      + (value !== undefined ? ` · value ${formatNumber(value)}` : '');
    info.hidden = false;
    window.quadrille.lastPick = { vertex: hit.vertex, triangle: hit.triangle, point: [...p] };
  }
  requestRender();
}

function attachInput() {
  const pointers = new Map(); // id → { x, y }
  let press = null; // { x, y, time, moved } of a single-pointer press, for click-to-pick
  const scale = () => canvas.width / canvas.getBoundingClientRect().width;

  canvas.addEventListener('pointerdown', (e) => {
    canvas.setPointerCapture(e.pointerId);
    pointers.set(e.pointerId, { x: e.clientX, y: e.clientY });
    press = pointers.size === 1 ? { x: e.clientX, y: e.clientY, time: performance.now(), moved: false } : null;
  });
  canvas.addEventListener('pointermove', (e) => {
    const last = pointers.get(e.pointerId);
    if (!last) return;
    const k = scale();
    if (pointers.size === 1) {
      const dx = (e.clientX - last.x) * k;
      const dy = (e.clientY - last.y) * k;
      if (press && Math.hypot(e.clientX - press.x, e.clientY - press.y) > 4) press.moved = true;
      if (e.buttons & 6 || e.shiftKey) viewer.pan(dx, dy);
      else viewer.orbit(dx, dy);
    } else if (pointers.size === 2) {
      const [a, b] = [...pointers.values()];
      const other = a === last ? b : a;
      const before = Math.hypot(last.x - other.x, last.y - other.y);
      const after = Math.hypot(e.clientX - other.x, e.clientY - other.y);
      if (before > 0 && after > 0) viewer.zoom(before / after);
      viewer.pan((e.clientX - last.x) * k / 2, (e.clientY - last.y) * k / 2);
    }
    pointers.set(e.pointerId, { x: e.clientX, y: e.clientY });
    requestRender();
  });
  const release = (e) => {
    if (!pointers.delete(e.pointerId)) return;
    if (press && !press.moved && e.type === 'pointerup' && e.button === 0 && performance.now() - press.time < 600) {
      pickAt(e.clientX, e.clientY);
    }
    press = null;
  };
  canvas.addEventListener('pointerup', release);
  canvas.addEventListener('pointercancel', release);
  canvas.addEventListener('contextmenu', (e) => e.preventDefault());
  canvas.addEventListener('wheel', (e) => {
    e.preventDefault();
    const lines = e.deltaMode === 1 ? 16 : e.deltaMode === 2 ? 400 : 1;
    viewer.zoom(Math.exp(Math.max(-200, Math.min(200, e.deltaY * lines)) * 0.0015));
    requestRender();
  }, { passive: false });
  canvas.addEventListener('dblclick', () => fitView());
}

function fitView() {
  if (!viewer) return;
  viewer.fit_view();
  requestRender();
}

// A PNG of the current view: draw, then read the canvas in the same task
// (WebGL and WebGPU canvases keep their pixels until the task ends).
function screenshot() {
  return new Promise((resolve, reject) => {
    if (!viewer) {
      reject(new Error('there is no 3D view'));
      return;
    }
    renderNow();
    canvas.toBlob((blob) => (blob ? resolve(blob) : reject(new Error('the canvas gave no image'))), 'image/png');
  });
}

async function saveScreenshot() {
  try {
    const blob = await screenshot();
    const a = document.createElement('a');
    a.href = URL.createObjectURL(blob);
    a.download = `${(meshInfo?.name || 'quadrille').replace(/\.[^.]*$/, '')}.png`;
    a.click();
    setTimeout(() => URL.revokeObjectURL(a.href), 10000);
  } catch (error) {
    showError(`screenshot failed: ${error.message}`);
  }
}

window.quadrille.screenshot = async () => {
  const blob = await screenshot();
  return new Uint8Array(await blob.arrayBuffer());
};
window.quadrille.cancel = () => cancel();
window.quadrille.panicForTesting = () => {
  current = { job: nextJob++, name: 'panic test', started: performance.now(), stages: {}, flag: null, deadline: 0 };
  worker.postMessage({ type: 'panic-for-testing', job: current.job });
};

// ---------------------------------------------------------------- wiring

const buttons = $('sample-buttons');
for (const name of SAMPLES) {
  const b = document.createElement('button');
  b.type = 'button';
  b.textContent = name;
  b.addEventListener('click', () => loadSample(name));
  buttons.append(b);
}
$('file').addEventListener('change', (e) => {
  if (e.target.files.length) loadFile(e.target.files[0]);
  e.target.value = '';
});
$('cancel').addEventListener('click', () => cancel());
$('fit').addEventListener('click', fitView);
$('screenshot').addEventListener('click', saveScreenshot);

// Dropping anywhere on the page opens the file.
let dragDepth = 0;
document.addEventListener('dragenter', (e) => { e.preventDefault(); dragDepth++; document.body.classList.add('dragging'); });
document.addEventListener('dragleave', () => { if (--dragDepth <= 0) { dragDepth = 0; document.body.classList.remove('dragging'); } });
document.addEventListener('dragover', (e) => e.preventDefault());
document.addEventListener('drop', (e) => {
  e.preventDefault();
  dragDepth = 0;
  document.body.classList.remove('dragging');
  const file = e.dataTransfer && e.dataTransfer.files[0];
  if (file) loadFile(file);
});

document.addEventListener('keydown', (e) => {
  if (e.ctrlKey || e.metaKey || e.altKey || e.target.matches('input, textarea, select')) return;
  const key = e.key.toLowerCase();
  const layers = LAYERS.filter((l) => l.key === key && available.has(l.name));
  if (layers.length) layers.forEach((l) => setLayerVisible(l.name, !l.visible));
  else if (key === 'f') fitView();
  else if (key === 'p') saveScreenshot();
  else if (key === 'o') $('file').click();
  else if (key === 'escape') cancel();
  else return;
  e.preventDefault();
});

updateLayersPanel();
startWorker();
const viewerReady = init().then(startViewer).catch((error) => showError(`could not start: ${error.message}`));
// The default sample is processed at start; its mesh is shown once the viewer is up.
viewerReady.then(() => {
  const sample = params.get('sample');
  loadSample(SAMPLES.includes(sample) ? sample : DEFAULT_SAMPLE);
});
