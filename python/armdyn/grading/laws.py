"""The laws of the method as the textbooks state them, and the statements of them a
derivation writes before it instantiates them.

A derivation often opens with the general laws, in an index or in generic names:
Craig's ``k_i = \\frac12 m_i v_{C_i}^T v_{C_i} + \\frac12 {}^{C_i}\\omega_i^T {}^{C_i}I_i {}^{C_i}\\omega_i``,
``u_i = -m_i {}^0g^T {}^0P_{C_i} + u_{ref}``, ``\\mathcal L = K - P``, Spong's
``D(q) = \\sum_i m_i J_{v_i}^T J_{v_i} + J_{\\omega_i}^T R_i I_i R_i^T J_{\\omega_i}`` and
``c_{ijk} = \\frac12(\\frac{\\partial d_{kj}}{\\partial q_i} + \\frac{\\partial d_{ki}}{\\partial q_j}
- \\frac{\\partial d_{ij}}{\\partial q_k})``, Craig's outward and inward iterations
(``{}^{i+1}\\omega_{i+1} = {}^{i+1}_{i}R\\,{}^{i}\\omega_i + \\dot\\theta_{i+1}\\,{}^{i+1}\\hat Z_{i+1}``,
``F_i = m_i \\dot v_{C_i}``, ``\\tau_i = n_i^T \\hat Z_i``...), ``T = \\frac12 m v^2 + \\frac12 I\\omega^2``.

:func:`judge` reads such a statement (:mod:`.law_reading`: every generic quantity a random
exact value, every index a number, sums written out) and compares each side with the
textbook forms of the law its left-hand side names (:data:`LAWS`), evaluated at the same
values, for every value of the indices:

* equal to one of the forms: ``correct`` ("the kinetic energy of a link, stated as in the
  textbooks"); the conventions of the field are forms too (Craig's frames or Spong's
  rotation ``R_i I_i R_i^T``; the sign of ``m g^T P`` with ``g`` along or against gravity;
  the free index of a Christoffel symbol first or last; a reference level ``u_{ref}``);
* equal to a form with one slip (a term missing, of the wrong sign, a ``\\frac12`` missing or
  extra, the rotation transposed, a velocity for an acceleration): ``wrong``, naming it;
* anything else: not judged (``unrecognised``, saying so): a right law in a form the table
  does not know must never be called wrong.

The Lagrange equation itself is :func:`.statements.lagrange_law`'s; the equations of motion
in matrix form are :func:`.statements.matrix_form`'s.
"""

from __future__ import annotations

import itertools
import re
from dataclasses import dataclass

import sympy as sp

from .latex import LatexError, Name, parse
from .law_reading import (
    PATTERN,
    NotALaw,
    Placeholders,
    Quantity,
    Reader,
    Values,
    script_letters,
    strip_arguments,
)
from .law_table import HALF, LAGRANGE_LAWS, Ctx, Form, add_terms, classify, native_frame
from .law_table_ne import NE_LAWS

#: every law a statement is judged against
LAWS = [*LAGRANGE_LAWS, *NE_LAWS]


# -- judging a statement
@dataclass
class LawResult:
    """The verdict on a statement of a law: ``status`` (correct, wrong, unrecognised),
    the law's name, the message, and the method it belongs to."""

    status: str
    law: str
    message: str
    method: str = "lagrange"


#: sides beyond which an equation is not read as a law (each is read for every index value)
MAX_SIDES = 8
#: the values of each index a law is checked for (three letters: every order of 1, 2, 3 and repeats)
_VALUES = (1, 2, 3)
_TRIPLES = [*itertools.permutations(_VALUES), (1, 1, 2), (1, 2, 1), (2, 1, 1), (2, 2, 2)]


def _bindings(letters: set) -> list[dict]:
    ordered = sorted(letters)
    if len(ordered) == 3:
        return [dict(zip(ordered, t)) for t in _TRIPLES]
    return [dict(zip(ordered, t)) for t in itertools.product(_VALUES, repeat=len(ordered))]


def _lhs(text: str, binding: dict) -> tuple[Quantity, Name] | None:
    """The one generic name a left-hand side is, read under ``binding``."""
    names: list[Name] = []
    marker = sp.Symbol("law_lhs")
    try:
        value = parse(strip_arguments(text), lambda n: names.append(n) or marker)
    except (LatexError, TypeError, ValueError):
        return None
    if value != marker or len(names) != 1:
        return None
    try:
        quantity, _ = classify(names[0], "lhs", "space", binding)
    except LatexError:
        return None
    return quantity, names[0]


