// vola view: the page. Loads every file's metadata, streams levels coarse to fine as
// binary batches, streams tile sets by distance from the camera (tiles.js), and answers
// clicks on files by casting the click's ray on the server at the level shown. A scale
// bar in the CRS's unit and a north arrow follow the camera (overlay.js).
// window.volaView exposes the state and a few actions for scripts (the browser tests
// drive the page through it and through real clicks).
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import { fetchCells, fetchFiles, fetchPick, fetchTileSets } from './api.js';
import { VoxelLayer } from './layer.js';
import { unitLabel, updateNorthArrow, updateScaleBar } from './overlay.js';
import { CELL_BUDGET, CELL_CACHE, TileStreamer } from './tiles.js';
import { classColour, fileColour, rampColour } from './palette.js';

const BATCH_CELLS = 1 << 20;
// The default detail is the finest whose levels hold at most this many cells in all:
// what a laptop's browser draws smoothly. Finer levels load when the slider asks.
const DEFAULT_CELL_BUDGET = 3_000_000;

const $ = (id) => document.getElementById(id);
const canvas = $('scene');
const renderer = new THREE.WebGLRenderer({ canvas, antialias: true, preserveDrawingBuffer: true });
renderer.setPixelRatio(window.devicePixelRatio);
renderer.setClearColor(0x15181d);
const scene = new THREE.Scene();
const camera = new THREE.PerspectiveCamera(45, 1, 0.1, 1e7);
camera.up.set(0, 0, 1);
const controls = new OrbitControls(camera, canvas);
controls.addEventListener('change', () => { render(); cutTileSets(); });

// Uniforms every layer shares: the slicing plane, and pixels per unit of size at unit
// distance (for layers drawn as points).
const slice = { on: { value: 0 }, axis: { value: new THREE.Vector3(0, 0, 1) }, at: { value: 0 },
  pointScale: { value: 1 } };
const sliceHelper = new THREE.Mesh(new THREE.PlaneGeometry(1, 1),
  new THREE.MeshBasicMaterial({ color: 0x66aaff, transparent: true, opacity: 0.15, side: THREE.DoubleSide,
    depthWrite: false }));
sliceHelper.visible = false;
scene.add(sliceHelper);
const highlight = new THREE.LineSegments(new THREE.EdgesGeometry(new THREE.BoxGeometry(1, 1, 1)),
  new THREE.LineBasicMaterial({ color: 0xffffff }));
highlight.visible = false;
scene.add(highlight);

const state = {
  files: [],
  tileSets: [],
  streamers: [],           // one TileStreamer per tile set
  units: { unit: 'units', north: false },  // of the first file or set that states a CRS
  sceneOrigin: [0, 0, 0],  // world point at the scene's 0 (float32 on the GPU needs small numbers)
  bounds: null,            // world box of every file's voxels: { min, max }
  detail: 1,
  visible: [],
  layers: new Map(),       // "file/level" -> VoxelLayer
  colourMode: 'height',
  lastPick: null,
  loading: Promise.resolve(),
};

// Draws at the next animation frame, once however many changes asked for it.
let frameRequested = false;
function render() {
  if (frameRequested) return;
  frameRequested = true;
  requestAnimationFrame(() => {
    frameRequested = false;
    renderer.render(scene, camera);
    updateScaleBar($('scale'), camera, controls.target, cssPixelsPerUnit(), state.units.unit);
    updateNorthArrow($('north'), camera, controls.target, state.units.north);
  });
}

// Screen (CSS) pixels one unit spans at unit distance from the camera.
function cssPixelsPerUnit() {
  return window.innerHeight / (2 * Math.tan(THREE.MathUtils.degToRad(camera.fov) / 2));
}

// Cuts every tile set's tree again for the camera, once per frame however many moves.
let cutRequested = false;
function cutTileSets() {
  if (cutRequested || !state.streamers.length) return;
  cutRequested = true;
  requestAnimationFrame(() => {
    cutRequested = false;
    for (const streamer of state.streamers) streamer.update(camera, cssPixelsPerUnit());
  });
}

function reportTiles() {
  for (const [i, streamer] of state.streamers.entries()) {
    const c = streamer.counts();
    const row = $(`tiles-${i}`);
    const number = (n) => n.toLocaleString('en-US');
    row.textContent = `${c.loaded} of ${c.pieces} pieces loaded (${c.tilesLoaded} tiles, ${c.overviewsLoaded} ` +
      `overviews), ${c.shown} drawn, ${number(c.cells)} cells (budget ${number(c.budget)})`;
    row.dataset.tilesLoaded = String(c.tilesLoaded);
    row.dataset.overviewsLoaded = String(c.overviewsLoaded);
    row.dataset.cells = String(c.cells);
  }
}

