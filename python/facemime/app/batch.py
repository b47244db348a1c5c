"""Many videos at once on a Dask cluster (``facemime batch``): one task per video, results
written atomically into an output folder, a manifest of every video's outcome, resumable.

:func:`run_batch` lists the videos (:mod:`~facemime.batch.inputs`), sends one task per video to
the cluster (:mod:`~facemime.batch.cluster`); each task (:mod:`~facemime.batch.worker`) first
checks whether the video's results from an earlier batch are complete and valid, and if not
redoes them; the manifest (:mod:`~facemime.batch.manifest`) gets a line for each video that ran.
"""

from __future__ import annotations

import contextlib
import sys
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from facemime.batch.cluster import dashboard_link, open_client
from facemime.batch.inputs import Item, list_videos
from facemime.batch.manifest import RESULTS, Manifest, result_paths
from facemime.batch.worker import START_SECONDS, TIMEOUT_EVENT, Task, process
from facemime.errors import InvalidInputError
from facemime.io.outputs import OutputFileError

__all__ = ["WHAT", "BatchResult", "run_batch"]

#: What a batch can make of each video.
WHAT = tuple(RESULTS)
#: Default seconds allowed per declared frame of a video (beyond a fixed start allowance).
TIMEOUT_PER_FRAME = 2.0


@dataclass
class BatchResult:
    """The outcome of a batch: videos in it, ``done`` (this run), ``skipped`` (complete from an
    earlier run), the manifest lines of those ``failed`` and ``timed_out``, frames done this run,
    wall ``seconds``, the ``manifest`` file and the ``dashboard`` address (None without one)."""

    total: int
    done: int = 0
    skipped: int = 0
    failed: list[dict[str, Any]] = field(default_factory=list)
    timed_out: list[dict[str, Any]] = field(default_factory=list)
    frames: int = 0
    seconds: float = 0.0
    manifest: Path | None = None
    dashboard: str | None = None


