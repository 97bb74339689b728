"""Point filters from Python: vola.convert(filters=...) and vola.translate(filters=...)
write what the CLI's --filter/--where flags write, and bad stages raise."""
import subprocess

import pytest
import vola


def test_convert_filters_match_the_cli(shared_data, vola_cli, tmp_path):
    autzen = shared_data / "las" / "pdal_autzen_trim.las"
    if not autzen.exists():
        pytest.skip(f"no {autzen}")
    ours = vola.convert(autzen, voxel_size=3.0, filters=["smrf", "where:Classification == 2"])
    subprocess.run([vola_cli, "convert", str(autzen), str(tmp_path / "cli.vol"), "--voxel-size", "3", "--filter",
                    "smrf", "--where", "Classification == 2", "-q"], check=True)
    assert ours.to_bytes() == (tmp_path / "cli.vol").read_bytes()
    everything = vola.convert(autzen, voxel_size=3.0)
    assert 0 < ours.census()["voxels"] < everything.census()["voxels"]


def test_translate_filters_match_the_cli(shared_data, vola_cli, tmp_path):
    autzen = shared_data / "las" / "pdal_autzen_trim.las"
    if not autzen.exists():
        pytest.skip(f"no {autzen}")
    vola.translate(autzen, tmp_path / "py.laz", filters=["smrf"])
    subprocess.run([vola_cli, "translate", str(autzen), str(tmp_path / "cli.laz"), "--filter", "smrf", "-q"], check=True)
    assert (tmp_path / "py.laz").read_bytes() == (tmp_path / "cli.laz").read_bytes()


def test_bad_stages_raise(shared_data, tmp_path):
    autzen = shared_data / "las" / "pdal_autzen_trim.las"
    with pytest.raises(vola.InvalidArgument, match="no filter 'ground'"):
        vola.convert(autzen, voxel_size=3.0, filters=["ground"])
    with pytest.raises(vola.InvalidArgument, match="no dimension 'Clasification'"):
        vola.translate(autzen, tmp_path / "x.las", filters=["where:Clasification == 2"])