function resize() {
  const w = window.innerWidth;
  const h = window.innerHeight;
  renderer.setSize(w, h, false);
  camera.aspect = w / h;
  camera.updateProjectionMatrix();
  slice.pointScale.value = (h * renderer.getPixelRatio()) / (2 * Math.tan(THREE.MathUtils.degToRad(camera.fov) / 2));
  render();
}

function levelOf(file) {
  return Math.min(state.detail, file.depth) - 1;
}

function fileOffset(file) {
  return file.origin.map((o, a) => o - state.sceneOrigin[a]);
}

function colourOf(layer, i) {
  const file = layer.file;
  switch (state.colourMode) {
    case 'classification':
      return layer.classes ? classColour(layer.classes[i]) : [150, 150, 150];
    case 'stored':
      return layer.stored ? [layer.stored[3 * i], layer.stored[3 * i + 1], layer.stored[3 * i + 2]] : [150, 150, 150];
    case 'file':
      return fileColour(file.index);
    default: {
      const z = file.origin[2] + layer.height(i);
      return rampColour((z - state.bounds.min[2]) / Math.max(state.bounds.max[2] - state.bounds.min[2], 1e-9));
    }
  }
}

function setStatus(text, isError = false) {
  $('status').textContent = text;
  $('status').className = isError ? 'error' : '';
}

// Streams one level of one file in batches, drawing each as it arrives.
async function loadLayer(file, level) {
  const key = `${file.index}/${level}`;
  let layer = state.layers.get(key);
  if (layer && layer.loaded === layer.total) return layer;
  if (!layer) {
    layer = new VoxelLayer(file, level, fileOffset(file), slice);
    state.layers.set(key, layer);
    scene.add(layer.mesh);
  }
  updateVisibility();
  while (layer.loaded < layer.total) {
    setStatus(`${file.name}: level ${level}, ${layer.loaded.toLocaleString()} of ${layer.total.toLocaleString()} cells`);
    const batch = await fetchCells(file.index, level, layer.loaded, BATCH_CELLS);
    if (batch.count === 0) throw new Error(`${file.name}: the server sent no cells at ${layer.loaded}`);
    layer.append(batch, colourOf);
    render();
  }
  return layer;
}

function updateVisibility() {
  for (const layer of state.layers.values())
    layer.mesh.visible = state.visible[layer.file.index] && layer.level === levelOf(layer.file);
  render();
}

// Shows detail d (1 = coarsest), loading every coarser level first so that something
// is on screen at once; the queue keeps loads in order.
function setDetail(d) {
  state.detail = d;
  $('detail').value = d;
  // Levels as vola info counts them: 0 (the root's 4x4x4 cells) to depth - 1 (the voxels).
  $('detail-label').textContent = state.files.map((f) => {
    const level = levelOf(f);
    const { cells, cell_size: size } = f.levels[level];
    return `${f.name}: level ${level} (levels 0-${f.depth - 1}, depth ${f.depth}), ` +
      `${cells.toLocaleString()} cells of ${size} ${unitLabel(f.units.unit)}`;
  }).join('\n');
  updateVisibility();
  state.loading = state.loading.then(async () => {
    for (let step = 1; step <= d; ++step) {
      for (const file of state.files) {
        const level = Math.min(step, file.depth) - 1;
        // Coarser levels are shown while they stream only when nothing finer is loaded yet.
        await loadLayer(file, level);
      }
    }
    updateVisibility();
    setStatus('');
  }).catch((e) => setStatus(e.message, true));
  return state.loading;
}

function recolourAll() {
  for (const layer of state.layers.values()) layer.recolour(colourOf);
  for (const streamer of state.streamers) streamer.recolour();
  renderLegend();
  render();
}

