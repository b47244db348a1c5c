"""Fixtures of the batch tests: short clips of the shared videos, three broken files, and one
local Dask cluster (two single-threaded workers) shared by the tests that need no cluster of
their own."""

from __future__ import annotations

import logging
from pathlib import Path

import av
import numpy as np
import pytest

from facemime.io.video import VideoWriter


def cut(source: Path, frames: int, path: Path) -> Path:
    """The first ``frames`` frames of ``source``, written (H.264, 25 frames/s) to ``path``."""
    with av.open(str(source)) as c, VideoWriter(path, fps=25) as w:
        for _, frame in zip(range(frames), c.decode(video=0)):
            w.write(frame.to_ndarray(format="rgb24"))
    return path


@pytest.fixture(scope="session")
def broken(shared, tmp_path_factory) -> dict[str, Path]:
    """A truncated MP4 (its first third: no index), random bytes named .mp4, a faceless video
    (ten flat grey frames)."""
    folder = tmp_path_factory.mktemp("broken")
    data = (shared / "video" / "lp_d12.mp4").read_bytes()
    (folder / "truncated.mp4").write_bytes(data[: len(data) // 3])
    (folder / "random.mp4").write_bytes(np.random.default_rng(0).bytes(50_000))
    with VideoWriter(folder / "noface.mp4", 25) as w:
        for _ in range(10):
            w.write(np.full((64, 64, 3), 128, np.uint8))
    return {p.stem: p for p in folder.iterdir()}


@pytest.fixture(scope="session")
def clips(shared, tmp_path_factory) -> list[Path]:
    """Four short clips (30-45 frames) of four shared videos."""
    folder = tmp_path_factory.mktemp("clips")
    return [
        cut(shared / "video" / f"{name}.mp4", n, folder / f"{name}.mp4")
        for name, n in (("lp_d0", 30), ("vr_2", 35), ("st_aoc", 40), ("lp_d12", 45))
    ]


@pytest.fixture(scope="module")
def scheduler() -> str:
    """The address of a local cluster of two worker processes, one thread each."""
    from distributed import LocalCluster

    with LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0", silence_logs=logging.ERROR
    ) as cluster:
        yield cluster.scheduler_address
