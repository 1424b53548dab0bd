"""The stub ``__init__.pyi`` (installed beside the package) declares exactly what the module
exports: the names of ``__all__``, every public method and property of its classes, and the
parameters of its functions."""

import ast
import inspect
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


def declared_parameters(node):
    """(name, kind, default) of each parameter of a stub function; `inspect._empty` for no
    default."""
    a = node.args
    positional = a.posonlyargs + a.args
    defaults = [inspect.Parameter.empty] * (len(positional) - len(a.defaults)) + [
        ast.literal_eval(d) for d in a.defaults
    ]
    out = [(p.arg, "POSITIONAL_OR_KEYWORD", d) for p, d in zip(positional, defaults)]
    if a.vararg:
        out.append((a.vararg.arg, "VAR_POSITIONAL", inspect.Parameter.empty))
    for p, d in zip(a.kwonlyargs, a.kw_defaults):
        default = inspect.Parameter.empty if d is None else ast.literal_eval(d)
        out.append((p.arg, "KEYWORD_ONLY", default))
    return out


def test_stub_functions_match_the_module():
    # Every function's parameters (names, kinds, defaults) are the module's signature; of an
    # overloaded function (`ccd`), the first overload is the signature the module reports.
    seen = set()
    for node in stub().body:
        if not isinstance(node, ast.FunctionDef) or node.name in seen:
            continue
        seen.add(node.name)
        real = inspect.signature(getattr(dhcd, node.name))
        actual = [(p.name, p.kind.name, p.default) for p in real.parameters.values()]
        assert declared_parameters(node) == actual, node.name
    assert {"ccd", "vertex_face_ccd", "edge_edge_ccd", "proximity"} <= seen
