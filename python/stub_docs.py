"""Writes the docstrings of python/rvr.pyi as a C++ header for the bindings, so that help() and
the type stubs say the same thing from one source.

    stub_docs.py rvr.pyi stub_docs.h

Each docstring becomes `rvr::python::docs::NAME`: a module-level function or class by its name,
a class member as CLASS_MEMBER, the module's own as `module`; leading, trailing and doubled
underscores are dropped (`Scene.__init__` is Scene_init, `_repr_png_` repr_png). A binding
that names a docstring the stub does not have fails to compile."""
import ast
import os
import re
import sys


def identifier(*parts):
    name = "_".join(re.sub(r"_+", "_", p).strip("_") for p in parts)
    if not re.fullmatch(r"[A-Za-z][A-Za-z0-9_]*", name):
        raise SystemExit(f"stub_docs: no C++ name for {'.'.join(parts)}")
    return name


def docstrings(tree):
    """(name, docstring) of the module, its functions and classes, and the classes' members."""
    module_doc = ast.get_docstring(tree, clean=True)
    if module_doc:
        yield "module", module_doc
    for node in tree.body:
        if isinstance(node, ast.FunctionDef):
            doc = ast.get_docstring(node, clean=True)
            if doc:
                yield identifier(node.name), doc
        elif isinstance(node, ast.ClassDef):
            doc = ast.get_docstring(node, clean=True)
            if doc:
                yield identifier(node.name), doc
            for member in node.body:
                if isinstance(member, ast.FunctionDef):
                    doc = ast.get_docstring(member, clean=True)
                    if doc:
                        yield identifier(node.name, member.name), doc


def main(stub, header):
    with open(stub, encoding="utf-8") as f:
        tree = ast.parse(f.read(), filename=stub)
    seen = set()
    lines = [
        f"// Generated from {stub.rsplit('/', 1)[-1]} by python/stub_docs.py: do not edit.",
        "#pragma once",
        "",
        "namespace rvr::python::docs {",
        "",
    ]
    for name, doc in docstrings(tree):
        if name in seen:
            raise SystemExit(f"stub_docs: two docstrings for {name}")
        if ")rvrdoc\"" in doc:
            raise SystemExit(f"stub_docs: {name}'s docstring ends the raw string")
        seen.add(name)
        lines.append(f'inline constexpr char {name}[] = R"rvrdoc({doc})rvrdoc";')
    lines += ["", "}  // namespace rvr::python::docs", ""]
    text = "\n".join(lines)
    try:
        with open(header, encoding="utf-8") as f:
            if f.read() == text:
                return  # unchanged: nothing recompiled
    except FileNotFoundError:
        pass
    os.makedirs(os.path.dirname(os.path.abspath(header)), exist_ok=True)
    with open(header, "w", encoding="utf-8") as f:
        f.write(text)


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
