"""armdyn's numeric API over Dask arrays: the same functions, for batches that do not fit
one machine (or one process).

    import dask.array as da
    from armdyn import dask as ad
    q = da.from_array(q_np, chunks=(100_000, -1))     # (N, dof), chunked along states
    tau = ad.rnea(ur5, q, qd, qdd)                    # lazy (N, dof); .compute() anywhere
    run = ad.simulate(ur5, q0, dt=1e-3, steps=1000, stride=10)   # lazy arrays of a Trajectory
    dq, dqd, M = dask.compute(*ad.rnea_derivatives(ur5, q, qd, qdd))   # (N, dof, dof) each

Every function maps the Rust core over blocks of rows with ``dask.array.map_blocks``;
the compiled model (``armdyn.NumericModel``) pickles (it is rebuilt from its
description), so the graph runs on any scheduler: threads, processes, or a
``distributed`` cluster (``dask-jobqueue`` on a batch system, ``dask-kubernetes``...).
Inputs are ``(N, dof)`` arrays (Dask, or NumPy which is wrapped with ``chunks``), chunked
along the states only (the joint axis is made one chunk). Within a block the core uses
``threads`` threads (default 1: Dask provides the parallelism across blocks). Results
equal the in-process functions bit for bit (each row is computed alone, whatever the
blocking).

Conventions (docs/architecture.md): SI units, radians; ``M(q) qdd + C(q, qd) qd + g(q) = tau``.
"""

from __future__ import annotations

import numpy as np

from .numeric import check_threads, compiled_model, core_model

__all__ = ["rnea", "aba", "crba", "simulate", "rnea_derivatives", "aba_derivatives", "minverse", "gravity_derivatives"]


def _arrays(dof, chunks, *xs):
    """Dask arrays (N, width) with the joint axis in one chunk and row chunks aligned to
    the first argument's. ``dof``: every argument's width, or one width per argument (q
    nq wide, the others nv: a floating base or joints of several coordinates)."""
    import dask.array as da

    widths = list(dof) if isinstance(dof, (tuple, list)) else [dof] * len(xs)
    out = []
    for k, (x, width) in enumerate(zip(xs, widths)):
        if not isinstance(x, da.Array):
            x = da.from_array(np.asarray(x, dtype=float), chunks=(chunks, width) if chunks else "auto")
        if x.ndim != 2 or x.shape[1] != width:
            raise ValueError(f"argument {k}: shape {x.shape}, expected (N, {width})")
        if k and x.shape[0] != out[0].shape[0]:
            raise ValueError(f"argument {k}: shape {x.shape} does not match {out[0].shape} (one row per state)")
        x = x.astype(float).rechunk({1: -1} if k == 0 else {0: out[0].chunks[0], 1: -1})
        out.append(x)
    return out


def _c(*xs):
    # blocks received over the network can be unaligned; the core needs aligned C arrays
    return [np.require(x, dtype=float, requirements=["C", "A"]) for x in xs]


def _rnea(q, qd, qdd, model, threads):
    return model.rnea(*_c(q, qd, qdd), threads)


def _aba(q, qd, tau, model, threads):
    return model.aba(*_c(q, qd, tau), threads)


def _crba(q, model, threads):
    return model.crba(*_c(q), threads)


def _widths(model) -> tuple[int, int]:
    """``(nq, nv)`` of a compiled model: dof each, wider with a floating base (7 + dof, 6 +
    dof) or joints of several coordinates (Pinocchio's layouts, armdyn.configuration)."""
    return getattr(model, "nq", model.dof), getattr(model, "nv", model.dof)


def rnea(robot, q, qd, qdd, *, chunks=None, threads=1):
    """Lazy inverse dynamics ``tau = M qdd + C qd + g``: (N, dof) Dask arrays in and out
    (q (N, nq) and the others (N, nv) for a floating base or joints of several
    coordinates). NumPy inputs are wrapped with ``chunks`` rows per block (default:
    Dask's "auto")."""
    model = compiled_model(robot)
    threads = check_threads(threads)  # Rust reads True as 1
    nq, nv = _widths(model)
    q, qd, qdd = _arrays((nq, nv, nv), chunks, q, qd, qdd)
    return q.map_blocks(
        _rnea, qd, qdd, model=model, threads=threads, dtype=float, meta=np.empty((0, 0)), chunks=(q.chunks[0], (nv,))
    )


def aba(robot, q, qd, tau, *, chunks=None, threads=1):
    """Lazy forward dynamics ``qdd = M^-1 (tau - C qd - g)``: (N, dof) in and out (widths
    as :func:`rnea`'s)."""
    model = compiled_model(robot)
    threads = check_threads(threads)  # Rust reads True as 1
    nq, nv = _widths(model)
    q, qd, tau = _arrays((nq, nv, nv), chunks, q, qd, tau)
    return q.map_blocks(
        _aba, qd, tau, model=model, threads=threads, dtype=float, meta=np.empty((0, 0)), chunks=(q.chunks[0], (nv,))
    )


