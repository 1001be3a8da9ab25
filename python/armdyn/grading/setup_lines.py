"""Equations that set the problem up rather than compute a step: the joint vector
``\\mathbf q = (\\theta_1, \\theta_2)^T`` (and its rates), the gravity vector
``\\mathbf g = (0, -g, 0)^T``, a relation between the model's parameters ``l_{c1} = l_1/2``,
the links' inertia tensors ``{}^{C_1}I_1 = {}^{C_2}I_2 = 0`` (when they are the model's).

They are read (the joint vector must be the model's coordinates, in its order; the gravity
vector one axis times the gravity magnitude; a relation only the parameters) and given the
status ``definition``: nothing in them is a step to judge (the model's own gravity and
parameters are used; the message says so).
"""

from __future__ import annotations

import sympy as sp

from .defined import simple_name
from .latex import LatexError, parse


def _value(grader, text: str):
    try:
        return parse(text, grader.symbols)
    except (LatexError, TypeError, ValueError, RecursionError, sp.ShapeError):
        return None


def _one_name(text: str):
    """The one symbol ``text`` is, its prescripts kept (``{}^{C_1}I_1``), else None."""
    names: list = []
    marker = sp.Symbol("armdyn_setup_marker")
    try:
        value = parse(text, lambda n: names.append(n) or marker)
    except (LatexError, TypeError, ValueError, RecursionError):
        return None
    return names[0] if value == marker and len(names) == 1 else None


def _inertia_link(name) -> int | None:
    """The link whose inertia tensor about its mass centre ``name`` is (``{}^{C_1}I_1``,
    ``I_{c1}``, ``I_1``), or None."""
    if name is None or name.base != "I" or name.dots:
        return None
    for text in (name.sub, name.pre_sup.lstrip("Cc_")):
        digits = text.replace("{", "").replace("}", "").lstrip("Cc_,")
        if digits.isdigit():
            return int(digits)
    return None


def _inertias(grader, eq) -> str | None:
    """``{}^{C_1}I_1 = {}^{C_2}I_2 = 0``: every name an inertia tensor, equal to the model's."""
    from .equations import sides

    parts = sides(eq.source)
    links = [_inertia_link(_one_name(p)) for p in parts[:-1]]
    if not links or None in links:
        return None
    value = _value(grader, parts[-1])
    value = sp.zeros(3, 3) if value == 0 else value
    named = list(grader.robot.links.values())
    if not isinstance(value, sp.MatrixBase) or value.shape != (3, 3):
        return None
    for k in links:
        if not 1 <= k < len(named) or any(sp.simplify(x) != 0 for x in value - named[k].inertia):
            return None
    if len(links) == 1:
        return f"the inertia tensor of link {links[0]} about its mass centre, as the model's: setup, read"
    which = ", ".join(map(str, links))
    return f"the inertia tensors of links {which} about their mass centres, as the model's: setup, read"


def setup_line(grader, eq) -> str | None:
    """The message for ``eq`` when it sets the problem up, else None."""
    if not eq.latex or eq.problem or isinstance(eq.value, list):
        return None
    inertia = _inertias(grader, eq)
    if inertia is not None:
        return inertia
    name = simple_name(eq.lhs)
    if name is None and eq.lhs.replace(" ", "") in ("\\dot{\\mathbf{q}}", "\\ddot{\\mathbf{q}}", "\\dot\\mathbf{q}"):
        name = None  # a dotted bold q: read below
    robot = grader.robot
    lhs = eq.lhs.replace(" ", "")
    dots = lhs.count("\\dot") - lhs.count("\\ddot") + 2 * lhs.count("\\ddot")
    base = lhs
    for mark in ("\\dot", "\\ddot", "\\mathbf", "\\boldsymbol", "\\bm", "\\vec", "{", "}"):
        base = base.replace(mark, "")
    value = None
    if base in ("q", "\\theta", "\\Theta", "\\mathrm{q}") and dots <= 2:
        value = _value(grader, str(eq.value))
        coords = [robot.q, robot.qd, robot.qdd][dots]
        if isinstance(value, sp.MatrixBase) and 1 in value.shape and len(value) == len(coords):
            if all(sp.simplify(a - b) == 0 for a, b in zip(value, coords, strict=True)):
                return "the joint vector (the model's coordinates, in its order): setup, read"
        return None
    if base in ("g", "{}^0g", "^0g") and (name is None or not name.sub):
        value = _value(grader, str(eq.value))
        if isinstance(value, sp.MatrixBase) and len(value) == 3:
            nonzero = [x for x in value if x != 0]
            if len(nonzero) == 1 and len(nonzero[0].free_symbols) == 1:
                return "the gravity vector: setup, read (the model's gravity is used)"
        return None
    if name is not None and not name.dots:
        try:
            symbol = grader.symbols(name)
        except (LatexError, TypeError, ValueError):
            return None
        joint = set(robot.q) | set(robot.qd) | set(robot.qdd)
        if not isinstance(symbol, sp.Symbol) or symbol in joint or symbol not in robot.free_symbols():
            return None
        value = _value(grader, str(eq.value))
        if isinstance(value, sp.Expr) and symbol not in value.free_symbols and not value.free_symbols & joint:
            if value.free_symbols:
                return f"a relation between the model's parameters ({name.latex()}): setup, read, not checked"
    return None
