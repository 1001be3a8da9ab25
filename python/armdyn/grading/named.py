"""Quantities used by name across a derivation, as textbooks and exam answers write them.

:mod:`.defined` keeps the values the student gave under plain names (:class:`Entry`, keyed by
:func:`plain`); this module reads the other ways a derivation uses them:

* a name applied to its arguments, ``M_{11}(\\theta_2)\\ddot\\theta_1``, ``K_1(\\theta,\\dot\\theta)``:
  the quantity itself, not a product with the joint variable (:func:`drop_arguments`);
* the time derivative of a named quantity, ``\\dot M_{11}``, and its partial by a joint variable,
  ``\\frac{\\partial M_{11}}{\\partial \\theta_2}``: that derivative of the student's own value
  (:func:`differentiated`, :func:`partials_as_names`); a step ``\\dot M_{11} = ...`` is checked
  against it (:func:`derivative_step`);
* a link's energy under any textbook name, ``\\mathcal L = \\mathcal K_1 + \\mathcal K_2 - ...``
  after ``\\mathcal E_{K_1} = ...``, and a speed given through its square, ``v_2^2 = ...`` then
  ``\\frac12 m_2 v_2^2`` (:func:`keep_named`);
* a name used before the step that gives it (``T = T_1 + T_2`` above ``T_1 = ...``): the
  equation waits for it and is graded, at its own line, once it is given
  (:class:`Waiting`); a name never given is said so;
* ``M_{21} = M_{12}``: the symmetry, after which ``M_{21}`` stands for ``M_{12}``
  (:func:`symmetric_entry`); ``\\tau = M(q)\\ddot q`` in names only: a statement of the form
  (:func:`form_only`).
"""

from __future__ import annotations

import re
from dataclasses import dataclass

import sympy as sp

from .latex import LatexError, Name, UnknownSymbol, parse

#: a function's argument list is at most this long (bounds the scan of each "(")
MAX_ARGS_TEXT = 80
#: one argument: a joint variable, its rate, or the joint vector (\theta_2, \dot{\theta}_1, q, \dot{\mathbf q}, \Theta)
_ARG = re.compile(
    r"(?:\\(?:dot|mathbf|boldsymbol|bm|vec)\s*\{?\s*){0,3}\\?[A-Za-z]+\s*(?:\}\s*){0,3}(?:_\{?\w{1,3}\}?)?"
)
#: the joint vector's letters, written without an index as a function's argument
_JOINT_VECTOR = {"q", "theta", "Theta", "vartheta", "t", "d"}
#: the name written just before "(": a letter or command, its accent or typeface, a subscript
_BEFORE = re.compile(
    r"(?:\\(?:dot|mathcal|mathbf|mathrm|boldsymbol)\s*\{?\s*){0,2}\\?[A-Za-z]+\s*\}{0,2}\s*"
    r"(?:_\{[^{}]{1,20}\}|_\\?[A-Za-z0-9]+)?\s*$"
)
#: equations waiting for a name given further on at most (each is looked at after every equation)
MAX_WAITING = 200
#: a link's kinetic and potential energy under each textbook's name (plain keys, index appended)
KINETIC_NAMES = ("K", "T", "KE", "k", "EK", "Ek", "Ekin")
POTENTIAL_NAMES = ("P", "U", "V", "PE", "u", "EP", "Ep", "Epot")


@dataclass
class Entry:
    """A name with a value: ``own`` (the student's), ``right`` (the model's, when it names a
    model quantity; else the definition read with right values), where it was given."""

    name: str
    own: object
    right: object
    line: int = 0
    wrong: str = ""  # the verdict name of a wrong step, or "" (a definition: never wrong itself)
    note: str = ""  # said in the verdicts of steps that use it


def simple_name(lhs: str) -> Name | None:
    """The one undotted symbol ``lhs`` is (``X``, ``c_1``, ``d_{11}``, ``\\phi_3``; also written
    with its arguments, ``M_{12}(\\theta_2)``), else None."""
    lhs = without_arguments(lhs)
    names: list[Name] = []
    marker = sp.Symbol("armdyn_lhs_marker")
    try:
        value = parse(lhs, lambda n: names.append(n) or marker)
    except (LatexError, TypeError, ValueError, RecursionError):
        return None
    if value != marker or len(names) != 1 or names[0].dots or names[0].pre_sup or names[0].pre_sub:
        return None
    return names[0]


