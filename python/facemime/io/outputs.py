"""Output files: never overwrite what exists unless asked, never an input (``--force`` or not),
never leave half-written files, and a command's several outputs all or none (:class:`Outputs`)."""

from __future__ import annotations

import os
import re
import tempfile
from collections.abc import Iterable, Iterator
from contextlib import contextmanager
from pathlib import Path

import cv2
import numpy as np

from facemime.errors import FacemimeError, InvalidInputError


class OutputExistsError(FacemimeError, FileExistsError):
    """An output file exists and overwriting was not allowed."""


class OutputFileError(FacemimeError, OSError):
    """An output file cannot be written there."""


#: Image file types :func:`write_image` writes.
IMAGE_SUFFIXES = (".png", ".jpg", ".jpeg", ".bmp", ".tif", ".tiff", ".webp")


def check_image_suffix(path: str | Path) -> None:
    """Refuse an image file name whose type :func:`write_image` cannot write.

    Parameters
    ----------
    path
        The image file name; its suffix (any case) must be one of :data:`IMAGE_SUFFIXES`, else
        :class:`InvalidInputError`.
    """
    if Path(path).suffix.lower() not in IMAGE_SUFFIXES:
        raise InvalidInputError(f"cannot write image {path}: its name must end in one of {', '.join(IMAGE_SUFFIXES)}")


#: The longest file name (bytes) outputs may have: the common file systems' limit.
NAME_MAX = 255


def _same(a: Path, b: Path) -> bool:
    """Whether two paths name one file: the same real path (symbolic links followed), or, both
    existing, the same file on disk (hard links)."""
    if a.resolve() == b.resolve():
        return True
    try:
        return a.exists() and b.exists() and os.path.samefile(a, b)
    except OSError:
        return False


def check_outputs(paths: Iterable[str | Path], force: bool, inputs: Iterable[str | Path | None] = ()) -> None:
    """Refuse, with one message naming them, outputs that cannot or may not be written.

    Refused are an output that is one of the command's inputs or another of its outputs (also
    through a link), whatever ``force`` says; existing files unless ``force``; a folder; and
    outputs whose folder cannot be created or written.

    Parameters
    ----------
    paths
        The command's output files.
    force
        Allow existing files to be overwritten (:class:`OutputExistsError` otherwise).
    inputs
        The command's input files; None entries (an option not given) are skipped.
    """
    files = [Path(p) for p in paths]
    for i, p in enumerate(files):
        for q in (Path(q) for q in inputs if q is not None):
            if _same(p, q):
                raise InvalidInputError(f"the output {p} would replace the input {q}; choose another name")
        for q in files[i + 1 :]:
            if _same(p, q):
                raise InvalidInputError(f"two outputs are one file: {p} and {q}")
    for p in files:
        if len(p.name.encode()) > NAME_MAX:
            raise InvalidInputError(f"cannot write {p}: its name is over {NAME_MAX} bytes long")
    existing = [str(p) for p in files if p.exists()]
    if existing and not force:
        raise OutputExistsError(
            f"{', '.join(existing)} already exist{'s' if len(existing) == 1 else ''}; use --force to overwrite"
        )
    for p in files:
        if p.is_dir():
            raise InvalidInputError(f"{p} is a folder, expected a file name")
        parent = p.parent
        while not parent.exists():
            parent = parent.parent
        if not parent.is_dir() or not os.access(parent, os.W_OK):
            raise InvalidInputError(f"cannot write {p}: {parent} is not a writeable folder")


def temporary_sibling(path: Path) -> Path:
    """A new, unique file next to ``path`` with the same suffix (same filesystem, so the final
    rename is atomic).

    Parameters
    ----------
    path
        The file to be written; its folder is created if missing.

    Returns
    -------
    Path
        The temporary file, ``.<stem>.<random>.part<suffix>`` in ``path``'s folder (the stem cut
        to keep the name within :data:`NAME_MAX` bytes), created empty with the usual mode (0666
        less the umask).
    """
    room = NAME_MAX - len(f"..{'x' * 8}.part{path.suffix}".encode())  # mkstemp adds 8 characters
    stem = path.stem.encode()[: max(room, 1)].decode(errors="ignore")
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=f".{stem}.", suffix=f".part{path.suffix}", dir=path.parent)
    except OSError as e:
        raise OutputFileError(f"cannot write {path}: {e.strerror or e}") from None
    os.close(fd)
    umask = os.umask(0)
    os.umask(umask)
    os.chmod(tmp, 0o666 & ~umask)  # mkstemp makes 0600; the final file gets the usual mode
    return Path(tmp)


