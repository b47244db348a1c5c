"""run_batch: the manifest of done and failed videos, time limits, crashed workers, resuming."""

from __future__ import annotations

import json
import os
import sys
import time
from pathlib import Path

import cloudpickle
import pytest

from facemime.app.batch import default_task, run_batch
from facemime.batch.manifest import Manifest

# The tasks below go to the workers by value (the workers cannot import this module).
cloudpickle.register_pickle_by_value(sys.modules[__name__])


def lines(out: Path) -> list[dict]:
    return [json.loads(line) for line in (out / "manifest.jsonl").read_text().splitlines()]


def test_ten_videos_done_and_three_broken_ones_failed(tmp_path, shared, broken, scheduler):
    videos = sorted((shared / "video").glob("*.mp4"))
    listing = tmp_path / "videos.txt"
    listing.write_text(
        "# the shared videos and three broken files\n"
        + "\n".join(map(str, videos))
        + "\n\n"
        + "\n".join(str(broken[n]) for n in ("truncated", "random", "noface"))
        + "\n"
    )
    out = tmp_path / "out"
    result = run_batch(listing, out, scheduler=scheduler)
    assert (result.total, result.done, result.skipped, len(result.failed), result.timed_out) == (13, 10, 0, 3, [])
    records = {r["video"]: r for r in lines(out)}
    assert len(records) == len(lines(out)) == 13
    import av

    for v in videos:
        r = records[v.stem]
        with av.open(str(v)) as c:
            declared = c.streams.video[0].frames
        doc = json.loads((out / f"{v.stem}.json").read_text())
        assert r["status"] == "done" and r["error"] is None and r["what"] == "track" and r["path"] == str(v)
        assert r["frames"] == len(doc["frames"]) and abs(doc["video"]["frames"] - declared) <= 2
        assert r["frames"] >= declared - 2  # a face from the first frames on
        assert 0.5 < r["mean_confidence"] <= 1 and 0 <= r["lost_frames"] <= r["frames"] and r["seconds"] > 0
        assert r["source"] == {"bytes": v.stat().st_size, "mtime_ns": v.stat().st_mtime_ns}
    assert result.frames == sum(records[v.stem]["frames"] for v in videos)
    errors = {n: records[n]["error"] for n in ("truncated", "random", "noface")}
    assert errors == {
        "truncated": f"cannot read video {broken['truncated']}: Invalid data found when processing input",
        "random": f"cannot read video {broken['random']}: Invalid data found when processing input",
        "noface": f"no face found in any of the 10 frames of {broken['noface']}; "
        "pass the contours with --init INIT.json",
    }
    assert all(records[n]["status"] == "failed" and records[n]["frames"] is None for n in errors)
    assert sorted(p.name for p in out.iterdir()) == sorted([f"{v.stem}.json" for v in videos] + ["manifest.jsonl"])


def slow_task(video: Path, results: list[Path], what: str) -> list[str]:
    """A task that never ends by itself."""
    while True:
        time.sleep(0.02)


def test_a_task_past_its_time_limit_is_stopped(tmp_path, clips, scheduler):
    (tmp_path / "in").mkdir()
    os.symlink(clips[0], tmp_path / "in" / "a.mp4")
    t0 = time.perf_counter()
    result = run_batch(
        tmp_path / "in",
        tmp_path / "out",
        scheduler=scheduler,
        timeout_per_frame=0.01,
        start_seconds=0.5,
        task=slow_task,
    )
    assert time.perf_counter() - t0 < 15
    [r] = lines(tmp_path / "out")
    assert [r["video"] for r in result.timed_out] == ["a"] and r["status"] == "timed out" and r["frames"] is None
    assert r["error"] == "stopped after 0.8 s, its limit (0.5 s + 0.01 s a frame for 30 frames)"


def crash_once(video: Path, results: list[Path], what: str) -> list[str]:
    """Ends its worker process the first time (a marker file beside the results remembers)."""
    marker = results[0].parent / f"{video.stem}.crashed"
    if not marker.exists():
        marker.write_text("1")
        os._exit(1)
    return default_task(video, results, what)


