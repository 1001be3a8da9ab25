"""python/armdyn has no import cycles, counting the imports that run inside functions.

The graph is read from the source with :mod:`ast`, nothing is imported. An edge
``a -> b`` is any import statement in module ``a`` that loads module ``b`` when it runs:
at module level, inside functions and methods, inside ``try``/``if`` blocks, and
``importlib.import_module("literal")`` calls. Imports under ``if TYPE_CHECKING:`` are left
out: they never run (only type checkers read them), so they cannot take part in a cycle.
``from pkg import name`` is an import of ``pkg.name`` when that is a submodule, of ``pkg``
otherwise; relative imports are resolved against the importing module's package. Parent
packages that Python initialises on the way to a submodule are not edges: a package's
``__init__`` is always already loading when one of its submodules runs.

A cycle is a strongly connected component of more than one module (Tarjan's algorithm);
the failure lists each with the edges inside it and the lines that make them. The second
test proves the detector can fail, on a small package written to ``tmp_path``.

The same walk checks that no module imports another module's private name
(``from x import _name``): a name used across modules is public, or lives where it is used.
"""

from __future__ import annotations

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
PACKAGE_DIR = ROOT / "python" / "armdyn"


def module_names(package_dir: Path) -> dict[str, Path | None]:
    """Every module under ``package_dir``: dotted name -> file (a package is its ``__init__.py``).

    Compiled extensions (``armdyn._core``: a ``.so`` and its ``.pyi`` stub) are modules too,
    so that ``from . import _core`` is an import of ``armdyn._core``, not of ``armdyn``; they
    import nothing of ours, and are mapped to no source (``None``).
    """
    top = package_dir.name
    modules: dict[str, Path | None] = {}
    for path in sorted(package_dir.rglob("*")):
        if path.suffix not in (".py", ".pyi", ".so", ".pyd"):
            continue
        relative = path.relative_to(package_dir)
        parts = [top, *relative.parent.parts, path.name.split(".")[0]]
        if parts[-1] == "__init__":
            parts.pop()
        name = ".".join(parts)
        if path.suffix == ".py":
            modules[name] = path
        else:
            modules.setdefault(name, None)
    return modules


def _is_type_checking(test: ast.expr) -> bool:
    """``if TYPE_CHECKING:`` or ``if typing.TYPE_CHECKING:``."""
    return (isinstance(test, ast.Name) and test.id == "TYPE_CHECKING") or (
        isinstance(test, ast.Attribute) and test.attr == "TYPE_CHECKING"
    )


def _runtime_nodes(tree: ast.AST):
    """All nodes of ``tree`` except the bodies of ``if TYPE_CHECKING:`` (their ``else`` runs)."""
    stack = [tree]
    while stack:
        node = stack.pop()
        yield node
        if isinstance(node, ast.If) and _is_type_checking(node.test):
            stack.extend(node.orelse)
            continue
        stack.extend(ast.iter_child_nodes(node))


def _resolve(module: str, is_package: bool, level: int, target: str | None) -> str:
    """The absolute module a (possibly relative) import in ``module`` names."""
    if level == 0:
        return target or ""
    base = module.split(".") if is_package else module.split(".")[:-1]
    base = base[: len(base) - (level - 1)]
    return ".".join([*base, target] if target else base)


def _import_module_target(call: ast.Call, module: str, is_package: bool) -> str | None:
    """The module an ``importlib.import_module("...")`` call with a literal name loads."""
    func = call.func
    name = func.attr if isinstance(func, ast.Attribute) else func.id if isinstance(func, ast.Name) else ""
    if name != "import_module" or not call.args:
        return None
    first = call.args[0]
    if not (isinstance(first, ast.Constant) and isinstance(first.value, str)):
        return None  # a computed name (lazy attribute tables): not knowable from the source
    text = first.value
    level = len(text) - len(text.lstrip("."))
    if not level:
        return text
    # a relative name is resolved against the second argument, a package name
    anchor = call.args[1] if len(call.args) > 1 else None
    if isinstance(anchor, ast.Constant) and isinstance(anchor.value, str):
        package = anchor.value
    elif isinstance(anchor, ast.Name) and anchor.id in ("__name__", "__package__"):
        package = module if (is_package or anchor.id == "__name__") else module.rpartition(".")[0]
    else:
        return None
    return _resolve(package, True, level, text[level:] or None)


