"""The Khronos glTF Validator (npm ``gltf-validator``, run by ``web/test/validate-gltf.mjs``)
finds no error and no warning in exported files, and does find them in a broken one (so the
check can fail)."""

import json
import struct
import subprocess

from facemime.export.gltf import BIN_CHUNK, GLB_MAGIC, JSON_CHUNK, read_glb

from .conftest import WEB

SCRIPT = WEB / "test" / "validate-gltf.mjs"


def validate(node, *files):
    """(exit status, one report per file: errors, warnings, infos, hints, messages)."""
    run = subprocess.run([node, str(SCRIPT), *map(str, files)], cwd=WEB, capture_output=True, text=True, timeout=120)
    assert run.stderr == "", run.stderr
    return run.returncode, [json.loads(line) for line in run.stdout.splitlines()]


def test_exported_files_have_no_errors_and_no_warnings(node, generic_export, real_export, tmp_path):
    code, reports = validate(node, generic_export[1], real_export[2])
    for r in reports:
        assert r["errors"] == 0 and r["warnings"] == 0, r["messages"]
        assert r["info"]["hasMorphTargets"] and r["info"]["hasTextures"] and r["info"]["animationCount"] == 1
    assert code == 0 and len(reports) == 2


def repacked(doc, blob):
    """A .glb of ``doc`` (JSON) and ``blob`` (binary chunk, already padded)."""
    text = json.dumps(doc).encode()
    text += b" " * (-len(text) % 4)
    chunks = struct.pack("<II", len(text), JSON_CHUNK) + text + struct.pack("<II", len(blob), BIN_CHUNK) + blob
    return struct.pack("<III", GLB_MAGIC, 2, 12 + len(chunks)) + chunks


def test_a_broken_file_fails_validation(node, generic_export, tmp_path):
    doc, blob = read_glb(generic_export[1].read_bytes())
    positions = doc["accessors"][doc["meshes"][0]["primitives"][0]["attributes"]["POSITION"]]
    positions["max"] = [0.0, 0.0, 0.0]  # bounds that do not hold
    (tmp_path / "broken.glb").write_bytes(repacked(doc, blob))
    intact = generic_export[1].read_bytes()
    assert repacked(*read_glb(intact)) != b"" and read_glb(repacked(*read_glb(intact)))[0] == read_glb(intact)[0]
    code, [report] = validate(node, tmp_path / "broken.glb")
    assert code == 1 and report["errors"] >= 1 and any("ACCESSOR_MAX_MISMATCH" in m for m in report["messages"]), report
