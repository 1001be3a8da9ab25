"""Numeric dynamics: the Rust core (``armdyn._core``) behind a small NumPy API.

Every function takes a robot and one state or a batch of states:

* ``robot``: an :class:`armdyn.Robot` with no free symbols (bind them first with
  ``robot.bind({...})``; otherwise :class:`armdyn.errors.UnboundParameterError`
  names them), or a :class:`NumericModel` from :func:`compile_model`. The compiled
  model is built once per Robot and cached on it (attribute ``_numeric_model``).
* ``q``, ``qd``, ``qdd``, ``tau``: shape ``(n,)`` for one state or ``(N, n)`` for ``N``
  states (one per row), ``n = robot.dof``, joints in ``robot.coordinate_names`` order.
  Float64 C-contiguous arrays are used as they are; anything else is converted once.
  A wrong shape, NaN or inf raises ``ValueError`` naming the argument.
* ``threads``: for batches, the number of threads (``None``: all cores). The GIL is
  released while a batch is computed. Batched results equal single calls bit for bit.

Conventions (DESIGN.md): SI units, radians; ``M(q) qdd + C(q, qd) qd + g(q) = tau``;
gravity is the robot's vector in the base frame; frames as in :mod:`armdyn.model`.
"""

from __future__ import annotations

import numpy as np
import sympy as sp

from . import _core
from .errors import ModelError, UnboundParameterError
from .model import Link, Robot

__all__ = [
    "NumericModel",
    "compile_model",
    "rnea",
    "crba",
    "aba",
    "gravity",
    "bias",
    "coriolis_matrix",
    "kinetic_energy",
    "potential_energy",
    "forward_kinematics",
    "jacobian",
    "regressor",
]

#: A robot compiled for numeric evaluation (built by :func:`compile_model`). Its
#: methods mirror this module's functions without the ``robot`` argument
#: (``gravity`` is ``gravity_torques`` there); attributes ``dof``, ``nlinks``,
#: ``link_names``, ``coordinate_names``, ``gravity`` (3,), ``name``.
NumericModel = _core.NumericModel

_TYPE_CODES = {"revolute": 0, "prismatic": 1, "fixed": 2}


def _floats(values, where: str) -> list[float]:
    """SymPy numbers (exact or float) to Python floats."""
    out = []
    for v in values:
        try:
            out.append(float(sp.N(v)))
        except (TypeError, ValueError):
            raise ModelError(f"value {v} is not a real number", where) from None
    return out


def compile_model(robot: Robot | NumericModel) -> NumericModel:
    """The compiled numeric model of ``robot`` (built on first use, then cached on it).

    Raises UnboundParameterError if the robot still has free symbols, TypeError if
    ``robot`` is neither a Robot nor a NumericModel.
    """
    if isinstance(robot, NumericModel):
        return robot
    if not isinstance(robot, Robot):
        raise TypeError(f"expected an armdyn.Robot or NumericModel, got {type(robot).__name__}")
    cached = robot.__dict__.get("_numeric_model")
    if cached is not None:
        return cached
    free = robot.free_symbols()
    if free:
        names = sorted(s.name for s in free)
        raise UnboundParameterError(
            f"robot '{robot.name}' has unbound parameters {names}; "
            f"bind them to numbers first: robot.bind({{{', '.join(repr(n) + ': ...' for n in names)}}})"
        )
    joint_index = {j.child: k for k, j in enumerate(robot.joints)}
    parents, types, rotations, translations, axes = [], [], [], [], []
    masses, coms, inertias = [], [], []
    for j in robot.joints:
        where = f"joint '{j.name}'"
        parents.append(joint_index.get(j.parent, -1))
        types.append(_TYPE_CODES[j.type])
        rotations.append(np.reshape(_floats(j.rotation, where), (3, 3)).tolist())
        translations.append(_floats(j.xyz, where))
        axes.append(_floats(j.axis, where) if j.movable else [0.0, 0.0, 1.0])
        link = robot.links[j.child]
        where = f"link '{link.name}'"
        masses.append(_floats([link.mass], where)[0])
        coms.append(_floats(link.com, where))
        inertias.append(np.reshape(_floats(link.inertia, where), (3, 3)).tolist())
    # per movable joint [armature, viscous, coulomb, offset] (absent = 0); None when all zero
    joint_dynamics = [
        _floats([getattr(j, k) if getattr(j, k) is not None else 0 for k in ("armature", "damping", "friction", "torque_offset")],
                f"joint '{j.name}'")
        for j in robot.movable_joints
    ]
    if not any(any(row) for row in joint_dynamics):
        joint_dynamics = None
    gravity_vec = _floats(robot.gravity, f"robot '{robot.name}'")
    base = robot.links[robot.base]
    where = f"link '{base.name}'"
    try:
        model = NumericModel(
            parents, types, rotations, translations, axes, masses, coms, inertias, gravity_vec,
            list(robot.links), list(robot.coordinate_names), robot.name,
            _floats([base.mass], where)[0], _floats(base.com, where), joint_dynamics,
        )
    except ValueError as err:
        raise ModelError(str(err), f"robot '{robot.name}'") from None
    robot._numeric_model = model
    return model