def plain(name: Name) -> str:
    """The key a name is kept under (as :class:`~.notation.SymbolMap` looks names up)."""
    return name.base + re.sub(r"[{}\s,_]|\\mathrm|\\text", "", name.sub or "")


def shorthand_name(name: Name) -> bool:
    """``c_1``, ``s_{12}``, ``C_2``: a name the grader reads as the sine or cosine of joint angles."""
    return name.base in ("s", "c", "S", "C") and (name.sub or "").strip("{} ").isdigit()


def _arguments(text: str, grader) -> bool:
    """Is ``text`` (between the parentheses) a list of joint variables, rates or the joint vector?"""
    parts = [p.strip() for p in text.split(",")]
    if not parts or len(parts) > 6:
        return False
    for part in parts:
        if not _ARG.fullmatch(part) or "ddot" in part:
            return False
        if grader.symbols.coordinate_of(part) is not None:
            continue
        letters = re.sub(r"\\(?:dot|mathbf|boldsymbol|bm|vec)\b|[{}\s]|_.*$", "", part).lstrip("\\")
        if letters not in _JOINT_VECTOR:
            return False
    return True


def _named(grader, text: str) -> Name | None:
    """The Name ``text`` is when it is a quantity the student (or the method) names: not a
    symbol of the model (``m_2(\\dot\\theta_1)^2`` stays a product), not the shorthand ``c_1``."""
    name = simple_name(text)
    if name is None:
        base = _strip_dots(text)
        name = simple_name(base) if base != text else None
        if name is None:
            return None
    if shorthand_name(name) or _model_symbol(grader, name):
        return None
    return name


def _strip_dots(text: str) -> str:
    return re.sub(r"\\d?dot\s*", "", text, count=1)


def drop_arguments(grader, text: str) -> str:
    """``text`` with the argument list of each named quantity blanked (``M_{11}(\\theta_2)``
    -> ``M_{11}``, positions kept), said once in the report's notes."""
    out = text
    start = 0
    while True:
        i = out.find("(", start)
        if i < 0:
            return out
        start = i + 1
        j = out.find(")", i, i + MAX_ARGS_TEXT)
        if j < 0 or "(" in out[i + 1 : j] or not _arguments(out[i + 1 : j], grader):
            continue
        if out[j + 1 : j + 2] == "^" or out[j + 1 : j + 3] == "'^":
            continue  # m_2(\dot\theta_1)^2: a power of the bracket
        m = _BEFORE.search(out, max(0, i - 60), i)
        if m is None or not m.group(0).strip():
            continue
        name = _named(grader, m.group(0).strip())
        if name is None:
            continue
        out = out[:i] + " " * (j + 1 - i) + out[j + 1 :]
        note = f"{m.group(0).strip()}{text[i : j + 1]} read as the quantity {name.latex()} (its arguments named)"
        if note not in grader.notes:
            grader.notes.append(note)


def time_derivative(value, robot, order: int = 1):
    """The total time derivative of ``value`` along the joint motion: Σ ∂/∂q_k q̇_k + ∂/∂q̇_k q̈_k."""
    from ..symbolic.terms import time_derivative as chain_rule

    for _ in range(order):
        value = chain_rule(value, robot.q, robot.qd, robot.qdd)
    return value


def differentiated(names, name: Name):
    """``\\dot X``: the time derivative of the value ``X`` has (the student's, or with
    :attr:`~.defined.DefinedNames.right` the right one), or None when ``X`` has none."""
    if name.dots > 2 or name.pre_sup or name.pre_sub:
        return None
    base = Name(name.base, 0, name.sub, name.sup)
    saved, names.active = names.active, True
    try:
        value = names.lookup(base)
        if value is None:
            value = names.model(base)
    finally:
        names.active = saved
    if value is None or not isinstance(value, (sp.Expr, sp.MatrixBase)):
        return None
    return time_derivative(value, names.symbols.robot, name.dots)


