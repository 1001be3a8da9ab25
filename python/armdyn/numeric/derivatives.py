"""Derivatives of the dynamics in :mod:`armdyn.numeric` (Carpentier & Mansard, RSS 2018):
of inverse and forward dynamics, of gravity, and M^-1 by the articulated-body recursion."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from .. import _core
from .checks import check_threads, fixed_base_threads, overflow_error
from .compiled import NumericModel, RobotLike, canonical_wrenches, compiled_model, core_model, mimic_model
from .dynamics import at_rest

# rnea_derivatives, aba_derivatives and minverse decide here which path a call takes: the
# common one (a Robot already compiled to a plain NumericModel, or that model itself, and
# no f_ext) goes straight to the Rust entry, every argument by position; a robot not
# compiled yet (no `_numeric_model`: AttributeError), mimic joints (a MimicModel, which
# the entry refuses with a TypeError before doing anything) and f_ext go through the
# `_<name>_path` functions after them, which also raise again what a bad argument raised.
# One state takes about a microsecond, so the dispatch is kept lean: trying the entry
# costs less than testing the model's type first, and f_ext, frame, threads and out are
# not keyword-only, because CPython 3.11 has no specialised call for a function with
# keyword-only parameters (about 30 ns more per call).


def rnea_derivatives(
    robot: RobotLike,
    q: ArrayLike,
    qd: ArrayLike,
    qdd: ArrayLike,
    f_ext: ArrayLike | None = None,
    frame: str = "local",
    threads: int | None = None,
    out=None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Partial derivatives of inverse dynamics, analytically (Carpentier & Mansard, RSS 2018).

    robot: a Robot (or its compiled :func:`compile_model`, whose f_ext rows follow the
    model's own link order). q, qd, qdd: (n,) or (N, n). Returns ``(dtau_dq, dtau_dqd, M)``,
    each (n, n) or (N, n, n), row = output, column = input: ``dtau_dq[i, j] = d tau_i / d q_j``;
    ``M = d tau / d qdd``.

    f_ext: external wrenches, one per link: shape (nlinks, 6) (or (N, nlinks, 6) for a
    batch), rows in ``list(robot.links)`` order (base first; the base's row does not act
    on the joints), each ``[fx, fy, fz, nx, ny, nz]`` (force, then moment). ``frame``
    says where: ``"local"``: in the link's frame, moment about its origin (the wrench
    moves with the link; Pinocchio's LOCAL ``fext``); ``"world"``: in base axes, moment
    about the base frame's origin (the wrench stays fixed in space). Then
    ``tau = M qdd + C qd + g - sum_L J_L^T w_L``.

    Joint friction, rotor inertia and offset (as in :func:`rnea`) are included: ``M`` has
    ``diag(Ia)``, ``dtau_dqd`` has ``diag(Fv)``. Coulomb friction ``Fc sign(qd)`` is
    piecewise constant: it adds nothing, also at ``qd_k = 0`` where rnea's term jumps
    (``sign(0) = 0``) and has no derivative; the value given there is that of either side.
    Robots with mimic joints: ``G^T D_full G`` (chain rule, see :mod:`armdyn.mimic`); no f_ext.
    A floating base (module doc): q (nq,), qd, qdd (nv,) (or with a leading N); every
    result (nv, nv), ``dtau_dq`` on the tangent space; f_ext in the link frames only (the
    base link's row acts on the base; ``frame="world"`` is a NotImplementedError).

    out: optionally, the three arrays to write the results into and return (float64,
    C-contiguous, the results' shapes, sharing no memory with the inputs): a loop over
    batches then allocates nothing, and a large batch is spared the first-touch page
    faults of fresh arrays.
    """
    threads = threads if threads is None else check_threads(threads)  # (Rust would read True as 1)
    if f_ext is None:
        try:  # the core takes a NumericModel only: a Robot's cached one, or the model itself
            return _core.rnea_derivatives(robot._numeric_model, q, qd, qdd, None, frame, threads, out)  # type: ignore[union-attr]
        except (AttributeError, TypeError):
            pass  # not compiled yet, or mimic joints (see above)
    return _rnea_derivatives_path(robot, q, qd, qdd, f_ext, frame, threads, out)


