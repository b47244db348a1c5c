"""``facemime encode``, ``decode`` and ``call``: the commands of the bitstream."""

from __future__ import annotations

import sys
from pathlib import Path

import click

from facemime.cli.app import actor_option, cli, force_option, mask_only_option, out_option


@cli.command()
@click.argument("video", metavar="VIDEO_OR_TRACK", type=click.Path(path_type=Path))
@actor_option(
    "NAME.actor of this person that the receiver already holds: the stream names it instead of "
    "carrying it (default: fit one on the first frame, or for a track file the generic head, "
    "and carry it)."
)
@click.option("--quality", type=click.IntRange(0, 10), help="0 (coarsest) to 10 (finest); default 5, under 2 kbit/s.")
@click.option(
    "--rate", type=float, help="Target rate of the motion, kbit/s: the finest quality that fits (instead of --quality)."
)
@click.option(
    "--keyframe",
    type=float,
    default=1.0,
    show_default=True,
    help="Seconds between intra packets (where a receiver can join or recover from loss).",
)
@click.option(
    "--packet",
    type=float,
    default=0.5,
    show_default=True,
    help="Seconds of frames per packet (shorter: less delay, more bytes).",
)
@click.option("--embed-actor", is_flag=True, help="Carry the actor given with --actor in the stream too.")
@click.option(
    "--appearance",
    type=float,
    default=0.0,
    show_default=True,
    help="kbit/s for sending the face's appearance again where it changes (light, skin); 0: never.",
)
@click.option(
    "--samples/--no-samples",
    default=True,
    show_default=True,
    help="Send with the actor a library of the face's own mouth and eyes taken from VIDEO (about 30 kB once).",
)
@out_option("X.fmstream to write.")
@force_option
def encode(
    video: Path,
    actor_file: Path | None,
    quality: int | None,
    rate: float | None,
    keyframe: float,
    packet: float,
    embed_actor: bool,
    appearance: float,
    samples: bool,
    out_file: Path,
    force: bool,
) -> None:
    """Analyse the face in VIDEO and write its motion as a facemime stream: a couple of kilobits
    a second, plus the actor once. A TRACK.json (from run, or expression weights written by hand)
    is coded from its recorded motion instead, at its size and frame rate (no --appearance)."""
    from facemime.app.coding import encode_video
    from facemime.codec.stream import DEFAULT_QUALITY, Settings
    from facemime.errors import InvalidInputError

    if quality is not None and rate is not None:
        raise InvalidInputError("give --quality or --rate, not both")
    settings = Settings(quality=DEFAULT_QUALITY if quality is None else quality, keyframe=keyframe, packet=packet)
    result = encode_video(
        video, out_file, actor_file, settings, rate, True if embed_actor else None, force, appearance, samples
    )
    for w in result.warnings:
        click.echo(f"facemime: warning: {w}", err=True)
    click.echo(str(out_file))
    scene = f", its scene {result.scene_bytes} of them" if result.scene_bytes else ""
    scene += f", its mouth and eye samples {result.samples_bytes}" if result.samples_bytes else ""
    actor = (
        f"the actor {result.actor_bytes} bytes once{scene}" if result.actor_bytes else f"the actor named ({actor_file})"
    )
    updates = (
        f", appearance {result.appearance_kbit_s:.2f} kbit/s ({result.appearance_updates} updates, "
        f"{result.appearance_bytes} bytes)"
        if appearance
        else ""
    )
    click.echo(
        f"encoded {result.frames} frames at quality {result.quality}: motion {result.motion_kbit_s:.2f} kbit/s "
        f"({result.motion_bytes} bytes){updates}, header {result.header_bytes} bytes, {actor}",
        err=True,
    )


