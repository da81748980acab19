// The design mode's worker (dual strip weaving, Campen & Kobbelt 2014 §4.1):
// one LayoutDesigner (Rust) holds the loop engine and the undoable design
// state, so hover queries and the strip analysis never block the page.
//
// Messages in:   { type: 'init', bytes: ArrayBuffer, name }
//                { type: 'hover', point: [x, y, z], t }          the page keeps one in flight
//                { type: 'action', name, args: [...], t }        addAnchor, setLastAnchorDirection,
//                  insertAnchorOnLoop, moveGrabbedAnchor, clearAnchors, commit, deleteStrip, undo, redo,
//                  browse, moveLayoutVertex, setMirror
//                { type: 'export', id, format }                 'obj' | 'json' | 'grid-obj'
//                { type: 'grid', id, counts }                   grid the layout (one count per strip)
//                { type: 'fit', id }                            fit the gridded layout
//                { type: 'crash-for-testing' }
// Messages out:  { type: 'progress', text }
//                { type: 'ready', faces, inputFaces, proxy, buildMs, surface }
//                { type: 'hover', proposal: Float32Array, ms, t }
//                { type: 'state', action, value, state, ms, t }  right after each action
//                { type: 'analysis', analysis, ms }             afterwards, when the strips changed
//                { type: 'reply', id, value?, error? }
//                { type: 'error', message, fatal }              fatal: the worker must be replaced
import init, { LayoutDesigner, takePanicMessage, panicForTesting } from './pkg/quadrille.js';

const loaded = performance.now();
const ready = init();
let wasmMs = null;
ready.then(() => { wasmMs = performance.now() - loaded; });
let designer = null;
let analysisQueued = false;

function transferables(value, out = []) {
  if (ArrayBuffer.isView(value)) out.push(value.buffer);
  else if (value && typeof value === 'object') for (const v of Object.values(value)) transferables(v, out);
  return out;
}

function fail(error) {
  const fatal = error instanceof WebAssembly.RuntimeError;
  let message = String((error && error.message) || error);
  if (fatal) {
    try { message = takePanicMessage() || message; } catch { /* the module is gone */ }
  }
  self.postMessage({ type: 'error', message, fatal });
}

// The analysis runs after the reply to the action has gone out, and only
// for the latest revision (actions that arrive meanwhile are handled first).
function queueAnalysis() {
  if (analysisQueued) return;
  analysisQueued = true;
  setTimeout(() => {
    analysisQueued = false;
    if (!designer || !designer.analysisStale()) return;
    try {
      const started = performance.now();
      const analysis = designer.analyze();
      self.postMessage({ type: 'analysis', analysis, ms: performance.now() - started }, transferables(analysis));
    } catch (error) {
      fail(error);
    }
  }, 0);
}

const ACTIONS = new Set(['addAnchor', 'setLastAnchorDirection', 'insertAnchorOnLoop', 'moveGrabbedAnchor', 'clearAnchors',
  'commit', 'deleteStrip', 'undo', 'redo', 'browse', 'moveLayoutVertex', 'setMirror']);

self.onmessage = async (event) => {
  const m = event.data;
  try {
    await ready;
    if (m.type === 'init') {
      if (designer) designer.free();
      designer = null;
      self.postMessage({ type: 'progress', text: `building the loop engine for ${m.name}…` });
      const started = performance.now();
      designer = new LayoutDesigner(new Uint8Array(m.bytes), m.name);
      designer.warmUp();
      const surface = designer.surface();
      self.postMessage({
        type: 'ready', faces: designer.faceCount(), inputFaces: designer.inputFaceCount(), proxy: designer.usesProxy(),
        buildMs: performance.now() - started, wasmMs, surface,
      }, transferables(surface));
    } else if (m.type === 'crash-for-testing') {
      panicForTesting();
    } else if (!designer) {
      throw new Error('the layout worker has no mesh yet');
    } else if (m.type === 'hover') {
      const started = performance.now();
      const proposal = designer.hover(m.point);
      self.postMessage({ type: 'hover', proposal, ms: performance.now() - started, t: m.t }, [proposal.buffer]);
    } else if (m.type === 'action') {
      if (!ACTIONS.has(m.name)) throw new Error(`unknown design action ${m.name}`);
      const started = performance.now();
      const value = designer[m.name](...(m.args || []));
      const state = designer.state();
      self.postMessage({ type: 'state', action: m.name, value, state, ms: performance.now() - started, t: m.t }, transferables(state));
      if (designer.analysisStale()) queueAnalysis();
    } else if (m.type === 'export' || m.type === 'grid' || m.type === 'fit') {
      try {
        const value = m.type === 'export' ? designer.export(m.format)
          : m.type === 'grid' ? designer.grid(new Uint32Array(m.counts)) : designer.fit();
        self.postMessage({ type: 'reply', id: m.id, value }, transferables(value));
      } catch (error) {
        if (error instanceof WebAssembly.RuntimeError) throw error;
        self.postMessage({ type: 'reply', id: m.id, error: String(error.message || error) });
      }
    }
  } catch (error) {
    fail(error);
  }
};
