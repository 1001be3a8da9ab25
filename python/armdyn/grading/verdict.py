"""What grading a derivation produces: one verdict per step, and the report around them.

A student's derivation is a list of equations ``LHS = ... = RHS``. Each one whose LHS
names a step of the method (``\\dot{v}_1^1``, ``F_2^2``, ``\\tau_1``, ``T``...) gets a
:class:`StepVerdict`; the :class:`GradeReport` holds them in the student's order with
the summary (first wrong step, which final torques are right).

Statuses (``StepVerdict.status``):

* ``correct``: the student's value equals the expected one (exactly, up to
  ``sin^2 + cos^2 = 1``).
* ``correct-by-convention``: equal up to a named convention (``convention`` says which:
  the d'Alembert sign ``F = -m vcd``; force on link i by link i-1 versus by link i on
  i+1; gravity as a base acceleration versus as a force).
* ``wrong``: neither; ``difference`` = got - expected (in the student's convention) and
  ``components`` the wrong components.
* ``follows-from-earlier-error``: wrong, but exactly what the method gives from the
  student's own earlier values (``caused_by`` names the earliest wrong step it inherits).
* ``correct-but-unsupported``: right, but not what the student's own earlier steps give.
* ``consistent``: with no model (the robot could not be read from the text), what the
  student's own earlier values give, one of which could not be checked: right only if that
  one is, which nothing can say; it does not pass.
* ``unrecognised``: the LHS could not be mapped to a step, or the value could not be
  read (the message says where, line and column, and why); it counts against passing.
* ``definition``: an equation that introduces a name used later (``X = ...``, ``l_{c1} =
  l_1/2``) or sets the problem up (the joint vector ``\\mathbf q = (\\theta_1, \\theta_2)^T``,
  the gravity vector): read (its value stands for the name in later steps), not judged;
  it passes (the steps that use it are judged with it).

Values are SymPy: a (3, 1) ``Matrix`` for vectors, an expression for scalars, in the
robot model's symbols (``theta1``, ``theta1_dot``, ``l1``...); ``symbol_latex`` maps those
symbols to LaTeX as the field writes them (``\\dot{\\theta}_{1}``), the names the derivation
report prints too (:func:`armdyn.symbolic.names.latex_symbol_names`).
"""

from __future__ import annotations

from dataclasses import dataclass, field

from ..dispatch import call

STATUSES = (
    "correct",
    "correct-by-convention",
    "wrong",
    "follows-from-earlier-error",
    "correct-but-unsupported",
    "consistent",
    "unrecognised",
    "definition",
)

#: statuses that count as right for the exit status (0 when every equation is one of these);
#: a definition introduces a name or sets up the problem: read, nothing to be wrong about
#: (where it is used, the step using it is judged)
PASSING = ("correct", "correct-by-convention", "definition")


@dataclass
class StepVerdict:
    """The verdict on one equation of the student's derivation.

    name:        display name of the step, e.g. ``"v_dot_1"``, ``"F_2"``, ``"tau_1"``, ``"T"``
    key:         the method's step key (``"v_dot"``, ``"F"``, ``"tau"``, ``"T"``...), "" if unrecognised
    link:        the model's link (or joint, for tau) name, "" for whole-robot quantities
    status:      one of :data:`STATUSES`
    label:       LaTeX of the student's left-hand side as written
    source:      the student's whole equation as written (LaTeX or YAML text)
    line:        1-based line number of the equation in the submission
    expected:    the correct value (SymPy Matrix (3, 1) or expression) in the student's
                 convention, or None (unrecognised)
    got:         the student's value, parsed, or None
    difference:  got - expected, or None when they agree
    components:  0-based indices of the wrong components of a vector ([] for scalars / none)
    convention:  the convention the student used, named, or None
    caused_by:   name of the earlier step an inherited error comes from, or None
    message:     one readable sentence, e.g. "missing term −l1·θ̇1² in the x component"
    frame:       the frame the value is expressed in, e.g. "1" (text), "" for scalars
    part:        the assignment's part the equation is in (``"7-4"``), None when the task
                 has no number or there are no parts (see :mod:`armdyn.grading.parts`)
    task:        that task's title (the first line of its statement), "" if none
    column:      1-based column where the value starts (0: not known, e.g. YAML)
    counterexample: for a wrong proof link, the small body on which its sides differ
                 (masses, points, vectors, rotations, both sides' values), else None
    """

    name: str
    key: str
    link: str
    status: str
    label: str
    source: str
    line: int
    expected: object = None
    got: object = None
    difference: object = None
    components: list[int] = field(default_factory=list)
    convention: str | None = None
    caused_by: str | None = None
    message: str = ""
    frame: str = ""
    part: str | None = None
    task: str = ""
    column: int = 0
    counterexample: dict | None = None

    @property
    def passed(self) -> bool:
        return self.status in PASSING


@dataclass
class GradeReport:
    """The result of grading one submission.

    robot:         name of the model the student's frames follow
    method:        "newton-euler" or "lagrange"
    submission:    path (or "<string>") of the graded file
    steps:         one verdict per recognised or unrecognised equation, in the student's order
    first_wrong:   ``name`` of the first step whose status is wrong (``wrong`` or
                   ``follows-from-earlier-error`` cannot be first: the first wrong step is
                   always ``wrong``), or None
    tau_correct:   per joint: the student's final tau_i is right (supported or not);
                   False where the student gave no tau_i
    symbol_latex:  SymPy symbol -> its LaTeX, as the derivation report writes it
    notes:         general remarks (mapping used, steps the method has that the student skipped)
    model_note:    when no model was named and it was read from the text, the note saying so
                   (also first in ``notes``): the text and HTML reports open with it, else ""
    shorthand:     sin/cos terms the student wrote as shorthand -> symbols printing as theirs
                   (``sin(q1 + q2)`` -> ``s₁₂``), for showing values in their notation
    """

    robot: str
    method: str
    submission: str
    steps: list[StepVerdict]
    first_wrong: str | None
    tau_correct: list[bool]
    symbol_latex: dict = field(default_factory=dict)
    notes: list[str] = field(default_factory=list)
    shorthand: dict = field(default_factory=dict)
    model_note: str = ""

    @property
    def passed(self) -> bool:
        """Every equation read and right or a definition (an unread one is not a pass: it was
        not checked)."""
        return all(s.status in PASSING for s in self.steps)

    # the text, JSON and HTML renderers (text.py, html.py) register with armdyn.dispatch
    def text(self, ascii_only: bool = False) -> str:
        """The plain-text report (Unicode dots unless ``ascii_only``)."""
        return call("text", self, ascii_only)

    def to_dict(self) -> dict:
        """The JSON object (stable field names), expressions as SymPy strings."""
        return call("dict", self)

    def to_json(self) -> str:
        return call("json", self)

    def __str__(self) -> str:
        return self.text()

    def _repr_html_(self) -> str:
        """Jupyter: the report as HTML (MathML math, no network)."""
        return call("html", self)
