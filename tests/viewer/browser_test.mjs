// vola view end to end in headless Chromium (Debian's, driven by playwright-core):
// converts a real LAS survey, serves it beside a coarser conversion of the same survey,
// and checks that the page shows the voxel counts and levels `vola info` reports, that clicks pick
// the voxel the camera's ray meets first (computed here from `vola voxels`, with and
// without the slicing plane), that the page needs nothing but the loopback server, that
// bad API requests get clear errors without stopping the server, that the first camera
// has the whole survey in view, with a scale bar in feet and a north arrow (the survey's
// CRS is in feet), and that the screenshot it writes is not blank.
// Usage: node browser_test.mjs VOLA DATA_DIR NODE_MODULES CHROMIUM OUT.png ($VOLA_SHARED/data if set)
// Exit 77 (skip) when the data is missing and CI is not set.
import { execFileSync } from 'node:child_process';
import { mkdtempSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import path from 'node:path';
import {
  autzenOrSkip, check, dataInView, launchChromium, openPage, screenshotNotBlank, startView,
} from './browser_support.mjs';

const [vola, defaultDataDir, nodeModules, chromiumPath, screenshotPath] = process.argv.slice(2);
const las = autzenOrSkip(defaultDataDir);
const run = (...args) => execFileSync(vola, args, { encoding: 'utf8', maxBuffer: 1 << 28 });

const tmp = mkdtempSync(path.join(tmpdir(), 'vola-view-'));
let server = null;
let browser = null;
try {
  const fine = path.join(tmp, 'fine.vol');
  const coarse = path.join(tmp, 'coarse.vol');
  run('convert', las, fine, '--voxel-size', '2', '--quiet');
  run('convert', las, coarse, '--voxel-size', '5', '--quiet');
  const info = JSON.parse(run('info', fine, '--json'));
  const coarseInfo = JSON.parse(run('info', coarse, '--json'));

  // The column to look down: the one nearest the middle of the survey among columns of
  // two voxels or more; the camera's ray down its centre meets its top voxel first, and
  // with the plane just below the top voxel's centre, the next voxel down.
  const columns = new Map();
  for (const line of run('voxels', fine).split('\n')) {
    if (!line) continue;
    const [x, y, z] = line.split(' ').map(Number);
    const key = `${x} ${y}`;
    const zs = columns.get(key) || [];
    zs.push(z);
    columns.set(key, zs);
  }
  let xs = [], ys = [];
  for (const key of columns.keys()) { const [x, y] = key.split(' ').map(Number); xs.push(x); ys.push(y); }
  const mid = [(Math.min(...xs) + Math.max(...xs)) / 2, (Math.min(...ys) + Math.max(...ys)) / 2];
  let column = null;
  for (const [key, zs] of columns) {
    if (zs.length < 2) continue;
    const [x, y] = key.split(' ').map(Number);
    const d = Math.hypot(x - mid[0], y - mid[1]);
    if (!column || d < column.d) column = { x, y, zs: zs.sort((a, b) => b - a), d };
  }
  check(column, 'no column with two voxels');
  const top = [column.x, column.y, column.zs[0]];
  const below = [column.x, column.y, column.zs[1]];
  const size = info.voxel_size;
  const centreOf = (v) => v.map((c, a) => info.origin[a] + (c + 0.5) * size);

  let url;
  ({ server, url } = await startView(vola, [fine, coarse]));
  browser = await launchChromium(nodeModules, chromiumPath);
  const { page, problems, foreign } = await openPage(browser, url);

  const started = Date.now();
  await page.goto(url);
  await page.evaluate(async () => { await window.volaView.ready; await window.volaView.whenIdle(); });
  console.log(`page ready in ${Date.now() - started} ms`);

  // Voxel counts, as `vola info` reports them.
  for (const [i, expected] of [[0, info.voxels], [1, coarseInfo.voxels]]) {
    const shown = await page.textContent(`[data-testid=voxel-count-${i}]`);
    check(Number(shown.replace(/,/g, '')) === expected, `file ${i}: the page shows ${shown} voxels, vola info ${expected}`);
  }
  // The first camera has every voxel's box in view.
  const bounds = await page.evaluate(() => window.volaView.state.bounds);
  check(await dataInView(page, bounds), `the first camera crops the survey (${JSON.stringify(bounds)})`);
  // Feet, as the survey's CRS (EPSG:2994) says, and north shown.
  check(await page.getAttribute('#scale', 'data-unit') === 'foot', 'the scale bar is not in feet');
  check(/^\d+ ft$/.test(await page.textContent('#scale-label')), `scale: ${await page.textContent('#scale-label')}`);
  check(await page.isVisible('#north'), 'no north arrow');

  // Hide the coarse survey with its toggle, show the finest level, look down the column.
  await page.click('[data-testid=visible-1]');
  const pickAtCentre = async () => {
    await page.evaluate(() => { window.volaView.state.lastPick = undefined; });
    await page.mouse.click(640, 400);
    await page.waitForFunction(() => window.volaView.state.lastPick !== undefined);
    return page.evaluate(() => window.volaView.state.lastPick);
  };
  await page.evaluate(async ([depth, target]) => {
    await window.volaView.setDetail(depth);
    window.volaView.lookDownAt(target, 300);
  }, [info.depth, centreOf(top)]);
  // Levels as vola info counts them: the finest is depth - 1.
  const label = await page.textContent('#detail-label');
  check(label.includes(`fine.vol: level ${info.depth - 1} (levels 0-${info.depth - 1}, depth ${info.depth})`) &&
    info.levels.length === info.depth, `the detail label reads: ${label}`);
  let pick = await pickAtCentre();
  check(pick && pick.file === 0, `the click picked nothing in the fine survey: ${JSON.stringify(pick)}`);
  check(pick.voxel.join(' ') === top.join(' '), `picked voxel ${pick.voxel}, expected the column's top ${top}`);
  const panel = await page.getAttribute('#pick', 'data-voxel');
  check(panel === top.join(' '), `the panel shows voxel ${panel}, expected ${top}`);
  // Its attributes, as `vola get` reads them.
  const get = run('get', fine, ...top.map(String));
  const classLine = get.split('\n').find((l) => l.startsWith('classification '));
  check(Number(classLine.split(' ')[1]) === pick.attributes.classification,
    `picked classification ${pick.attributes.classification}, vola get: ${classLine}`);
  check(pick.voxel_centre.every((c, a) => Math.abs(c - centreOf(top)[a]) < 1e-6 * Math.abs(c) + 1e-9),
    `CRS centre ${pick.voxel_centre}, expected ${centreOf(top)}`);
  const text = await page.textContent('#pick');
  check(text.includes(top.join(' ')) && text.includes(pick.class_name), `the panel reads: ${text}`);

  // The slicing plane just below the top voxel's centre hides it: the pick goes through.
  await page.evaluate((at) => window.volaView.setSlice(true, 2, at), centreOf(top)[2] - 0.5 * size);
  pick = await pickAtCentre();
  check(pick && pick.voxel.join(' ') === below.join(' '), `sliced pick ${pick && pick.voxel}, expected ${below}`);
  await page.evaluate(() => window.volaView.setSlice(false));

  // Bad requests: clear errors, and the server keeps serving.
  for (const [request, status] of [['/api/files/7/cells?level=0&first=0&count=1', 404],
    ['/api/files/0/cells?level=x&first=0&count=1', 400], ['/api/files/0/cells?level=0&first=0&count=99999999', 400],
    ['/api/files/0/pick?level=1&ox=0&oy=0&oz=0&dx=0&dy=0&dz=0', 400], ['/api/files/0/cell?level=2&x=1&y=1', 400],
    ['/no/such/path', 404]]) {
    const response = await fetch(new URL(request, url));
    const body = await response.json();
    check(response.status === status && typeof body.error === 'string' && body.error.length > 0,
      `${request}: status ${response.status}, body ${JSON.stringify(body)}`);
  }
  check((await fetch(new URL('/api/files', url))).ok, 'the server stopped answering after bad requests');

  // The screenshot: the whole survey, coloured by height; not blank.
  await page.evaluate(() => window.volaView.frameAll());
  await screenshotNotBlank(page, screenshotPath);

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
