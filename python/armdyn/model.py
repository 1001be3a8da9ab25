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
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Iterable, Mapping

import numpy as np
import sympy as sp

from .dispatch import call
from .errors import ModelError
from .inertia import check_physical, physical_violations

JOINT_TYPES = ("revolute", "prismatic", "fixed")
#: Joint fields that add to tau (docs/architecture.md: Fv, Fc, Ia, offset), in that naming.
JOINT_DYNAMICS = ("damping", "friction", "armature", "torque_offset")


def _vec3(value, what: str) -> sp.Matrix:
    if isinstance(value, sp.MatrixBase) and value.shape == (3, 1):
        return sp.Matrix(value)  # entries are SymPy objects already (readers pass these)
    try:
        m = sp.Matrix(value)
    except Exception as exc:  # noqa: BLE001 - re-raised with context
        raise ModelError(f"{what} is not a 3-vector ({exc})") from None
    if m.shape == (1, 3):
        m = m.T
    if m.shape != (3, 1):
        raise ModelError(f"{what} must have 3 components, got shape {m.shape}")
    return m.applyfunc(sp.sympify)


def _mat3(value, what: str) -> sp.Matrix:
    if isinstance(value, sp.MatrixBase) and value.shape == (3, 3):
        return sp.Matrix(value)
    try:
        m = sp.Matrix(value)
    except Exception as exc:  # noqa: BLE001
        raise ModelError(f"{what} is not a 3x3 matrix ({exc})") from None
    if m.shape != (3, 3):
        raise ModelError(f"{what} must be 3x3, got shape {m.shape}")
    return m.applyfunc(sp.sympify)


def _is_zero(expr) -> bool | None:
    """True/False if decidable, None if it depends on free symbols."""
    expr = sp.sympify(expr)
    if expr.free_symbols:
        return None
    return bool(abs(complex(expr.evalf())) < 1e-12)


def exact_number(value: float) -> sp.Expr:
    """A float read from a file as SymPy: whole numbers exact (0 and 1 stay exact, which
    keeps zero tests and axis-aligned rotations exact), others as Float (all 53 bits)."""
    value = float(value)
    return sp.Integer(int(value)) if value.is_integer() and abs(value) < 2**53 else sp.Float(value)


class Numbers:
    """A numeric model field held as floats, its SymPy form built only when asked for.

    Readers of big numeric models (a URDF with 10^4 joints) pass these instead of SymPy
    matrices: building a SymPy ``Matrix``/``Float`` costs ~10 ms per joint, and the
    numeric engines never need it (they read :meth:`Joint.floats` / :meth:`Link.floats`).

    floats: array of the field's shape: ``()`` for a scalar, ``(3,)`` for a vector
            (``(3, 1)`` as SymPy), ``(3, 3)`` for a matrix. Must be finite.
    exact:  optional picklable zero-argument callable giving the SymPy form (e.g. a
            rotation with exact pi/2 angles); default :func:`exact_number` per entry.
    """

    __slots__ = ("floats", "exact")

    def __init__(self, floats, exact=None):
        f = np.array(floats, dtype=float)
        if not np.isfinite(f).all():
            raise ModelError(f"value {f.tolist()} is not finite")
        f.setflags(write=False)
        self.floats = f
        self.exact = exact

    def sympy(self):
        if self.exact is not None:
            return self.exact()
        f = self.floats
        if f.ndim == 0:
            return exact_number(f)
        rows, cols = (f.shape[0], 1) if f.ndim == 1 else f.shape
        return sp.Matrix(rows, cols, [exact_number(x) for x in f.ravel()])

    def __reduce__(self):
        return (Numbers, (self.floats, self.exact))


_DEFAULT = object()  # a lazy field not given: __post_init__ puts its default in


class _LazyField:
    """Data descriptor for a numeric field of Link/Joint: the instance keeps what it was
    given (SymPy, or :class:`Numbers`) under the field's name and reading the attribute
    always gives SymPy, built from Numbers on first read and cached (``_sym_<name>``)."""

    def __init__(self, optional: bool = False):
        self.optional = optional  # an optional field's default is None

    def __set_name__(self, owner, name):
        self.name = name

    def __get__(self, obj, owner=None):
        if obj is None:
            return None if self.optional else _DEFAULT  # the dataclass default
        d = obj.__dict__
        raw = d[self.name]
        if not isinstance(raw, Numbers):
            return raw
        key = "_sym_" + self.name
        if key not in d:
            d[key] = raw.sympy()
        return d[key]

    def __set__(self, obj, value):
        obj.__dict__[self.name] = value


def _field_floats(obj, name: str):
    """Float array of a Link/Joint field (shape () / (3,) / (3, 3)), None when it has
    free symbols; cached on the instance."""
    d = obj.__dict__
    raw = d[name]
    if isinstance(raw, Numbers):
        return raw.floats
    if raw is None:
        return None
    key = "_floats_" + name
    if key not in d:
        if raw.free_symbols:
            d[key] = None
        else:
            try:
                if isinstance(raw, sp.MatrixBase):  # (3, 1) -> (3,), (3, 3) stays
                    f = np.array([float(x) for x in raw], dtype=float).reshape(raw.shape)
                    f = f.reshape(-1) if raw.shape[1] == 1 else f
                else:
                    f = np.array(float(raw), dtype=float)
                f.setflags(write=False)
            except (TypeError, ValueError):
                f = None  # complex or not a number: the SymPy-side checks report it
            d[key] = f
    return d[key]


