// The "Design layout" mode: dual strip weaving (Campen & Kobbelt 2014 §4.1)
// on the page. The LayoutDesigner lives in its own worker (layout-worker.js);
// this file turns pointer and key events into its actions and draws what it
// answers: the proposal loop, anchors, committed loops, and — once the
// analysis arrives — stripes, region colouring, singularities and the layout.
//
// Hover: at most one query in flight; when its answer arrives the latest
// pointer position (if it moved) is sent. The same holds for drags.

const COLOURS = {
  proposal: [255, 122, 26, 255],
  anchor: [20, 20, 20, 255],
  directional: [59, 111, 216, 255],
  loop: [29, 35, 48, 255],
  layoutEdge: [17, 17, 17, 255],
  layoutVertex: [106, 61, 154, 255],
  grid: [70, 70, 70, 255],
  selfCrossing: [230, 0, 126, 255],
};
// Layers this mode draws (line and point layers of the viewer).
const LAYER_NAMES = ['design proposal', 'design anchors', 'design self-crossings', 'design loops', 'strips', 'strip singularities', 'layout edges', 'layout vertices', 'layout grid'];
export const REGION_SURFACE = 'layout regions';
const CLICK_PX = 4;

// Flat polyline (xyz…) → segments (six floats each).
function segmentsOf(polyline) {
  const n = polyline.length / 3;
  if (n < 2) return new Float32Array(0);
  const out = new Float32Array((n - 1) * 6);
  for (let i = 0; i + 1 < n; i++) out.set(polyline.subarray(i * 3, i * 3 + 6), i * 6);
  return out;
}

function concat(arrays) {
  const out = new Float32Array(arrays.reduce((s, a) => s + a.length, 0));
  let k = 0;
  for (const a of arrays) { out.set(a, k); k += a.length; }
  return out;
}

const dist2 = (a, b) => (a[0] - b[0]) ** 2 + (a[1] - b[1]) ** 2 + (a[2] - b[2]) ** 2;

// Squared distance from p to the polyline, and the nearest point.
function nearestOnPolyline(polyline, p) {
  let best = { d2: Infinity, point: null };
  for (let i = 0; i + 5 < polyline.length; i += 3) {
    const a = polyline.subarray(i, i + 3);
    const b = polyline.subarray(i + 3, i + 6);
    const ab = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    const len2 = ab[0] ** 2 + ab[1] ** 2 + ab[2] ** 2;
    const t = len2 > 0 ? Math.max(0, Math.min(1, ((p[0] - a[0]) * ab[0] + (p[1] - a[1]) * ab[1] + (p[2] - a[2]) * ab[2]) / len2)) : 0;
    const q = [a[0] + ab[0] * t, a[1] + ab[1] * t, a[2] + ab[2] * t];
    const d2 = dist2(p, q);
    if (d2 < best.d2) best = { d2, point: q };
  }
  return best;
}

const median = (xs) => {
  if (!xs.length) return null;
  const s = [...xs].sort((a, b) => a - b);
  return s[Math.floor(s.length / 2)];
};

