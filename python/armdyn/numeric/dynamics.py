"""Dynamics of :mod:`armdyn.numeric`: inverse and forward dynamics, the inertia matrix,
gravity, bias, Coriolis matrix, energies and the torque regressor."""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

from .. import _core
from ..model import Robot
from .checks import check_threads, fixed_base_threads, overflow_error, require_fixed_base
from .compiled import RobotLike, canonical_wrenches, compile_model, compiled_model, core_model


def rnea(
    robot: RobotLike,
    q: ArrayLike,
    qd: ArrayLike,
    qdd: ArrayLike,
    f_ext: ArrayLike | None = None,
    frame: str = "local",
    threads: int | None = None,
) -> np.ndarray:
    """Inverse dynamics by the recursive Newton-Euler algorithm.

    q, qd, qdd: (n,) or (N, n). Returns tau = M(q) qdd + C(q, qd) qd + g(q), same shape;
    with external wrenches ``f_ext`` (see :func:`rnea_derivatives`), minus sum J^T w.
    A floating base (see the module doc): q (nq,) or (N, nq); qd, qdd (nv,) or (N, nv);
    tau (nv,): the wrench the base needs (base frame, force then moment; zero when the
    robot flies freely at that acceleration), then the joint torques.
    """
    # the common call (one state or a batch, no f_ext, a Robot compiled already) is kept
    # to two attribute lookups and the core's call: the core checks shapes, finiteness and
    # its result, and the floating base and mimic joints are its model's own methods
    if threads is not None:
        threads = check_threads(threads)
    if f_ext is None:
        try:
            model = robot._numeric_model  # type: ignore[union-attr]
        except AttributeError:  # not compiled yet (or not a robot: compile_model says so)
            model = compile_model(robot)
        try:
            return model.rnea(q, qd, qdd, threads)
        except FloatingPointError:  # the core checks its result: an overflow from finite inputs
            raise overflow_error("rnea", {"q": q, "qd": qd, "qdd": qdd}) from None
    require_fixed_base(robot, "rnea with f_ext")
    f_ext = canonical_wrenches(robot, f_ext, frame)
    return _finite(
        _core.rnea_ext(core_model(robot, "rnea with f_ext"), q, qd, qdd, f_ext, frame, threads),
        "rnea",
        q=q,
        qd=qd,
        qdd=qdd,
    )


def crba(robot: RobotLike, q: ArrayLike, threads: int | None = None) -> np.ndarray:
    """Joint-space inertia matrix M(q) by the composite rigid-body algorithm.

    q: (n,) or (N, n). Returns the full symmetric M: (n, n) or (N, n, n). A floating
    base (see the module doc): q (nq,) or (N, nq); M (nv, nv) in the order of the
    velocity (base linear, base angular in the base frame, joints); it does not depend
    on the base's pose. (``threads`` may be given by position: a call with keyword-only
    parameters costs CPython 3.11 about 30 ns more.)
    """
    if threads is not None:  # as in rnea
        threads = check_threads(threads)
    try:
        model = robot._numeric_model  # type: ignore[union-attr]
    except AttributeError:
        model = compile_model(robot)
    try:
        return model.crba(q, threads)
    except FloatingPointError:
        raise overflow_error("crba", {"q": q}) from None


def aba(
    robot: RobotLike,
    q: ArrayLike,
    qd: ArrayLike,
    tau: ArrayLike,
    f_ext: ArrayLike | None = None,
    frame: str = "local",
    threads: int | None = None,
) -> np.ndarray:
    """Forward dynamics by the articulated-body algorithm.

    q, qd, tau: (n,) or (N, n). Returns qdd = M^-1 (tau - C qd - g), same shape; with
    external wrenches ``f_ext`` (see :func:`rnea_derivatives`), M^-1 (tau + sum J^T w - C qd - g).
    A floating base (see the module doc): q (nq,) or (N, nq); qd, tau, qdd (nv,) or (N, nv),
    tau's first 6 the wrench applied to the base (base frame, force then moment), qdd's
    the base's linear then angular acceleration (base frame).
    """
    if threads is not None:  # as in rnea
        threads = check_threads(threads)
    if f_ext is None:
        try:
            model = robot._numeric_model  # type: ignore[union-attr]
        except AttributeError:
            model = compile_model(robot)
        try:
            return model.aba(q, qd, tau, threads)
        except ValueError as err:
            # the core calls any non-finite result "singular at this state"; an overflow (M
            # well conditioned, tau or qd too large) is told apart by factoring M at that q
            if "singular at this state" in str(err) and _well_conditioned(crba(robot, q, threads)):
                raise overflow_error("aba", {"qd": qd, "tau": tau}) from None
            raise
    require_fixed_base(robot, "aba with f_ext")
    f_ext = canonical_wrenches(robot, f_ext, frame)
    return _core.aba_ext(core_model(robot, "aba with f_ext"), q, qd, tau, f_ext, frame, threads)


