"""Check a student's own derivation step by step: :func:`grade` (exported as ``armdyn.grade``).

    report = armdyn.grade("my-derivation.md")             # front matter names the robot
    report = armdyn.grade("steps.yaml", robot="rp-arm")
    print(report.text()); report.to_json(); report.first_wrong

The submission (Markdown with LaTeX display math, or YAML; see :mod:`.reader`) is read,
each equation's left-hand side is mapped to a step of Newton-Euler or Lagrange
(:mod:`.notation`), and each step gets a verdict (:mod:`.grader` walks the equations,
:mod:`.engine` decides, statuses in
:mod:`.verdict`): correct, correct-by-convention, wrong, follows-from-earlier-error,
correct-but-unsupported, unrecognised, or definition (a name given a value, a setup line;
it passes). Bad input (no equation recognised, malformed
front matter, an unknown symbol, a vector of the wrong length, a link that does not
exist) raises :class:`armdyn.errors.ModelError` naming the file and line.
"""

from __future__ import annotations

# the text, JSON and HTML renderers register GradeReport's text, to_dict, to_json and
# _repr_html_ with armdyn.dispatch when imported
from . import html as _html_report  # noqa: F401
from . import text as _text_report  # noqa: F401
from .entry import grade
from .verdict import STATUSES, GradeReport, StepVerdict

__all__ = ["grade", "GradeReport", "StepVerdict", "STATUSES"]
