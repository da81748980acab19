// Page wiring: the worker that runs the pipeline, the viewer (Rust + wgpu on
// this thread), file input, drag and drop, samples, layers, keys. No mesh
// work happens here, and the user's mesh is never sent anywhere.
import init, { Viewer, gridMapKey } from './pkg/quadrille.js';
import { createDesignMode, REGION_SURFACE } from './design.js';

const SAMPLES = ['stanford-bunny', 'fandisk', 'rocker-arm', 'spot', 'cow', 'teapot', 'suzanne', 'beetle', 'torus'];
const DEFAULT_SAMPLE = 'stanford-bunny';
// A step that overruns this after Cancel gets its worker terminated.
const CANCEL_DEADLINE_MS = 400;


const $ = (id) => document.getElementById(id);
const canvas = $('canvas');
const params = new URLSearchParams(location.search);

window.quadrille = { lastImport: null, lastError: null, lastRun: null, backend: null, frames: 0, progressGapsMs: {} };

// ---------------------------------------------------------------- status

function setStatus(text, isError = false) {
  $('status').textContent = text;
  $('status').classList.toggle('error', isError);
}

function showError(message) {
  window.quadrille.lastError = message;
  setStatus(message, true);
  hideLoading();
}

// The loading indicator over the view: shown from the start until the
// module is up and the first mesh is on screen (or something failed).
function setLoading(text) {
  $('loading').querySelector('.loading-text').textContent = text;
}
function hideLoading() {
  $('loading').hidden = true;
}

// What each stage does, for the status line while it runs.
const STAGE_TEXT = {
  import: 'reading the file',
  analysis: 'measuring curvature and features',
  hierarchy: 'building the multi-resolution hierarchy',
  orientation: 'solving the cross field (orientation)',
  position: 'solving the position field',
  extraction: 'extracting the quad mesh',
  postprocess: 'cleaning up the quad mesh',
  fit: 'fitting the Catmull–Clark control mesh',
  parametrization: 'computing the integer-grid map (parametrization)',
};

// The result in one line: vertices, quad share, singularities, limit error.
// Returns null when no quad came out.
function resultSummary(run) {
  const c = run.counts || {};
  const m = run.metrics;
  const faces = m ? m.topology.faces : c.quad_mesh_faces;
  const quads = m ? m.quads.quads : 0;
  if (!faces || !quads) return null;
  const parts = [
    `${c.quad_mesh_vertices.toLocaleString('en-US')} vertices`,
    `${(100 * quads / faces).toFixed(1)} % quads`,
    // The global mode's singularities are the map's cones.
    c.mode === 'global'
      ? `${(c.cones ?? 0).toLocaleString('en-US')} cones`
      : `${(c.orientation_singularities ?? 0).toLocaleString('en-US')} singularities`,
  ];
  const l = run.limit_surface;
  if (l) parts.push(`limit error ${Number((100 * l.after.hausdorff).toPrecision(2))} % of the size`);
  // What of the input the output lost is never silent (metrics.rs, PreservationMetrics).
  const kept = m && m.preservation;
  if (kept) {
    const closed = kept.loops_closed.length, lost = kept.components_lost.length;
    if (closed) parts.push(`${closed} input boundary loop${closed === 1 ? '' : 's'} closed over`);
    if (lost) parts.push(`${lost} input part${lost === 1 ? '' : 's'} lost (more vertices keep small parts)`);
  }
  return parts.join(' · ');
}

function showTimings(stages) {
  const rows = Object.entries(stages).map(([stage, ms]) => {
    const tr = document.createElement('tr');
    const a = document.createElement('td');
    a.textContent = stage;
    const b = document.createElement('td');
    b.textContent = `${ms.toFixed(0)} ms`;
    tr.append(a, b);
    return tr;
  });
  $('timings').replaceChildren(...rows);
  $('timings-panel').hidden = rows.length === 0;
}

const progressEl = $('progress');
// The stages of each remeshing mode (remesh.mode; src/pipeline.rs Stage::remeshing).
const STAGES_OF = {
  local: ['import', 'analysis', 'hierarchy', 'orientation', 'position', 'extraction', 'postprocess', 'fit'],
  global: ['import', 'analysis', 'parametrization', 'extraction', 'postprocess', 'fit'],
};
const MODE_PATH = 'remesh.mode';
const currentMode = () => (getPath(paramValues, MODE_PATH) === 'global' ? 'global' : 'local');
const stagesOfMode = () => STAGES_OF[currentMode()];
function showProgress(text, fraction, stage = null) {
  progressEl.hidden = false;
  progressEl.querySelector('.progress-text').textContent = text;
  progressEl.querySelector('.progress-fill').style.width = `${Math.round(fraction * 100)}%`;
  if (stage) {
    const li = $(`progress-${stage}`);
    if (li) {
      li.querySelector('.bar > div').style.width = `${Math.round(fraction * 100)}%`;
      li.classList.toggle('done', fraction >= 1);
      // Earlier stages are finished or were kept from the previous run.
      for (let prev = li.previousElementSibling; prev; prev = prev.previousElementSibling) {
        prev.classList.add('done');
        prev.querySelector('.bar > div').style.width = '100%';
      }
    }
  }
}
// One small bar per stage; stages that will not run (cached) start full.
function resetStageBars(from = 'import', stages = stagesOfMode()) {
  const start = stages.indexOf(from);
  $('progress-stages').replaceChildren(...stages.map((stage, i) => {
    const li = document.createElement('li');
    li.id = `progress-${stage}`;
    li.textContent = stage;
    const bar = document.createElement('div');
    bar.className = 'bar';
    const fill = document.createElement('div');
    fill.style.width = i < start ? '100%' : '0%';
    bar.append(fill);
    li.append(bar);
    li.classList.toggle('done', i < start);
    return li;
  }));
}
const hideProgress = () => { progressEl.hidden = true; };

// ---------------------------------------------------------------- viewer

let viewer = null;
let renderQueued = false;
let afterFrame = []; // callbacks run once the next frame is drawn