function renderLegend() {
  const legend = $('legend');
  legend.replaceChildren();
  const row = (rgb, text) => {
    const div = document.createElement('div');
    const swatch = document.createElement('span');
    swatch.className = 'swatch';
    swatch.style.background = `rgb(${rgb.join(',')})`;
    div.append(swatch, text);
    legend.append(div);
  };
  if (state.colourMode === 'classification') {
    const seen = new Map();
    for (const f of state.files)
      for (const c of f.classes) seen.set(c.code, (seen.get(c.code) || 0) + c.voxels);
    for (const [code, voxels] of [...seen].sort((a, b) => a[0] - b[0])) {
      const name = state.files.flatMap((f) => f.classes).find((c) => c.code === code).name;
      row(classColour(code), `${code} ${name} (${voxels.toLocaleString()} voxels)`);
    }
    if (!seen.size) legend.append('no file has a classification column');
  } else if (state.colourMode === 'height') {
    row(rampColour(0), `${state.bounds.min[2].toFixed(2)} (lowest)`);
    row(rampColour(1), `${state.bounds.max[2].toFixed(2)} (highest)`);
  } else if (state.colourMode === 'file') {
    for (const f of state.files) row(fileColour(f.index), f.name);
    for (const t of state.tileSets) row(fileColour(t.index), `${t.name} (tile set)`);
  } else if (!state.files.some((f) => f.has_colours)) {
    legend.append('no file has red/green/blue columns');
  }
}

function updateSlice() {
  const axis = Number($('slice-axis').value);
  const { min, max } = state.bounds;
  const t = Number($('slice-at').value) / 1000;
  const at = min[axis] + t * (max[axis] - min[axis]);  // world
  slice.on.value = $('slice-on').checked ? 1 : 0;
  slice.axis.value.set(axis === 0 ? 1 : 0, axis === 1 ? 1 : 0, axis === 2 ? 1 : 0);
  slice.at.value = at - state.sceneOrigin[axis];
  state.sliceWorld = slice.on.value ? { axis, at } : null;
  // The plane helper, spanning the scene's box on the other two axes.
  sliceHelper.visible = slice.on.value === 1;
  const centre = min.map((m, a) => (m + max[a]) / 2 - state.sceneOrigin[a]);
  centre[axis] = slice.at.value;
  sliceHelper.position.set(...centre);
  sliceHelper.rotation.set(axis === 1 ? Math.PI / 2 : 0, axis === 0 ? Math.PI / 2 : 0, 0);
  const extent = max.map((m, a) => m - min[a]);
  const others = [0, 1, 2].filter((a) => a !== axis);
  sliceHelper.scale.set(extent[others[0]] * 1.05 || 1, extent[others[1]] * 1.05 || 1, 1);
  render();
}

// Casts the ray through a canvas point at every visible file's shown level and reports
// the nearest hit. The slicing plane clips the ray as it hides cells.
async function pickAt(clientX, clientY) {
  const rect = canvas.getBoundingClientRect();
  const ndc = new THREE.Vector2(((clientX - rect.left) / rect.width) * 2 - 1,
    -((clientY - rect.top) / rect.height) * 2 + 1);
  const raycaster = new THREE.Raycaster();
  // The camera as the controls left it, even when no frame has drawn it yet.
  camera.updateMatrixWorld();
  raycaster.setFromCamera(ndc, camera);
  const originWorld = raycaster.ray.origin.toArray().map((v, a) => v + state.sceneOrigin[a]);
  const direction = raycaster.ray.direction.toArray();
  let best = null;
  for (const file of state.files) {
    if (!state.visible[file.index]) continue;
    const level = levelOf(file);
    const size = file.levels[level].cell_size;
    let o = originWorld.map((v, a) => (v - file.origin[a]) / size);
    let skipped = 0;  // cell units travelled before the ray enters the kept side
    let tMax;
    if (state.sliceWorld) {
      const a = state.sliceWorld.axis;
      // Cells whose centre lies above the plane are hidden: keep indices <= k.
      const k = Math.floor((state.sliceWorld.at - file.origin[a]) / size - 0.5);
      const plane = k + 1;
      if (o[a] > plane) {
        if (direction[a] >= 0) continue;
        skipped = (plane - o[a]) / direction[a];
        o = o.map((v, i) => (i === a ? plane : v + skipped * direction[i]));
      } else if (direction[a] > 0) {
        tMax = (plane - o[a]) / direction[a];
      }
    }
    const hit = await fetchPick(file.index, level, o, direction, tMax);
    if (!hit.hit) continue;
    const distance = (skipped + hit.t) * size;
    if (!best || distance < best.distance) best = { ...hit, distance, file: file.index, fileName: file.name };
  }
  state.lastPick = best;
  showPick(best);
  return best;
}

