"""Equations that state a law or a condition rather than compute a step's value.

* The Lagrange equation as students state it before using it,
  ``\\frac{d}{dt}\\frac{\\partial L}{\\partial \\dot{\\theta}} - \\frac{\\partial L}{\\partial \\theta} = \\tau``
  (any coordinate name, with or without a joint index; ``\\mathcal{L}``; ``Q`` for
  ``\\tau``): :func:`lagrange_law` says whether it is the right law, and if not what is
  off (a sign, the order of the terms, a missing ``d/dt``, a zero right-hand side).
* The free end's condition, ``f_{n+1} = 0``, ``n_{n+1} = 0`` (Craig's start of the
  inward iteration; ``f_3 = 0`` on a two-link arm): nothing acts on the last link's
  tip, so it is right exactly when the value is zero (:data:`FREE_END`).
"""

from __future__ import annotations

import re

from .notation import normalise

#: the law as it is right, for messages
LAW = "d/dt ∂L/∂q̇ − ∂L/∂q = τ"
#: what a wrong free-end condition is told
FREE_END = "nothing acts on the free end: the iteration starts from f_{n+1} = 0 and n_{n+1} = 0 (no load at the tool)"

_DDT = (r"\frac{d}{dt}", r"\frac{\mathrm{d}}{\mathrm{d}t}", r"\dfrac{d}{dt}", "d/dt", r"\frac{\mathrm{d}}{dt}")
_PARTIAL_L = re.compile(r"\\partial(?:L|\\mathcal\{?L\}?)")
RHS_TORQUE = re.compile(r"^(?:\\tau|Q|u)(?:_\{?[^{}]*\}?)?(?:\^\{?T\}?)?$")


def _signed_terms(s: str) -> list[tuple[int, str]]:
    """``s`` split at top-level ``+``/``-`` into (sign, term)."""
    out, depth, sign, start = [], 0, 1, 0
    for i, c in enumerate(s):
        if c in "{([":
            depth += 1
        elif c in "})]":
            depth -= 1
        elif c in "+-" and depth == 0:
            op = 1 if c == "+" else -1
            if s[start:i]:  # the end of a term: the next one starts with this sign
                out.append((sign, s[start:i]))
                sign = op
            else:  # a leading or repeated sign
                sign *= op
            start = i + 1
    if s[start:]:
        out.append((sign, s[start:]))
    return out


def _kind(term: str) -> str | None:
    """``"ddt"`` (d/dt ∂L/∂q̇), ``"dq"`` (∂L/∂q), ``"dqd"`` (∂L/∂q̇ without d/dt) or None."""
    if not _PARTIAL_L.search(term):
        return None
    ddt = any(term.startswith(p) for p in _DDT)
    dotted = "\\dot" in term.split("\\partial", 2)[-1] if term.count("\\partial") >= 2 else False
    if ddt:
        return "ddt"
    return "dqd" if dotted else "dq"


def lagrange_law(lhs: str, rhs: str) -> tuple[bool, str] | None:
    """Is ``lhs = rhs`` the Lagrange equation? None when it is not a statement of the
    law at all (no ∂L in it); else ``(right, message)``."""
    left, right = normalise(lhs), normalise(rhs)
    if not _PARTIAL_L.search(left) or _PARTIAL_L.search(right):
        return None
    terms = [(sign, _kind(t)) for sign, t in _signed_terms(left)]
    if any(k is None for _, k in terms) or len(terms) != 2:
        return False, f"not the Lagrange equation {LAW}"
    kinds = {k: sign for sign, k in terms}
    torque = bool(RHS_TORQUE.match(right))
    if "dqd" in kinds and "ddt" not in kinds:
        return False, f"d/dt missing before ∂L/∂q̇: the Lagrange equation is {LAW}"
    if set(kinds) != {"ddt", "dq"}:
        return False, f"not the Lagrange equation {LAW}"
    if right == "0":
        return False, f"the right-hand side is the joint force or torque τ ({LAW}); 0 only without actuation"
    if not torque:
        return False, f"the right-hand side should be the joint force or torque τ ({LAW})"
    if kinds["ddt"] == 1 and kinds["dq"] == -1:
        return True, ""
    if kinds["ddt"] == -1 and kinds["dq"] == 1:
        return False, f"the terms are in the wrong order: ∂L/∂q − d/dt ∂L/∂q̇ is −τ; the law is {LAW}"
    return False, f"wrong sign on {'∂L/∂q' if kinds['ddt'] == 1 else 'd/dt ∂L/∂q̇'}: the law is {LAW}"


_MATRIX_LETTER = re.compile(r"^(?:M|D|H|C|V|G|g|B|N|h|b|c)(?:\([^()]*\))?")


#: a whole term of the vector form: a matrix letter (``[M]`` too), its arguments, and an
#: un-indexed joint vector (``\ddot{q}``, ``\dot{\Theta}``), Craig's configuration-space rate
#: products (``B(\Theta)(\dot\Theta\dot\Theta)``, ``C(\Theta)[\dot\Theta^2]``) or none
_VECTOR_TERM = re.compile(
    r"^(?:\[(?:M|D|H|C|V|G|g|B|N|h|b|c)\]|(?:M|D|H|C|V|G|g|B|N|h|b|c)(?:\([^()]*\))?)"
    r"(?:\\d?dot\{\\?[A-Za-z]+\}|[(\[](?:\\dot\{\\?[A-Za-z]+\}(?:\^\{?2\}?)?){1,2}[)\]])?$"
)


def matrix_form(lhs: str, rhs: str) -> bool:
    """Is ``lhs = rhs`` the equations of motion in matrix form, ``M(q) q̈ + C(q, q̇) q̇ +
    g(q) = τ`` (Spong's ``D``, Craig's ``V(θ, θ̇)`` and ``G(θ)``, Siciliano's ``B(q)``, Lynch &
    Park's ``c(θ, θ̇)``; either side first)? With ``τ`` first every term must be a whole
    matrix times an un-indexed joint vector (``τ = [M]q̈ + [C]q̇ + [G]``), so that one
    joint's torque written out with entries (``τ_1 = M_{11} q̈_1 + …``) stays a step."""
    left, right = normalise(lhs), normalise(rhs)
    if RHS_TORQUE.match(left) and not RHS_TORQUE.match(right):
        terms = [t for _, t in _signed_terms(right)]
        if not all(_VECTOR_TERM.match(t) for t in terms) or not left.startswith("\\tau"):
            return False
        left, right = "+".join(re.sub(r"^\[(\w)\]", r"\1", t) for t in terms), left
    if not RHS_TORQUE.match(right):
        return False
    terms = [t for _, t in _signed_terms(left)]
    if not 2 <= len(terms) <= 5 or not all(_MATRIX_LETTER.match(t) for t in terms):
        return False
    return "\\ddot{" in terms[0] and all(len(t) <= 40 for t in terms)