def _law_role(q: Quantity) -> str:
    if q.role in ("omega", "v") and q.dots == 1:
        return "vc1" if q.role == "v" and q.centre else q.role + "1"
    return q.role if q.dots == 0 else ""


def _partial(top: Quantity, by: Quantity, ddt: bool, values: Values):
    """∂(mass-matrix entry)/∂q_k and ∂P/∂q_k: one random number each (the entry's symmetry kept)."""
    if not ddt and by.role == "q" and by.dots == 0 and by.link is not None:
        if top.role == "Mentry":
            return values.get(("dM", None, 0, False, (top.entry, by.link)), "scalar")
        if top.role == "PE" and top.link is None:
            return values.get(("dP", None, 0, False, (by.link,)), "scalar")
    raise NotALaw("a derivative the laws do not use")


def _plain(x):
    if isinstance(x, sp.MatrixBase) and x.shape == (1, 1):
        return x[0, 0]
    return x


def _same(a: list, b: list) -> bool:
    for x, y in zip(a, b, strict=True):
        x, y = _plain(x), _plain(y)
        if isinstance(x, sp.MatrixBase) != isinstance(y, sp.MatrixBase):
            if (x == 0 and isinstance(y, sp.MatrixBase) and y.is_zero_matrix) or (
                y == 0 and isinstance(x, sp.MatrixBase) and x.is_zero_matrix
            ):
                continue
            return False
        if isinstance(x, sp.MatrixBase) and x.shape != y.shape:
            return False
        if x != y:
            return False
    return True


def _variants(form: Form):
    """(terms kept, a note on what was left out) for each choice of the optional terms."""
    optional = [t for t in form.terms if t.optional]
    for k in range(len(optional) + 1):
        for left_out in itertools.combinations(optional, k):
            yield [t for t in form.terms if t not in left_out], left_out


def _slips(terms: list):
    """(rank, message, [(term, factor)] or "transpose") of the one-slip versions of a form's
    terms; the lowest rank is named when several explain a side."""
    for t in terms:
        yield 1, f"{t.what} has the wrong sign", [(u, -1 if u is t else 1) for u in terms]
        yield 2, f"{t.what} is missing", [(u, 1) for u in terms if u is not t]
        if "½" in t.what:
            yield 1, f"the factor ½ of {t.what} is missing", [(u, 2 if u is t else 1) for u in terms]
        yield 3, f"{t.what}: a factor ½ too many", [(u, HALF if u is t else 1) for u in terms]
    if len(terms) > 1:
        yield 4, "the whole side has the wrong sign", [(u, -1) for u in terms]
    yield 1, "the rotation is transposed (it must map the vector into the frame of the left-hand side)", "transpose"


def _evaluate(terms, factors, ctxs):
    out = []
    for c in ctxs:
        total = None
        for t, k in factors if factors is not None else [(t, 1) for t in terms]:
            total = add_terms(total, k * t.value(c))
        out.append(0 if total is None else total)
    return out


def _judge_side(side_values, ctxs, laws, transposed_ctxs):
    """(status, law, message) of one side: a form it equals, or the one slip it has, or None."""
    for law in laws:
        for form in law.forms:
            for terms, left_out in _variants(form):
                try:
                    if _same(side_values, _evaluate(terms, None, ctxs)):
                        said = [form.note] if form.note else []
                        said += [f"without {t.what}" for t in left_out if "reference" not in t.what]
                        return "correct", law, "; ".join(said)
                except (TypeError, ValueError, sp.ShapeError, AttributeError):
                    continue
    found = []  # (rank, message, law): the most local slip is named
    for law in laws:
        for form in law.forms:
            for terms, _ in _variants(form):
                for rank, message, factors in _slips(terms):
                    try:
                        if factors == "transpose":
                            got = _evaluate(terms, None, transposed_ctxs)
                            if _same(got, _evaluate(terms, None, ctxs)):
                                continue  # no rotation in it
                        else:
                            got = _evaluate(terms, factors, ctxs)
                    except (TypeError, ValueError, sp.ShapeError, AttributeError):
                        continue
                    if _same(side_values, got):
                        found.append((rank, message, law))
        for message, slip in law.slips:
            try:
                if _same(side_values, [slip(c) for c in ctxs]):
                    found.append((0, message, law))
            except (TypeError, ValueError, sp.ShapeError, AttributeError):
                continue
    if found:
        rank, message, law = min(found, key=lambda f: f[0])
        return "wrong", law, message
    return None


