// The design mode's worker (dual strip weaving, Campen & Kobbelt 2014 §4.1):
// one LayoutDesigner (Rust) holds the loop engine and the undoable design
// state, so hover queries never block the page; the strip analysis runs in
// a further worker (analysis-worker.js) so it never blocks hover either,
// and so do the exports, the grid and the fit, which it makes from its
// newest analysis.
//
// Messages in:   { type: 'init', bytes: ArrayBuffer, name, hoverFirst, hoverHold, hoverBridge, inbox }  hoverFirst: null, a count of g′
//                  nodes instead of HOVER_FIRST, or 'all' (every hover answered exactly at once); hoverHold:
//                  null or ms instead of HOVER_HOLD (below); hoverBridge: '0' shows no provisional loop
//                  bridged to a recent one (benchmarks); inbox: null
//                  or a SharedArrayBuffer where the page counts the messages it posts after init
//                { type: 'hover', point: [x, y, z], t }          the page keeps one in flight
//                { type: 'action', name, args: [...], t, serial } addAnchor, setLastAnchorDirection,
//                  insertAnchorOnLoop, moveGrabbedAnchor, clearAnchors, commit, deleteStrip, undo, redo,
//                  browse, moveLayoutVertex, setMirror
//                { type: 'export', id, format }                 'obj' | 'json' | 'grid-obj'
//                { type: 'grid', id, counts }                   grid the layout (one count per strip);
//                                                               the reply's serial: the analysis it goes with
//                { type: 'fit', id }                            fit the gridded layout
//                  (export, grid and fit are answered by the analysis worker, from the analysis
//                  of the newest design state, so they never block hover or clicks)
//                { type: 'crash-for-testing' }
//                { type: 'hold-analysis-for-testing', on }      while on, a running analysis waits at its first step
// Messages out:  { type: 'progress', text }
//                { type: 'ready', faces, inputFaces, proxy, buildMs, surface }
//                { type: 'hover', proposal: Float32Array, ms, t, exact, final }
//                  the answer to a hover, at once: the exact best loop (exact), or the cheapest loop found
//                  within HOVER_FIRST settled g′ nodes (provisional); after a provisional one, the exact
//                  loop for the same t (final, exact; ms: the worker's time over all its slices;
//                  unchanged: it is the provisional loop, node for node)
//                { type: 'state', action, value, state, ms, t, serial }  right after each action
//                { type: 'analysis', analysis, ms, serial }     afterwards, when the strips or moves changed
//                { type: 'analysis-cancelled', revision, started, ms }  a stale analysis given up
//                { type: 'analysis-held', revision }            (tests) an analysis waits, held
//                { type: 'reply', id, value?, error? }
//                { type: 'error', message, fatal }              fatal: the worker must be replaced
import init, { LayoutDesigner, takePanicMessage, panicForTesting } from './pkg/quadrille.js';

const loaded = performance.now();
const ready = init();
let wasmMs = null;
ready.then(() => { wasmMs = performance.now() - loaded; });
let designer = null;

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

// The analysis runs in a worker of its own (analysis-worker.js): after each
// action that changed the committed loops (or the layout-vertex moves) the
// loops go there with a new serial; its answer is used only when it is for
// the newest serial, and its covered directions (§6.2) only when they are
// for the current revision (LayoutDesigner.applyCovered checks).
//
// A newer action cancels a stale analysis: the newest serial is shared with
// the analysis worker (`latest`), which stops a running analysis at its next
// step once the serial is no longer its own. Without cross-origin isolation
// (no SharedArrayBuffer) the analysis worker is replaced instead when a
// request is still unanswered.
let analyzer = null;
let analyzerInit = null;
let serial = 0;
const latest = self.crossOriginIsolated ? new Int32Array(new SharedArrayBuffer(4)) : null;
const hold = self.crossOriginIsolated ? new Int32Array(new SharedArrayBuffer(4)) : null; // tests only
let unanswered = 0; // requests the analysis worker has not answered yet
const forwarded = new Set(); // ids of the page's export, grid and fit requests it has not answered yet

