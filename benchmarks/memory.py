"""Memory of the video commands: (a) the peak resident memory of reading (with a fast and a slow
caller), ``facemime track`` and ``facemime run`` on a 30-frame 3840×2160 clip; (b) a soak:
``facemime run`` on a long video (a shared video looped to ``--minutes``), its resident memory
sampled every ``--every`` seconds, with the verdict whether it grows by more than 10 % after the
first minute, its steady growth (MiB a minute, from the first minute to 90 % of the run: before
the outputs are written) and the curve drawn to a PNG; with ``--copy-soak`` the same of a copy of
the long video through VideoReader and VideoWriter alone.

The test clips are written once to ``--tmp`` (kept for the next run): the 4K clip is a shared
video's first 30 frames scaled to 2160×2160 and centred on a black 3840×2160 canvas; the long
video repeats a shared video's packets, re-timed (no re-encoding: seconds to write).

Each command runs in a process of its own under GNU ``/usr/bin/time``, whose ``%M`` (the
kernel's high-water mark of the command's resident set) is its peak; run directly from this
script, a child's high-water mark would start at this script's own.

    python benchmarks/memory.py [--data ../shared/data] [--tmp /tmp/facemime-memory] \\
        [--minutes 30] [--every 10] [--no-peak] [--no-soak] [--copy-soak]

The last line of output is one JSON object (memory in MiB, times in seconds).
"""

from __future__ import annotations

import argparse
import contextlib
import json
import math
import subprocess
import sys
import time
from pathlib import Path

import av
import cv2
import numpy as np

ROOT = Path(__file__).resolve().parents[1]
MIB = 1024 * 1024
TIME = "/usr/bin/time"  # GNU time: -f %M is the peak resident memory, KiB

#: Read the video ``argv[1]`` (none: "-"), spending ``argv[2]`` seconds on each frame (a slow
#: caller: the decoder's queue fills).
READ = """import sys, time
from facemime.io.video import VideoReader
if sys.argv[1] != "-":
    with VideoReader(sys.argv[1]) as reader:
        for frame in reader:
            time.sleep(float(sys.argv[2]))
"""


#: Copy the video ``argv[1]`` to ``argv[2]`` through VideoReader and VideoWriter: the soak of the video
#: input and output alone.
COPY = """import sys
from facemime.io.video import VideoReader, VideoWriter
with VideoReader(sys.argv[1]) as reader, VideoWriter(sys.argv[2], reader.fps) as writer:
    for frame in reader:
        writer.write(frame)
"""
SOAKS = {"run": "facemime run", "copy": "VideoReader -> VideoWriter"}


def make_4k(source: Path, path: Path, frames: int = 30) -> None:
    """``source``'s first ``frames`` frames scaled to 2160×2160 on a black 3840×2160 canvas."""
    if path.exists():
        return
    canvas = np.zeros((2160, 3840, 3), np.uint8)
    with av.open(str(source)) as src, av.open(str(path), "w") as out:
        stream = src.streams.video[0]
        enc = out.add_stream("libx264", rate=stream.average_rate)
        enc.width, enc.height, enc.pix_fmt = 3840, 2160, "yuv420p"
        enc.options = {"crf": "20", "preset": "ultrafast"}
        for _, frame in zip(range(frames), src.decode(stream)):
            canvas[:, 840:3000] = cv2.resize(
                frame.to_ndarray(format="rgb24"), (2160, 2160), interpolation=cv2.INTER_CUBIC
            )
            out.mux(enc.encode(av.VideoFrame.from_ndarray(canvas, format="rgb24")))
        out.mux(enc.encode())


def make_long(source: Path, path: Path, minutes: float) -> int:
    """``source`` looped to ``minutes`` by copying its packets with shifted timestamps; returns
    the frame count."""
    with av.open(str(source)) as src:
        stream = src.streams.video[0]
        packets = [p for p in src.demux(stream) if p.size]
        tick = stream.time_base
        step = max(p.pts + p.duration for p in packets) - min(p.pts for p in packets)  # one loop, in ticks
        loops = max(1, round(minutes * 60 / float(step * tick)))
        if path.exists():
            return loops * len(packets)
        with av.open(str(path), "w") as out:
            copy = out.add_stream_from_template(stream)
            for loop in range(loops):
                for p in packets:
                    q = av.Packet(bytes(p))
                    q.pts, q.dts, q.duration, q.time_base = p.pts + loop * step, p.dts + loop * step, p.duration, tick
                    q.is_keyframe = p.is_keyframe
                    q.stream = copy
                    out.mux(q)
    return loops * len(packets)


def start(args: list[str], log: Path) -> subprocess.Popen:
    """Start ``args`` under ``/usr/bin/time``, which writes its peak resident memory to ``log``
    with the suffix ``.maxrss``, and with its output to ``log`` (a pipe would fill and stop it)."""
    with open(log, "wb") as f:
        return subprocess.Popen(
            [TIME, "-f", "%M", "-o", str(log.with_suffix(".maxrss"))] + args, stdout=f, stderr=subprocess.STDOUT
        )