def run_batch(
    source: str | Path,
    out_dir: str | Path,
    jobs: int = 2,
    scheduler: str | None = None,
    what: str = "track",
    timeout_per_frame: float | None = TIMEOUT_PER_FRAME,
    retries: int = 2,
    task: Task | None = None,
    progress: Callable[[BatchResult], None] | None = None,
    on_dashboard: Callable[[str], None] | None = None,
    start_seconds: float = START_SECONDS,
) -> BatchResult:
    """Run one command on every video of a folder or list, one Dask task per video. Videos whose
    results from an earlier batch are complete and valid are skipped; every other video gets a
    line in ``out_dir/manifest.jsonl`` (:mod:`facemime.batch.manifest`), and one that fails does
    not stop the batch.

    Parameters
    ----------
    source
        A folder (its video files and those of its subfolders) or a text file listing videos, one
        path a line (:func:`facemime.batch.inputs.list_videos`); videos inside ``out_dir`` are
        left out.
    out_dir
        The folder for the results, created if missing: per video ``NAME.json`` (track, run),
        ``NAME.run.mp4`` (run) or ``NAME.fmstream`` (encode), NAME its path relative to
        ``source`` without the suffix (for a list, its stem); and ``manifest.jsonl``.
    jobs
        Worker processes of the local cluster, one thread each (about one per core); at least 1.
        Unused with ``scheduler``.
    scheduler
        The address of a running Dask scheduler to use instead of a local cluster
        (``tcp://HOST:PORT``); None: a local cluster.
    what
        What to make of each video: ``track`` (the track JSON, as ``facemime track``), ``run``
        (also the side-by-side video, as ``facemime run``) or ``encode`` (the ``.fmstream``, as
        ``facemime encode``).
    timeout_per_frame
        Seconds allowed per frame the video's container declares, after ``start_seconds``, before
        its task is stopped and recorded as timed out (default 2 s); None: never. Must be
        positive.
    retries
        Times a video whose worker process died is tried again (local cluster; a running
        scheduler's own setting applies to it); 0 or more.
    task
        The work per video, ``task(video, results, what)`` returning warnings; None: the
        command's (:func:`default_task`). Another is for tests.
    progress
        Called with the result so far once the tasks are sent and after each video; None: not
        called.
    on_dashboard
        Called with the Dask dashboard's address, once, when there is one (bokeh installed);
        None: not called.
    start_seconds
        Seconds each task is allowed beyond its per-frame allowance (start-up: loading models,
        fitting the face; default 30).

    Returns
    -------
    BatchResult
        Videos in the batch, done, skipped, the manifest lines of those failed and timed out,
        frames done, wall seconds, the manifest file and the dashboard's address.
    """
    task = task or default_task
    if what not in WHAT:
        raise InvalidInputError(f"what must be one of {', '.join(WHAT)}, got {what!r}")
    if jobs < 1:
        raise InvalidInputError(f"jobs must be at least 1, got {jobs}")
    if timeout_per_frame is not None and not timeout_per_frame > 0:
        raise InvalidInputError(f"the time limit per frame must be positive, got {timeout_per_frame}")
    if retries < 0:
        raise InvalidInputError(f"retries must be 0 or more, got {retries}")
    out_dir = Path(out_dir)
    if out_dir.exists() and not out_dir.is_dir():
        raise InvalidInputError(f"the output {out_dir} is a file, expected a folder")
    items = [it for it in list_videos(source) if not _inside(it.path, out_dir)]
    if not items:
        raise InvalidInputError(f"no videos in {source} outside the output folder {out_dir}")
    try:
        out_dir.mkdir(parents=True, exist_ok=True)
    except OSError as e:
        raise OutputFileError(f"cannot write {out_dir}: {e.strerror or e}") from None
    manifest = Manifest(out_dir)
    previous = manifest.read()
    result = BatchResult(len(items), manifest=manifest.path)
    t0 = time.perf_counter()
    with open_client(jobs, scheduler, retries) as client:
        result.dashboard = dashboard_link(client)
        if result.dashboard and on_dashboard is not None:
            on_dashboard(result.dashboard)
        futures = {
            _submit(client, it, out_dir, what, (timeout_per_frame, start_seconds), task, previous.get(it.name)): it
            for it in items
        }
        timed_out = _watch_timeouts(client, {it.name: f for f, it in futures.items()})
        from distributed import as_completed

        if progress is not None:
            progress(result)
        for future in as_completed(futures):
            record = _record(future, futures[future], what, timed_out, retries)
            if record.pop("skipped", False):
                result.skipped += 1
            else:
                manifest.append(record)
                if record["status"] == "done":
                    result.done += 1
                    result.frames += record["frames"]
                else:
                    (result.timed_out if record["status"] == "timed out" else result.failed).append(record)
            result.seconds = time.perf_counter() - t0
            if progress is not None:
                progress(result)
            future.release()
    result.seconds = time.perf_counter() - t0
    return result


def _inside(path: Path, folder: Path) -> bool:
    try:
        return path.resolve().is_relative_to(folder.resolve())
    except OSError:
        return False


def _submit(
    client: Any,
    item: Item,
    out_dir: Path,
    what: str,
    timeout: tuple[float | None, float],
    task: Task,
    previous: dict[str, Any] | None,
) -> Any:
    results = [str(p) for p in result_paths(out_dir, item.name, what)]
    return client.submit(
        process,
        item.name,
        str(item.path),
        results,
        what,
        timeout[0],
        task,
        previous,
        timeout[1],
        pure=False,
        key=f"facemime-{what}-{item.name}-{time.time_ns()}",
    )


