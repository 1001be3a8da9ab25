"""The equations of motion ``M(q) qdd + C(q, qd) qd + g(q) = tau`` and their terms.

Both derivations (Newton-Euler, Lagrange) return an :class:`EquationsOfMotion`. Its
``tau`` is what the method produced; ``M``, ``C`` and ``g`` are split off ``tau`` on
first use (so timing ``tau`` does not pay for them):

* ``M[i, j] = d tau_i / d qdd_j``     (tau is linear in qdd; a method may supply M more
  cheaply: Lagrange's Hessian of T, Newton-Euler's unit-acceleration passes)
* ``g = tau(qd = 0, qdd = 0)``
* ``C`` from the Christoffel symbols of the first kind of ``M``:
  ``C[k, j] = sum_i 1/2 (dM[k, j]/dq_i + dM[k, i]/dq_j - dM[i, j]/dq_k) qd_i``,
  the one choice for which ``Mdot - 2 C`` is skew-symmetric.

All vectors are SymPy column matrices of shape (n, 1); matrices are (n, n).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property
from typing import Any, Callable

import symengine as se
import sympy as sp

from ..dispatch import call
from ..model import Robot
from . import dag


@dataclass(frozen=True)
class Step:
    """One intermediate result of a derivation, for reports.

    stage:  "outward" / "inward" (Newton-Euler), "energy" / "equations" (Lagrange).
    link:   link (or joint) the quantity belongs to, "" for whole-robot quantities.
    name:   short key, e.g. "omega", "vc_dot", "T_rot", "tau".
    label:  LaTeX of the quantity, e.g. r"{}^{1}\\omega_{1}".
    value:  SymPy expression or (3, 1) matrix, in the frame the label says.
    """

    stage: str
    link: str
    name: str
    label: str
    value: object
    note: str = ""


def christoffel_coriolis(M: sp.Matrix, q: sp.Matrix, qd: sp.Matrix) -> sp.Matrix:
    """Coriolis/centrifugal matrix C (n x n) from the Christoffel symbols of M (n x n).

    Differentiated by SymEngine (see lagrange.py), returned as SymPy."""
    n = M.shape[0]
    q_, qd_ = list(se.sympify(list(q))), list(se.sympify(list(qd)))
    M_ = [[se.sympify(M[k, j]) for j in range(n)] for k in range(n)]
    # dM[i][k][j] = dM[k, j]/dq_i, each entry differentiated once (M is symmetric)
    dM: list[list[list[Any]]] = [[[None] * n for _ in range(n)] for _ in range(n)]
    for i in range(n):
        for k in range(n):
            for j in range(k, n):
                dM[i][k][j] = dM[i][j][k] = M_[k][j].diff(q_[i])
    half = se.Rational(1, 2)
    C = sp.zeros(n, n)
    for k in range(n):
        for j in range(n):
            c = se.Integer(0)
            for i in range(n):
                c += half * (dM[i][k][j] + dM[j][k][i] - dM[k][i][j]) * qd_[i]
            C[k, j] = sp.sympify(c)
    return C


def time_derivative(expr, q: sp.Matrix, qd: sp.Matrix, qdd: sp.Matrix | None = None):
    """d/dt of an expression (or matrix) of q and qd, by the chain rule (SymEngine)."""
    if isinstance(expr, sp.MatrixBase):
        return expr.applyfunc(lambda e: time_derivative(e, q, qd, qdd))
    e = se.sympify(expr)
    pairs = list(zip(se.sympify(list(q)), se.sympify(list(qd))))
    if qdd is not None:
        pairs += list(zip(se.sympify(list(qd)), se.sympify(list(qdd))))
    return sp.sympify(sum((e.diff(x) * xd for x, xd in pairs), se.Integer(0)))


@dataclass
class EquationsOfMotion:
    """Closed-form equations of motion of a robot, ``M qdd + C qd + g = tau``.

    robot:      the :class:`~armdyn.model.Robot` they describe.
    method:     "newton-euler" or "lagrange".
    q, qd, qdd: (n, 1) joint coordinates, velocities, accelerations (plain symbols).
    tau:        (n, 1) joint torques/forces as the method produced them (not simplified).
    steps:      list of :class:`Step`, every intermediate result in order.
    parameters: dict name -> Symbol of the model parameters.
    """

    robot: Robot
    method: str
    tau: sp.Matrix
    steps: list[Step] = field(default_factory=list)
    # a method may supply a function computing M on first use (Lagrange: the Hessian of
    # T; Newton-Euler: Walker-Orin unit-acceleration passes); otherwise d tau/d qdd
    _M_builder: Callable[[], sp.Matrix] | None = None

    @property
    def q(self) -> sp.Matrix:
        return self.robot.q

    @property
    def qd(self) -> sp.Matrix:
        return self.robot.qd

    @property
    def qdd(self) -> sp.Matrix:
        return self.robot.qdd

    @property
    def parameters(self) -> dict[str, sp.Symbol]:
        return self.robot.parameters

    @cached_property
    def M(self) -> sp.Matrix:
        """Joint-space inertia matrix (n x n), d tau / d qdd."""
        if self._M_builder is not None:
            return self._M_builder()
        n = self.robot.dof
        return sp.Matrix(n, n, lambda i, j: sp.diff(self.tau[i], self.qdd[j]))

    @cached_property
    def g(self) -> sp.Matrix:
        """Gravity torques (n x 1): tau at qd = qdd = 0."""
        zero = {s: 0 for s in list(self.qd) + list(self.qdd)}
        return dag.xreplace(self.tau, zero)

    @cached_property
    def friction(self) -> sp.Matrix:
        """Joint friction (n x 1) ``Fv qd + Fc sign(qd)``: the part of tau outside
        ``M qdd + C qd + g`` (zero without joint friction). Rotor inertia is in M, the
        torque offset in g (see :mod:`armdyn.symbolic.joint_terms`)."""
        from .joint_terms import friction_torques

        return friction_torques(self.robot, self.qd)

    @cached_property
    def C(self) -> sp.Matrix:
        """Coriolis/centrifugal matrix (n x n) from the Christoffel symbols of M."""
        return christoffel_coriolis(self.M, self.q, self.qd)

    def symbol_names(self, fmt: str) -> dict:
        """Symbol -> name ("text" or "latex" ``fmt``) of the symbols beyond the robot's q,
        qd, qdd and parameters (a floating base's twist: newton_euler_floating.py)."""
        return {}

    def steps_of(self, name: str) -> dict[str, object]:
        """The values of one kind of step by link, e.g. ``eom.steps_of("omega")``."""
        return {s.link: s.value for s in self.steps if s.name == name}

    def step(self, name: str, link: str):
        """The value of one step, e.g. ``eom.step("vc_dot", "link2")``."""
        for s in self.steps:
            if s.name == name and s.link == link:
                return s.value
        raise KeyError(f"no step {name!r} for {link!r} in the {self.method} derivation")

    def __repr__(self) -> str:
        return f"EquationsOfMotion({self.robot.name!r}, method={self.method!r}, dof={self.robot.dof})"

    def _repr_html_(self) -> str:
        """Jupyter: tau as MathML (report_html.py, through :mod:`armdyn.dispatch`)."""
        return call("html", self)

    def _repr_latex_(self) -> str:
        """Jupyter: tau as LaTeX (report.py, through :mod:`armdyn.dispatch`)."""
        return call("latex", self)