def at_rest(robot: RobotLike, q: ArrayLike) -> np.ndarray:
    """Zeros of ``robot.nv`` per state of ``q`` (one state or a batch): a floating robot's
    velocities or accelerations at rest, for the quantities that are rnea's at them."""
    nv: int = robot.nv  # type: ignore[union-attr]  # only floating robots come here: a Robot or its model
    shape = np.shape(q)
    return np.zeros((*shape[:-1], nv) if len(shape) in (1, 2) else (nv,))


def gravity(robot: RobotLike, q: ArrayLike, *, threads: int | None = None) -> np.ndarray:
    """Gravity torques g(q) = rnea(q, 0, 0). q: (n,) or (N, n); same shape out. A floating
    base: q (nq,) or (N, nq), g (nv,) or (N, nv) (the base's wrench first)."""
    if getattr(robot, "floating", False):
        zero = at_rest(robot, q)
        return rnea(robot, q, zero, zero, threads=threads)
    threads = fixed_base_threads(robot, threads, "gravity")
    try:
        return compiled_model(robot).gravity_torques(q, threads)
    except FloatingPointError:
        raise overflow_error("gravity", {"q": q}) from None


def bias(robot: RobotLike, q: ArrayLike, qd: ArrayLike, *, threads: int | None = None) -> np.ndarray:
    """Nonlinear effects h(q, qd) = C(q, qd) qd + g(q) = rnea(q, qd, 0).

    q, qd: (n,) or (N, n); same shape out. A floating base: q (nq,), qd and h (nv,) (or
    with a leading N).
    """
    if getattr(robot, "floating", False):
        return rnea(robot, q, qd, at_rest(robot, q), threads=threads)
    threads = fixed_base_threads(robot, threads, "bias")
    try:
        return compiled_model(robot).bias(q, qd, threads)
    except FloatingPointError:
        raise overflow_error("bias", {"q": q, "qd": qd}) from None


def coriolis_matrix(robot: RobotLike, q: ArrayLike, qd: ArrayLike, *, threads: int | None = None) -> np.ndarray:
    """The Coriolis matrix C(q, qd) built from the Christoffel symbols of M.

    C qd = h - g, and Mdot - 2C is skew-symmetric. q, qd: (n,) or (N, n).
    Returns (n, n) or (N, n, n).
    """
    threads = check_threads(threads)  # (a floating base too: free_root.rs)
    try:
        return compiled_model(robot).coriolis_matrix(q, qd, threads)
    except FloatingPointError:
        raise overflow_error("coriolis_matrix", {"q": q, "qd": qd}) from None


def kinetic_energy(robot: RobotLike, q: ArrayLike, qd: ArrayLike, *, threads: int | None = None) -> float | np.ndarray:
    """Kinetic energy T = 1/2 qd^T M(q) qd. q, qd: (n,) -> float, or (N, n) -> (N,)."""
    if threads is not None:  # (a floating base too)
        threads = check_threads(threads)
    try:
        return compiled_model(robot).kinetic_energy(q, qd, threads)
    except FloatingPointError:
        raise overflow_error("kinetic_energy", {"q": q, "qd": qd}) from None


def potential_energy(robot: RobotLike, q: ArrayLike, *, threads: int | None = None) -> float | np.ndarray:
    """Potential energy V = -sum_i m_i gravity . p_ci over every link (the base and links
    welded to it included, a constant), zero with every centre of mass at the base
    origin (p_ci: link i's centre of mass in the base frame).

    q: (n,) -> float, or (N, n) -> (N,).
    """
    if threads is not None:  # (a floating base too)
        threads = check_threads(threads)
    try:
        return compiled_model(robot).potential_energy(q, threads)
    except FloatingPointError:
        raise overflow_error("potential_energy", {"q": q}) from None


