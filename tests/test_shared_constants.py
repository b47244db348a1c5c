"""The constants the Python synthesis and the browser receiver share come from one source,
shared_constants.toml: the generated Python and TypeScript modules are current, and an edit of the
source reaches both, documented."""

from __future__ import annotations

import importlib.machinery
import importlib.util
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
TOOL = ROOT / "tools" / "shared_constants"
_loader = importlib.machinery.SourceFileLoader("shared_constants_tool", str(TOOL))
_spec = importlib.util.spec_from_loader(_loader.name, _loader)
assert _spec is not None
tool = importlib.util.module_from_spec(_spec)
_loader.exec_module(tool)


def test_the_generated_modules_are_current():
    done = subprocess.run([sys.executable, str(TOOL), "--check"], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr


def test_an_edit_of_the_source_reaches_both_sides_with_its_documentation():
    text = tool.SOURCE.read_text(encoding="utf-8").replace("SEAL = 0.05", "SEAL = 0.07")
    text += '\n# Two lines\n# of documentation.\nNEW_NAMES = ["a", "b"]\n'
    python, typescript = tool.python_module(text), tool.typescript_module(text)
    assert "\nSEAL = 0.07\n" in python and "\nexport const SEAL = 0.07;\n" in typescript
    assert '#: Two lines\n#: of documentation.\nNEW_NAMES = ("a", "b")\n' in python
    assert '/** Two lines\n * of documentation. */\nexport const NEW_NAMES = ["a", "b"] as const;\n' in typescript
    namespace: dict = {}
    exec(python, namespace)  # the Python module is valid Python holding the values
    assert namespace["SEAL"] == 0.07 and namespace["RINGS"] == ((1.2, 1.0), (1.7, 0.0))