def crba(robot, q, *, chunks=None, threads=1):
    """Lazy joint-space inertia matrices: q (N, nq) -> M (N, nv, nv) (nq = nv = dof for
    1-dof joints on a fixed base)."""
    model = compiled_model(robot)
    threads = check_threads(threads)  # Rust reads True as 1
    nq, n = _widths(model)
    (q,) = _arrays(nq, chunks, q)
    return q.map_blocks(
        _crba,
        model=model,
        threads=threads,
        dtype=float,
        meta=np.empty((0, 0, 0)),
        new_axis=2,
        chunks=(q.chunks[0], (n,), (n,)),
    )


_PER_ROW = ("q_final", "qd_final")
_FLAGS = ("limit_step", "limit_joint", "nonfinite_step", "nonfinite_joint")


def _simulate(q0, qd0, model, options, samples, energies, threads):
    from .simulate import simulate as run_simulation

    q0, qd0 = _c(q0, qd0)
    run = run_simulation(model, q0, qd0, energies=energies, threads=threads, **options)
    rows = q0.shape[0]
    parts = [run.q.reshape(rows, -1), np.stack([run.qd, run.qdd, run.tau], axis=2).reshape(rows, -1), run.work]
    if energies:
        parts.append(np.stack([run.kinetic, run.potential], axis=2).reshape(rows, -1))
    parts += [run.q_final, run.qd_final] + [np.asarray(getattr(run, f), dtype=float)[:, None] for f in _FLAGS]
    return np.concatenate(parts, axis=1)


def simulate(
    robot,
    q0,
    qd0=None,
    *,
    dt,
    duration=None,
    steps=None,
    method="rk4",
    torque=None,
    controller=None,
    stride=1,
    energies=True,
    limits=None,
    chunks=None,
    threads=1,
):
    """Lazy :func:`armdyn.simulate.simulate` of the states ``q0``, ``qd0`` (N, dof), one
    block of rows per task. Returns a :class:`armdyn.simulate.Trajectory` whose arrays are
    Dask arrays (``t`` is NumPy): ``q``, ``qd``, ``qdd``, ``tau`` (N, S, dof); ``kinetic``,
    ``potential``, ``work`` (N, S); ``q_final``, ``qd_final`` (N, dof); ``limit_step``,
    ``limit_joint``, ``nonfinite_step``, ``nonfinite_joint`` (N,) int64. ``torque`` may be None, (dof,) or
    (steps, dof) (shared by all states); a controller's targets are one state's.
    A floating base or joints of several coordinates: ``q0``, ``q``, ``q_final`` are nq
    wide, the others nv, as :func:`armdyn.simulate.simulate`'s.
    """
    import dask.array as da

    from .simulate import step_count
    from .simulate_arrays import BASE_VELOCITY_NAMES
    from .trajectory import PD, ComputedTorque, Trajectory, joint_limits

    model = compiled_model(robot)
    threads = check_threads(threads)  # Rust reads True as 1
    nq, dof = _widths(model)
    steps = step_count(duration, steps, dt)
    if torque is not None and (callable(torque) or np.ndim(torque) > 2):
        raise ValueError("armdyn.dask.simulate: torque must be None, (dof,) or (steps, dof)")
    if isinstance(controller, (PD, ComputedTorque)) and np.ndim(controller.target) > 1:
        raise ValueError("armdyn.dask.simulate: the controller's target must be one state's (1-d)")
    if qd0 is None:
        rows = np.shape(q0)[0] if np.ndim(q0) == 2 else 0
        qd0 = da.zeros((rows, dof), chunks=(q0.chunks[0], dof)) if isinstance(q0, da.Array) else np.zeros((rows, dof))
    q0, qd0 = _arrays((nq, dof), chunks, q0, qd0)
    if limits is None:  # the robot's own (the workers get the compiled model); a joint without
        # limits (a ball joint's +-inf) as the largest floats, which simulate takes and no finite q passes
        limits = tuple(np.nan_to_num(x) for x in joint_limits(robot))
    options = dict(
        dt=dt, steps=steps, method=method, torque=torque, controller=controller, stride=stride, limits=limits
    )
    samples = steps // stride + 1
    width = samples * (nq + 3 * dof) + samples + (2 * samples if energies else 0) + nq + dof + len(_FLAGS)
    packed = q0.map_blocks(
        _simulate,
        qd0,
        model=model,
        options=options,
        samples=samples,
        energies=energies,
        threads=threads,
        dtype=float,
        meta=np.empty((0, 0)),
        chunks=(q0.chunks[0], (width,)),
    )
    n = q0.shape[0]
    out = {"q": packed[:, : samples * nq].reshape(n, samples, nq)}
    at = samples * (nq + 3 * dof)
    states = packed[:, samples * nq : at].reshape(n, samples, 3, dof)
    out.update({name: states[:, :, k, :] for k, name in enumerate(("qd", "qdd", "tau"))})
    out["work"] = packed[:, at : at + samples]
    at += samples
    kinetic = potential = None
    if energies:
        e = packed[:, at : at + 2 * samples].reshape(n, samples, 2)
        kinetic, potential = e[:, :, 0], e[:, :, 1]
        at += 2 * samples
    out["q_final"], out["qd_final"] = packed[:, at : at + nq], packed[:, at + nq : at + nq + dof]
    at += nq + dof
    for k, name in enumerate(_FLAGS):
        out[name] = packed[:, at + k].astype(np.int64)
    t = np.arange(samples) * (stride * float(dt))
    return Trajectory(
        t=t,
        dt=float(dt),
        stride=stride,
        method=method,
        coordinate_names=[*(BASE_VELOCITY_NAMES if getattr(model, "floating", False) else ()), *model.coordinate_names],
        kinetic=kinetic,
        potential=potential,
        **out,
    )


