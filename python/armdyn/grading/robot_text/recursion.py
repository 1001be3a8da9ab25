"""Where Craig's frames and mass centres are, from the accelerations of an outward recursion
that uses ``{}^{i}P_{C_i}`` and ``{}^{i}P_{i+1}`` only inside products.

A Newton-Euler text often names those vectors in its formulas and gives their values only in
words ("on X_i at l_ci"), yet writes out what they give:

- ``{}^{k}\\dot v_{C_k} = {}^{k}\\dot v_k + {}^{k}\\dot\\omega_k \\times P + {}^{k}\\omega_k \\times
  ({}^{k}\\omega_k \\times P)``: with the text's own ω_k, ω̇_k, v̇_k and v̇_{C_k}, the one
  constant P = ``{}^{k}P_{C_k}`` that makes it hold;
- ``{}^{k}\\dot v_k = R (\\dot v_{k-1} + \\dot\\omega_{k-1} \\times P + \\omega_{k-1} \\times
  (\\omega_{k-1} \\times P))``, R the stated rotation from frame k-1 to k: P = ``{}^{k-1}P_k``.

The product is linear in P, so P is solved for at random joint values and rates (each
parameter kept a symbol) and checked at others; a component the equation does not decide
(along a planar arm's z axis) is 0. The line it comes from is named: that line is then a
statement of the geometry, as a position written out would be.
"""

from __future__ import annotations

import random

import sympy as sp

from ..notation import parse_lhs
from .statements import Statement, parse

_KEYS = {"omega": "w", "omega_dot": "dw", "v_dot": "a", "vc_dot": "ac", "N": "N"}


def _vectors(equations, names) -> dict:
    """(kind, link) -> (3-vector in the link's own frame, equation), the first stated."""
    out: dict = {}
    for eq in equations:
        if not eq.latex or eq.problem:
            continue
        try:
            ref = parse_lhs(eq.lhs, lambda _latex: None)
        except (ValueError, RecursionError):
            continue
        if ref is None or ref.key not in _KEYS or ref.index is None or ref.frame not in (None, ref.index):
            continue
        key = (_KEYS[ref.key], ref.index)
        if key in out or len(str(eq.value)) > 2000:
            continue
        try:
            value = parse(str(eq.value), names)
        except Exception:  # noqa: BLE001 - any value the parser refuses is simply not used
            continue
        if isinstance(value, sp.MatrixBase) and len(value) == 3 and not value.free_symbols & _names_of_vectors(value):
            out[key] = (sp.Matrix(value).reshape(3, 1), eq)
    return out


def _names_of_vectors(value) -> set:
    """Symbols that look like a vector's name left in a value (P_C1, F2): not a stated value."""
    return {s for s in value.free_symbols if s.name[:1] in "PFNR" and any(ch.isdigit() for ch in s.name)}


def _solve(lhs, rhs_of, rates: list, seed: int):
    """The constant P with ``lhs == rhs_of(P)`` at random joint values and rates, or None."""
    P = sp.Matrix(sp.symbols("px py pz", real=True))
    rng = random.Random(seed)
    eqs = []
    points = [{r: sp.Rational(rng.randint(-9, 9) or 1, rng.randint(1, 5)) for r in rates} for _ in range(5)]
    diff = (lhs - rhs_of(P)).applyfunc(lambda e: sp.expand_trig(e))  # sin(q1 + q2) as the rotation gives it
    for pt in points[:3]:
        eqs += list(diff.xreplace(pt))
    sols = list(sp.linsolve([sp.expand(e) for e in eqs], list(P)))
    if len(sols) != 1:
        return None
    sol = sp.Matrix(sols[0]).subs({x: 0 for x in P})  # undecided components (along z of a planar arm): 0
    if sol.free_symbols & set(rates):
        return None
    for pt in points[3:]:
        if sp.expand((lhs - rhs_of(sol)).applyfunc(lambda e: sp.expand_trig(e)).xreplace(pt)) != sp.zeros(3, 1):
            return None
    return sp.simplify(sol)


