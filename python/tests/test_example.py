"""docs/python_example.py runs on a real survey and docs/python-example.md shows it as it is."""

import pathlib
import subprocess
import sys

import numpy as np
import pytest

import vola

DOCS = pathlib.Path(__file__).resolve().parents[2] / "docs"


def test_example_prints_a_census_and_plots_a_slice(shared_data, tmp_path):
    las = shared_data / "las" / "pdal_autzen_trim.las"
    if not las.exists():
        pytest.fail(f"{las} missing")
    png = tmp_path / "slice.png"
    run = subprocess.run([sys.executable, str(DOCS / "python_example.py"), str(las), str(png)],
                         capture_output=True, text=True, check=True)
    tree = vola.convert(las, voxel_size=2.0)
    assert f"voxels {len(tree)}," in run.stdout
    assert "ft^3, footprint" in run.stdout and "(foot)" in run.stdout  # Autzen is in feet, not metres
    assert "Ground" in run.stdout and f"level {tree.depth - 1}:" in run.stdout
    image = pytest.importorskip("matplotlib.image").imread(png)
    assert image.shape[0] > 100 and image.shape[1] > 100
    assert np.unique(image.reshape(-1, image.shape[-1]), axis=0).shape[0] > 50  # not blank


def test_markdown_shows_the_script_verbatim():
    markdown = (DOCS / "python-example.md").read_text()
    script = (DOCS / "python_example.py").read_text()
    assert "```python\n" + script + "```" in markdown