function startAnalyzer() {
  if (analyzer) analyzer.terminate();
  unanswered = 0;
  for (const id of forwarded) self.postMessage({ type: 'reply', id, error: 'the analysis worker was restarted: try again' });
  forwarded.clear();
  analyzer = new Worker(new URL('./analysis-worker.js', import.meta.url), { type: 'module' });
  analyzer.onmessage = (event) => {
    const r = event.data;
    if (r.type === 'held') {
      self.postMessage({ type: 'analysis-held', revision: r.revision });
      return;
    }
    if (r.type === 'reply') {
      forwarded.delete(r.id);
      self.postMessage(r, transferables(r));
      if (r.fatal) startAnalyzer();
      return;
    }
    if (r.serial !== null) unanswered = Math.max(0, unanswered - 1);
    if (r.type === 'cancelled') {
      self.postMessage({ type: 'analysis-cancelled', revision: r.revision, started: r.started, ms: r.ms });
      return;
    }
    if (r.serial !== serial || !designer) return;
    if (r.type === 'error') {
      self.postMessage({ type: 'error', message: `analysis: ${r.message}`, fatal: false });
      if (r.fatal) startAnalyzer();
      return;
    }
    const a = r.analysis;
    // New covered directions drop the prepared fields: prepare them again.
    if (designer.applyCovered(r.revision, a.coveredCounts, a.coveredDirections)) prepareSoon();
    delete a.coveredCounts;
    delete a.coveredDirections;
    self.postMessage({ type: 'analysis', analysis: a, ms: r.ms, serial: r.serial }, transferables(a));
  };
  analyzer.onerror = (e) => {
    self.postMessage({ type: 'error', message: `analysis worker: ${e.message || e}`, fatal: false });
  };
  // The design meshes are copied (not transferred): a restarted analysis worker gets them again.
  if (analyzerInit) analyzer.postMessage({ type: 'init', meshes: analyzerInit, latest: latest && latest.buffer, hold: hold && hold.buffer });
}

function queueAnalysis() {
  const input = designer && designer.takeAnalysisInput();
  if (!input) return;
  serial += 1;
  if (latest) Atomics.store(latest, 0, serial);
  else if (unanswered > 0) {
    self.postMessage({ type: 'analysis-cancelled', revision: null, started: true, ms: null });
    startAnalyzer();
  }
  unanswered += 1;
  analyzer.postMessage({ type: 'analyze', serial, input }, transferables(input));
}

// Idle time: after the engine is built and after each action the distance
// fields that the next queries read (LayoutDesigner.prepareFields: those of
// the loop through the anchors, then the distances from the boundary node ∂
// that every hover and dual curve reads) are settled a slice at a time, each
// slice a task of its own, so that a message waits for one slice at most (a
// few milliseconds) and the next hover, grab, drag update or click finds
// them settled. The answers do not change, only how soon they come.
//
// The hover is progressive (Campen & Kobbelt 2014 §4.1: the best loop
// through the pointer, "constantly updated"): its first slice of search
// (HOVER_FIRST g′ nodes, a few ms) answers at once, with the exact loop
// when the search finished, else with the cheapest loop or dual curve found
// so far; the search then goes on by slices (HOVER_SLICE) in the same task
// for as long as no message waits (the page counts its messages in the
// shared `inbox`), then in idle tasks before the fields (one slice per task
// without cross-origin isolation), and the exact loop follows. A newer hover
// replaces the unfinished search; Enter, the wheel and new covered strips
// finish it first (LayoutDesign::finish_hover), so what is committed or
// browsed is the exact loop.
const PREPARE_SLICE = 10000; // g′ nodes per slice
const HOVER_FIRST = 6000; // g′ nodes before the first answer
let hoverFirst = HOVER_FIRST;
const HOVER_SLICE = 4000; // g′ nodes per later slice
// `hoverHold` (ms, `?hoverHold=`): a hover whose first slice did not finish
// its search goes on searching for up to this long from its start (in the
// same task, while no message waits) before its provisional loop is posted:
// an exact loop found meanwhile is posted instead, so the page does not
// draw a provisional frame that the exact one replaces a moment later (on
// a software renderer each frame holds the page's main thread for about
// 120 ms, and the exact answer waits behind it). 0: off — measured with
// 16 and 50 ms it did not lower the exact draw's 95th percentile on
// rocker-arm or the bunny and made the first draw later (docs/RESULTS.md,
// issue21s).
const HOVER_HOLD = 0;
let hoverHold = HOVER_HOLD;
const idle = new MessageChannel();
let scheduled = false;
let prepareMore = false; // prepareFields has more to settle
let hoverJob = null; // the unfinished hover: { t, ms }
let inbox = null; // Int32Array: messages the page has posted since init
let received = 0; // … and those this worker has received

// Slices of the unfinished hover search: one, or (with `inbox`) as many as
// run before a message waits; posts the exact loop once it is known.
function hoverSlices() {
  const started = performance.now();
  let exact;
  do {
    exact = designer.hoverStep(HOVER_SLICE);
  } while (exact === undefined && inbox && designer.hoverPending() && Atomics.load(inbox, 0) === received);
  if (hoverJob) hoverJob.ms += performance.now() - started;
  if (exact !== undefined) {
    if (hoverJob) self.postMessage({ type: 'hover', proposal: exact, ms: hoverJob.ms, t: hoverJob.t, exact: true, final: true, unchanged: designer.hoverUnchanged() }, [exact.buffer]);
    hoverJob = null;
  }
}

