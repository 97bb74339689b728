"""Shared fixtures: real data from $VOLA_SHARED (default: the CMake cache's
VOLA_SHARED_DIR, passed by ctest as VOLA_SHARED_DEFAULT) and the vola CLI ($VOLA_CLI).
Missing data skips a test, unless CI is set: then it fails."""

import os
import pathlib

import pytest


def _require(path: pathlib.Path, what: str) -> pathlib.Path:
    if path.exists():
        return path
    message = f"{what} missing at {path} (set VOLA_SHARED)"
    if os.environ.get("CI"):
        pytest.fail(message + " and CI is set")
    pytest.skip(message)


@pytest.fixture(scope="session")
def shared_data() -> pathlib.Path:
    root = os.environ.get("VOLA_SHARED") or os.environ.get("VOLA_SHARED_DEFAULT") or ""
    return _require(pathlib.Path(root) / "data", "shared data")


@pytest.fixture(scope="session")
def las_file(shared_data: pathlib.Path) -> pathlib.Path:
    return _require(shared_data / "las" / "pdal_autzen-utm.las", "LAS survey")


@pytest.fixture(scope="session")
def vola_cli() -> str:
    cli = os.environ.get("VOLA_CLI", "")
    if not cli or not os.access(cli, os.X_OK):
        if os.environ.get("CI"):
            pytest.fail("VOLA_CLI is not set to the vola executable and CI is set")
        pytest.skip("VOLA_CLI is not set to the vola executable")
    return cli


@pytest.fixture(scope="session")
def autzen_trim(shared_data: pathlib.Path) -> pathlib.Path:
    """A dense survey (110 000 points, Oregon feet) where las_file is a sparse one."""
    return _require(shared_data / "las" / "pdal_autzen_trim.las", "LAS survey")
