// The pipeline's worker: all Rust/wasm work happens here, never on the page's thread.
import init, { importReport } from './pkg/quadrille.js';

const ready = init();

self.onmessage = async (event) => {
  const { id, name, bytes } = event.data;
  try {
    await ready;
    const started = performance.now();
    const report = importReport(new Uint8Array(bytes), name);
    self.postMessage({ id, kind: 'report', report, ms: performance.now() - started });
  } catch (error) {
    self.postMessage({ id, kind: 'error', message: String(error && error.message || error) });
  }
};