idle.port1.onmessage = () => {
  scheduled = false;
  if (!designer) return;
  try {
    if (designer.hoverPending()) {
      hoverSlices();
    } else if (prepareMore) {
      prepareMore = designer.prepareFields(PREPARE_SLICE);
    }
  } catch (error) {
    fail(error);
    return;
  }
  if (designer.hoverPending() || prepareMore) idleSoon();
};
function idleSoon() {
  if (scheduled) return;
  scheduled = true;
  idle.port2.postMessage(null);
}
function prepareSoon() {
  prepareMore = true;
  idleSoon();
}

const ACTIONS = new Set(['addAnchor', 'setLastAnchorDirection', 'insertAnchorOnLoop', 'moveGrabbedAnchor', 'clearAnchors',
  'commit', 'deleteStrip', 'undo', 'redo', 'browse', 'moveLayoutVertex', 'setMirror']);

self.onmessage = async (event) => {
  const m = event.data;
  if (m.type !== 'init') received += 1;
  try {
    await ready;
    if (m.type === 'init') {
      if (designer) designer.free();
      designer = null;
      self.postMessage({ type: 'progress', text: `building the loop engine for ${m.name}…` });
      inbox = m.inbox ? new Int32Array(m.inbox) : null;
      received = 0;
      hoverFirst = m.hoverFirst === 'all' ? 0xffffffff : Number(m.hoverFirst) > 0 ? Number(m.hoverFirst) : HOVER_FIRST;
      hoverHold = m.hoverHold != null && Number(m.hoverHold) >= 0 ? Number(m.hoverHold) : HOVER_HOLD;
      const started = performance.now();
      designer = new LayoutDesigner(new Uint8Array(m.bytes), m.name);
      if (m.hoverBridge === '0') designer.setHoverBridge(false);
      // The analysis worker gets the design mesh (the proxy, for a large
      // input) made here, and the input: it neither imports nor decimates
      // the file again while the first hovers run.
      analyzerInit = designer.takeAnalysisMeshes();
      startAnalyzer();
      designer.warmUp();
      const surface = designer.surface();
      self.postMessage({
        type: 'ready', faces: designer.faceCount(), inputFaces: designer.inputFaceCount(), proxy: designer.usesProxy(),
        buildMs: performance.now() - started, wasmMs, surface,
      }, transferables(surface));
      // The distances from ∂ (open meshes) in idle time, before the hovers need them.
      prepareSoon();
    } else if (m.type === 'crash-for-testing') {
      panicForTesting();
    } else if (m.type === 'hold-analysis-for-testing') {
      if (!hold) throw new Error('holding the analysis needs cross-origin isolation');
      Atomics.store(hold, 0, m.on ? 1 : 0);
      if (!m.on) Atomics.notify(hold, 0);
    } else if (!designer) {
      throw new Error('the layout worker has no mesh yet');
    } else if (m.type === 'hover') {
      const started = performance.now();
      let proposal = designer.hoverBegin(m.point, hoverFirst);
      let exact = designer.hoverExact();
      while (!exact && hoverHold > 0 && designer.hoverPending() && performance.now() - started < hoverHold
        && (!inbox || Atomics.load(inbox, 0) === received)) {
        const found = designer.hoverStep(HOVER_SLICE);
        if (found !== undefined) { proposal = found; exact = true; }
      }
      const ms = performance.now() - started;
      self.postMessage({ type: 'hover', proposal, ms, t: m.t, exact, final: false }, [proposal.buffer]);
      hoverJob = exact ? null : { t: m.t, ms };
      if (designer.hoverPending() && inbox) hoverSlices();
      if (designer.hoverPending()) idleSoon();
    } else if (m.type === 'action') {
      if (!ACTIONS.has(m.name)) throw new Error(`unknown design action ${m.name}`);
      const started = performance.now();
      const value = designer[m.name](...(m.args || []));
      // An action that finished an unfinished hover (Enter, the wheel)
      // answered with its exact loop: the hover's own answer is dropped.
      if (hoverJob && !designer.hoverPending()) hoverJob = null;
      const state = designer.state();
      self.postMessage({ type: 'state', action: m.name, value, state, ms: performance.now() - started, t: m.t, serial: m.serial }, transferables(state));
      queueAnalysis();
      prepareSoon();
    } else if (m.type === 'export' || m.type === 'grid' || m.type === 'fit') {
      // For the state of the newest analysis request; answered by the
      // analysis worker (relayed above).
      forwarded.add(m.id);
      analyzer.postMessage({ ...m, serial });
    }
    // A hover search this message interrupted goes on.
    if (designer && designer.hoverPending()) idleSoon();
  } catch (error) {
    fail(error);
  }
};