def _watch_timeouts(client: Any, by_name: dict[str, Any]) -> set[str]:
    """The names of videos whose worker was ended for their time limit (a task stuck in native
    code), filled as the workers report them; their tasks are cancelled, not retried."""
    names: set[str] = set()
    lock = threading.Lock()

    def handler(event: tuple[float, Any]) -> None:
        msg = event[1] if isinstance(event, tuple) and len(event) == 2 else event
        name = msg.get("video") if isinstance(msg, dict) else None
        if name in by_name:
            with lock:
                names.add(name)
            by_name[name].cancel()

    # An older scheduler lacks the topic: time limits of native code then go unreported.
    with contextlib.suppress(Exception):
        client.subscribe_topic(TIMEOUT_EVENT, handler)
    return names


def _record(future: Any, item: Item, what: str, timed_out: set[str], retries: int) -> dict[str, Any]:
    """The manifest line of a finished future: its result, or the line for a task that did not
    return (its worker ended for the time limit, or died ``retries`` + 1 times)."""
    from facemime.batch.manifest import source_stamp

    base = {
        "video": item.name,
        "path": str(item.path),
        "what": what,
        "source": source_stamp(item.path),
        "frames": None,
        "seconds": None,
    }
    if item.name in timed_out:
        return {
            **base,
            "status": "timed out",
            "error": "stopped for its time limit (its worker was ended: stuck outside Python)",
        }
    if future.status == "finished":
        return future.result()
    if future.status == "cancelled":
        return {**base, "status": "failed", "error": "cancelled"}
    e = future.exception()
    if type(e).__name__ == "KilledWorker":
        return {
            **base,
            "status": "failed",
            "error": f"its worker process died {retries + 1} time(s) while running "
            "it (a crash in native code, or out of memory)",
        }
    return {**base, "status": "failed", "error": " ".join(f"{type(e).__name__}: {e}".split())}


def print_progress() -> tuple[Callable[[BatchResult], None], Callable[[], None]]:
    """A progress display for :func:`run_batch` on stderr (when it is a terminal; else it shows
    nothing): videos done, frames/s overall and failures, time left.

    Returns
    -------
    update : callable
        ``update(result)``, the ``progress`` argument of :func:`run_batch`; starts the display on
        its first call.
    stop : callable
        ``stop()`` ends the display (call it when the batch ends, also on an error).
    """
    if not sys.stderr.isatty():
        return (lambda r: None), (lambda: None)
    from rich.console import Console
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeRemainingColumn

    bar = Progress(
        TextColumn("videos"),
        BarColumn(),
        MofNCompleteColumn(),
        TextColumn("{task.fields[rate]}"),
        TimeRemainingColumn(),
        console=Console(stderr=True),
        transient=True,
    )
    task_id = None

    def update(r: BatchResult) -> None:
        nonlocal task_id
        if task_id is None:
            bar.start()
            task_id = bar.add_task("videos", total=r.total, rate="")
        count = r.done + r.skipped + len(r.failed) + len(r.timed_out)
        rate = f"{r.frames / r.seconds:.0f} frames/s, {len(r.failed) + len(r.timed_out)} failed" if r.seconds else ""
        bar.update(task_id, completed=count, rate=rate)

    return update, bar.stop


def default_task(video: Path, results: list[Path], what: str) -> list[str]:
    """The work of ``facemime track``, ``run`` or ``encode`` on one video, writing over results
    left incomplete by an earlier batch.

    Parameters
    ----------
    video
        The video file.
    results
        Its result files, in the order of :func:`facemime.batch.manifest.result_paths`: the track
        JSON (track, run), then the side-by-side video (run); or the stream (encode).
    what
        ``track``, ``run`` or ``encode``.

    Returns
    -------
    list of str
        Warnings for the user, one line each.
    """
    if what == "track":
        from facemime.app.track import track_video

        return track_video(video, None, results[0], force=True).warnings
    if what == "run":
        from facemime.app.run import run_video

        return run_video(video, results[1], None, results[0], force=True).warnings
    from facemime.app.coding import encode_video

    return encode_video(video, results[0], force=True).warnings