class Outputs:
    """A command's output files, all or none: each is written to a temporary name beside it
    (:meth:`stage`), and they are put in place together when the block ends without an error;
    otherwise (an error, Ctrl-C, SIGTERM) none is, and the temporary files are removed.

    Parameters
    ----------
    paths
        The command's output files: checked at once by :func:`check_outputs`.
    force
        Allow existing files to be overwritten.
    inputs
        The command's input files, which no output may replace; None entries are skipped.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> folder = pathlib.Path(tempfile.mkdtemp())
    >>> with Outputs([folder / "a.txt", folder / "b.txt"], force=False) as out:
    ...     _ = out.stage(folder / "a.txt").write_text("a")
    ...     _ = out.stage(folder / "b.txt").write_text("b")
    >>> sorted(p.name for p in folder.iterdir())
    ['a.txt', 'b.txt']
    """

    def __init__(self, paths: Iterable[str | Path], force: bool, inputs: Iterable[str | Path | None] = ()):
        self.paths = [Path(p) for p in paths]
        check_outputs(self.paths, force, inputs)
        self._staged: dict[Path, Path] = {}

    def __enter__(self) -> Outputs:
        return self

    def stage(self, path: str | Path) -> Path:
        """The temporary file to write an output to.

        Parameters
        ----------
        path
            One of the outputs (a ``ValueError`` otherwise).

        Returns
        -------
        Path
            Its temporary file beside it (the same one on each call), put in place when the block
            ends without an error.
        """
        path = Path(path)
        if path not in self.paths:
            raise ValueError(f"{path} is not one of the outputs")
        if path not in self._staged:
            self._staged[path] = temporary_sibling(path)
        return self._staged[path]

    def __exit__(self, exc_type: type | None, exc: BaseException | None, tb: object) -> None:
        if isinstance(exc, FacemimeError) and exc.args:  # name the output, not its temporary file
            message = str(exc.args[0])
            for final in self.paths:
                temporary = (
                    re.escape(str(final.parent / f".{final.stem}.")) + r"\S*?" + re.escape(f".part{final.suffix}")
                )
                message = re.sub(temporary, str(final).replace("\\", "\\\\"), message)
            exc.args = (message, *exc.args[1:])
        try:
            if exc_type is None:
                for final, tmp in self._staged.items():
                    try:
                        os.replace(tmp, final)
                    except OSError as e:
                        raise OutputFileError(f"cannot write {final}: {e.strerror or e}") from None
        finally:
            for tmp in self._staged.values():
                tmp.unlink(missing_ok=True)


@contextmanager
def atomic_file(path: Path) -> Iterator[Path]:
    """Write a file atomically through a temporary file next to it.

    When the block ends without an error the temporary file replaces ``path`` in one step,
    otherwise it is removed. OS errors become one line (:class:`OutputFileError`).

    Parameters
    ----------
    path
        The file to write; its folder is created if missing.

    Yields
    ------
    Path
        The temporary file to write (from :func:`temporary_sibling`).
    """
    tmp = temporary_sibling(path)
    try:
        yield tmp
        os.replace(tmp, path)
    except OSError as e:
        raise OutputFileError(f"cannot write {path}: {e.strerror or e}") from None
    finally:
        tmp.unlink(missing_ok=True)


def write_text(path: str | Path, text: str) -> Path:
    """Write a UTF-8 text file atomically.

    Parameters
    ----------
    path
        The file to write; its folder is created if missing.
    text
        The file's content.

    Returns
    -------
    Path
        ``path``.
    """
    path = Path(path)
    with atomic_file(path) as tmp:
        tmp.write_text(text, encoding="utf-8")
    return path


def write_bytes(path: str | Path, data: bytes) -> Path:
    """Write a binary file atomically.

    Parameters
    ----------
    path
        The file to write; its folder is created if missing.
    data
        The file's content.

    Returns
    -------
    Path
        ``path``.
    """
    path = Path(path)
    with atomic_file(path) as tmp:
        tmp.write_bytes(data)
    return path


def write_image(path: str | Path, image: np.ndarray) -> Path:
    """Write an image file atomically, its type (PNG, JPEG, ...) by the name's suffix.

    Parameters
    ----------
    path
        The file to write; its suffix must be one of :data:`IMAGE_SUFFIXES`.
    image
        (H, W, 3) uint8 RGB or (H, W) uint8 gray image.

    Returns
    -------
    Path
        ``path``.
    """
    path = Path(path)
    check_image_suffix(path)
    with atomic_file(path) as tmp:
        bgr = image[..., ::-1] if image.ndim == 3 else image
        if not cv2.imwrite(str(tmp), np.ascontiguousarray(bgr)):
            raise OutputFileError(f"cannot write image {path}")
    return path
