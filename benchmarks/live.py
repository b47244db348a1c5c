"""``facemime live`` on one core: sustained frames/s from a 640x480 source and the latency from a
frame's arrival to its OSC bundle sent (issue 66: >= 60 frames/s, <= 15 ms median).

Each shared video is made a 640x480 clip (scaled to 480 rows, centred on a grey 640-wide frame,
H.264) and sent to a VMC receiver of our own on 127.0.0.1 (a UDP socket that counts the bundles):

- **sustained**: the clip's frames as fast as they are analysed (``paced=False``), frames/s from
  the first frame's arrival to the last bundle, decoding included; beside it, in the same run,
  the analysis alone (:func:`facemime.animate.analysis.analysed`, no eye model, no ARKit solve,
  no sending): the ratio says what the blendshapes and the VMC output cost;
- **latency**: the clip played at its own frame rate (as ``facemime live`` plays a file), ms from
  each frame's due time to its bundle sent: median and 95th percentile.

The process is pinned to one CPU (``os.sched_setaffinity``), so decoding threads share it too.

    python benchmarks/live.py [--data ../shared/data] [--videos lp_d3,vr_1]

Prints a line per video and, last, one JSON line with every figure and the machine.
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")  # one core (set before numpy loads)

import argparse
import json
import platform
import socket
import tempfile
import threading
import time
from pathlib import Path

import av
import cv2
import numpy as np

from facemime.animate.analysis import analysed
from facemime.app.live import Live
from facemime.io.video import VideoReader

VIDEOS = ("lp_d0", "lp_d3", "lp_d6", "lp_d12", "mt_sun", "mt_yongen", "st_aoc", "st_kh", "vr_1", "vr_2")
ROOT = Path(__file__).resolve().parents[1]
SIZE = (640, 480)


def vga_clip(video: Path, out: Path) -> Path:
    """``video`` scaled to 480 rows (640 columns at most) and centred on a 640x480 grey frame."""
    with VideoReader(video) as reader, av.open(str(out), "w") as container:
        stream = container.add_stream("libx264", rate=round(reader.fps))
        stream.width, stream.height, stream.pix_fmt = *SIZE, "yuv420p"
        stream.options = {"crf": "18", "preset": "fast"}
        for frame in reader:
            h, w = frame.shape[:2]
            k = min(SIZE[1] / h, SIZE[0] / w)
            small = cv2.resize(frame, (round(w * k) // 2 * 2, round(h * k) // 2 * 2), interpolation=cv2.INTER_AREA)
            canvas = np.full((SIZE[1], SIZE[0], 3), 128, np.uint8)
            y, x = (SIZE[1] - small.shape[0]) // 2, (SIZE[0] - small.shape[1]) // 2
            canvas[y : y + small.shape[0], x : x + small.shape[1]] = small
            for packet in stream.encode(av.VideoFrame.from_ndarray(canvas, format="rgb24")):
                container.mux(packet)
        for packet in stream.encode():
            container.mux(packet)
    return out


class Counter:
    """A UDP receiver on 127.0.0.1 that counts datagrams."""

    def __init__(self) -> None:
        self.socket = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.socket.bind(("127.0.0.1", 0))
        self.socket.settimeout(0.2)
        self.address = f"127.0.0.1:{self.socket.getsockname()[1]}"
        self.count, self._stop = 0, threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True)
        self._thread.start()

    def _run(self) -> None:
        while not self._stop.is_set():
            try:
                self.socket.recv(65536)
                self.count += 1
            except TimeoutError:
                continue

    def close(self) -> int:
        time.sleep(0.3)
        self._stop.set()
        self._thread.join()
        self.socket.close()
        return self.count


def analysis_alone(clip: Path) -> float:
    """Frames/s of the analysis alone over the clip, decoding included."""
    with VideoReader(clip) as reader:
        t0, n = time.perf_counter(), 0
        for _ in analysed(reader, clip.name, fps=reader.fps):
            if n == 0:
                t0 = time.perf_counter()  # from the first frame analysed, as the live figure
            n += 1
    return (n - 1) / (time.perf_counter() - t0)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--data", type=Path, default=ROOT.parent / "shared" / "data")
    ap.add_argument("--videos", default=",".join(VIDEOS))
    args = ap.parse_args()
    cv2.setNumThreads(1)
    os.sched_setaffinity(0, {min(os.sched_getaffinity(0))})
    results: dict = {"machine": f"{platform.processor() or platform.machine()}, {os.cpu_count()} CPUs, one used"}
    with tempfile.TemporaryDirectory() as tmp:
        for name in args.videos.split(","):
            clip = vga_clip(args.data / "video" / f"{name}.mp4", Path(tmp) / f"{name}.mp4")
            row = {}
            for paced in (False, True):
                counter = Counter()
                with Live(str(clip), counter.address, paced=paced) as live:
                    stats = live.run()
                received = counter.close()
                key = "paced" if paced else "sustained"
                row[key] = {
                    "frames": stats.frames,
                    "received": received,
                    "fps": round(stats.fps, 1),
                    "latency_median_ms": round(stats.latency(50), 2),
                    "latency_p95_ms": round(stats.latency(95), 2),
                }
            row["analysis_alone_fps"] = round(analysis_alone(clip), 1)
            row["live_over_analysis"] = round(row["sustained"]["fps"] / row["analysis_alone_fps"], 3)
            results[name] = row
            print(name, row, flush=True)
    print(json.dumps(results))


if __name__ == "__main__":
    main()
