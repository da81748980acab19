// The pipeline's worker: all mesh work happens here, never on the page's
// thread. One Session (Rust) lives here between messages.
//
// Messages in:   { type: 'run', job, name, bytes: ArrayBuffer, cancelFlag?: SharedArrayBuffer }
//                { type: 'cancel', job }
//                { type: 'panic-for-testing', job }
// Messages out:  { type: 'progress', job, stage, fraction, text }
//                { type: 'stage', job, stage, ms, ...result }   typed arrays transferred
//                  (result: report, mesh, scalars, lines, points, counts; see src/web/worker_api.rs)
//                { type: 'done', job, summary }
//                { type: 'cancelled', job }
//                { type: 'error', job, message, fatal }        fatal: the worker must be replaced
//
// Cancellation is checked between stages, when this script is back in its
// event loop; when the page is cross-origin isolated it also passes a shared
// flag that stages read through the progress callback. The page terminates
// the worker as the last resort (see main.js).
import init, { Session, takePanicMessage, panicForTesting } from './pkg/quadrille.js';

const ready = init();
let session = null;
let current = null; // { job, cancelled, flag }

const nextTask = () => new Promise((resolve) => setTimeout(resolve, 0));

// Every ArrayBuffer under a result, so it moves to the page instead of being copied.
function transferables(value, out = []) {
  if (ArrayBuffer.isView(value)) out.push(value.buffer);
  else if (value && typeof value === 'object') for (const v of Object.values(value)) transferables(v, out);
  return out;
}

function fail(job, error) {
  const fatal = error instanceof WebAssembly.RuntimeError;
  const message = (fatal && takePanicSafely()) || String((error && error.message) || error);
  self.postMessage({ type: 'error', job, message, fatal });
}

function takePanicSafely() {
  try { return takePanicMessage(); } catch { return null; }
}

async function run({ job, name, bytes, cancelFlag }) {
  if (current) current.cancelled = true;
  const me = { job, cancelled: false, flag: cancelFlag ? new Int32Array(cancelFlag) : null };
  current = me;
  const isCancelled = () => me.cancelled || (me.flag !== null && Atomics.load(me.flag, 0) !== 0);
  try {
    await ready;
    session ??= new Session();
    session.start(new Uint8Array(bytes), name);
    // Returns whether to go on; stages ask it in their loops.
    const progress = (stage, fraction, text) => {
      self.postMessage({ type: 'progress', job, stage, fraction, text });
      return !isCancelled();
    };
    const emit = (result) => self.postMessage({ type: 'stage', job, ...result }, transferables(result));
    while (session.nextStep() !== undefined) {
      await nextTask();
      if (isCancelled()) break;
      session.step(progress, emit);
      if (session.cancelled) break;
    }
    if (isCancelled() || session.cancelled) {
      self.postMessage({ type: 'cancelled', job });
      return;
    }
    self.postMessage({ type: 'done', job, summary: session.summary() });
  } catch (error) {
    fail(job, error);
  } finally {
    if (current === me) current = null;
  }
}

self.onmessage = async (event) => {
  const message = event.data;
  if (message.type === 'run') {
    run(message);
  } else if (message.type === 'cancel') {
    if (current && current.job === message.job) current.cancelled = true;
  } else if (message.type === 'panic-for-testing') {
    try {
      await ready;
      panicForTesting();
    } catch (error) {
      fail(message.job, error);
    }
  }
};