def _lazy_init(obj, name: str, convert, default: "Numbers", shape: tuple) -> None:
    """Normalise a lazy field in ``__post_init__``: the default when not given, a
    :class:`Numbers` of the right shape kept as it is, anything else converted to SymPy."""
    raw = obj.__dict__.get(name, _DEFAULT)
    if raw is _DEFAULT:
        raw = default
    elif raw is None and default is None:  # an optional field left out
        pass
    elif isinstance(raw, Numbers):
        if raw.floats.shape != shape:
            raise ModelError(f"{name} must have shape {shape}, got {raw.floats.shape}")
    else:
        raw = convert(raw)
    obj.__dict__[name] = raw


_I3 = np.eye(3)
_ZERO3 = Numbers(np.zeros(3))
_EYE3 = Numbers(np.eye(3))
_ZERO33 = Numbers(np.zeros((3, 3)))
_Z_AXIS = Numbers(np.array([0.0, 0.0, 1.0]))
_ZERO = Numbers(0.0)


def rot_x(a) -> sp.Matrix:
    """Rotation (3x3) by angle ``a`` about x."""
    c, s = sp.cos(a), sp.sin(a)
    return sp.Matrix([[1, 0, 0], [0, c, -s], [0, s, c]])


def rot_y(a) -> sp.Matrix:
    """Rotation (3x3) by angle ``a`` about y."""
    c, s = sp.cos(a), sp.sin(a)
    return sp.Matrix([[c, 0, s], [0, 1, 0], [-s, 0, c]])


def rot_z(a) -> sp.Matrix:
    """Rotation (3x3) by angle ``a`` about z."""
    c, s = sp.cos(a), sp.sin(a)
    return sp.Matrix([[c, -s, 0], [s, c, 0], [0, 0, 1]])


def rpy_matrix(roll, pitch, yaw) -> sp.Matrix:
    """URDF roll-pitch-yaw: ``Rz(yaw) * Ry(pitch) * Rx(roll)`` (fixed axes x, y, z)."""
    # zero angles are identity factors: skipping them saves SymPy products (big URDFs)
    factors = [rot(a) for rot, a in ((rot_z, yaw), (rot_y, pitch), (rot_x, roll)) if a != 0]
    out = sp.eye(3)
    for f in factors:
        out = out * f
    return out


def axis_angle_matrix(axis, angle) -> sp.Matrix:
    """Rodrigues' rotation (3x3) by ``angle`` about the unit vector ``axis``.

    The coordinate axes give the exact ``rot_x/rot_y/rot_z`` forms, so symbolic
    results stay as simple as a hand derivation.
    """
    a = sp.Matrix(axis)
    for i, rot in enumerate((rot_x, rot_y, rot_z)):
        unit = [0, 0, 0]
        unit[i] = 1
        if list(a) == unit:
            return rot(angle)
        unit[i] = -1
        if list(a) == unit:
            return rot(-angle)
    c, s = sp.cos(angle), sp.sin(angle)
    k = skew(a)
    return sp.eye(3) + s * k + (1 - c) * k * k


