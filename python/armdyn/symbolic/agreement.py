"""Proof that two derivations agree, and structural checks of M and C.

:func:`check` compares ``tau`` of two :class:`EquationsOfMotion` (normally
Newton-Euler and Lagrange), checks that ``M`` is symmetric, and that the Coriolis
matrix ``C`` built from the Christoffel symbols of ``M`` reproduces the velocity terms
the Newton-Euler recursion computed on its own: ``tau == M qdd + C qd + g``.

``Mdot - 2C`` skew-symmetric is not reported: for the Christoffel ``C`` it holds by
construction once ``M`` is symmetric, so it would check nothing. (Against a ``C``
computed independently of ``M`` it is a real check: the Rust core's
``coriolis_matrix``, Echeandia & Wensing's algorithm, is tested that way, and equals
the symbolic ``C`` in tests/test_numeric_vs_symbolic.py.) Each check is done exactly where that is cheap (the expression
is small enough to reduce to 0 as a polynomial in the parameters, the joint
velocities/accelerations, prismatic coordinates and sin/cos of revolute ones,
modulo sin^2 + cos^2 = 1) and otherwise at random numeric points; the report says
which was used for each.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import sympy as sp

from ..dispatch import call
from . import dag
from .newton_euler_spherical import refuse_quasi_velocities
from .terms import EquationsOfMotion

#: an expression with more nodes than this is compared at random numeric points
EXACT_NODE_LIMIT = 4000


def trig_reduce(expr, q: sp.Matrix, keep_trig: bool = False):
    """``expr`` as an expanded polynomial in sin(q_i) -> S_i, cos(q_i) -> C_i with
    every S_i^2 replaced by 1 - C_i^2, so that an identity reduces to exactly 0.

    keep_trig: give the result back in sin(q_i), cos(q_i) (for display) instead of the
    polynomial variables."""
    S = {qi: sp.Dummy(f"S_{qi}") for qi in q}
    C = {qi: sp.Dummy(f"C_{qi}") for qi in q}
    table = {sp.sin(qi): S[qi] for qi in q}
    table.update({sp.cos(qi): C[qi] for qi in q})
    e = sp.expand(sp.sympify(expr).xreplace(table))
    for qi in q:
        s, c = S[qi], C[qi]
        while True:
            powers = [p for p in e.atoms(sp.Pow) if p.base == s and p.exp.is_Integer and p.exp >= 2]
            if not powers:
                break
            e = sp.expand(e.xreplace({p: s ** (p.exp - 2) * (1 - c**2) for p in powers}))
    if keep_trig:
        e = e.xreplace({v: k for k, v in table.items()})
    return e


def _exactly_zero(expr, q) -> bool:
    e = trig_reduce(expr, q)
    if e == 0:
        return True
    # something the polynomial reduction does not see (e.g. sin(2 q)): last resort
    return sp.simplify(e) == 0


@dataclass
class CheckResult:
    """One check: ``name``, ``passed``, ``how`` ("exact" or "numeric, N points"),
    ``max_error`` (largest absolute difference seen, 0 for exact)."""

    name: str
    passed: bool
    how: str
    max_error: float = 0.0

    def line(self) -> str:
        mark = "OK  " if self.passed else "FAIL"
        err = "" if self.how == "exact" else f", max |difference| {self.max_error:.2e}"
        return f"[{mark}] {self.name} ({self.how}{err})"


@dataclass
class AgreementReport:
    """Result of :func:`check`; ``bool(report)`` is True when every check passed."""

    robot: str
    results: list[CheckResult] = field(default_factory=list)
    #: random points drawn for the numeric checks (None: every check was exact)
    samples: int | None = None

    def __bool__(self) -> bool:
        return bool(self.results) and all(r.passed for r in self.results)

    def text(self) -> str:
        head = f"checks for '{self.robot}': " + ("all passed" if self else "FAILED")
        if any(r.how != "exact" for r in self.results):
            head += f" ({self.samples} random points for the numeric checks)"
        return "\n".join([head] + ["  " + r.line() for r in self.results])

    def _repr_html_(self) -> str:
        """Jupyter: the checks as a table (report_html.py, through :mod:`armdyn.dispatch`)."""
        return call("html", self)


class _NumericSampler:
    """Random states and parameter values, and evaluation of matrices at them."""

    def __init__(self, eom: EquationsOfMotion, samples: int, seed: int):
        robot = eom.robot
        self.symbols = list(eom.q) + list(eom.qd) + list(eom.qdd)
        self.symbols += sorted(robot.parameters.values(), key=lambda s: s.name)
        # symbols that are neither coordinates nor declared parameters still get values
        self.symbols += sorted(robot.free_symbols() - set(self.symbols), key=lambda s: s.name)
        rng = np.random.default_rng(seed)
        # parameters in [0.5, 2] keep masses positive and lengths non-degenerate
        n_state = 3 * robot.dof
        self.points = np.empty((samples, len(self.symbols)))
        self.points[:, :n_state] = rng.uniform(-np.pi, np.pi, (samples, n_state))
        self.points[:, n_state:] = rng.uniform(0.5, 2.0, (samples, len(self.symbols) - n_state))

    def evaluate(self, matrix: sp.Matrix) -> np.ndarray:
        """(samples, rows, cols) values of ``matrix``."""
        values = dict(zip(self.symbols, self.points.T))
        out = dag.evaluate(matrix, values)
        return np.moveaxis(out, -1, 0)


def _compare(name, a: sp.Matrix, b: sp.Matrix, q, sampler, exact: bool | None, tol: float) -> CheckResult:
    diff = a - b
    if exact is None:
        exact = not any(dag.larger_than(e, EXACT_NODE_LIMIT) for e in diff)
    if exact:
        return CheckResult(name, all(_exactly_zero(e, q) for e in diff), "exact")
    va, vb = sampler().evaluate(a), sampler().evaluate(b)
    if len(va) == 0:  # a check that evaluated nothing proves nothing
        return CheckResult(name, False, "numeric, 0 points", float("nan"))
    err = float(np.max(np.abs(va - vb))) if va.size else 0.0
    scale = max(1.0, float(np.max(np.abs(va))) if va.size else 1.0)
    # NaN/inf at a sample fails (comparisons with NaN are False; inf - inf is NaN)
    ok = bool(np.all(np.isfinite(va)) and np.all(np.isfinite(vb)) and err <= tol * scale)
    return CheckResult(name, ok, f"numeric, {len(va)} points", err)


def _mimic_angles(robot) -> bool:
    """Whether a mimic joint's coordinate is not just +-q_leader (``c q + o`` with
    ``c != +-1`` or ``o != 0``), which the exact reduction cannot handle."""
    for joint in getattr(robot, "mimic_joints", []):
        _, c, o = robot.follows(joint)
        if abs(c) != 1 or o != 0:
            return True
    return False


def check(
    a: EquationsOfMotion,
    b: EquationsOfMotion | None = None,
    *,
    exact: bool | None = None,
    samples: int = 25,
    seed: int = 0,
    tol: float = 1e-9,
    structure: bool = True,
) -> AgreementReport:
    """Check that ``a`` and ``b`` give the same tau, M symmetric, and that C (the
    Christoffel matrix of M) and g reproduce the Newton-Euler tau.

    exact:   True forces exact symbolic checks, False forces numeric ones, None
             (default) picks exact for small expressions and numeric otherwise (and
             numeric for a robot with mimic joints ``q = c q_leader + o`` other than
             ``+-q_leader``).
    samples: number of random (state, parameter) points for numeric checks (at least
             1); joint values in [-pi, pi], parameters in [0.5, 2].
    tol:     relative tolerance of numeric checks.
    structure: also check M symmetric and tau == M qdd + C qd + g (False: only
             compare tau, which is much cheaper for big arms).

    Raises ValueError if ``samples < 1`` (a sampled check with no samples checks nothing).
    """
    if isinstance(samples, bool) or not isinstance(samples, (int, np.integer)) or samples < 1:
        raise ValueError(f"samples must be a positive integer (random points for numeric checks), got {samples!r}")
    robot = a.robot
    refuse_quasi_velocities(robot, "armdyn.check (Newton-Euler against Lagrange)")
    if robot.floating:
        from ..errors import FloatingBaseError

        raise FloatingBaseError(
            "armdyn.check does not support a floating base (root_joint='free-flyer'): it is derived by "
            "Newton-Euler alone, and C is no Christoffel matrix of M for a base twist",
            f"robot '{robot.name}'",
            robot.meta.get("file"),
        )
    report = AgreementReport(robot.name)
    cache = {}
    if exact is None and _mimic_angles(robot):
        exact = False  # sin(c q + o) is no polynomial in sin q, cos q: compare at points

    def sampler():
        if "s" not in cache:
            cache["s"] = _NumericSampler(a, samples, seed)
            report.samples = samples
        return cache["s"]

    if b is not None:
        report.results.append(_compare(f"tau: {a.method} == {b.method}", a.tau, b.tau, a.q, sampler, exact, tol))
    if not structure:
        return report
    for eom in [a] + ([b] if b is not None else []):
        if eom.method == "lagrange":
            continue  # built symmetric by the method itself (Lagrange's Hessian): nothing to prove
        M = eom.M
        report.results.append(_compare(f"M symmetric ({eom.method})", M, M.T, a.q, sampler, exact, tol))
    # tau = M qdd + C qd + g (+ joint friction) on the Newton-Euler derivation when there
    # is one: its velocity terms come from the recursion (omega x I omega, ...), C only
    # from M's Christoffel symbols, so they agree only if both are right. (On a Lagrange
    # derivation alone the velocity terms are the same Christoffel sums: weaker.)
    e = next((x for x in (a, b) if x is not None and x.method == "newton-euler"), a)
    recon = e.M * e.qdd + e.C * e.qd + e.g
    name = f"tau ({e.method}) == M qdd + C qd + g, C from the Christoffel symbols of M"
    if any(x != 0 for x in e.friction):
        recon, name = recon + e.friction, name + ", + Fv qd + Fc sign(qd)"
    report.results.append(_compare(name, e.tau, recon, e.q, sampler, exact, tol))
    return report
