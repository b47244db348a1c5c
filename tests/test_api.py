"""The public API (``facemime.__all__``): every name is there, ``import facemime`` stays light,
and the README's examples use only these names and run on a real photo and video."""

import re
import subprocess
import sys
from pathlib import Path

import numpy as np

import facemime

README = Path(__file__).resolve().parents[1] / "README.md"


def test_every_public_name_resolves_to_its_module_object():
    for name in facemime.__all__:
        value = getattr(facemime, name)
        assert value is not None, name
        module = facemime._API.get(name)
        if module is not None:
            assert value is getattr(__import__(module, fromlist=[name]), name)
    assert set(facemime.__all__) <= set(dir(facemime))


def test_import_facemime_loads_none_of_the_heavy_modules():
    code = (
        "import sys, facemime; print(sorted(m for m in ('cv2', 'av', 'click', 'facemime.animate') if m in sys.modules))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "[]"


def test_the_readme_uses_only_public_names():
    used = set(re.findall(r"facemime\.(\w+)", "\n".join(re.findall(r"```python\n(.*?)```", README.read_text(), re.S))))
    assert used and used <= set(facemime.__all__), used - set(facemime.__all__)


def test_the_readme_examples_run_on_a_real_photo_and_video(shared, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "me.jpg").write_bytes((shared / "photos" / "lp_s1.jpg").read_bytes())
    (tmp_path / "talk.mp4").write_bytes((shared / "video" / "lp_d0.mp4").read_bytes())
    blocks = re.findall(r"```python\n(.*?)```", README.read_text(), re.S)
    assert len(blocks) == 2
    exec(blocks[0], {})
    for name in ("me.actor", "talk.track.json", "talk.run.mp4", "talk.fmstream", "talk.decoded.mp4"):
        assert (tmp_path / name).stat().st_size > 0, name
    (tmp_path / "me.actor").unlink()
    scope: dict = {}
    exec(blocks[1], scope)
    motion = scope["motion"]
    assert motion.face and np.isfinite(motion.offsets).all() and (tmp_path / "me.actor").exists()
