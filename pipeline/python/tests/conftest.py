"""Shared fixtures: the repository, the `pipeline` binary the bindings are compared with, and
the demo set."""

import os
import shutil
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[3]


@pytest.fixture(scope="session")
def pipeline_bin() -> Path:
    """The command line built from the same sources (QRM_PIPELINE overrides)."""
    path = Path(os.environ.get("QRM_PIPELINE", ROOT / "target" / "release" / "pipeline"))
    if not path.is_file():
        pytest.fail(f"{path} is missing: cargo build --release -p pipeline first")
    return path


@pytest.fixture(scope="session")
def cli(pipeline_bin):
    def run(*args, check=True):
        return subprocess.run(
            [str(pipeline_bin), *map(str, args)], capture_output=True, text=True, check=check
        )

    return run


@pytest.fixture(scope="session")
def demo(tmp_path_factory) -> Path:
    """A copy of datasets/demo (runs must not write into the repository)."""
    copy = tmp_path_factory.mktemp("data") / "demo"
    shutil.copytree(ROOT / "datasets" / "demo", copy)
    return copy