@cli.command()
@click.argument("stream", type=click.Path(path_type=Path))
@actor_option("NAME.actor the stream names, when the stream does not carry its actor.")
@out_option("Video of the synthesised picture to write (.mp4 or .webm).")
@mask_only_option
@force_option
def decode(stream: Path, actor_file: Path | None, out_file: Path, mask_only: bool, force: bool) -> None:
    """Synthesise the face of a facemime STREAM into a video, with no access to the source video."""
    from facemime.app.coding import decode_stream

    result = decode_stream(stream, out_file, actor_file, force, mask_only)
    click.echo(str(out_file))
    s = result.stats
    damage = (
        f"; {result.concealed} frames concealed ({s['lost_packets']} packets lost, {s['damaged_bytes']} bytes "
        f"damaged, {s['undecodable']} undecodable)"
        if result.concealed or s["damaged_bytes"]
        else ""
    )
    refused = f", {result.appearance_refused} refused" if result.appearance_refused else ""
    updates = (
        f", {result.appearance_updates} appearance updates{refused}"
        if result.appearance_updates or result.appearance_refused
        else ""
    )
    click.echo(f"decoded {result.frames} frames in {result.seconds:.1f} s{updates}{damage}", err=True)


@cli.command()
@click.argument("source", metavar="VIDEO_OR_CAMERA")
@actor_option("NAME.actor of this person to send (default: fit one on the first frame); the stream carries it.")
@click.option(
    "--port",
    default=8766,
    show_default=True,
    type=click.IntRange(0, 65535),
    help="Local port of the page and the stream (0: any free port).",
)
@click.option(
    "--quality",
    type=click.IntRange(0, 10),
    help="0 (coarsest) to 10 (finest) (default: the finest whose first 2 s fit --rate).",
)
@click.option(
    "--rate",
    default=2.0,
    show_default=True,
    type=float,
    help="Target rate of the motion, kbit/s, when no --quality is given.",
)
@click.option(
    "--packet",
    "packet_frames",
    default=2,
    show_default=True,
    type=click.IntRange(1, 32),
    help="Frames per packet (more: more delay, fewer bytes).",
)
@click.option("--record", type=click.Path(path_type=Path), help="X.fmstream to write the stream to, as sent.")
@force_option
@click.option("--no-browser", is_flag=True, help="Do not open a browser; print the address only.")
@click.option("--loop", is_flag=True, help="Play a video file again and again, as one continuing stream.")
def call(
    source: str,
    actor_file: Path | None,
    port: int,
    quality: int | None,
    rate: float,
    packet_frames: int,
    record: Path | None,
    force: bool,
    no_browser: bool,
    loop: bool,
) -> None:
    """Send the face in VIDEO_OR_CAMERA (a video file played at its own pace, or a camera's number
    such as 0) live, as a facemime stream, to receivers in a web browser on this machine. The
    first 2 s are analysed only (to learn the motion's basis); then the stream starts. Stops at
    the video's end, or with Ctrl-C."""
    import webbrowser

    from facemime.app.call import Call
    from facemime.io.actor_file import load_actor

    actor = load_actor(actor_file) if actor_file is not None else None
    c = Call(source, actor, port, quality, packet_frames, record, force, loop, actor_path=actor_file, rate=rate)
    try:
        click.echo(c.url)
        sys.stdout.flush()
        click.echo(
            f"sending {c.source.name} ({c.source.size[0]}x{c.source.size[1]}, {c.source.fps:g} frames/s); "
            f"the stream starts after {c.sender.warmup_frames} frames of warm-up; Ctrl-C stops",
            err=True,
        )
        if not no_browser:
            webbrowser.open(c.url)
        c.start()
        while not c.wait(0.2):
            pass
    finally:
        c.close()
        s = c.sender.stats
        delays = (
            f"; arrival to sending {1000 * sum(d[1] for d in s.delays) / len(s.delays):.1f} ms a packet "
            f"from its last frame, {1000 * max(d[0] for d in s.delays):.0f} ms at most from its first"
            if s.delays
            else ""
        )
        if s.header_bytes:  # a stream started: what it sent
            click.echo(
                f"sent {s.frames} frames ({s.warmup_frames} of warm-up not sent) at quality "
                f"{c.sender.settings.quality}: motion "
                f"{s.motion_kbit_s(c.sender.fps):.2f} kbit/s ({s.packet_bytes} bytes in {s.packets} packets), "
                f"header {s.header_bytes} bytes, actor {s.actor_bytes} bytes; {s.intra_honoured} of "
                f"{s.intra_asked} intra requests honoured; {c.hub.served} clients served{delays}",
                err=True,
            )
    if record is not None and c.sender.stats.header_bytes:
        click.echo(str(record))
