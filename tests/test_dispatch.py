"""armdyn.dispatch: the data classes' display methods reach renderers registered by the
layers above them (see "Where display lives" in docs/architecture.md).

The registry itself is checked on classes made here; the wiring is checked from the
source: every ``call("kind", ...)`` in a data module must find a registration once the
module's package is imported, in a fresh interpreter that imports nothing else."""

from __future__ import annotations

import ast
import json
import subprocess
import sys
from pathlib import Path

import pytest

from armdyn import dispatch

ROOT = Path(__file__).resolve().parent.parent
PACKAGE = ROOT / "python" / "armdyn"


def test_the_nearest_registered_class_wins_and_a_missing_kind_is_named():
    class Shape:
        pass

    class Square(Shape):
        pass

    class Tile(Square):
        pass

    @dispatch.register("test-describe", Shape)
    def shape(obj, suffix=""):
        return "shape" + suffix

    @dispatch.register("test-describe", Square)
    def square(obj, suffix=""):
        return "square" + suffix

    try:
        assert dispatch.call("test-describe", Shape()) == "shape"
        assert dispatch.call("test-describe", Tile(), suffix="!") == "square!"  # Square is nearer than Shape
        assert dispatch.call("test-describe", Tile) == "square"  # a class: its own MRO (classmethods)
        with pytest.raises(LookupError, match=r"no 'test-other' registered for Tile"):
            dispatch.call("test-other", Tile())
    finally:  # the table is process-wide: leave it as found
        del dispatch._TABLE[("test-describe", Shape)], dispatch._TABLE[("test-describe", Square)]


def test_the_registry_imports_nothing_of_armdyn():
    tree = ast.parse((PACKAGE / "dispatch.py").read_text(encoding="utf-8"))
    imported = [
        n.module if isinstance(n, ast.ImportFrom) else a.name
        for n in ast.walk(tree)
        if isinstance(n, (ast.Import, ast.ImportFrom))
        for a in n.names
    ]
    assert imported and all(m and not m.startswith("armdyn") for m in imported), imported
    assert not any(isinstance(n, ast.ImportFrom) and n.level for n in ast.walk(tree))


def _calls_in_data_modules() -> set[tuple[str, str]]:
    """``(kind, module.Class)`` for every ``call("kind", self or cls, ...)`` in a class body."""
    found = set()
    for path in PACKAGE.rglob("*.py"):
        tree = ast.parse(path.read_text(encoding="utf-8"))
        module = ".".join(["armdyn", *path.relative_to(PACKAGE).with_suffix("").parts]).removesuffix(".__init__")
        for cls in (n for n in ast.walk(tree) if isinstance(n, ast.ClassDef)):
            for node in ast.walk(cls):
                if (
                    isinstance(node, ast.Call)
                    and isinstance(node.func, ast.Name)
                    and node.func.id == "call"
                    and node.args
                    and isinstance(node.args[0], ast.Constant)
                ):
                    found.add((node.args[0].value, f"{module}.{cls.name}"))
    return found


def test_every_dispatched_method_finds_its_renderer_in_a_fresh_interpreter():
    wanted = _calls_in_data_modules()
    # the four data classes and their methods: _repr_html_ (3 + GradeReport), _repr_latex_,
    # from_urdf, GradeReport's text, to_dict, to_json
    assert len(wanted) == 9, sorted(wanted)
    modules = sorted({name.rpartition(".")[0] for _, name in wanted})
    script = (
        "import importlib, json, sys\n"
        f"for m in {modules!r}: importlib.import_module(m)\n"
        "from armdyn import dispatch\n"
        "print(json.dumps(dispatch.registered()))\n"
    )
    env = {"PYTHONPATH": str(ROOT / "python"), "PATH": "/usr/bin:/bin"}
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, env=env, timeout=300)
    assert done.returncode == 0, done.stderr[-2000:]
    registered = {tuple(pair) for pair in json.loads(done.stdout)}
    assert wanted <= registered, sorted(wanted - registered)


def test_the_methods_give_what_the_renderers_give():
    import armdyn
    from armdyn.grading.html import repr_html
    from armdyn.grading.text import text, to_json
    from armdyn.io.urdf import load_urdf
    from armdyn.symbolic.report import eom_latex
    from armdyn.symbolic.report_html import agreement_html, eom_html, robot_html

    robot = armdyn.load("rp-arm")
    eom = armdyn.derive(robot)
    agreement = armdyn.check(eom, armdyn.derive(robot, "lagrange"))
    assert robot._repr_html_() == robot_html(robot) and "<table" in robot_html(robot)
    assert eom._repr_html_() == eom_html(eom) and "<math" in eom_html(eom)
    assert eom._repr_latex_() == eom_latex(eom) and eom_latex(eom).startswith("$$\\begin{aligned}")
    assert agreement._repr_html_() == agreement_html(agreement)

    report = armdyn.grade(str(ROOT / "examples" / "grading" / "rp-arm-dalembert.md"))
    assert report.text() == text(report) == str(report) and report.to_json() == to_json(report)
    assert report._repr_html_() == repr_html(report)
    assert json.loads(report.to_json()) == report.to_dict()

    urdf = next((PACKAGE / "robots").glob("*.urdf"))
    assert repr(armdyn.Robot.from_urdf(str(urdf))) == repr(load_urdf(str(urdf)))
