"""A LAS survey through the vola Python module: convert, census, a slice plotted.

Run (after a CMake build):
    PYTHONPATH=build/python python3 docs/python_example.py ../shared/data/las/pdal_autzen_trim.las slice.png
"""

import sys

import matplotlib

matplotlib.use("Agg")  # files only, no display needed
import matplotlib.pyplot as plt
import numpy as np

import vola

las_path, png_path = sys.argv[1], sys.argv[2]

# 1. Convert: any input `vola convert` reads. 2-unit voxels on a grid in the survey's CRS (Autzen's unit is the foot: 2 ft).
tree = vola.convert(las_path, voxel_size=2.0)
print(tree)
crs = vola.describe_crs(tree.crs_wkt) if tree.crs_wkt else {"name": "unknown", "unit": "unit"}
unit = {"metre": "m", "foot": "ft", "US survey foot": "ftUS"}.get(crs["unit"], crs["unit"])  # Autzen: feet
print(f"CRS {crs['name']} ({crs['unit']}), origin {tree.origin}, {tree.side}^3 grid")

# 2. Census: per-level blocks, volume, footprint and ASPRS classes.
census = tree.census()
print(f"voxels {census['voxels']}, volume {census['volume']:.0f} {unit}^3, footprint {census['footprint_area']:.0f} {unit}^2")
for level, row in enumerate(census["levels"]):
    print(f"  level {level}: {row['blocks']:6d} blocks  {row['cells']:7d} cells  fill {row['fill']:.2f}")
for attribute in census["attributes"]:
    for code, name, count in attribute["classes"]:
        print(f"  class {code:3d} {name:<20s} {count:7d} voxels")

# 3. Arrays: voxel indices, world centres and attribute columns, in the same (rank) order.
voxels = tree.voxels()                           # (N, 3) uint32
centres = tree.centers()                         # (N, 3) float64, CRS coordinates
intensity = tree.attribute("intensity")          # read-only view, no copy
print(f"mean intensity {intensity.mean():.1f}; highest voxel centre z = {centres[:, 2].max():.1f} {unit}")

# 4. A horizontal slice through the middle of the occupied heights, as a dense image.
z = int(np.median(voxels[:, 2]))
in_slice = voxels[:, 2] == z
image = np.full((voxels[:, 1].max() + 1, voxels[:, 0].max() + 1), np.nan)
image[voxels[in_slice, 1], voxels[in_slice, 0]] = intensity[in_slice]
figure, axes = plt.subplots(figsize=(8, 4.5), dpi=100)
extent = (tree.origin[0], tree.origin[0] + image.shape[1] * tree.voxel_size,
          tree.origin[1], tree.origin[1] + image.shape[0] * tree.voxel_size)
shown = axes.imshow(image, origin="lower", extent=extent, cmap="viridis", interpolation="nearest")
figure.colorbar(shown, ax=axes, label="intensity (voxel mean)")
axes.set_title(f"voxels at z = {tree.origin[2] + (z + 0.5) * tree.voxel_size:.1f} {unit} ({in_slice.sum()} voxels)")
axes.set_xlabel("easting")
axes.set_ylabel("northing")
figure.tight_layout()
figure.savefig(png_path)
print(f"slice z={z}: {in_slice.sum()} voxels -> {png_path}")
