"""The compiled model behind :mod:`armdyn.numeric`: built once per Robot and cached on it,
and the moves between a Robot's link frames and the compiled model's on-joint frames."""

from __future__ import annotations

import numpy as np
import sympy as sp

from .. import _core
from ..errors import FloatingBaseError, ModelError, UnboundParameterError
from ..mimic import MimicModel
from ..model import Robot

#: A robot compiled for numeric evaluation (built by :func:`compile_model`). Its
#: methods mirror armdyn.numeric's functions without the ``robot`` argument
#: (``gravity`` is ``gravity_torques`` there); attributes ``dof``, ``nlinks``,
#: ``link_names``, ``coordinate_names``, ``gravity`` (3,), ``name``.
NumericModel = _core.NumericModel
#: builds a NumericModel joint by joint (crates/armdyn-py/src/builder.rs)
ModelBuilder = _core.ModelBuilder

#: what armdyn.numeric's functions accept as ``robot``: a bound Robot (compiled on first use,
#: then cached on it) or an already compiled model
RobotLike = Robot | NumericModel | MimicModel


def _floats(values, where: str) -> list[float]:
    """SymPy numbers (exact or float) to Python floats."""
    out = []
    for v in values:
        if isinstance(v, (int, float, sp.Integer, sp.Float)):  # the common case, no evalf
            out.append(float(v))
            continue
        try:
            out.append(float(sp.N(v)))
        except (TypeError, ValueError):
            raise ModelError(f"value {v} is not a real number", where) from None
    return out


def _field(obj, name: str, where: str) -> list | float:
    """A Link/Joint field as floats (nested lists): read from the floats it was built
    from when it has them (no SymPy per joint for big URDFs), else from SymPy."""
    f = obj.floats(name)
    if f is not None:
        return f.tolist()
    value = getattr(obj, name)
    if isinstance(value, sp.MatrixBase):
        flat = _floats(value, where)
        return flat if value.shape[1] == 1 else np.reshape(flat, value.shape).tolist()
    return _floats([value], where)[0]


def compile_model(robot: Robot | NumericModel | MimicModel) -> NumericModel | MimicModel:
    """The compiled numeric model of ``robot`` (built on first use, then cached on it):
    for a robot with mimic joints, a :class:`~armdyn.mimic.MimicModel` around one.

    Raises UnboundParameterError if the robot still has free symbols, TypeError if
    ``robot`` is neither a Robot nor a NumericModel.
    """
    if isinstance(robot, (NumericModel, MimicModel)):
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
    source = robot
    robot = robot.canonical()  # link frames on their joints; the dynamics are the same
    where = f"robot '{robot.name}'"
    if robot.floating and robot.mimic_joints:
        raise FloatingBaseError(
            "mimic joints with a floating base are not supported yet", where, robot.meta.get("file")
        )
    base = robot.links[robot.base]
    builder = ModelBuilder(robot.name, _floats(robot.gravity, where), base.name, floating=robot.floating)
    here = f"link '{base.name}'"
    # a floating base moves: its own inertia counts (a fixed one only adds a constant potential)
    inertia = _field(base, "inertia", here) if robot.floating else np.zeros((3, 3)).tolist()
    builder.set_base_body(_field(base, "mass", here), _field(base, "com", here), inertia)
    for j in robot.joints:
        here = f"joint '{j.name}'"
        # friction, rotor inertia and offset on each of its velocity coordinates (absent = 0);
        # a mimic joint's own are not modelled (yet): zeros, as in the reference
        terms = [j.floats(k) if j.mimic is None else None for k in ("armature", "damping", "friction", "torque_offset")]
        k = builder.add_joint(
            j.name,
            j.parent,
            j.child,
            j.type,
            _field(j, "rotation", here),
            _field(j, "xyz", here),
            _field(j, "axis", here) if j.nv == 1 else [0.0, 0.0, 1.0],
            list(j.coordinate_names),
            [0.0 if t is None else float(t) for t in terms] if any(t is not None for t in terms) else None,
        )
        link = robot.links[j.child]
        here = f"link '{link.name}'"
        builder.append_body(k, _field(link, "mass", here), _field(link, "com", here), _field(link, "inertia", here))
    try:
        core = builder.build()
    except ValueError as err:
        raise ModelError(str(err), where) from None
    # every non-fixed joint is free in `core`; see armdyn.mimic
    model = MimicModel(core, robot) if robot.mimic_joints else core
    source._numeric_model = model
    return model