def import_edges(package_dir: Path):
    """Runtime imports between the package's own modules.

    Returns ``(edges, private)``: ``edges`` maps ``(importer, imported)`` to the line
    numbers of the imports, ``private`` lists ``(importer, line, module, name)`` for each
    ``from module import _name`` of another module's private name.
    """
    modules = module_names(package_dir)
    edges: dict[tuple[str, str], list[int]] = {}
    private: list[tuple[str, int, str, str]] = []

    def add(importer: str, target: str, line: int) -> None:
        # `import a.b.c` loads a.b.c; keep the longest prefix that is one of ours
        while target and target not in modules:
            target = target.rpartition(".")[0]
        if target and target != importer:
            lines = edges.setdefault((importer, target), [])
            if line not in lines:
                lines.append(line)

    for name, path in modules.items():
        if path is None:
            continue  # a compiled extension
        is_package = path.name == "__init__.py"
        tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
        for node in _runtime_nodes(tree):
            if isinstance(node, ast.Import):
                for alias in node.names:
                    add(name, alias.name, node.lineno)
            elif isinstance(node, ast.ImportFrom):
                source = _resolve(name, is_package, node.level, node.module)
                if source not in modules:
                    continue  # a third-party or standard module
                for alias in node.names:
                    submodule = f"{source}.{alias.name}"
                    if submodule in modules:
                        add(name, submodule, node.lineno)
                    else:
                        add(name, source, node.lineno)
                        if alias.name.startswith("_") and not alias.name.startswith("__") and source != name:
                            private.append((name, node.lineno, source, alias.name))
            elif isinstance(node, ast.Call):
                target = _import_module_target(node, name, is_package)
                if target:
                    add(name, target, node.lineno)
    return edges, private


