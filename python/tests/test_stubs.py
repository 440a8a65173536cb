"""The type stubs (python/strata/_strata.pyi) describe what the compiled module holds."""

import ast
import inspect
import pathlib

import strata
from strata import _strata

STUB = pathlib.Path(strata.__file__).with_name("_strata.pyi")


def stub_names():
    tree = ast.parse(STUB.read_text())
    names, members = set(), {}
    for node in tree.body:
        if isinstance(node, (ast.FunctionDef, ast.ClassDef)):
            names.add(node.name)
        if isinstance(node, ast.ClassDef):
            members[node.name] = {
                n.name if isinstance(n, ast.FunctionDef) else n.target.id
                for n in node.body
                if isinstance(n, ast.FunctionDef) or (isinstance(n, ast.AnnAssign))
            }
    return names, members


def test_stub_lists_every_name_of_the_module_and_no_other():
    names, _ = stub_names()
    module = {n for n in dir(_strata) if not n.startswith("__")}
    assert names == module


def test_stub_classes_list_their_members():
    _, members = stub_names()
    for cls, listed in members.items():
        real = {n for n in dir(getattr(_strata, cls)) if not n.startswith("_")}
        if issubclass(getattr(_strata, cls), BaseException):
            continue
        assert real == {n for n in listed if not n.startswith("_")}, cls


def test_public_functions_have_documented_defaults():
    for name in ("simplify", "untangle", "check", "slice", "sample_field", "scene_from_arrays"):
        fn = getattr(strata, name)
        assert fn.__doc__ and len(fn.__doc__) > 200, name
        for p in inspect.signature(fn).parameters.values():
            if p.default is not inspect.Parameter.empty and p.default is not None:
                # every keyword with a default value names it (or its meaning) in the doc
                assert p.name in fn.__doc__, (name, p.name)
