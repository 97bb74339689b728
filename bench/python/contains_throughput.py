"""vola.Tree.contains from Python: one vectorised call over (M, 3) against a Python loop
of single-row calls and a numpy dense-grid lookup, on the shared surface set.

    PYTHONPATH=build/python /usr/bin/python3 bench/python/contains_throughput.py ../shared/data/bench
Prints the median of 5 runs of each (million lookups per second).
"""

import pathlib
import statistics
import sys
import time

import numpy as np

import vola


def median_rate(f, count, runs=5):
    times = []
    for _ in range(runs):
        start = time.perf_counter()
        f()
        times.append(time.perf_counter() - start)
    return count / statistics.median(times) / 1e6


data = pathlib.Path(sys.argv[1])
points = np.load(data / "surface_points_1e6.npy")
queries = np.load(data / "surface_queries_1e6.npy").astype(np.int64)
start = time.perf_counter()
tree = vola.build_from_voxels(points, depth=5)
print(f"build_from_voxels: {len(points) / (time.perf_counter() - start) / 1e6:.1f} M points/s (one run), {len(tree)} voxels")
hits = tree.contains(queries)
dense = tree.to_dense()
assert np.array_equal(hits, dense[queries[:, 0], queries[:, 1], queries[:, 2]])
print(f"tree.contains, (1e6, 3) array:  {median_rate(lambda: tree.contains(queries), len(queries)):7.2f} M lookups/s")
print(f"numpy dense[x, y, z] (1 GiB grid): {median_rate(lambda: dense[queries[:, 0], queries[:, 1], queries[:, 2]], len(queries)):7.2f} M lookups/s")
few = queries[:20000]
print(f"tree.contains, Python loop:     {median_rate(lambda: [tree.contains(q) for q in few], len(few)):7.2f} M lookups/s")