function requestRender() {
  if (!viewer || renderQueued) return;
  renderQueued = true;
  requestAnimationFrame(() => {
    renderQueued = false;
    renderNow();
    const callbacks = afterFrame;
    afterFrame = [];
    for (const f of callbacks) f();
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
    viewer.set_line_width((design.active ? 2.5 : 1.25) * dpr);
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
  viewer.set_glyph_spacing(Number($('glyph-spacing').value) * dpr());
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
  'principal directions': { key: 'd', color: '#c0392b', color2: '#1f5fbf', hidden: true, glyph: true },
  'cross field': { key: 'x', color: '#33415c', glyph: true },
  'extracted mesh': { key: 'm', color: '#111111', hidden: true },
  'quad mesh': { key: 'q', color: '#111111' },
  'non-quad faces': { key: 'n', color: '#f28e2b', color2: '#8e44ad', size: 5 },
  'feature vertices': { key: 'v', color: '#e68a00', size: 6, hidden: true },
  'orientation singularities': { key: 'g', color: '#1f6fdd', color2: '#d8342c', size: 10 },
  'position field': { key: 'l', color: '#ff7f0e', size: 5, hidden: true },
  'position singularities': { key: 'k', color: '#1b9e4b', size: 8, hidden: true },
  'control cage': { key: 'w', color: '#3b6fd8', hidden: true },
  'smooth regions': { key: 'r', color: '#1f78b4', color2: '#33a02c', hidden: true },
  'quad mesh faces': { key: 'a', color: '#d5dbe6', color2: '#f28e2b' },
  'limit surface': { key: 'u', color: '#9970ab', color2: '#5aae61', hidden: true },
  // Computed on demand when switched on (seconds on big meshes).
  parametrization: { key: 'i', color: '#c8cdd8', color2: '#6e7380', hidden: true },
  'parametrization cones': { key: 'j', color: '#1f6fdd', color2: '#d8342c', size: 10 },
};
const PARAM_LAYER = 'parametrization';
// Meshes with more polygon edges than this open with the edges hidden: they
// are drawn one line per edge, a solid mass at first sight. (The field
// glyphs are thinned to the screen, so they open shown on any mesh.)
const DENSE = 30000;
let LAYERS = BASE_LAYERS.map((l) => ({ ...l }));
const available = new Set();
let scalars = {}; // name → { values, min, max, colormap }
let scalarName = null;

function addLayer(name, kind) {
  const style = STYLES[name] || { color: '#555555' };
  const visible = !style.hidden;
  LAYERS = LAYERS.filter((l) => l.name !== name);
  LAYERS.push({ name, label: name[0].toUpperCase() + name.slice(1), kind, ...style, visible });
  available.add(name);
  if (viewer) viewer.set_layer_visible(name, visible);
}

function setLayerVisible(name, visible) {
  const layer = LAYERS.find((l) => l.name === name);
  if (!layer) return;
  layer.visible = visible;
  if (name === PARAM_LAYER && visible && !extraSurfaces[PARAM_LAYER]) requestParametrization();
  if (layer.kind === 'surface') {
    if (visible) for (const l of LAYERS) if (l.kind === 'surface' && l !== layer) l.visible = false;
    showSurface();
    return;
  }
  if (viewer) viewer.set_layer_visible(name, visible);
  updateLayersPanel();
  requestRender();
}

function setScalar(name) {
  scalarName = name in scalars ? name : null;
  if (viewer && drawnSurface === 'input') {
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

// Input ⇄ result: one control flips the view between the input mesh (its
// surface and edges alone) and what the last run made; the result layers
// hidden for the input view come back as they were.
const INPUT_LAYERS = new Set(['surface', 'scalar', 'polygon edges', 'boundary', 'picked']);
let compareHidden = []; // the result layers hidden to show the input
const resultLayers = () => LAYERS.filter((l) => !INPUT_LAYERS.has(l.name) && l.visible && available.has(l.name));
function toggleCompare() {
  const shown = resultLayers();
  if (shown.length) {
    compareHidden = shown.map((l) => l.name);
    for (const name of compareHidden) setLayerVisible(name, false);
  } else {
    const back = compareHidden.length ? compareHidden : ['quad mesh', 'quad mesh faces'];
    compareHidden = [];
    // Line and point layers first, then the one surface layer.
    const order = (n) => (LAYERS.find((l) => l.name === n)?.kind === 'surface' ? 1 : 0);
    for (const name of [...back].sort((a, b) => order(a) - order(b))) if (available.has(name)) setLayerVisible(name, true);
  }
}
function updateCompareButton() {
  const showingResult = resultLayers().length > 0;
  $('compare').textContent = showingResult ? 'Show the input (H)' : 'Show the result (H)';
  $('compare').disabled = !showingResult && !available.has('quad mesh faces') && !compareHidden.some((n) => available.has(n));
  $('compare').setAttribute('aria-pressed', String(!showingResult));
}

function updateLayersPanel() {
  updateCompareButton();
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
      // A result surface brings its own colouring: the select says so.
      const own = drawnSurface !== 'input' ? extraSurfaces[drawnSurface]?.scalar : null;
      const names = ['none', ...Object.keys(scalars)];
      for (const name of own ? [...names, '@surface'] : names) {
        const option = document.createElement('option');
        option.value = name;
        option.textContent = name === '@surface' ? `${own.name} (${drawnSurface})` : name;
        option.selected = own ? name === '@surface' : (scalarName || 'none') === name;
        select.append(option);
      }
      select.addEventListener('change', () => {
        if (select.value === '@surface') return;
        setScalar(select.value);
        // The scalars belong to the input: show it.
        if (drawnSurface !== 'input') {
          for (const l of LAYERS) if (l.kind === 'surface') l.visible = false;
          showSurface();
        }
      });
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

// What each encoding layer means: [colour, text] rows (point layers get
// round swatches), or one line of explanation.
const LAYER_LEGENDS = {
  'orientation singularities': { title: 'Orientation singularities (cross field)', dots: true,
    rows: [['#1f6fdd', 'valence 3 · index +\u00bc'], ['#d8342c', 'valence 5 · index \u2212\u00bc']] },
  'position singularities': { title: 'Position singularities', dots: true,
    rows: [['#1b9e4b', 'faces where the position lattice does not close up: the extraction mends the mesh there']] },
  'non-quad faces': { title: 'Non-quad faces', dots: true, rows: [['#f28e2b', 'triangle'], ['#8e44ad', 'five or more sides']] },
  'principal directions': { title: 'Principal curvature directions', rows: [['#c0392b', 'most curved'], ['#1f5fbf', 'least curved']] },
  'feature vertices': { title: 'Feature vertices', dots: true, rows: [['#e68a00', 'on sharp edges and corners (kept by the remesher)']] },
  'position field': { title: 'Position field', dots: true, rows: [['#ff7f0e', 'lattice points: where output vertices go']] },
  'cross field': { title: 'Cross field', rows: [['#1d2330', 'the four directions the quads follow']] },
  parametrization: { title: 'Parametrization (integer-grid map)',
    rows: [['#c8cdd8', 'checkerboard of (u, v): one square = one target edge, lines at integer u, v'], ['#e02dc8', 'flipped triangles (parametric area \u2264 0)']] },
  'parametrization cones': { title: 'Cones of the map', dots: true,
    rows: [['#1f6fdd', 'index +\u00bc (valence 3)'], ['#d8342c', 'index \u2212\u00bc (valence 5)']] },
  boundary: { title: 'Boundary', rows: [['#d8342c', 'open edges (holes)']] },
};

function updateLayerLegend() {
  const el = $('layer-legend');
  const shown = LAYERS.filter((l) => LAYER_LEGENDS[l.name] && l.visible && available.has(l.name));
  el.replaceChildren(...shown.map((l) => {
    const { title, rows, dots } = LAYER_LEGENDS[l.name];
    const block = document.createElement('div');
    block.className = 'legend-block';
    block.dataset.layer = l.name;
    const h = document.createElement('div');
    h.className = 'legend-name';
    h.textContent = title;
    block.append(h);
    for (const [color, text] of rows) {
      const row = document.createElement('div');
      row.className = 'legend-row';
      const swatch = document.createElement('span');
      swatch.className = dots ? 'legend-dot' : 'legend-line';
      swatch.style.background = color;
      swatch.dataset.color = color;
      const label = document.createElement('span');
      label.textContent = text;
      row.append(swatch, label);
      block.append(row);
    }
    return block;
  }));
  el.hidden = shown.length === 0;
}

function updateLegend() {
  updateLayerLegend();
  const legend = viewer && viewer.legend();
  const el = $('legend');
  el.hidden = !legend;
  if (!legend) return;
  el.querySelector('.legend-name').textContent = legend.name;
  el.querySelector('.legend-bar').style.background = `linear-gradient(to right, ${legend.stops.join(', ')})`;
  el.querySelector('.min').textContent = formatNumber(legend.min);
  el.querySelector('.max').textContent = formatNumber(legend.max);
  el.querySelector('.mid').textContent = legend.colormap === 'face-degree' ? '4 · 5' : formatNumber((legend.min + legend.max) / 2);
  if (legend.colormap === 'face-degree') el.querySelector('.max').textContent = '6+';
  if (legend.colormap === 'categories') {
    const layout = legend.name.startsWith('layout regions');
    el.querySelector('.min').textContent = layout ? 'fine' : 'grey: discarded';
    el.querySelector('.mid').textContent = '';
    el.querySelector('.max').textContent = layout ? '' : 'colour: one per region';
    if (layout) {
      // Four swatches: fine, red, orange, yellow (categories 0, 6, 8, 11;
      // src/web/layout_glue.rs REGION_*).
      const swatches = [0, 6, 8, 11].map((c, i) => `${legend.stops[c]} ${25 * i}% ${25 * (i + 1)}%`);
      el.querySelector('.legend-bar').style.background = `linear-gradient(to right, ${swatches.join(', ')})`;
    }
  }
}

const formatNumber = (x) => Number(x.toPrecision(3)).toString();
const rgba = (hex) => new Uint8Array([1, 3, 5].map((i) => parseInt(hex.slice(i, i + 2), 16)).concat(255));
const layerColor = (name) => rgba(LAYERS.find((l) => l.name === name).color);
const dpr = () => window.devicePixelRatio || 1;

// ---------------------------------------------------------------- results

let meshInfo = null; // { name, vertices } of the mesh on screen
// The camera from the share link (`cam=` yaw,pitch,distance,target xyz).
let linkCamera = params.get('cam') ? params.get('cam').split(',').map(Number) : null;
let inputSurface = null; // the import's arrays, kept to swap back
// Result surfaces by layer name ('quad mesh faces', 'limit surface'):
// { positions, triangles, normals, scalar } from the worker.
let extraSurfaces = {};
let drawnSurface = 'input';

// The drawn surface is the input's (with the chosen scalar), or one result
// surface with its own colouring (faces by degree, limit surface by its
// signed error) while that layer is on; at most one is on.
function showSurface() {
  if (!viewer || !inputSurface) return;
  const on = LAYERS.find((l) => l.kind === 'surface' && l.visible && extraSurfaces[l.name]);
  const name = on ? on.name : 'input';
  const s = on ? extraSurfaces[name] : inputSurface;
  try {
    viewer.replace_surface(s.positions, s.triangles, s.normals);
    drawnSurface = name;
    if (on) {
      const e = s.scalar;
      if (e) viewer.set_scalar(e.name, e.values, e.min, e.max, e.colormap);
      else viewer.clear_scalar();
      if (s.colors) viewer.set_vertex_colors(s.colors);
      if (s.uv) viewer.set_uv(s.uv);
    } else {
      setScalar(scalarName);
    }
  } catch (error) {
    showError(`could not show the ${name} surface: ${error.message}`);
  }
  updateLayersPanel();
  requestRender();
}

function showMesh(name, mesh) {
  available.clear();
  LAYERS = BASE_LAYERS.map((l) => ({ ...l, visible: LAYERS.find((x) => x.name === l.name)?.visible ?? l.visible }));
  scalars = {};
  scalarName = null;
  $('pick-info').hidden = true;
  if (!viewer) return;
  try {
    inputSurface = mesh;
    extraSurfaces = {};
    drawnSurface = 'input';
    compareHidden = [];
    viewer.set_mesh(mesh.positions, mesh.triangles, mesh.normals);
    viewer.set_edges('polygon edges', mesh.polygonEdges, layerColor('polygon edges'));
    viewer.set_edges('boundary', mesh.boundaryEdges, layerColor('boundary'));
    // Dense meshes are a solid mass of edges at first sight; show their edges on demand (E).
    LAYERS.find((l) => l.name === 'polygon edges').visible = mesh.polygonEdges.length / 2 <= DENSE;
    for (const layer of LAYERS) viewer.set_layer_visible(layer.name, layer.visible);
    available.add('surface').add('polygon edges').add('picked');
    addParametrizationLayer();
    if (mesh.boundaryEdges.length) available.add('boundary');
    meshInfo = { name, vertices: mesh.positions.length / 3 };
    // The link's camera, once, for the linked sample.
    if (linkCamera && lastInput?.sample === params.get('sample')) {
      if (!viewer.set_camera_state(new Float32Array(linkCamera))) showError('the link\u2019s camera is not readable');
      linkCamera = null;
    }
    hideLoading();
  } catch (error) {
    showError(`could not show ${name}: ${error.message}`);
  }
  updateLayersPanel();
  requestRender();
}

// The parametrization layer is offered from the import on and computed in
// the worker when first switched on (after a running pipeline job ends).
// `mapKey` is what the shown map was computed from (gridMapKey of the
// parameters: analysis, sizing and target, alignment); a parameter change
// that leaves it the same keeps the map.
let paramWanted = false;
let mapKey = null;
function currentMapKey() {
  try { return gridMapKey(paramValues); } catch { return null; }
}
function addParametrizationLayer() {
  const was = LAYERS.find((l) => l.name === PARAM_LAYER);
  if (!was) LAYERS.push({ name: PARAM_LAYER, label: 'Parametrization (computed on demand)', kind: 'surface', ...STYLES[PARAM_LAYER], visible: false });
  available.add(PARAM_LAYER);
}
function dropParametrization() {
  delete extraSurfaces[PARAM_LAYER];
  window.quadrille.lastParam = null;
  mapKey = null;
  if (viewer) viewer.set_points('parametrization cones', new Float32Array(0), new Uint8Array(4), 1);
  available.delete('parametrization cones');
  LAYERS = LAYERS.filter((l) => l.name !== 'parametrization cones');
  const layer = LAYERS.find((l) => l.name === PARAM_LAYER);
  if (layer) layer.label = 'Parametrization (computed on demand)';
}
// The line, point and surface layers only one mode's stages make (the
// other stages' layers are replaced by the next run's).
const MODE_LAYERS = {
  local: ['cross field', 'orientation singularities', 'smooth regions', 'position field', 'position singularities'],
  global: [],
};
let shownMode = 'local'; // the mode of the layers on screen
// The stage whose result drew each line, point and surface layer.
const layerStage = {};
function dropLayersOfMode(mode) {
  dropLayers(MODE_LAYERS[mode]);
  // The global mode's map is the pipeline's: a local run computes its own on demand.
  if (mode === 'global') dropParametrization();
  updateLayersPanel();
  requestRender();
}
// A run that failed in `stage`: the layers of that stage and the later
// ones are an earlier run's (another mode's, other parameters'), so they
// go, and what stays on screen is what this input and these parameters
// gave before the failure.
function dropLayersFrom(stage) {
  const order = stagesOfMode();
  const from = order.indexOf(stage);
  if (from < 0) return;
  const stale = Object.keys(layerStage).filter((name) => {
    const i = order.indexOf(layerStage[name]);
    return i < 0 || i >= from;
  });
  dropLayers(stale);
  if (stale.includes(PARAM_LAYER)) dropParametrization();
  updateLayersPanel();
  requestRender();
}
function dropLayers(names) {
  for (const name of names) {
    delete layerStage[name];
    const layer = LAYERS.find((l) => l.name === name);
    if (!layer) continue;
    if (viewer) {
      if (layer.kind === 'points') viewer.set_points(name, new Float32Array(0), new Uint8Array(4), 1);
      else if (layer.kind === 'lines' && STYLES[name]?.glyph) viewer.set_glyphs(name, new Float32Array(0), new Uint8Array(4), 2, new Uint32Array());
      else if (layer.kind === 'lines') viewer.set_lines(name, new Float32Array(0), new Uint8Array(4));
    }
    if (layer.kind === 'surface') delete extraSurfaces[name];
    available.delete(name);
    LAYERS = LAYERS.filter((l) => l.name !== name);
    if (drawnSurface === name) showSurface();
  }
}
function requestParametrization() {
  paramWanted = true;
  if (current || !lastInput) return; // started when the running job ends
  if (!workerHasInput) { rerun(); return; }
  paramWanted = false;
  window.quadrille.paramJobs = (window.quadrille.paramJobs || 0) + 1;
  const flag = self.crossOriginIsolated ? new SharedArrayBuffer(4) : null;
  current = { job: nextJob++, name: lastInput.name, started: performance.now(), stages: {}, flag, deadline: 0, param: true, mapKey: currentMapKey() };
  resetStageBars('parametrization', ['parametrization']);
  showProgress(`${lastInput.name}: parametrization…`, 0, 'parametrization');
  setStatus(`${lastInput.name}: ${STAGE_TEXT.parametrization}…`);
  worker.postMessage({ type: 'param', job: current.job, cancelFlag: flag });
}
function afterJob() {
  const layer = LAYERS.find((l) => l.name === PARAM_LAYER);
  if (paramWanted && layer && layer.visible && !extraSurfaces[PARAM_LAYER]) requestParametrization();
}

// Each stage's result as soon as the worker has it: the import brings the
// mesh; later stages bring scalars, line layers and point layers by name.
function onStage(job, result) {
  job.stages[result.stage] = result.ms;
  if (result.stage === 'import') {
    window.quadrille.lastImport = result.report;
    window.quadrille.lastError = null;
    showReport(result.report);
    updateTargetControl();
    showMesh(job.name, result.mesh);
    return;
  }
  if (!viewer) return;
  for (const [name, s] of Object.entries(result.scalars || {})) {
    scalars[name] = s;
    available.add('scalar');
  }
  for (const [name, l] of Object.entries(result.lines || {})) {
    // Field glyphs are drawn at screen density (the glyph spacing control).
    if (STYLES[name]?.glyph) viewer.set_glyphs(name, l.segments, l.colors, 2, l.triangles || new Uint32Array());
    else viewer.set_lines(name, l.segments, l.colors);
    addLayer(name, 'lines');
    layerStage[name] = result.stage;
  }
  for (const [name, p] of Object.entries(result.points || {})) {
    viewer.set_points(name, p.positions, p.colors, (STYLES[name]?.size || 6) * dpr());
    addLayer(name, 'points');
    layerStage[name] = result.stage;
    // Nothing to show (the global mode's pure quads have no non-quad
    // faces): no legend, and the layer's box greys out.
    if (p.positions.length === 0) available.delete(name);
  }
  if (result.metrics) showMetrics(result.metrics, null);
  if (result.param) {
    window.quadrille.lastParam = result.param;
    mapKey = job.mapKey ?? null;
    const layer = LAYERS.find((l) => l.name === PARAM_LAYER);
    if (layer) layer.label = 'Parametrization';
  }
  if (result.limitSurface) showMetrics(null, result.limitSurface);
  if (result.surface) {
    const name = result.surface.name;
    extraSurfaces[name] = result.surface;
    layerStage[name] = result.stage;
    const was = LAYERS.find((l) => l.name === name);
    // The quad mesh's faces are shown when they arrive (the input's surface
    // would hide its edges, which cut below a curved input).
    const visible = was ? was.visible : !STYLES[name]?.hidden && !LAYERS.some((l) => l.kind === 'surface' && l.visible);
    LAYERS = LAYERS.filter((l) => l.name !== name);
    LAYERS.push({ name, label: name[0].toUpperCase() + name.slice(1), kind: 'surface', ...STYLES[name], visible });
    if (name === PARAM_LAYER) { const i = LAYERS.length - 1; LAYERS[i] = { ...LAYERS[i], label: 'Parametrization' }; }
    available.add(name);
    if (visible || drawnSurface === name) showSurface();
  }
  if (result.scalars && !scalarName && !design.active) setScalar(Object.keys(result.scalars)[0]);
  if (design.active) hideForDesign();
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
let workerHasInput = false; // whether the worker's session holds the current input (parameter changes re-use it)
let lastInput = null; // { name, bytes (a copy), sample } of the input on screen
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
  workerHasInput = false;
  for (const { reject } of pending.values()) reject(new Error('the worker was restarted'));
  pending.clear();
  startWorker();
}

// Requests answered with { type: 'reply', id }: exports and the schema.
const pending = new Map(); // id → { resolve, reject }
let nextRequest = 1;
function request(message) {
  return new Promise((resolve, reject) => {
    const id = nextRequest++;
    pending.set(id, { resolve, reject });
    worker.postMessage({ ...message, id });
  });
}

function onWorkerMessage(m) {
  if (m.type === 'reply') {
    const p = pending.get(m.id);
    pending.delete(m.id);
    if (p) (m.error !== undefined ? p.reject(new Error(m.error)) : p.resolve(m.value));
    return;
  }
  if (m.type === 'error' && m.fatal) replaceWorker();
  if (!current || m.job !== current.job) return;
  const job = current;
  switch (m.type) {
    case 'progress': {
      showProgress(`${job.name}: ${m.stage} — ${m.text}`, m.fraction, m.stage);
      if (job.stage !== m.stage) {
        job.stage = m.stage;
        setStatus(`${job.name}: ${STAGE_TEXT[m.stage] || m.stage}…`);
      }
      break;
    }
    case 'stage':
      try {
        onStage(job, m);
      } catch (error) {
        finishJob(`${job.name}: ${error.message}`, true);
      }
      break;
    case 'done':
      window.quadrille.lastRun = m.summary;
      // The longest wait between two progress reports per stage, measured in the worker.
      window.quadrille.progressGapsMs = m.progressGapsMs;
      workerHasInput = true;
      if (m.summary.metrics) showMetrics(m.summary.metrics, m.summary.limit_surface);
      showTimings(job.stages);
      {
        const summary = resultSummary(m.summary);
        if (summary) finishJob(`${job.name}: ${summary}`);
        else finishJob(`No quads came out of ${job.name}: the run finished but the quad mesh is empty (the input is too small or degenerate for this target).`, true);
      }
      break;
    case 'param-done': {
      const p = window.quadrille.lastParam;
      const m = p && p.measures;
      job.stages.parametrization = p ? p.ms : 0;
      finishJob(m ? `${job.name}: parametrization · ${m.cones} cones · ${m.flipped_triangles} flipped triangles · ${(p.ms / 1000).toFixed(1)} s` : `${job.name}: parametrization done`);
      break;
    }
    case 'cancelled':
      finishJob(`${job.name}: cancelled.`);
      break;
    case 'error':
      if (!job.param && job.stage) dropLayersFrom(job.stage);
      // The file was read but the remesher could not make quads of it.
      if (job.stages.import !== undefined && !m.fatal) {
        const reason = m.message.startsWith(`${job.name}: `) ? m.message.slice(job.name.length + 2) : m.message;
        finishJob(`No quads came out of ${job.name}: ${reason}.`, true);
      } else {
        finishJob(m.message, true);
      }
      break;
  }
}

function finishJob(message, isError = false) {
  const wasParam = current && current.param;
  if (current) clearTimeout(current.deadline);
  current = null;
  hideProgress();
  if (isError) showError(message);
  else setStatus(message);
  // A cancelled or failed parametrization is not asked again by itself.
  if (wasParam) {
    paramWanted = false;
    const layer = LAYERS.find((l) => l.name === PARAM_LAYER);
    if (layer && !extraSurfaces[PARAM_LAYER] && layer.visible) { layer.visible = false; updateLayersPanel(); }
  } else if (!isError) afterJob();
}

function run(name, bytes, sample = null) {
  if (current) cancel({ quiet: true });
  if (design.active) toggleDesign();
  design.reset();
  lastInput = { name, bytes: bytes.slice(0), sample };
  window.quadrille.progressGapsMs = {};
  workerHasInput = false;
  const flag = self.crossOriginIsolated ? new SharedArrayBuffer(4) : null;
  current = { job: nextJob++, name, started: performance.now(), stages: {}, flag, deadline: 0, mapKey: currentMapKey(), mode: currentMode() };
  shownMode = currentMode();
  resetStageBars();
  showProgress(`${name}: reading ${(bytes.byteLength / 1024).toFixed(0)} KiB…`, 0);
  setStatus(`${name}: ${STAGE_TEXT.import}…`);
  worker.postMessage({ type: 'run', job: current.job, name, bytes, params: paramValues, cancelFlag: flag }, [bytes]);
}

// New parameters: the worker keeps the input and every stage before the
// first one they change; without it (a restarted worker) the input runs again.
function rerun() {
  if (!lastInput) return;
  if (!workerHasInput) {
    run(lastInput.name, lastInput.bytes.slice(0), lastInput.sample);
    return;
  }
  // A running parametrization is asked again after the pipeline run.
  if (current && current.param) paramWanted = true;
  if (current) cancel({ quiet: true });
  // The map depends on the analysis, sizing, target and alignment
  // parameters: dropped (and recomputed on demand) only when they change.
  if (extraSurfaces[PARAM_LAYER] && currentMapKey() !== mapKey) {
    dropParametrization();
    if (LAYERS.find((l) => l.name === PARAM_LAYER)?.visible) paramWanted = true;
  }
  // Another remeshing mode: the layers only the other mode makes go.
  if (shownMode !== currentMode()) dropLayersOfMode(shownMode);
  shownMode = currentMode();
  const flag = self.crossOriginIsolated ? new SharedArrayBuffer(4) : null;
  current = { job: nextJob++, name: lastInput.name, started: performance.now(), stages: {}, flag, deadline: 0, mapKey: currentMapKey(), mode: currentMode() };
  resetStageBars('analysis');
  showProgress(`${lastInput.name}: new parameters…`, 0);
  setStatus(`Parameters changed: running ${lastInput.name} again from the first stage they affect…`);
  worker.postMessage({ type: 'params', job: current.job, params: paramValues, cancelFlag: flag });
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
    run(`${name}.obj`, await response.arrayBuffer(), name);
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
    const regions = drawnSurface === 'smooth regions' ? extraSurfaces['smooth regions'] : null;
    let text = `vertex ${hit.vertex} · triangle ${hit.triangle} · (${[...p].map((x) => x.toFixed(3)).join(', ')})`;
    if (regions) {
      // The smooth-region surface has one triangle per input face.
      const r = regions.faceRegion[hit.triangle];
      text += r < 0 ? ' · no smooth region'
        : ` · smooth region ${r}: significance ${formatNumber(regions.regionSignificance[r])}°${regions.regionFiltered[r] ? '' : ' (discarded)'}`;
      window.quadrille.lastPickRegion = r < 0 ? null : { region: r, significance: regions.regionSignificance[r], filtered: !!regions.regionFiltered[r] };
    } else if (value !== undefined) {
      const legend = viewer.legend();
      const what = legend ? legend.name : 'value';
      const degree = { 3: 'triangle', 4: 'quad', 5: 'pentagon' };
      const shown = what === 'face degree' ? `${value} (${degree[value] || `${value} sides`})` : formatNumber(value);
      text += ` · ${what} ${shown}`;
    }
    if (drawnSurface !== 'input' && !regions) {
      // Vertex and triangle indices of a result surface's drawing mean nothing to the user.
      text = `${drawnSurface} · (${[...p].map((x) => x.toFixed(3)).join(', ')})${text.slice(text.indexOf(')') + 1)}`;
    }
    info.textContent = text;
    info.hidden = false;
    window.quadrille.lastPick = { vertex: hit.vertex, triangle: hit.triangle, point: [...p] };
  }
  requestRender();
}

function attachInput() {
  const pointers = new Map(); // id → { x, y }
  let press = null; // { x, y, time, moved } of a single-pointer press, for click-to-pick
  const scale = () => canvas.width / canvas.getBoundingClientRect().width;

  // In the design mode the left button places anchors (design.js); the
  // view turns with the right button or Alt+drag, Shift+right-drag pans.
  let designing = false; // the current press belongs to the design mode
  canvas.addEventListener('pointerdown', (e) => {
    canvas.setPointerCapture(e.pointerId);
    designing = design.active && pointers.size === 0 && e.button === 0 && !e.altKey && design.onDown(e);
    if (designing) return;
    pointers.set(e.pointerId, { x: e.clientX, y: e.clientY });
    press = pointers.size === 1 ? { x: e.clientX, y: e.clientY, time: performance.now(), moved: false } : null;
  });
  canvas.addEventListener('pointermove', (e) => {
    if (designing) { design.onDrag(e); return; }
    const last = pointers.get(e.pointerId);
    if (!last) {
      if (design.active && pointers.size === 0) design.onHoverMove(e);
      return;
    }
    const k = scale();
    if (pointers.size === 1) {
      const dx = (e.clientX - last.x) * k;
      const dy = (e.clientY - last.y) * k;
      if (press && Math.hypot(e.clientX - press.x, e.clientY - press.y) > 4) press.moved = true;
      if (design.active ? e.shiftKey : e.buttons & 6 || e.shiftKey) viewer.pan(dx, dy);
      else viewer.orbit(dx, dy);
    } else if (pointers.size === 2) {
      const [a, b] = [...pointers.values()];
      const other = a === last ? b : a;
      const before = Math.hypot(last.x - other.x, last.y - other.y);
      const after = Math.hypot(e.clientX - other.x, e.clientY - other.y);
      if (before > 0 && after > 0) {
        // Pinch: zoom toward the point between the fingers.
        const rect = canvas.getBoundingClientRect();
        viewer.zoom_at(before / after, ((e.clientX + other.x) / 2 - rect.left) * k, ((e.clientY + other.y) / 2 - rect.top) * k);
      }
      viewer.pan((e.clientX - last.x) * k / 2, (e.clientY - last.y) * k / 2);
    }
    pointers.set(e.pointerId, { x: e.clientX, y: e.clientY });
    requestRender();
  });
  const release = (e) => {
    if (designing) { designing = false; design.onUp(e); return; }
    if (!pointers.delete(e.pointerId)) return;
    if (press && !design.active && !press.moved && e.type === 'pointerup' && e.button === 0 && performance.now() - press.time < 600) {
      pickAt(e.clientX, e.clientY);
    }
    press = null;
  };
  canvas.addEventListener('pointerup', release);
  canvas.addEventListener('pointercancel', release);
  canvas.addEventListener('contextmenu', (e) => e.preventDefault());
  canvas.addEventListener('wheel', (e) => {
    e.preventDefault();
    if (design.active && !e.shiftKey) { design.onWheel(e); return; }
    const lines = e.deltaMode === 1 ? 16 : e.deltaMode === 2 ? 400 : 1;
    // Shift turns the wheel sideways in some browsers.
    const delta = e.deltaY || (e.shiftKey ? e.deltaX : 0);
    const rect = canvas.getBoundingClientRect();
    const k = canvas.width / rect.width;
    viewer.zoom_at(Math.exp(Math.max(-200, Math.min(200, delta * lines)) * 0.0015), (e.clientX - rect.left) * k, (e.clientY - rect.top) * k);
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
    // The view and, over it, the legends as the page shows them.
    const out = document.createElement('canvas');
    out.width = canvas.width;
    out.height = canvas.height;
    const ctx = out.getContext('2d');
    ctx.drawImage(canvas, 0, 0);
    drawLegends(ctx, canvas.width / canvas.getBoundingClientRect().width);
    out.toBlob((blob) => (blob ? resolve(blob) : reject(new Error('the canvas gave no image'))), 'image/png');
  });
}

// Paints the visible legend boxes onto a 2D context of the canvas's size
// (`k`: drawing-buffer pixels per CSS pixel), at their places on the page.
function drawLegends(ctx, k) {
  const origin = canvas.getBoundingClientRect();
  const box = (el) => {
    const r = el.getBoundingClientRect();
    return [(r.left - origin.left) * k, (r.top - origin.top) * k, r.width * k, r.height * k];
  };
  const text = (el, bold = false) => {
    const [x, y, , h] = box(el);
    ctx.font = `${bold ? '600 ' : ''}${parseFloat(getComputedStyle(el).fontSize) * k}px system-ui, sans-serif`;
    ctx.fillStyle = '#1d2330';
    ctx.textBaseline = 'middle';
    ctx.fillText(el.textContent, x, y + h / 2);
  };
  for (const id of ['legend', 'layer-legend']) {
    const el = $(id);
    if (el.hidden) continue;
    const [x, y, w, h] = box(el);
    ctx.fillStyle = '#ffffff';
    ctx.fillRect(x, y, w, h);
    for (const name of el.querySelectorAll('.legend-name')) text(name, true);
    for (const row of el.querySelectorAll('.legend-row')) {
      const swatch = row.firstChild;
      const [sx, sy, sw, sh] = box(swatch);
      ctx.fillStyle = swatch.dataset.color;
      if (swatch.className === 'legend-dot') {
        ctx.beginPath();
        ctx.arc(sx + sw / 2, sy + sh / 2, sw / 2, 0, 2 * Math.PI);
        ctx.fill();
      } else {
        ctx.fillRect(sx, sy, sw, sh);
      }
      text(row.lastChild);
    }
    const bar = el.querySelector('.legend-bar');
    if (bar) {
      const [bx, by, bw, bh] = box(bar);
      const legend = viewer.legend();
      if (legend) {
        const g = ctx.createLinearGradient(bx, 0, bx + bw, 0);
        legend.stops.forEach((c, i) => g.addColorStop(i / (legend.stops.length - 1), c));
        ctx.fillStyle = g;
        ctx.fillRect(bx, by, bw, bh);
      }
      for (const span of el.querySelectorAll('.legend-range span')) if (span.textContent) text(span);
    }
  }
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
window.quadrille.failStageForTesting = (stage) => worker.postMessage({ type: 'fail-stage-for-testing', stage });
// The next job's `stage` waits after its first progress report until it is cancelled (worker.js).
window.quadrille.holdStageForTesting = (stage) => {
  if (!self.crossOriginIsolated) throw new Error('holding a stage needs cross-origin isolation');
  worker.postMessage({ type: 'hold-stage-for-testing', stage });
};
window.quadrille.panicForTesting = () => {
  current = { job: nextJob++, name: 'panic test', started: performance.now(), stages: {}, flag: null, deadline: 0 };
  worker.postMessage({ type: 'panic-for-testing', job: current.job });
};


// ---------------------------------------------------------------- parameters

// The panel is generated from the schema the wasm module exports
// (src/params_schema.rs: path, one-line help, kind, range, default), so
// every parameter of the pipeline is here with its default.
let schema = []; // [{ path, help, kind, min, max, options, nullable, default }]
let paramValues = {}; // the full parameter object sent to the worker
let paramsTimer = 0;

const getPath = (obj, path) => path.split('.').reduce((o, k) => (o == null ? undefined : o[k]), obj);
function setPath(obj, path, value) {
  const keys = path.split('.');
  let o = obj;
  for (const k of keys.slice(0, -1)) o = o[k] ??= {};
  o[keys[keys.length - 1]] = value;
}
const same = (a, b) => JSON.stringify(a) === JSON.stringify(b);
const defaultParams = () => {
  const p = {};
  for (const e of schema) setPath(p, e.path, structuredClone(e.default));
  return p;
};
// { path: value } of the parameters that differ from their defaults.
const changedParams = () => Object.fromEntries(schema
  .filter((e) => !same(getPath(paramValues, e.path), e.default))
  .map((e) => [e.path, getPath(paramValues, e.path)]));

function paramInput(e) {
  const value = getPath(paramValues, e.path);
  let input;
  if (e.kind === 'bool') {
    input = document.createElement('input');
    input.type = 'checkbox';
    input.checked = !!value;
  } else if (e.kind === 'choice') {
    input = document.createElement('select');
    for (const o of e.options) {
      const option = document.createElement('option');
      option.value = option.textContent = o;
      option.selected = o === value;
      input.append(option);
    }
  } else if (e.kind === 'json') {
    input = document.createElement('input');
    input.type = 'text';
    input.value = JSON.stringify(value);
  } else {
    input = document.createElement('input');
    input.type = 'number';
    if (e.min !== undefined) input.min = e.min;
    if (e.max !== undefined) input.max = e.max;
    input.step = e.kind === 'integer' ? '1' : 'any';
    input.value = value ?? '';
    if (e.nullable) input.placeholder = 'auto';
  }
  input.id = `param-${e.path}`;
  input.dataset.path = e.path;
  input.addEventListener('change', () => {
    const { value: v, error } = readInput(e, input.type === 'checkbox' ? input.checked : input.value);
    const row = input.closest('.param');
    // An invalid value stays in the field, explained next to it, and is not run.
    showFieldError(row.querySelector('.field-error'), input, error);
    row.classList.toggle('invalid', !!error);
    if (error) return;
    commitParam(e, v);
  });
  return input;
}

// Sets a parameter from a control, keeps the other control of the same
// parameter in step, and re-runs shortly after.
function commitParam(e, v) {
  setPath(paramValues, e.path, v);
  const input = document.getElementById(`param-${e.path}`);
  if (input) {
    const row = input.closest('.param');
    row.classList.toggle('changed', !same(v, e.default));
    row.classList.remove('invalid');
    showFieldError(row.querySelector('.field-error'), input, null);
    if (input.type !== 'checkbox' && document.activeElement !== input) input.value = e.kind === 'json' ? JSON.stringify(v) : v ?? '';
  }
  if (e.path === TARGET_PATH) updateTargetControl();
  if (e.path === MODE_PATH) updateModeControl();
  clearTimeout(paramsTimer);
  paramsTimer = setTimeout(rerun, 250);
}

function showFieldError(el, input, error) {
  if (!el) return;
  el.hidden = !error;
  el.textContent = error || '';
  if (error) input.setAttribute('aria-invalid', 'true');
  else input.removeAttribute('aria-invalid');
}

// The target vertex count's valid range for the mesh on screen (the
// pipeline's check_target: at least 8, at most a third of the input's vertices).
const MIN_TARGET = 8;
function targetRange() {
  const n = window.quadrille.lastImport?.vertices;
  return n ? { min: MIN_TARGET, max: Math.max(MIN_TARGET, Math.floor(n / 3)), input: n } : null;
}

// `{ value }` of a control's raw value (text, or a checkbox's state), or
// `{ error }` saying why it is not valid.
function readInput(e, raw) {
  if (e.kind === 'bool') return { value: !!raw };
  if (e.kind === 'choice') return { value: raw };
  if (e.kind === 'json') {
    try { return { value: JSON.parse(raw) }; } catch (error) { return { error: `Not valid JSON: ${error.message}.` }; }
  }
  const text = String(raw).trim();
  if (text === '') return e.nullable ? { value: null } : { error: 'A value is needed here.' };
  const x = Number(text);
  if (!Number.isFinite(x)) return { error: `“${text}” is not a number.` };
  if (e.kind === 'integer' && !Number.isInteger(x)) return { error: `${text} is not a whole number.` };
  if (e.path === TARGET_PATH && targetRange()) {
    const r = targetRange();
    if (x < r.min || x > r.max) {
      return { error: `${x.toLocaleString('en-US')} is outside what this mesh supports: between ${r.min} and ${r.max.toLocaleString('en-US')} (a third of its ${r.input.toLocaleString('en-US')} input vertices).` };
    }
  }
  if ((e.min !== undefined && x < e.min) || (e.max !== undefined && x > e.max)) {
    return { error: `${text} is out of range: between ${e.min} and ${e.max}.` };
  }
  return { value: x };
}

// ---------------------------------------------------------------- target vertex count

const TARGET_PATH = 'sizing.target_vertex_count';
const targetEntry = () => schema.find((e) => e.path === TARGET_PATH);
// The slider is logarithmic over the valid range.
function sliderToCount(t, r) {
  return Math.round(Math.exp(Math.log(r.min) + (Math.log(r.max) - Math.log(r.min)) * t / 1000));
}
function countToSlider(n, r) {
  if (r.max <= r.min) return 0;
  return Math.round(1000 * (Math.log(Math.min(r.max, Math.max(r.min, n))) - Math.log(r.min)) / (Math.log(r.max) - Math.log(r.min)));
}

function updateTargetControl() {
  const number = $('target-count');
  const slider = $('target-slider');
  const r = targetRange();
  const value = getPath(paramValues, TARGET_PATH);
  const auto = r ? Math.round(r.input / 16) : null;
  number.placeholder = auto ? `auto (${auto.toLocaleString('en-US')})` : 'auto';
  if (document.activeElement !== number && number.getAttribute('aria-invalid') !== 'true') number.value = value ?? '';
  if (r) {
    number.min = r.min;
    number.max = r.max;
    slider.disabled = false;
    slider.value = countToSlider(value ?? auto, r);
  } else {
    slider.disabled = true;
  }
  const edge = getPath(paramValues, 'sizing.edge_length');
  $('target-note').textContent = edge != null
    ? `Ignored while sizing.edge_length is set (${edge}).`
    : r ? `Empty: auto, the input's vertices / 16. Valid for this mesh: ${r.min}–${r.max.toLocaleString('en-US')}.` : '';
}

// The remeshing mode, next to the target count: the same parameter as
// remesh.mode in the panel.
const modeEntry = () => schema.find((e) => e.path === MODE_PATH);
function updateModeControl() {
  const mode = currentMode();
  $('remesh-mode').value = mode;
  $('mode-note').textContent = mode === 'global'
    ? 'Pure quads from a global integer-grid map (Ebke et al. 2014): its cones are the singularities.'
    : 'Quad-dominant, from Instant Meshes\u2019 local fields as in the thesis.';
}
function attachModeControl() {
  $('remesh-mode').addEventListener('change', () => {
    const e = modeEntry();
    if (e) commitParam(e, $('remesh-mode').value);
  });
}

function attachTargetControl() {
  const number = $('target-count');
  const slider = $('target-slider');
  slider.addEventListener('input', () => {
    const r = targetRange();
    if (!r) return;
    number.value = sliderToCount(Number(slider.value), r);
    showFieldError($('target-error'), number, null);
  });
  slider.addEventListener('change', () => {
    const r = targetRange();
    if (r && targetEntry()) commitParam(targetEntry(), sliderToCount(Number(slider.value), r));
  });
  number.addEventListener('change', () => {
    const e = targetEntry();
    if (!e) return;
    const { value, error } = readInput(e, number.value);
    showFieldError($('target-error'), number, error);
    if (!error) commitParam(e, value);
  });
}

// ---------------------------------------------------------------- parameter search

// Shows the parameters whose path or help has every word of the query,
// opening their groups; an empty query shows all, groups collapsed.
function filterParams() {
  const words = $('param-search').value.toLowerCase().split(/\s+/).filter(Boolean);
  let shown = 0;
  for (const group of document.querySelectorAll('#params .group')) {
    let any = false;
    for (const row of group.querySelectorAll('.param')) {
      const text = `${row.dataset.path} ${row.querySelector('.help').textContent}`.toLowerCase();
      const match = words.every((w) => text.includes(w));
      row.hidden = !match;
      if (match) any = true;
      if (match && words.length) shown++;
    }
    group.hidden = !any;
    group.open = words.length > 0 && any;
  }
  if (words.length) $('params-panel').open = true;
  $('param-search-note').textContent = words.length ? `${shown} match${shown === 1 ? '' : 'es'}` : '';
}

function buildParamsPanel() {
  const groups = new Map();
  for (const e of schema) {
    const group = e.path.split('.')[0];
    if (!groups.has(group)) groups.set(group, []);
    groups.get(group).push(e);
  }
  $('params').replaceChildren(...[...groups].map(([group, entries]) => {
    const details = document.createElement('details');
    details.className = 'group';
    const summary = document.createElement('summary');
    summary.textContent = `${group} (${entries.length})`;
    details.append(summary);
    for (const e of entries) {
      const row = document.createElement('div');
      row.className = 'param';
      row.dataset.path = e.path;
      row.classList.toggle('changed', !same(getPath(paramValues, e.path), e.default));
      const input = paramInput(e);
      const label = document.createElement('label');
      label.htmlFor = input.id;
      label.textContent = e.path.split('.').slice(1).join('.');
      const help = document.createElement('div');
      help.className = 'help';
      const range = e.min !== undefined ? ` Range ${e.min}–${e.max}.` : '';
      help.textContent = `${e.help}${range} `;
      const def = document.createElement('span');
      def.className = 'default';
      def.textContent = `Default: ${e.default === null ? 'auto' : JSON.stringify(e.default)}.`;
      help.append(def);
      const error = document.createElement('div');
      error.className = 'field-error';
      error.setAttribute('role', 'alert');
      error.hidden = true;
      row.append(label, input, error, help);
      details.append(row);
    }
    return details;
  }));
  if ($('param-search').value) filterParams();
  updateTargetControl();
  updateModeControl();
}

// Parameters from the address (`p=` JSON of { path: value }), over the defaults.
function paramsFromUrl() {
  paramValues = defaultParams();
  const text = params.get('p');
  if (!text) return;
  try {
    const changed = JSON.parse(text);
    for (const [path, value] of Object.entries(changed)) {
      if (schema.some((e) => e.path === path)) setPath(paramValues, path, value);
    }
  } catch (error) {
    showError(`the link's parameters are not readable: ${error.message}`);
  }
}

function resetParams() {
  paramValues = defaultParams();
  buildParamsPanel();
  rerun();
}

// ---------------------------------------------------------------- metrics

let shownMetrics = { metrics: null, limit: null };
function showMetrics(metrics, limit) {
  if (metrics) shownMetrics.metrics = metrics;
  if (limit) shownMetrics.limit = limit;
  const m = shownMetrics.metrics;
  if (!m) return;
  const n = (x, d = 3) => (typeof x === 'number' ? Number(x.toPrecision(d)).toString() : String(x ?? '—'));
  const t = m.topology;
  const rows = [
    ['vertices / faces / edges', `${t.vertices} / ${t.faces} / ${t.edges}`],
    ['input vertices', t.input_vertices],
    ['vertex reduction', `${n(t.vertex_reduction_percent)} %`],
    ['extraordinary vertices', `${n(t.extraordinary_vertex_percent)} %`],
    ['non-quad faces', `${n(t.non_quad_percent)} %`],
    ['face degrees', t.face_degrees.map(([d, c]) => `${c}×${d}`).join(', ')],
    ['boundary edges / loops', `${t.boundary_edges} / ${t.boundary_loops}`],
    ['non-manifold edges / vertices', `${t.nonmanifold_edges} / ${t.nonmanifold_vertices}`],
    ['components · Euler · genus', `${t.components} · ${t.euler_characteristic} · ${t.genus ?? '—'}`],
    ['quads', m.quads.quads],
    ['planarity (diagonal midpoints)', n(m.quads.planarity)],
    ['corner angle |α − 90°|', `${n(m.quads.corner_angle_deviation_degrees)}°`],
    ['mean corner angle', `${n(m.quads.mean_corner_angle_degrees)}°`],
    ['opposite-edge ratio', n(m.quads.opposite_edge_ratio)],
    ['quad quality (0 best)', n(m.quads.quad_quality)],
    ['Hausdorff distance', n(m.distance.hausdorff)],
    ['output → input mean / max', `${n(m.distance.output_to_input_mean)} / ${n(m.distance.output_to_input_max)}`],
    ['input → output mean / max', `${n(m.distance.input_to_output_mean)} / ${n(m.distance.input_to_output_max)}`],
    ['face centroids mean / max', `${n(m.distance.face_centroid_mean)} / ${n(m.distance.face_centroid_max)}`],
    ['edge length mean ± sd', `${n(m.edges.mean)} ± ${n(m.edges.std_dev)}`],
    ['edge length min / max', `${n(m.edges.min)} / ${n(m.edges.max)}`],
  ];
  const l = shownMetrics.limit;
  if (l) {
    rows.push(
      ['control mesh vertices / faces', `${l.control_vertices} / ${l.control_faces}`],
      ['fit iterations (converged)', `${l.iterations} (${l.converged ? 'yes' : 'no'})`],
      ['least-squares steps', `${l.lspia_iterations ?? 0}`],
      ['limit Hausdorff before → after', `${n(l.before.hausdorff)} → ${n(l.after.hausdorff)}`],
      ['limit mean error before → after', `${n(l.before.stats.mean)} → ${n(l.after.stats.mean)}`],
    );
  }
  rows.push(['lengths in', 'units of the input\u2019s largest bounding-box axis']);
  $('metrics').replaceChildren(...rows.map(([k, v]) => {
    const tr = document.createElement('tr');
    for (const text of [k, v]) {
      const td = document.createElement('td');
      td.textContent = String(text);
      tr.append(td);
    }
    return tr;
  }));
  $('metrics-panel').hidden = false;
}

// ---------------------------------------------------------------- export, share

const baseName = () => (lastInput?.name || 'quadrille').replace(/\.[^.]*$/, '');
async function exportMesh(kind, format) {
  const bytes = await request({ type: 'export', kind, format });
  return bytes;
}
async function downloadMesh(kind, format) {
  try {
    const bytes = await exportMesh(kind, format);
    const a = document.createElement('a');
    a.href = URL.createObjectURL(new Blob([bytes], { type: format === 'obj' ? 'text/plain' : 'application/octet-stream' }));
    a.download = `${baseName()}-${kind}.${format}`;
    a.click();
    setTimeout(() => URL.revokeObjectURL(a.href), 10000);
  } catch (error) {
    showError(`export failed: ${error.message}`);
  }
}

// The address that reproduces this run: the sample and the changed parameters.
function shareUrl() {
  const url = new URL(location.href);
  url.search = '';
  const backend = params.get('backend');
  if (backend) url.searchParams.set('backend', backend);
  if (lastInput?.sample) url.searchParams.set('sample', lastInput.sample);
  const changed = changedParams();
  if (Object.keys(changed).length) url.searchParams.set('p', JSON.stringify(changed));
  if (viewer && lastInput?.sample) url.searchParams.set('cam', [...viewer.camera_state()].map((x) => Number(x.toFixed(5))).join(','));
  return url.toString();
}
async function share() {
  const url = shareUrl();
  const el = $('share-url');
  el.value = url;
  el.hidden = false;
  el.select();
  history.replaceState(null, '', url);
  $('share-note').textContent = lastInput && !lastInput.sample
    ? 'Your own file is not in the link (it never leaves this page): the link carries only the parameters.'
    : 'Link copied to the address bar.';
  try { await navigator.clipboard.writeText(url); $('share-note').textContent += ' Copied.'; } catch { /* no clipboard permission */ }
}

// ---------------------------------------------------------------- shortcuts help

const OTHER_KEYS = [['F', 'fit view'], ['P', 'PNG screenshot'], ['O', 'open a file'], ['T', 'design layout mode (dual strip weaving)'],
  ['H', 'compare: the input ⇄ the result'],
  ['Enter', 'design mode: commit the loop as a strip'], ['Esc', 'cancel / close · design mode: clear the anchors'],
  ['Ctrl+Z · Ctrl+Shift+Z', 'design mode: undo · redo'], ['Wheel', 'design mode: browse alternative loops'],
  ['Shift+wheel', 'design mode: zoom'], ['Right-drag · Alt+drag', 'design mode: turn the view'], ['?', 'this list']];
function toggleShortcuts(show) {
  const el = $('shortcuts');
  el.hidden = show === undefined ? !el.hidden : !show;
  if (el.hidden) return;
  const rows = [...LAYERS.filter((l) => l.key).map((l) => [l.key.toUpperCase(), l.label]), ...OTHER_KEYS];
  $('shortcut-table').replaceChildren(...rows.map(([k, v]) => {
    const tr = document.createElement('tr');
    const a = document.createElement('td');
    const kbd = document.createElement('kbd');
    kbd.textContent = k;
    a.append(kbd);
    const b = document.createElement('td');
    b.textContent = v;
    tr.append(a, b);
    return tr;
  }));
}

window.quadrille.exportMesh = exportMesh;
window.quadrille.shareUrl = shareUrl;
window.quadrille.setParam = (path, value) => {
  setPath(paramValues, path, value);
  buildParamsPanel();
  rerun();
};
window.quadrille.params = () => structuredClone(paramValues);

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
$('compare').addEventListener('click', toggleCompare);
window.quadrille.drawnSurface = () => drawnSurface;
$('fit').addEventListener('click', fitView);
for (const b of document.querySelectorAll('[data-preset]')) {
  b.addEventListener('click', () => { if (viewer) { viewer.view_preset(b.dataset.preset); requestRender(); } });
}
$('flat-shading').addEventListener('change', () => { if (viewer) { viewer.set_flat_shading($('flat-shading').checked); requestRender(); } });
// Glyph spacing in CSS pixels; the viewer counts drawing-buffer pixels.
const applyGlyphSpacing = () => { if (viewer) { viewer.set_glyph_spacing(Number($('glyph-spacing').value) * dpr()); requestRender(); } };
$('glyph-spacing').addEventListener('input', applyGlyphSpacing);
window.quadrille.glyphCount = (name) => (viewer ? viewer.glyph_count(name) : 0);
$('crease-angle').addEventListener('change', () => {
  if (!viewer) return;
  const wanted = Number($('crease-angle').value);
  const used = viewer.set_crease_angle(wanted);
  if (used !== wanted) $('crease-angle').value = String(used);
  requestRender();
});
// Small screens: the panel is a drawer over the view.
$('panel-toggle').addEventListener('click', () => {
  const open = !document.body.classList.contains('panel-open');
  document.body.classList.toggle('panel-open', open);
  $('panel-toggle').setAttribute('aria-expanded', String(open));
  $('panel-toggle').textContent = open ? 'Close the panel' : 'Layers & controls';
});
window.quadrille.camera = () => (viewer ? [...viewer.camera_state()] : null);
// Tests: looks from (yaw, pitch) at the framed surface.
window.quadrille.setCamera = ([yaw, pitch, distance]) => {
  if (!viewer) return;
  const s = viewer.camera_state();
  s[0] = yaw ?? s[0];
  s[1] = pitch ?? s[1];
  s[2] = distance ?? s[2];
  viewer.set_camera_state(s);
  requestRender();
};
$('screenshot').addEventListener('click', saveScreenshot);
for (const b of document.querySelectorAll('#exports button')) b.addEventListener('click', () => downloadMesh(b.dataset.kind, b.dataset.format));
$('share').addEventListener('click', share);
$('params-reset').addEventListener('click', resetParams);
$('param-search').addEventListener('input', filterParams);
attachTargetControl();
attachModeControl();
$('shortcuts-close').addEventListener('click', () => toggleShortcuts(false));

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
  if (e.target.matches('input, textarea, select')) return;
  if (design.active && $('shortcuts').hidden && design.onKey(e)) { e.preventDefault(); return; }
  if (e.ctrlKey || e.metaKey || e.altKey) return;
  const key = e.key.toLowerCase();
  const layers = LAYERS.filter((l) => l.key === key && available.has(l.name));
  if (layers.length) layers.forEach((l) => setLayerVisible(l.name, !l.visible));
  else if (key === 'f') fitView();
  else if (key === 'p') saveScreenshot();
  else if (key === 'o') $('file').click();
  else if (key === 't') toggleDesign();
  else if (key === 'h') toggleCompare();
  else if (key === '?') toggleShortcuts();
  else if (key === 'escape') { if (!$('shortcuts').hidden) toggleShortcuts(false); else cancel(); }
  else return;
  e.preventDefault();
});

// ---------------------------------------------------------------- design mode

// Layers hidden while designing (restored when leaving the mode).
let hiddenForDesign = [];
let scalarBeforeDesign = null;
function setRegionSurface(surface) {
  LAYERS = LAYERS.filter((l) => l.name !== REGION_SURFACE);
  delete extraSurfaces[REGION_SURFACE];
  available.delete(REGION_SURFACE);
  if (surface) {
    extraSurfaces[REGION_SURFACE] = surface;
    for (const l of LAYERS) if (l.kind === 'surface') l.visible = false;
    const label = surface.label || (surface.scalar ? 'Layout regions' : 'Design proxy');
    LAYERS.push({ name: REGION_SURFACE, label, kind: 'surface', color: surface.color || (surface.scalar ? '#e31a1c' : '#c8cdd8'), color2: surface.color2 || (surface.scalar ? '#ff7f00' : undefined), visible: true });
    available.add(REGION_SURFACE);
  }
  showSurface();
}
const design = createDesignMode({
  $,
  viewer: () => viewer,
  requestRender,
  afterNextFrame: (f) => { afterFrame.push(f); requestRender(); },
  pick: (clientX, clientY) => {
    if (!viewer) return null;
    const rect = canvas.getBoundingClientRect();
    const hit = viewer.pick((clientX - rect.left) * (canvas.width / rect.width), (clientY - rect.top) * (canvas.height / rect.height));
    return hit ? [...hit.point] : null;
  },
  input: () => (lastInput && inputSurface ? lastInput : null),
  setRegionSurface,
  setStatus,
  showError,
  dpr,
});
function toggleDesign() {
  if (design.active) {
    design.leave();
    if (viewer) viewer.set_line_width(1.25 * dpr());
    setScalar(scalarBeforeDesign);
    for (const name of hiddenForDesign) setLayerVisible(name, true);
    hiddenForDesign = [];
    return;
  }
  design.enter();
  if (!design.active) return;
  // The input's scalar colouring would compete with the loops: plain while designing.
  scalarBeforeDesign = scalarName;
  setScalar(null);
  // Loops and stripes are the content now: thicker lines.
  if (viewer) viewer.set_line_width(2.5 * dpr());
  hideForDesign();
  if (drawnSurface !== 'input') showSurface();
}
// The pipeline's results (and the input's edges) would hide the loops: off
// while designing, also those that arrive meanwhile.
function hideForDesign() {
  const clutter = (l) => l.visible && available.has(l.name) && l.name !== REGION_SURFACE
    && (l.kind === 'lines' || l.kind === 'points' || l.kind === 'surface' || ['polygon edges', 'picked'].includes(l.name));
  for (const l of LAYERS.filter(clutter)) {
    if (!hiddenForDesign.includes(l.name)) hiddenForDesign.push(l.name);
    setLayerVisible(l.name, false);
  }
}
$('design-toggle').addEventListener('click', toggleDesign);
window.quadrille.design = design.stats;
window.quadrille.toggleDesign = toggleDesign;
window.quadrille.exportLayout = (format) => design.exportLayout(format);
window.quadrille.gridLayout = (counts) => design.gridLayout(counts);
window.quadrille.fitLayout = () => design.fitLayout();
window.quadrille.designAction = (name, args = []) => design.action(name, args);
window.quadrille.crashLayoutWorker = () => design.crashForTesting();
window.quadrille.holdDesignAnalysis = (on) => design.holdAnalysisForTesting(on);
window.quadrille.hoverMedianMs = () => design.hoverMedianMs();
// The surface point (local coordinates) under a client position, for tests.
window.quadrille.surfacePoint = (clientX, clientY) => {
  if (!viewer) return null;
  const rect = canvas.getBoundingClientRect();
  const hit = viewer.pick((clientX - rect.left) * (canvas.width / rect.width), (clientY - rect.top) * (canvas.height / rect.height));
  return hit ? [...hit.point] : null;
};

updateLayersPanel();
startWorker();
const viewerReady = init().then(startViewer).catch((error) => showError(`could not start: ${error.message}`));
const schemaReady = request({ type: 'schema' }).then((s) => {
  schema = s;
  paramsFromUrl();
  buildParamsPanel();
}).catch((error) => showError(`could not read the parameters: ${error.message}`));
// The default sample (or the link's) is processed at start, with the
// link's parameters; its mesh is shown once the viewer is up.
Promise.all([viewerReady, schemaReady]).then(() => {
  const sample = params.get('sample');
  setLoading(`Opening ${SAMPLES.includes(sample) ? sample : DEFAULT_SAMPLE}…`);
  if (params.get('p') && !sample) {
    $('share-note').textContent = 'This link carries parameters only (the mesh was someone\u2019s own file, which never leaves their page): open your file to run it with them.';
  }
  loadSample(SAMPLES.includes(sample) ? sample : DEFAULT_SAMPLE);
});
