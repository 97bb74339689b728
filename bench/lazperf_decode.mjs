// laz-perf's (npm, WebAssembly under node) decode speed on one LAZ file: every point read
// with getPoint, `repeats` times; prints the best and median points per second. The peer
// figure for bench/laz_peers.sh (the only LAZ decoder available on this system).
//
//   node bench/lazperf_decode.mjs <path to laz-perf package> file.laz [repeats]
import { createRequire } from 'node:module';
import { readFileSync } from 'node:fs';
import { resolve } from 'node:path';

const [modulePath, file, repeatsText = '5'] = process.argv.slice(2);
if (!modulePath || !file) {
  console.error('usage: node lazperf_decode.mjs <laz-perf package> <file.laz> [repeats]');
  process.exit(2);
}
const require = createRequire(import.meta.url);
const { createLazPerf } = require(resolve(modulePath));
const lazperf = await createLazPerf();
const bytes = readFileSync(file);
const buffer = lazperf._malloc(bytes.length);
lazperf.HEAPU8.set(bytes, buffer);
const rates = [];
let points = 0;
for (let r = 0; r < Number(repeatsText); ++r) {
  const reader = new lazperf.LASZip();
  reader.open(buffer, bytes.length);
  points = reader.getCount();
  const point = lazperf._malloc(reader.getPointLength());
  const start = process.hrtime.bigint();
  for (let i = 0; i < points; ++i) reader.getPoint(point);
  const seconds = Number(process.hrtime.bigint() - start) / 1e9;
  lazperf._free(point);
  reader.delete();
  rates.push(points / seconds);
}
rates.sort((a, b) => a - b);
const best = rates[rates.length - 1], median = rates[Math.floor(rates.length / 2)];
console.log(`laz-perf ${file}: ${points} points, best ${(best / 1e6).toFixed(2)} M points/s, median ${(median / 1e6).toFixed(2)} M points/s`);
