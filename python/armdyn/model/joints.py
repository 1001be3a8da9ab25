"""Links and joints: the placement, motion and inertia of each body (conventions: the
package docstring, :mod:`armdyn.model`)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Iterable

import numpy as np
import sympy as sp

from ..errors import ModelError
from .numbers import (
    EYE3,
    I3,
    Z_AXIS,
    ZERO,
    ZERO3,
    ZERO33,
    LazyField,
    Numbers,
    field_floats,
    is_zero,
    lazy_init,
    mat3,
    vec3,
)
from .rotations import axis_angle_matrix

JOINT_TYPES = ("revolute", "prismatic", "fixed", "spherical", "planar", "floating")
#: The joints of several coordinates, in Pinocchio's layouts (docs/architecture.md,
#: "Joint kinds"): type -> (nq, nv, the names of the velocity coordinates). Velocities
#: are the child frame's motion relative to the parent, in child-frame axes.
#:
#: * spherical: q = the rotation's unit quaternion x, y, z, w; v = the angular velocity;
#: * planar: q = x, y (in the placement frame), cos, sin of the turn about z; v = the
#:   linear velocity along the moved x and y axes, then the turn's rate;
#: * floating: q = the position (placement frame) then the unit quaternion x, y, z, w;
#:   v = the linear velocity of the child frame's origin, then the angular velocity.
MULTI_DOF = {
    "spherical": (4, 3, ("wx", "wy", "wz")),
    "planar": (4, 3, ("vx", "vy", "wz")),
    "floating": (7, 6, ("vx", "vy", "vz", "wx", "wy", "wz")),
}
#: Joint fields that add to tau (docs/architecture.md: Fv, Fc, Ia, offset), in that naming.
JOINT_DYNAMICS = ("damping", "friction", "armature", "torque_offset")


def _check_joint_dynamics(joint, where: str) -> None:
    """Numeric friction/armature/offset values must be finite; damping, friction and
    armature must not be negative (symbolic ones are checked once bound)."""
    for name in JOINT_DYNAMICS:
        raw = joint.__dict__[name]
        if isinstance(raw, Numbers):  # finite already; only the sign to check
            if name != "torque_offset" and raw.floats < 0:
                raise ModelError(f"{name} {float(raw.floats)} is negative (it must be >= 0)", where)
            continue
        value = getattr(joint, name)
        if value is None or value.free_symbols:
            continue
        try:
            x = complex(value.evalf())
        except (TypeError, ValueError):
            raise ModelError(f"{name} {value} is not a number", where) from None
        if x.imag != 0 or not np.isfinite(x.real):
            raise ModelError(f"{name} {value} is not a finite real number", where)
        if name != "torque_offset" and x.real < 0:
            raise ModelError(f"{name} {value} is negative (it must be >= 0)", where)


@dataclass(frozen=True)
class Link:
    """A rigid body.

    mass:    scalar (kg).
    com:     (3, 1) centre of mass in the link frame (m).
    inertia: (3, 3) inertia tensor about the centre of mass, link-frame axes (kg m^2).
    """

    name: str
    mass: sp.Expr = LazyField()
    com: sp.Matrix = LazyField()
    inertia: sp.Matrix = LazyField()

    def __post_init__(self):
        where = f"link '{self.name}'"
        try:
            lazy_init(self, "mass", sp.sympify, ZERO, ())
            lazy_init(self, "com", lambda v: vec3(v, "com"), ZERO3, (3,))
            lazy_init(self, "inertia", lambda v: mat3(v, "inertia"), ZERO33, (3, 3))
        except ModelError as err:
            raise err.located(element=where)
        except (sp.SympifyError, TypeError) as exc:
            raise ModelError(f"bad value ({exc})", where) from None

    def floats(self, name: str):
        """``mass``, ``com`` or ``inertia`` as a float array of shape ``()``, ``(3,)``
        or ``(3, 3)`` without building SymPy objects; None when it has free symbols."""
        return field_floats(self, name)


@dataclass(frozen=True)
class Mimic:
    """A joint that follows another one (URDF ``<mimic>``): its coordinate is
    ``multiplier * q_leader + offset``, so its velocity and acceleration are
    ``multiplier`` times the leader's, it adds no degree of freedom, and the torque
    (force) along it adds ``multiplier`` times itself to the leader's.

    joint:      name of the leader joint, of the same type (revolute or prismatic).
                A chain (a mimic of a mimic) is composed; a loop is an error.
    multiplier: dimensionless.
    offset:     rad (revolute) or m (prismatic).
    """

    joint: str
    multiplier: sp.Expr = sp.Integer(1)
    offset: sp.Expr = sp.Integer(0)

    def __post_init__(self):
        try:
            object.__setattr__(self, "multiplier", sp.sympify(self.multiplier))
            object.__setattr__(self, "offset", sp.sympify(self.offset))
        except (sp.SympifyError, TypeError) as exc:
            raise ModelError(f"bad mimic value ({exc})") from None
        if not isinstance(self.joint, str) or not self.joint:
            raise ModelError(f"mimic: the leader joint must be a name, got {self.joint!r}")


@dataclass(frozen=True)
class Joint:
    """A joint between ``parent`` and ``child`` links.

    type:     "revolute", "prismatic", "fixed", or one of several coordinates
              (:data:`MULTI_DOF`): "spherical", "planar" (in the placement frame's x-y
              plane) or "floating"; those take no axis, mimic or limits, and their joint
              dynamics apply to each of their velocity coordinates.
    xyz:      (3, 1) placement translation in the parent link frame (m).
    rotation: (3, 3) placement rotation: placement-frame axes in the parent frame.
    axis:     (3, 1) unit axis of motion in the placement frame (ignored when fixed).
    frame_xyz, frame_rotation:
              (3, 1) and (3, 3): where the child link's frame sits in the moved joint
              frame (default: on it). A frame off the joint's axis, like the exercise's
              frame 1 at the point mass, at l1 from joint 1's axis: ``frame_xyz = (l1, 0, 0)``.
              The child frame is ``placement * motion(q) * frame``.
    lower, upper, velocity, effort: optional limits, kept on the model (None when not given).
    damping, friction, armature, torque_offset: joint-space terms added to the rigid-body
              torque (docs/architecture.md): ``tau_k += armature qdd_k + damping qd_k
              + friction sign(qd_k) + torque_offset`` with sign(0) = 0. ``damping`` is the
              viscous coefficient Fv (N m s/rad or N s/m), ``friction`` the Coulomb level Fc,
              ``armature`` the rotor inertia Ia reflected to the joint (gear^2 times the
              rotor's own inertia), ``torque_offset`` a constant torque/force. None (the
              default) means absent, which is the same as 0. Numbers must be finite;
              damping, friction and armature must not be negative. Ignored on a fixed joint.
    mimic:    a :class:`Mimic` when the joint follows another joint (no coordinate of
              its own), else None.
    """

    name: str
    type: str
    parent: str
    child: str
    xyz: sp.Matrix = LazyField()
    rotation: sp.Matrix = LazyField()
    axis: sp.Matrix = LazyField()
    frame_xyz: sp.Matrix = LazyField()
    frame_rotation: sp.Matrix = LazyField()
    lower: sp.Expr | None = LazyField(optional=True)
    upper: sp.Expr | None = LazyField(optional=True)
    velocity: sp.Expr | None = LazyField(optional=True)
    effort: sp.Expr | None = LazyField(optional=True)
    damping: sp.Expr | None = LazyField(optional=True)
    friction: sp.Expr | None = LazyField(optional=True)
    mimic: Mimic | None = None
    armature: sp.Expr | None = LazyField(optional=True)
    torque_offset: sp.Expr | None = LazyField(optional=True)

    def __post_init__(self):
        where = f"joint '{self.name}'"
        if self.type not in JOINT_TYPES:
            raise ModelError(
                f"unknown joint type '{self.type}' (expected one of {', '.join(JOINT_TYPES)})",
                where,
            )
        try:
            lazy_init(self, "xyz", lambda v: vec3(v, "xyz"), ZERO3, (3,))
            lazy_init(self, "rotation", lambda v: mat3(v, "rotation"), EYE3, (3, 3))
            lazy_init(self, "axis", lambda v: vec3(v, "axis"), Z_AXIS, (3,))
            lazy_init(self, "frame_xyz", lambda v: vec3(v, "frame_xyz"), ZERO3, (3,))
            lazy_init(self, "frame_rotation", lambda v: mat3(v, "frame_rotation"), EYE3, (3, 3))
            for name in ("lower", "upper", "velocity", "effort") + JOINT_DYNAMICS:
                lazy_init(self, name, sp.sympify, None, ())
        except ModelError as err:
            raise err.located(element=where)
        except (sp.SympifyError, TypeError) as exc:
            raise ModelError(f"bad value ({exc})", where) from None
        if self.mimic is not None:
            if not isinstance(self.mimic, Mimic):
                raise ModelError(f"mimic must be a Mimic, got {type(self.mimic).__name__}", where)
            if self.type == "fixed":
                raise ModelError("a fixed joint cannot mimic another joint", where)
        if self.type in MULTI_DOF:
            # friction and rotor inertia apply to each of its coordinates, as MuJoCo's on a ball joint
            given = [k for k in ("lower", "upper", "velocity") if self.__dict__[k] is not None]
            if self.mimic is not None or given:
                what = "mimic" if self.mimic is not None else ", ".join(given)
                raise ModelError(
                    f"a {self.type} joint takes no {what} (not modelled for joints of several coordinates)", where
                )
        _check_joint_dynamics(self, where)
        for key in ("rotation", "frame_rotation"):
            if self.__dict__[key] is EYE3:  # the default: a rotation, no check needed
                continue
            R = self.floats(key)
            if R is not None:
                # R^T R = I (np.allclose's tolerances: atol 1e-9, rtol 1e-5) and det R > 0
                (a, b, c), (d, e, f), (g, h, i) = R.tolist()
                det = a * (e * i - f * h) - b * (d * i - f * g) + c * (d * h - e * g)
                if not (np.all(np.abs(R.T @ R - I3) <= 1e-9 + 1e-5 * I3) and det > 0):
                    raise ModelError(f"{key} {R.tolist()} is not a proper rotation matrix", where)
        axis = self.__dict__["axis"]
        if self.type in MULTI_DOF:
            return  # no axis: the motion is in the placement frame's own axes
        if self.type != "fixed" and isinstance(axis, Numbers):  # numbers: checked without SymPy
            norm = float(np.linalg.norm(axis.floats))
            if norm == 0:
                raise ModelError("axis is zero", where)
            if abs(norm - 1) > 1e-12:
                raise ModelError(f"axis {axis.floats.tolist()} is not a unit vector (norm {norm:.6g})", where)
        elif self.type != "fixed":
            norm2 = sp.expand(sum(c**2 for c in self.axis))
            zero = is_zero(norm2)
            if zero:
                raise ModelError("axis is zero", where)
            if zero is False and is_zero(norm2 - 1) is False:
                raise ModelError(
                    f"axis {list(self.axis)} is not a unit vector (norm {sp.sqrt(norm2).evalf(6)})",
                    where,
                )

    @property
    def movable(self) -> bool:
        return self.type != "fixed"

    @property
    def nq(self) -> int:
        """Configuration coordinates of the joint: 0 fixed, 1 revolute or prismatic, 4
        spherical or planar, 7 floating (a mimic joint's are its leader's)."""
        return MULTI_DOF[self.type][0] if self.type in MULTI_DOF else int(self.movable)

    @property
    def nv(self) -> int:
        """Velocity coordinates of the joint: 0, 1, 3 (spherical, planar) or 6 (floating)."""
        return MULTI_DOF[self.type][1] if self.type in MULTI_DOF else int(self.movable)

    @property
    def coordinate_names(self) -> tuple[str, ...]:
        """The names of its velocity coordinates: the joint's own name for a joint of one,
        ``<name>.wx`` and so on for the others (:data:`MULTI_DOF`), none when fixed."""
        if self.type in MULTI_DOF:
            return tuple(f"{self.name}.{c}" for c in MULTI_DOF[self.type][2])
        return (self.name,) if self.movable else ()

    def floats(self, name: str):
        """``xyz``, ``axis``, ``frame_xyz`` (shape ``(3,)``), ``rotation`` or
        ``frame_rotation`` (``(3, 3)``) as a float array without building SymPy
        objects; None when it has free symbols."""
        return field_floats(self, name)

    @property
    def has_frame_offset(self) -> bool:
        """True when the child frame is not the moved joint frame itself."""
        fx, fr = self.__dict__["frame_xyz"], self.__dict__["frame_rotation"]
        if isinstance(fx, Numbers) and isinstance(fr, Numbers):  # no SymPy for numbers
            return bool(np.any(fx.floats != 0) or np.any(fr.floats != np.eye(3)))
        return self.frame_xyz != sp.zeros(3, 1) or self.frame_rotation != sp.eye(3)

    def motion(self, q=0) -> tuple[sp.Matrix, sp.Matrix]:
        """The child frame in the placement frame at coordinate ``q``: ``(R, p)``, the
        joint's motion followed by the fixed ``frame`` offset."""
        if self.type in MULTI_DOF:
            Rm, pm = multi_dof_motion(self.type, q)
        elif self.type == "revolute":
            # at exactly 0 (the grouping's placements), Rodrigues' rotation is the identity
            at_zero = q is sp.S.Zero or (type(q) is int and q == 0)
            Rm, pm = sp.eye(3) if at_zero else axis_angle_matrix(self.axis, q), sp.zeros(3, 1)
        elif self.type == "prismatic":
            Rm, pm = sp.eye(3), self.axis * q
        else:
            Rm, pm = sp.eye(3), sp.zeros(3, 1)
        if not self.has_frame_offset:
            return Rm, pm
        return Rm * self.frame_rotation, pm + Rm * self.frame_xyz

    def transform(self, q=0) -> tuple[sp.Matrix, sp.Matrix]:
        """Child frame in the parent frame at coordinate ``q``: ``(R (3x3), p (3x1))``.

        ``R`` has the child frame's axes as columns, in parent coordinates; ``p`` is the
        child frame's origin in the parent frame.
        """
        R, p = self.motion(q)
        return self.rotation * R, self.xyz + self.rotation * p

    @property
    def child_axis(self) -> sp.Matrix:
        """(3, 1) the joint's axis in the child frame's axes (``axis`` unless the frame
        offset rotates)."""
        return self.frame_rotation.T * self.axis if self.has_frame_offset else self.axis

    def joint_point(self, q=0) -> sp.Matrix:
        """(3, 1) the placement frame's origin (a point on the joint's axis, fixed in the
        parent) in child-frame coordinates: zero for a revolute joint whose child frame
        sits on its axis (constant for any revolute joint), ``-q axis`` for a prismatic
        joint without offset."""
        slide = self.axis * q if self.type == "prismatic" else sp.zeros(3, 1)
        return -(self.frame_rotation.T * (self.frame_xyz + slide))

    def origin_motion(self, qd, qdd=0) -> tuple[sp.Matrix, sp.Matrix]:
        """Velocity and acceleration (3, 1) of the child frame's origin relative to the
        parent frame, in child-frame axes: ``(qd z, qdd z)`` for a prismatic joint;
        ``qd z x r`` and ``qdd z x r + qd^2 z x (z x r)`` for a revolute joint whose
        child origin sits at ``r`` from its axis point (zero on the axis)."""
        z, zero = self.child_axis, sp.zeros(3, 1)
        if self.type == "prismatic":
            return qd * z, qdd * z
        r = -self.joint_point()
        if self.type == "fixed" or r == zero:
            return zero, zero
        return qd * z.cross(r), qdd * z.cross(r) + qd**2 * z.cross(z.cross(r))


