"""``facemime run``, ``view``, ``export`` and ``demo``: the commands that show or export a
synthesised face."""

from __future__ import annotations

import time
from pathlib import Path

import click

from facemime.cli.app import actor_option, cli, force_option, mask_only_option, out_option, user_motion_options


@cli.command()
@click.argument("video", metavar="VIDEO_OR_TRACK", type=click.Path(path_type=Path))
@actor_option(
    "NAME.actor to drive (from facemime fit; default: the face fitted on the first frame, or for a "
    "track file the generic head)."
)
@out_option(
    "Side-by-side video to write (.mp4 or .webm): the original with contours | the synthesised picture "
    "(for a track file: the synthesised picture alone)."
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
@force_option
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
    from facemime.animate.synth import UserMotion
    from facemime.app.run import run_track, run_video
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
@click.argument("source", metavar="VIDEO_OR_TRACK", type=click.Path(path_type=Path))
@actor_option("NAME.actor to drive (default: the video's own face, or the generic head for a track file).")
@click.option("--port", default=8765, show_default=True, help="Local port of the viewer's web page (0: any free port).")
@click.option("--no-browser", is_flag=True, help="Do not open a browser; print the address only.")
@mask_only_option
def view(source: Path, actor_file: Path | None, port: int, no_browser: bool, mask_only: bool) -> None:
    """Play VIDEO (analysed live) or a TRACK.json from facemime run in the interactive viewer, a
    page in your web browser: keys turn, tilt, roll, zoom and exaggerate the synthesised face.
    Stop with Ctrl-C."""
    import webbrowser

    from facemime.app.view import HELP, Viewer
    from facemime.app.view_server import make_server
    from facemime.io.actor_file import load_actor

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
@actor_option("NAME.actor to carry the performance (default: the generic head, as view plays a track file).")
@out_option(
    "PERFORMANCE.glb to write: binary glTF 2.0, the textured head, its expression morph targets and "
    "one animation (weights and head pose) at the track's frame rate; or AVATAR.vrm: the head as a "
    "VRM 1.0 avatar (humanoid skeleton, an expression per ARKit name) for facemime live --vmc."
)
@force_option
def export(track: Path, actor_file: Path | None, out_file: Path, force: bool) -> None:
    """Export the performance of TRACK.json (from facemime run) as a glTF 2.0 file for Blender,
    three.js, Unity or Unreal: the actor's textured mesh in metres, y up, its named expression
    controls (ARKit names) as morph targets, and their weights and the head pose per frame. An
    --out ending in .vrm writes the head as a VRM 1.0 avatar instead, for VSeeFace, Warudo or
    three-vrm."""
    from facemime.app.export import export_track

    result = export_track(track, out_file, actor_file, force)
    click.echo(str(result.path))
    click.echo(
        f"exported {result.frames} frames, {result.controls} morph targets, {result.bytes} bytes "
        f"in {result.seconds:.2f} s",
        err=True,
    )


@cli.command()
@click.option(
    "--out",
    "out_dir",
    type=click.Path(path_type=Path),
    default=Path("facemime-demo"),
    show_default=True,
    help="Folder for the demo's files.",
)
@force_option
def demo(out_dir: Path, force: bool) -> None:
    """Run the main job on built-in data: fit the astronaut photo, animate her with a scripted
    performance, track it back and re-synthesise it on her and on a second face; write the videos
    and report.html."""
    from facemime.app.demo import run_demo

    result = run_demo(out_dir, force)
    for f in result.files:
        click.echo(str(f))
    errors = ", ".join(f"{g.replace('_', ' ')} {v:.3f}" for g, v in result.nme.items())
    click.echo(f"tracked {result.frames} frames back: mean NME {errors}; open {result.files[-1]}", err=True)