def finish(proc: subprocess.Popen, log: Path) -> float:
    """Wait for ``proc``; returns its peak resident memory in MiB, or exits with its output."""
    if proc.wait():
        sys.exit(f"{' '.join(proc.args)} failed:\n{log.read_text(errors='replace')[-4000:]}")
    return int(log.with_suffix(".maxrss").read_text().split()[-1]) * 1024 / MIB


def peak(args: list[str], log: Path) -> tuple[float, float]:
    """Run ``args``; returns (peak resident memory in MiB, seconds)."""
    t0 = time.perf_counter()
    return finish(start(args, log), log), time.perf_counter() - t0


def rss(pid: int) -> float | None:
    """The resident memory (MiB) now of the child that ``/usr/bin/time`` (``pid``) runs; None
    when there is none."""
    try:
        child = Path(f"/proc/{pid}/task/{pid}/children").read_text().split()[0]
        with open(f"/proc/{child}/status") as f:
            return next(int(line.split()[1]) * 1024 / MIB for line in f if line.startswith("VmRSS:"))
    except (OSError, IndexError, StopIteration):
        return None


def soak(args: list[str], log: Path, every: float) -> tuple[list[tuple[float, float]], float, float]:
    """Run ``args``, its resident memory sampled every ``every`` seconds; returns
    ([(seconds, MiB)], peak MiB, seconds)."""
    t0 = time.perf_counter()
    proc = start(args, log)
    samples = []
    while proc.poll() is None:
        if (mib := rss(proc.pid)) is not None:
            samples.append((time.perf_counter() - t0, mib))
        with contextlib.suppress(subprocess.TimeoutExpired):
            proc.wait(timeout=every)
    return samples, finish(proc, log), time.perf_counter() - t0


def growth(samples: list[tuple[float, float]], after: float = 60.0) -> tuple[float, float, float, float]:
    """(MiB at the first sample from ``after`` seconds, the most after it, the growth as a fraction,
    the steady growth in MiB a minute: the slope from ``after`` to 90 % of the run, before the
    outputs are written)."""
    later = [(t, m) for t, m in samples if t >= after] or samples[-1:]
    steady = [(t, m) for t, m in later if t <= 0.9 * samples[-1][0]]
    slope = 60 * float(np.polyfit(*np.array(steady).T, 1)[0]) if len(steady) > 2 else 0.0
    first, most = later[0][1], max(m for _, m in later)
    return first, most, most / first - 1, slope


