"""A floating base's symbols, shared by the floating-base derivation
(:mod:`.newton_euler_floating`) and the numeric values of a derivation's symbols
(:func:`.newton_euler_spherical.state_values`): the base twist, its derivative and
gravity in the base frame, and gravity's value there."""

from __future__ import annotations

import numpy as np
import sympy as sp

from ..model import Robot

#: the base twist's symbols (linear, angular: Pinocchio's order), their time derivatives
#: and gravity in the base frame
BASE_VELOCITY = sp.Matrix(sp.symbols("vb_x vb_y vb_z wb_x wb_y wb_z"))
BASE_ACCELERATION = sp.Matrix([sp.Symbol(f"{s.name}_dot") for s in BASE_VELOCITY])
BASE_GRAVITY = sp.Matrix(sp.symbols("gb_x gb_y gb_z"))


def gravity_in_base(robot: Robot, quaternion) -> np.ndarray:
    """``R^T g`` (3,): the robot's gravity (world frame) in the base frame of orientation
    ``quaternion`` (x, y, z, w, Pinocchio's order; normalised here), the values of
    :data:`BASE_GRAVITY`. The robot's gravity must be numeric."""
    x, y, z, w = np.asarray(quaternion, dtype=float) / np.linalg.norm(np.asarray(quaternion, dtype=float))
    R = np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )
    return R.T @ np.array([float(c) for c in robot.gravity])
