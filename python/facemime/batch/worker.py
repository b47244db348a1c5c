"""The task a worker runs for one video: pin the process to one thread of compute, do the work
(track, run or encode), check its results and return the video's manifest line. Every error of
the video becomes a ``failed`` line; a task that runs past its time limit is stopped and becomes
a ``timed out`` line; only a crash of the process itself (native code, out of memory) is left to
the scheduler, which retries the task on another worker."""

from __future__ import annotations

import ctypes
import os
import threading
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

from facemime.batch.manifest import is_complete, result_sizes, source_stamp, summarise
from facemime.errors import FacemimeError
from facemime.io.video import VideoReader

#: Environment variables that size the thread pools of BLAS and OpenMP libraries (read when they load).
THREAD_VARIABLES = (
    "OMP_NUM_THREADS",
    "OPENBLAS_NUM_THREADS",
    "MKL_NUM_THREADS",
    "VECLIB_MAXIMUM_THREADS",
    "NUMEXPR_NUM_THREADS",
)
#: Seconds a task may take beyond its per-frame allowance (start-up: loading models, fitting the face).
START_SECONDS = 30.0
#: Seconds a task stopped for its time limit has to end before its worker process is ended.
GRACE_SECONDS = 10.0
#: Name of the worker event that says a task's worker was ended for its time limit.
TIMEOUT_EVENT = "facemime-batch-timeout"

#: ``task(video, results, what)`` writes the results of one video (paths from
#: :func:`facemime.batch.manifest.result_paths`) and returns warnings, one line each.
Task = Callable[[Path, list[Path], str], list[str]]


class TimedOut(BaseException):
    """Raised in a task's thread when it runs past its time limit (a BaseException, so that no
    ``except Exception`` in the work keeps it)."""


def pin_threads() -> None:
    """One thread of compute in this process: the BLAS/OpenMP variables (for libraries loaded
    later), OpenCV's pool, FFmpeg's decoding threads (it would start one a core in every worker)
    and, if threadpoolctl is there, pools already loaded. Decoding still runs on a thread of its
    own beside the task (:class:`facemime.io.video.VideoReader`'s decode-ahead): one worker keeps
    about 1.5 cores busy (2 of its 6 CPU ms a frame are decoding)."""
    for name in THREAD_VARIABLES:
        os.environ[name] = "1"
    import cv2

    cv2.setNumThreads(1)
    VideoReader.DECODE_THREADS = 1
    try:
        from threadpoolctl import threadpool_limits
    except ImportError:
        return
    threadpool_limits(1)


def declared_frames(video: Path) -> int:
    """The frames a video's container declares, for its time limit.

    Parameters
    ----------
    video
        The video file.

    Returns
    -------
    int
        The frame count of its first video stream, or its duration × average frame rate where the
        container has no count; 0 when unreadable or neither is known.
    """
    import av

    try:
        with av.open(str(video)) as c:
            s = c.streams.video[0]
            if s.frames:
                return int(s.frames)
            rate = float(s.average_rate or 0)
            return int(float(s.duration * s.time_base) * rate) if s.duration and rate else 0
    except Exception:  # noqa: BLE001 (the task itself reports an unreadable file)
        return 0


def _remove_temporaries(paths: list[Path]) -> None:
    """Remove the temporary files an earlier, killed run of this video left beside its results."""
    for p in paths:
        for tmp in p.parent.glob(f".{p.stem}.*.part{p.suffix}") if p.parent.is_dir() else ():
            tmp.unlink(missing_ok=True)


