"""``facemime batch``: many videos on a Dask cluster."""

from __future__ import annotations

import sys
from pathlib import Path

import click

from facemime.cli.app import ExitStatus, cli


@cli.command()
@click.argument("source", metavar="INPUT_DIR_OR_LIST", type=click.Path(path_type=Path))
@click.option(
    "--out",
    "out_dir",
    type=click.Path(path_type=Path),
    required=True,
    help="Folder for the results (NAME.json, and NAME.run.mp4 or NAME.fmstream) and manifest.jsonl.",
)
@click.option(
    "--jobs",
    default=2,
    show_default=True,
    type=click.IntRange(1, 1024),
    help="Worker processes of the local cluster, one thread each (about one per core).",
)
@click.option("--scheduler", help="Address of a running Dask scheduler to use instead (tcp://HOST:PORT).")
@click.option(
    "--what",
    type=click.Choice(["track", "run", "encode"]),
    default="track",
    show_default=True,
    help="What to make of each video: the track JSON; also the side-by-side video; the .fmstream.",
)
@click.option(
    "--timeout-per-frame",
    type=float,
    default=2.0,
    show_default=True,
    help="Seconds allowed per frame of a video (after 30 s to start) before its task is stopped.",
)
@click.option(
    "--retries",
    default=2,
    show_default=True,
    type=click.IntRange(0, 100),
    help="Times a video whose worker process died is tried again (local cluster).",
)
def batch(
    source: Path, out_dir: Path, jobs: int, scheduler: str | None, what: str, timeout_per_frame: float, retries: int
) -> None:
    """Run track, run or encode on every video of a folder (and its subfolders) or listed in a
    text file (one path a line), on a Dask cluster: a local one by default, or an existing one
    (--scheduler). A rerun skips the videos whose results are complete and redoes the rest; a
    video that fails is recorded in OUT/manifest.jsonl and the batch goes on. Exit status 3 when
    some videos failed or timed out."""
    from facemime.app.batch import print_progress, run_batch

    update, stop = print_progress()
    try:
        result = run_batch(
            source,
            out_dir,
            jobs,
            scheduler,
            what,
            timeout_per_frame,
            retries,
            progress=update,
            on_dashboard=lambda link: click.echo(f"dashboard: {link}", err=True),
        )
    finally:
        stop()
    click.echo(str(result.manifest))
    for r in result.failed + result.timed_out:
        click.echo(f"facemime: warning: {r['video']} {r['status']}: {r['error']}", err=True)
    rate = f" ({result.frames / result.seconds:.0f} frames/s)" if result.seconds > 0 else ""
    skipped = f", {result.skipped} complete from before" if result.skipped else ""
    click.echo(
        f"batch of {result.total} videos: {result.done} done{skipped}, {len(result.failed)} failed, "
        f"{len(result.timed_out)} timed out; {result.frames} frames in {result.seconds:.1f} s{rate}",
        err=True,
    )
    if result.failed or result.timed_out:
        sys.exit(ExitStatus.SOME_FAILED)
