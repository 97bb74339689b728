// Colours: a height ramp, the ASPRS classes, one colour per file.

// ASPRS LAS 1.4 standard classes 0-18, in the colours GIS tools usually give them.
const ASPRS = [
  [160, 160, 160], [170, 170, 170], [166, 120, 60], [140, 200, 90], [60, 170, 60], [20, 110, 30],
  [230, 80, 60], [255, 0, 255], [200, 200, 0], [60, 120, 230], [150, 110, 160], [90, 90, 90],
  [255, 230, 150], [240, 200, 0], [255, 150, 0], [200, 60, 200], [255, 120, 180], [120, 220, 230], [255, 255, 255],
];

export function classColour(code) {
  if (code < ASPRS.length) return ASPRS[code];
  // Reserved and user classes: a fixed scramble, distinct from neighbours.
  const h = (code * 2654435761) >>> 0;
  return [64 + (h & 127), 64 + ((h >> 8) & 127), 64 + ((h >> 16) & 127)];
}

// A perceptual-ish ramp from deep blue through green and yellow to red, t in [0, 1].
const RAMP = [[48, 18, 120], [30, 110, 220], [30, 190, 160], [140, 220, 60], [250, 200, 40], [230, 60, 30]];
export function rampColour(t) {
  const x = Math.min(Math.max(t, 0), 1) * (RAMP.length - 1);
  const i = Math.min(Math.floor(x), RAMP.length - 2);
  const f = x - i;
  return RAMP[i].map((c, k) => Math.round(c + f * (RAMP[i + 1][k] - c)));
}

const FILE_COLOURS = [[90, 170, 255], [255, 140, 60], [120, 220, 120], [230, 90, 200], [240, 230, 90]];
export function fileColour(index) {
  return FILE_COLOURS[index % FILE_COLOURS.length];
}
