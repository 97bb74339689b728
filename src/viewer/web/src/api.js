// The server's API: JSON metadata and picks, binary cell batches (see
// include/vola/viewer/viewed_file.hpp for the batch layout).

async function getJson(url) {
  const response = await fetch(url);
  const body = await response.json();
  if (!response.ok) throw new Error(body.error || `${url}: HTTP ${response.status}`);
  return body;
}

export function fetchFiles() {
  return getJson('/api/files');
}

export function fetchTileSets() {
  return getJson('/api/tilesets');
}

// A ray in the level's cell units: origin o, direction d, optional tMax.
export function fetchPick(file, level, o, d, tMax) {
  const q = new URLSearchParams({ level, ox: o[0], oy: o[1], oz: o[2], dx: d[0], dy: d[1], dz: d[2] });
  if (tMax !== undefined) q.set('tmax', tMax);
  return getJson(`/api/files/${file}/pick?${q}`);
}

const FLAG_CLASSES = 1;
const FLAG_COLOURS = 2;
const HEADER_BYTES = 32;

// Cells [first, first + count) of a level: { first, count, coords, classes, colours }.
export function fetchCells(file, level, first, count) {
  return fetchBatch(`/api/files/${file}/cells?level=${level}&first=${first}&count=${count}`);
}

// The same from piece `piece` of tile set `set`.
export function fetchPieceCells(set, piece, level, first, count) {
  return fetchBatch(`/api/tilesets/${set}/pieces/${piece}/cells?level=${level}&first=${first}&count=${count}`);
}

async function fetchBatch(url) {
  const response = await fetch(url);
  if (!response.ok) throw new Error((await response.json()).error || `${url}: HTTP ${response.status}`);
  const buffer = await response.arrayBuffer();
  const view = new DataView(buffer);
  const magic = String.fromCharCode(...new Uint8Array(buffer, 0, 4));
  if (magic !== 'VOLC') throw new Error(`${url}: not a cell batch`);
  const coordinateBytes = view.getUint32(8, true);
  const flags = view.getUint32(12, true);
  const n = Number(view.getBigUint64(24, true));
  const coordsLength = n * 3 * coordinateBytes;
  // Copies, so that the typed arrays are aligned whatever the offsets.
  const raw = buffer.slice(HEADER_BYTES, HEADER_BYTES + coordsLength);
  const coords = coordinateBytes === 2 ? new Uint16Array(raw) : new Uint32Array(raw);
  let at = HEADER_BYTES + coordsLength;
  let classes = null;
  let colours = null;
  if (flags & FLAG_CLASSES) { classes = new Uint8Array(buffer, at, n); at += n; }
  if (flags & FLAG_COLOURS) { colours = new Uint8Array(buffer, at, 3 * n); }
  return { first: Number(view.getBigUint64(16, true)), count: n, coords, classes, colours };
}
