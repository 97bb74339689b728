// vola view on a tile set in headless Chromium: tiles a real LAS survey with `vola tile`,
// serves its index.geojson, and checks that the page lists every piece the index has;
// that from the first camera (the whole survey in view) only overviews load; that
// looking down at the survey's middle from close by loads tiles there, and not the
// whole set; that with a small cache (the page's ?budget=&cache=) the tiles left behind
// are freed when the camera moves on; that the scale bar is in the CRS's feet with a
// north arrow; and that the screenshot it writes is not blank.
// Usage: node browser_tiles_test.mjs VOLA DATA_DIR NODE_MODULES CHROMIUM OUT.png
// Exit 77 (skip) when the data is missing and CI is not set.
import { execFileSync } from 'node:child_process';
import { mkdtempSync, readFileSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import path from 'node:path';
import {
  autzenOrSkip, check, dataInView, launchChromium, openPage, screenshotNotBlank, startView,
} from './browser_support.mjs';

const [vola, defaultDataDir, nodeModules, chromiumPath, screenshotPath] = process.argv.slice(2);
const las = autzenOrSkip(defaultDataDir);
const run = (...args) => execFileSync(vola, args, { encoding: 'utf8', maxBuffer: 1 << 28 });

const tmp = mkdtempSync(path.join(tmpdir(), 'vola-view-tiles-'));
let server = null;
let browser = null;
try {
  const folder = path.join(tmp, 'tiles');
  run('tile', las, '--tile-size', '256', '--depth', '4', '-o', folder, '--quiet');
  const index = JSON.parse(readFileSync(path.join(folder, 'index.geojson'), 'utf8'));
  const tiles = index.features.length;
  const overviews = index.vola.overviews.length;
  check(tiles > 4 && overviews > 0, `vola tile made ${tiles} tiles and ${overviews} overviews`);

  let url;
  ({ server, url } = await startView(vola, [path.join(folder, 'index.geojson')]));
  browser = await launchChromium(nodeModules, chromiumPath);
  const { page, problems, foreign } = await openPage(browser, url);
  await page.goto(url);
  await page.evaluate(async () => { await window.volaView.ready; await window.volaView.whenIdle(); });

  // The listing is the index: every tile and overview, by file.
  const [set] = await (await fetch(new URL('/api/tilesets', url))).json();
  const listed = set.pieces.map((p) => p.file).sort();
  const indexed = [...index.features.map((f) => f.properties.file), ...index.vola.overviews.map((o) => o.file)].sort();
  check(JSON.stringify(listed) === JSON.stringify(indexed),
    `listed ${listed.length} pieces, the index has ${indexed.length}`);

  const counts = async () => (await page.evaluate(() => window.volaView.tileCounts()))[0];
  const shownCount = async () => Number(await page.getAttribute('#tiles-0', 'data-tiles-loaded'));
  // From afar, the whole survey in view: overviews only.
  const bounds = await page.evaluate(() => window.volaView.state.bounds);
  check(await dataInView(page, bounds), `the first camera crops the survey (${JSON.stringify(bounds)})`);
  let c = await counts();
  console.log(`from afar: ${JSON.stringify(c)}`);
  check(c.overviewsLoaded > 0 && c.tilesLoaded === 0 && c.shown > 0, `from afar: ${JSON.stringify(c)}`);

  // Close to the survey's middle: the tiles there, not all of them.
  const middle = bounds.min.map((m, a) => (m + bounds.max[a]) / 2);
  middle[2] = bounds.max[2];
  await page.evaluate(async (p) => { window.volaView.lookDownAt(p, 150); await window.volaView.whenIdle(); }, middle);
  c = await counts();
  console.log(`close by: ${JSON.stringify(c)}`);
  check(c.tilesLoaded > 0 && c.tilesLoaded < tiles, `close by: ${JSON.stringify(c)} of ${tiles} tiles`);
  check(await shownCount() === c.tilesLoaded, 'the panel does not report the tiles loaded');
  check(c.cells <= 2 * c.budget, `${c.cells} cells held, budget ${c.budget}`);

  // Feet, as the survey's CRS (EPSG:2994) says; north shown.
  check(set.units.unit === 'foot' && await page.getAttribute('#scale', 'data-unit') === 'foot',
    'the scale is not in feet');
  check(await page.isVisible('#north'), 'no north arrow');

  // The screenshot: the whole survey again, some tiles still held.
  await page.evaluate(async () => { window.volaView.frameAll(); await window.volaView.whenIdle(); });
  await screenshotNotBlank(page, screenshotPath);

  // A small cache: looking down at the west end, then the east end, frees the west's tiles.
  const small = await openPage(browser, url);
  // The west end's tiles in view hold 42,772 cells, the east end's more than 20,000.
  await small.page.goto(`${url}?budget=60000&cache=60000`);
  const visit = (p) => small.page.evaluate(async (q) => {
    window.volaView.lookDownAt(q, 150);
    await window.volaView.whenIdle();
    return window.volaView.tileCounts()[0];
  }, p);
  await small.page.evaluate(async () => { await window.volaView.ready; await window.volaView.whenIdle(); });
  const west = await visit([bounds.min[0] + 0.1 * (bounds.max[0] - bounds.min[0]), middle[1], middle[2]]);
  const east = await visit([bounds.max[0] - 0.1 * (bounds.max[0] - bounds.min[0]), middle[1], middle[2]]);
  console.log(`west: ${JSON.stringify(west)}\neast: ${JSON.stringify(east)}`);
  check(west.tilesLoaded > 0 && east.tilesLoaded > 0, 'no tiles loaded at the ends');
  check(east.cells <= east.cache, `${east.cells} cells held, the cache is ${east.cache}`);
  check(west.loadedTiles.some((id) => !east.loadedTiles.includes(id)), 'the west end\'s tiles were not freed');
  check(small.foreign.length === 0 && small.problems.length === 0, [...small.foreign, ...small.problems].join('\n'));

  check(foreign.length === 0, `the page asked for other hosts: ${foreign.join(', ')}`);
  check(problems.length === 0, problems.join('\n'));
  console.log('PASS');
} catch (e) {
  console.error(`FAIL: ${e.message}`);
  process.exitCode = 1;
} finally {
  if (browser) await browser.close();
  if (server) server.kill();
  rmSync(tmp, { recursive: true, force: true });
}
