// The design mode's analysis worker (dual strip weaving, Campen & Kobbelt
// 2014 §4.2, §6, §7): strips, regions, singularities and the primal layout
// of the committed loops, away from the layout worker so that hover, clicks
// and Enter never wait for it. Started by the layout worker.
//
// Messages in:   { type: 'init', bytes: ArrayBuffer, name }
//                { type: 'analyze', serial, input }   input: LayoutDesigner.takeAnalysisInput()
// Messages out:  { type: 'analysis', serial, revision, analysis, ms }
//                { type: 'error', serial, message, fatal }
//
// Only the newest request runs: requests that arrive while one is running
// replace each other (a newer action cancels a stale analysis that has not
// started); the layout worker ignores results whose serial is not its newest.
import init, { LayoutAnalyzer, takePanicMessage } from './pkg/quadrille.js';

const ready = init();
let analyzer = null;
let pending = null;
let scheduled = false;

function transferables(value, out = []) {
  if (ArrayBuffer.isView(value)) out.push(value.buffer);
  else if (value && typeof value === 'object') for (const v of Object.values(value)) transferables(v, out);
  return out;
}

function run() {
  scheduled = false;
  const m = pending;
  pending = null;
  if (!m || !analyzer) return;
  try {
    const started = performance.now();
    const i = m.input;
    const analysis = analyzer.analyze(i.points, i.lengths, i.closed, i.moves);
    analysis.revision = i.revision;
    self.postMessage({ type: 'analysis', serial: m.serial, revision: i.revision, analysis, ms: performance.now() - started },
      transferables(analysis));
  } catch (error) {
    const fatal = error instanceof WebAssembly.RuntimeError;
    let message = String((error && error.message) || error);
    if (fatal) {
      try { message = takePanicMessage() || message; } catch { /* the module is gone */ }
    }
    self.postMessage({ type: 'error', serial: m.serial, message, fatal });
  }
}

self.onmessage = async (event) => {
  const m = event.data;
  await ready;
  if (m.type === 'init') {
    if (analyzer) analyzer.free();
    analyzer = null;
    pending = null;
    try {
      analyzer = new LayoutAnalyzer(new Uint8Array(m.bytes), m.name);
    } catch (error) {
      self.postMessage({ type: 'error', serial: null, message: String((error && error.message) || error), fatal: false });
    }
  } else if (m.type === 'analyze') {
    pending = m;
    if (!scheduled) {
      scheduled = true;
      setTimeout(run, 0);
    }
  }
};
