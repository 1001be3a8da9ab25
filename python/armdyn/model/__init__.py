"""The robot description: one model shared by the symbolic and the numeric engines.

Conventions (see docs/architecture.md):

* SI units, radians.
* A joint sits at a fixed placement in its parent link's frame: a translation ``xyz``
  (3,) and a rotation ``rotation`` (3x3, the placement frame's axes expressed in the
  parent frame, as URDF's ``origin``). It then moves about (revolute) or along
  (prismatic) its unit ``axis``, given in the placement frame. The child link's frame is
  the placement frame after that motion:

      revolute:   R_parent_child = rotation * Rot(axis, q),   p = xyz
      prismatic:  R_parent_child = rotation,                  p = xyz + rotation * axis * q
      fixed:      R_parent_child = rotation,                  p = xyz

* A link's inertia: ``mass``, centre of mass ``com`` (3,) in the link frame, and the
  inertia tensor ``inertia`` (3x3) about the centre of mass, in the link frame's
  orientation (as URDF). A point mass has a zero tensor.
* Gravity is a vector (3,) in the base frame, part of the model.
* Joints are kept in tree order (every joint's parent link is the base or the child of an
  earlier joint). The joint coordinates ``q`` are those of the movable (non-fixed) joints
  in that order.

Any number may be a SymPy expression of named parameters (``Robot.parameters``). A robot
with parameters is bound to numbers with :meth:`Robot.bind`.

The package, by concept: ``robot.py`` (:class:`Robot`), ``joints.py`` (:class:`Joint`,
:class:`Link`, :class:`Mimic`), ``tree.py`` (the joints' order, mimic joints' coordinates),
``rotations.py``, ``numbers.py`` (exact and lazy numbers) and
``frozen.py`` (the immutable containers).
"""

from .frozen import FrozenDict, FrozenList
from .joints import JOINT_DYNAMICS, JOINT_TYPES, Joint, Link, Mimic, coordinate_symbols
from .numbers import Numbers, exact_number
from .robot import Robot
from .rotations import axis_angle_matrix, rot_x, rot_y, rot_z, rpy_matrix, skew

__all__ = [
    "JOINT_DYNAMICS",
    "JOINT_TYPES",
    "FrozenDict",
    "FrozenList",
    "Joint",
    "Link",
    "Mimic",
    "Numbers",
    "Robot",
    "axis_angle_matrix",
    "coordinate_symbols",
    "exact_number",
    "rot_x",
    "rot_y",
    "rot_z",
    "rpy_matrix",
    "skew",
]
