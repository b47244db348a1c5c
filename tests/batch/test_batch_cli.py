"""`facemime batch`: its one-line errors, and a batch killed halfway then run again."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time

import pytest

from cli.test_cli import run


def one_error(code: int, err: str) -> str:
    assert code == 1 and err.count("\n") == 1 and err.startswith("facemime: error: "), err
    return err.strip()


def test_no_inputs(tmp_path, capsys):
    (tmp_path / "empty").mkdir()
    (tmp_path / "empty" / "notes.txt").write_text("no video here")
    err = one_error(*run(capsys, "batch", str(tmp_path / "empty"), "--out", str(tmp_path / "out"))[::2])
    assert err.startswith(f"facemime: error: no videos in {tmp_path / 'empty'} (looked for files ending in .mp4")
    (tmp_path / "list.txt").write_text("# nothing\n\n")
    err = one_error(*run(capsys, "batch", str(tmp_path / "list.txt"), "--out", str(tmp_path / "out"))[::2])
    assert err == f"facemime: error: no videos listed in {tmp_path / 'list.txt'}"
    err = one_error(*run(capsys, "batch", str(tmp_path / "missing"), "--out", str(tmp_path / "out"))[::2])
    assert err == f"facemime: error: input {tmp_path / 'missing'} does not exist"
    assert not (tmp_path / "out").exists()


def test_unreadable_folder(tmp_path, capsys, monkeypatch):
    folder = tmp_path / "locked"
    folder.mkdir()
    real = os.scandir

    def scandir(path="."):  # as for a folder without read permission (the tests may run as root)
        if os.fspath(path) == str(folder):
            raise PermissionError(13, "Permission denied", str(folder))
        return real(path)

    monkeypatch.setattr(os, "scandir", scandir)
    err = one_error(*run(capsys, "batch", str(folder), "--out", str(tmp_path / "out"))[::2])
    assert err == f"facemime: error: cannot read folder {folder}: Permission denied"


@pytest.mark.parametrize(
    ("address", "message"),
    [
        ("localhost:8786", "the scheduler address must look like tcp://HOST:PORT, got 'localhost:8786'"),
        ("tcp://127.0.0.1:99999", "the scheduler address must look like tcp://HOST:PORT, got 'tcp://127.0.0.1:99999'"),
        ("tcp://127.0.0.1:9", "cannot reach the Dask scheduler at tcp://127.0.0.1:9: "),
    ],
)
def test_bad_scheduler_address(tmp_path, capsys, clips, address, message):
    (tmp_path / "in").mkdir()
    os.symlink(clips[0], tmp_path / "in" / "a.mp4")
    err = one_error(
        *run(capsys, "batch", str(tmp_path / "in"), "--out", str(tmp_path / "out"), "--scheduler", address)[::2]
    )
    assert err.startswith(f"facemime: error: {message}")


def manifest(out) -> list[dict]:
    path = out / "manifest.jsonl"
    return [json.loads(line) for line in path.read_text().splitlines()] if path.exists() else []


def test_a_batch_killed_halfway_then_rerun_redoes_only_the_unfinished(tmp_path, clips):
    inp, out = tmp_path / "in", tmp_path / "out"
    inp.mkdir()
    for c in clips:
        os.symlink(c, inp / c.name)
    command = [sys.executable, "-m", "facemime", "batch", str(inp), "--out", str(out), "--jobs", "1"]
    # Killed (SIGKILL, the cluster's processes with it) as soon as its first result is in the manifest.
    p = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, start_new_session=True)
    try:
        deadline = time.monotonic() + 60
        while not manifest(out) and p.poll() is None and time.monotonic() < deadline:
            time.sleep(0.02)
    finally:
        os.killpg(p.pid, signal.SIGKILL)
        p.communicate()
    first = manifest(out)
    assert 1 <= len(first) < len(clips) and all(r["status"] == "done" for r in first)
    finished = {r["video"]: (out / f"{r['video']}.json").stat().st_mtime_ns for r in first}
    # Run again to the end: the finished videos are not redone, the others are.
    rerun = subprocess.run(command, capture_output=True, text=True, timeout=120)
    assert rerun.returncode == 0, rerun.stderr
    assert rerun.stdout == f"{out / 'manifest.jsonl'}\n"
    assert f"{len(clips) - len(first)} done, {len(first)} complete from before, 0 failed" in rerun.stderr
    second = manifest(out)[len(first) :]
    assert sorted(r["video"] for r in second) == sorted(c.stem for c in clips if c.stem not in finished)
    assert all(r["status"] == "done" for r in second)
    assert {v: (out / f"{v}.json").stat().st_mtime_ns for v in finished} == finished
    assert sorted(p.name for p in out.iterdir()) == sorted([f"{c.stem}.json" for c in clips] + ["manifest.jsonl"])
