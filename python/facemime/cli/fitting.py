"""``facemime fit``, ``track`` and ``model-preview``: the commands that make an actor, a track or a
view of a head model."""

from __future__ import annotations

from pathlib import Path

import click

from facemime.cli.app import cli, force_option, out_option


@cli.command("model-preview")
@click.argument("model", required=False, type=click.Path(path_type=Path))
@out_option("PNG to write.")
@force_option
def model_preview(model: Path | None, out_file: Path, force: bool) -> None:
    """Render a head model (facemime .json or CANDIDE .wfm; default: the built-in head) from
    five angles, textured, shaded and as a wireframe, into one PNG."""
    from facemime.head import generic_head, painted_texture
    from facemime.io import check_image_suffix, check_outputs, write_image
    from facemime.io.head_file import load_head
    from facemime.io.wfm import load_wfm
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
@click.argument("source", metavar="IMAGE_OR_VIDEO", type=click.Path(path_type=Path))
@click.option("--frame", default=0, show_default=True, help="Frame of a video to fit on (0-based).")
@click.option(
    "--points",
    "points_file",
    type=click.Path(path_type=Path),
    help="facemime.points/1 JSON with reference points marked by hand (default: found automatically).",
)
@click.option(
    "--samples-from",
    "samples_from",
    type=click.Path(path_type=Path),
    help="A video of the same person (first frame frontal and neutral): keep samples of their own mouth "
    "and eyes in the actor, drawn instead of a painted mouth interior and moved irises.",
)
@out_option("NAME.actor to write; the preview goes to NAME.preview.png.")
@force_option
def fit(
    source: Path, frame: int, points_file: Path | None, samples_from: Path | None, out_file: Path, force: bool
) -> None:
    """Fit the generic head to the frontal face in IMAGE_OR_VIDEO: reference points, elastic
    adjustment, texture; write the actor file and a preview PNG."""
    from facemime.app.fit import fit_file

    run = fit_file(source, out_file, frame, points_file, force, samples_from)
    for w in run.warnings:
        click.echo(f"facemime: warning: {w}", err=True)
    for f in run.files:
        click.echo(str(f))
    click.echo(
        f"fitted in {run.seconds:.2f} s; the model's contours end {run.residual:.2f} px from the points", err=True
    )


@cli.command()
@click.argument("video", type=click.Path(path_type=Path))
@click.option(
    "--init",
    "init",
    type=click.Path(path_type=Path),
    help="facemime.init/1 JSON with the eight contours of the first tracked frame "
    "(default: found automatically on the first frame).",
)
@out_option("facemime.track/1 JSON to write.")
@click.option(
    "--overlay", type=click.Path(path_type=Path), help="Also write the video with the contours drawn (.mp4 or .webm)."
)
@click.option(
    "--pose/--no-pose",
    default=True,
    show_default=True,
    help="Also write the head pose of every frame with the face (one landmark pass a frame).",
)
@force_option
def track(video: Path, init: Path | None, out_file: Path, overlay: Path | None, pose: bool, force: bool) -> None:
    """Track the mouth and eyebrow contours through VIDEO with STB-snakes."""
    from facemime.app.track import track_video

    run = track_video(video, init, out_file, overlay, force, pose=pose)
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
