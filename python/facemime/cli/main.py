"""The ``facemime`` command line. Errors a user can cause print one line,
``facemime: error: <message>``, on stderr and exit with status 1; ``--traceback`` shows the
Python trace instead. Data goes to stdout, progress to stderr."""

from __future__ import annotations

import signal
import sys
import threading
import time
from pathlib import Path

import click

from facemime import __version__
from facemime.errors import FacemimeError


@click.group(context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(__version__, prog_name="facemime")
@click.option("--traceback", is_flag=True, help="Show the Python traceback of an error.")
@click.pass_context
def cli(ctx: click.Context, traceback: bool) -> None:
    """Track mouth and eyebrow motion with dynamic contours and re-synthesise it on a textured
    3D head model."""
    ctx.obj = {"traceback": traceback}


@cli.command()
@click.option(
    "--out",
    "out_dir",
    type=click.Path(path_type=Path),
    default=Path("facemime-demo"),
    show_default=True,
    help="Folder for the demo's files.",
)
@click.option("--force", is_flag=True, help="Overwrite files from an earlier run.")
def demo(out_dir: Path, force: bool) -> None:
    """Run the main job on built-in data: fit the astronaut photo, animate her with a scripted
    performance, track it back and re-synthesise it on her and on a second face; write the videos
    and report.html."""
    from facemime.demo import run_demo

    result = run_demo(out_dir, force)
    for f in result.files:
        click.echo(str(f))
    errors = ", ".join(f"{g.replace('_', ' ')} {v:.3f}" for g, v in result.nme.items())
    click.echo(f"tracked {result.frames} frames back: mean NME {errors}; open {result.files[-1]}", err=True)


@cli.command("model-preview")
@click.argument("model", required=False, type=click.Path(path_type=Path))
@click.option("--out", "out_file", type=click.Path(path_type=Path), required=True, help="PNG to write.")
@click.option("--force", is_flag=True, help="Overwrite the output file.")
def model_preview(model: Path | None, out_file: Path, force: bool) -> None:
    """Render a head model (facemime .json or CANDIDE .wfm; default: the built-in head) from
    five angles, textured, shaded and as a wireframe, into one PNG."""
    from facemime.io import check_image_suffix, check_outputs, write_image
    from facemime.model import generic_head, load_head, load_wfm, painted_texture
    from facemime.render.head_view import views_sheet

    check_image_suffix(out_file)
    check_outputs([out_file], force, inputs=[model])
    if model is None:
        head = generic_head()
    elif model.suffix.lower() == ".wfm":
        head = load_wfm(model)
    else:
        head = load_head(model)
    texture = painted_texture(head) if head.uv is not None and head.groups else None
    write_image(out_file, views_sheet(head, texture))
    click.echo(str(out_file))


@cli.command()
@click.argument("video", type=click.Path(path_type=Path))
@click.option(
    "--init",
    "init",
    type=click.Path(path_type=Path),
    help="facemime.init/1 JSON with the eight contours of the first tracked frame "
    "(default: found automatically on the first frame).",
)
@click.option(
    "--out", "out_file", type=click.Path(path_type=Path), required=True, help="facemime.track/1 JSON to write."
)
@click.option(
    "--overlay", type=click.Path(path_type=Path), help="Also write the video with the contours drawn (.mp4 or .webm)."
)
@click.option("--force", is_flag=True, help="Overwrite existing output files.")
def track(video: Path, init: Path | None, out_file: Path, overlay: Path | None, force: bool) -> None:
    """Track the mouth and eyebrow contours through VIDEO with STB-snakes."""
    from facemime.track.video import track_video

    run = track_video(video, init, out_file, overlay, force)
    for w in run.warnings:
        click.echo(f"facemime: warning: {w}", err=True)
    click.echo(str(out_file))
    if overlay is not None:
        click.echo(str(overlay))
    lost = f", {run.frames_with_lost} with a lost feature" if run.frames_with_lost else ""
    lost += f", {len(run.redetected)} put right by re-detection" if run.redetected else ""
    rate = f" at {(run.frames - 1) / run.seconds:.0f} frames/s" if run.frames > 1 and run.seconds > 0 else ""
    click.echo(
        f"tracked {run.frames} frames{rate} after a {run.start_seconds:.2f} s start on the first "
        f"(decoding and encoding excluded){lost}",
        err=True,
    )


@cli.command()
@click.argument("source", metavar="IMAGE_OR_VIDEO", type=click.Path(path_type=Path))
@click.option("--frame", default=0, show_default=True, help="Frame of a video to fit on (0-based).")
@click.option(
    "--points",
    "points_file",
    type=click.Path(path_type=Path),
    help="facemime.points/1 JSON with reference points marked by hand (default: found automatically).",
)
@click.option(
    "--out",
    "out_file",
    type=click.Path(path_type=Path),
    required=True,
    help="NAME.actor to write; the preview goes to NAME.preview.png.",
)
@click.option("--force", is_flag=True, help="Overwrite existing output files.")
def fit(source: Path, frame: int, points_file: Path | None, out_file: Path, force: bool) -> None:
    """Fit the generic head to the frontal face in IMAGE_OR_VIDEO: reference points, elastic
    adjustment, texture; write the actor file and a preview PNG."""
    from facemime.fit.run import fit_file

    run = fit_file(source, out_file, frame, points_file, force)
    for w in run.warnings:
        click.echo(f"facemime: warning: {w}", err=True)
    for f in run.files:
        click.echo(str(f))
    click.echo(
        f"fitted in {run.seconds:.2f} s; the model's contours end {run.residual:.2f} px from the points", err=True
    )


#: ``--mask-only`` of the commands that show a synthesised picture (``run``, ``decode``, ``view``).
mask_only_option = click.option(
    "--mask-only", is_flag=True, help="Show the synthesised face alone on a plain backdrop, not in its actor's scene."
)


def user_motion_options(f):
    """The options that add motion on top of the measured one (``run`` and ``view``)."""
    for opt in reversed(
        (
            click.option(
                "--yaw", default=0.0, show_default=True, help="Extra head turn, degrees (+: towards the image's right)."
            ),
            click.option("--pitch", default=0.0, show_default=True, help="Extra head tilt, degrees (+: nose down)."),
            click.option(
                "--roll",
                default=0.0,
                show_default=True,
                help="Extra in-plane rotation, degrees (+: counter-clockwise).",
            ),
            click.option("--zoom", default=1.0, show_default=True, help="Factor on the face's size."),
            click.option(
                "--exaggerate",
                "gain",
                default=1.0,
                show_default=True,
                help="Factor on the mouth and brow motion (0: a still face, 2: twice the motion).",
            ),
        )
    ):
        f = opt(f)
    return f


@cli.command()
@click.argument("video", metavar="VIDEO_OR_TRACK", type=click.Path(path_type=Path))
@click.option(
    "--actor",
    "actor_file",
    type=click.Path(path_type=Path),
    help="NAME.actor to drive (from facemime fit; default: the face fitted on the first frame, or for a "
    "track file the generic head).",
)
@click.option(
    "--out",
    "out_file",
    type=click.Path(path_type=Path),
    required=True,
    help="Side-by-side video to write (.mp4 or .webm): the original with contours | the synthesised picture "
    "(for a track file: the synthesised picture alone).",
)
@click.option(
    "--track",
    "track_file",
    type=click.Path(path_type=Path),
    help="facemime.track/1 JSON to write: contours, head pose and motion per frame (default: OUT with .json).",
)
@click.option(
    "--weights",
    "weights_file",
    type=click.Path(path_type=Path),
    help="CSV to write with the expression weights per frame (frame,time_s,jawOpen,...), for a spreadsheet.",
)
@user_motion_options
@mask_only_option
@click.option("--force", is_flag=True, help="Overwrite existing output files.")
def run(
    video: Path,
    actor_file: Path | None,
    out_file: Path,
    track_file: Path | None,
    weights_file: Path | None,
    yaw: float,
    pitch: float,
    roll: float,
    zoom: float,
    gain: float,
    mask_only: bool,
    force: bool,
) -> None:
    """Analyse the face in VIDEO (fit, track, head pose) and re-synthesise every frame on an actor,
    in the actor's own scene (the picture it was fitted on). A TRACK.json (from run, or expression
    weights written by hand) is played instead: its synthesised picture alone, at its size and
    frame rate, with the motion options added; --track and --weights need a video."""
    from facemime.animate.run import run_track, run_video
    from facemime.animate.synth import UserMotion
    from facemime.errors import InvalidInputError

    user = UserMotion(yaw=yaw, pitch=pitch, roll=roll, zoom=zoom, gain=gain)
    t0 = time.perf_counter()
    if video.suffix.lower() == ".json":
        if track_file is not None or weights_file is not None:
            raise InvalidInputError(
                f"--track and --weights write what run measures on a video; {video} is a track file already"
            )
        result = run_track(video, out_file, actor_file, user, force, mask_only)
        wall = time.perf_counter() - t0
        click.echo(str(out_file))
        missing = f"; no face in {result.frames_without_face} frames" if result.frames_without_face else ""
        click.echo(
            f"played {result.frames} frames of {video} in {wall:.1f} s ({result.frames / wall:.0f} frames/s){missing}",
            err=True,
        )
        return
    result = run_video(video, out_file, actor_file, track_file, user, force, mask_only=mask_only, weights=weights_file)
    wall = time.perf_counter() - t0
    for w in result.warnings:
        click.echo(f"facemime: warning: {w}", err=True)
    for f in result.files:
        click.echo(str(f))
    shares = ", ".join(f"{k} {100 * v:.0f}%" for k, v in result.shares.items())
    missing = f"; no face in {result.frames_without_face} frames" if result.frames_without_face else ""
    if result.departs:
        ranges = ", ".join(f"{a}" if a == b else f"{a}-{b}" for a, b in result.departs[:8])
        more = f" and {len(result.departs) - 8} more ranges" if len(result.departs) > 8 else ""
        click.echo(
            f"facemime: note: frames {ranges}{more} depart from their synthesis (something passes in front of "
            "the face, or the body or the camera moves more than one key frame can show); they are marked in "
            "the track file",
            err=True,
        )
    click.echo(
        f"ran {result.frames} frames in {wall:.1f} s ({result.frames / wall:.0f} frames/s; the per-frame work "
        f"beside the encoder {result.fps:.0f} frames/s: {shares}){missing}",
        err=True,
    )


@cli.command()
@click.argument("video", metavar="VIDEO_OR_TRACK", type=click.Path(path_type=Path))
@click.option(
    "--actor",
    "actor_file",
    type=click.Path(path_type=Path),
    help="NAME.actor of this person that the receiver already holds: the stream names it instead of "
    "carrying it (default: fit one on the first frame, or for a track file the generic head, "
    "and carry it).",
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
@click.option("--out", "out_file", type=click.Path(path_type=Path), required=True, help="X.fmstream to write.")
@click.option("--force", is_flag=True, help="Overwrite an existing output file.")
def encode(
    video: Path,
    actor_file: Path | None,
    quality: int | None,
    rate: float | None,
    keyframe: float,
    packet: float,
    embed_actor: bool,
    appearance: float,
    out_file: Path,
    force: bool,
) -> None:
    """Analyse the face in VIDEO and write its motion as a facemime stream: a couple of kilobits
    a second, plus the actor once. A TRACK.json (from run, or expression weights written by hand)
    is coded from its recorded motion instead, at its size and frame rate (no --appearance)."""
    from facemime.codec.files import encode_video
    from facemime.codec.stream import DEFAULT_QUALITY, Settings
    from facemime.errors import InvalidInputError

    if quality is not None and rate is not None:
        raise InvalidInputError("give --quality or --rate, not both")
    settings = Settings(quality=DEFAULT_QUALITY if quality is None else quality, keyframe=keyframe, packet=packet)
    result = encode_video(video, out_file, actor_file, settings, rate, True if embed_actor else None, force, appearance)
    for w in result.warnings:
        click.echo(f"facemime: warning: {w}", err=True)
    click.echo(str(out_file))
    scene = f", its scene {result.scene_bytes} of them" if result.scene_bytes else ""
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
@click.option(
    "--actor",
    "actor_file",
    type=click.Path(path_type=Path),
    help="NAME.actor the stream names, when the stream does not carry its actor.",
)
@click.option(
    "--out",
    "out_file",
    type=click.Path(path_type=Path),
    required=True,
    help="Video of the synthesised picture to write (.mp4 or .webm).",
)
@mask_only_option
@click.option("--force", is_flag=True, help="Overwrite an existing output file.")
def decode(stream: Path, actor_file: Path | None, out_file: Path, mask_only: bool, force: bool) -> None:
    """Synthesise the face of a facemime STREAM into a video, with no access to the source video."""
    from facemime.codec.files import decode_stream

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
@click.argument("source", metavar="VIDEO_OR_TRACK", type=click.Path(path_type=Path))
@click.option(
    "--actor",
    "actor_file",
    type=click.Path(path_type=Path),
    help="NAME.actor to drive (default: the video's own face, or the generic head for a track file).",
)
@click.option("--port", default=8765, show_default=True, help="Local port of the viewer's web page (0: any free port).")
@click.option("--no-browser", is_flag=True, help="Do not open a browser; print the address only.")
@mask_only_option
def view(source: Path, actor_file: Path | None, port: int, no_browser: bool, mask_only: bool) -> None:
    """Play VIDEO (analysed live) or a TRACK.json from facemime run in the interactive viewer, a
    page in your web browser: keys turn, tilt, roll, zoom and exaggerate the synthesised face.
    Stop with Ctrl-C."""
    import webbrowser

    from facemime.io.actor_file import load_actor
    from facemime.viewer import HELP, Viewer, make_server

    actor = load_actor(actor_file) if actor_file is not None else None
    with Viewer(source, actor, mask_only) as viewer:
        server = make_server(viewer, port)
        url = f"http://127.0.0.1:{server.server_address[1]}/"
        click.echo(url)
        click.echo(f"keys: {HELP}; Ctrl-C stops", err=True)
        if not no_browser:
            webbrowser.open(url)
        try:
            server.serve_forever()
        finally:
            server.server_close()


@cli.command()
@click.argument("track", type=click.Path(path_type=Path))
@click.option(
    "--actor",
    "actor_file",
    type=click.Path(path_type=Path),
    help="NAME.actor to carry the performance (default: the generic head, as view plays a track file).",
)
@click.option(
    "--out",
    "out_file",
    type=click.Path(path_type=Path),
    required=True,
    help="PERFORMANCE.glb to write: binary glTF 2.0, the textured head, its expression morph targets and "
    "one animation (weights and head pose) at the track's frame rate.",
)
@click.option("--force", is_flag=True, help="Overwrite the output file.")
def export(track: Path, actor_file: Path | None, out_file: Path, force: bool) -> None:
    """Export the performance of TRACK.json (from facemime run) as a glTF 2.0 file for Blender,
    three.js, Unity or Unreal: the actor's textured mesh in metres, y up, its named expression
    controls (ARKit names) as morph targets, and their weights and the head pose per frame."""
    from facemime.export import export_track

    result = export_track(track, out_file, actor_file, force)
    click.echo(str(result.path))
    click.echo(
        f"exported {result.frames} frames, {result.controls} morph targets, {result.bytes} bytes "
        f"in {result.seconds:.2f} s",
        err=True,
    )


@cli.command()
@click.argument("source", metavar="VIDEO_OR_CAMERA")
@click.option(
    "--actor",
    "actor_file",
    type=click.Path(path_type=Path),
    help="NAME.actor of this person to send (default: fit one on the first frame); the stream carries it.",
)
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
@click.option("--force", is_flag=True, help="Overwrite an existing recording.")
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

    from facemime.call import Call
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
    from facemime.batch import print_progress, run_batch

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
        sys.exit(3)


class Terminated(BaseException):
    """SIGTERM or SIGHUP: the command stops as on Ctrl-C, removing its unfinished outputs (a
    BaseException, like KeyboardInterrupt, but not one: click would take it for Ctrl-C)."""

    def __init__(self, signum: int):
        super().__init__(signum)
        self.signum = signum


def _terminate(signum: int, frame: object) -> None:
    raise Terminated(signum)


def main(argv: list[str] | None = None) -> None:
    """Entry point: run the CLI, turning expected errors into one line on stderr; SIGTERM and
    SIGHUP stop it cleanly (exit status 128 + the signal's number), and so does SIGINT (Ctrl-C,
    status 130) even where the process was started with SIGINT ignored, as a shell script's
    background job is: a command that says "Ctrl-C stops" stops on it."""
    argv = sys.argv[1:] if argv is None else argv
    handlers = {}
    if threading.current_thread() is threading.main_thread():
        handlers = {sig: signal.signal(sig, _terminate) for sig in (signal.SIGTERM, signal.SIGHUP)}
        handlers[signal.SIGINT] = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        _run(argv)
    finally:
        for sig, handler in handlers.items():
            signal.signal(sig, handler)


def _run(argv: list[str]) -> None:
    try:
        cli.main(args=argv, prog_name="facemime", standalone_mode=False)
    except click.exceptions.Abort:
        click.echo("facemime: interrupted", err=True)
        sys.exit(130)
    except click.ClickException as e:
        e.show()
        sys.exit(e.exit_code)
    except FacemimeError as e:
        if "--traceback" in argv:
            raise
        click.echo(f"facemime: error: {e}", err=True)
        sys.exit(1)
    except Terminated as e:
        click.echo("facemime: terminated", err=True)
        sys.exit(128 + e.signum)
    except KeyboardInterrupt:
        click.echo("facemime: interrupted", err=True)
        sys.exit(130)
    except MemoryError:
        click.echo("facemime: error: out of memory", err=True)
        sys.exit(1)
    except Exception as e:  # a defect: still one line, with the way to the trace
        if "--traceback" in argv:
            raise
        click.echo(
            f"facemime: error: unexpected {type(e).__name__}: {e} (a bug in facemime; run again with "
            "--traceback and report it)",
            err=True,
        )
        sys.exit(2)
