// A tile set (vola tile's index.geojson) streamed as Potree streams a point cloud: the
// pieces form a tree (an overview of level L covers 4 x 4 x 4 pieces of level L - 1,
// level 0 being the tiles), and on every camera move the tree is cut again. From the
// coarsest overviews down, the piece whose voxels look largest on screen is replaced by
// its children in view while the cells of the cut stay within the budget; pieces out of
// view are not refined, and children out of view are left out. Pieces of the cut load nearest first (a few at a time), each its finest
// level, batch by batch; until a piece is loaded its nearest loaded ancestor stays on
// screen. Loaded pieces off the cut are freed, least useful first, once the cells held
// exceed the cache. So the page never asks for the whole set.
import * as THREE from 'three';
import { fetchPieceCells } from './api.js';
import { VoxelLayer } from './layer.js';

const BATCH_CELLS = 1 << 18;
// Cells of the cut, and cells held (cut or not), unless the page's URL says otherwise
// (?budget=N&cache=N: a weaker machine, or a test that wants to see pieces freed).
export const CELL_BUDGET = 2_000_000;
export const CELL_CACHE = 4_000_000;
// A piece whose voxels span at most this many pixels is fine enough: its cubes already
// merge into surfaces on screen.
const REFINE_PIXELS = 3;
const LOADS_AT_ONCE = 2;

export class TileStreamer {
  // set: /api/tilesets metadata; sceneOrigin: the world point at the scene's 0;
  // slice: shared uniforms (layer.js); colourOf(layer, i); changed(): called when what is
  // drawn or loaded changes; failed(error): a piece could not be loaded; limits:
  // { budget, cache } in cells.
  constructor(set, sceneOrigin, slice, scene, colourOf, changed, failed, limits) {
    this.set = set;
    this.sceneOrigin = sceneOrigin;
    this.slice = slice;
    this.scene = scene;
    this.colourOf = colourOf;
    this.changed = changed;
    this.failed = failed;
    this.budget = limits.budget;
    this.cache = limits.cache;
    this.nodes = set.pieces.map((p) => ({
      piece: p,
      children: [],
      parent: null,
      layer: null,    // a VoxelLayer once loading starts
      loaded: false,
      priority: 0,    // how large its voxels look on screen, in pixels
      inView: false,  // whether its points' box meets the camera's frustum
      // Distances are to the piece's points, not to its grid's box (mostly empty air).
      box: new THREE.Box3(new THREE.Vector3(...p.points_min.map((v, a) => v - sceneOrigin[a])),
        new THREE.Vector3(...p.points_max.map((v, a) => v - sceneOrigin[a]))),
    }));
    const byKey = new Map(this.nodes.map((n) => [`${n.piece.level}/${n.piece.tile.join('/')}`, n]));
    for (const n of this.nodes) {
      if (n.piece.level === set.overview_levels) continue;
      const parent = byKey.get(`${n.piece.level + 1}/${n.piece.tile.map((t) => Math.floor(t / 4)).join('/')}`);
      if (parent) { n.parent = parent; parent.children.push(n); }
    }
    this.roots = this.nodes.filter((n) => !n.parent);
    this.cut = [];
    this.loading = 0;
    this.idleWaiters = [];
  }

  // Cuts the tree for `camera` (pixelsPerUnit: screen pixels a unit spans at unit
  // distance) and starts the loads it needs.
  update(camera, pixelsPerUnit) {
    camera.updateMatrixWorld();
    const frustum = new THREE.Frustum().setFromProjectionMatrix(
      new THREE.Matrix4().multiplyMatrices(camera.projectionMatrix, camera.matrixWorldInverse));
    const eye = camera.position;
    for (const n of this.nodes) {
      const distance = Math.max(n.box.distanceToPoint(eye), n.piece.voxel_size);
      n.priority = (n.piece.voxel_size * pixelsPerUnit) / distance;
      n.inView = frustum.intersectsBox(n.box);
    }
    const queue = [...this.roots];
    let cells = this.roots.reduce((sum, n) => sum + n.piece.voxels, 0);
    const cut = [];
    while (queue.length) {
      queue.sort((a, b) => b.priority - a.priority);  // a few hundred pieces: sorting is cheap
      const n = queue.shift();
      const children = n.children.filter((c) => c.inView);
      const more = children.reduce((sum, c) => sum + c.piece.voxels, 0) - n.piece.voxels;
      if (children.length && n.inView && n.priority > REFINE_PIXELS && cells + more <= this.budget) {
        cells += more;
        queue.push(...children);
      } else {
        cut.push(n);
      }
    }
    this.cut = cut;
    this.show();
    this.evict();
    this.pump();
  }

