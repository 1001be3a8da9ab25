"""Running a course on armdyn: a variant of the exercise per student, the class graded.

    from armdyn.course import Gradebook, Rubric, summary_html
    rubric = Rubric.load("rubric.yaml")                    # or Rubric.default()
    gb = Gradebook.from_results(items, rubric=rubric)      # items: (student, variant, grade_json, error)
    gb.rows; gb.to_csv(); gb.to_json()
    page = summary_html(gb)                                # the class summary, one HTML page

    from armdyn.course import make_exercise, grade_class
    make_exercise("rp", "exercise/", seed=7, roster="roster.csv")
    grade_class("submissions/", "grades.csv", variants="exercise/", html_dir="reports/")

One concept per module: :mod:`.kinds` (the arms), :mod:`.variants` (one drawn variant
and its model file), :mod:`.statement` (problem.md / problem.html), :mod:`.solution`
(the worked solution, injected slips), :mod:`.exercise` (the folders, the roster),
:mod:`.drawing` (the statement's drawing), :mod:`.expected` (the parts and steps a kind
asks), :mod:`.rubric` (points per step and part), :mod:`.gradebook` (one row per student,
CSV, JSON), :mod:`.slipkinds` (the kind of a wrong step, from its values),
:mod:`.errorkinds` (from its message), :mod:`.summary` (the class page, per kind),
:mod:`.chart` (reproducible SVG charts), :mod:`.page` (the HTML frame), :mod:`.isolate`
(a forked child per submission, with limits), :mod:`.batch` (the class graded),
:mod:`.cli` (the command line).

Names are imported on first use, so that ``armdyn --help`` stays fast.
"""

from __future__ import annotations

__all__ = ["Gradebook", "Rubric", "grade_class", "make_exercise", "summary_html"]

_WHERE = {
    "Gradebook": "gradebook",
    "Rubric": "rubric",
    "summary_html": "summary",
    "make_exercise": "exercise",
    "grade_class": "batch",
}


def __getattr__(name: str):
    if name in _WHERE:
        from importlib import import_module

        value = getattr(import_module(f"{__name__}.{_WHERE[name]}"), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