def core_model(robot, what: str, link_frames: bool = False) -> NumericModel:
    """The compiled model for the functions that exist only in the plain Rust core: not
    (yet) for robots with mimic joints, nor, where a link frame is involved (wrenches in
    link frames, jacobian_dot), for link frames off their joint's axis."""
    model = compiled_model(robot)
    if not isinstance(model, NumericModel):
        raise ValueError(f"{what} is not available yet for robots with mimic joints")
    if link_frames and frame_offsets(robot) is not None:
        raise ValueError(
            f"{what}: link frames off their joint's axis are not supported here yet; "
            "pass robot.canonical() (frames on the joints, same dynamics)"
        )
    return model


def canonical_wrenches(robot, f_ext, frame: str):
    """Wrenches given in the link frames (``frame="local"``) moved to the compiled model's
    on-joint frames (:meth:`armdyn.model.Robot.canonical`): with the link frame at
    ``(Rf, pf)`` in its joint frame, ``f' = Rf f`` and ``n' = Rf n + pf x f'``. Other
    inputs unchanged (validated by the core)."""
    offsets = frame_offsets(robot)
    if f_ext is None or frame != "local" or offsets is None:
        return f_ext
    w = np.array(f_ext, dtype=float)  # a copy
    if w.shape[-2:] != (len(offsets), 6):
        return f_ext  # the core names what is wrong with the shape
    R, p = offsets[:, :3, :3], offsets[:, :3, 3]
    f = np.einsum("lij,...lj->...li", R, w[..., :3])
    n = np.einsum("lij,...lj->...li", R, w[..., 3:]) + np.cross(p, f)
    return np.ascontiguousarray(np.concatenate([f, n], axis=-1))


def frame_offsets(robot) -> np.ndarray | None:
    """(nlinks, 4, 4) each link frame in its canonical (on-joint) frame, or None when
    every link frame sits on its joint (see :meth:`armdyn.model.Robot.canonical`)."""
    if not isinstance(robot, Robot) or not any(j.has_frame_offset for j in robot.joints):
        return None
    out = np.tile(np.eye(4), (len(robot.links), 1, 1))
    for j in robot.joints:
        k = robot.link_index(j.child)
        out[k, :3, :3] = np.reshape(_floats(j.frame_rotation, f"joint '{j.name}'"), (3, 3))
        out[k, :3, 3] = _floats(j.frame_xyz, f"joint '{j.name}'")
    return out


def compiled_model(robot) -> NumericModel | MimicModel:
    """The compiled model of a Robot (built once, cached on it), or a NumericModel /
    MimicModel itself: what every function here passes to the Rust core."""
    # Fast path: a Robot already compiled, or a NumericModel (whose
    # ``_numeric_model`` is itself).
    try:
        return robot._numeric_model
    except AttributeError:
        return compile_model(robot)


def mimic_model(robot, what: str, f_ext=None, frame: str = "local") -> MimicModel | None:
    """The compiled model if ``robot`` has mimic joints (its derivatives are the full
    tree's reduced by the chain rule, see armdyn.mimic), else None. External wrenches are
    not available for those robots (as for rnea/aba)."""
    model = compiled_model(robot)
    if not isinstance(model, MimicModel):
        return None
    if f_ext is not None:
        raise ValueError(f"{what} with f_ext is not available yet for robots with mimic joints")
    if frame not in ("local", "world"):
        raise ValueError(f"frame: expected 'local' or 'world', got '{frame}'")
    return model
