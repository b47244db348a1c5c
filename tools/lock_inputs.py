"""What the test environment's lock (requirements/test.txt) is resolved from, and a digest of it.

The inputs: pyproject.toml's ``requires-python``, ``dependencies``, optional dependencies and
``[build-system] requires``, and requirements/build.in. ``tools/lock`` writes the digest into the
lock's first line; tests/test_lock.py fails when the two differ (the inputs changed, the lock did
not). Run as a script, it prints the digest.
"""

from __future__ import annotations

import hashlib
import json
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
LOCK = ROOT / "requirements" / "test.txt"
BUILD_IN = ROOT / "requirements" / "build.in"
#: The lock's first line: this prefix, then the digest.
PREFIX = "# inputs: sha256 "


def inputs() -> dict[str, object]:
    """The declarations the lock is resolved from."""
    with open(ROOT / "pyproject.toml", "rb") as f:
        pyproject = tomllib.load(f)
    project = pyproject["project"]
    build = [line.strip() for line in BUILD_IN.read_text().splitlines() if line.strip() and not line.startswith("#")]
    return {
        "requires-python": project["requires-python"],
        "dependencies": project["dependencies"],
        "optional-dependencies": project.get("optional-dependencies", {}),
        "build-system": pyproject["build-system"]["requires"],
        "build.in": build,
    }


def digest() -> str:
    """The SHA-256 of :func:`inputs`, hex."""
    return hashlib.sha256(json.dumps(inputs(), sort_keys=True).encode()).hexdigest()


if __name__ == "__main__":
    print(digest())
