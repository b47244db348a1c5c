"""Shared fixtures. Tests that need real data use ../shared next to the repository (CI has it)."""

from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SHARED = ROOT.parent / "shared"


@pytest.fixture(scope="session")
def shared() -> Path:
    if not (SHARED / "data").is_dir():
        pytest.skip(f"shared data folder not found at {SHARED}")
    return SHARED / "data"


@pytest.fixture(scope="session")
def candide_path(shared: Path) -> Path:
    return shared / "models" / "candide3.wfm"
