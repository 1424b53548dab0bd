"""The stub ``__init__.pyi`` (installed beside the package) declares exactly what the module
exports: the names of ``__all__`` and every public method and property of its classes."""

import ast
import os

import dhcd


def stub():
    path = os.path.join(os.path.dirname(dhcd.__file__), "__init__.pyi")
    with open(path) as f:
        return ast.parse(f.read())


def test_stub_declares_the_exports():
    tree = stub()
    declared = set()
    for node in tree.body:
        if isinstance(node, (ast.ClassDef, ast.FunctionDef)):
            declared.add(node.name)
        elif isinstance(node, ast.AnnAssign):
            declared.add(node.target.id)
        elif isinstance(node, ast.Assign) and node.targets[0].id == "__all__":
            listed = [e.value for e in node.value.elts]
    assert sorted(listed) == sorted(dhcd.__all__)
    assert set(dhcd.__all__) <= declared


def test_stub_classes_match_the_module():
    for node in stub().body:
        if not isinstance(node, ast.ClassDef):
            continue
        members = {f.name for f in node.body if isinstance(f, ast.FunctionDef)}
        public = {m for m in members if not m.startswith("_")}
        real = {m for m in dir(getattr(dhcd, node.name)) if not m.startswith("_")}
        assert public == real, node.name
