"""Centre of mass and centroidal momentum, for a floating base or a fixed one (the Rust
core's ``algo/centroidal.rs``; Pinocchio's ``centerOfMass``, ``jacobianCenterOfMass``,
``computeCentroidalMap``, ``computeCentroidalMomentum``,
``computeCentroidalMomentumTimeVariation`` and ``computeCentroidalMapTimeVariation``,
with the same results).

Arguments as in :mod:`armdyn.numeric`: ``robot`` a bound Robot or a compiled model; ``q``
``(nq,)`` or ``(N, nq)``, ``v`` and ``a`` ``(nv,)`` or ``(N, nv)`` (a floating base:
Pinocchio's free-flyer layout, ``nq = 7 + dof``, ``nv = 6 + dof``, the quaternion checked
unit; a fixed base: ``nq = nv = dof``); ``threads`` for batches. A wrong shape, NaN or inf
raises ``ValueError`` naming the argument.

* The world frame: the frame ``q``'s base pose is given in (a fixed base: the base frame).
* The mass is that of the bodies that move: every link a joint moves, and for a floating
  base the base link with the links welded to it. A fixed base and the links welded to it
  are left out (as Pinocchio leaves out its universe). A robot with none of that mass has
  no centre of mass (``ValueError``).
* The centroidal momentum ``h_G = [p; k_G]`` (6,): the linear momentum ``p = m c'``, then
  the angular momentum about the centre of mass ``c``, both in world axes.

A robot with mimic joints (a fixed base) is computed on its full tree, the matrices
mapped to the independent coordinates (:class:`armdyn.mimic.MimicModel`).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from . import _core
from .numeric import RobotLike, check_threads, compiled_model

__all__ = [
    "center_of_mass",
    "com_jacobian",
    "centroidal_momentum_matrix",
    "centroidal_momentum",
    "centroidal_momentum_rate",
    "centroidal_momentum_matrix_rate",
]


# Each function below runs the core's function on a compiled model, a MimicModel's method
# of the same name otherwise (the full tree's quantities in the independent coordinates),
# written out in each (no shared helper): a call costs 1 to 3 us, and a helper's frame and
# argument packing were a fifth of that.
_NumericModel = _core.NumericModel


def _too_large(what: str, err: FloatingPointError) -> ValueError:
    """The core found the result not finite from finite inputs: an overflow, a ValueError
    as in :mod:`armdyn.numeric`."""
    return ValueError(f"{what}: {err}; the state is too large for this robot")


def center_of_mass(robot: RobotLike, q: ArrayLike, *, threads: int | None = None) -> np.ndarray:
    """Centre of mass ``c`` of the bodies that move, in the world frame: (3,) or (N, 3)."""
    model = getattr(robot, "_numeric_model", None) or compiled_model(robot)
    try:
        if type(model) is _NumericModel:
            return _core.center_of_mass(model, q, threads if threads is None else check_threads(threads))
        return model.center_of_mass(q, threads if threads is None else check_threads(threads))
    except FloatingPointError as err:
        raise _too_large("center_of_mass", err) from None


def com_jacobian(robot: RobotLike, q: ArrayLike, *, threads: int | None = None) -> np.ndarray:
    """Jacobian ``J_c`` of the centre of mass, ``c' = J_c v`` (world axes): (3, nv) or
    (N, 3, nv). It is the first three rows of :func:`centroidal_momentum_matrix` over the
    mass."""
    model = getattr(robot, "_numeric_model", None) or compiled_model(robot)
    try:
        if type(model) is _NumericModel:
            return _core.com_jacobian(model, q, threads if threads is None else check_threads(threads))
        return model.com_jacobian(q, threads if threads is None else check_threads(threads))
    except FloatingPointError as err:
        raise _too_large("com_jacobian", err) from None


def centroidal_momentum_matrix(robot: RobotLike, q: ArrayLike, *, threads: int | None = None) -> np.ndarray:
    """Centroidal momentum matrix ``A_G`` (6, nv) or (N, 6, nv): ``h_G = A_G v``, rows the
    linear momentum then the angular momentum about the centre of mass, world axes
    (Orin and Goswami's; Pinocchio's ``computeCentroidalMap``). Column k is the momentum
    of the robot moving at a unit rate of velocity coordinate k."""
    model = getattr(robot, "_numeric_model", None) or compiled_model(robot)
    try:
        if type(model) is _NumericModel:
            return _core.centroidal_map(model, q, threads if threads is None else check_threads(threads))
        return model.centroidal_map(q, threads if threads is None else check_threads(threads))
    except FloatingPointError as err:
        raise _too_large("centroidal_momentum_matrix", err) from None


def centroidal_momentum(robot: RobotLike, q: ArrayLike, v: ArrayLike, *, threads: int | None = None) -> np.ndarray:
    """Centroidal momentum ``h_G = A_G(q) v`` (6,) or (N, 6): linear momentum, then the
    angular momentum about the centre of mass, world axes (by one pass over the bodies,
    without forming ``A_G``)."""
    model = getattr(robot, "_numeric_model", None) or compiled_model(robot)
    try:
        if type(model) is _NumericModel:
            return _core.centroidal_momentum(model, q, v, threads if threads is None else check_threads(threads))
        return model.centroidal_momentum(q, v, threads if threads is None else check_threads(threads))
    except FloatingPointError as err:
        raise _too_large("centroidal_momentum", err) from None


def centroidal_momentum_rate(
    robot: RobotLike, q: ArrayLike, v: ArrayLike, a: ArrayLike, *, threads: int | None = None
) -> np.ndarray:
    """Time derivative of the centroidal momentum, ``h_G' = A_G a + A_G' v`` (6,) or (N, 6)
    for the acceleration ``a`` (Pinocchio's ``computeCentroidalMomentumTimeVariation``);
    ``a = 0`` gives ``A_G' v``. Equal to the net external wrench on the robot, gravity
    included, about the centre of mass (world axes) when ``a`` is the motion it causes."""
    model = getattr(robot, "_numeric_model", None) or compiled_model(robot)
    try:
        if type(model) is _NumericModel:
            return _core.centroidal_momentum_rate(
                model, q, v, a, threads if threads is None else check_threads(threads)
            )
        return model.centroidal_momentum_rate(q, v, a, threads if threads is None else check_threads(threads))
    except FloatingPointError as err:
        raise _too_large("centroidal_momentum_rate", err) from None


def centroidal_momentum_matrix_rate(
    robot: RobotLike, q: ArrayLike, v: ArrayLike, *, threads: int | None = None
) -> np.ndarray:
    """Time derivative ``A_G'(q, v)`` of the centroidal momentum matrix (6, nv) or
    (N, 6, nv) when the robot moves at ``v``; ``A_G' v`` is
    ``centroidal_momentum_rate(robot, q, v, 0)``.

    Pinocchio's ``computeCentroidalMapTimeVariation`` moves the moments to the centre of
    mass as if it stood still: its ``dAg`` is this plus ``c' x`` (the centre of mass's
    velocity crossed with) the linear rows of ``A_G`` in the angular rows, a difference
    that ``dAg v`` does not see (``c' x m c' = 0``)."""
    model = getattr(robot, "_numeric_model", None) or compiled_model(robot)
    try:
        if type(model) is _NumericModel:
            return _core.centroidal_map_rate(model, q, v, threads if threads is None else check_threads(threads))
        return model.centroidal_map_rate(q, v, threads if threads is None else check_threads(threads))
    except FloatingPointError as err:
        raise _too_large("centroidal_momentum_matrix_rate", err) from None