// ctx: { $, viewer(), requestRender(), afterNextFrame(fn), pick(clientX, clientY) → [x,y,z] | null,
//        input() → { name, bytes } | null, setRegionSurface(surface | null), setStatus, showError, dpr() }
export function createDesignMode(ctx) {
  const { $ } = ctx;
  const stats = {
    active: false, ready: false, crashed: false, state: null, analysis: null, proxy: false,
    faces: 0, inputFaces: 0, buildMs: null, hoverPickMs: [], hoverReplies: 0,
    // The hover is answered progressively (layout-worker.js): a first draw
    // at once (the exact loop, or a provisional one while the exact search
    // goes on), then the exact loop. Per hover, from its handler: the exact
    // loop drawn (hoverLatencies; what the tests wait for) and the first
    // draw (hoverFirstLatencies); the layout worker's time to the exact
    // answer (hoverWorkerMs, summed over its slices) and to the first
    // (hoverFirstWorkerMs); hovers first drawn provisionally (a provisional
    // answer without a loop is not drawn: that hover's first draw is its
    // exact draw).
    hoverLatencies: [], hoverFirstLatencies: [], hoverWorkerMs: [], hoverFirstWorkerMs: [], hoverProvisional: 0,
    // … of which the exact loop was the provisional one (not drawn again);
    // hovers whose first answer was not the exact loop (drawn or not).
    hoverUnchanged: 0, hoverUnfinished: 0,
    analyses: 0, lastDrawn: 0, exportCount: 0, actionMs: {},
    // Per action: event → its state drawn (ms, measured on the page).
    actionLatencies: {},
    // Enter while an action was in flight: queued, or dropped (a second
    // press while one waits).
    queuedEnters: 0, droppedEnters: 0, queuedEnterProposal: null,
    actionsSent: 0, actionsAnswered: 0,
    // Revisions of the analyses drawn, in order, and the stale analyses
    // given up ({ revision, started, ms }; started: stopped while running).
    analysisRevisions: [], cancelledAnalyses: [],
    // Tests: the revision of the analysis last held at its first step.
    heldAnalysis: null,
    // Segments in each line layer this mode drew last, and the label of
    // the surface it shows (null: the input's).
    segments: {}, shownSurface: null,
  };
  let worker = null;
  let inputName = null;
  let surface = null; // the design mesh (proxy or input): { positions, triangles }
  let hoverBusy = false;
  let hoverNext = null; // { point, t }
  let hoverSent = -Infinity; // t of the newest hover posted
  let undrawn = null; // t of the newest hover whose provisional answer had no loop (not drawn)
  let firstDrawn = { t: null, at: null }; // the newest hover's first draw: its t and the frame's time
  let actionBusy = false;
  let dragNext = null; // latest drag update: { name, args, t, serial }
  let actionSerial = 0; // serial of the newest action (posted or waiting in dragNext)
  let enterAfter = null; // Enter pressed during an action: { after: serial, t }
  let proposal = new Float32Array(0);
  let gesture = null; // the current left-button gesture
  let nextRequest = 1;
  const pending = new Map();
  const stripCounts = new Map(); // grid count per strip id (none: the panel's count)
  let gridSerial = null; // the analysis serial (strips and moves) the drawn grid belongs to

  function post(message, transfer) {
    if (worker && !stats.crashed) toWorker(message, transfer);
  }

  // Every message after init is counted in `inbox` (shared with the layout
  // worker when the page is cross-origin isolated), so that the worker's
  // unfinished hover search stops for it at its next slice.
  let inbox = null;
  function toWorker(message, transfer = []) {
    if (inbox) Atomics.add(inbox, 0, 1);
    worker.postMessage(message, transfer);
  }

  function start() {
    const input = ctx.input();
    if (!input) { ctx.showError('open a mesh first'); return false; }
    stop();
    stats.crashed = false;
    stats.ready = false;
    stripCounts.clear(); // a new session: its strip ids start again
    clearGrid();
    inputName = input.name;
    stats.startedAt = performance.now();
    worker = new Worker(new URL('./layout-worker.js', import.meta.url), { type: 'module' });
    worker.onmessage = (event) => onMessage(event.data);
    worker.onerror = (event) => { event.preventDefault(); crashed(event.message || 'the layout worker stopped'); };
    const bytes = input.bytes.slice(0);
    // `?hoverFirst=N`: g′ nodes the layout worker searches before a hover's
    // first answer (benchmarks; `all`: every hover answered exactly at once).
    const hoverFirst = new URLSearchParams(location.search).get('hoverFirst');
    // `?hoverHold=ms`: how long an unfinished hover search goes on before
    // its provisional loop is posted (layout-worker.js's HOVER_HOLD).
    const hoverHold = new URLSearchParams(location.search).get('hoverHold');
    // `?hoverBridge=0`: no provisional loops bridged to recent ones (benchmarks).
    const hoverBridge = new URLSearchParams(location.search).get('hoverBridge');
    inbox = self.crossOriginIsolated ? new Int32Array(new SharedArrayBuffer(4)) : null;
    worker.postMessage({ type: 'init', bytes, name: input.name, hoverFirst, hoverHold, hoverBridge, inbox: inbox && inbox.buffer }, [bytes]);
    $('design-note').textContent = `Building the loop engine for ${input.name}…`;
    return true;
  }

  function stop() {
    if (worker) worker.terminate();
    worker = null;
    hoverBusy = actionBusy = false;
    hoverNext = dragNext = enterAfter = null;
    stats.actionsAnswered = stats.actionsSent; // nothing is in flight any more
    for (const { reject } of pending.values()) reject(new Error('the design mode was closed'));
    pending.clear();
  }

  function crashed(message) {
    stats.crashed = true;
    stop();
    $('design-crash').hidden = false;
    $('design-crash-text').textContent = `The layout worker crashed (${message}). The page is fine; your strips are lost.`;
    ctx.showError(`layout worker crashed: ${message}`);
  }

  function onMessage(m) {
    switch (m.type) {
      case 'progress':
        $('design-note').textContent = m.text;
        break;
      case 'ready':
        stats.ready = true;
        stats.proxy = m.proxy;
        stats.faces = m.faces;
        stats.inputFaces = m.inputFaces;
        stats.buildMs = m.buildMs;
        stats.wasmMs = m.wasmMs;
        stats.readyAfterMs = performance.now() - stats.startedAt;
        surface = m.surface;
        // On a proxy, the proxy is drawn: the loops lie on it, not on the input.
        if (m.proxy) setSurface(proxySurface());
        $('design-note').textContent = (m.proxy
          ? `Designing on a proxy of ${m.faces} faces (decimated from the ${m.inputFaces}-face input) so hovering stays fast. `
          : `${m.faces} faces. `) + `Loop engine built in ${m.buildMs.toFixed(0)} ms.`;
        // Apply the mirror option chosen before the engine was ready.
        if ($('design-mirror').value !== 'off') action('setMirror', [$('design-mirror').value]);
        else action('clearAnchors', []);
        break;
      case 'hover': {
        // First the answer to a hover (m.exact: the exact loop, else a
        // provisional one), then, when that was provisional, the exact
        // loop for the same hover (m.final).
        // A provisional answer without a loop (none found yet) is not
        // drawn: the hover's first draw is then its exact draw.
        const nothing = !m.exact && m.proposal.length === 0;
        if (!m.final) {
          hoverBusy = false;
          stats.hoverReplies++;
          if (!nothing) stats.hoverFirstWorkerMs.push(m.ms);
          if (!m.exact && !nothing) stats.hoverProvisional++;
          if (!m.exact) stats.hoverUnfinished++;
          undrawn = nothing ? m.t : null;
        }
        if (m.exact) stats.hoverWorkerMs.push(m.ms);
        if (m.final && undrawn === m.t) stats.hoverFirstWorkerMs.push(m.ms);
        // An exact loop for a hover since replaced by a newer one is not drawn.
        const current = !m.final || (m.t >= hoverSent && !hoverNext);
        const shown = current && !nothing && (!stats.state || stats.state.anchors.length === 0);
        if (shown && m.final && undrawn === m.t) drawProposal(m.proposal, m.t, { first: true, exact: true });
        else if (shown && m.final && m.unchanged) {
          // The provisional loop on screen is the exact one: it is not drawn
          // again, and its exact draw is its first draw.
          stats.hoverUnchanged++;
          if (firstDrawn.t === m.t) stats.hoverLatencies.push(firstDrawn.at - m.t);
          else ctx.afterNextFrame(() => stats.hoverLatencies.push((firstDrawn.t === m.t ? firstDrawn.at : performance.now()) - m.t));
        } else if (shown) drawProposal(m.proposal, m.t, { first: !m.final, exact: m.exact });
        if (hoverNext) { const h = hoverNext; hoverNext = null; sendHover(h.point, h.t); }
        break;
      }
      case 'state': {
        actionBusy = false;
        stats.actionsAnswered++;
        (stats.actionMs[m.action] ??= []).push(m.ms);
        onState(m.state, m.t);
        const t = m.t;
        ctx.afterNextFrame(() => (stats.actionLatencies[m.action] ??= []).push(performance.now() - t));
        if (m.action === 'commit' && m.value === 0 && !m.state.error) { ctx.setStatus('nothing to commit: hover over the surface first'); stats.statusShown = true; }
        // A drag update queued before a waiting Enter goes first; the Enter
        // then commits the loop of the newest action before it, now drawn.
        if (dragNext && (!enterAfter || dragNext.serial <= enterAfter.after)) {
          const d = dragNext;
          dragNext = null;
          send(d);
        } else if (enterAfter && m.serial >= enterAfter.after) {
          const e = enterAfter;
          enterAfter = null;
          stats.queuedEnterProposal = proposal;
          action('commit', [], e.t);
        }
        break;
      }
      case 'analysis':
        // A newer analysis: the strips or the layout-vertex moves changed.
        if (stats.grid && m.serial > gridSerial) clearGrid();
        stats.analysisRevisions.push(m.analysis.revision);
        onAnalysis(m.analysis, m.ms);
        break;
      case 'analysis-cancelled':
        stats.cancelledAnalyses.push({ revision: m.revision, started: m.started, ms: m.ms });
        break;
      case 'analysis-held':
        stats.heldAnalysis = m.revision;
        break;
      case 'reply': {
        const p = pending.get(m.id);
        pending.delete(m.id);
        if (p) (m.error !== undefined ? p.reject(new Error(m.error)) : p.resolve(m.value));
        break;
      }
      case 'error':
        if (m.fatal) crashed(m.message);
        else ctx.showError(`design: ${m.message}`);
        break;
    }
  }

  function sendHover(point, t) {
    if (!stats.ready) return;
    if (hoverBusy) { hoverNext = { point, t }; return; }
    hoverBusy = true;
    hoverSent = t;
    post({ type: 'hover', point, t });
  }

  // Actions; drag updates (direction, grabbed anchor) keep one in flight, the latest wins.
  // Each action gets a serial (echoed in its state) so that an Enter
  // pressed meanwhile commits right after the action it followed.
  function action(name, args, t = performance.now(), { latest = false } = {}) {
    if (!stats.ready) return;
    const serial = ++actionSerial;
    if (latest && actionBusy) { dragNext = { name, args, t, serial }; return; }
    send({ name, args, t, serial });
  }

  function send({ name, args, t, serial }) {
    actionBusy = true;
    stats.actionsSent++;
    post({ type: 'action', name, args, t, serial });
  }

  function layerRgba(c, n) {
    const out = new Uint8Array(4 * n);
    for (let i = 0; i < n; i++) out.set(c, 4 * i);
    return out;
  }

  function setLines(name, segments, rgba) {
    const v = ctx.viewer();
    if (!v) return;
    v.set_lines(name, segments, rgba);
    stats.segments[name] = segments.length / 6;
  }

  function setSurface(surface) {
    stats.shownSurface = surface ? surface.label || surface.name : null;
    ctx.setRegionSurface(surface);
  }

  function setPoints(name, positions, rgba, size) {
    const v = ctx.viewer();
    if (!v) return;
    v.set_points(name, positions, rgba, size * ctx.dpr());
  }

  // A hover's answer (t: its handler's time) records its first draw and,
  // when exact, its exact draw; any other proposal (t given) its exact draw.
  function drawProposal(polyline, t, { first = false, exact = true } = {}) {
    proposal = polyline;
    stats.proposal = polyline;
    setLines('design proposal', segmentsOf(polyline), new Uint8Array(COLOURS.proposal));
    ctx.requestRender();
    if (t !== undefined) {
      ctx.afterNextFrame(() => {
        const now = performance.now();
        if (first) {
          stats.hoverFirstLatencies.push(now - t);
          firstDrawn = { t, at: now };
        }
        if (exact) {
          stats.lastDrawn = now;
          stats.hoverLatencies.push(now - t);
        }
      });
    }
  }

  function onState(state, t) {
    stats.state = state;
    if (state.error) { ctx.setStatus(`design: ${state.error}`); stats.statusShown = true; }
    else if (stats.statusShown) { ctx.setStatus(''); stats.statusShown = false; }
    // With anchors the proposal is their loop; without, keep the hover's.
    if (state.anchors.length || state.proposal.length) drawProposal(state.proposal, t);
    else if (!state.anchors.length) drawProposal(new Float32Array(0));
    const n = state.anchors.length / 3;
    const colours = new Uint8Array(4 * n);
    for (let i = 0; i < n; i++) {
      const d = state.anchorDirections.subarray(3 * i, 3 * i + 3);
      colours.set(d[0] || d[1] || d[2] ? COLOURS.directional : COLOURS.anchor, 4 * i);
    }
    setPoints('design anchors', state.anchors, colours, 10);
    // §8.1: the proposal's self-crossings, highlighted, with a request to adjust.
    const crossings = state.selfCrossings || new Float32Array(0);
    setPoints('design self-crossings', crossings, new Uint8Array(COLOURS.selfCrossing), 16);
    if (crossings.length) {
      const worst = Math.min(...state.selfCrossingAngles);
      ctx.setStatus(`design: the loop crosses itself ${crossings.length / 3}× (smallest angle ${worst.toFixed(0)}°): move or add anchors to adjust it`);
      stats.statusShown = true;
    }
    // Committed loops (spines): drawn at once; the stripes follow with the analysis.
    const loops = state.loops.map((l) => segmentsOf(l.points));
    const loopColours = new Uint8Array(loops.reduce((n, l) => n + l.length / 6, 0) * 4);
    let k = 0;
    loops.forEach((l, i) => {
      const c = STRIP_RGBA[i % STRIP_RGBA.length];
      for (let j = 0; j < l.length / 6; j++, k++) loopColours.set(c, 4 * k);
    });
    setLines('design loops', concat(loops), loopColours.length ? loopColours : new Uint8Array(COLOURS.loop));
    updatePanel();
    ctx.requestRender();
  }

  function onAnalysis(a, ms) {
    stats.analysis = a;
    stats.analyses++;
    stats.analysisMs = ms;
    setLines('strips', a.stripes, a.stripeColours.length ? a.stripeColours : new Uint8Array(COLOURS.loop));
    setPoints('strip singularities', a.singularities, a.singularityColours.length ? a.singularityColours : new Uint8Array([31, 111, 221, 255]), 9);
    setLines('layout edges', a.layoutEdges, new Uint8Array(COLOURS.layoutEdge));
    setPoints('layout vertices', a.layoutVertices, new Uint8Array(COLOURS.layoutVertex), 13);
    drawGridAndSurface();
    updatePanel();
    ctx.requestRender();
  }

  // The gridded layout (in the stripes' place) and the surface the mode
  // shows: the fit's limit surface, else the region colouring, else the
  // proxy (or the input's own surface).
  function drawGridAndSurface() {
    if (stats.grid) {
      setLines('layout grid', stats.grid.edges, new Uint8Array(COLOURS.grid));
      setLines('strips', new Float32Array(0), new Uint8Array(4));
    }
    const a = stats.analysis;
    const f = stats.fit && stats.fit.surface;
    setSurface(f ? { name: REGION_SURFACE, label: 'Limit surface (design)', color: '#9970ab', color2: '#5aae61', positions: f.positions, triangles: f.triangles, normals: f.normals, scalar: f.scalar }
      : a && a.regionCategory.length && surface ? regionSurface(a.regionCategory)
        : stats.proxy && surface ? proxySurface() : null);
  }

  // The proxy as an indexed surface with area-weighted vertex normals.
  function proxySurface() {
    const { positions: p, triangles: t } = surface;
    const normals = new Float32Array(p.length);
    for (let f = 0; f < t.length; f += 3) {
      const [a, b, c] = [t[f], t[f + 1], t[f + 2]];
      const u = [p[3 * b] - p[3 * a], p[3 * b + 1] - p[3 * a + 1], p[3 * b + 2] - p[3 * a + 2]];
      const v = [p[3 * c] - p[3 * a], p[3 * c + 1] - p[3 * a + 1], p[3 * c + 2] - p[3 * a + 2]];
      const n = [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]];
      for (const i of [a, b, c]) for (let k = 0; k < 3; k++) normals[3 * i + k] += n[k];
    }
    for (let i = 0; i < normals.length; i += 3) {
      const len = Math.hypot(normals[i], normals[i + 1], normals[i + 2]) || 1;
      for (let k = 0; k < 3; k++) normals[i + k] /= len;
    }
    return { name: REGION_SURFACE, positions: p, triangles: t, normals, scalar: null };
  }

  // An unindexed per-face copy of the design mesh coloured by region category.
  function regionSurface(category) {
    const { positions: p, triangles: t } = surface;
    const smooth = proxySurface().normals;
    const nf = t.length / 3;
    const positions = new Float32Array(nf * 9);
    const normals = new Float32Array(nf * 9);
    const values = new Float32Array(nf * 3);
    for (let f = 0; f < nf; f++) {
      for (let k = 0; k < 3; k++) {
        const vertex = t[3 * f + k];
        positions.set(p.subarray(3 * vertex, 3 * vertex + 3), 9 * f + 3 * k);
        normals.set(smooth.subarray(3 * vertex, 3 * vertex + 3), 9 * f + 3 * k);
        values[3 * f + k] = category[f] ?? 0;
      }
    }
    const triangles = new Uint32Array(nf * 3).map((_, i) => i);
    return {
      name: REGION_SURFACE, positions, triangles, normals,
      scalar: { name: 'layout regions: red not a disc · orange curvature extrema · yellow valence off', values, min: 0, max: 12, colormap: 'categories' },
    };
  }

  function updatePanel() {
    const s = stats.state;
    const a = stats.analysis;
    $('design-undo').disabled = !s || !s.canUndo;
    $('design-redo').disabled = !s || !s.canRedo;
    $('design-clear').disabled = !s || !s.anchors.length;
    const strips = s ? s.loops.length : 0;
    const fresh = a && s && a.revision === s.revision;
    $('design-status').textContent = fresh ? a.status : strips ? `${strips} strip${strips === 1 ? '' : 's'} · analysing…` : 'Hover over the surface to see the best loop; Enter commits it.';
    $('design-status').classList.toggle('error', !!(fresh && a.counts.red > 0));
    // Before the first strip the line is a hint, styled as one.
    $('design-status').classList.toggle('note', !strips);
    const c = fresh ? a.counts : null;
    const t = fresh ? a.timings : null;
    const fmt = (x) => (typeof x === 'number' ? `${x.toFixed(0)} ms` : '—');
    const rows = [
      ['strips', strips],
      ['patches', c ? c.patches : '—'],
      ['regions (red / orange / yellow)', c ? `${c.regions} (${c.red} / ${c.orange} / ${c.yellow})` : '—'],
      ['singularities', c ? c.singularities : '—'],
      ['loop (hover, median)', fmt(median(stats.hoverWorkerMs.slice(-50)))],
      ['field', fmt(t?.field_ms)],
      ['parametrization', fmt(t?.parametrization_ms)],
      ['layout', fmt(t?.layout_ms)],
    ];
    if (s) {
      const [i, n] = s.browse;
      if (n > 1) rows.push(['alternative', `${i + 1} of ${n}`]);
    }
    $('design-counts').replaceChildren(...rows.map(([k, v]) => {
      const tr = document.createElement('tr');
      for (const text of [k, v]) {
        const td = document.createElement('td');
        td.textContent = String(text);
        tr.append(td);
      }
      return tr;
    }));
    $('design-strips').replaceChildren(...(s ? s.loops : []).map((l, i) => {
      const li = document.createElement('li');
      const sw = document.createElement('span');
      sw.className = 'swatch';
      sw.style.background = STRIP_CSS[i % STRIP_CSS.length];
      const label = document.createElement('span');
      label.textContent = `strip ${i + 1}${l.mirrored ? ' (mirror image)' : ''}${l.closed ? '' : ' (ends on the boundary)'}`;
      const del = document.createElement('button');
      del.type = 'button';
      del.textContent = 'Delete';
      del.className = 'design-delete';
      del.addEventListener('click', () => action('deleteStrip', [i]));
      const count = document.createElement('input');
      count.type = 'number';
      count.min = '1';
      count.max = '256';
      count.className = 'design-strip-count';
      count.title = `grid segments across strip ${i + 1}`;
      count.value = String(stripCounts.get(l.id) ?? gridCount());
      count.addEventListener('change', () => { stripCounts.set(l.id, Math.round(Number(count.value)) || gridCount()); });
      li.append(sw, label, count, del);
      return li;
    }));
  }

  // ---------------------------------------------------------------- input

  function onHoverMove(e) {
    // With anchors the loop is theirs: hovering does not change it.
    if (!stats.ready || gesture || (stats.state && stats.state.anchors.length)) return;
    // The hover's latency counts from here: the pick is part of it.
    const t = performance.now();
    const p = ctx.pick(e.clientX, e.clientY);
    stats.hoverPickMs.push(performance.now() - t);
    if (p) sendHover(p, t);
  }

  function onWheel(e) {
    const d = e.deltaY || e.deltaX;
    if (!d) return;
    action('browse', [d > 0 ? 1 : -1], performance.now(), { latest: true });
  }

  // Left button: click = positional anchor; drag from the surface =
  // directional anchor; press on the current loop and drag = grab.
  function onDown(e) {
    const p = ctx.pick(e.clientX, e.clientY);
    if (!p) { gesture = null; return false; }
    const s = stats.state;
    let grab = null;
    if (s && s.anchors.length && proposal.length) {
      const near = nearestOnPolyline(proposal, p);
      const tolerance = 0.015; // local units: the largest bounding-box axis is 1
      if (near.d2 < tolerance * tolerance) grab = near.point;
    }
    const vertex = nearestLayoutVertex(p);
    gesture = { x: e.clientX, y: e.clientY, point: p, grab, vertex, started: false, index: null };
    return true;
  }

  function nearestLayoutVertex(p) {
    const a = stats.analysis;
    if (!a || !a.layoutVertices.length) return null;
    let best = null;
    for (let i = 0; i < a.layoutVertices.length / 3; i++) {
      const d2 = dist2(p, a.layoutVertices.subarray(3 * i, 3 * i + 3));
      if (d2 < 0.03 ** 2 && (!best || d2 < best.d2)) best = { i, d2 };
    }
    return best ? best.i : null;
  }

  function onDrag(e) {
    const g = gesture;
    if (!g) return;
    if (!g.started && Math.hypot(e.clientX - g.x, e.clientY - g.y) <= CLICK_PX) return;
    const t = performance.now();
    const p = ctx.pick(e.clientX, e.clientY);
    if (!p) return;
    if (g.vertex !== null) {
      g.started = true;
      g.to = p;
      const a = stats.analysis;
      const moved = new Float32Array(a.layoutVertices);
      moved.set(p, 3 * g.vertex);
      setPoints('layout vertices', moved, new Uint8Array(COLOURS.layoutVertex), 13);
      ctx.requestRender();
      return;
    }
    if (g.grab) {
      if (!g.started) action('insertAnchorOnLoop', [g.grab, p], t);
      else action('moveGrabbedAnchor', [p], t, { latest: true });
    } else {
      const dir = [p[0] - g.point[0], p[1] - g.point[1], p[2] - g.point[2]];
      if (!g.started) action('addAnchor', [g.point, dir], t);
      else action('setLastAnchorDirection', [dir], t, { latest: true });
    }
    g.started = true;
  }

  function onUp(e) {
    const g = gesture;
    gesture = null;
    if (!g) return;
    if (g.started) {
      if (g.vertex !== null && g.to) action('moveLayoutVertex', [g.vertex, g.to]);
      return;
    }
    if (e.type === 'pointerup') action('addAnchor', [g.point, []]);
  }

  function onKey(e) {
    const key = e.key.toLowerCase();
    if ((e.ctrlKey || e.metaKey) && key === 'z') { action(e.shiftKey ? 'redo' : 'undo', []); return true; }
    if ((e.ctrlKey || e.metaKey) && key === 'y') { action('redo', []); return true; }
    if (e.ctrlKey || e.metaKey || e.altKey) return false;
    // Enter commits the loop on screen. While an action is still being
    // answered, the press waits (by serial) for that action's answer, then
    // commits the loop it draws; a second press while one waits is dropped
    // (it would commit a loop nobody saw).
    if (key === 'enter') {
      if (!actionBusy) action('commit', []);
      else if (enterAfter) stats.droppedEnters++;
      else { enterAfter = { after: actionSerial, t: performance.now() }; stats.queuedEnters++; }
      return true;
    }
    if (key === 'escape') { action('clearAnchors', []); return true; }
    return false;
  }

  function clearLayers() {
    const v = ctx.viewer();
    if (!v) return;
    for (const name of LAYER_NAMES) {
      if (name.endsWith('anchors') || name.endsWith('vertices') || name.endsWith('singularities') || name.endsWith('crossings')) v.set_points(name, new Float32Array(0), new Uint8Array(4), 1);
      else v.set_lines(name, new Float32Array(0), new Uint8Array(4));
    }
    setSurface(null);
  }

  function enter() {
    if (stats.active) return;
    const input = ctx.input();
    if (!input) { ctx.showError('open a mesh first'); return; }
    stats.active = true;
    document.body.classList.add('designing');
    $('design-panel').hidden = false;
    $('design-toggle').textContent = 'Leave design mode (T)';
    $('design-crash').hidden = true;
    if (!worker || inputName !== input.name || stats.crashed) {
      stats.state = stats.analysis = null;
      stats.hoverLatencies = [];
      stats.hoverFirstLatencies = [];
      stats.hoverWorkerMs = [];
      stats.hoverFirstWorkerMs = [];
      stats.hoverPickMs = [];
      start();
    } else if (stats.state) {
      // Back in the mode: everything as it was, the grid and fit included.
      onState(stats.state);
      if (stats.analysis) onAnalysis(stats.analysis, stats.analysisMs);
      else drawGridAndSurface();
    }
    updatePanel();
  }

  function leave() {
    if (!stats.active) return;
    stats.active = false;
    gesture = null;
    document.body.classList.remove('designing');
    $('design-panel').hidden = true;
    $('design-toggle').textContent = 'Design layout (T)';
    clearLayers();
    ctx.requestRender();
  }

  // A new mesh: the design belongs to the old one.
  function reset() {
    leave();
    stop();
    stats.state = stats.analysis = null;
    stats.ready = false;
    inputName = null;
  }

  function request(message) {
    return new Promise((resolve, reject) => {
      if (!worker || stats.crashed) { reject(new Error('the design mode is not running')); return; }
      const id = nextRequest++;
      pending.set(id, { resolve, reject });
      toWorker({ ...message, id });
    });
  }

  const gridCount = () => Math.max(1, Math.min(256, Math.round(Number($('design-grid-count').value)) || 8));
  // One count per committed strip, in the strips' order, kept by strip id.
  const counts = () => (stats.state ? stats.state.loops : []).map((l) => stripCounts.get(l.id) ?? gridCount());

  function clearGrid() {
    gridSerial = null;
    stats.grid = stats.fit = null;
    setLines('layout grid', new Float32Array(0), new Uint8Array(4));
    $('design-fit').disabled = true;
    $('design-export-grid').disabled = true;
    $('design-grid-status').textContent = 'Grid the layout into quads, then fit a Catmull–Clark surface.';
  }

  // Grids the layout (one count per strip) and draws the quads.
  async function gridLayout(given) {
    const g = await request({ type: 'grid', counts: given || counts() });
    stats.grid = g;
    stats.fit = null;
    gridSerial = g.serial;
    drawGridAndSurface();
    $('design-fit').disabled = false;
    $('design-export-grid').disabled = false;
    $('design-grid-status').textContent = `${g.vertices} vertices · ${g.faces} quads${g.folded ? ` · ${g.folded} folded` : ''} · ${g.ms.toFixed(0)} ms`;
    ctx.requestRender();
    return g;
  }

  // Fits the gridded layout and shows its limit surface coloured by error.
  async function fitLayout() {
    $('design-grid-status').textContent = 'fitting…';
    const f = await request({ type: 'fit' });
    stats.fit = f;
    drawGridAndSurface();
    const after = f.summary.after;
    $('design-grid-status').textContent = `${stats.grid.faces} quads → control mesh of ${f.summary.control_faces} · limit error ${Number((100 * after.hausdorff).toPrecision(2))} % of the size (mean ${Number((100 * after.stats.mean).toPrecision(2))} %) · ${f.ms.toFixed(0)} ms`;
    ctx.requestRender();
    return f;
  }

  async function guarded(what, run) {
    try { return await run(); } catch (error) { ctx.showError(`${what} failed: ${error.message}`); $('design-grid-status').textContent = `${what} failed: ${error.message}`; return null; }
  }

  async function exportLayout(format) {
    const text = await request({ type: 'export', format });
    stats.exportCount++;
    return text;
  }

  async function downloadLayout(format) {
    try {
      const text = await exportLayout(format);
      const a = document.createElement('a');
      a.href = URL.createObjectURL(new Blob([text], { type: format === 'json' ? 'application/json' : 'text/plain' }));
      const ext = format === 'grid-obj' ? 'grid.obj' : format;
      a.download = `${(inputName || 'layout').replace(/\.[^.]*$/, '')}-layout.${ext}`;
      a.click();
      setTimeout(() => URL.revokeObjectURL(a.href), 10000);
    } catch (error) {
      ctx.showError(`layout export failed: ${error.message}`);
    }
  }

  $('design-commit').addEventListener('click', () => action('commit', []));
  $('design-clear').addEventListener('click', () => action('clearAnchors', []));
  $('design-undo').addEventListener('click', () => action('undo', []));
  $('design-redo').addEventListener('click', () => action('redo', []));
  $('design-restart').addEventListener('click', () => { $('design-crash').hidden = true; start(); });
  $('design-mirror').addEventListener('change', () => action('setMirror', [$('design-mirror').value]));
  $('design-export-obj').addEventListener('click', () => downloadLayout('obj'));
  $('design-export-json').addEventListener('click', () => downloadLayout('json'));
  $('design-export-grid').addEventListener('click', () => downloadLayout('grid-obj'));
  $('design-grid').addEventListener('click', () => guarded('gridding', () => gridLayout()));
  $('design-fit').addEventListener('click', () => guarded('the fit', () => fitLayout()));

  return {
    stats,
    get active() { return stats.active; },
    enter, leave, reset, onHoverMove, onWheel, onDown, onDrag, onUp, onKey, exportLayout, gridLayout, fitLayout,
    action: (name, args) => action(name, args),
    crashForTesting: () => post({ type: 'crash-for-testing' }),
    holdAnalysisForTesting: (on) => post({ type: 'hold-analysis-for-testing', on }),
    hoverMedianMs: () => median(stats.hoverLatencies),
  };
}

// The strip colours of src/web/layout_glue.rs (STRIP_COLOURS).
const STRIP_CSS = ['#1f77b4', '#d62728', '#2ca02c', '#9467bd', '#ff7f0e', '#17becf', '#8c564b', '#e377c2', '#7f7f7f', '#bcbd22'];
const STRIP_RGBA = STRIP_CSS.map((c) => [1, 3, 5].map((i) => parseInt(c.slice(i, i + 2), 16)).concat(255));
