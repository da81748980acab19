// The pipeline's worker: all mesh work happens here, never on the page's
// thread. One Session (Rust) lives here between messages.
//
// Messages in:   { type: 'run', job, name, bytes: ArrayBuffer, params: object, cancelFlag?: SharedArrayBuffer }
//                { type: 'params', job, params: object, cancelFlag? }   re-runs from the first changed stage
//                { type: 'param', job, cancelFlag? }   the parametrization layer, on demand (needs an import)
//                { type: 'export', id, kind, format }
//                { type: 'schema', id }
//                { type: 'cancel', job }
//                { type: 'panic-for-testing', job }
//                { type: 'fail-stage-for-testing', stage }   the next run's `stage` fails (once)
//                { type: 'hold-stage-for-testing', stage }   the next job's `stage`, after its first progress
//                  report, waits until the job's shared cancel flag is set (HOLD_MS at most), then goes on
//                  (once; needs cross-origin isolation)
// Messages out:  { type: 'progress', job, stage, fraction, text }
//                { type: 'stage', job, stage, ms, ...result }   typed arrays transferred
//                  (result: report, mesh, scalars, lines, points, counts, metrics, surface; see src/web/worker_api.rs)
//                { type: 'done', job, summary, from }          from: first stage run again (parameter changes)
//                { type: 'param-done', job }                 after the parametrization's 'stage' message
//                { type: 'cancelled', job }
//                { type: 'error', job, message, fatal }        fatal: the worker must be replaced
//                { type: 'reply', id, value?, error? }         answers to export and schema
//
// Cancellation is checked between stages, when this script is back in its
// event loop; when the page is cross-origin isolated it also passes a shared
// flag that stages read through the progress callback. The page terminates
// the worker as the last resort (see main.js).
import init, { Session, takePanicMessage, panicForTesting } from './pkg/quadrille.js';

const ready = init();
let session = null;
let current = null; // { job, cancelled, flag }
let failStage = null; // (tests) the stage the next run fails in
let holdStage = null; // (tests) the stage the next job holds in until cancelled
// (tests) The longest a held stage waits for its cancel flag before it goes on.
const HOLD_MS = 20000;

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

// Runs `prepare(session)` then every remaining step of the session; with
// `work`, runs `work(session, progress, emit)` instead of the steps (the
// parametrization layer), which returns false when cancelled.
async function drive({ job, cancelFlag }, prepare, work = null) {
  if (current) current.cancelled = true;
  const me = { job, cancelled: false, failed: null, flag: cancelFlag ? new Int32Array(cancelFlag) : null };
  current = me;
  const isCancelled = () => me.cancelled || (me.flag !== null && Atomics.load(me.flag, 0) !== 0);
  try {
    await ready;
    session ??= new Session();
    const from = prepare(session);
    // Returns whether to go on; stages ask it in their loops. The longest
    // wait between two calls within a stage is measured here, in the
    // worker (the page's clock would add its own busy time).
    const gaps = {};
    let last = null;
    const progress = (stage, fraction, text) => {
      const now = performance.now();
      if (last && last.stage === stage) gaps[stage] = Math.max(gaps[stage] || 0, Math.round(now - last.time));
      last = { stage, time: now };
      self.postMessage({ type: 'progress', job, stage, fraction, text });
      // (tests) The stage stops as if cancelled, and the run fails below.
      if (failStage !== null && stage === failStage) {
        me.failed = stage;
        failStage = null;
      }
      // (tests) The stage is running and has said so: it waits here for
      // Cancel (the page sets the shared flag), so that Cancel always meets
      // it running however fast it is.
      if (holdStage !== null && stage === holdStage && me.flag !== null) {
        holdStage = null;
        // The page stores the flag without a notify: looked at every 5 ms.
        const until = performance.now() + HOLD_MS;
        while (Atomics.load(me.flag, 0) === 0 && performance.now() < until) Atomics.wait(me.flag, 0, 0, 5);
      }
      return !isCancelled() && !me.failed;
    };
    const emit = (result) => self.postMessage({ type: 'stage', job, ...result }, transferables(result));
    if (work) {
      await nextTask();
      if (isCancelled() || !work(session, progress, emit)) self.postMessage({ type: 'cancelled', job });
      else self.postMessage({ type: 'param-done', job, progressGapsMs: gaps });
      return;
    }
    while (session.nextStep() !== undefined) {
      await nextTask();
      if (isCancelled()) break;
      session.step(progress, emit);
      if (me.failed) throw new Error(`${me.failed}: a failure asked for by a test`);
      if (session.cancelled) break;
    }
    if (isCancelled() || session.cancelled) {
      self.postMessage({ type: 'cancelled', job });
      return;
    }
    self.postMessage({ type: 'done', job, summary: session.summary(), from, progressGapsMs: gaps });
  } catch (error) {
    fail(job, error);
  } finally {
    if (current === me) current = null;
  }
}

async function reply(id, f) {
  try {
    await ready;
    const value = f();
    self.postMessage({ type: 'reply', id, value }, transferables(value));
  } catch (error) {
    self.postMessage({ type: 'reply', id, error: String((error && error.message) || error) });
  }
}

self.onmessage = async (event) => {
  const message = event.data;
  if (message.type === 'run') {
    drive(message, (s) => {
      s.setParams(message.params ?? {});
      s.start(new Uint8Array(message.bytes), message.name);
      return 'import';
    });
  } else if (message.type === 'params') {
    drive(message, (s) => s.setParams(message.params) ?? null);
  } else if (message.type === 'param') {
    drive(message, () => null, (s, progress, emit) => s.parametrize(progress, emit));
  } else if (message.type === 'export') {
    reply(message.id, () => {
      if (!session) throw new Error('nothing was imported');
      return session.export(message.kind, message.format);
    });
  } else if (message.type === 'schema') {
    reply(message.id, () => Session.parameterSchema());
  } else if (message.type === 'cancel') {
    if (current && current.job === message.job) current.cancelled = true;
  } else if (message.type === 'fail-stage-for-testing') {
    failStage = message.stage;
  } else if (message.type === 'hold-stage-for-testing') {
    holdStage = message.stage;
  } else if (message.type === 'panic-for-testing') {
    try {
      await ready;
      panicForTesting();
    } catch (error) {
      fail(message.job, error);
    }
  }
};