def _lagrange(sides: list[str], chain: bool) -> LawResult | None:
    from .notation import normalise
    from .statements import LAW, RHS_TORQUE, lagrange_law

    if len(sides) < 2 or len(sides) > 2 and not chain or not any("\\partial" in s for s in sides[:2]):
        return None  # τ_1 = (the law) = a value: the value is a step, graded as one
    # τ_1 = (the law) alone is joint 1's torque left unworked: a step refused with its reason
    later = " (the sides after it not checked)" if len(sides) > 2 else ""
    for law_side, torque in ((sides[0], sides[1]), (sides[1], sides[0])):
        if (
            RHS_TORQUE.match(normalise(torque))
            and "\\partial" in law_side
            and (len(sides) > 2 or not re.search(r"\d", torque))
        ):
            verdict = lagrange_law(law_side, torque)
            if verdict is not None:
                ok, message = verdict
                if ok:
                    return LawResult(
                        "correct", "the Lagrange equation", "the Lagrange equation, stated as in the textbooks" + later
                    )
                return LawResult("wrong", "the Lagrange equation", message or f"not the Lagrange equation {LAW}")
    return None


def judge(sides: list[str], n_links: int = 3, chain: bool = False) -> LawResult | None:
    """Is ``sides[0] = sides[1] = ...`` a statement of a law of the method, and is it
    right? None when it states no law (a name in it is no generic quantity, or its
    left-hand side names none); ``n_links``: the links a sum over ``n`` runs over; ``chain``:
    the Lagrange equation may be followed by sides not checked (its value could not be read)."""
    if len(sides) > MAX_SIDES:
        return None
    lagrange = _lagrange(sides, chain)
    if lagrange is not None:
        return lagrange
    if len(sides) < 2:
        return None
    lhs_text = sides[0]
    letters = script_letters(lhs_text)
    bindings = _bindings(letters)
    first = _lhs(lhs_text, bindings[0])
    if first is None:
        return None
    quantity, lhs_name = first
    role = _law_role(quantity)
    laws = [
        law for law in LAWS if law.role == role and (law.indexed is None or law.indexed == (quantity.link is not None))
    ]
    if not laws:
        return None
    stated = laws[0]
    if any(PATTERN.search(s) for s in sides[1:]):
        return LawResult(
            "unrecognised",
            stated.name,
            f"{stated.name} written as a pattern (\\cdots): read, not checked",
            stated.method,
        )
    if quantity.frame is not None and quantity.frame != native_frame(quantity):
        return LawResult("unrecognised", stated.name, f"{stated.name} in another frame than its own: not checked")
    lhs_bare = strip_arguments(lhs_text).replace(" ", "")
    verdicts = []
    for side in sides[1:]:
        if strip_arguments(side).replace(" ", "") == lhs_bare:
            continue  # k(\Theta, \dot\Theta): the name again, with what it depends on
        verdict = _side(side, laws, bindings, letters, n_links, lhs_text)
        if verdict is None:
            return None
        verdicts.append(verdict)
    if not verdicts:
        return None
    law = verdicts[0][1]
    wrong = [v for v in verdicts if v[0] == "wrong"]
    unknown = [v for v in verdicts if v[0] == "unrecognised"]
    if wrong:
        return LawResult(
            "wrong", wrong[0][1].name, f"{wrong[0][2]} ({wrong[0][1].name}: {wrong[0][1].stated})", law.method
        )
    if unknown:
        return LawResult("unrecognised", law.name, unknown[0][2], law.method)
    notes = "; ".join(dict.fromkeys(v[2] for v in verdicts if v[2]))
    return LawResult(
        "correct", law.name, f"{law.name}, stated as in the textbooks" + (f" ({notes})" if notes else ""), law.method
    )


