"""Checks our connected components against scipy.ndimage.label on the grids written by
analysis_scipy_dump: the same number of components and a bijection between labels.
Usage: compare_scipy.py DIR. Exit 0 when every grid agrees, 1 otherwise."""
import glob
import os
import sys

import numpy as np
from scipy import ndimage

RANK = {6: 1, 18: 2, 26: 3}


def main(folder):
    grids = sorted(p for p in glob.glob(os.path.join(folder, "*.npy")) if ".c" not in os.path.basename(p))
    if not grids:
        print("no grids in", folder)
        return 1
    failures = 0
    for grid_path in grids:
        grid = np.load(grid_path)
        for c, rank in RANK.items():
            rows = np.load(grid_path[:-4] + ".c%d.npy" % c)
            theirs, count = ndimage.label(grid, structure=ndimage.generate_binary_structure(3, rank))
            ours = rows[:, 3]
            at = theirs[rows[:, 0], rows[:, 1], rows[:, 2]]
            pairs = set(zip(ours.tolist(), at.tolist()))
            ok = (len(rows) == int(grid.sum()) and (at > 0).all() and len(set(ours.tolist())) == count
                  and len(pairs) == count)
            print("%s connectivity %d: %d voxels, scipy %d components, ours %d: %s" %
                  (os.path.basename(grid_path), c, len(rows), count, len(set(ours.tolist())), "ok" if ok else "DIFFERENT"))
            failures += not ok
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1]))
