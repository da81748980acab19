// Screenshots of the design mode (dual strip weaving) on the real page, for
// notes; not a test and not part of `make test`. For each sample: strips
// are committed the way a user does (hover, the wheel for another loop,
// Enter; led by the region colours, see designGreedy; the torus and the
// bunny by set anchors, see designTorus and designBunny) until the layout is
// sufficient, then the layout is gridded (the count doubled while the grid
// asks for higher counts, up to 64) and fitted; a layout that does not grid,
// or grids with more than 5 % of its quads folded, gets more strips (up to 4 more per round, 3
// rounds), led by the orange regions (several curvature extrema), and is
// gridded again. Three PNGs per sample in OUT_DIR:
//   NAME-1-layout.png   the strips, the regions and the layout
//   NAME-2-grid.png     the gridded layout (pure quads) on the surface
//   NAME-3-limit.png    the fitted Catmull–Clark limit surface, coloured by error
// (a layout that does not grid is written as NAME-layout.json instead).
//
//   make web && cargo build --release --example serve
//   cd tests/e2e && node screenshots_design.mjs OUT_DIR [sample …]   (default: torus rocker-arm stanford-bunny)
//   SHOTS_GRID=n  segments per strip (default 8) · SHOTS_STRIPS=n  most strips tried per sample (default 16)
//   SHOTS_ORANGE=1  go on adding strips until no region has several curvature extrema
import { mkdirSync, writeFileSync } from 'node:fs';
import { PNG } from 'pngjs';
import { join, resolve } from 'node:path';
import { startServer, CONFIGS, launch, open, waitForRun, settle, surfaceGrid, enterDesign, DESIGN_WAIT } from './harness.mjs';

const [outArg, ...names] = process.argv.slice(2);
if (!outArg) {
  console.error('usage: node screenshots_design.mjs OUT_DIR [sample …]');
  process.exit(2);
}
const out = resolve(outArg);
mkdirSync(out, { recursive: true });
const samples = names.length ? names : ['torus', 'rocker-arm', 'stanford-bunny'];
const gridCount = Number(process.env.SHOTS_GRID || 8);
const maxStrips = Number(process.env.SHOTS_STRIPS || 16);
const chaseOrange = process.env.SHOTS_ORANGE === '1';
const LONG = { timeout: 600000 };

// The design as the analysis sees it. Sufficient regions whose layout has
// no patch (a loop no other strip crosses) make no grid: counted as
// insufficient, every face as if red, so a crossing strip improves on it.
const designed = (page) => page.evaluate(() => {
  const d = window.quadrille.design;
  if (!(d.analysis && d.state && d.analysis.revision === d.state.revision)) return null;
  const c = d.analysis.counts;
  const noPatch = c.patches === 0;
  return { strips: d.state.loops.length, counts: c, sufficient: d.analysis.sufficient && !noPatch, status: d.analysis.status,
    red: noPatch ? d.analysis.regionCategory.length // faces in red regions (REGION_RED)
      : d.analysis.regionCategory.filter((k) => k === 6).length };
});
const waitForAnalysis = (page) => page.waitForFunction(() => {
  const d = window.quadrille.design;
  return d.analysis && d.state && d.analysis.revision === d.state.revision;
}, null, LONG);

// Hovers at `hit`, optionally turns the wheel `wheel` notches (the next
// alternative loops), and commits the loop drawn with Enter. Returns false
// (nothing committed) when no closed loop is proposed there.
async function commitAt(page, hit, wheel = 0) {
  const loops = await page.evaluate(() => window.quadrille.design.state.loops.length);
  // Keys to the view, not to the grid-count field a grid left focused.
  await page.evaluate(() => document.activeElement?.blur());
  // Away first: a move onto the point the pointer is already at hovers
  // nothing (the second alternative at one target).
  await page.mouse.move(0, 0);
  const n = await page.evaluate(() => window.quadrille.design.hoverLatencies.length);
  await page.mouse.move(hit.x, hit.y);
  try {
    await page.waitForFunction((n) => window.quadrille.design.hoverLatencies.length > n, n, { timeout: 30000 });
  } catch {
    return false;
  }
  for (let k = 0; k < wheel; k++) {
    const b = await page.evaluate(() => window.quadrille.design.state.browse[0]);
    await page.mouse.wheel(0, 120);
    try {
      await page.waitForFunction((b) => window.quadrille.design.state.browse[0] !== b, b, { timeout: 30000 });
    } catch {
      return false; // no other alternative there
    }
  }
  // Closed loops only: a dual curve ending on one of a scan's holes (the
  // bunny's base) makes the regions beside it touch the boundary twice.
  const closed = await page.evaluate(() => {
    const p = window.quadrille.design.proposal;
    const n = p.length;
    return n >= 6 && Math.hypot(p[0] - p[n - 3], p[1] - p[n - 2], p[2] - p[n - 1]) < 1e-6;
  });
  if (!closed) return false;
  await page.keyboard.press('Enter');
  try {
    await page.waitForFunction((l) => window.quadrille.design.state.loops.length > l, loops, { timeout: 30000 });
  } catch {
    return false;
  }
  await waitForAnalysis(page);
  return true;
}

