// The scale bar and the north arrow over the scene, redrawn with every frame. Both are
// true at the orbit's target: the bar spans a round length there in the CRS's unit, and
// the arrow points where the grid's +y runs on screen (north, for a CRS vola voxelises:
// easting/northing, or longitude/latitude).
import * as THREE from 'three';

const BAR_PIXELS = 150;  // the longest the bar may be
const SHORT = { metre: 'm', foot: 'ft', 'US survey foot': 'US survey ft' };

// How the page writes a unit PROJ names ("metre": "m"); "units" when there is no CRS.
export function unitLabel(unit) {
  return SHORT[unit] || unit;
}

// The largest 1, 2 or 5 times a power of ten not above `limit` (> 0).
function roundLength(limit) {
  const power = 10 ** Math.floor(Math.log10(limit));
  return [5, 2, 1].map((m) => m * power).find((l) => l <= limit) || power;
}

// pixelsPerUnit: screen pixels a unit spans at unit distance; unit: PROJ's name of the
// CRS's unit, or "units" when there is none.
export function updateScaleBar(box, camera, target, pixelsPerUnit, unit) {
  const atTarget = pixelsPerUnit / Math.max(camera.position.distanceTo(target), 1e-9);
  const length = roundLength(BAR_PIXELS / atTarget);
  box.querySelector('#scale-bar').style.width = `${Math.round(length * atTarget)}px`;
  const text = Number(length.toPrecision(1)).toLocaleString('en-US', { maximumFractionDigits: 12 });
  box.querySelector('#scale-label').textContent = `${text} ${unitLabel(unit)}`;
  box.dataset.length = String(length);
  box.dataset.unit = unit;
}

// Hidden when the CRS is not known (north then is not either).
export function updateNorthArrow(box, camera, target, north) {
  box.hidden = !north;
  if (!north) return;
  camera.updateMatrixWorld();
  const step = Math.max(camera.position.distanceTo(target), 1e-9) * 0.1;
  const from = target.clone().project(camera);
  const to = target.clone().add(new THREE.Vector3(0, step, 0)).project(camera);
  // Clockwise from the screen's up, in pixels (NDC y points up, screen y down).
  const angle = Math.atan2((to.x - from.x) * window.innerWidth, (to.y - from.y) * window.innerHeight);
  box.querySelector('#north-turn').style.transform = `rotate(${angle}rad)`;
  box.dataset.angle = String(angle);
}
