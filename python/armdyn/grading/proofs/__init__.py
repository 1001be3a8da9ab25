"""Proofs about rigid bodies in a graded derivation: every ``=`` of every line checked.

The exercise's proofs (the parallel axis theorem, the rotational kinetic energy
``1/2 w^T I w``) are chains of equalities between integrals over the body, vectors, skew
matrices ``S(.)``, rotations and inertia tensors. A proof line can be false while the
proof's conclusion is a well-known true formula, so each link ``A = B`` is checked on its
own (:mod:`.checker`):

* :mod:`.regions` finds the proofs in the Markdown text (by their prose or by what their
  lines say) and their display lines;
* :mod:`.prose` reads what the sentences say the names mean (the point ``r`` is measured
  from, the origin, a point's coordinates, a worked example's scalars);
* :mod:`.expr` reads each side into a typed, non-commutative expression tree (:mod:`.nodes`);
* :mod:`.evaluate` gives the names their meaning (rules in its docstring) and evaluates a
  tree exactly (Fractions, :mod:`.matrices`) on a body of point masses (:mod:`.body`);
  :mod:`.motion` takes time derivatives (``\\dot R``, ``\\dot L``) by the product rule;
* :mod:`.counterexample` finds a small body on which a wrong link's sides differ.

How equality is decided. Both sides are evaluated on ``K = 3`` random bodies of 4 point
masses: integer masses in [1, 2^31], integer coordinates, constant vectors and Cayley
rotation parameters in [-2^31, 2^31]; the mass center is computed exactly; rotations are
exactly orthogonal. The difference of the two sides, denominators cleared, is a polynomial
in these integers of degree ``D <= deg(left) + deg(right)``, each counted from its tree
(:func:`.evaluate.degree`; a side above 400 is not evaluated, so ``D <= 800``). If it is not
identically zero, by the Schwartz-Zippel lemma a random draw makes it vanish with
probability at most ``D / 2^31 < 4e-7``; three independent draws all vanish with
probability below ``1e-19``. Equal sides are always found equal
(exact arithmetic: no tolerance, no false failure). Nothing in the student's text is
executed (no eval, no sympify).
"""

from __future__ import annotations

import sympy as sp

from ...errors import ModelError
from ..verdict import StepVerdict
from .checker import LinkVerdict, ProofChecker
from .matrices import Mat
from .regions import proof_regions

__all__ = ["check_text", "grade_proofs"]

#: display lines of proofs in one submission beyond which grading stops with an error
MAX_PROOF_LINES = 400


def _sympy(value):
    if not isinstance(value, Mat):
        return None
    if value.is_scalar:
        return sp.Rational(value.v[0].numerator, value.v[0].denominator)
    return sp.Matrix(value.r, value.c, [sp.Rational(x.numerator, x.denominator) for x in value.v])


def _name(links: list[LinkVerdict]) -> None:
    """``proof_<line>``, or ``proof_<line>.<k>`` for the k-th link of a line with several."""
    per_line: dict = {}
    for v in links:
        per_line.setdefault(v.line, []).append(v)
    for line, group in per_line.items():
        for k, v in enumerate(group, start=1):
            v.name = f"proof_{line}" if len(group) == 1 else f"proof_{line}.{k}"
    for v in links:
        if v.cause is not None:
            v.caused_by = v.cause.name


def _verdict(v: LinkVerdict) -> StepVerdict:
    return StepVerdict(
        name=v.name,
        key="proof",
        link="",
        status=v.status,
        label=v.label,
        source=v.source,
        line=v.line,
        expected=_sympy(v.right),
        got=_sympy(v.left),
        message=v.message,
        caused_by=v.caused_by,
        counterexample=v.counterexample,
    )


def check_text(text: str, path: str = "<string>", step_lines: set | None = None) -> list[StepVerdict]:
    """The verdicts on every link of every proof in a Markdown text, in order."""
    regions = proof_regions(text, step_lines or set())
    total = sum(len(r) for r in regions)
    if total > MAX_PROOF_LINES:
        line = regions[-1][-1].line
        raise ModelError(f"{total} proof lines (at most {MAX_PROOF_LINES} are checked)", source=f"{path}:{line}")
    links: list[LinkVerdict] = []
    checker = None
    for region in regions:
        checker = ProofChecker() if checker is None else _fresh(checker)
        for n, d in enumerate(region):
            following = region[n + 1].prose if n + 1 < len(region) else ""
            if d.prose:
                extra = checker.vanishing(d)
                if extra is not None:
                    links.append(extra)
            links.extend(checker.display(d, following))
    _name(links)
    return [_verdict(v) for v in links]


def _fresh(previous: ProofChecker) -> ProofChecker:
    """A new proof's checker, sharing the overall time budget."""
    return ProofChecker(deadline=previous.deadline)


def grade_proofs(sub, verdicts: list[StepVerdict]) -> list[StepVerdict]:
    """The grader's verdicts with every unrecognised equation inside a proof replaced by
    the verdicts on its links (and bare expressions that continue a proof line added).
    The proofs are read from the text the submission was read from (``sub.text``), so a
    file, a posted text and a batch's file are graded alike; a YAML submission has none."""
    text = getattr(sub, "text", "")  # the text as read: a file, the web app's post, a batch's file alike
    if not text:
        return verdicts
    proofs = check_text(text, getattr(sub, "path", "") or "<string>", {v.line for v in verdicts if v.key})
    if not proofs:
        return verdicts
    # a law stated in general symbols (grading.laws) stays when the proof checker cannot read its line
    laws = {v.line for v in verdicts if v.name in ("law", "identity") and not v.key}
    proofs = [p for p in proofs if not (p.line in laws and p.status == "unrecognised")]
    handled = {v.line for v in proofs}
    kept = [v for v in verdicts if v.key or v.line not in handled]
    return sorted(kept + proofs, key=lambda v: v.line)
