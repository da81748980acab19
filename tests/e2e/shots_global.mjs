// Screenshots of the global mode on shared meshes (for notes; not a test):
//   node shots_global.mjs fandisk stanford-bunny rocker-arm
import { join, resolve } from 'node:path';
import { mkdirSync } from 'node:fs';
import { root, startServer, CONFIGS, launch, open, waitForRun, settle } from './harness.mjs';

const out = resolve(root, 'target/shots');
mkdirSync(out, { recursive: true });
const { server, url } = await startServer();
const context = await launch(CONFIGS.webgl2.flags);
try {
  for (const name of process.argv.slice(2)) {
    const env = { context, url, query: CONFIGS.webgl2.query, backend: 'webgl2' };
    const { page } = await open(env, `sample=${name}`);
    await waitForRun(page, `${name}.obj`);
    await page.selectOption('#remesh-mode', 'global');
    await page.waitForFunction(() => document.getElementById('progress').hidden
      && window.quadrille.lastRun && window.quadrille.lastRun.parameters.remesh.mode === 'global', null, { timeout: 300000 });
    await settle(page);
    await page.screenshot({ path: join(out, `${name}-global.png`) });
    console.log(name, (await page.textContent('#status')).trim());
    await page.close();
  }
} finally {
  await context.close();
  server.kill();
}
