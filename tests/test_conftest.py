"""The rule for tests whose data or tools are missing: skipped locally, failed in CI."""

import os
import subprocess
import sys
from pathlib import Path

import pytest

import conftest
from conftest import unavailable


def test_missing_data_skips_locally(monkeypatch):
    monkeypatch.delenv("CI", raising=False)
    with pytest.raises(pytest.skip.Exception, match="shared data folder not found"):
        unavailable("shared data folder not found at /nowhere")


def test_missing_data_fails_when_ci_is_set(monkeypatch):
    monkeypatch.setenv("CI", "true")
    with pytest.raises(pytest.fail.Exception, match="shared data folder not found"):
        unavailable("shared data folder not found at /nowhere")


@pytest.mark.parametrize(("ci", "outcome"), [(None, "1 skipped"), ("1", "1 error")])
def test_the_shared_fixture_without_its_folder(tmp_path, ci, outcome):
    # This conftest, pointed at a shared folder that does not exist, in a session of its own.
    source = Path(conftest.__file__).read_text()
    line = 'SHARED = ROOT.parent / "shared"'
    assert line in source
    (tmp_path / "conftest.py").write_text(source.replace(line, f"SHARED = Path({str(tmp_path / 'none')!r})"))
    (tmp_path / "test_it.py").write_text("def test_uses_shared(shared):\n    pass\n")
    env = {k: v for k, v in os.environ.items() if k != "CI"} | ({"CI": ci} if ci else {})
    done = subprocess.run(
        [
            sys.executable,
            "-m",
            "pytest",
            "-p",
            "no:cacheprovider",
            "-q",
            "-rs",
            "--rootdir",
            str(tmp_path),
            str(tmp_path),
        ],
        capture_output=True,
        text=True,
        env=env,
        cwd=tmp_path,
    )
    assert outcome in done.stdout and "shared data folder not found" in done.stdout, done.stdout + done.stderr
