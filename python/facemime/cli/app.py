"""The ``facemime`` command group and what its commands share: the exit statuses, the ``--force``
option, and the options of the commands that show a synthesised picture. The commands are in the
modules beside this one, one per family; :mod:`facemime.cli.main` runs them."""

from __future__ import annotations

from enum import IntEnum
from pathlib import Path

import click

from facemime import __version__


class ExitStatus(IntEnum):
    """The ``facemime`` command's exit statuses (a signal ``N`` that stops it: 128 + N)."""

    OK = 0
    #: An error the user can put right (bad input, a missing file, no face): one line on stderr.
    ERROR = 1
    #: A defect of facemime, or a command line click refuses (its usage errors).
    BUG = 2
    #: ``batch``: some videos failed or timed out (the others are done).
    SOME_FAILED = 3
    #: Ctrl-C.
    INTERRUPTED = 130


@click.group(context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(__version__, prog_name="facemime")
@click.option("--traceback", is_flag=True, help="Show the Python traceback of an error.")
def cli(traceback: bool) -> None:
    """Track mouth and eyebrow motion with dynamic contours and re-synthesise it on a textured
    3D head model."""


def actor_option(help: str):
    """``--actor NAME.actor`` (``actor_file``), with what it is for in this command."""
    return click.option("--actor", "actor_file", type=click.Path(path_type=Path), help=help)


def out_option(help: str):
    """``--out PATH`` (``out_file``, required), with what is written there."""
    return click.option("--out", "out_file", type=click.Path(path_type=Path), required=True, help=help)


#: ``--force`` of every command that writes files.
force_option = click.option(
    "--force", is_flag=True, help="Overwrite output files that exist (an input file is never overwritten)."
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