def process(
    name: str,
    video: str,
    results: list[str],
    what: str,
    timeout_per_frame: float | None,
    task: Task,
    previous: dict[str, Any] | None = None,
    start_seconds: float = START_SECONDS,
) -> dict[str, Any]:
    """The manifest line (see :mod:`facemime.batch.manifest`) of one video: its earlier line when
    the results it describes are complete and valid; otherwise that of a new run of ``task``, its
    results checked. Run on a worker; pins the process to one thread (:func:`pin_threads`) and
    first removes temporary files an earlier, killed run left beside the results.

    Parameters
    ----------
    name
        The video's name (:attr:`facemime.batch.inputs.Item.name`), its line's ``video``.
    video
        Path of the video file.
    results
        Paths of its result files (:func:`facemime.batch.manifest.result_paths`).
    what
        ``track``, ``run`` or ``encode``.
    timeout_per_frame
        Seconds allowed per frame the container declares (:func:`declared_frames`), beyond
        ``start_seconds``; None: no time limit.
    task
        The work (the command's, :func:`facemime.app.batch.default_task`), called as
        ``task(Path(video), results as Paths, what)``.
    previous
        The video's last manifest line from an earlier batch; None when it has none.
    start_seconds
        Seconds allowed beyond the per-frame allowance (start-up: loading models, fitting the face).

    Returns
    -------
    dict
        ``previous`` with ``skipped`` set to True, when complete; otherwise a new line with
        ``video``, ``path``, ``what``, ``source``, ``status`` (``done``, ``failed`` or ``timed
        out``), ``error`` (one line; None when done), ``frames`` (None unless done), ``seconds``
        (wall time of this call, s) and, when done, ``mean_confidence``, ``lost_frames``,
        ``results`` and ``warnings`` (only when there were any); ``finished`` is left to
        :meth:`facemime.batch.manifest.Manifest.append`.
    """
    path, paths = Path(video), [Path(p) for p in results]
    if previous is not None and is_complete(previous, path, paths, what):
        return {**previous, "skipped": True}
    _remove_temporaries(paths)
    pin_threads()
    t0 = time.perf_counter()
    record: dict[str, Any] = {"video": name, "path": video, "what": what, "source": source_stamp(path)}
    frames = declared_frames(path) if timeout_per_frame is not None else 0
    limit = None if timeout_per_frame is None else start_seconds + timeout_per_frame * frames
    watchdog = _Watchdog(limit, name) if limit is not None else None
    try:
        warnings = task(path, paths, what)
        if watchdog is not None:
            watchdog.finish()
        record.update(status="done", **summarise(paths, what), error=None, results=result_sizes(paths))
        if warnings:
            record["warnings"] = [" ".join(str(w).split()) for w in warnings]
    except TimedOut:
        record.update(
            status="timed out",
            error=f"stopped after {limit:.1f} s, its limit ({start_seconds:g} s + "
            f"{timeout_per_frame:g} s a frame for {frames} frames)",
        )
    except FacemimeError as e:
        record.update(status="failed", error=" ".join(str(e).split()))
    except MemoryError:
        record.update(status="failed", error="out of memory")
    except Exception as e:  # noqa: BLE001 (one video's defect must not stop the batch)
        record.update(status="failed", error=" ".join(f"unexpected {type(e).__name__}: {e}".split()))
    finally:
        if watchdog is not None:
            watchdog.finish()
    record.setdefault("frames", None)
    record["seconds"] = round(time.perf_counter() - t0, 3)
    return record


class _Watchdog:
    """Raises :class:`TimedOut` in the calling thread once ``limit`` seconds pass, unless
    :meth:`finish` was called; if the thread is still busy ``GRACE_SECONDS`` later (stuck in
    native code, which a Python exception cannot interrupt), records a worker event and ends the
    worker process (the batch then records the task as timed out).

    Parameters
    ----------
    limit
        Seconds from now (wall clock) until :class:`TimedOut` is raised.
    name
        The video's name, for the watchdog thread's name and the worker event.
    """

    def __init__(self, limit: float, name: str):
        self._target = threading.get_ident()
        self._lock = threading.Lock()
        self._done = threading.Event()
        self._fired = False
        self._name = name
        threading.Thread(target=self._watch, args=(limit,), daemon=True, name=f"watchdog {name}").start()

    def _watch(self, limit: float) -> None:
        if self._done.wait(limit):
            return
        with self._lock:
            if self._done.is_set():
                return
            self._fired = True
            ctypes.pythonapi.PyThreadState_SetAsyncExc(ctypes.c_ulong(self._target), ctypes.py_object(TimedOut))
        if self._done.wait(GRACE_SECONDS):
            return
        try:
            from distributed import get_worker

            get_worker().log_event(TIMEOUT_EVENT, {"video": self._name, "limit": limit})
            time.sleep(0.5)  # the event's way to the scheduler
        except Exception:  # noqa: BLE001 (not in a worker: end the process all the same)
            pass
        os._exit(3)

    def finish(self) -> None:
        """The task ended: no exception is raised after this returns."""
        with self._lock:
            if self._done.is_set():
                return
            self._done.set()
            if self._fired:  # raised but maybe not yet delivered: take it back
                ctypes.pythonapi.PyThreadState_SetAsyncExc(ctypes.c_ulong(self._target), None)