def _side(side: str, laws: list, bindings: list, letters: set, n_links: int, lhs_text: str):
    """One right-hand side judged against ``laws`` (("correct"|"wrong"|"unrecognised", law,
    message)), or None when it uses a name that is no generic quantity."""
    not_law = None
    for world in ("space", "plane"):
        values = Values(seed=7, n=max(n_links, 1))
        ph = Placeholders()
        try:
            text = ph.prepare(side, letters)
        except LatexError:
            return None
        family = laws[0].family
        reader = Reader(
            lambda name, b, fam=family, w=world: classify(name, fam, w, b), values, ph, _partial, native_frame
        )
        try:
            got, ctxs, tctxs = [], [], []
            for b in bindings:
                got.append(reader.read(text, b))
                lq, _ = _lhs(lhs_text, b)
                ctxs.append(Ctx(values, world, lq.link, lq.entry))
                tctxs.append(Ctx(values, world, lq.link, lq.entry, transpose=True))
        except NotALaw as err:
            not_law = not_law or err
            continue
        except (LatexError, TypeError, ValueError, sp.ShapeError, AttributeError, IndexError, ZeroDivisionError):
            continue
        if not reader.used:
            return None  # a constant (f_{n+1} = 0): no statement of the law
        verdict = _judge_side(got, ctxs, laws, tctxs)
        if verdict is not None:
            return verdict
        return (
            "unrecognised",
            laws[0],
            (
                f"read as {laws[0].name} ({laws[0].stated}), but in a form the textbooks' table does not hold: not judged"
            ),
        )
    return None


# -- the grader's side (a function of armdyn.grading.grader.Grader, as defined.definition)
def law_statement(grader, eq, fallback: bool = False):
    """(The verdict, the method) on ``eq`` when it states a law, else None. Without ``fallback`` only a
    statement marked general (an index letter, a sum, a pattern, a derivative) is tried;
    with it (the equation named no step, or its value could not be read) any, and only a
    judged one (correct or wrong) is returned."""
    return law_verdict(eq, max(grader.robot.dof, 1), fallback)


def law_verdict(eq, n_links: int, fallback: bool = False):
    """:func:`law_statement` for an arm of ``n_links`` links, with no model (the text graded on
    its own values: a law stated is judged, never taken for a value of this arm)."""
    from .equations import sides
    from .verdict import StepVerdict

    if not eq.latex or eq.problem or isinstance(eq.value, list):
        return None
    text = eq.source
    # a pattern (\cdots) is a law's only when its left side names no link (G, not \tau_2: a step
    # with entries left out is refused where they are, grader's reading)
    pattern = PATTERN.search(text) and not re.search(r"\d", eq.lhs)
    general = script_letters(text) or "\\sum" in text or "\\partial" in text or pattern
    if not general and not fallback:
        return None
    try:
        result = judge(sides(text), n_links=n_links, chain=fallback)
    except (LatexError, TypeError, ValueError, RecursionError, sp.ShapeError):
        return None
    if result is None or fallback and result.status == "unrecognised":
        return None
    return StepVerdict(
        name="lagrange_equation" if result.law == "the Lagrange equation" else "law",
        # no step (a proof's checker may take the line over, grading.proofs); the Lagrange
        # equation is reported as statements.py reports it
        key="law" if result.law == "the Lagrange equation" else "",
        link="",
        status=result.status,
        label=eq.lhs,
        source=eq.source,
        line=eq.line,
        message=result.message,
    ), result.method


#: sides larger than this (operations) are not compared as an identity (simplify is slow)
MAX_IDENTITY_OPS = 150


def identity(grader, eq):
    """``cos a cos b + sin a sin b = cos(a - b)``, ``c_2 c_{23} + s_2 s_{23} = c_3``, a cross
    product written out: a general statement whose sides are equal for every value of
    their symbols (the model's, and any other name a free symbol). The verdict
    (``correct``) when every side reads and all are equal; else None (never judged wrong:
    an equation that is no identity may still be meant as something else)."""
    from .equations import sides
    from .latex import UnknownSymbol
    from .verdict import StepVerdict

    if not eq.latex or eq.problem or isinstance(eq.value, list):
        return None
    free: dict = {}

    def resolve(name):
        try:
            return grader.symbols(name)
        except (UnknownSymbol, LatexError):
            return free.setdefault(name.latex(), sp.Symbol(f"armdyn_free_{len(free)}"))

    try:
        values = [parse(s, resolve) for s in sides(eq.source)]
    except (LatexError, TypeError, ValueError, RecursionError, sp.ShapeError, AttributeError):
        return None
    if not 2 <= len(values) <= MAX_SIDES:
        return None
    flat = []
    for v in values:
        items = list(v) if isinstance(v, sp.MatrixBase) else [v]
        if isinstance(v, sp.MatrixBase) and v.shape != getattr(values[0], "shape", None):
            return None
        if any(not isinstance(x, sp.Expr) or sp.count_ops(x) > MAX_IDENTITY_OPS for x in items):
            return None
        flat.append(items)
    for other in flat[1:]:
        for a, b in zip(flat[0], other, strict=True):
            if sp.simplify(sp.expand_trig(a - b)) != 0:
                return None
    return StepVerdict(
        name="identity",
        key="",  # no step: a proof's checker may take the line over (grading.proofs)
        link="",
        status="correct",
        label=eq.lhs,
        source=eq.source,
        line=eq.line,
        message="an identity: its sides are equal for every value of their symbols",
    )