def positions_from_accelerations(equations, names, q: list, rot: dict, stated: set) -> tuple[list, list]:
    """Statements ``Pc`` (link k's mass centre in frame k) and ``P`` (frame k's origin in frame
    k-1) solved from the text's own accelerations, for the k in neither ``stated`` set, and the
    assumptions naming each one's line."""
    vec = _vectors(equations, names)
    if not vec:
        return [], []
    rates = list(q) + sorted(
        {s for v, _ in vec.values() for s in v.free_symbols if s.name.endswith(("_dot", "_ddot"))}, key=str
    )
    out, notes = [], []
    n = len(q)
    for k in range(1, n + 1):
        w, dw, a, ac = (vec.get((x, k)) for x in ("w", "dw", "a", "ac"))
        if ("Pc", k) not in stated and w and dw and a and ac:
            W, dW, A = w[0], dw[0], a[0]
            P = _solve(ac[0], lambda p: A + dW.cross(p) + W.cross(W.cross(p)), rates, k)
            if P is not None:
                out.append(Statement("Pc", ac[1].line, ac[1].source, P, k, k))
                notes.append(
                    f"link {k}'s mass centre {{}}^{{{k}}}P_{{C_{k}}} = {list(P)}: the one vector that gives line "
                    f"{ac[1].line}'s {{}}^{{{k}}}\\dot v_{{C_{k}}} from the text's own ω{k}, ω̇{k}, v̇{k} "
                    "(its value is stated nowhere else)"
                )
        prev = [vec.get((x, k - 1)) for x in ("w", "dw", "a")]
        if k >= 2 and ("P", k) not in stated and all(prev) and a:
            W, dW, A0 = (p[0] for p in prev)
            c, s_ = sp.cos(q[k - 1]), sp.sin(q[k - 1])
            turns = [(rot[k][0], f"line {rot[k][1].line}'s")] if rot.get(k) and rot[k][1] is not None else []
            turns = turns or [(sp.Matrix([[c, -s_, 0], [s_, c, 0], [0, 0, 1]]), "joint {k}'s turn about z, as assumed")]
            for axes, whose in turns:
                into = axes.T  # frame k-1's coordinates to frame k's
                P = _solve(a[0], lambda p, into=into: into * (A0 + dW.cross(p) + W.cross(W.cross(p))), rates, 10 + k)
                if P is None:
                    continue
                out.append(Statement("P", a[1].line, a[1].source, P, k, k - 1))
                notes.append(
                    f"frame {k}'s origin {{}}^{{{k - 1}}}P_{{{k}}} = {list(P)}: the one vector that gives line "
                    f"{a[1].line}'s {{}}^{{{k}}}\\dot v_{{{k}}} from the text's own ω{k - 1}, ω̇{k - 1}, v̇{k - 1} "
                    f"and {whose.format(k=k)} rotation (its value is stated nowhere else)"
                )
                break
        N = vec.get(("N", k))
        if ("I", k) not in stated and N and w and dw:  # Euler's N = I ω̇ + ω × I ω, I = diag(p)
            W, dW = w[0], dw[0]
            D = _solve(N[0], lambda p: sp.diag(*p) * dW + W.cross(sp.diag(*p) * W), rates, 20 + k)
            if D is not None and any(x != 0 for x in D):
                if D[0] == 0 and D[1] == 0:  # only the moment about z decided: a thin rod along x (iyy = izz)
                    D = sp.Matrix([0, D[2], D[2]])
                out.append(Statement("I", N[1].line, N[1].source, sp.diag(*D), k, None))
                notes.append(
                    f"link {k}'s inertia about its mass centre diag{tuple(D)}: the one diagonal tensor that gives "
                    f"line {N[1].line}'s N_{k} from the text's own ω{k}, ω̇{k} (iyy = izz, ixx = 0 when it decides only izz: "
                    "a thin rod along x, as a planar arm's dynamics do not depend on them)"
                )
    return out, notes
