// The design mode's analysis worker (dual strip weaving, Campen & Kobbelt
// 2014 §4.2, §6, §7): strips, regions, singularities and the primal layout
// of the committed loops, away from the layout worker so that hover, clicks
// and Enter never wait for it. Started by the layout worker.
//
// Messages in:   { type: 'init', meshes, latest: SharedArrayBuffer | null, hold: SharedArrayBuffer | null }
//                  meshes: LayoutDesigner.takeAnalysisMeshes() (the design mesh, made once in the
//                  layout worker, the input when that is a proxy, the file's frame); hold (tests):
//                  while 1, a running analysis waits at its first step (after posting 'held')
//                { type: 'analyze', serial, input }   input: LayoutDesigner.takeAnalysisInput()
//                { type: 'export' | 'grid' | 'fit', id, serial, format?, counts? }
//                                                     the page's requests (see layout-worker.js), for
//                                                     the design state of analysis `serial`
// Messages out:  { type: 'analysis', serial, revision, analysis, ms }
//                { type: 'held', serial, revision }
//                { type: 'cancelled', serial, revision, started, ms }
//                { type: 'error', serial, message, fatal }
//                { type: 'reply', id, value?, error?, fatal? }   to an export, grid or fit
// Every request is answered once (analysis, cancelled or error; reply).
//
// Exports, the grid and the fit are made from the newest finished analysis
// (LayoutAnalyzer keeps it, with its grid), here rather than in the layout
// worker, so that they never block hover or clicks either. Their serial
// says which analysis they need: when it is still pending it runs first.
//
// A newer action cancels a stale analysis: requests that arrive while one
// runs replace each other (the replaced one is answered 'cancelled' with
// started false), and the running one stops at its next step when the
// layout worker's newest serial (`latest`, shared, written by the layout
// worker) is no longer its own (answered 'cancelled' with started true).
// Without cross-origin isolation there is no shared memory: then the layout
// worker replaces this worker instead (see layout-worker.js).
import init, { LayoutAnalyzer, takePanicMessage } from './pkg/quadrille.js';

const ready = init();
let analyzer = null;
let latest = null; // Int32Array over the shared newest serial, or null
let hold = null; // Int32Array over the tests' hold flag, or null
let pending = null;
let scheduled = false;
let analysed = null; // the serial of the analysis the analyzer holds

function transferables(value, out = []) {
  if (ArrayBuffer.isView(value)) out.push(value.buffer);
  else if (value && typeof value === 'object') for (const v of Object.values(value)) transferables(v, out);
  return out;
}

function panicMessage(error) {
  let message = String((error && error.message) || error);
  if (error instanceof WebAssembly.RuntimeError) {
    try { message = takePanicMessage() || message; } catch { /* the module is gone */ }
  }
  return message;
}

function cancelled(m, started, ms) {
  self.postMessage({ type: 'cancelled', serial: m.serial, revision: m.input.revision, started, ms });
}

function run() {
  scheduled = false;
  const m = pending;
  pending = null;
  if (!m) return;
  if (!analyzer) {
    self.postMessage({ type: 'error', serial: m.serial, message: 'the analysis worker has no mesh', fatal: false });
    return;
  }
  try {
    const started = performance.now();
    const i = m.input;
    const current = () => {
      if (hold && Atomics.load(hold, 0) === 1) {
        self.postMessage({ type: 'held', serial: m.serial, revision: i.revision });
        Atomics.wait(hold, 0, 1);
      }
      return !latest || Atomics.load(latest, 0) === m.serial;
    };
    const analysis = analyzer.analyze(i.points, i.lengths, i.closed, i.moves, current);
    if (analysis === null) { cancelled(m, true, performance.now() - started); return; }
    analysed = m.serial;
    analysis.revision = i.revision;
    self.postMessage({ type: 'analysis', serial: m.serial, revision: i.revision, analysis, ms: performance.now() - started },
      transferables(analysis));
  } catch (error) {
    self.postMessage({ type: 'error', serial: m.serial, message: panicMessage(error), fatal: error instanceof WebAssembly.RuntimeError });
  }
}

// An export, grid or fit of the design state of analysis `m.serial`.
function answer(m) {
  if (pending && pending.serial === m.serial) run();
  try {
    if (!analyzer) throw new Error('the analysis worker has no mesh');
    if (analysed !== m.serial) throw new Error('the design changed before its analysis was done: try again');
    const value = m.type === 'export' ? analyzer.export(m.format)
      : m.type === 'grid' ? analyzer.grid(new Uint32Array(m.counts)) : analyzer.fit();
    if (m.type === 'grid') value.serial = m.serial;
    self.postMessage({ type: 'reply', id: m.id, value }, transferables(value));
  } catch (error) {
    self.postMessage({ type: 'reply', id: m.id, error: panicMessage(error), fatal: error instanceof WebAssembly.RuntimeError });
  }
}

self.onmessage = async (event) => {
  const m = event.data;
  await ready;
  if (m.type === 'init') {
    if (analyzer) analyzer.free();
    analyzer = null;
    pending = null;
    analysed = null;
    latest = m.latest ? new Int32Array(m.latest) : null;
    hold = m.hold ? new Int32Array(m.hold) : null;
    try {
      const g = m.meshes;
      analyzer = new LayoutAnalyzer(g.positions, g.triangles, g.originalPositions, g.originalTriangles, g.frame);
    } catch (error) {
      self.postMessage({ type: 'error', serial: null, message: String((error && error.message) || error), fatal: false });
    }
  } else if (m.type === 'analyze') {
    if (pending) cancelled(pending, false, 0);
    pending = m;
    if (!scheduled) {
      scheduled = true;
      setTimeout(run, 0);
    }
  } else if (m.type === 'export' || m.type === 'grid' || m.type === 'fit') {
    answer(m);
  }
};
