// How fast `vola view` opens a file in headless Chromium: time until the server prints its
// URL, until the first cells are drawn, until the default level of detail has loaded,
// and (with DETAIL) until the finest level asked for has loaded. One JSON line per run.
// Usage: node bench/viewer_open.mjs VOLA FILE.vol NODE_MODULES [DETAIL]
//   NODE_MODULES: <build>/src/viewer/web/node_modules (playwright-core); Chromium: /usr/bin/chromium
import { spawn } from 'node:child_process';
import { createRequire } from 'node:module';
import path from 'node:path';

const [vola, file, nodeModules, detail] = process.argv.slice(2);
const { chromium } = createRequire(path.join(nodeModules, 'noop.js'))('playwright-core');
const start = Date.now();
const server = spawn(vola, ['view', file], { stdio: ['ignore', 'pipe', 'inherit'] });
const url = await new Promise((resolve) => server.stdout.on('data', (chunk) => {
  const m = String(chunk).match(/http:\/\/127\.0\.0\.1:\d+\//);
  if (m) resolve(m[0]);
}));
const serverMs = Date.now() - start;
const browser = await chromium.launch({ executablePath: '/usr/bin/chromium', headless: true,
  args: ['--no-sandbox', '--headless', '--disable-gpu', '--enable-unsafe-swiftshader', '--use-angle=swiftshader'] });
try {
  const page = await browser.newPage({ viewport: { width: 1280, height: 800 } });
  const t0 = Date.now();
  await page.goto(url);
  await page.waitForFunction(() => window.volaView &&
    [...window.volaView.state.layers.values()].some((layer) => layer.loaded > 0));
  const firstCellsMs = Date.now() - t0;
  await page.evaluate(async () => { await window.volaView.ready; await window.volaView.whenIdle(); });
  const defaultMs = Date.now() - t0;
  const defaultDetail = await page.evaluate(() => window.volaView.state.detail);
  let detailMs = null;
  if (detail) {
    const t1 = Date.now();
    await page.evaluate(async (d) => { await window.volaView.setDetail(d); }, Number(detail));
    detailMs = Date.now() - t1;
  }
  console.log(JSON.stringify({ server_ms: serverMs, first_cells_ms: firstCellsMs, default_detail: defaultDetail,
    default_loaded_ms: defaultMs, detail: detail ? Number(detail) : null, detail_loaded_ms: detailMs }));
} finally {
  await browser.close();
  server.kill();
}
