"""The test environment's lock (requirements/test.txt, written by tools/lock) is current: made from
pyproject.toml's dependency declarations as they are, every declared requirement pinned at a version
it allows, every pin hashed; and requirements/build.in asks for the build backend pyproject.toml
builds with."""

from __future__ import annotations

import importlib.util
import re
import tomllib
from pathlib import Path

from packaging.requirements import Requirement
from packaging.utils import canonicalize_name
from packaging.version import Version

ROOT = Path(__file__).resolve().parent.parent
_spec = importlib.util.spec_from_file_location("lock_inputs", ROOT / "tools" / "lock_inputs.py")
assert _spec is not None and _spec.loader is not None
lock_inputs = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(lock_inputs)


def entries() -> list[tuple[str, str]]:
    """(requirement with its marker, hash options) of each pin of the lock."""
    text = lock_inputs.LOCK.read_text()
    body = re.sub(r"\\\n\s*", " ", text)  # continuation lines joined
    return [
        (line.split(" --hash=")[0].strip(), line)
        for line in body.splitlines()
        if line.strip() and not line.lstrip().startswith("#")
    ]


def pins() -> dict[str, list[Version]]:
    """Each locked package's versions (one per marker it is forked on)."""
    out: dict[str, list[Version]] = {}
    for requirement, _ in entries():
        r = Requirement(requirement)
        (spec,) = r.specifier
        assert spec.operator == "==", requirement
        out.setdefault(canonicalize_name(r.name), []).append(Version(spec.version))
    return out


def test_the_lock_was_made_from_pyprojects_dependencies_as_they_are():
    first = lock_inputs.LOCK.read_text().splitlines()[0]
    assert first == lock_inputs.PREFIX + lock_inputs.digest(), (
        "pyproject.toml's dependencies (or requirements/build.in) changed since requirements/test.txt "
        "was made: run tools/lock"
    )


def test_every_declared_requirement_is_pinned_at_a_version_it_allows_and_every_pin_is_hashed():
    declared = lock_inputs.inputs()
    requirements = [
        *declared["dependencies"],
        *(r for extra in declared["optional-dependencies"].values() for r in extra),
        *declared["build.in"],
    ]
    locked = pins()
    for text in requirements:
        r = Requirement(text)
        versions = locked.get(canonicalize_name(r.name))
        assert versions, f"{r.name} is not in the lock"
        assert all(r.specifier.contains(v, prereleases=True) for v in versions), (text, versions)
    assert all("--hash=sha256:" in line for _, line in entries())


def test_the_locked_build_backend_is_the_one_pyproject_builds_with():
    with open(ROOT / "pyproject.toml", "rb") as f:
        backend = tomllib.load(f)["build-system"]["requires"]
    assert sorted(lock_inputs.inputs()["build.in"]) == sorted(backend)
