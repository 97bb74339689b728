#!/usr/bin/env python3
"""Peak memory of vola's readers on every file of the shared data, two builds side by side.

For each input file (points, meshes, DEMs, voxel grids) runs `vola convert FILE out.vol
--depth 6`
with each of two vola binaries, alternating, and reports the median peak RSS (KiB, from
/usr/bin/time) of each and their ratio. A reader whose file both binaries refuse is listed
as refused. Used for issue 21's "no reader's peak memory grows by more than 10%".

Usage: bench/reader_memory.py OLD_VOLA NEW_VOLA [SHARED_DATA_DIR] [--runs N]
"""
import argparse
import os
import pathlib
import statistics
import subprocess
import tempfile

INPUTS = ("las/*.las", "laz/*.laz", "ply/*.ply", "pcd/*.pcd", "kitti/*.bin", "kitti/object_training/velodyne/*.bin",
          "binvox/*.binvox", "mesh/*/*", "dem/*.tif", "bench/*.npy")


def peak_kib(vola: str, path: pathlib.Path, out: pathlib.Path) -> int | None:
    run = subprocess.run(["/usr/bin/time", "-f", "%M", vola, "convert", str(path), str(out), "--depth", "6", "-q"],
                         capture_output=True, text=True)
    if run.returncode != 0:
        return None
    return int(run.stderr.strip().splitlines()[-1])


def main() -> int:
    parser = argparse.ArgumentParser()
    parser.add_argument("old")
    parser.add_argument("new")
    parser.add_argument("data", nargs="?", default=os.path.join(os.environ.get("VOLA_SHARED", "../shared"), "data"))
    parser.add_argument("--runs", type=int, default=3)
    args = parser.parse_args()
    data = pathlib.Path(args.data)
    files = sorted({p for pattern in INPUTS for p in data.glob(pattern) if p.is_file()})
    worst = 0.0
    with tempfile.TemporaryDirectory() as tmp:
        out = pathlib.Path(tmp) / "out.vol"
        print(f"{'file':58s} {'old KiB':>9s} {'new KiB':>9s} {'new/old':>8s}")
        for path in files:
            old, new = [], []
            for _ in range(args.runs):
                old.append(peak_kib(args.old, path, out))
                new.append(peak_kib(args.new, path, out))
            name = str(path.relative_to(data))
            if None in old or None in new:
                state = "refused by both" if all(v is None for v in old + new) else (
                    "refused by old" if None in old and None not in new else "refused by new")
                print(f"{name:58s} {state}")
                continue
            o, n = statistics.median(old), statistics.median(new)
            worst = max(worst, n / o)
            print(f"{name:58s} {o:9.0f} {n:9.0f} {n / o:8.3f}")
    print(f"largest new/old: {worst:.3f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