def plot(samples: list[tuple[float, float]], path: Path, title: str, limit: float) -> None:
    """Draw resident memory (MiB) over time (minutes) to a PNG with OpenCV, with the ``limit``
    (MiB, red) from the first minute on."""
    w, h, left, bottom, top, right = 900, 500, 80, 50, 40, 20
    img = np.full((h, w, 3), 255, np.uint8)
    t = np.array([s[0] for s in samples]) / 60
    m = np.array([s[1] for s in samples])
    t_step, m_step = _step(t.max()), _step(max(m.max(), limit))
    t_max, m_max = t_step * math.ceil(t.max() / t_step), m_step * (math.floor(max(m.max(), limit) / m_step) + 1)
    px = lambda x: int(left + x / t_max * (w - left - right))  # noqa: E731
    py = lambda y: int(h - bottom - y / m_max * (h - bottom - top))  # noqa: E731
    font, grey, black = cv2.FONT_HERSHEY_SIMPLEX, (200, 200, 200), (0, 0, 0)
    for y in np.arange(0, m_max + m_step / 2, m_step):
        cv2.line(img, (left, py(y)), (w - right, py(y)), grey, 1)
        cv2.putText(img, f"{y:g}", (5, py(y) + 5), font, 0.45, black, 1, cv2.LINE_AA)
    for x in np.arange(0, t_max + t_step / 2, t_step):
        cv2.line(img, (px(x), top), (px(x), h - bottom), grey, 1)
        cv2.putText(img, f"{x:g}", (px(x) - 8, h - bottom + 20), font, 0.45, black, 1, cv2.LINE_AA)
    cv2.rectangle(img, (left, top), (w - right, h - bottom), black, 1)
    if t_max > 1:
        cv2.line(img, (px(1), py(limit)), (px(t_max), py(limit)), (0, 0, 220), 1, cv2.LINE_AA)
        cv2.putText(img, "+10% of 1 min", (px(1) + 6, py(limit) - 6), font, 0.45, (0, 0, 220), 1, cv2.LINE_AA)
    cv2.polylines(
        img,
        [np.stack([[px(a) for a in t], [py(b) for b in m]], 1).astype(np.int32)],
        False,
        (200, 80, 0),
        2,
        cv2.LINE_AA,
    )
    cv2.putText(img, title, (left, 25), font, 0.55, black, 1, cv2.LINE_AA)
    cv2.putText(img, "minutes", (w // 2 - 30, h - 8), font, 0.5, black, 1, cv2.LINE_AA)
    cv2.putText(img, "MiB", (5, top - 10), font, 0.5, black, 1, cv2.LINE_AA)
    cv2.imwrite(str(path), img)


def _step(top: float) -> float:
    """A round axis step (1, 2 or 5 times a power of ten) that divides 0..``top`` in 4 to 10."""
    power = 10.0 ** math.floor(math.log10(max(top, 1e-9) / 4))
    return next(power * k for k in (1, 2, 5, 10) if top / (power * k) <= 10)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--data", type=Path, default=ROOT.parent / "shared" / "data")
    ap.add_argument("--tmp", type=Path, default=Path("/tmp/facemime-memory"))
    ap.add_argument("--video", default="lp_d0", help="the shared video the clips are made of")
    ap.add_argument("--minutes", type=float, default=30.0, help="length of the soak's video")
    ap.add_argument("--every", type=float, default=10.0, help="seconds between memory samples")
    ap.add_argument("--no-peak", action="store_true", help="skip the 4K peak measurements")
    ap.add_argument("--no-soak", action="store_true", help="skip the soak")
    ap.add_argument(
        "--copy-soak",
        action="store_true",
        help="also soak a copy of the long video through VideoReader and VideoWriter alone",
    )
    a = ap.parse_args()
    a.tmp.mkdir(parents=True, exist_ok=True)
    source = a.data / "video" / f"{a.video}.mp4"
    py, report = sys.executable, {}
    if not a.no_peak:
        clip = a.tmp / "4k.mp4"
        make_4k(source, clip)
        cli = [py, "-m", "facemime"]
        runs = {
            "python_and_reader_imports": [py, "-c", READ, "-"],
            "read": [py, "-c", READ, str(clip), "0"],
            "read_slow_caller": [py, "-c", READ, str(clip), "0.1"],
            "track": cli + ["track", str(clip), "--out", str(a.tmp / "4k.track.json"), "--force"],
            "run": cli + ["run", str(clip), "--out", str(a.tmp / "4k.run.mp4"), "--force"],
        }
        for name, args in runs.items():
            mib, seconds = peak(args, a.tmp / f"{name}.log")
            report[f"peak_{name}_mib"] = round(mib, 1)
            print(f"{name:>26}: peak {mib:7.1f} MiB in {seconds:5.1f} s", flush=True)
    if not a.no_soak:
        long = a.tmp / f"{a.video}-{a.minutes:g}min.mp4"
        frames = make_long(source, long, a.minutes)
        soaks = {"run": [py, "-m", "facemime", "run", str(long), "--out", str(a.tmp / "soak.mp4"), "--force"]}
        if a.copy_soak:
            soaks["copy"] = [py, "-c", COPY, str(long), str(a.tmp / "soak_copy.mp4")]
        for kind, args in soaks.items():
            print(f"soak ({kind}): {long} ({frames} frames), memory every {a.every:g} s", flush=True)
            samples, top, seconds = soak(args, a.tmp / f"soak_{kind}.log", a.every)
            first, most, grew, slope = growth(samples)
            png = a.tmp / f"soak_{kind}_rss.png"
            plot(
                samples, png, f"{SOAKS[kind]}, {a.minutes:g} min video ({frames} frames): resident memory", 1.1 * first
            )
            (a.tmp / f"soak_{kind}_rss.json").write_text(json.dumps(samples))
            print(
                f"soak ({kind}): {seconds:.0f} s, {frames / seconds:.1f} frames/s; RSS {first:.0f} MiB at 1 min, "
                f"at most {most:.0f} MiB after ({100 * grew:+.1f} %), {samples[-1][1]:.0f} MiB at the end, "
                f"peak {top:.0f} MiB; steady growth {slope:.1f} MiB/min ({slope / 60 * MIB / (frames / seconds):.0f} "
                f"bytes a frame); {'GROWS' if grew > 0.10 else 'flat'}; plot {png}",
                flush=True,
            )
            report[f"soak_{kind}"] = {
                "minutes": a.minutes,
                "frames": frames,
                "seconds": round(seconds, 1),
                "rss_at_1min_mib": round(first, 1),
                "rss_max_after_1min_mib": round(most, 1),
                "rss_end_mib": round(samples[-1][1], 1),
                "peak_mib": round(top, 1),
                "growth": round(grew, 4),
                "grows": grew > 0.10,
                "steady_mib_per_min": round(slope, 2),
                "png": str(png),
            }
    print(json.dumps(report))


if __name__ == "__main__":
    main()