# -- steps about named quantities
_DOTTED_LHS = re.compile(r"\s*\\(d?dot)\s*(\{[^{}]*\}|\\?[A-Za-z]+)(.*)$", re.S)
#: \frac{\partial M_{11}}{\partial \theta_2}: the partial of a named quantity by one joint variable or rate
_PARTIAL_LHS = re.compile(r"\s*\\frac\s*\{\s*\\partial\s*([^{}]*(?:\{[^{}]*\}[^{}]*)*)\}\s*\{\s*\\partial\s*(.+)\}\s*")


def _derivative_of(grader, lhs: str):
    """(the quantity's Name, a function value -> its derivative, the step's name, what it is) of a
    left-hand side ``\\dot X`` / ``\\frac{\\partial X}{\\partial q_k}`` of a named quantity, or None."""

    m = _DOTTED_LHS.fullmatch(lhs)
    if m is not None:
        inner = m.group(2)[1:-1] if m.group(2).startswith("{") else m.group(2)
        base = simple_name(inner + m.group(3))
        if base is None:
            return None
        dots = 2 if m.group(1) == "ddot" else 1
        label = f"{base.base}{'dot' * dots}" + (f"_{plain(base)[len(base.base) :]}" if base.sub else "")
        robot = grader.robot
        return base, lambda v: time_derivative(v, robot, dots), label, f"the time derivative of {base.latex()}"
    m = _PARTIAL_LHS.fullmatch(lhs)
    if m is None:
        return None
    base = simple_name(m.group(1))
    found = grader.symbols.coordinate_of(m.group(2).strip())
    if base is None or found is None:
        return None
    k, order = found
    var = (grader.robot.q if order == 0 else grader.robot.qd)[k - 1]
    label = f"d{base.base}" + (f"_{plain(base)[len(base.base) :]}" if base.sub else "") + f"_d{var}"

    def partial(v):
        return v.diff(var) if isinstance(v, sp.MatrixBase) else sp.diff(v, var)

    return base, partial, label, f"the partial of {base.latex()} by {m.group(2).strip()}"


def derivative_step(grader, eq) -> bool:
    """Grade ``eq`` when it states a derivative of a named quantity (:func:`derivative_verdict`)."""
    verdict = derivative_verdict(grader, eq)
    if verdict is not None:
        grader.verdicts.append(verdict)
    return verdict is not None


def derivative_verdict(grader, eq):
    """``\\dot M_{11} = ...`` or ``\\frac{\\partial M_{11}}{\\partial \\theta_2} = ...`` of a quantity the
    student named: checked against that derivative of their own value and of the right one; the
    verdict, or None."""
    from .verdict import StepVerdict

    found = _derivative_of(grader, eq.lhs) if eq.latex else None
    if found is None:
        return None
    base, derive, label, what = found
    if _model_symbol(grader, base):
        return None
    names = grader.names
    names.used = []
    saved = names.active, names.right
    names.active = True
    try:
        names.right = False
        own_value = names.lookup(base)
        own_value = names.model(base) if own_value is None else own_value
        names.right = True
        right_value = names.lookup(base)
        right_value = names.model(base) if right_value is None else right_value
    finally:
        names.active, names.right = saved
    if own_value is None or right_value is None or not isinstance(own_value, (sp.Expr, sp.MatrixBase)):
        return None
    own_expected, right_expected = derive(own_value), derive(right_value)
    used = [e for e in names.used if e.line or e.wrong]

    try:
        got, _ = grader.names.read(str(eq.value))
    except (LatexError, TypeError, ValueError, RecursionError) as err:
        why = f"{label}: {str(err).splitlines()[0][:200]}"
        return StepVerdict(
            name=label,
            key="",
            link="",
            status="unrecognised",
            label=eq.lhs,
            source=eq.source,
            line=eq.line,
            message=why,
        )
    fp = grader.sampler.fingerprint
    from .engine import equal

    def same(a, b):
        try:
            return bool(equal(fp(a), fp(b)).all())
        except (TypeError, ValueError, sp.ShapeError):
            return False

    right, own = same(got, right_expected), same(got, own_expected)
    wrong_entry = next((e for e in used if e.wrong), None)
    where = f" (line {used[-1].line})" if used and used[-1].line else ""
    caused_by, difference = None, None
    if right and (own or wrong_entry is None):
        status, message = "correct", f"{what}{where}"
    elif right:
        status = "correct-but-unsupported"
        message = f"right, but not {what} as you gave it{where}"
    elif own and wrong_entry is not None:
        status, caused_by = "follows-from-earlier-error", wrong_entry.wrong
        message = f"follows from the error in {wrong_entry.wrong} (line {wrong_entry.line}): {what} as you gave it"
    else:
        from .explain import describe

        status = "wrong"
        message = f"{describe(got, own_expected, grader.robot, grader.sampler)} ({what}{where})"
        difference = sp.simplify(got - own_expected) if not isinstance(got, sp.MatrixBase) else got - own_expected
    return StepVerdict(
        name=label,
        key="dt",
        link="",
        status=status,
        label=eq.lhs,
        source=eq.source,
        line=eq.line,
        expected=right_expected,
        got=got,
        difference=difference,
        caused_by=caused_by,
        message=message,
    )


