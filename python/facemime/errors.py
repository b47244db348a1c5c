"""The exception family of facemime. Every expected failure raises a :class:`FacemimeError`
whose message is one line that names the argument or file, what was expected and what was found.
"""


class FacemimeError(Exception):
    """Base class of every error facemime raises on purpose."""


class InvalidInputError(FacemimeError, ValueError):
    """An argument has the wrong type, shape, dtype or value."""


class InputFileError(FacemimeError, FileNotFoundError):
    """An input file is missing or cannot be read."""


class ModelFormatError(FacemimeError, ValueError):
    """A model file (generic head JSON, CANDIDE .wfm) is malformed."""


class OutputFileError(FacemimeError, OSError):
    """An output file cannot be written (a full disk, a failing encoder)."""


class NoFaceError(FacemimeError, ValueError):
    """No human face was found in an image."""
