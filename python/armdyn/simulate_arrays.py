"""The arrays and energies the simulators share (:mod:`armdyn.simulate`, its adaptive
and callable loops, :mod:`armdyn.dask`): states and per-joint values checked and made
C-contiguous, and a floating base's energies from the CRBA."""

from __future__ import annotations

import numpy as np

from .configuration import rotate_vector


def contiguous(a):
    """C-contiguous, aligned float64 (arrays received over a network can be unaligned)."""
    return np.require(a, dtype=float, requirements=["C", "A"])


def checked_state(x, name, dof):
    try:
        a = np.asarray(x, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"{name}: cannot be read as an array of numbers") from None
    if a.ndim not in (1, 2) or a.shape[-1] != dof:
        raise ValueError(f"{name}: shape {a.shape}, expected ({dof},) or (N, {dof})")
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{name} contains NaN or inf")
    return a


def per_joint(x, name, dof):
    a = np.broadcast_to(np.asarray(x, dtype=float), (dof,)) if np.ndim(x) == 0 else np.asarray(x, dtype=float)
    if a.shape != (dof,):
        raise ValueError(f"{name}: expected a finite scalar or ({dof},) values, got shape {a.shape}")
    if not np.all(np.isfinite(a)):  # the shape is right: say what is wrong instead
        raise ValueError(f"{name} contains NaN or inf")
    return contiguous(a)


#: the names of a floating base's six velocity coordinates (base frame)
BASE_VELOCITY_NAMES = ("base_vx", "base_vy", "base_vz", "base_wx", "base_wy", "base_wz")


def floating_energies(model, q: np.ndarray, v: np.ndarray, threads=None, rows: int = 2048):
    """``(kinetic, potential)`` (N,) of a floating-base robot at the states ``q`` (N, 7 +
    dof), ``v`` (N, 6 + dof): ``T = 1/2 v^T M(q) v`` and ``V = -g . (m p_B + R_B h)``
    over every link, the base included, with ``m`` the total mass and ``h = m c`` the
    first moment of the whole robot in the base frame, both read from the CRBA's base
    block (``M[:3, :3] = m 1``, ``M[3:6, :3] = [h]x``). ``rows`` at a time (M is
    (6 + dof)^2 per state)."""
    kinetic, potential = np.empty(len(q)), np.empty(len(q))
    g = np.asarray(model.gravity, dtype=float).ravel()
    for at in range(0, len(q), rows):
        qs, vs = contiguous(q[at : at + rows]), contiguous(v[at : at + rows])
        M = model.crba(qs, threads)
        kinetic[at : at + rows] = 0.5 * np.einsum("ni,nij,nj->n", vs, M, vs)
        h = np.stack([M[:, 5, 1], M[:, 3, 2], M[:, 4, 0]], axis=-1)
        com_moment = M[:, 0, 0, None] * qs[:, :3] + rotate_vector(qs[:, 3:7], h)
        potential[at : at + rows] = -com_moment @ g
    return kinetic, potential
