// Page wiring: file input, drag and drop, samples, and the worker that does the work.
const SAMPLES = ['stanford-bunny', 'fandisk', 'rocker-arm', 'spot', 'cow', 'teapot', 'suzanne', 'beetle'];
const DEFAULT_SAMPLE = 'stanford-bunny';

const statusEl = document.getElementById('status');
const drop = document.getElementById('drop');
const reportPanel = document.getElementById('report-panel');

let worker = null;
let nextId = 1;
const pending = new Map();

window.quadrille = { lastImport: null, lastError: null };

function startWorker() {
  worker = new Worker(new URL('./worker.js', import.meta.url), { type: 'module' });
  worker.onmessage = (event) => {
    const job = pending.get(event.data.id);
    if (!job) return;
    pending.delete(event.data.id);
    if (event.data.kind === 'error') job.reject(new Error(event.data.message));
    else job.resolve(event.data);
  };
  // A crashed worker is replaced, so the page keeps working.
  worker.onerror = (event) => {
    event.preventDefault();
    for (const job of pending.values()) job.reject(new Error(event.message || 'the worker crashed'));
    pending.clear();
    worker.terminate();
    startWorker();
  };
}

function request(name, bytes) {
  const id = nextId++;
  return new Promise((resolve, reject) => {
    pending.set(id, { resolve, reject });
    worker.postMessage({ id, name, bytes }, [bytes]);
  });
}

function setStatus(text, isError = false) {
  statusEl.textContent = text;
  statusEl.classList.toggle('error', isError);
}

async function load(name, bytes) {
  setStatus(`Reading ${name} (${(bytes.byteLength / 1024).toFixed(0)} KiB)…`);
  try {
    const { report, ms } = await request(name, bytes);
    window.quadrille.lastImport = report;
    window.quadrille.lastError = null;
    showReport(report);
    setStatus(`${name}: imported in ${ms.toFixed(0)} ms.`);
  } catch (error) {
    window.quadrille.lastError = error.message;
    setStatus(error.message, true);
  }
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
  const table = document.getElementById('report');
  table.replaceChildren(...rows.map(([k, v]) => {
    const tr = document.createElement('tr');
    for (const text of [k, v]) {
      const td = document.createElement('td');
      td.textContent = String(text);
      tr.append(td);
    }
    return tr;
  }));
  document.getElementById('report-title').textContent = r.file;
  reportPanel.hidden = false;
}

const fmt = (v) => `(${v.map((x) => Number(x.toPrecision(4))).join(', ')})`;

async function loadSample(name) {
  const response = await fetch(`samples/${name}.obj`);
  if (!response.ok) {
    setStatus(`sample ${name} is not available (${response.status})`, true);
    return;
  }
  await load(`${name}.obj`, await response.arrayBuffer());
}

async function loadFile(file) {
  await load(file.name, await file.arrayBuffer());
}

startWorker();

const buttons = document.getElementById('sample-buttons');
for (const name of SAMPLES) {
  const b = document.createElement('button');
  b.textContent = name;
  b.addEventListener('click', () => loadSample(name));
  buttons.append(b);
}
document.getElementById('file').addEventListener('change', (e) => {
  if (e.target.files.length) loadFile(e.target.files[0]);
});
drop.addEventListener('dragover', (e) => { e.preventDefault(); drop.classList.add('over'); });
drop.addEventListener('dragleave', () => drop.classList.remove('over'));
drop.addEventListener('drop', (e) => {
  e.preventDefault();
  drop.classList.remove('over');
  const file = e.dataTransfer.files[0];
  if (file) loadFile(file);
});
// Dropping anywhere on the page works too.
document.addEventListener('dragover', (e) => e.preventDefault());
document.addEventListener('drop', (e) => {
  if (e.target.closest && e.target.closest('#drop')) return;
  e.preventDefault();
  const file = e.dataTransfer.files[0];
  if (file) loadFile(file);
});

const sample = new URLSearchParams(location.search).get('sample') || DEFAULT_SAMPLE;
loadSample(SAMPLES.includes(sample) ? sample : DEFAULT_SAMPLE);