def skew(v) -> sp.Matrix:
    """Cross-product matrix (3x3): ``skew(v) * w == v x w``."""
    x, y, z = v
    return sp.Matrix([[0, -z, y], [z, 0, -x], [-y, x, 0]])


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
    mass: sp.Expr = _LazyField()
    com: sp.Matrix = _LazyField()
    inertia: sp.Matrix = _LazyField()

    def __post_init__(self):
        where = f"link '{self.name}'"
        try:
            _lazy_init(self, "mass", sp.sympify, _ZERO, ())
            _lazy_init(self, "com", lambda v: _vec3(v, "com"), _ZERO3, (3,))
            _lazy_init(self, "inertia", lambda v: _mat3(v, "inertia"), _ZERO33, (3, 3))
        except ModelError as err:
            raise err.located(element=where)
        except (sp.SympifyError, TypeError) as exc:
            raise ModelError(f"bad value ({exc})", where) from None

    def floats(self, name: str):
        """``mass``, ``com`` or ``inertia`` as a float array of shape ``()``, ``(3,)``
        or ``(3, 3)`` without building SymPy objects; None when it has free symbols."""
        return _field_floats(self, name)


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

    type:     "revolute", "prismatic" or "fixed".
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
    xyz: sp.Matrix = _LazyField()
    rotation: sp.Matrix = _LazyField()
    axis: sp.Matrix = _LazyField()
    frame_xyz: sp.Matrix = _LazyField()
    frame_rotation: sp.Matrix = _LazyField()
    lower: sp.Expr | None = _LazyField(optional=True)
    upper: sp.Expr | None = _LazyField(optional=True)
    velocity: sp.Expr | None = _LazyField(optional=True)
    effort: sp.Expr | None = _LazyField(optional=True)
    damping: sp.Expr | None = _LazyField(optional=True)
    friction: sp.Expr | None = _LazyField(optional=True)
    mimic: Mimic | None = None
    armature: sp.Expr | None = _LazyField(optional=True)
    torque_offset: sp.Expr | None = _LazyField(optional=True)

    def __post_init__(self):
        where = f"joint '{self.name}'"
        if self.type not in JOINT_TYPES:
            raise ModelError(
                f"unknown joint type '{self.type}' (expected one of {', '.join(JOINT_TYPES)})",
                where,
            )
        try:
            _lazy_init(self, "xyz", lambda v: _vec3(v, "xyz"), _ZERO3, (3,))
            _lazy_init(self, "rotation", lambda v: _mat3(v, "rotation"), _EYE3, (3, 3))
            _lazy_init(self, "axis", lambda v: _vec3(v, "axis"), _Z_AXIS, (3,))
            _lazy_init(self, "frame_xyz", lambda v: _vec3(v, "frame_xyz"), _ZERO3, (3,))
            _lazy_init(self, "frame_rotation", lambda v: _mat3(v, "frame_rotation"), _EYE3, (3, 3))
            for name in ("lower", "upper", "velocity", "effort") + JOINT_DYNAMICS:
                _lazy_init(self, name, sp.sympify, None, ())
        except ModelError as err:
            raise err.located(element=where)
        except (sp.SympifyError, TypeError) as exc:
            raise ModelError(f"bad value ({exc})", where) from None
        if self.mimic is not None:
            if not isinstance(self.mimic, Mimic):
                raise ModelError(f"mimic must be a Mimic, got {type(self.mimic).__name__}", where)
            if self.type == "fixed":
                raise ModelError("a fixed joint cannot mimic another joint", where)
        _check_joint_dynamics(self, where)
        for key in ("rotation", "frame_rotation"):
            if self.__dict__[key] is _EYE3:  # the default: a rotation, no check needed
                continue
            R = self.floats(key)
            if R is not None:
                # R^T R = I (np.allclose's tolerances: atol 1e-9, rtol 1e-5) and det R > 0
                (a, b, c), (d, e, f), (g, h, i) = R.tolist()
                det = a * (e * i - f * h) - b * (d * i - f * g) + c * (d * h - e * g)
                if not (np.all(np.abs(R.T @ R - _I3) <= 1e-9 + 1e-5 * _I3) and det > 0):
                    raise ModelError(f"{key} {R.tolist()} is not a proper rotation matrix", where)
        axis = self.__dict__["axis"]
        if self.type != "fixed" and isinstance(axis, Numbers):  # numbers: checked without SymPy
            norm = float(np.linalg.norm(axis.floats))
            if norm == 0:
                raise ModelError("axis is zero", where)
            if abs(norm - 1) > 1e-12:
                raise ModelError(f"axis {axis.floats.tolist()} is not a unit vector (norm {norm:.6g})", where)
        elif self.type != "fixed":
            norm2 = sp.expand(sum(c**2 for c in self.axis))
            zero = _is_zero(norm2)
            if zero:
                raise ModelError("axis is zero", where)
            if zero is False and _is_zero(norm2 - 1) is False:
                raise ModelError(
                    f"axis {list(self.axis)} is not a unit vector (norm {sp.sqrt(norm2).evalf(6)})",
                    where,
                )

    @property
    def movable(self) -> bool:
        return self.type != "fixed"

    def floats(self, name: str):
        """``xyz``, ``axis``, ``frame_xyz`` (shape ``(3,)``), ``rotation`` or
        ``frame_rotation`` (``(3, 3)``) as a float array without building SymPy
        objects; None when it has free symbols."""
        return _field_floats(self, name)

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
        if self.type == "revolute":
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


def coordinate_symbols(names: Iterable[str]) -> tuple[sp.Matrix, sp.Matrix, sp.Matrix]:
    """Joint coordinates ``q``, velocities ``qd`` and accelerations ``qdd`` as (n, 1)
    column vectors of plain symbols named ``<joint>``, ``<joint>_dot``, ``<joint>_ddot``.
    """
    names = list(names)
    q = sp.Matrix([sp.Symbol(n) for n in names])
    qd = sp.Matrix([sp.Symbol(f"{n}_dot") for n in names])
    qdd = sp.Matrix([sp.Symbol(f"{n}_ddot") for n in names])
    return q, qd, qdd


class FrozenList(list):
    """A list that refuses in-place changes (``+`` still gives a new plain list)."""

    def _refuse(self, *args, **kwargs):
        raise TypeError("this list belongs to a Robot, which is immutable: build a new Robot instead")

    append = extend = insert = pop = remove = clear = sort = reverse = _refuse
    __setitem__ = __delitem__ = __iadd__ = __imul__ = _refuse

    def __copy__(self):
        return list(self)

    def __reduce__(self):
        # pickle's default for a list subclass refills it with extend(), which is refused
        return (FrozenList, (list(self),))


