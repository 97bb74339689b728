// What the viewer's browser tests share: `vola view` started on a free port, headless
// Chromium (Debian's, driven by playwright-core) on a page that may reach nothing but
// that server, and a check that a screenshot is not blank.
import { spawn } from 'node:child_process';
import { existsSync } from 'node:fs';
import { createRequire } from 'node:module';
import path from 'node:path';

export function check(condition, message) {
  if (!condition) throw new Error(message);
}

// The shared survey, or exit 77 (skip) when it is missing and CI is not set.
// VOLA_SHARED in the environment overrides the configured data folder, as for every test.
export function autzenOrSkip(defaultDataDir) {
  const dataDir = process.env.VOLA_SHARED ? path.join(process.env.VOLA_SHARED, 'data') : defaultDataDir;
  const las = path.join(dataDir, 'las', 'pdal_autzen_trim.las');
  if (!existsSync(las)) {
    if (process.env.CI) { console.error(`FAIL: ${las} is missing (CI is set)`); process.exit(1); }
    console.log(`SKIP: ${las} is missing; set VOLA_SHARED`);
    process.exit(77);
  }
  return las;
}

// Starts `vola view ARGS...` and resolves to { server, url } once it prints its URL.
export async function startView(vola, args) {
  const server = spawn(vola, ['view', ...args], { stdio: ['ignore', 'pipe', 'inherit'] });
  const url = await new Promise((resolve, reject) => {
    let out = '';
    server.stdout.on('data', (chunk) => {
      out += chunk;
      const m = out.match(/http:\/\/127\.0\.0\.1:\d+\//);
      if (m) resolve(m[0]);
    });
    server.on('exit', (code) => reject(new Error(`vola view exited (${code}): ${out}`)));
  });
  console.log(`vola view serves ${url}`);
  return { server, url };
}

export function launchChromium(nodeModules, chromiumPath) {
  const { chromium } = createRequire(path.join(nodeModules, 'noop.js'))('playwright-core');
  return chromium.launch({
    executablePath: chromiumPath,
    headless: true,
    args: ['--no-sandbox', '--headless', '--disable-gpu', '--enable-unsafe-swiftshader', '--use-angle=swiftshader',
      '--disable-background-networking', '--disable-component-update', '--disable-sync', '--disable-default-apps',
      '--disable-domain-reliability', '--no-first-run', '--metrics-recording-only', '--no-pings'],
  });
}

// A 1280x800 page that records its errors in `problems` and every request for another
// host in `foreign` (and aborts it): the page must need nothing but `url`.
export async function openPage(browser, url) {
  const page = await browser.newPage({ viewport: { width: 1280, height: 800 } });
  const problems = [];
  page.on('pageerror', (e) => problems.push(`page error: ${e.message}`));
  page.on('console', (m) => { if (m.type() === 'error') problems.push(`console: ${m.text()}`); });
  const foreign = [];
  await page.route('**/*', (route) => {
    const u = route.request().url();
    if (u.startsWith(url)) return route.continue();
    foreign.push(u);
    return route.abort();
  });
  return { page, problems, foreign };
}

// Writes the page's screenshot to `file` and fails when it is (nearly) blank: too little
// contrast, too few pixels unlike the background (#15181d), or too few colours.
export async function screenshotNotBlank(page, file) {
  const png = await page.screenshot({ path: file });
  const stats = await page.evaluate(async (b64) => {
    const bytes = Uint8Array.from(atob(b64), (c) => c.charCodeAt(0));
    const image = await createImageBitmap(new Blob([bytes], { type: 'image/png' }));
    const canvas = new OffscreenCanvas(image.width, image.height);
    const context = canvas.getContext('2d');
    context.drawImage(image, 0, 0);
    const data = context.getImageData(0, 0, image.width, image.height).data;
    let sum = 0, sum2 = 0, away = 0;
    const colours = new Set();
    const n = data.length / 4;
    for (let i = 0; i < data.length; i += 4) {
      const l = 0.299 * data[i] + 0.587 * data[i + 1] + 0.114 * data[i + 2];
      sum += l; sum2 += l * l;
      if (Math.abs(data[i] - 0x15) + Math.abs(data[i + 1] - 0x18) + Math.abs(data[i + 2] - 0x1d) > 30) ++away;
      colours.add((data[i] << 16) | (data[i + 1] << 8) | data[i + 2]);
    }
    const mean = sum / n;
    return { variance: sum2 / n - mean * mean, drawn: away / n, colours: colours.size };
  }, png.toString('base64'));
  console.log(`screenshot ${file}: luminance variance ${stats.variance.toFixed(1)}, ` +
    `${(100 * stats.drawn).toFixed(1)}% of pixels drawn, ${stats.colours} colours`);
  check(stats.variance > 100 && stats.drawn > 0.1 && stats.colours > 200, 'the screenshot is (nearly) blank');
}

// Whether the 8 corners of the world box `bounds` ({ min, max }) all project inside the
// page's view through its camera as it is now.
export function dataInView(page, bounds) {
  return page.evaluate(({ min, max }) => {
    const { camera, state } = window.volaView;
    camera.updateMatrixWorld();
    const view = camera.matrixWorldInverse.elements;
    const projection = camera.projectionMatrix.elements;
    const times = (m, v) => [0, 1, 2, 3].map((r) => m[r] * v[0] + m[4 + r] * v[1] + m[8 + r] * v[2] + m[12 + r] * v[3]);
    for (let corner = 0; corner < 8; ++corner) {
      const p = [0, 1, 2].map((a) => ((corner >> a) & 1 ? max[a] : min[a]) - state.sceneOrigin[a]);
      const clip = times(projection, times(view, [...p, 1]));
      if (clip[3] <= 0 || [0, 1].some((a) => Math.abs(clip[a] / clip[3]) > 1)) return false;
    }
    return true;
  }, bounds);
}