const polylineLength = (p) => {
  let s = 0;
  for (let i = 3; i < p.length; i += 3) s += Math.hypot(p[i] - p[i - 3], p[i + 1] - p[i - 2], p[i + 2] - p[i - 1]);
  return s;
};

// The torus: two meridians and the loop around the hole (as the browser tests).
async function designTorus(page) {
  const byX = [...await surfaceGrid(page)].sort((a, b) => a.p[0] - b.p[0]);
  await commitAt(page, byX[Math.floor(byX.length * 0.05)]);
  await commitAt(page, byX[Math.floor(byX.length * 0.95)]);
  const meridian = await page.evaluate(() => [...window.quadrille.design.state.loops[0].points]);
  const mid = byX[Math.floor(byX.length * 0.5)];
  await page.mouse.move(mid.x, mid.y);
  await page.waitForFunction(() => window.quadrille.design.proposal.length > 0, null, DESIGN_WAIT);
  for (let k = 0; k < 8; k++) {
    const proposal = await page.evaluate(() => [...window.quadrille.design.proposal]);
    if (polylineLength(proposal) > 1.6 * polylineLength(meridian)) break;
    const b = await page.evaluate(() => window.quadrille.design.state.browse[0]);
    await page.mouse.wheel(0, 120);
    await page.waitForFunction((b) => window.quadrille.design.state.browse[0] !== b, b, DESIGN_WAIT);
  }
  await page.keyboard.press('Enter');
  await page.waitForFunction(() => window.quadrille.design.state.loops.length === 3, null, DESIGN_WAIT);
  await waitForAnalysis(page);
}

// The bunny: five loops, each through four directional anchors on a plane
// section that misses the base's holes (around the lower body, the rump, the
// side, the neck, and lengthwise over the head and one ear; the native test
// bunny_layout_grids_around_its_holes grids these sections), in the page's
// (normalised) coordinates. The automatic proposals near the base end on its
// holes, which the greedy design cannot get past.
const BUNNY_LOOPS = [
  [[[0.38502, -0.25, -0.00823], [0.2648, 0, 0.9643]], [[0.15757, -0.25, 0.36884], [-0.9873, 0, 0.159]], [[-0.33626, -0.25, 0.23405], [-0.8573, 0, -0.5148]], [[-0.09195, -0.25, -0.17227], [0.3596, 0, -0.9331]]],
  [[[0.3, -0.18259, 0.291], [0, -0.981, 0.194]], [[0.3, -0.47568, 0.13588], [0, -0.2706, -0.9627]], [[0.3, -0.26072, -0.12131], [0, 0.954, -0.2999]], [[0.3, 0.05826, 0.03459], [0, 0.2483, 0.9687]]],
  [[[-0.08391, 0.05704, 0.2], [0.9967, 0.0811, 0]], [[0.40264, -0.30393, 0.2], [0.9193, 0.3935, 0]], [[-0.19845, -0.487, 0.2], [-0.9996, 0.0297, 0]], [[-0.45039, 0.01878, 0.2], [-0.8261, 0.5635, 0]]],
  [[[-0.44139, 0.2, 0.03992], [-0.3294, 0, 0.9442]], [[-0.45268, 0.2, 0.26219], [0.5236, 0, 0.852]], [[-0.26814, 0.2, 0.22121], [0.6989, 0, -0.7152]], [[-0.24861, 0.2, -0.00435], [-0.8421, 0, -0.5394]]],
  [[[-0.34, 0.29164, 0.05132], [0, -0.0815, -0.9967]], [[-0.34, 0.2996, -0.31219], [0, -0.9975, -0.0705]], [[-0.34, -0.17692, -0.09928], [0, -0.9891, 0.1473]], [[-0.34, -0.05049, 0.2633], [0, 0.9003, -0.4352]]],
];
async function designBunny(page) {
  for (const anchors of BUNNY_LOOPS) {
    const loops = await page.evaluate(() => window.quadrille.design.state.loops.length);
    for (const [p, d] of anchors) await page.evaluate(([p, d]) => window.quadrille.designAction('addAnchor', [p, d]), [p, d]);
    await page.evaluate(() => window.quadrille.designAction('commit', []));
    await page.waitForFunction((l) => window.quadrille.design.state.loops.length > l, loops, DESIGN_WAIT);
    await waitForAnalysis(page);
    const d = await designed(page);
    console.log(`  strip ${d.strips}: ${d.status}`);
  }
}

