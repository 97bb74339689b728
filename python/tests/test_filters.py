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


def test_pipeline_from_a_file_text_or_lists_writes_what_the_cli_writes(shared_data, vola_cli, tmp_path):
    import json
    autzen = shared_data / "las" / "pdal_autzen_trim.las"

    def spec(prefix):
        return [str(autzen), {"type": "filters.smrf"},
                {"type": "filters.range", "limits": "Classification[2:2]"},
                {"type": "writers.las", "filename": str(tmp_path / f"{prefix}ground.laz")},
                {"type": "writers.vola", "filename": str(tmp_path / f"{prefix}ground.vol"), "voxel_size": 3}]

    (tmp_path / "cli.json").write_text(json.dumps(spec("cli_")))
    subprocess.run([vola_cli, "pipeline", str(tmp_path / "cli.json"), "-q"], check=True)
    (tmp_path / "file.json").write_text(json.dumps(spec("file_")))
    runs = {"list_": vola.pipeline(spec("list_")), "text_": vola.pipeline(json.dumps(spec("text_"))),
            "file_": vola.pipeline(tmp_path / "file.json")}
    for prefix, reports in runs.items():
        for ext in ("laz", "vol"):
            assert (tmp_path / f"{prefix}ground.{ext}").read_bytes() == (tmp_path / f"cli_ground.{ext}").read_bytes()
        points, voxels = reports
        assert not points["voxels"] and voxels["voxels"]
        assert [s["spec"].split(":")[0] for s in points["stages"]] == ["smrf", "where"]
        assert points["warnings"] == [] and voxels["warnings"] == []  # LAZ and .vol keep the CRS
        smrf, where = points["stages"]
        assert smrf["points_in"] == smrf["points_out"] == 110000 and 0 < smrf["ground"] < 110000
        assert where["points_out"] == smrf["ground"]
        assert voxels["voxel_count"] == len(vola.read(tmp_path / f"{prefix}ground.vol"))
        # The .vol writer's report has the same stage counts (its "stages" were empty).
        assert voxels["stages"] == points["stages"]
    with pytest.raises(vola.InvalidArgument, match="pipeline stage 1"):
        vola.pipeline([str(autzen), {"type": "filters.nothing"}, str(tmp_path / "x.las")])
    with pytest.raises(vola.IoError, match="no_such.json: cannot open"):
        vola.pipeline(tmp_path / "no_such.json")


def test_pipeline_reports_what_a_point_file_cannot_keep(shared_data, tmp_path):
    autzen = shared_data / "las" / "pdal_autzen_trim.las"
    (report,) = vola.pipeline([str(autzen), str(tmp_path / "a.ply")])
    assert len(report["warnings"]) == 1 and "PLY has no place for the CRS" in report["warnings"][0]
