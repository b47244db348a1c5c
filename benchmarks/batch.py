"""``facemime batch`` on this machine: the speed-up of two workers over one on the shared videos,
and (``--simulate``) the Dask scheduler's overhead per task, from many small synthetic tasks.

    python benchmarks/batch.py [--rounds 2]            # speed-up, 1 vs 2 workers, same run
    python benchmarks/batch.py --simulate [--tasks 2000 --task-ms 5 --per-frame-ms 4.6]

Speed-up: ``facemime track``'s work (:func:`facemime.app.batch.run_batch`, ``what="track"``) on the
ten shared videos, on a local cluster of 1 then 2 single-threaded workers (started and warmed up
before the clock starts: the cluster's start is a fixed cost, not the per-video rate), rounds
alternating; reported as frames/s and the ratio of the medians. Beside it: the CPU time of
decoding alone (the reader's decode-ahead thread runs beside each task), which bounds it.

Simulation: ``--tasks`` tasks that each compute for ``--task-ms`` ms, submitted at once to a
local cluster of 2 workers and gathered as ``run_batch`` does (one manifest line appended and
fsynced per task); the overhead per task is (wall × workers - tasks × task time) / tasks,
compared with the work of a 10-second video (250 frames × ``--per-frame-ms``, the per-frame
cost measured by the speed-up run on one worker).
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import resource
import statistics
import tempfile
import time
from pathlib import Path

SHARED = Path(__file__).resolve().parents[2] / "shared" / "data" / "video"


def machine() -> str:
    load = os.getloadavg()
    return (
        f"{platform.machine()}, {os.cpu_count()} cores, Python {platform.python_version()}, "
        f"load average {load[0]:.1f} at the start (a shared VM)"
    )


def cluster(workers: int):
    """A local cluster as ``facemime batch`` starts it (one thread a worker, pools pinned to one)."""
    from facemime.batch.cluster import local_cluster

    return local_cluster(workers)


def warm(client) -> None:
    """Import the tracker in every worker (as the first task would) before timing."""

    def load() -> None:
        pass

    client.run(load)


def cpu_seconds(client) -> float:
    """CPU seconds (user + system, all threads) the workers' processes have used so far."""

    def used() -> float:
        r = resource.getrusage(resource.RUSAGE_SELF)
        return r.ru_utime + r.ru_stime

    return sum(client.run(used).values())


def batch_once(videos: list[Path], workers: int) -> tuple[float, int, float]:
    """Seconds, frames and the workers' CPU seconds of one batch of ``videos`` on a fresh,
    warmed-up cluster."""
    from distributed import Client

    from facemime.app.batch import run_batch

    with tempfile.TemporaryDirectory() as tmp, cluster(workers) as c, Client(c) as client:
        warm(client)
        cpu = cpu_seconds(client)
        listing = Path(tmp) / "videos.txt"
        listing.write_text("\n".join(map(str, videos)) + "\n")
        t0 = time.perf_counter()
        result = run_batch(listing, Path(tmp) / "out", scheduler=c.scheduler_address)
        seconds = time.perf_counter() - t0
        assert result.done == len(videos), result.failed
        return seconds, result.frames, cpu_seconds(client) - cpu


def decode_seconds(videos: list[Path]) -> tuple[float, int]:
    """CPU seconds of decoding ``videos`` to RGB alone (as the reader's thread does), and frames."""
    from facemime.io.video import VideoReader

    r0, frames = resource.getrusage(resource.RUSAGE_SELF), 0
    for v in videos:
        with VideoReader(v) as reader:
            frames += sum(1 for _ in reader)
    r1 = resource.getrusage(resource.RUSAGE_SELF)
    return r1.ru_utime + r1.ru_stime - r0.ru_utime - r0.ru_stime, frames


