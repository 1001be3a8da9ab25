"""Customized Newton-Euler in the base parameters.

A base parameter ``beta_j`` groups standard parameters onto one of them, ``pi_k(j)``
(Khalil's grouping: ``ZZ2R = ZZ2 + XX3 + ...``, the others eliminated), and the base
regressor keeps that parameter's column: ``Y_base[:, j] = Y[:, k(j)]``. So

    tau = Y_base beta = Y pi'     with  pi'_k(j) = beta_j,  every other pi'_k = 0,

and the customized Newton-Euler evaluated at ``pi'`` IS the base model: the zeros
propagate and the eliminated parameters cost nothing (Khalil and Dombre 2002, sec. 9.5).
This module finds ``k(j)`` (the column of the standard regressor equal to each base
column, at random points) and which link and slot (``M, MX, ..., ZZ``) each standard
parameter is (``regressor.pi`` matched to :func:`standard_parameters`). Columns that are
not a link's inertial parameter (rotor inertia, friction, offsets) are added to tau as
``Y_base[:, j] beta_j``. The result is checked against ``Y_base beta`` at random points
before use; when anything does not match, None is returned and the caller falls back
to ``Y_base beta`` through common-subexpression elimination.
"""

from __future__ import annotations

import numpy as np
import sympy as sp

from ..model import Robot
from ..symbolic import dag
from .customized_ne import standard_parameters


def _slots(robot: Robot):
    """[(link, slot index in STANDARD_NAMES order, (row, col) or None, expression)]."""
    params, definitions = standard_parameters(robot)
    table = dict(definitions)
    out = []
    for link, (M, MS, J) in params.items():
        entries = [M, MS[0], MS[1], MS[2], J[0, 0], J[0, 1], J[1, 1], J[0, 2], J[1, 2], J[2, 2]]
        where = [None, 0, 1, 2, (0, 0), (0, 1), (1, 1), (0, 2), (1, 2), (2, 2)]
        for slot, (value, w) in enumerate(zip(entries, where)):
            out.append((link, slot, w, sp.sympify(value), sp.sympify(table.get(value, value))))
    return out


def base_inertials(robot: Robot, Y: sp.Matrix, pi, Yb: sp.Matrix, beta_symbols, seed: int = 7):
    """``(parameters, extra)`` for :func:`customized_newton_euler` in the base
    parameters, or None. ``parameters``: ``{link: (M, MS, J)}`` with ``beta_j`` at its
    kept slot and zeros elsewhere; ``extra``: (dof,) expressions ``sum_j Yb[:, j] beta_j``
    over the base columns that are no link's inertial parameter."""
    pi = [sp.sympify(p) for p in pi]
    if Y.shape[1] != len(pi) or Yb.shape[1] != len(beta_symbols):
        return None
    slots = _slots(robot)
    # match by name first; expand only what no name matches (expanding every pair
    # against every slot took seconds on a 6-dof arm)
    by_name, by_value = {}, {}
    for s in slots:
        by_name.setdefault(str(s[3]), []).append(s)
    slot_of = {}
    for k, p in enumerate(pi):
        if not p.free_symbols:
            continue  # a number: no way to tell which parameter it is
        hits = by_name.get(str(p), [])
        if not hits:
            if not by_value:
                for s in slots:
                    by_value.setdefault(sp.expand(s[4]), []).append(s)
            hits = by_value.get(sp.expand(p), [])
        if len(hits) == 1:
            slot_of[k] = hits[0]
    # the standard column equal to each base column, at random points
    rng = np.random.default_rng(seed)
    states = set(robot.q) | set(robot.qd) | set(robot.qdd)
    free = sorted((dag.free_symbols(Y) | dag.free_symbols(Yb) | states), key=str)
    samples = 3
    values = {s: rng.uniform(-1.3, 1.3, samples) for s in free}
    Yn = dag.evaluate(Y, values)
    Ybn = dag.evaluate(Yb, values)
    if not (np.all(np.isfinite(Yn)) and np.all(np.isfinite(Ybn))):
        return None
    n = robot.dof
    params = {link: [sp.Integer(0), sp.zeros(3, 1), sp.zeros(3, 3)] for link in robot.links if link != robot.base}
    extra = sp.zeros(n, 1)
    for j, b in enumerate(beta_symbols):
        scale = max(1.0, float(np.abs(Ybn[:, j, :]).max()))
        matches = [k for k in range(Y.shape[1]) if np.abs(Yn[:, k, :] - Ybn[:, j, :]).max() <= 1e-9 * scale]
        inertial = [k for k in matches if k in slot_of]
        if inertial:
            link, slot, w, _, _ = slot_of[inertial[0]]
            if slot == 0:
                params[link][0] = b
            elif w is not None and isinstance(w, int):
                params[link][1][w] = b
            else:
                params[link][2][w] = params[link][2][w[::-1]] = b
        elif matches:
            extra += Yb[:, j] * b
        else:
            return None
    return {link: (v[0], v[1], v[2]) for link, v in params.items()}, extra