// Where a region of guidance colour `kind` ('red': not a disc, 'orange':
// several curvature extrema) is seen on the canvas: the client position
// deepest inside the largest patch of that colour, or null.
const COLOURS = {
  red: (r, g, b) => r > 80 && g < 0.25 * r && b < 0.25 * r,
  orange: (r, g, b) => r > 100 && g > 0.35 * r && g < 0.65 * r && b < 0.15 * r,
};
async function regionPoint(page, kind) {
  await page.mouse.move(0, 0);
  await settle(page);
  const box = await page.locator('#canvas').boundingBox();
  const { data, width, height } = PNG.sync.read(await page.screenshot({ clip: box }));
  const is = COLOURS[kind];
  const inside = (x, y) => x >= 0 && y >= 0 && x < width && y < height
    && is(data[4 * (y * width + x)], data[4 * (y * width + x) + 1], data[4 * (y * width + x) + 2]);
  // Every pixel of a square of half-side r around (x, y), every 2 pixels.
  const square = (x, y, r) => {
    for (let dy = -r; dy <= r; dy += 2) for (let dx = -r; dx <= r; dx += 2) if (!inside(x + dx, y + dy)) return false;
    return true;
  };
  let best = null;
  for (let y = 0; y < height; y += 4) {
    for (let x = 0; x < width; x += 4) {
      let r = best ? best.r : 4;
      if (!square(x, y, r)) continue;
      while (square(x, y, r + 2)) r += 2;
      if (!best || r > best.r) best = { x, y, r };
    }
  }
  if (!best) return null;
  const hit = { x: box.x + best.x, y: box.y + best.y };
  return (await page.evaluate(({ x, y }) => window.quadrille.surfacePoint(x, y), hit)) ? hit : null;
}

// Whether design a (one strip more) improves on b: fewer faces in regions
// that are not discs; with as many, while some remain, no more orange
// regions (a loop that leaves a red region in one piece may still have cut
// one of its handles); once none remain, fewer orange regions, else more
// regions.
const improves = (a, b) => (a.red !== b.red ? a.red < b.red
  : b.red > 0 ? a.counts.orange <= b.counts.orange
    : a.counts.orange !== b.counts.orange ? a.counts.orange < b.counts.orange : a.counts.regions > b.counts.regions);

// Any other mesh, the way the guidance leads a user: the first strip
// through the middle of the view, then strips through the middle of a red
// region (not a disc) while there is one (SHOTS_ORANGE=1: then of an
// orange one too, several curvature extrema); a strip is kept when it improves the design
// (`improves`), else undone and the next alternative loop (the wheel)
// tried. When no such region is in view the view turns.
// Until the layout is sufficient (without orange regions, with
// SHOTS_ORANGE=1) or `maxStrips` strips were tried.
async function designGreedy(page, { orange = chaseOrange, budget = maxStrips } = {}) {
  const start = await page.evaluate(() => window.quadrille.camera());
  const views = [[0, 0], [Math.PI / 2, 0], [Math.PI, 0], [-Math.PI / 2, 0], [0, 1.2], [0, -1.2]];
  let view = 0;
  let now = await designed(page);
  let tried = 0;
  if (!now || now.strips === 0) {
    const hits = await surfaceGrid(page, 16);
    const byY = [...hits].sort((a, b) => a.y - b.y);
    await commitAt(page, byY[Math.floor(byY.length / 2)]);
    now = await designed(page);
    console.log(`  strip 1: kept · ${now.status}`);
    tried = 1;
  }
  let turns = 0;
  while (tried < budget && !(now.sufficient && (!orange || now.counts.orange === 0))) {
    const kind = now.counts.red > 0 ? 'red' : 'orange';
    // (no patch yet, nothing red: an orange region, or the view turns)
    const target = await regionPoint(page, kind);
    if (!target) {
      if (++turns > views.length) break;
      view = (view + 1) % views.length;
      await page.evaluate(([s, v]) => window.quadrille.setCamera([s[0] + v[0], s[1] + v[1]]), [start, views[view]]);
      await settle(page);
      continue;
    }
    turns = 0;
    for (let wheel = 0; wheel < 3 && tried < budget; wheel++) {
      tried++;
      if (!(await commitAt(page, target, wheel))) continue;
      const next = await designed(page);
      const kept = improves(next, now);
      console.log(`  strip ${next.strips} (${kind} region, alternative ${wheel}): ${kept ? 'kept' : 'undone'} · ${next.status}`);
      if (kept) { now = next; break; }
      await page.keyboard.press('Control+z');
      await page.waitForFunction((n) => window.quadrille.design.state.loops.length === n, now.strips, DESIGN_WAIT);
      await waitForAnalysis(page);
    }
  }
  await page.evaluate((s) => window.quadrille.setCamera(s), start);
}

