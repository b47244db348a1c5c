"""The stubs of the private native module (_core.pyi) match the built module."""

import ast
import inspect
from pathlib import Path

from facemime import _core

STUB = Path(__file__).resolve().parents[1] / "python" / "facemime" / "_core.pyi"


def stub_items():
    """(functions -> parameter names, classes -> {method -> parameter names}, other names)."""
    tree = ast.parse(STUB.read_text())
    params = lambda f: [a.arg for a in f.args.args]  # noqa: E731
    funcs = {n.name: params(n) for n in tree.body if isinstance(n, ast.FunctionDef)}
    classes = {
        n.name: {m.name: params(m) for m in n.body if isinstance(m, ast.FunctionDef)}
        for n in tree.body
        if isinstance(n, ast.ClassDef)
    }
    names = {n.target.id for n in tree.body if isinstance(n, ast.AnnAssign)}
    return funcs, classes, names


def test_stubs_list_exactly_the_module_contents():
    funcs, classes, names = stub_items()
    public = {n for n in dir(_core) if not n.startswith("_")} | {"__version__"}
    assert set(funcs) | set(classes) | names == public


def test_stub_signatures_match():
    funcs, classes, _ = stub_items()
    for name, params in funcs.items():
        assert list(inspect.signature(getattr(_core, name)).parameters) == params, name
    for cls, methods in classes.items():
        for method, params in methods.items():
            if method == "__init__":
                assert ["self", *inspect.signature(getattr(_core, cls)).parameters] == params, cls
            else:
                assert list(inspect.signature(getattr(getattr(_core, cls), method)).parameters) == params, (cls, method)
