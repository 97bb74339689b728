// Decodes LAZ files written by vola's encoder with laz-perf (an independent LAZ
// implementation, npm package laz-perf 0.0.7) and compares the records with the ones vola
// encoded. laz-perf is not part of vola: install it in a scratch folder and pass that
// folder's node_modules/laz-perf (or set LAZPERF):
//
//   mkdir /tmp/lazperf && cd /tmp/lazperf && npm install laz-perf@0.0.7
//   VOLA_LAZ_OUT=/tmp/lazout build/tests/vola_laz_tests --gtest_filter='LazEncode.LasFilesBecomeLazFiles'
//   node tests/laz/lazperf_roundtrip.mjs /tmp/lazperf/node_modules/laz-perf /tmp/lazout
//
// Every <name>.laz in the folder is decoded and compared with <name>.records. Exit 0
// when all match, 1 otherwise (2: usage).
import { createRequire } from 'node:module';
import { readdirSync, readFileSync } from 'node:fs';
import { join, resolve } from 'node:path';

const [modulePath = process.env.LAZPERF, folder] = process.argv.slice(2);
if (!modulePath || !folder) {
  console.error('usage: node lazperf_roundtrip.mjs <path to laz-perf package> <folder of .laz + .records>');
  process.exit(2);
}
const require = createRequire(import.meta.url);
const { createLazPerf } = require(resolve(modulePath));
const lazperf = await createLazPerf();

function decode(bytes) {
  const file = lazperf._malloc(bytes.length);
  lazperf.HEAPU8.set(bytes, file);
  const reader = new lazperf.LASZip();
  try {
    reader.open(file, bytes.length);
    const count = reader.getCount(), length = reader.getPointLength();
    const point = lazperf._malloc(length);
    const records = new Uint8Array(count * length);
    for (let i = 0; i < count; ++i) {
      reader.getPoint(point);
      records.set(lazperf.HEAPU8.subarray(point, point + length), i * length);
    }
    lazperf._free(point);
    return records;
  } finally {
    reader.delete();
    lazperf._free(file);
  }
}

let failures = 0, files = 0;
for (const name of readdirSync(folder).filter((n) => n.endsWith('.laz')).sort()) {
  const expected = readFileSync(join(folder, name.replace(/\.laz$/, '.records')));
  let verdict;
  try {
    const records = decode(readFileSync(join(folder, name)));
    const same = records.length === expected.length && records.every((b, i) => b === expected[i]);
    let first = -1;
    if (!same) first = records.findIndex((b, i) => b !== expected[i]);
    verdict = same ? 'ok' : `MISMATCH (${records.length} vs ${expected.length} bytes, first difference at ${first})`;
    if (!same) ++failures;
  } catch (e) {
    verdict = `FAILED: ${e}`;
    ++failures;
  }
  ++files;
  console.log(`${name}: ${verdict}`);
}
console.log(`${files - failures} of ${files} files decode in laz-perf to vola's records`);
process.exit(failures || files === 0 ? 1 : 0);