async function shot(page, file) {
  await page.mouse.move(0, 0);
  await settle(page);
  await page.screenshot({ path: join(out, file) });
  console.log(`  wrote ${join(out, file)}`);
}

const { server, url } = await startServer();
const context = await launch(CONFIGS.webgl2.flags);
try {
  for (const name of samples) {
    const env = { context, url, query: CONFIGS.webgl2.query, backend: 'webgl2' };
    const { page, errors } = await open(env, `sample=${name}`);
    await waitForRun(page, `${name}.obj`);
    await enterDesign(page, 300000);
    console.log(`${name}: ${await page.textContent('#design-note')}`);
    if (name === 'torus') await designTorus(page);
    else if (name === 'stanford-bunny') await designBunny(page);
    else await designGreedy(page);
    let d = await designed(page);
    console.log(`  ${d.strips} strips: ${d.status}`);
    // Grid; on "raise the grid counts" double the count; when it does not
    // grid or folds, add strips (orange regions first) and try again.
    let g = null;
    for (let round = 0; round < 4 && !g; round++) {
      if (round > 0 || !d.sufficient) {
        await designGreedy(page, { orange: true, budget: d.strips + 4 });
        d = await designed(page);
        console.log(`  ${d.strips} strips: ${d.status}`);
      }
      if (!d.sufficient) continue;
      // The layout before its grid is drawn over it.
      await shot(page, `${name}-1-layout.png`);
      for (let count = gridCount; count <= 64; count *= 2) {
        await page.fill('#design-grid-count', String(count));
        const tryGrid = await page.evaluate(() => window.quadrille.gridLayout().then(
          (g) => ({ vertices: g.vertices, faces: g.faces, folded: g.folded, ms: g.ms }), (e) => ({ error: e.message })));
        if (tryGrid.error) {
          console.log(`  grid ${count} failed: ${tryGrid.error}`);
          if (/raise the grid counts/.test(tryGrid.error)) continue;
          break;
        }
        console.log(`  grid ${count}: ${tryGrid.vertices} vertices, ${tryGrid.faces} quads, ${tryGrid.folded} folded, ${tryGrid.ms.toFixed(0)} ms`);
        // More than 5 % folded quads: more strips first, unless this was
        // the last round.
        if (20 * tryGrid.folded <= tryGrid.faces || round === 3) g = tryGrid;
        break;
      }
    }
    if (!d.sufficient) await shot(page, `${name}-1-layout.png`);
    if (!g) {
      if (d.sufficient) {
        // The layout that did not grid, for a look at it.
        writeFileSync(join(out, `${name}-layout.json`), await page.evaluate(() => window.quadrille.exportLayout('json')));
        console.log(`  no grid (layout in ${join(out, `${name}-layout.json`)})`);
      } else {
        console.log('  no layout: not gridded');
      }
    } else {
      await shot(page, `${name}-2-grid.png`);
      await page.evaluate(() => window.quadrille.fitLayout().then(() => null));
      console.log(`  fit: ${await page.textContent('#design-grid-status')}`);
      await shot(page, `${name}-3-limit.png`);
    }
    if (errors.length) console.log(`  console errors: ${errors.join(' | ')}`);
    await page.close();
  }
} finally {
  await context.close();
  server.kill();
}