_TRAILING_ARGS = re.compile(r"\(([^()]{0,%d})\)\s*$" % MAX_ARGS_TEXT)


def without_arguments(lhs: str) -> str:
    """A left-hand side without the argument list written after its name (``M_{12}(\\theta_2)``,
    ``K_1(\\theta,\\dot\\theta)``, ``g(q)``): the name it gives a value to."""
    m = _TRAILING_ARGS.search(lhs)
    if m is None or m.start() == 0:
        return lhs
    parts = [p.strip() for p in m.group(1).split(",")]
    if all(_ARG.fullmatch(p) and "ddot" not in p for p in parts):
        return lhs[: m.start()].rstrip()
    return lhs


def _model_symbol(grader, name: Name) -> bool:
    """Is ``name`` a symbol of the model (a length, a mass, a joint variable), read without the
    student's names?"""
    names, symbols = grader.names, grader.symbols
    saved, names.active = names.active, False
    steps, symbols.steps = symbols.steps, {}
    try:
        symbols(name)
        return True
    except (UnknownSymbol, LatexError):
        return False
    finally:
        names.active = saved
        symbols.steps = steps


def _alias_names(v) -> list[Name]:
    """The textbooks' names of the energy a verdict graded (``K_1``, ``T_1``, ``\\mathcal E_{K_1}``...)."""
    kinetic = v.key in ("T", "Tl")
    index = ""
    if v.key in ("Tl", "Vl"):
        index = v.name.rpartition("_")[2]
        if not index.isdigit():
            return []
    out = []
    for base in KINETIC_NAMES if kinetic else POTENTIAL_NAMES:
        if base.startswith("E") and len(base) > 1:  # E_{K_1}, E_{k,1} (Lynch & Park)
            out.append(Name("E", sub=base[1:] + index))
        else:
            out.append(Name(base, sub=index))
    return out


def keep_named(grader, eq, v, own, right, wrong: str) -> None:
    """After a step: a link's (or the total) energy kept under every textbook name of it, a
    speed given through its square (``v_2^2 = ...``) kept as the speed ``v_2``, for later values.
    A name the student gave a value to themselves is never replaced by another's."""

    names = grader.names
    if v.status == "unrecognised" or own is None or isinstance(own, sp.MatrixBase):
        return
    if v.key in ("T", "V", "Tl", "Vl"):
        for alias in _alias_names(v):
            key = plain(alias)
            if key in names.entries and key not in names.aliased or _model_symbol(grader, alias):
                continue
            names.entries[key] = Entry(alias.latex(), own, right, eq.line, wrong)
            names.aliased.add(key)
        return
    m = re.fullmatch(r"\s*(?:\|(.+)\|\s*|(.+?))\s*\^\s*\{?\s*2\s*\}?\s*", eq.lhs) if eq.latex else None
    name = simple_name(m.group(1) or m.group(2)) if m else None
    if name is None or _model_symbol(grader, name) or not isinstance(own, sp.Expr):
        return
    # the speed whose square was given: its square gives the value back exactly
    names.entries[plain(name)] = Entry(name.latex(), sp.sqrt(own), sp.sqrt(right), eq.line, wrong)
    names.pending.pop(plain(name), None)


