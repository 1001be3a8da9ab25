"""Argument checks shared by :mod:`armdyn.numeric`'s functions: ``threads``, a floating
base where it is not supported, and the core's overflow told in the caller's words."""

from __future__ import annotations

import numpy as np

from ..errors import FloatingBaseError, ModelError
from ..model import Robot
from ..model.robot import NUMERIC_EVERYWHERE

MAX_THREADS = 256


def check_threads(threads):
    """Checked ``threads``: ``threads`` if it is None or an integer from 1 to MAX_THREADS;
    TypeError naming it for anything but an integer (``True`` is an int to Python and to
    PyO3), ValueError for an integer out of range (2**64 would be PyO3's OverflowError,
    naming nothing)."""
    if threads is None or type(threads) is int and 1 <= threads <= MAX_THREADS:
        return threads
    shown = repr(threads) if len(repr(threads)) <= 40 else f"{type(threads).__name__} {repr(threads)[:30]}..."
    message = f"threads: expected None or an integer from 1 to {MAX_THREADS}, got {shown}"
    if isinstance(threads, (bool, np.bool_)) or not isinstance(threads, (int, np.integer)):
        raise TypeError(message)
    if not 1 <= threads <= MAX_THREADS:
        raise ValueError(message)
    return int(threads)


def overflow_error(what: str, arrays: dict) -> ValueError:
    sizes = []
    for name, a in arrays.items():
        try:
            sizes.append(f"max |{name}| = {float(np.max(np.abs(np.asarray(a, dtype=float)))):.3g}")
        except (TypeError, ValueError):
            pass
    return ValueError(
        f"{what}: the result overflows float64 (not finite) for finite inputs ({', '.join(sizes)}); "
        "the state or torque is too large for this arm"
    )


def require_fixed_base(robot, what: str) -> None:
    """Raise :class:`~armdyn.errors.FloatingBaseError` naming ``what`` if ``robot`` (a Robot
    or a compiled model) has a floating base."""
    if getattr(robot, "floating", False):
        if isinstance(robot, Robot):
            robot.require_fixed_base(what)
        raise FloatingBaseError(
            f"{what} does not support a floating base (root_joint='free-flyer') yet; {NUMERIC_EVERYWHERE} do",
            f"robot '{robot.name}'",
        )


def fixed_base_threads(robot, threads, what: str):
    """The first lines of every function that has no floating-base form: refuse a floating
    ``robot`` (:func:`require_fixed_base`, naming ``armdyn.numeric.<what>``), then return
    ``threads`` checked by :func:`check_threads`."""
    if getattr(robot, "floating", False):
        require_fixed_base(robot, f"armdyn.numeric.{what}")
    return threads if threads is None else check_threads(threads)


def require_one_dof_joints(robot, what: str) -> None:
    """Raise :class:`~armdyn.errors.ModelError` naming ``what`` if ``robot`` (a Robot or a
    compiled model) has a joint of several coordinates (spherical, planar, floating): for
    what handles revolute and prismatic joints only. A compiled model tells them by its
    widths (each such joint has one configuration coordinate more than velocities)."""
    if isinstance(robot, Robot):
        robot.require_one_dof_joints(what)
        return
    nq, nv = getattr(robot, "nq", None), getattr(robot, "nv", None)
    if isinstance(nq, int) and isinstance(nv, int) and nq - nv != (1 if getattr(robot, "floating", False) else 0):
        raise ModelError(
            f"{what} handles revolute and prismatic joints only (yet); this model has joints of several "
            f"coordinates (nq {nq}, nv {nv}); {NUMERIC_EVERYWHERE} take them",
            f"robot '{robot.name}'",
        )
