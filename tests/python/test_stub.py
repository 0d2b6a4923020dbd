# python/rvr.pyi against the module it describes: every name of the one is in the other, each
# function and method takes the same parameters (names, positional or keyword-only, defaults),
# each property is settable in both or neither, and every docstring is the stub's (the build
# takes them from it: python/stub_docs.py). Types are not compared: pybind11 spells them after
# the C++ types (object, numpy.ndarray[numpy.float32]) where the stub says what is accepted.
import ast
import inspect
import os
import pathlib

import pytest

import rvr

STUB = pathlib.Path(os.environ["RVR_SOURCE_DIR"]) / "python" / "rvr.pyi"


def stub_tree():
    return ast.parse(STUB.read_text(), filename=str(STUB))


def is_typed_dict(node):
    return any(isinstance(b, ast.Name) and b.id == "TypedDict" for b in node.bases)


def parameters(args, skip_self):
    """[(name, kind, default)] of an ast.arguments; default is the value, or inspect.Parameter.empty."""
    out = []
    positional = args.posonlyargs + args.args
    defaults = [inspect.Parameter.empty] * (len(positional) - len(args.defaults)) + [
        ast.literal_eval(d) for d in args.defaults]
    for a, d in zip(positional, defaults):
        out.append((a.arg, "positional", d))
    if args.vararg:
        out.append(("*" + args.vararg.arg, "var_positional", inspect.Parameter.empty))
    for a, d in zip(args.kwonlyargs, args.kw_defaults):
        out.append((a.arg, "keyword_only",
                    inspect.Parameter.empty if d is None else ast.literal_eval(d)))
    if args.kwarg:
        out.append(("**", "var_keyword", inspect.Parameter.empty))  # its name is free
    if skip_self:
        assert out and out[0][0] == "self", "a method takes self first"
        out = out[1:]
    return [(n, k, list(d) if isinstance(d, tuple) else d) for n, k, d in out]


def module_signature(function, skip_self):
    """The parameters and docstring of a pybind11 function, from the signature line pybind11
    puts first in its __doc__."""
    doc = function.__doc__
    line, _, rest = doc.partition("\n")
    tree = ast.parse("def " + line + ": pass")
    params = parameters(tree.body[0].args, skip_self)
    return params, rest.lstrip("\n").removesuffix("\n")  # pybind11 ends it with a newline


def stub_docstring(node):
    return ast.get_docstring(node, clean=True)


def check_function(stub_node, function, skip_self, where):
    stub_params = parameters(stub_node.args, skip_self)
    params, doc = module_signature(function, skip_self)
    assert params == stub_params, f"{where}: module {params} != stub {stub_params}"
    assert doc == stub_docstring(stub_node), f"{where}: the docstring is not the stub's"


def stub_items():
    """The module-level functions, classes and annotated names of the stub."""
    tree = stub_tree()
    functions, classes, names = {}, {}, set()
    for node in tree.body:
        if isinstance(node, ast.FunctionDef):
            functions[node.name] = node
        elif isinstance(node, ast.ClassDef) and not is_typed_dict(node):
            classes[node.name] = node
        elif isinstance(node, ast.AnnAssign):
            names.add(node.target.id)
    return tree, functions, classes, names


def test_module_docstring_is_the_stubs():
    assert rvr.__doc__ == ast.get_docstring(stub_tree(), clean=True)


def test_every_name_is_in_both():
    _, functions, classes, names = stub_items()
    stub_names = set(functions) | set(classes) | names
    module_names = {n for n in dir(rvr) if not (n.startswith("__") and n != "__version__")}
    assert module_names == stub_names


def test_functions_match():
    _, functions, _, _ = stub_items()
    for name, node in functions.items():
        check_function(node, getattr(rvr, name), False, f"rvr.{name}")


def test_classes_match():
    _, _, classes, _ = stub_items()
    for class_name, node in classes.items():
        cls = getattr(rvr, class_name)
        assert cls.__doc__ == stub_docstring(node), f"rvr.{class_name}: docstring"
        members = {}
        setters = set()
        for member in node.body:
            if not isinstance(member, ast.FunctionDef):
                continue
            decorators = [ast.unparse(d) for d in member.decorator_list]
            if any(d.endswith(".setter") for d in decorators):
                setters.add(member.name)
                continue
            members[member.name] = (member, decorators)
        # A class without a constructor (rvr.Render: made only by rvr.render) has the slot
        # wrapper pybind11 puts there to refuse construction, not a bound __init__.
        bound_init = type(vars(cls).get("__init__")).__name__ == "instancemethod"
        own = {n for n in vars(cls) if not n.startswith("__") or (n == "__init__" and bound_init)}
        if issubclass(cls, BaseException):
            assert not members, f"rvr.{class_name}: an exception with members"
            continue
        assert own == set(members), f"rvr.{class_name}: module {sorted(own)} != stub {sorted(members)}"
        for name, (member, decorators) in members.items():
            where = f"rvr.{class_name}.{name}"
            value = vars(cls)[name]
            if "property" in decorators:
                assert isinstance(value, property), f"{where}: not a property"
                assert value.__doc__ == stub_docstring(member), f"{where}: docstring"
                assert (value.fset is not None) == (name in setters), f"{where}: settable"
            elif "staticmethod" in decorators:
                assert isinstance(value, staticmethod), f"{where}: not a static method"
                check_function(member, getattr(cls, name), False, where)
            else:
                check_function(member, value, True, where)


def test_the_checks_catch_a_difference(monkeypatch):
    # The comparison itself, on a stub with one default changed and one docstring changed.
    node = stub_items()[1]["study"]
    changed = ast.parse(ast.unparse(node).replace("width: int=1024", "width: int=512")).body[0]
    with pytest.raises(AssertionError, match="module .* != stub"):
        check_function(changed, rvr.study, False, "rvr.study")
    changed = ast.parse(ast.unparse(node).replace("Runs `rvr study`", "Runs")).body[0]
    with pytest.raises(AssertionError, match="docstring"):
        check_function(changed, rvr.study, False, "rvr.study")