class Waiting:
    """Equations that use a name given only further on (``T = T_1 + T_2`` above ``T_1 = ...``):
    graded again, at their own line, as soon as every name they use is known; a name never
    given is said so at the end (:meth:`finish`)."""

    def __init__(self, grader):
        self.grader = grader
        self.items: list[tuple] = []  # (equation, its unrecognised verdict, the name missing)

    def hold(self, eq, new: list) -> None:
        """``eq`` could not be read for a name not given (yet): wait for it."""
        unknown = self.grader.names.unknown
        if len(new) == 1 and new[0].status == "unrecognised" and unknown and "unknown symbol" in new[0].message:
            if len(self.items) < MAX_WAITING:
                self.items.append((eq, new[0], unknown[-1]))

    def known(self, name: Name) -> bool:
        names = self.grader.names
        used, unknown = names.used, names.unknown
        names.used, names.unknown = [], []
        try:
            self.grader.symbols(name)
            return True
        except (LatexError, TypeError, ValueError, RecursionError):
            return False
        finally:
            names.used, names.unknown = used, unknown

    def retry(self, grade) -> None:
        """Grade again each waiting equation whose missing name is now given; ``grade(eq)``
        grades one equation and returns its new verdicts (appended), which take the old
        verdict's place."""
        progress = True
        while progress and self.items:
            progress = False
            known = {m: self.known(m) for m in {item[2] for item in self.items}}  # each name looked up once
            for item in list(self.items):
                eq, old, missing = item
                if not known[missing]:
                    continue
                self.items.remove(item)
                verdicts = self.grader.verdicts
                at = next((k for k, x in enumerate(verdicts) if x is old), None)
                if at is None:
                    continue
                del verdicts[at]
                self.grader.names.unknown = []
                done = len(verdicts)
                new = grade(eq)
                verdicts[at:at] = verdicts[done:]
                del verdicts[done + len(new) :]
                self.hold(eq, new)
                progress = True

    def finish(self) -> None:
        """The names never given: said in the verdicts of the equations that use them."""
        from .notation import parse_lhs

        n = len(self.grader.robot.links) - 1
        for _eq, verdict, missing in self.items:
            plain = Name(missing.base, 0, missing.sub).latex()
            ref = parse_lhs(plain, lambda _: None) or parse_lhs(plain + "^2", lambda _: None)  # v_1: a speed
            indices = [k for k in (ref.index, *ref.entry) if k is not None] if ref is not None else []
            if ref is None or not all(1 <= k <= n for k in indices):
                continue  # not a quantity of this arm: "unknown symbol" (map it) says more
            where, _, rest = verdict.message.partition(": ")
            step = rest.partition(": ")[0] if ": unknown symbol" in rest else ""
            said = f"{missing.latex()} is used but never given"
            verdict.message = ": ".join(x for x in (where, step, said) if x)


#: the placeholder a partial of a named quantity is read as (a letter no derivation writes)
PARTIAL_MARK = "ð"
_PARTIAL_VALUE = re.compile(
    r"\\frac\s*\{\s*\\partial\s*((?:[^{}]|\{[^{}]{0,30}\}){1,40})\}\s*\{\s*\\partial\s*((?:[^{}]|\{[^{}]{0,30}\}){1,40})\}"
)


def partials_as_names(grader, text: str) -> str:
    """``text`` with each ``\\frac{\\partial X}{\\partial q_k}`` of a quantity ``X`` the student gave
    (``M_{11}``, ``d_{12}``, ``V``) by a joint variable or rate replaced, positions kept, by a
    placeholder name read as that partial of their value (:func:`partial_value`)."""
    out, start = text, 0
    names = grader.names
    while True:
        i = out.find("\\frac", start)
        if i < 0:
            return out
        start = i + 5
        m = _PARTIAL_VALUE.match(out, i)
        if m is None:
            continue
        name = _quantity(grader, m.group(1).strip())
        found = grader.symbols.coordinate_of(m.group(2).strip()) if name is not None else None
        if found is None:
            continue
        k, order = found
        var = (grader.robot.q if order == 0 else grader.robot.qd)[k - 1]
        key = next((s for s, v in names.partials.items() if v == (name, var)), None)
        if key is None:
            key = str(len(names.partials))
            names.partials[key] = (name, var)
        mark = f"{PARTIAL_MARK}_{{{key}}}"
        out = out[:i] + mark + " " * (m.end() - i - len(mark)) + out[m.end() :]


