"""Shared fixtures of the Python package's tests: the repository's data and the CLI binary."""

import os
import pathlib
import shutil

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
DATA = ROOT / "tests" / "data"
SLICES = DATA / "slices"


@pytest.fixture(scope="session")
def cli():
    """The `strata` CLI (STRATA_CLI, else build/tools/strata), to compare with; tests that
    need it are skipped when it has not been built."""
    path = os.environ.get("STRATA_CLI", str(ROOT / "build" / "tools" / "strata"))
    if not os.access(path, os.X_OK):
        pytest.skip(f"no strata CLI at {path} (set STRATA_CLI)")
    return path


@pytest.fixture
def slice_files():
    return sorted(SLICES.glob("*.json"))


@pytest.fixture
def slices_copy(tmp_path):
    """A copy of tests/data/slices (so that outputs never land beside the originals)."""
    dest = tmp_path / "slices"
    shutil.copytree(SLICES, dest)
    return dest