def regressor(
    robot: RobotLike, q: ArrayLike, qd: ArrayLike, qdd: ArrayLike, *, threads: int | None = None, columns: str = "model"
) -> np.ndarray:
    """The joint torque regressor Y with ``rnea(q, qd, qdd) = Y @ pi`` (Rust core,
    algo/regressor.rs). q, qd, qdd: (n,) or (N, n). Returns (n, P) or (N, n, P).

    Columns, for every link but the base (in ``list(robot.links)`` order, links on
    fixed joints included): ``[m, m cx, m cy, m cz, Ixx, Ixy, Iyy, Ixz, Iyz, Izz]``,
    inertia about the link frame's origin in its axes (Pinocchio's order); then

    * ``columns="model"`` (default, ``robot`` a Robot): per movable joint the columns
      of the terms it has (``armature``, ``damping``, ``friction``, ``torque_offset`` not
      None: ``qdd, qd, sign(qd), 1``), the order of
      :func:`armdyn.identification.regressor`'s ``pi``;
    * ``columns="all"``: every movable joint's four columns ``[qdd, qd, sign(qd), 1]``.
    """
    threads = check_threads(threads)  # (a floating base too: free_root.rs)
    if columns not in ("model", "all"):
        raise ValueError(f"columns must be 'model' or 'all', got {columns!r}")
    # parameters about each link's frame on its joint (Robot.canonical), as the symbolic
    # armdyn.identification.regressor defines them
    model = core_model(robot, "regressor")
    try:
        Y = _core.regressor(model, q, qd, qdd, threads)
    except FloatingPointError:
        raise overflow_error("regressor", {"q": q, "qd": qd, "qdd": qdd}) from None
    if columns == "all":
        return Y
    keep = robot.__dict__.get("_regressor_columns") if isinstance(robot, Robot) else None
    if keep is None:
        if not isinstance(robot, Robot):
            raise TypeError("columns='model' needs the Robot (a NumericModel does not say which terms a joint has)")
        first = 10 * (len(robot.joints) + robot.floating)  # a floating base link has its ten
        # one row of four columns per velocity coordinate (a joint of several coordinates has several)
        rows = [j for j in robot.movable_joints for _ in range(j.nv)]
        extra = [
            first + 4 * i + k
            for i, j in enumerate(rows)
            for k, name in enumerate(("armature", "damping", "friction", "torque_offset"))
            if getattr(j, name) is not None
        ]
        # a plain slice (a view, no copy) when the model has no joint terms
        keep = slice(0, first) if not extra else np.array(list(range(first)) + extra)
        robot._regressor_columns = keep  # cached like the compiled model
    return Y[..., keep]


def _well_conditioned(M) -> bool:
    """Every (n, n) matrix of ``M`` finite, positive definite, condition number < 1e12."""
    M = np.asarray(M, dtype=float)
    try:
        np.linalg.cholesky(M)
    except np.linalg.LinAlgError:
        return False
    return bool(np.isfinite(M).all() and np.linalg.cond(M.reshape((-1,) + M.shape[-2:])).max() < 1e12)


def _all_finite(result) -> bool:
    """No NaN or inf in ``result`` (a float or an array). Small arrays by the sum of their
    entries as Python floats (NaN and inf propagate; a sum that overflows is checked
    again entry by entry), about 4 times quicker than ``np.isfinite`` on a 6-vector."""
    if type(result) is float:
        return math.isfinite(result)
    if result.ndim == 1 and result.size <= 64 and math.isfinite(sum(result.tolist())):
        return True
    return bool(np.isfinite(result).all())


def _finite(result, what: str, **arrays):
    """``result``, or the ValueError of :func:`overflow_error` if it holds NaN or inf: the core
    checks that the inputs are finite, so that is an overflow (qd = 1e300 squared in the
    velocity products), which the core would return silently."""
    if not _all_finite(result):
        raise overflow_error(what, arrays)
    return result