def _quantity(grader, text: str) -> Name | None:
    """The Name ``text`` is when it names a quantity with a value now (not a model symbol)."""

    name = simple_name(text)
    if name is None or _model_symbol(grader, name):
        return None
    names = grader.names
    used, unknown = list(names.used), list(names.unknown)
    try:
        grader.symbols(name)
        return name
    except (LatexError, TypeError, ValueError, RecursionError):
        return None
    finally:
        names.used, names.unknown = used, unknown


def partial_value(names, name: Name):
    """The value of a placeholder of :func:`partials_as_names` (own or right, as being read), or None."""
    if name.base != PARTIAL_MARK or name.sub not in names.partials:
        return None
    base, var = names.partials[name.sub]
    value = names.symbols(base)
    return value.diff(var) if isinstance(value, sp.MatrixBase) else sp.diff(value, var)


#: why a torque column written through names only is not graded
NAMES_ONLY = (
    "the torques written through names of whole quantities only ({}): a statement of the form, "
    "not graded (the equations of motion in matrix form are M q̈ + C q̇ + g)"
)


def names_only(grader, text: str) -> str:
    """The names of a value written only through the joint vector and whole quantities the
    student named (``M(q)\\ddot q``), no parameter or joint variable of its own; else ""."""
    from .notation import JOINT_VECTOR

    found: list[Name] = []
    try:
        parse(drop_arguments(grader, text), lambda n: found.append(n) or sp.Symbol(f"x{len(found)}"))
    except (LatexError, TypeError, ValueError, RecursionError, sp.ShapeError):
        return ""
    if not found or not any(n.base in JOINT_VECTOR and not n.sub for n in found):
        return ""
    for n in found:
        if n.base in JOINT_VECTOR and not n.sub:
            continue
        if n.sub or _model_symbol(grader, n):
            return ""
    return ", ".join(dict.fromkeys(n.latex() for n in found))


def form_only(grader, eq) -> bool:
    """``τ = M(q)\\ddot q`` (names only): recorded as not graded, said why; False for other values."""
    names = names_only(grader, str(eq.value)) if eq.latex else ""
    if names:
        grader._unrecognised(eq, NAMES_ONLY.format(names))
    return bool(names)


def symmetric_entry(grader, eq, ref) -> bool:
    """``M_{21} = M_{12}``: the inertia matrix's symmetry, right whatever the value of ``M_{12}``;
    from here ``M_{21}`` stands for the student's ``M_{12}`` (its latest value). False for other
    equations."""
    from .notation import parse_lhs
    from .verdict import StepVerdict

    if ref.key != "M" or len(ref.entry) != 2 or ref.entry[0] == ref.entry[1] or not eq.latex:
        return False
    other = simple_name(str(eq.value))
    mine = simple_name(eq.lhs)
    if other is None or mine is None or other.base != mine.base:
        return False
    ref2 = parse_lhs(other.latex(), lambda _: None)
    if ref2 is None or ref2.key != "M" or ref2.entry != ref.entry[::-1]:
        return False
    names = grader.names
    names.links[plain(mine)] = plain(other)
    names.entries.pop(plain(mine), None)
    given = names.entries.get(plain(other))
    where = f" (line {given.line})" if given is not None and given.line else ""
    grader.verdicts.append(
        StepVerdict(
            name=ref.name,
            key=ref.key,
            link="",
            status="correct",
            label=eq.lhs,
            source=eq.source,
            line=eq.line,
            message=f"the inertia matrix is symmetric: {mine.latex()} is {other.latex()}{where}, "
            f"whatever its value (used by name from here)",
        )
    )
    return True