function showPick(pick) {
  const box = $('pick');
  if (!pick) {
    box.textContent = 'no voxel under the pointer';
    box.dataset.voxel = '';
    highlight.visible = false;
    render();
    return;
  }
  const fmt = (p) => p.map((v) => v.toFixed(3)).join(', ');
  const lines = [
    `file     ${pick.fileName}`,
    `level    ${pick.level}, cell ${pick.cell.join(' ')} (${pick.cell_size} units)`,
    `voxel    ${pick.voxel.join(' ')}${pick.level === state.files[pick.file].depth - 1 ? '' : ' (first in the cell)'}`,
    `crs      ${fmt(pick.voxel_centre)}`,
    `cell crs ${fmt(pick.centre)}`,
    `rank     ${pick.rank}`,
  ];
  if (pick.class_name !== undefined) lines.push(`class    ${pick.attributes.classification} ${pick.class_name}`);
  for (const [name, value] of Object.entries(pick.attributes))
    if (name !== 'classification') lines.push(`${name.padEnd(8)} ${Number.isInteger(value) ? value : value.toFixed(3)}`);
  box.textContent = lines.join('\n');
  box.dataset.voxel = pick.voxel.join(' ');
  box.dataset.file = pick.file;
  highlight.visible = true;
  highlight.scale.setScalar(pick.cell_size * 1.02);
  highlight.position.set(...pick.centre.map((v, a) => v - state.sceneOrigin[a]));
  render();
}

// Frames the whole scene from above and to the south: the camera backs off until the
// sphere around the data's box fits the narrower of the two fields of view.
function frameAll() {
  const { min, max } = state.bounds;
  const centre = min.map((m, a) => (m + max[a]) / 2 - state.sceneOrigin[a]);
  const radius = Math.max(Math.hypot(max[0] - min[0], max[1] - min[1], max[2] - min[2]) / 2, 1);
  const halfHeight = THREE.MathUtils.degToRad(camera.fov) / 2;
  const halfWidth = Math.atan(Math.tan(halfHeight) * camera.aspect);
  const distance = radius / Math.sin(Math.min(halfHeight, halfWidth));
  const direction = new THREE.Vector3(0, -1.15, 0.9).normalize();
  controls.target.set(...centre);
  camera.position.set(...centre).addScaledVector(direction, distance);
  camera.near = radius / 1000;
  camera.far = (distance + radius) * 100;
  camera.updateProjectionMatrix();
  controls.update();
  render();
  cutTileSets();
}

// Looks straight down at world point p from `height` above it: the canvas centre's ray
// then passes through p (whatever the camera's roll).
function lookDownAt(p, height) {
  const target = p.map((v, a) => v - state.sceneOrigin[a]);
  controls.target.set(...target);
  camera.position.set(target[0], target[1], target[2] + height);
  controls.update();
  render();
  cutTileSets();
}

function buildFileList() {
  const list = $('files');
  for (const file of state.files) {
    const row = document.createElement('div');
    row.className = 'file';
    const label = document.createElement('label');
    const box = document.createElement('input');
    box.type = 'checkbox';
    box.checked = true;
    box.dataset.testid = `visible-${file.index}`;
    box.addEventListener('change', () => { state.visible[file.index] = box.checked; updateVisibility(); });
    const swatch = document.createElement('span');
    swatch.className = 'swatch';
    swatch.style.background = `rgb(${fileColour(file.index).join(',')})`;
    label.append(box, swatch, file.name);
    const count = document.createElement('div');
    const n = document.createElement('span');
    n.className = 'count';
    n.dataset.testid = `voxel-count-${file.index}`;
    n.dataset.voxels = String(file.voxels);
    n.textContent = file.voxels.toLocaleString('en-US');
    const unit = unitLabel(file.units.unit);
    count.append(n, ` voxels, depth ${file.depth}, voxel ${file.voxel_size} ${unit}` +
      (file.epsg !== 2000 ? `, EPSG:${file.epsg}` : file.crs_wkt ? ', CRS from WKT' : ''));
    row.append(label, count);
    list.append(row);
  }
  for (const set of state.tileSets) {
    const row = document.createElement('div');
    row.className = 'file';
    const swatch = document.createElement('span');
    swatch.className = 'swatch';
    swatch.style.background = `rgb(${fileColour(set.index).join(',')})`;
    const title = document.createElement('div');
    title.append(swatch, `${set.name} (tile set)`);
    const about = document.createElement('div');
    const unit = unitLabel(set.units.unit);
    const overviews = set.overview_levels ? `overview levels 1-${set.overview_levels}` : 'no overviews';
    about.textContent = `${set.tiles} tiles of ${set.tile_size} ${unit}, depth ${set.depth}, voxel ` +
      `${set.voxel_size} ${unit}, ${overviews}` +
      (set.epsg !== null ? `, EPSG:${set.epsg}` : set.crs_wkt ? ', CRS from WKT' : '');
    const status = document.createElement('div');
    status.className = 'count';
    status.id = `tiles-${set.index}`;
    row.append(title, about, status);
    list.append(row);
  }
}

