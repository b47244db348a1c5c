"""The stubs of the private native module (_core.pyi) match the built module."""

import ast
import inspect
from pathlib import Path

from facemime import _core

STUB = Path(__file__).resolve().parents[1] / "python" / "facemime" / "_core.pyi"


def stub_items():
    tree = ast.parse(STUB.read_text())
    funcs = {n.name: [a.arg for a in n.args.args] for n in tree.body if isinstance(n, ast.FunctionDef)}
    names = {t.id for n in tree.body if isinstance(n, ast.AnnAssign) for t in [n.target]}
    return funcs, names


def test_stubs_list_exactly_the_module_contents():
    funcs, names = stub_items()
    public = {n for n in dir(_core) if not n.startswith("_")} | {"__version__"}
    assert set(funcs) | names == public


def test_stub_signatures_match():
    funcs, _ = stub_items()
    for name, params in funcs.items():
        assert list(inspect.signature(getattr(_core, name)).parameters) == params, name