class FrozenDict(dict):
    """A dict that refuses in-place changes (``dict(d)``, ``{**d}`` give plain copies)."""

    def _refuse(self, *args, **kwargs):
        raise TypeError("this mapping belongs to a Robot, which is immutable: build a new Robot instead")

    __setitem__ = __delitem__ = __ior__ = pop = popitem = clear = update = setdefault = _refuse

    def __copy__(self):
        return dict(self)

    def __reduce__(self):
        # pickle's default for a dict subclass refills it item by item, which is refused
        return (FrozenDict, (dict(self),))


class _FreezeAfterInit(type):
    """Robot's metaclass: once ``__init__`` (whatever fields it sets) has returned, the
    instance is frozen (see :meth:`Robot.__setattr__`). No field is listed here."""

    def __call__(cls, *args, **kwargs):
        obj = super().__call__(*args, **kwargs)
        object.__setattr__(obj, "_frozen", True)
        return obj


#: what a Robot caches about itself (dropped when a thawed copy changes)
_CACHES = ("_numeric_model", "_canonical")


class Robot(metaclass=_FreezeAfterInit):
    """A fixed-base robot: links and joints in tree order, and gravity.

    Immutable once constructed: setting a public attribute raises AttributeError and
    its lists and dicts (``joints``, ``links``, ``parameters``, ...) refuse changes,
    so the compiled numeric model cached on it (:func:`armdyn.numeric.compile_model`)
    always describes it. Build a changed robot with :meth:`bind`, :meth:`subs` or
    ``Robot(...)``. (``copy.copy(robot)`` gives a thawed copy for ``with_*`` style
    constructors: its attributes may be set, and each set drops its cached model.)
    ``meta`` stays an ordinary dict: it describes the model and is never compiled.

    Attributes
    ----------
    name:        the robot's name.
    base:        name of the base link (the root, fixed in the world).
    links:       dict name -> :class:`Link`, base first, then each joint's child in order.
    joints:      list of :class:`Joint` in tree order (fixed ones included).
    gravity:     (3, 1) gravity vector in the base frame (m/s^2).
    parameters:  dict name -> sympy Symbol of the model's named parameters.
    defaults:    dict name -> number: the model file's published values of its parameters
                 (may be empty or partial); ``bind()`` with no argument uses them.
    meta:        free-form description (source, convention, ...).
    strict:      True (default): a link whose mass/inertia is not physical (mass < 0,
                 inertia not symmetric or not positive semi-definite, principal moments
                 breaking the triangle inequality) is a ModelError; False: a warning.
                 Symbolic values are checked once bound.

    Derived:
    movable_joints: the non-fixed joints, in order; ``dof`` is their number.
    q, qd, qdd:     (dof, 1) symbol vectors named after the movable joints.
    """

    def __setattr__(self, name, value):
        if self.__dict__.get("_frozen") and not name.startswith("_"):
            raise AttributeError(
                f"Robot is immutable: cannot set '{name}' (build a new robot with bind(), subs() or Robot(...))"
            )
        if not name.startswith("_"):  # a thawed copy changing: its compiled model is stale
            for cache in _CACHES:
                self.__dict__.pop(cache, None)
        object.__setattr__(self, name, value)

    def __delattr__(self, name):
        if self.__dict__.get("_frozen") and not name.startswith("_"):
            raise AttributeError(f"Robot is immutable: cannot delete '{name}'")
        for cache in _CACHES:
            self.__dict__.pop(cache, None)
        object.__delattr__(self, name)

    def __copy__(self):
        """A thawed shallow copy without the cached numeric model (see the class doc)."""
        new = object.__new__(type(self))
        state = {k: v for k, v in self.__dict__.items() if k not in ("_frozen", *_CACHES)}
        for k, v in state.items():  # plain containers, so that a with_* constructor may edit them
            if isinstance(v, FrozenList):
                state[k] = list(v)
            elif isinstance(v, FrozenDict):
                state[k] = dict(v)
        new.__dict__.update(state)
        return new

    def __deepcopy__(self, memo):
        if self.__dict__.get("_frozen"):
            return self  # immutable: a copy is the same robot
        import copy

        new = object.__new__(type(self))
        memo[id(self)] = new
        state = {k: v for k, v in self.__dict__.items() if k not in _CACHES}
        new.__dict__.update(copy.deepcopy(state, memo))
        return new

    def __init__(
        self,
        name: str,
        links: Iterable[Link],
        joints: Iterable[Joint],
        gravity=(0, 0, -9.81),
        parameters: Mapping[str, sp.Symbol] | Iterable[sp.Symbol] | None = None,
        meta: Mapping | None = None,
        base: str | None = None,
        defaults: Mapping[str, float] | None = None,
        strict: bool = True,
    ):
        self.name = name
        links = list(links)
        joints = list(joints)
        self.meta = dict(meta or {})  # "file" (if any) names the model file in messages
        try:
            self.gravity = _vec3(gravity, "gravity")
        except ModelError as err:
            raise err.located(element=f"robot '{name}'")

        self.strict = strict
        # (link, problems) a bundled model is published with, reported once by armdyn.load:
        # not warned about again in every bound copy
        accepted = self.meta.get("nonphysical_accepted", ())
        self.links: dict[str, Link] = {}
        for link in links:
            if link.name in self.links:
                raise ModelError("duplicate link name", f"link '{link.name}'")
            # an error is located by the loader (which knows the line); a warning cannot be
            # located later, so it names the model file itself
            source = None if strict else self.meta.get("file")
            m, inertia = link.floats("mass"), link.floats("inertia")  # floats: no SymPy per link
            m, inertia = link.mass if m is None else m, link.inertia if inertia is None else inertia
            if not (accepted and not strict and (link.name, "; ".join(physical_violations(m, inertia))) in accepted):
                check_physical(m, inertia, f"link '{link.name}'", source, strict=strict)
            self.links[link.name] = link

        children = {j.child for j in joints}
        if base is None:
            roots = [ln.name for ln in links if ln.name not in children]
            if len(roots) != 1:
                raise ModelError(
                    f"expected exactly one root link (not the child of any joint), found {roots or 'none (a cycle?)'}",
                    f"robot '{name}'",
                )
            base = roots[0]
        self.base = base
        self.joints = self._tree_order(joints)
        # links ordered base first, then children in joint order
        self.links = {base: self.links[base], **{j.child: self.links[j.child] for j in self.joints}}

        if isinstance(parameters, Mapping):
            self.parameters: dict[str, sp.Symbol] = dict(parameters)
        else:
            symbols: Iterable[sp.Symbol] = parameters or ()
            self.parameters = {s.name: s for s in symbols}
        self.defaults: dict[str, float] = dict(defaults or {})
        stray = set(self.defaults) - set(self.parameters)
        if stray:
            raise ModelError(f"default values given for unknown parameters {sorted(stray)}", f"robot '{name}'")

        # joints with a coordinate of their own; mimic joints move but follow a leader
        self.movable_joints = [j for j in self.joints if j.movable and j.mimic is None]
        self.mimic_joints = [j for j in self.joints if j.mimic is not None]
        self.dof = len(self.movable_joints)
        self.coordinate_names = [j.name for j in self.movable_joints]
        self.q, self.qd, self.qdd = coordinate_symbols(self.coordinate_names)
        clash = set(self.coordinate_names) & set(self.parameters)
        if clash:
            raise ModelError(f"names used both as joint and as parameter: {sorted(clash)}", f"robot '{name}'")
        self._link_index = {name: i for i, name in enumerate(self.links)}
        # index of each movable joint's coordinate, None for fixed joints
        coordinate = {n: i for i, n in enumerate(self.coordinate_names)}
        self._coord_index = {j.name: coordinate.get(j.name) if j.movable else None for j in self.joints}
        self._parent_joint = {j.child: j for j in self.joints}
        self._children: dict[str, list[Joint]] = {}
        for j in self.joints:
            self._children.setdefault(j.parent, []).append(j)
        self._follows = self._resolve_mimics()
        self._check_defaults()
        # read-only from here on (the metaclass then freezes the attributes)
        self.joints = FrozenList(self.joints)
        self.movable_joints = FrozenList(self.movable_joints)
        self.mimic_joints = FrozenList(self.mimic_joints)
        self.coordinate_names = FrozenList(self.coordinate_names)
        self.links = FrozenDict(self.links)
        self.parameters = FrozenDict(self.parameters)
        self.defaults = FrozenDict(self.defaults)
        self.gravity = sp.ImmutableMatrix(self.gravity)

    def _check_defaults(self) -> None:
        """Published values must be finite real numbers (a NaN or inf default would only
        show up later, as NaN torques)."""
        for key, value in self.defaults.items():
            try:
                finite = not isinstance(value, bool) and math.isfinite(float(value))
            except (TypeError, ValueError, OverflowError):
                finite = False
            if not finite:
                raise ModelError(
                    f"the default value of parameter '{key}' is not a finite number: {value!r}", f"robot '{self.name}'"
                )

    def _tree_order(self, joints: list[Joint]) -> list[Joint]:
        names: set[str] = set()
        child_of: dict[str, Joint] = {}
        for j in joints:
            where = f"joint '{j.name}'"
            if j.name in names:
                raise ModelError("duplicate joint name", where)
            names.add(j.name)
            if j.parent not in self.links:
                raise ModelError(f"parent link '{j.parent}' does not exist", where)
            if j.child not in self.links:
                raise ModelError(f"child link '{j.child}' does not exist", where)
            if j.child in child_of:
                raise ModelError(f"link '{j.child}' is already the child of joint '{child_of[j.child].name}'", where)
            if j.child == self.base:
                raise ModelError(f"the base link '{self.base}' cannot be a child", where)
            child_of[j.child] = j
        # breadth-first from the base keeps the given order among siblings
        ordered, reached = [], {self.base}
        by_parent: dict[str, list[Joint]] = {}
        for j in joints:
            by_parent.setdefault(j.parent, []).append(j)
        frontier = [self.base]
        while frontier:
            nxt = []
            for link in frontier:
                for j in by_parent.get(link, []):
                    ordered.append(j)
                    reached.add(j.child)
                    nxt.append(j.child)
            frontier = nxt
        # keep the user's order where it already is a tree order (stable for DH chains)
        if len(ordered) != len(joints):
            placed = {j.name for j in ordered}
            stray = [j.name for j in joints if j.name not in placed]
            raise ModelError(
                f"joints not connected to the base '{self.base}' (a cycle?): {stray}", f"robot '{self.name}'"
            )
        # the given order is a tree order when every joint comes after its parent joint
        # (the joint whose child is its parent link): one dict lookup per joint, O(n)
        position = {j.name: i for i, j in enumerate(joints)}
        if all(b.parent not in child_of or position[child_of[b.parent].name] < position[b.name] for b in joints):
            return list(joints)
        return ordered

    def _resolve_mimics(self) -> dict[str, tuple[int, sp.Expr, sp.Expr]]:
        """For every non-fixed joint, ``(k, multiplier, offset)`` with its own coordinate
        ``multiplier * q[k] + offset``; a chain of mimics is composed down to a joint
        with a coordinate. A missing or fixed leader, a leader of another type, and a
        loop are ModelErrors naming the mimic joint."""
        by_name = {j.name: j for j in self.joints}
        follows: dict[str, tuple[int, sp.Expr, sp.Expr]] = {}
        for j in self.movable_joints:
            k = self._coord_index[j.name]
            assert k is not None  # a movable joint has a coordinate of its own
            follows[j.name] = (k, sp.Integer(1), sp.Integer(0))
        for start in self.mimic_joints:
            chain: list[Joint] = []
            joint, seen = start, {start.name}
            while joint.name not in follows:  # walk up to a resolved joint (memoised: O(n) overall)
                where = f"joint '{joint.name}'"
                mimic = joint.mimic
                assert mimic is not None  # only mimic joints are still unresolved
                leader = by_name.get(mimic.joint)
                if leader is None:
                    raise ModelError(f"mimics joint '{mimic.joint}', which does not exist", where)
                if leader.type == "fixed":
                    raise ModelError(f"mimics joint '{leader.name}', which is fixed", where)
                if leader.type != joint.type:
                    raise ModelError(
                        f"a {joint.type} joint cannot mimic the {leader.type} joint '{leader.name}' "
                        "(a mimic joint must be of its leader's type)",
                        where,
                    )
                if leader.name in seen:
                    loop = " -> ".join([j.name for j in chain] + [joint.name, leader.name])
                    raise ModelError(f"mimic joints form a loop ({loop})", f"joint '{start.name}'")
                chain.append(joint)
                seen.add(leader.name)
                joint = leader
            for j in reversed(chain):  # q_j = m_j q_leader + o_j, q_leader = m q_k + o
                mimic = j.mimic
                assert mimic is not None
                k, m, o = follows[mimic.joint]
                follows[j.name] = (k, mimic.multiplier * m, mimic.multiplier * o + mimic.offset)
        return follows

    # ------------------------------------------------------------------ queries
    def coordinate_index(self, joint: str | Joint) -> int | None:
        """Index of a joint's coordinate in ``q`` (None for a fixed joint, and for a
        mimic joint, which has none of its own: see :meth:`follows`)."""
        name = joint.name if isinstance(joint, Joint) else joint
        return self._coord_index[name]

    def link_index(self, link: str) -> int:
        """Frame number of a link: 0 for the base, then tree order (as in ``links``)."""
        return self._link_index[link]

    def joint_coordinate(self, joint: Joint):
        """The joint's coordinate: its symbol, ``multiplier * q_leader + offset`` for a
        mimic joint, 0 for a fixed joint."""
        f = self._follows.get(joint.name)
        if f is None:
            return sp.Integer(0)
        k, m, o = f
        if m is sp.S.One and o is sp.S.Zero:  # a joint's own coordinate: no SymPy arithmetic
            return self.q[k]
        return m * self.q[k] + o

    def follows(self, joint: str | Joint) -> tuple[int, sp.Expr, sp.Expr] | None:
        """``(k, multiplier, offset)``: the joint's own coordinate is
        ``multiplier * q[k] + offset``, its velocity and acceleration ``multiplier``
        times ``qd[k]``, ``qdd[k]``, and its torque (force) adds ``multiplier`` times
        itself to ``tau[k]``. ``(k, 1, 0)`` for a joint with coordinate k, the leader's
        (chains composed) for a mimic joint, None for a fixed joint."""
        return self._follows.get(joint.name if isinstance(joint, Joint) else joint)

    def parent_joint(self, link: str) -> Joint | None:
        return self._parent_joint.get(link)

    def children(self, link: str) -> list[Joint]:
        """The joints whose parent is ``link``, in tree order."""
        return list(self._children.get(link, ()))

    def free_symbols(self) -> set[sp.Symbol]:
        """Symbols the model's numbers depend on (the joint coordinates excluded)."""

        def free(obj, name):  # Numbers have none (and are not built into SymPy here)
            raw = obj.__dict__[name]  # None, Numbers or SymPy (sympify would copy a Matrix to ask it)
            return set() if raw is None or isinstance(raw, Numbers) else raw.free_symbols

        out: set = set(self.gravity.free_symbols)
        for link in self.links.values():
            out |= free(link, "mass") | free(link, "com") | free(link, "inertia")
        for j in self.joints:
            for name in ("xyz", "rotation", "axis", "frame_xyz", "frame_rotation"):
                out |= free(j, name)
            if j.mimic is not None:
                out |= j.mimic.multiplier.free_symbols | j.mimic.offset.free_symbols
            for name in JOINT_DYNAMICS:
                out |= free(j, name)
        return out

    def canonical(self) -> "Robot":
        """The same mechanism with every link frame on its joint (no ``frame`` offsets).

        Where a joint has an offset ``(Rf, pf)``, its child's inertial data are moved into
        the moved joint frame (``com' = Rf com + pf``, ``I' = Rf I Rf^T``) and the child's
        own joints are placed from there (``xyz' = pf + Rf xyz``, ``rotation' = Rf rotation``).
        The dynamics are unchanged (tau does not depend on where link frames sit); only the
        link frames differ. The numeric engines use this form. ``self`` if nothing moves.
        """
        cached = self.__dict__.get("_canonical")
        if cached is not None:
            return cached
        offsets = {j.child: (j.frame_rotation, j.frame_xyz) for j in self.joints if j.has_frame_offset}
        if not offsets:
            return self
        links = []
        for link in self.links.values():
            if link.name in offsets:
                Rf, pf = offsets[link.name]
                link = Link(link.name, link.mass, Rf * link.com + pf, Rf * link.inertia * Rf.T)
            links.append(link)
        joints = []
        for j in self.joints:
            changes = {"frame_xyz": sp.zeros(3, 1), "frame_rotation": sp.eye(3)}
            if j.parent in offsets:
                Rf, pf = offsets[j.parent]
                changes.update(xyz=pf + Rf * j.xyz, rotation=Rf * j.rotation)
            joints.append(replace(j, **changes))
        out = Robot(
            self.name,
            links,
            joints,
            self.gravity,
            self.parameters,
            self.meta,
            self.base,
            self.defaults,
            strict=self.strict,
        )
        self.__dict__["_canonical"] = out  # built once: the numeric engines and codegen share it
        return out

    @classmethod
    def from_urdf(cls, source, strict: bool = True) -> "Robot":
        """A robot from a URDF file path or XML string: :func:`armdyn.io.urdf.load_urdf`
        (registered with :mod:`armdyn.dispatch`; ``armdyn.load`` reads any format)."""
        return call("urdf", cls, source, strict=strict)

    @property
    def is_numeric(self) -> bool:
        return not self.free_symbols()

    # ----------------------------------------------------------- transformations
    def subs(self, values: Mapping) -> "Robot":
        """A copy with ``values`` (symbol or name -> number/expression) substituted."""
        table = {}
        for key, val in values.items():
            sym = self.parameters.get(key, sp.Symbol(key)) if isinstance(key, str) else key
            table[sym] = sp.sympify(val)
        if not table and self.__dict__.get("_frozen"):  # nothing to substitute: the same
            return self  # immutable robot (a big numeric URDF is not rebuilt in SymPy)

        def s(x):
            return None if x is None else sp.sympify(x).xreplace(table)

        links = [
            Link(ln.name, s(ln.mass), ln.com.xreplace(table), ln.inertia.xreplace(table)) for ln in self.links.values()
        ]
        joints = [
            replace(
                j,
                xyz=j.xyz.xreplace(table),
                rotation=j.rotation.xreplace(table),
                axis=j.axis.xreplace(table),
                frame_xyz=j.frame_xyz.xreplace(table),
                frame_rotation=j.frame_rotation.xreplace(table),
                **{k: s(getattr(j, k)) for k in ("lower", "upper", "velocity", "effort") + JOINT_DYNAMICS},
                mimic=None
                if j.mimic is None
                else replace(j.mimic, multiplier=s(j.mimic.multiplier), offset=s(j.mimic.offset)),
            )
            for j in self.joints
        ]
        remaining = {n: p for n, p in self.parameters.items() if p not in table}
        defaults = {n: v for n, v in self.defaults.items() if n in remaining}
        try:
            return Robot(
                self.name,
                links,
                joints,
                self.gravity.xreplace(table),
                remaining,
                self.meta,
                self.base,
                defaults,
                strict=self.strict,
            )
        except ModelError as err:  # e.g. a bound value that is not physical: name the model file
            raise err.located(source=self.meta.get("file")) from None

    def bind(self, values: Mapping | None = None) -> "Robot":
        """A copy with parameters bound to numbers.

        ``robot.bind()`` uses the model's ``defaults`` (its published values);
        ``robot.bind({"m1": 2.0})`` overrides some of them (keys: names or symbols).
        Unknown names are an error, so typos do not silently leave a parameter free.
        Parameters with neither a default nor a given value stay symbolic.
        """
        values = dict(values or {})
        unknown = [k for k in values if isinstance(k, str) and k not in self.parameters]
        if unknown:
            raise ModelError(
                f"unknown parameter(s) {unknown}; the model has {sorted(self.parameters)}",
                f"robot '{self.name}'",
            )
        given = {k if isinstance(k, str) else k.name for k in values}
        merged = {k: v for k, v in self.defaults.items() if k not in given}
        merged.update(values)
        return self.subs(merged)

    def with_payload(self, mass, com=(0, 0, 0), inertia=None, link: str | None = None) -> "Robot":
        """A new robot with a rigid load fixed to ``link`` (default: the last link in tree
        order, the tool of a serial arm). This robot is not changed.

        mass:    the payload's mass (kg), number or SymPy expression.
        com:     (3,) its centre of mass in ``link``'s frame (m).
        inertia: (3, 3) its inertia tensor about its own centre of mass, in ``link``'s
                 axes (kg m^2); default zero (a point mass).

        The link and the load become one body (:func:`armdyn.inertia.combine`: total
        mass, mass-weighted centre of mass, parallel axis theorem). A payload that is not
        physical (negative or non-finite mass, inertia not symmetric, not positive
        semi-definite or breaking the triangle inequality) is a ModelError naming it.
        """
        from .inertia import Body, combine

        where = "payload"
        link = link if link is not None else list(self.links)[-1]
        if link not in self.links:
            raise ModelError(f"no link named {link!r} (links: {', '.join(self.links)})", where)
        if link == self.base:
            raise ModelError(f"the base link {link!r} does not move: a payload on it has no effect", where)
        try:
            mass = sp.sympify(mass)
            com = _vec3(com, "com")
            inertia = sp.zeros(3, 3) if inertia is None else _mat3(inertia, "inertia")
        except ModelError as err:
            raise err.located(element=where)
        except (sp.SympifyError, TypeError) as exc:
            raise ModelError(f"bad value ({exc})", where) from None
        for name, values in (("mass", [mass]), ("com", list(com)), ("inertia", list(inertia))):
            for v in values:
                if not v.free_symbols and not np.isfinite(complex(v.evalf())).all():
                    raise ModelError(f"{name} has a value that is not finite ({v})", where)
        check_physical(mass, inertia, where, strict=True)
        old = self.links[link]
        body = combine([Body(old.mass, old.com, old.inertia), Body(mass, com, inertia)])
        new = Link(old.name, sp.sympify(body.mass), sp.Matrix(body.com), sp.Matrix(body.inertia))
        links = [new if ln.name == link else ln for ln in self.links.values()]
        params = dict(self.parameters)
        for s in mass.free_symbols | com.free_symbols | inertia.free_symbols:
            params.setdefault(s.name, s)
        import warnings

        with warnings.catch_warnings():  # this robot's own links were warned about when it was built
            warnings.simplefilter("ignore")
            return Robot(
                self.name,
                links,
                self.joints,
                self.gravity,
                params,
                self.meta,
                self.base,
                self.defaults,
                strict=self.strict,
            )

    @property
    def joint_dynamics(self) -> tuple[str, ...]:
        """The joint-space terms (of ``damping``, ``friction``, ``armature``,
        ``torque_offset``) that some movable joint carries with a value other than 0:
        ``rnea``/``aba`` include them, a rigid-body library such as Pinocchio does not."""
        present = []
        for name in JOINT_DYNAMICS:
            for j in self.movable_joints:
                value = getattr(j, name)
                if value is not None and (value.free_symbols or float(value) != 0.0):
                    present.append(name)
                    break
        return tuple(present)

    def without_joint_dynamics(self) -> "Robot":
        """A copy with no joint damping, friction, armature or torque offset: the rigid-body
        dynamics alone, as Pinocchio's ``rnea``/``aba`` compute them (Robotics Toolbox's
        ``nofriction()``, with armature and offset dropped too). This robot is not changed."""
        if not self.joint_dynamics:
            return self
        joints = [replace(j, **dict.fromkeys(JOINT_DYNAMICS)) for j in self.joints]  # type: ignore[arg-type]
        import warnings

        with warnings.catch_warnings():  # this robot's own links were warned about when it was built
            warnings.simplefilter("ignore")
            return Robot(
                self.name,
                self.links.values(),
                joints,
                self.gravity,
                self.parameters,
                self.meta,
                self.base,
                self.defaults,
                strict=self.strict,
            )

    def __repr__(self) -> str:
        kinds = "".join({"revolute": "R", "prismatic": "P", "fixed": "F"}[j.type] for j in self.joints)
        extra = f", joint_dynamics={list(self.joint_dynamics)}" if self.joint_dynamics else ""
        return f"Robot({self.name!r}, dof={self.dof}, joints={kinds}, parameters={sorted(self.parameters)}{extra})"

    def _repr_html_(self) -> str:
        """Jupyter: tables of the joints and links (symbolic/report_html.py, through :mod:`armdyn.dispatch`)."""
        return call("html", self)