def multi_dof_motion(kind: str, q) -> tuple[sp.Matrix, sp.Matrix]:
    """``(R, p)`` of a joint of several coordinates (:data:`MULTI_DOF`) at its
    configuration ``q`` ((nq,) numbers or SymPy expressions; ``0``: the neutral one, no
    motion). Quaternions are used as given (unit length is the caller's to check)."""
    if isinstance(q, (int, sp.Integer)) and q == 0:
        return sp.eye(3), sp.zeros(3, 1)
    q = list(q)
    nq = MULTI_DOF[kind][0]
    if len(q) != nq:
        raise ModelError(f"a {kind} joint's configuration has {nq} coordinates, got {len(q)}")
    if kind == "planar":
        x, y, c, s = q
        return sp.Matrix([[c, -s, 0], [s, c, 0], [0, 0, 1]]), sp.Matrix([x, y, 0])
    p = sp.Matrix(q[:3]) if kind == "floating" else sp.zeros(3, 1)
    x, y, z, w = q[-4:]
    R = sp.Matrix(
        [
            [1 - 2 * (y**2 + z**2), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x**2 + z**2), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x**2 + y**2)],
        ]
    )
    return R, p


def coordinate_symbols(names: Iterable[str]) -> tuple[sp.Matrix, sp.Matrix, sp.Matrix]:
    """Joint coordinates ``q``, velocities ``qd`` and accelerations ``qdd`` as (n, 1)
    column vectors of plain symbols named ``<joint>``, ``<joint>_dot``, ``<joint>_ddot``.
    """
    names = list(names)
    q = sp.Matrix([sp.Symbol(n) for n in names])
    qd = sp.Matrix([sp.Symbol(f"{n}_dot") for n in names])
    qdd = sp.Matrix([sp.Symbol(f"{n}_ddot") for n in names])
    return q, qd, qdd