def speedup(rounds: int) -> dict:
    videos = sorted(SHARED.glob("*.mp4"))
    times: dict[int, list[float]] = {1: [], 2: []}
    cpus: dict[int, list[float]] = {1: [], 2: []}
    frames = 0
    for _ in range(rounds):
        for workers in (1, 2):
            seconds, frames, cpu = batch_once(videos, workers)
            times[workers].append(seconds)
            cpus[workers].append(cpu)
            print(
                f"  {workers} worker(s): {seconds:.2f} s, {frames / seconds:.0f} frames/s, workers' CPU {cpu:.1f} s "
                f"({cpu / seconds:.2f} cores busy)",
                flush=True,
            )
    one, two = statistics.median(times[1]), statistics.median(times[2])
    decode, decoded = decode_seconds(videos)
    return {
        "videos": len(videos),
        "frames": frames,
        "seconds_1": times[1],
        "seconds_2": times[2],
        "frames_per_s_1": frames / one,
        "frames_per_s_2": frames / two,
        "speedup": one / two,
        "per_frame_ms_1": 1000 * one / frames,
        "cpu_ms_per_frame_1": 1000 * statistics.median(cpus[1]) / frames,
        "cpu_ms_per_frame_2": 1000 * statistics.median(cpus[2]) / frames,
        "cores_busy_1": statistics.median(c / s for c, s in zip(cpus[1], times[1])),
        "cores_busy_2": statistics.median(c / s for c, s in zip(cpus[2], times[2])),
        "decode_cpu_ms_per_frame": 1000 * decode / decoded,
        "video_minutes": sum(_duration(v) for v in videos) / 60,
    }


def _duration(video: Path) -> float:
    import av

    with av.open(str(video)) as c:
        s = c.streams.video[0]
        return float(s.frames / s.average_rate)


def spin(seconds: float) -> float:
    """Compute (not sleep) for ``seconds``."""
    end = time.perf_counter() + seconds
    n = 0
    while time.perf_counter() < end:
        n += 1
    return seconds


def simulate(tasks: int, task_ms: float, per_frame_ms: float, workers: int = 2) -> dict:
    from distributed import Client, as_completed

    from facemime.batch.manifest import Manifest

    with tempfile.TemporaryDirectory() as tmp, cluster(workers) as c, Client(c) as client:
        client.submit(spin, 0.0).result()
        manifest = Manifest(Path(tmp))
        t0 = time.perf_counter()
        futures = [client.submit(spin, task_ms / 1000, pure=False) for _ in range(tasks)]
        for i, f in enumerate(as_completed(futures)):
            f.result()
            manifest.append({"video": f"v{i}", "status": "done"})
            f.release()
        wall = time.perf_counter() - t0
    overhead = (wall * workers - tasks * task_ms / 1000) / tasks
    video10 = 250 * per_frame_ms / 1000
    return {
        "tasks": tasks,
        "task_ms": task_ms,
        "workers": workers,
        "wall_s": wall,
        "overhead_ms_per_task": 1000 * overhead,
        "work_10s_video_s": video10,
        "overhead_share_of_10s_video": overhead / video10,
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--rounds", type=int, default=2, help="rounds of 1 and 2 workers (alternating)")
    parser.add_argument("--simulate", action="store_true", help="measure the scheduler's overhead per task instead")
    parser.add_argument("--tasks", type=int, default=2000)
    parser.add_argument("--task-ms", type=float, default=5.0, help="compute per simulated task, ms")
    parser.add_argument(
        "--per-frame-ms",
        type=float,
        default=4.6,
        help="one worker's wall ms per frame (from the speed-up run) for the 10 s video's work",
    )
    args = parser.parse_args()
    print(machine(), flush=True)
    if args.simulate:
        r = simulate(args.tasks, args.task_ms, args.per_frame_ms)
        print(json.dumps(r, indent=1))
        print(
            f"scheduler overhead {r['overhead_ms_per_task']:.2f} ms per task = "
            f"{100 * r['overhead_share_of_10s_video']:.2f}% of a 10 s video's work "
            f"({r['work_10s_video_s']:.2f} s on one worker)"
        )
        return
    r = speedup(args.rounds)
    print(json.dumps(r, indent=1))
    print(
        f"speed-up 2 workers over 1: {r['speedup']:.2f}x ({r['frames_per_s_2']:.0f} vs {r['frames_per_s_1']:.0f} "
        f"frames/s; decoding alone {r['decode_cpu_ms_per_frame']:.2f} CPU ms a frame of the "
        f"{r['per_frame_ms_1']:.2f} ms wall a frame on one worker)"
    )


if __name__ == "__main__":
    main()