# ------------------------------------------------------------------ derivatives
# Batches of (dof, dof) matrices, row = output, column = input (docs/architecture.md), chunked along
# the states like crba: a block of rows (r, dof) maps to (r, dof, dof). The functions
# with three results compute them in one call per block, packed as (r, 3, dof, dof), and
# hand back three lazy views of that one graph: compute them together
# (``dask.compute(*ad.rnea_derivatives(...))``) so each block runs once.


def _rnea_derivatives(q, qd, qdd, model, threads):
    from . import _core

    return np.stack(_core.rnea_derivatives(model, *_c(q, qd, qdd), threads=threads), axis=1)


def _aba_derivatives(q, qd, tau, model, threads):
    from . import _core

    return np.stack(_core.aba_derivatives(model, *_c(q, qd, tau), threads=threads), axis=1)


def _minverse(q, model, threads):
    from . import _core

    return _core.minverse(model, *_c(q), threads=threads)


def _gravity_derivatives(q, model, threads):
    from . import _core

    return _core.gravity_derivatives(model, *_c(q), threads)


def _matrices(function, model, q, *more, threads):
    """Map ``function`` (block rows (r, dof) -> (r, dof, dof)) over the row blocks."""
    n = model.dof
    return q.map_blocks(
        function,
        *more,
        model=model,
        threads=threads,
        dtype=float,
        meta=np.empty((0, 0, 0)),
        new_axis=2,
        chunks=(q.chunks[0], (n,), (n,)),
    )


def _triple(function, model, q, *more, threads):
    """Map ``function`` (block rows -> (r, 3, dof, dof)) and split its three results."""
    n = model.dof
    packed = q.map_blocks(
        function,
        *more,
        model=model,
        threads=threads,
        dtype=float,
        meta=np.empty((0, 0, 0, 0)),
        new_axis=[2, 3],
        chunks=(q.chunks[0], (3,), (n,), (n,)),
    )
    return packed[:, 0], packed[:, 1], packed[:, 2]


def rnea_derivatives(robot, q, qd, qdd, *, chunks=None, threads=1):
    """Lazy :func:`armdyn.numeric.rnea_derivatives` (without external wrenches): q, qd,
    qdd (N, dof) -> ``(dtau_dq, dtau_dqd, M)``, three (N, dof, dof) Dask arrays,
    ``dtau_dq[k, i, j] = d tau_i / d q_j`` at state k (compute them together, see above)."""
    model = core_model(robot, "rnea_derivatives")
    threads = check_threads(threads)  # Rust reads True as 1
    q, qd, qdd = _arrays(model.dof, chunks, q, qd, qdd)
    return _triple(_rnea_derivatives, model, q, qd, qdd, threads=threads)


def aba_derivatives(robot, q, qd, tau, *, chunks=None, threads=1):
    """Lazy :func:`armdyn.numeric.aba_derivatives` (without external wrenches): q, qd, tau
    (N, dof) -> ``(dqdd_dq, dqdd_dqd, Minv)``, three (N, dof, dof) Dask arrays."""
    model = core_model(robot, "aba_derivatives")
    threads = check_threads(threads)  # Rust reads True as 1
    q, qd, tau = _arrays(model.dof, chunks, q, qd, tau)
    return _triple(_aba_derivatives, model, q, qd, tau, threads=threads)


def minverse(robot, q, *, chunks=None, threads=1):
    """Lazy :func:`armdyn.numeric.minverse`: q (N, dof) -> M^-1 (N, dof, dof)."""
    model = core_model(robot, "minverse")
    threads = check_threads(threads)  # Rust reads True as 1
    (q,) = _arrays(model.dof, chunks, q)
    return _matrices(_minverse, model, q, threads=threads)


def gravity_derivatives(robot, q, *, chunks=None, threads=1):
    """Lazy :func:`armdyn.numeric.gravity_derivatives`: q (N, dof) -> dg/dq (N, dof, dof),
    ``[k, i, j] = d g_i / d q_j`` at state k."""
    model = core_model(robot, "gravity_derivatives")
    threads = check_threads(threads)  # Rust reads True as 1
    (q,) = _arrays(model.dof, chunks, q)
    return _matrices(_gravity_derivatives, model, q, threads=threads)