  // Draws the loaded pieces of the cut, and for each piece of it still loading, its
  // nearest loaded ancestor.
  show() {
    const shown = new Set();
    for (const n of this.cut) {
      let m = n;
      while (m && !m.loaded) m = m.parent;
      if (m) shown.add(m);
    }
    for (const n of this.nodes) if (n.layer) n.layer.mesh.visible = shown.has(n);
    this.changed();
  }

  // Frees loaded pieces that are neither cut nor drawn, lowest priority first, until the
  // cells held fit the cache.
  evict() {
    let held = this.cellsHeld();
    if (held <= this.cache) return;
    const keep = new Set(this.cut);
    const spare = this.nodes.filter((n) => n.loaded && !keep.has(n) && !n.layer.mesh.visible)
      .sort((a, b) => a.priority - b.priority);
    for (const n of spare) {
      if (held <= this.cache) break;
      held -= n.layer.total;
      n.layer.dispose();
      n.layer = null;
      n.loaded = false;
    }
    this.changed();
  }

  pump() {
    const waiting = this.cut.filter((n) => !n.layer).sort((a, b) => b.priority - a.priority);
    while (this.loading < LOADS_AT_ONCE && waiting.length) this.load(waiting.shift()).catch(this.failed);
    if (this.loading === 0) for (const resolve of this.idleWaiters.splice(0)) resolve();
  }

  async load(n) {
    ++this.loading;
    const p = n.piece;
    const level = this.set.depth - 1;
    const file = {
      index: this.set.index, name: p.file, origin: p.origin, has_classes: this.set.has_classes,
      has_colours: this.set.has_colours, levels: [],
    };
    file.levels[level] = { cells: p.voxels, cell_size: p.voxel_size };
    const layer = new VoxelLayer(file, level, p.origin.map((o, a) => o - this.sceneOrigin[a]), this.slice);
    layer.mesh.visible = false;
    n.layer = layer;
    this.scene.add(layer.mesh);
    try {
      while (layer.loaded < layer.total) {
        const batch = await fetchPieceCells(this.set.index, p.id, level, layer.loaded, BATCH_CELLS);
        if (batch.count === 0)
          throw new Error(`${this.set.name}/${p.file}: the server sent no cells at ${layer.loaded}`);
        layer.append(batch, this.colourOf);
      }
      n.loaded = true;
      this.show();
      this.evict();
    } finally {
      --this.loading;
      this.pump();
    }
  }

  // Resolves when no piece of the cut is waiting or loading.
  idle() {
    return new Promise((resolve) => {
      this.idleWaiters.push(resolve);
      this.pump();
    });
  }

  cellsHeld() {
    return this.nodes.reduce((sum, n) => sum + (n.layer ? n.layer.loaded : 0), 0);
  }

  // What the page reports: pieces and cells loaded, tiles among them.
  counts() {
    const loaded = this.nodes.filter((n) => n.loaded);
    return {
      pieces: this.nodes.length,
      loaded: loaded.length,
      tilesLoaded: loaded.filter((n) => n.piece.level === 0).length,
      overviewsLoaded: loaded.filter((n) => n.piece.level > 0).length,
      shown: this.nodes.filter((n) => n.layer && n.layer.mesh.visible).length,
      cells: this.cellsHeld(),
      loadedTiles: loaded.filter((n) => n.piece.level === 0).map((n) => n.piece.id),
      budget: this.budget,
      cache: this.cache,
    };
  }

  recolour() {
    for (const n of this.nodes) if (n.layer) n.layer.recolour(this.colourOf);
  }

  layers() {
    return this.nodes.filter((n) => n.layer).map((n) => n.layer);
  }
}