def crash_always(video: Path, results: list[Path], what: str) -> list[str]:
    with open(results[0].parent / f"{video.stem}.crashes", "a") as f:
        f.write("1")
    os._exit(1)


def test_a_worker_killed_during_a_task_is_retried(tmp_path, clips, scheduler):
    (tmp_path / "in").mkdir()
    os.symlink(clips[0], tmp_path / "in" / "a.mp4")
    result = run_batch(tmp_path / "in", tmp_path / "out", scheduler=scheduler, task=crash_once)
    assert (result.done, result.failed) == (1, [])
    assert (tmp_path / "out" / "a.crashed").exists()  # it did crash once
    [r] = lines(tmp_path / "out")
    assert r["status"] == "done" and r["frames"] == 30


def test_a_task_that_always_kills_its_worker_fails_after_its_retries(tmp_path, clips):
    (tmp_path / "in").mkdir()
    os.symlink(clips[0], tmp_path / "in" / "a.mp4")
    result = run_batch(tmp_path / "in", tmp_path / "out", jobs=1, retries=1, task=crash_always)
    [r] = lines(tmp_path / "out")
    assert [r["video"] for r in result.failed] == ["a"] and r["status"] == "failed"
    assert r["error"] == "its worker process died 2 time(s) while running it (a crash in native code, or out of memory)"
    assert (tmp_path / "out" / "a.crashes").read_text() == "11"


def test_a_rerun_redoes_only_what_is_missing_or_broken(tmp_path, clips, scheduler):
    inp, out = tmp_path / "in", tmp_path / "out"
    inp.mkdir()
    for c in clips[:3]:
        os.symlink(c, inp / c.name)
    first = run_batch(inp, out, scheduler=scheduler)
    assert first.done == 3
    stamps = {p.name: p.stat().st_mtime_ns for p in out.glob("*.json")}
    # One result cut short (as by a full disk), one gone; a new video added.
    text = (out / "vr_2.json").read_text()
    (out / "vr_2.json").write_text(text[: len(text) // 2])
    (out / "st_aoc.json").unlink()
    os.symlink(clips[3], inp / clips[3].name)
    second = run_batch(inp, out, scheduler=scheduler)
    assert (second.done, second.skipped, second.failed) == (3, 1, [])
    assert (out / "lp_d0.json").stat().st_mtime_ns == stamps["lp_d0.json"]
    assert [r["video"] for r in lines(out)][3:] != [] and sorted(r["video"] for r in lines(out)[3:]) == [
        "lp_d12",
        "st_aoc",
        "vr_2",
    ]
    assert all(r["status"] == "done" for r in Manifest(out).read().values())
    # A third run has nothing to do.
    third = run_batch(inp, out, scheduler=scheduler)
    assert (third.done, third.skipped) == (0, 4) and len(lines(out)) == 6


@pytest.mark.parametrize(("what", "files"), [("run", ["a.json", "a.run.mp4"]), ("encode", ["a.fmstream"])])
def test_run_and_encode_results_are_checked(tmp_path, clips, scheduler, what, files):
    (tmp_path / "in").mkdir()
    os.symlink(clips[0], tmp_path / "in" / "a.mp4")
    result = run_batch(tmp_path / "in", tmp_path / "out", scheduler=scheduler, what=what)
    assert result.done == 1 and sorted(p.name for p in (tmp_path / "out").iterdir()) == files + ["manifest.jsonl"]
    [r] = lines(tmp_path / "out")
    assert r["status"] == "done" and r["frames"] == 30 and r["what"] == what
    assert (r["mean_confidence"] is None) == (what == "encode")
    # Resumed: complete, so skipped; the same folder for another kind of result redoes it.
    assert run_batch(tmp_path / "in", tmp_path / "out", scheduler=scheduler, what=what).skipped == 1
    big = tmp_path / "out" / files[-1]
    big.write_bytes(big.read_bytes()[:-100])
    assert run_batch(tmp_path / "in", tmp_path / "out", scheduler=scheduler, what=what).done == 1