def strongly_connected_components(graph: dict[str, set[str]]) -> list[list[str]]:
    """Tarjan's algorithm, iterative (no recursion limit): the components, each sorted."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    on_stack: set[str] = set()
    stack: list[str] = []
    components = []
    for root in sorted(graph):
        if root in index:
            continue
        work = [(root, iter(sorted(graph.get(root, ()))))]
        index[root] = low[root] = len(index)
        stack.append(root)
        on_stack.add(root)
        while work:
            node, successors = work[-1]
            for succ in successors:
                if succ not in index:
                    index[succ] = low[succ] = len(index)
                    stack.append(succ)
                    on_stack.add(succ)
                    work.append((succ, iter(sorted(graph.get(succ, ())))))
                    break
                if succ in on_stack:
                    low[node] = min(low[node], index[succ])
            else:
                work.pop()
                if work:
                    parent = work[-1][0]
                    low[parent] = min(low[parent], low[node])
                if low[node] == index[node]:
                    component = []
                    while True:
                        member = stack.pop()
                        on_stack.discard(member)
                        component.append(member)
                        if member == node:
                            break
                    components.append(sorted(component))
    return components


def import_cycles(package_dir: Path) -> list[str]:
    """One text per cycle: its modules, then each edge inside it with file lines."""
    edges, _ = import_edges(package_dir)
    graph: dict[str, set[str]] = {}
    for a, b in edges:
        graph.setdefault(a, set()).add(b)
        graph.setdefault(b, set())
    found = []
    for component in strongly_connected_components(graph):
        if len(component) < 2:
            continue
        members = set(component)
        lines = [f"cycle of {len(component)} modules: {', '.join(component)}"]
        for (a, b), at in sorted(edges.items()):
            if a in members and b in members:
                lines.append(f"    {a} -> {b}  (line {', '.join(map(str, sorted(at)))})")
        found.append("\n".join(lines))
    return found


def test_armdyn_has_no_import_cycles():
    edges, _ = import_edges(PACKAGE_DIR)
    assert len(edges) > 100, "the walk found almost no imports: the detector is broken"
    cycles = import_cycles(PACKAGE_DIR)
    assert not cycles, "import cycles in python/armdyn:\n" + "\n".join(cycles)


def test_no_module_imports_another_modules_private_name():
    _, private = import_edges(PACKAGE_DIR)
    listed = [f"{importer} line {line}: from {module} import {name}" for importer, line, module, name in private]
    assert not listed, "private names imported across modules:\n" + "\n".join(listed)


def _write(root: Path, files: dict[str, str]) -> Path:
    for relative, text in files.items():
        path = root / relative
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text, encoding="utf-8")
    return root / "pkg"


def test_the_detector_finds_known_cycles(tmp_path):
    package = _write(
        tmp_path,
        {
            # pkg -> pkg.a -> pkg.b -> pkg (a name from the package's __init__), module level
            "pkg/__init__.py": "from .a import thing\n",
            "pkg/a.py": "from . import b\nthing = 1\n",
            "pkg/b.py": "from pkg import thing\n",
            # pkg.sub.x <-> pkg.sub.y, one direction only inside a method
            "pkg/sub/__init__.py": "",
            "pkg/sub/x.py": "from .y import Y\nclass X:\n    def f(self):\n        from ..sub import x_helper\n",
            "pkg/sub/y.py": "class Y:\n    def g(self):\n        from .x import X\n        return X\n",
            "pkg/sub/x_helper.py": "",
            # pkg.lazy -> pkg.c by importlib, pkg.c -> pkg.lazy: a cycle
            "pkg/lazy.py": "import importlib\n\ndef load():\n    return importlib.import_module('.c', 'pkg')\n",
            "pkg/c.py": "import pkg.lazy\n",
            # under TYPE_CHECKING only: never runs, no cycle
            "pkg/t1.py": "from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n    from .t2 import T2\n",
            "pkg/t2.py": "from . import t1\nclass T2: ...\n",
            # a private name across modules
            "pkg/p.py": "from .a import _hidden\n",
        },
    )
    cycles = import_cycles(package)
    assert len(cycles) == 3, "\n".join(cycles)
    text = "\n".join(cycles)
    assert "cycle of 3 modules: pkg, pkg.a, pkg.b" in text
    assert "pkg.b -> pkg  (line 1)" in text
    assert "cycle of 2 modules: pkg.sub.x, pkg.sub.y" in text
    assert "pkg.sub.y -> pkg.sub.x  (line 3)" in text  # the function-level import
    assert "cycle of 2 modules: pkg.c, pkg.lazy" in text
    assert "pkg.lazy -> pkg.c  (line 4)" in text
    assert "t1" not in text and "t2" not in text
    # from ..sub import x_helper is the submodule pkg.sub.x_helper, not the package pkg.sub
    edges, private = import_edges(package)
    assert ("pkg.sub.x", "pkg.sub.x_helper") in edges and ("pkg.sub.x", "pkg.sub") not in edges
    assert private == [("pkg.p", 1, "pkg.a", "_hidden")]


def test_a_cycle_made_only_of_a_function_level_import_is_found(tmp_path):
    package = _write(
        tmp_path,
        {
            "pkg/__init__.py": "",
            "pkg/model.py": "def load():\n    from .reader import read\n    return read()\n",
            "pkg/reader.py": "from .model import load\n\ndef read():\n    return load\n",
        },
    )
    assert import_cycles(package) == [
        "cycle of 2 modules: pkg.model, pkg.reader\n"
        "    pkg.model -> pkg.reader  (line 2)\n"
        "    pkg.reader -> pkg.model  (line 1)"
    ]
    (package / "model.py").write_text("def load():\n    return None\n", encoding="utf-8")
    assert import_cycles(package) == []