def _model(robot) -> NumericModel:
    # Fast path: a Robot already compiled, or a NumericModel (whose
    # ``_numeric_model`` is itself).
    try:
        return robot._numeric_model
    except AttributeError:
        return compile_model(robot)


def rnea(robot, q, qd, qdd, *, threads=None):
    """Inverse dynamics by the recursive Newton-Euler algorithm.

    q, qd, qdd: (n,) or (N, n). Returns tau = M(q) qdd + C(q, qd) qd + g(q), same shape.
    """
    return _model(robot).rnea(q, qd, qdd, threads)


def crba(robot, q, *, threads=None):
    """Joint-space inertia matrix M(q) by the composite rigid-body algorithm.

    q: (n,) or (N, n). Returns the full symmetric M: (n, n) or (N, n, n).
    """
    return _model(robot).crba(q, threads)


def aba(robot, q, qd, tau, *, threads=None):
    """Forward dynamics by the articulated-body algorithm.

    q, qd, tau: (n,) or (N, n). Returns qdd = M^-1 (tau - C qd - g), same shape.
    """
    return _model(robot).aba(q, qd, tau, threads)


def gravity(robot, q, *, threads=None):
    """Gravity torques g(q) = rnea(q, 0, 0). q: (n,) or (N, n); same shape out."""
    return _model(robot).gravity_torques(q, threads)


def bias(robot, q, qd, *, threads=None):
    """Nonlinear effects h(q, qd) = C(q, qd) qd + g(q) = rnea(q, qd, 0).

    q, qd: (n,) or (N, n); same shape out.
    """
    return _model(robot).bias(q, qd, threads)


def coriolis_matrix(robot, q, qd, *, threads=None):
    """The Coriolis matrix C(q, qd) built from the Christoffel symbols of M.

    C qd = h - g, and Mdot - 2C is skew-symmetric. q, qd: (n,) or (N, n).
    Returns (n, n) or (N, n, n).
    """
    return _model(robot).coriolis_matrix(q, qd, threads)


def kinetic_energy(robot, q, qd, *, threads=None):
    """Kinetic energy T = 1/2 qd^T M(q) qd. q, qd: (n,) -> float, or (N, n) -> (N,)."""
    return _model(robot).kinetic_energy(q, qd, threads)


def potential_energy(robot, q, *, threads=None):
    """Potential energy V = -sum_i m_i gravity . p_ci over every link (the base and links
    welded to it included, a constant), zero with every centre of mass at the base
    origin (p_ci: link i's centre of mass in the base frame).

    q: (n,) -> float, or (N, n) -> (N,).
    """
    return _model(robot).potential_energy(q, threads)


def forward_kinematics(robot, q, *, threads=None):
    """Homogeneous pose of every link frame in the base frame.

    q: (n,) or (N, n). Returns (nlinks, 4, 4) or (N, nlinks, 4, 4), links in
    ``list(robot.links)`` order (base first); each ``[[R, p], [0, 0, 0, 1]]`` with R the
    link's axes in base coordinates and p its origin.
    """
    return _model(robot).forward_kinematics(q, threads)


def jacobian(robot, q, link, *, threads=None):
    """Geometric Jacobian of a link frame's origin.

    q: (n,) or (N, n); link: a link name, index in ``list(robot.links)``, or Link.
    Returns J (6, n) or (N, 6, n) with ``[v; w] = J qd``: rows [v_x v_y v_z w_x w_y w_z],
    v the velocity of the link frame's origin and w the link's angular velocity, both in
    base-frame axes (Spong's [J_v; J_w]; Pinocchio's LOCAL_WORLD_ALIGNED).
    """
    if isinstance(link, Link):
        link = link.name
    return _model(robot).jacobian(q, link, threads)


def regressor(robot, q, qd, qdd, *, threads=None, columns: str = "model"):
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
    if columns not in ("model", "all"):
        raise ValueError(f"columns must be 'model' or 'all', got {columns!r}")
    model = _model(robot)
    Y = _core.regressor(model, q, qd, qdd, threads)
    if columns == "all":
        return Y
    keep = robot.__dict__.get("_regressor_columns") if isinstance(robot, Robot) else None
    if keep is None:
        if not isinstance(robot, Robot):
            raise TypeError("columns='model' needs the Robot (a NumericModel does not say which terms a joint has)")
        first = 10 * len(robot.joints)
        extra = [first + 4 * i + k for i, j in enumerate(robot.movable_joints)
                 for k, name in enumerate(("armature", "damping", "friction", "torque_offset"))
                 if getattr(j, name) is not None]
        # a plain slice (a view, no copy) when the model has no joint terms
        keep = slice(0, first) if not extra else np.array(list(range(first)) + extra)
        robot._regressor_columns = keep  # cached like the compiled model
    return Y[..., keep]
