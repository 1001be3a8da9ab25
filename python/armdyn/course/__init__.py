"""Running a course on armdyn: a variant of the exercise per student, the class graded.

    from armdyn.course import Gradebook, Rubric, summary_html
    rubric = Rubric.load("rubric.yaml")                    # or Rubric.default()
    gb = Gradebook.from_results(items, rubric=rubric)      # items: (student, variant, grade_json, error)
    gb.rows; gb.to_csv(); gb.to_json()
    page = summary_html(gb)                                # the class summary, one HTML page

One concept per module: :mod:`.rubric` (points per step and part), :mod:`.gradebook`
(rows, CSV, JSON), :mod:`.errorkinds` (the kind of a wrong step), :mod:`.summary`
(the class page), :mod:`.chart` (reproducible SVG charts), :mod:`.page` (the HTML frame).
"""

from __future__ import annotations

from .gradebook import Gradebook
from .rubric import Rubric
from .summary import summary_html

__all__ = ["Gradebook", "Rubric", "summary_html"]
