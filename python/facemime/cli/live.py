"""``facemime live``: the face's motion to avatar software over VMC, as it happens."""

from __future__ import annotations

import sys
import time

import click

from facemime.cli.app import cli

#: Seconds between status lines where stderr is not a terminal (a terminal's is redrawn each second).
LOG_EVERY = 10.0


@cli.command()
@click.argument("source", metavar="VIDEO_OR_CAMERA")
@click.option(
    "--vmc",
    default="127.0.0.1:39539",
    show_default=True,
    metavar="HOST:PORT",
    help="The VMC receiver (VSeeFace, Warudo, VNyan, EVMC4U...): 39539 is their usual port.",
)
@click.option("--loop", is_flag=True, help="Play a video file again and again.")
def live(source: str, vmc: str, loop: bool) -> None:
    """Send the face in VIDEO_OR_CAMERA (a video file played at its own pace, or a camera's number
    such as 0) live to avatar software over the VMC protocol: the head's rotation and ARKit's 52
    blendshapes every frame (docs/live.md). Stops at the video's end, or with Ctrl-C."""
    from facemime.app.live import Live, LiveStats

    tty = sys.stderr.isatty()
    shown = [time.monotonic()]

    def status(s: LiveStats) -> str:
        return (
            f"{s.frames} frames, {s.fps:.1f} frames/s, latency {s.latency(50, 100):.1f} ms median "
            f"(last 100), face found in {s.face_frames}"
        )

    def report(s: LiveStats) -> None:
        now = time.monotonic()
        if now - shown[0] >= (1.0 if tty else LOG_EVERY):
            shown[0] = now
            click.echo(("\r" if tty else "") + "live: " + status(s), err=True, nl=not tty)

    with Live(source, vmc, loop) as session:
        click.echo(
            f"sending {session.source.name} ({session.source.size[0]}x{session.source.size[1]}, "
            f"{session.source.fps:g} frames/s) to {session.sender.address} over VMC; Ctrl-C stops",
            err=True,
        )
        try:
            s = session.run(report)
        finally:
            if tty:
                click.echo("", err=True)
        click.echo(
            f"sent {s.frames} frames in {s.seconds:.1f} s ({s.fps:.1f} frames/s), latency "
            f"{s.latency(50):.1f} ms median, {s.latency(95):.1f} ms at the 95th percentile; "
            f"face found in {s.face_frames}",
            err=True,
        )