def aba_derivatives(
    robot: RobotLike,
    q: ArrayLike,
    qd: ArrayLike,
    tau: ArrayLike,
    f_ext: ArrayLike | None = None,
    frame: str = "local",
    threads: int | None = None,
    out=None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Partial derivatives of forward dynamics (Carpentier & Mansard, RSS 2018, IV.C).

    q, qd, tau: (n,) or (N, n). Returns ``(dqdd_dq, dqdd_dqd, Minv)``, each (n, n) or
    (N, n, n): ``dqdd_dq[i, j] = d qdd_i / d q_j`` and ``Minv = d qdd / d tau = M^-1``.
    f_ext, frame: as in :func:`rnea_derivatives`; joint friction, rotor inertia and mimic
    joints as there (``Minv`` is that of ``M + diag(Ia)``). out: as there. A floating base:
    as there.
    """
    threads = threads if threads is None else check_threads(threads)  # (Rust would read True as 1)
    if f_ext is None:
        try:  # as in rnea_derivatives
            return _core.aba_derivatives(robot._numeric_model, q, qd, tau, None, frame, threads, out)  # type: ignore[union-attr]
        except (AttributeError, TypeError):
            pass
    return _aba_derivatives_path(robot, q, qd, tau, f_ext, frame, threads, out)


def minverse(robot: RobotLike, q: ArrayLike, threads: int | None = None, out=None) -> np.ndarray:
    """The inverse of the joint-space inertia matrix, by the articulated-body recursion
    (without forming or factorising M; Carpentier 2018). q: (n,) or (N, n). Returns (n, n)
    or (N, n, n). M includes the rotor inertias, ``diag(Ia)``, as :func:`crba`. Robots
    with mimic joints: ``(G^T M_full G)^-1`` by Cholesky (ValueError when M is not
    positive definite). out: optionally, the array to write M^-1 into and return (float64,
    C-contiguous, the result's shape, not sharing memory with q). A floating base: q (nq,),
    M^-1 (nv, nv), from the CRBA and M's sparse factors.
    """
    threads = threads if threads is None else check_threads(threads)  # (Rust would read True as 1)
    try:  # as in rnea_derivatives
        return _core.minverse(robot._numeric_model, q, threads, out)  # type: ignore[union-attr]
    except (AttributeError, TypeError):
        pass
    return _minverse_path(robot, q, threads, out)


def _into(out, result):
    """``result`` (an array or a tuple of arrays) copied into the caller's ``out`` (same
    structure, float64, same shapes, writeable), for the paths that compute apart from
    the Rust entries' own ``out=`` (mimic joints); returns ``out``. None: ``result``."""
    if out is None:
        return result
    many = isinstance(result, tuple)
    outs = tuple(out) if many and isinstance(out, (tuple, list)) else (out,)
    results = result if many else (result,)
    if len(outs) != len(results):
        raise ValueError(f"out: expected {len(results)} arrays, got {len(outs)}")
    for k, (o, r) in enumerate(zip(outs, results)):
        name = f"out[{k}]" if many else "out"
        if not isinstance(o, np.ndarray) or o.dtype != np.float64:
            raise ValueError(f"{name}: expected a float64 numpy array, got {type(o).__name__}")
        if o.shape != r.shape:
            raise ValueError(f"{name}: expected shape {list(r.shape)}, got {list(o.shape)}")
        if not o.flags.writeable:
            raise ValueError(f"{name}: is read-only")
        o[...] = r
    return outs if many else out


def _rnea_derivatives_path(robot, q, qd, qdd, f_ext, frame, threads, out):
    """:func:`rnea_derivatives` for a robot not compiled yet (this compiles and caches
    it), mimic joints, and external wrenches (a Robot's moved to the compiled model's
    frames)."""
    model = compiled_model(robot)
    if type(model) is not NumericModel:  # mimic joints: the chain rule, see armdyn.mimic
        return _into(out, mimic_model(robot, "rnea_derivatives", f_ext, frame).rnea_derivatives(q, qd, qdd, threads))
    if f_ext is not None:
        f_ext = canonical_wrenches(robot, f_ext, frame)
    return _core.rnea_derivatives(model, q, qd, qdd, f_ext, frame, threads, out)


def _aba_derivatives_path(robot, q, qd, tau, f_ext, frame, threads, out):
    """:func:`aba_derivatives` off the common call (as above)."""
    model = compiled_model(robot)
    if type(model) is not NumericModel:  # mimic joints: the chain rule, see armdyn.mimic
        return _into(out, mimic_model(robot, "aba_derivatives", f_ext, frame).aba_derivatives(q, qd, tau, threads))
    if f_ext is not None:
        f_ext = canonical_wrenches(robot, f_ext, frame)
    return _core.aba_derivatives(model, q, qd, tau, f_ext, frame, threads, out)


def _minverse_path(robot, q, threads, out):
    """:func:`minverse` off the common call (a robot not compiled yet, mimic joints)."""
    model = compiled_model(robot)
    if type(model) is NumericModel:
        return _core.minverse(model, q, threads, out)
    # mimic joints: (G^T M_full G)^-1 by Cholesky (the constraint couples branches)
    return _into(out, mimic_model(robot, "minverse").minverse(q, threads))


def gravity_derivatives(robot: RobotLike, q: ArrayLike, *, threads: int | None = None) -> np.ndarray:
    """``dg/dq`` of the gravity torques: (n, n) or (N, n, n), ``[i, j] = d g_i / d q_j``. A
    floating base: (nv, nv), on the tangent space (``rnea_derivatives`` at rest, as
    Pinocchio's ``computeGeneralizedGravityDerivatives``), and so with joints of several
    coordinates (``nq != nv``)."""
    if getattr(robot, "nq", 0) != getattr(robot, "nv", 0):
        zero = at_rest(robot, q)
        return rnea_derivatives(robot, q, zero, zero, threads=threads)[0]
    threads = fixed_base_threads(robot, threads, "gravity_derivatives")
    try:
        mimic = mimic_model(robot, "gravity_derivatives")
        if mimic is not None:
            return mimic.gravity_derivatives(q, threads)
        return _core.gravity_derivatives(core_model(robot, "gravity_derivatives"), q, threads)
    except FloatingPointError:  # the core checks its result: an overflow from finite inputs
        raise overflow_error("gravity_derivatives", {"q": q}) from None
