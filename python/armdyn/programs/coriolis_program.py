"""The Coriolis matrix C(q, qd) from the Christoffel symbols of M, as a straight-line program.

M comes as a program (:mod:`armdyn.programs.composite_mass_matrix`); its partial
derivatives are that program differentiated line by line (forward mode: for each
temporary ``t = e(a, b, ...)``, ``dt/dq_i = sum_a (de/da) (da/dq_i)``, with
``d cos q_k / dq_k = -sin q_k``), so nothing is expanded and zero derivatives vanish.
Then (Christoffel symbols of the first kind; Spong, Hutchinson, Vidyasagar eq. 7.58)::

    C[k, j] = sum_i 1/2 (dM[k, j]/dq_i + dM[k, i]/dq_j - dM[i, j]/dq_k) qd_i

the one C for which ``Mdot - 2 C`` is skew-symmetric, as in
:func:`armdyn.symbolic.terms.christoffel_coriolis`.
"""

from __future__ import annotations

import sympy as sp

from ..model import Robot
from .program import Builder, Program


def partial_derivative(e, a):
    """de/da for the sums, products, integer powers, sin and cos the builders emit
    (SymPy's diff for anything else); much cheaper than ``sp.diff`` on small terms."""
    if e == a:
        return sp.Integer(1)
    if e.is_Atom or a not in e.free_symbols:
        return sp.Integer(0)
    if e.is_Add:
        return sp.Add(*[partial_derivative(t, a) for t in e.args])
    if e.is_Mul:
        args = e.args
        terms = []
        for k, f in enumerate(args):
            df = partial_derivative(f, a)
            if df != 0:
                terms.append(sp.Mul(*args[:k], df, *args[k + 1 :]))
        return sp.Add(*terms)
    if e.is_Pow and e.exp.is_Integer:
        return e.exp * e.base ** (e.exp - 1) * partial_derivative(e.base, a)
    return sp.diff(e, a)


def christoffel_program(robot: Robot, M: Program, builder: Builder) -> Program:
    """C (n x n, row-major outputs) of ``robot`` from its mass-matrix program ``M``
    (built with ``builder``, whose temporaries it extends)."""
    n = robot.dof
    q = list(robot.q)
    b = builder
    trig = {}  # cos(q_k) / sin(q_k) -> their temporaries
    for s, e in M.assignments:
        if isinstance(e, (sp.cos, sp.sin)):
            trig[e] = s
    deriv: dict = {}  # temporary -> [d/dq_i for i in range(n)]

    def d_of(a, i):
        if a == q[i]:
            return sp.Integer(1)
        return deriv.get(a, (sp.Integer(0),) * n)[i]

    for s, e in M.assignments:
        row = []
        free = e.free_symbols
        for i in range(n):
            total = sp.Integer(0)
            for a in free:
                da = d_of(a, i)
                if da != 0:
                    total += partial_derivative(e, a).xreplace(trig) * da
            row.append(b.let(total, f"d{s.name}_{i + 1}") if total != 0 else sp.Integer(0))
        deriv[s] = row

    # dM[r][c] / d(its symbol a), once per entry of M: each is used for every q_i, and
    # C uses every dM/dq_i three times (in base parameters M's outputs are large sums, and
    # recomputing these was most of the time of C)
    partials: dict = {}

    def dM(r, c, i):
        if (r, c) not in partials:
            e = sp.sympify(M.outputs[r * n + c])
            partials[r, c] = [(partial_derivative(e, a).xreplace(trig), a) for a in e.free_symbols]
        return sum((p * d_of(a, i) for p, a in partials[r, c]), sp.Integer(0))

    qd = list(robot.qd)
    half = sp.Rational(1, 2)
    C = []
    for k in range(n):
        for j in range(n):
            terms = sp.Integer(0)
            for i in range(n):
                gamma = dM(k, j, i) + dM(k, i, j) - dM(i, j, k)
                if gamma != 0:
                    terms += b.let(gamma, f"G{k + 1}{j + 1}{i + 1}") * qd[i]
            C.append(b.let(half * terms, f"C{k + 1}{j + 1}"))
    return b.program(C, (n, n))
