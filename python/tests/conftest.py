import os
import pathlib

import pytest

REPO = pathlib.Path(__file__).resolve().parents[2]


@pytest.fixture
def repo() -> pathlib.Path:
    return REPO


@pytest.fixture
def tadslc() -> str:
    """The CLI the rollout is compared with: $TADSLC, else the workspace's debug build."""
    path = os.environ.get("TADSLC") or str(REPO / "target" / "debug" / "tadslc")
    if not os.path.exists(path):
        pytest.fail(f"{path} does not exist: build it (cargo build -p tadslc) or set TADSLC")
    return path
