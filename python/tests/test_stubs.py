"""The .pyi stubs installed beside the modules list exactly their public names and parameters."""

import ast
import importlib
import re
from pathlib import Path

import pytest

import tetseg


def stub_of(module):
    path = Path(module.__file__).parent / (module.__name__.rsplit(".", 1)[1] + ".pyi")
    return ast.parse(path.read_text())


def public(obj):
    names = {n for n in dir(obj) if not n.startswith("_") or n == "__version__"}
    constructor = getattr(obj, "__init__", None)
    if (constructor.__doc__ or "").startswith("__init__("):  # a pybind11 constructor
        names.add("__init__")
    return names


def pybind_params(function):
    """Parameter names from the signature line pybind11 puts first in a docstring."""
    signature = function.__doc__.splitlines()[0]
    params = signature[signature.index("(") + 1:signature.rindex(") ->")]
    return [n for n in re.findall(r"(?:^|, )(?:\*, )?(\w+): ", params) if n != "self"]


def stub_params(node):
    return [a.arg for a in node.args.args + node.args.kwonlyargs if a.arg != "self"]


def check_names_and_params(obj, body):
    stubbed = {}
    for node in body:
        if isinstance(node, (ast.FunctionDef, ast.ClassDef)):
            stubbed[node.name] = node
        elif isinstance(node, ast.AnnAssign):
            stubbed[node.target.id] = node
    if isinstance(obj, type) and issubclass(obj, BaseException):
        return  # exception classes: their attributes are set per instance
    names = public(obj)
    assert names == set(stubbed), (obj, names ^ set(stubbed))
    for name, node in stubbed.items():
        value = getattr(obj, name)
        if isinstance(node, ast.FunctionDef) and callable(value) and value.__doc__:
            if not any(isinstance(d, ast.Name) and d.id == "property" for d in node.decorator_list):
                assert pybind_params(value) == stub_params(node), name
        if isinstance(node, ast.ClassDef):
            check_names_and_params(value, node.body)


def test_runtime_stubs_match_the_module():
    check_names_and_params(tetseg._runtime, stub_of(tetseg._runtime).body)


@pytest.mark.preprocess
def test_preprocess_stubs_match_the_module():
    module = importlib.import_module("tetseg.preprocess")
    check_names_and_params(module, stub_of(module).body)
