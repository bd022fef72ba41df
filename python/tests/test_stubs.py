"""The type stubs (python/clearway.pyi, installed beside the module) name what the module has, with its
parameters and defaults, and every public name of the module says what it promises (help() shows it)."""
import ast
import inspect
import pathlib
import pydoc
import re

import pytest

import clearway
from conftest import REPO

STUB = REPO / "python" / "clearway.pyi"


def stub_tree():
    return ast.parse(STUB.read_text())


def public(names):
    return {n for n in names if not n.startswith("_")}


def stub_members(node):
    """name -> list of FunctionDef (overloads) for a module or class body; properties and plain names too."""
    out = {}
    for item in node.body:
        if isinstance(item, (ast.FunctionDef, ast.ClassDef)):
            out.setdefault(item.name, []).append(item)
        elif isinstance(item, ast.AnnAssign) and isinstance(item.target, ast.Name):
            out.setdefault(item.target.id, []).append(item)
        elif isinstance(item, ast.Assign):
            for t in item.targets:
                if isinstance(t, ast.Name):
                    out.setdefault(t.id, []).append(item)
    return {k: v for k, v in out.items() if not k.startswith("_") or k == "__init__"}


def signature_of(doc):
    """(params, kwonly) from pybind11's first docstring line 'name(a: T, b: T = default, *, c: T = d) -> R'."""
    first = doc.strip().splitlines()[0]
    m = re.match(r"^\w+\((.*)\) -> .*$", first)
    assert m, first
    tree = ast.parse(f"def f({m.group(1)}): pass")
    return tree.body[0].args


def described(args):
    """[(name, default source or None, keyword-only)] without self."""
    out = []
    pos = args.posonlyargs + args.args
    defaults = [None] * (len(pos) - len(args.defaults)) + list(args.defaults)
    for a, d in zip(pos, defaults):
        out.append((a.arg, None if d is None else ast.unparse(d), False))
    for a, d in zip(args.kwonlyargs, args.kw_defaults):
        out.append((a.arg, None if d is None else ast.unparse(d), True))
    return [x for x in out if x[0] != "self"]


def same_default(stub, runtime):
    if stub == "...":  # a default the module computes where it runs (audit's threads: the hardware's)
        return runtime is not None
    if stub is None or runtime is None:
        return stub == runtime
    return ast.literal_eval(stub) == ast.literal_eval(runtime)


def check_callable(qualname, runtime, defs):
    want = described(signature_of(runtime.__doc__))
    got = described(defs[0].args)  # the first overload carries every parameter and default
    assert [(n, k) for n, _, k in got] == [(n, k) for n, _, k in want], f"{qualname}: stub {got} != module {want}"
    for (n, sd, _), (_, rd, _) in zip(got, want):
        assert same_default(sd, rd), f"{qualname}({n}=...): stub default {sd} != module default {rd}"
    for other in defs[1:]:
        assert {n for n, _, _ in described(other.args)} == {n for n, _, _ in want}, f"{qualname}: an overload differs"


def test_the_stubs_name_what_the_module_has():
    stubs = stub_members(stub_tree())
    assert public(dir(clearway)) == public(stubs), "module and stubs differ by " + str(
        public(dir(clearway)) ^ public(stubs))
    for name in public(dir(clearway)):
        obj = getattr(clearway, name)
        node = stubs[name][0]
        if inspect.isclass(obj):
            assert isinstance(node, ast.ClassDef), name
            if issubclass(obj, Exception):
                continue
            members = stub_members(node)
            # Inherited members are the base's (Shape's); the stub states them there.
            runtime = {n for n in vars(obj) if not n.startswith("_")}
            if "__init__" in vars(obj) and "instancemethod" in type(vars(obj)["__init__"]).__name__:
                runtime.add("__init__")
            assert runtime == set(members), f"{name}: module and stubs differ by {runtime ^ set(members)}"
            for m in runtime:
                value = inspect.getattr_static(obj, m)
                defs = members[m]
                if isinstance(value, property):
                    assert any(isinstance(d, ast.Name) and d.id == "property" for d in defs[0].decorator_list), \
                        f"{name}.{m} is a property"
                else:
                    if isinstance(value, staticmethod):
                        assert any(isinstance(d, ast.Name) and d.id == "staticmethod" for d in defs[0].decorator_list)
                    check_callable(f"{name}.{m}", getattr(obj, m), defs)
        elif callable(obj):
            assert isinstance(node, ast.FunctionDef), name
            check_callable(name, obj, stubs[name])


def test_every_public_name_says_what_it_promises():
    def promise(doc, what):
        # pybind11 puts the signature first; the promise follows it.
        text = (doc or "").strip()
        if re.match(r"^\w+\(.*\) -> ", text):
            text = text.split("\n", 1)[1].strip() if "\n" in text else ""
        assert len(text) >= 4, f"{what} has no docstring beyond its signature"
        return text

    for name in public(dir(clearway)):
        obj = getattr(clearway, name)
        if inspect.isclass(obj):
            promise(obj.__doc__, name)
            page = pydoc.render_doc(obj, renderer=pydoc.plaintext)
            for m in public(vars(obj)):
                value = inspect.getattr_static(obj, m)
                text = promise(value.__doc__ if isinstance(value, property) else getattr(obj, m).__doc__, f"{name}.{m}")
                # help(clearway.NAME) shows it (wrapped lines aside).
                assert " ".join(text.split()[:6]) in " ".join(page.split()), f"help({name}) lacks {m}'s promise"
        elif callable(obj):
            promise(obj.__doc__, name)


def test_the_stubs_are_beside_the_module_when_installed_or_built():
    # The build tree and every install route put clearway.pyi next to the extension, where editors look.
    beside = pathlib.Path(clearway.__file__).with_name("clearway.pyi")
    if not beside.exists():
        pytest.fail(f"{beside} is missing: the stubs are not beside the module")
    assert beside.read_text() == STUB.read_text()