# -- a step of one robot written in an index: checked for every value the robot has
_SCRIPT = re.compile(r"([_^]\s*)(\{(?:[^{}]|\{[^{}]*\})*\}|[A-Za-z0-9])")


def substitute(text: str, letter: str, k: int) -> str:
    """``text`` with the index ``letter`` set to ``k`` in its sub- and superscripts
    (``c_{i+1}`` -> ``c_{2}`` for k = 1); commands (``\\sin``, ``J_{\\omega_i}``'s ``\\omega``) kept."""

    def one(m):
        body = re.sub(rf"(?<![A-Za-z\\]){letter}(?![A-Za-z])", str(k), m.group(2))
        body = re.sub(
            r"(\d+)\s*([+-])\s*(\d+)", lambda a: str(int(a[1]) + (1 if a[2] == "+" else -1) * int(a[3])), body
        )
        return m.group(1) + body

    return _SCRIPT.sub(one, text)


def indexed_step(grader, eq):
    """``{}^{i+1}_{i}R = \\begin{bmatrix} c_{i+1} & s_{i+1} & 0 \\\\ ...``: a rotation or a position
    of the robot written in an index, checked against the model for every value of the
    index its frames have. Right for every value: ``correct``; wrong for every one: ``wrong``
    (the first named); right for some only (a joint of another kind?): not judged."""
    from .engine import equal
    from .methods import position, rotation_between
    from .notation import parse_lhs
    from .verdict import StepVerdict

    letters = script_letters(eq.lhs)
    if not eq.latex or eq.problem or isinstance(eq.value, list) or len(letters) != 1:
        return None
    letter = letters.pop()
    ctx = grader.world("newton-euler").ctx
    fp = grader.sampler.fingerprint
    right, wrong = [], []
    for k in range(0, len(grader.robot.links)):
        try:
            ref = parse_lhs(substitute(eq.lhs, letter, k), grader.symbols.coordinate_of)
        except (LatexError, TypeError, ValueError):
            return None
        if ref is None or ref.key not in ("R", "P", "Pc"):
            return None
        if grader._check_index(ref):
            continue  # a frame this robot does not have
        try:
            value = parse(substitute(str(eq.value), letter, k), grader.symbols)
            if ref.key == "R":
                expected = rotation_between(ctx, ref.index, ref.frame)
            else:
                expected = sp.Matrix(position(ctx, ref.key, ref.index, ref.frame, ref.origin)[0])
            value = value if isinstance(value, sp.MatrixBase) else None
            if value is None or value.shape != expected.shape:
                return None
            (right if equal(fp(value), fp(expected)).all() else wrong).append(k)
        except (LatexError, TypeError, ValueError, RecursionError, sp.ShapeError, AttributeError):
            return None
    if not right and not wrong:
        return None
    values = lambda ks: ", ".join(f"{letter} = {k}" for k in ks)  # noqa: E731
    if right and wrong:
        status, message = (
            "unrecognised",
            (
                f"written in the index {letter}: right for {values(right)}, not for {values(wrong)} "
                "(a joint of another kind?): not judged"
            ),
        )
    elif wrong:
        status, message = "wrong", f"written in the index {letter}: not the robot's for {values(wrong)}"
    else:
        status, message = "correct", f"written in the index {letter}: the robot's for {values(right)}"
    return StepVerdict(
        name=f"{ref.key}_{letter}",
        key=ref.key,
        link="",
        status=status,
        label=eq.lhs,
        source=eq.source,
        line=eq.line,
        message=message,
    )