async function main() {
  [state.files, state.tileSets] = await Promise.all([fetchFiles(), fetchTileSets()]);
  state.visible = state.files.map(() => true);
  const nonEmpty = state.files.filter((f) => f.voxels > 0);
  if (!nonEmpty.length && !state.tileSets.length) throw new Error('every file is empty');
  state.sceneOrigin = nonEmpty.length ? [...nonEmpty[0].origin] : [...state.tileSets[0].points_min];
  const min = [Infinity, Infinity, Infinity];
  const max = [-Infinity, -Infinity, -Infinity];
  for (const f of nonEmpty)
    for (let a = 0; a < 3; ++a) {
      min[a] = Math.min(min[a], f.origin[a] + f.voxels_min[a] * f.voxel_size);
      max[a] = Math.max(max[a], f.origin[a] + (f.voxels_max[a] + 1) * f.voxel_size);
    }
  for (const t of state.tileSets)
    for (let a = 0; a < 3; ++a) {
      min[a] = Math.min(min[a], t.points_min[a]);
      max[a] = Math.max(max[a], t.points_max[a]);
    }
  state.bounds = { min, max };
  state.units = [...state.files, ...state.tileSets].map((f) => f.units).find((u) => u.unit !== 'units') ||
    state.units;
  buildFileList();
  const query = new URLSearchParams(window.location.search);
  const limits = { budget: Number(query.get('budget')) || CELL_BUDGET, cache: Number(query.get('cache')) || CELL_CACHE };
  state.streamers = state.tileSets.map((set) => new TileStreamer(set, state.sceneOrigin, slice, scene, colourOf,
    () => { reportTiles(); render(); }, (e) => setStatus(e.message, true), limits));
  $('detail-section').hidden = !state.files.length;
  const maxDepth = Math.max(1, ...state.files.map((f) => f.depth));
  $('detail').max = maxDepth;
  let d = 1;
  while (d < maxDepth && state.files.reduce((sum, f) => sum + f.levels[Math.min(d + 1, f.depth) - 1].cells, 0) <=
    DEFAULT_CELL_BUDGET) ++d;
  $('detail').addEventListener('input', () => setDetail(Number($('detail').value)));
  $('colour').addEventListener('change', () => { state.colourMode = $('colour').value; recolourAll(); });
  for (const id of ['slice-on', 'slice-axis', 'slice-at']) $(id).addEventListener('input', updateSlice);
  // A click that did not drag the view picks.
  let down = null;
  canvas.addEventListener('pointerdown', (e) => { down = [e.clientX, e.clientY]; });
  canvas.addEventListener('pointerup', (e) => {
    if (down && Math.hypot(e.clientX - down[0], e.clientY - down[1]) < 4)
      pickAt(e.clientX, e.clientY).catch((err) => setStatus(err.message, true));
    down = null;
  });
  window.addEventListener('resize', resize);
  resize();
  renderLegend();
  updateSlice();
  frameAll();
  await setDetail(d);
}

// Turns the slicing plane on at world coordinate `at` of `axis` (0 x, 1 y, 2 z), or off.
function setSlice(on, axis = 2, at = 0) {
  $('slice-on').checked = on;
  $('slice-axis').value = String(axis);
  const { min, max } = state.bounds;
  $('slice-at').value = String(Math.round(((at - min[axis]) / Math.max(max[axis] - min[axis], 1e-9)) * 1000));
  updateSlice();
  if (on) {
    // Exactly `at`, not the slider's rounding of it.
    slice.at.value = at - state.sceneOrigin[axis];
    state.sliceWorld = { axis, at };
    sliceHelper.position.setComponent(axis, slice.at.value);
    render();
  }
}

window.volaView = {
  state,
  camera,
  setSlice,
  ready: main().catch((e) => { setStatus(e.message, true); throw e; }),
  // Files and tile sets loaded as far as the detail and the camera ask.
  whenIdle: async () => {
    await state.loading;
    // A cut for the camera as it is now, not as the next frame will find it.
    for (const streamer of state.streamers) streamer.update(camera, cssPixelsPerUnit());
    await Promise.all(state.streamers.map((s) => s.idle()));
  },
  tileCounts: () => state.streamers.map((s) => s.counts()),
  setDetail,
  pickAt,
  lookDownAt,
  frameAll,
  render,
};
