"""The README and docs/ stay true: every relative link points to an existing file, and every
``facemime ...`` command shown in a fenced ``sh``/``console`` block of the README is a command of
the CLI whose ``--help`` exits 0."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from facemime.cli.main import main

ROOT = Path(__file__).resolve().parent.parent
DOCUMENTS = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
#: Markdown links and images: [text](target) or ![alt](target), target up to a space or ')'.
LINK = re.compile(r"!?\[[^\]]*\]\(\s*<?([^)\s>]+)>?(?:\s+\"[^\"]*\")?\s*\)")
FENCE = re.compile(r"^```(\w*)[^\n]*\n(.*?)^```", re.MULTILINE | re.DOTALL)


def relative_links(text: str) -> list[str]:
    """The link targets of a Markdown text that are paths (no scheme, no bare anchor), without
    their anchors; links inside fenced code blocks are not links."""
    text = FENCE.sub("", text)
    text = re.sub(r"`[^`\n]*`", "", text)  # inline code: `[x](y)` shown, not linked
    out = []
    for target in LINK.findall(text):
        if re.match(r"^[a-z][a-z0-9+.-]*:", target, re.IGNORECASE) or target.startswith("#"):
            continue
        out.append(target.split("#", 1)[0])
    return out


def readme_commands(text: str) -> list[list[str]]:
    """The ``facemime`` commands (words up to the first option) in the README's fenced ``sh``
    and ``console`` blocks."""
    commands = []
    for lang, body in FENCE.findall(text):
        if lang not in ("sh", "console", "shell", "bash"):
            continue
        for line in body.splitlines():
            line = line.strip().removeprefix("$ ")
            for part in re.split(r"&&|;|\|", line.split(" #", 1)[0]):
                words = part.split()
                if words[:1] == ["facemime"]:
                    commands.append(words)
    return commands


def test_the_link_checker_finds_links_and_skips_code():
    text = "[a](docs/a.md#x) ![b](b.png) [c](https://x.org) [d](#here) `[e](f.md)`\n```sh\n[g](h)\n```\n"
    assert relative_links(text) == ["docs/a.md", "b.png"]


@pytest.mark.parametrize("document", DOCUMENTS, ids=lambda p: p.relative_to(ROOT).as_posix())
def test_relative_links_point_to_files(document: Path):
    missing = [t for t in relative_links(document.read_text(encoding="utf-8")) if not (document.parent / t).exists()]
    assert not missing, f"{document.relative_to(ROOT)} links to missing files: {missing}"


def test_a_broken_link_is_caught(tmp_path: Path):
    doc = tmp_path / "doc.md"
    doc.write_text("[gone](no/such/file.md)\n", encoding="utf-8")
    assert [t for t in relative_links(doc.read_text()) if not (doc.parent / t).exists()] == ["no/such/file.md"]


def test_the_readme_shows_commands():
    commands = readme_commands((ROOT / "README.md").read_text(encoding="utf-8"))
    assert len({c[1] for c in commands if len(c) > 1}) >= 10


def _help_exit_status(words: list[str]) -> int:
    """Exit status of ``facemime <subcommand> --help``, run in-process."""
    subcommand = [w for w in words[1:2] if not w.startswith("-")]
    try:
        main([*subcommand, "--help"])
    except SystemExit as e:
        return 0 if e.code is None else e.code if isinstance(e.code, int) else 1
    return 0


@pytest.mark.parametrize(
    "words", readme_commands((ROOT / "README.md").read_text(encoding="utf-8")), ids=lambda w: " ".join(w[:2])
)
def test_readme_commands_exist(words: list[str], capsys: pytest.CaptureFixture[str]):
    assert _help_exit_status(words) == 0, f"`{' '.join(words)}`: `facemime {words[1]} --help` failed"
    assert capsys.readouterr().out.startswith("Usage:")


def test_an_unknown_command_is_caught(capsys: pytest.CaptureFixture[str]):
    assert _help_exit_status(["facemime", "no-such-command"]) != 0
