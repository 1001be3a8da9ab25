"""Numeric dynamics: the Rust core (``armdyn._core``) behind a small NumPy API.

Every function takes a robot and one state or a batch of states:

* ``robot``: an :class:`armdyn.Robot` with no free symbols (bind them first with
  ``robot.bind({...})``; otherwise :class:`armdyn.errors.UnboundParameterError`
  names them), or a :class:`NumericModel` from :func:`compile_model`. The compiled
  model is built once per Robot and cached on it (attribute ``_numeric_model``); a
  Robot is immutable, so the cache always describes it.
  A robot with mimic joints compiles to a :class:`armdyn.mimic.MimicModel` (same
  methods, in the independent coordinates; see that module for how).
* ``q``, ``qd``, ``qdd``, ``tau``: shape ``(n,)`` for one state or ``(N, n)`` for ``N``
  states (one per row), ``n = robot.dof``, joints in ``robot.coordinate_names`` order.
  Float64 C-contiguous arrays are used as they are; anything else is converted once.
  A wrong shape, NaN or inf raises ``ValueError`` naming the argument.
* ``threads``: for batches, the number of threads: ``None`` (all cores) or an integer
  from 1 to 256 (``TypeError`` for anything but an integer, ``True`` too; ``ValueError``
  for an integer out of range). At most that many threads work
  on the batch; counts above the number of cores run on one extra pool, grown to the
  largest count asked for and reused. The GIL is released while a batch is computed.
  Batched results equal single calls bit for bit.
* Arrays must hold real numbers: complex, boolean, string or other non-real arrays
  are refused with a ``ValueError`` (not converted).
* ``aba`` raises ``ValueError`` when the joint-space inertia matrix is singular: a
  movable joint whose subtree has no mass and no inertia (named in the message), or
  a state where the result is not finite.

Conventions (docs/architecture.md): SI units, radians; ``M(q) qdd + C(q, qd) qd + g(q) = tau``;
gravity is the robot's vector in the base frame; frames as in :mod:`armdyn.model`.

A floating base (``armdyn.load(path, root_joint="free-flyer")``, ``robot.floating``):
``rnea``, ``crba``, ``aba``, ``rnea_derivatives``, ``aba_derivatives`` and ``minverse`` take
Pinocchio's arrays, unchanged: ``q`` is
``(robot.nq,) = (7 + dof,)``, the base origin in the world frame (3), the base
orientation as a unit quaternion ``x, y, z, w`` (4; base axes in world coordinates),
then the joints; ``qd``, ``qdd`` and ``tau`` are ``(robot.nv,) = (6 + dof,)``: the base's
linear then angular velocity (acceleration; the force then the moment about the base
origin applied to the base), all in the base frame, then the joints; ``M`` and the
derivatives are ``(nv, nv)`` in that order, ``d/dq`` on the tangent space: along
``integrate(q, dq)`` at ``dq = 0`` (Pinocchio's ``computeRNEADerivatives``). Gravity is then in the world frame. A quaternion whose length
differs from 1 by more than 1e-9 is refused (``ValueError``). Batches ``(N, nq)`` run
as the fixed-base ones (SIMD lanes, ``threads``; bit for bit the single calls). :mod:`armdyn.configuration` moves on that configuration space
(``integrate``, ``difference``, ``neutral``, ``random_configuration``, re-exported
here). Every other function here raises :class:`~armdyn.errors.FloatingBaseError` (a
``ModelError`` and ``NotImplementedError``) for a floating robot, naming itself.
"""

from __future__ import annotations

import functools
import math

import numpy as np
import sympy as sp
from numpy.typing import ArrayLike

from . import _core
from .configuration import difference, integrate, neutral, random_configuration
from .errors import FloatingBaseError, ModelError, UnboundParameterError
from .mimic import MimicModel
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
    "rnea_derivatives",
    "aba_derivatives",
    "minverse",
    "gravity_derivatives",
    "jacobian_dot",
    "regressor",
    "integrate",
    "difference",
    "neutral",
    "random_configuration",
    "require_fixed_base",
]

#: A robot compiled for numeric evaluation (built by :func:`compile_model`). Its
#: methods mirror this module's functions without the ``robot`` argument
#: (``gravity`` is ``gravity_torques`` there); attributes ``dof``, ``nlinks``,
#: ``link_names``, ``coordinate_names``, ``gravity`` (3,), ``name``.
NumericModel = _core.NumericModel

#: what the functions below accept as ``robot``: a bound Robot (compiled on first use,
#: then cached on it) or an already compiled model
RobotLike = Robot | NumericModel | MimicModel

_TYPE_CODES = {"revolute": 0, "prismatic": 1, "fixed": 2}


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
    joint_index = {j.child: k for k, j in enumerate(robot.joints)}
    parents, types, rotations, translations, axes = [], [], [], [], []
    masses, coms, inertias = [], [], []
    for j in robot.joints:
        where = f"joint '{j.name}'"
        parents.append(joint_index.get(j.parent, -1))
        types.append(_TYPE_CODES[j.type])
        rotations.append(_field(j, "rotation", where))
        translations.append(_field(j, "xyz", where))
        axes.append(_field(j, "axis", where) if j.movable else [0.0, 0.0, 1.0])
        link = robot.links[j.child]
        where = f"link '{link.name}'"
        masses.append(_field(link, "mass", where))
        coms.append(_field(link, "com", where))
        inertias.append(_field(link, "inertia", where))
    # per movable joint [armature, viscous, coulomb, offset] (absent = 0); None when all zero
    # one row per joint the compiled model frees (mimic joints too); a mimic joint's own
    # friction and armature are not modelled (yet): zeros, as in the reference
    rows = [
        [
            0.0 if j.mimic is not None or j.floats(k) is None else float(j.floats(k))
            for k in ("armature", "damping", "friction", "torque_offset")
        ]
        for j in robot.joints
        if j.movable
    ]
    joint_dynamics = rows if any(any(row) for row in rows) else None
    gravity_vec = _floats(robot.gravity, f"robot '{robot.name}'")
    base = robot.links[robot.base]
    where = f"link '{base.name}'"
    if robot.floating and robot.mimic_joints:
        raise FloatingBaseError(
            "mimic joints with a floating base are not supported yet", f"robot '{robot.name}'", robot.meta.get("file")
        )
    # a floating base moves: its own inertia counts (a fixed one only adds a constant potential)
    base_inertia = _field(base, "inertia", where) if robot.floating else None
    try:
        core = NumericModel(
            parents,
            types,
            rotations,
            translations,
            axes,
            masses,
            coms,
            inertias,
            gravity_vec,
            list(robot.links),
            [j.name for j in robot.joints if j.movable],
            robot.name,
            _field(base, "mass", where),
            _field(base, "com", where),
            joint_dynamics,
            base_inertia,
            robot.floating,
        )
    except ValueError as err:
        raise ModelError(str(err), f"robot '{robot.name}'") from None
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
    if link_frames and _frame_offsets(robot) is not None:
        raise ValueError(
            f"{what}: link frames off their joint's axis are not supported here yet; "
            "pass robot.canonical() (frames on the joints, same dynamics)"
        )
    return model


def _canonical_wrenches(robot, f_ext, frame: str):
    """Wrenches given in the link frames (``frame="local"``) moved to the compiled model's
    on-joint frames (:meth:`armdyn.model.Robot.canonical`): with the link frame at
    ``(Rf, pf)`` in its joint frame, ``f' = Rf f`` and ``n' = Rf n + pf x f'``. Other
    inputs unchanged (validated by the core)."""
    offsets = _frame_offsets(robot)
    if f_ext is None or frame != "local" or offsets is None:
        return f_ext
    w = np.array(f_ext, dtype=float)  # a copy
    if w.shape[-2:] != (len(offsets), 6):
        return f_ext  # the core names what is wrong with the shape
    R, p = offsets[:, :3, :3], offsets[:, :3, 3]
    f = np.einsum("lij,...lj->...li", R, w[..., :3])
    n = np.einsum("lij,...lj->...li", R, w[..., 3:]) + np.cross(p, f)
    return np.ascontiguousarray(np.concatenate([f, n], axis=-1))


def _frame_offsets(robot) -> np.ndarray | None:
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


def rnea(
    robot: RobotLike,
    q: ArrayLike,
    qd: ArrayLike,
    qdd: ArrayLike,
    f_ext: ArrayLike | None = None,
    frame: str = "local",
    threads: int | None = None,
) -> np.ndarray:
    """Inverse dynamics by the recursive Newton-Euler algorithm.

    q, qd, qdd: (n,) or (N, n). Returns tau = M(q) qdd + C(q, qd) qd + g(q), same shape;
    with external wrenches ``f_ext`` (see :func:`rnea_derivatives`), minus sum J^T w.
    A floating base (see the module doc): q (nq,) or (N, nq); qd, qdd (nv,) or (N, nv);
    tau (nv,): the wrench the base needs (base frame, force then moment; zero when the
    robot flies freely at that acceleration), then the joint torques.
    """
    threads = check_threads(threads)
    if f_ext is not None:
        require_fixed_base(robot, "rnea with f_ext")
        f_ext = _canonical_wrenches(robot, f_ext, frame)
        return _finite(
            _core.rnea_ext(core_model(robot, "rnea with f_ext"), q, qd, qdd, f_ext, frame, threads),
            "rnea",
            q=q,
            qd=qd,
            qdd=qdd,
        )
    try:
        return compiled_model(robot).rnea(q, qd, qdd, threads)
    except FloatingPointError:  # the core checks its result: an overflow from finite inputs
        raise _overflow("rnea", {"q": q, "qd": qd, "qdd": qdd}) from None


def crba(robot: RobotLike, q: ArrayLike, *, threads: int | None = None) -> np.ndarray:
    """Joint-space inertia matrix M(q) by the composite rigid-body algorithm.

    q: (n,) or (N, n). Returns the full symmetric M: (n, n) or (N, n, n). A floating
    base (see the module doc): q (nq,) or (N, nq); M (nv, nv) in the order of the
    velocity (base linear, base angular in the base frame, joints); it does not depend
    on the base's pose.
    """
    threads = check_threads(threads)
    try:
        return compiled_model(robot).crba(q, threads)
    except FloatingPointError:
        raise _overflow("crba", {"q": q}) from None


def aba(
    robot: RobotLike,
    q: ArrayLike,
    qd: ArrayLike,
    tau: ArrayLike,
    f_ext: ArrayLike | None = None,
    frame: str = "local",
    threads: int | None = None,
) -> np.ndarray:
    """Forward dynamics by the articulated-body algorithm.

    q, qd, tau: (n,) or (N, n). Returns qdd = M^-1 (tau - C qd - g), same shape; with
    external wrenches ``f_ext`` (see :func:`rnea_derivatives`), M^-1 (tau + sum J^T w - C qd - g).
    A floating base (see the module doc): q (nq,) or (N, nq); qd, tau, qdd (nv,) or (N, nv),
    tau's first 6 the wrench applied to the base (base frame, force then moment), qdd's
    the base's linear then angular acceleration (base frame).
    """
    threads = check_threads(threads)
    if f_ext is not None:
        require_fixed_base(robot, "aba with f_ext")
        f_ext = _canonical_wrenches(robot, f_ext, frame)
        return _core.aba_ext(core_model(robot, "aba with f_ext"), q, qd, tau, f_ext, frame, threads)
    try:
        return compiled_model(robot).aba(q, qd, tau, threads)
    except ValueError as err:
        # the core calls any non-finite result "singular at this state"; an overflow (M
        # well conditioned, tau or qd too large) is told apart by factoring M at that q
        if "singular at this state" in str(err) and _well_conditioned(crba(robot, q, threads=threads)):
            raise _overflow("aba", {"qd": qd, "tau": tau}) from None
        raise


def gravity(robot: RobotLike, q: ArrayLike, *, threads: int | None = None) -> np.ndarray:
    """Gravity torques g(q) = rnea(q, 0, 0). q: (n,) or (N, n); same shape out."""
    threads = check_threads(threads)
    try:
        return compiled_model(robot).gravity_torques(q, threads)
    except FloatingPointError:
        raise _overflow("gravity", {"q": q}) from None


def bias(robot: RobotLike, q: ArrayLike, qd: ArrayLike, *, threads: int | None = None) -> np.ndarray:
    """Nonlinear effects h(q, qd) = C(q, qd) qd + g(q) = rnea(q, qd, 0).

    q, qd: (n,) or (N, n); same shape out.
    """
    threads = check_threads(threads)
    try:
        return compiled_model(robot).bias(q, qd, threads)
    except FloatingPointError:
        raise _overflow("bias", {"q": q, "qd": qd}) from None


def coriolis_matrix(robot: RobotLike, q: ArrayLike, qd: ArrayLike, *, threads: int | None = None) -> np.ndarray:
    """The Coriolis matrix C(q, qd) built from the Christoffel symbols of M.

    C qd = h - g, and Mdot - 2C is skew-symmetric. q, qd: (n,) or (N, n).
    Returns (n, n) or (N, n, n).
    """
    threads = check_threads(threads)
    try:
        return compiled_model(robot).coriolis_matrix(q, qd, threads)
    except FloatingPointError:
        raise _overflow("coriolis_matrix", {"q": q, "qd": qd}) from None


def kinetic_energy(robot: RobotLike, q: ArrayLike, qd: ArrayLike, *, threads: int | None = None) -> float | np.ndarray:
    """Kinetic energy T = 1/2 qd^T M(q) qd. q, qd: (n,) -> float, or (N, n) -> (N,)."""
    threads = check_threads(threads)
    try:
        return compiled_model(robot).kinetic_energy(q, qd, threads)
    except FloatingPointError:
        raise _overflow("kinetic_energy", {"q": q, "qd": qd}) from None


def potential_energy(robot: RobotLike, q: ArrayLike, *, threads: int | None = None) -> float | np.ndarray:
    """Potential energy V = -sum_i m_i gravity . p_ci over every link (the base and links
    welded to it included, a constant), zero with every centre of mass at the base
    origin (p_ci: link i's centre of mass in the base frame).

    q: (n,) -> float, or (N, n) -> (N,).
    """
    threads = check_threads(threads)
    try:
        return compiled_model(robot).potential_energy(q, threads)
    except FloatingPointError:
        raise _overflow("potential_energy", {"q": q}) from None


def forward_kinematics(robot: RobotLike, q: ArrayLike, *, threads: int | None = None) -> np.ndarray:
    """Homogeneous pose of every link frame in the base frame.

    q: (n,) or (N, n). Returns (nlinks, 4, 4) or (N, nlinks, 4, 4), links in
    ``list(robot.links)`` order (base first); each ``[[R, p], [0, 0, 0, 1]]`` with R the
    link's axes in base coordinates and p its origin.
    """
    poses = compiled_model(robot).forward_kinematics(q, threads)
    offsets = _frame_offsets(robot)
    return poses if offsets is None else poses @ offsets


#: the reference frames of :func:`jacobian`, named as Pinocchio names them
REFERENCE_FRAMES = ("local_world_aligned", "local", "world")


def jacobian(
    robot: RobotLike,
    q: ArrayLike,
    link: str | int | Link,
    *,
    reference_frame: str = "local_world_aligned",
    threads: int | None = None,
) -> np.ndarray:
    """Geometric Jacobian of a link frame.

    q: (n,) or (N, n); link: a link name, index in ``list(robot.links)``, or Link.
    Returns J (6, n) or (N, 6, n) with ``[v; w] = J qd``, rows [v_x v_y v_z w_x w_y w_z],
    w the link's angular velocity. ``reference_frame`` (Pinocchio's names, any case):

    * ``"local_world_aligned"`` (default): v the velocity of the link frame's origin p,
      v and w in base-frame axes (Spong's [J_v; J_w]);
    * ``"local"``: the same v and w in the link frame's own axes (``R^T v``, ``R^T w``);
    * ``"world"``: the spatial velocity in the base frame: v the velocity of the body
      point passing through the base origin, ``v_p - w x p``; w in base axes.
    """
    frame = str(getattr(reference_frame, "name", reference_frame)).lower()
    if frame not in REFERENCE_FRAMES:
        raise ValueError(f"reference_frame must be one of {', '.join(REFERENCE_FRAMES)}, got {reference_frame!r}")
    J = _aligned_jacobian(robot, q, link, threads)
    if frame == "local_world_aligned":
        return J
    name = link.name if isinstance(link, Link) else link
    k = name if isinstance(name, (int, np.integer)) else list(compiled_model(robot).link_names).index(name)
    pose = forward_kinematics(robot, q, threads=threads)[..., k, :, :]
    R, p = pose[..., :3, :3], pose[..., :3, 3]
    Jv, Jw = J[..., :3, :], J[..., 3:, :]
    if frame == "local":
        Rt = R.swapaxes(-1, -2)
        return np.concatenate([Rt @ Jv, Rt @ Jw], axis=-2)
    # world: v_O = v_p + w x (0 - p) = v_p + p x w, column by column
    return np.concatenate([Jv + np.cross(p[..., None, :], Jw.swapaxes(-1, -2)).swapaxes(-1, -2), Jw], axis=-2)


def _aligned_jacobian(robot, q, link, threads):
    """:func:`jacobian` in LOCAL_WORLD_ALIGNED."""
    if isinstance(link, Link):
        link = link.name
    J = compiled_model(robot).jacobian(q, link, threads)
    offsets = _frame_offsets(robot)
    if offsets is None or not isinstance(robot, Robot):  # offsets: only a Robot has them
        return J
    # the compiled model's link frame is on the joint; move the point to the link frame's
    # origin: v' = v + w x (R pf), so J_v' = J_v - [R pf]x J_w
    k = link if isinstance(link, (int, np.integer)) else robot.link_index(link)
    R = compiled_model(robot).forward_kinematics(q, threads)[..., k, :3, :3]
    r = R @ offsets[k, :3, 3]
    Jv, Jw = J[..., :3, :], J[..., 3:, :]
    return np.concatenate([Jv - np.cross(r[..., None, :], Jw.swapaxes(-1, -2)).swapaxes(-1, -2), Jw], axis=-2)


# --------------------------------------------------------------------------- derivatives


def _mimic(robot, what: str, f_ext=None, frame: str = "local") -> MimicModel | None:
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


# rnea_derivatives, aba_derivatives and minverse decide here which path a call takes: the
# common one (a Robot already compiled to a plain NumericModel, or that model itself, and
# no f_ext) goes straight to the Rust entry, every argument by position; a robot not
# compiled yet (no `_numeric_model`: AttributeError), mimic joints (a MimicModel, which
# the entry refuses with a TypeError before doing anything) and f_ext go through the
# `_<name>_path` functions after them, which also raise again what a bad argument raised.
# One state takes about a microsecond, so the dispatch is kept lean: trying the entry
# costs less than testing the model's type first, and f_ext, frame, threads and out are
# not keyword-only, because CPython 3.11 has no specialised call for a function with
# keyword-only parameters (about 30 ns more per call).


def rnea_derivatives(
    robot: RobotLike,
    q: ArrayLike,
    qd: ArrayLike,
    qdd: ArrayLike,
    f_ext: ArrayLike | None = None,
    frame: str = "local",
    threads: int | None = None,
    out=None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Partial derivatives of inverse dynamics, analytically (Carpentier & Mansard, RSS 2018).

    robot: a Robot (or its compiled :func:`compile_model`, whose f_ext rows follow the
    model's own link order). q, qd, qdd: (n,) or (N, n). Returns ``(dtau_dq, dtau_dqd, M)``,
    each (n, n) or (N, n, n), row = output, column = input: ``dtau_dq[i, j] = d tau_i / d q_j``;
    ``M = d tau / d qdd``.

    f_ext: external wrenches, one per link: shape (nlinks, 6) (or (N, nlinks, 6) for a
    batch), rows in ``list(robot.links)`` order (base first; the base's row does not act
    on the joints), each ``[fx, fy, fz, nx, ny, nz]`` (force, then moment). ``frame``
    says where: ``"local"``: in the link's frame, moment about its origin (the wrench
    moves with the link; Pinocchio's LOCAL ``fext``); ``"world"``: in base axes, moment
    about the base frame's origin (the wrench stays fixed in space). Then
    ``tau = M qdd + C qd + g - sum_L J_L^T w_L``.

    Joint friction, rotor inertia and offset (as in :func:`rnea`) are included: ``M`` has
    ``diag(Ia)``, ``dtau_dqd`` has ``diag(Fv)``. Coulomb friction ``Fc sign(qd)`` is
    piecewise constant: it adds nothing, also at ``qd_k = 0`` where rnea's term jumps
    (``sign(0) = 0``) and has no derivative; the value given there is that of either side.
    Robots with mimic joints: ``G^T D_full G`` (chain rule, see :mod:`armdyn.mimic`); no f_ext.
    A floating base (module doc): q (nq,), qd, qdd (nv,) (or with a leading N); every
    result (nv, nv), ``dtau_dq`` on the tangent space; f_ext in the link frames only (the
    base link's row acts on the base; ``frame="world"`` is a NotImplementedError).

    out: optionally, the three arrays to write the results into and return (float64,
    C-contiguous, the results' shapes, sharing no memory with the inputs): a loop over
    batches then allocates nothing, and a large batch is spared the first-touch page
    faults of fresh arrays.
    """
    if threads is not None:  # the common call (None) skips the check's frame
        threads = check_threads(threads)  # Rust reads True as 1
    if f_ext is None:
        try:  # the core takes a NumericModel only: a Robot's cached one, or the model itself
            return _core.rnea_derivatives(robot._numeric_model, q, qd, qdd, None, frame, threads, out)  # type: ignore[union-attr]
        except (AttributeError, TypeError):
            pass  # not compiled yet, or mimic joints (see above)
    return _rnea_derivatives_path(robot, q, qd, qdd, f_ext, frame, threads, out)


def aba_derivatives(
    robot: RobotLike,
    q: ArrayLike,
    qd: ArrayLike,
    tau: ArrayLike,
    f_ext: ArrayLike | None = None,
    frame: str = "local",
    threads: int | None = None,
    out=None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Partial derivatives of forward dynamics (Carpentier & Mansard, RSS 2018, IV.C).

    q, qd, tau: (n,) or (N, n). Returns ``(dqdd_dq, dqdd_dqd, Minv)``, each (n, n) or
    (N, n, n): ``dqdd_dq[i, j] = d qdd_i / d q_j`` and ``Minv = d qdd / d tau = M^-1``.
    f_ext, frame: as in :func:`rnea_derivatives`; joint friction, rotor inertia and mimic
    joints as there (``Minv`` is that of ``M + diag(Ia)``). out: as there. A floating base: as there.
    """
    if threads is not None:  # the common call (None) skips the check's frame
        threads = check_threads(threads)  # Rust reads True as 1
    if f_ext is None:
        try:  # as in rnea_derivatives
            return _core.aba_derivatives(robot._numeric_model, q, qd, tau, None, frame, threads, out)  # type: ignore[union-attr]
        except (AttributeError, TypeError):
            pass
    return _aba_derivatives_path(robot, q, qd, tau, f_ext, frame, threads, out)


def minverse(robot: RobotLike, q: ArrayLike, threads: int | None = None, out=None) -> np.ndarray:
    """The inverse of the joint-space inertia matrix, by the articulated-body recursion
    (without forming or factorising M; Carpentier 2018). q: (n,) or (N, n). Returns (n, n)
    or (N, n, n). M includes the rotor inertias, ``diag(Ia)``, as :func:`crba`. Robots
    with mimic joints: ``(G^T M_full G)^-1`` by Cholesky (ValueError when M is not
    positive definite). out: optionally, the array to write M^-1 into and return (float64,
    C-contiguous, the result's shape, not sharing memory with q). A floating base: q (nq,), M^-1
    (nv, nv), from the CRBA and M's sparse factors.
    """
    if threads is not None:  # the common call (None) skips the check's frame
        threads = check_threads(threads)  # Rust reads True as 1
    try:  # as in rnea_derivatives
        return _core.minverse(robot._numeric_model, q, threads, out)  # type: ignore[union-attr]
    except (AttributeError, TypeError):
        pass
    return _minverse_path(robot, q, threads, out)


def _into(out, result):
    """``result`` (an array or a tuple of arrays) copied into the caller's ``out`` (same
    structure, float64, same shapes, writeable), for the paths that compute apart from
    the Rust entries' own ``out=`` (mimic joints); returns ``out``. None: ``result``."""
    if out is None:
        return result
    many = isinstance(result, tuple)
    outs = tuple(out) if many and isinstance(out, (tuple, list)) else (out,)
    results = result if many else (result,)
    if len(outs) != len(results):
        raise ValueError(f"out: expected {len(results)} arrays, got {len(outs)}")
    for k, (o, r) in enumerate(zip(outs, results)):
        name = f"out[{k}]" if many else "out"
        if not isinstance(o, np.ndarray) or o.dtype != np.float64:
            raise ValueError(f"{name}: expected a float64 numpy array, got {type(o).__name__}")
        if o.shape != r.shape:
            raise ValueError(f"{name}: expected shape {list(r.shape)}, got {list(o.shape)}")
        if not o.flags.writeable:
            raise ValueError(f"{name}: is read-only")
        o[...] = r
    return outs if many else out


def _rnea_derivatives_path(robot, q, qd, qdd, f_ext, frame, threads, out):
    """:func:`rnea_derivatives` for a robot not compiled yet (this compiles and caches
    it), mimic joints, and external wrenches (a Robot's moved to the compiled model's
    frames)."""
    model = compiled_model(robot)
    if type(model) is not NumericModel:  # mimic joints: the chain rule, see armdyn.mimic
        return _into(out, _mimic(robot, "rnea_derivatives", f_ext, frame).rnea_derivatives(q, qd, qdd, threads))
    if f_ext is not None:
        f_ext = _canonical_wrenches(robot, f_ext, frame)
    return _core.rnea_derivatives(model, q, qd, qdd, f_ext, frame, threads, out)


def _aba_derivatives_path(robot, q, qd, tau, f_ext, frame, threads, out):
    """:func:`aba_derivatives` off the common call (as above)."""
    model = compiled_model(robot)
    if type(model) is not NumericModel:  # mimic joints: the chain rule, see armdyn.mimic
        return _into(out, _mimic(robot, "aba_derivatives", f_ext, frame).aba_derivatives(q, qd, tau, threads))
    if f_ext is not None:
        f_ext = _canonical_wrenches(robot, f_ext, frame)
    return _core.aba_derivatives(model, q, qd, tau, f_ext, frame, threads, out)


def _minverse_path(robot, q, threads, out):
    """:func:`minverse` off the common call (a robot not compiled yet, mimic joints)."""
    model = compiled_model(robot)
    if type(model) is NumericModel:
        return _core.minverse(model, q, threads, out)
    # mimic joints: (G^T M_full G)^-1 by Cholesky (the constraint couples branches)
    return _into(out, _mimic(robot, "minverse").minverse(q, threads))


def gravity_derivatives(robot: RobotLike, q: ArrayLike, *, threads: int | None = None) -> np.ndarray:
    """``dg/dq`` of the gravity torques: (n, n) or (N, n, n), ``[i, j] = d g_i / d q_j``."""
    mimic = _mimic(robot, "gravity_derivatives")
    if mimic is not None:
        return mimic.gravity_derivatives(q, threads)
    return _core.gravity_derivatives(core_model(robot, "gravity_derivatives"), q, threads)


def jacobian_dot(
    robot: RobotLike, q: ArrayLike, qd: ArrayLike, link: str | int | Link, *, threads: int | None = None
) -> np.ndarray:
    """Time derivative of :func:`jacobian`: ``dJ/dt`` (6, n) or (N, 6, n), same rows
    ``[v; w]`` in base-frame axes (Pinocchio's LOCAL_WORLD_ALIGNED), so that the link
    origin's acceleration and the link's angular acceleration are ``J qdd + Jdot qd``.
    link: a link name, index in ``list(robot.links)``, or Link."""
    if isinstance(link, Link):
        link = link.name
    mimic = _mimic(robot, "jacobian_dot")
    if mimic is not None:
        Jd = mimic.jacobian_dot(q, qd, link, threads)
    else:
        Jd = _core.jacobian_dot(core_model(robot, "jacobian_dot"), q, qd, link, threads)
    offsets = _frame_offsets(robot)
    if offsets is None or not isinstance(robot, Robot):  # offsets: only a Robot has them
        return Jd
    # the point at r = R pf from the compiled (on-joint) frame's origin: J_v' = J_v - [r]x J_w,
    # so Jdot_v' = Jdot_v - [w x r]x J_w - [r]x Jdot_w, with w = J_w qd
    model = compiled_model(robot)
    k = link if isinstance(link, (int, np.integer)) else robot.link_index(link)
    r = model.forward_kinematics(q, threads)[..., k, :3, :3] @ offsets[k, :3, 3]
    Jw = model.jacobian(q, link, threads)[..., 3:, :]
    w = np.einsum("...ij,...j->...i", Jw, np.asarray(qd, dtype=float))
    rd = np.cross(w, r)

    def cross_cols(v, A):  # [v]x A, column by column
        return np.cross(v[..., None, :], A.swapaxes(-1, -2)).swapaxes(-1, -2)

    Jdv = Jd[..., :3, :] - cross_cols(rd, Jw) - cross_cols(r, Jd[..., 3:, :])
    return np.concatenate([Jdv, Jd[..., 3:, :]], axis=-2)


def regressor(
    robot: RobotLike, q: ArrayLike, qd: ArrayLike, qdd: ArrayLike, *, threads: int | None = None, columns: str = "model"
) -> np.ndarray:
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
    # parameters about each link's frame on its joint (Robot.canonical), as the symbolic
    # armdyn.identification.regressor defines them
    model = core_model(robot, "regressor")
    Y = _core.regressor(model, q, qd, qdd, threads)
    if columns == "all":
        return Y
    keep = robot.__dict__.get("_regressor_columns") if isinstance(robot, Robot) else None
    if keep is None:
        if not isinstance(robot, Robot):
            raise TypeError("columns='model' needs the Robot (a NumericModel does not say which terms a joint has)")
        first = 10 * len(robot.joints)
        extra = [
            first + 4 * i + k
            for i, j in enumerate(robot.movable_joints)
            for k, name in enumerate(("armature", "damping", "friction", "torque_offset"))
            if getattr(j, name) is not None
        ]
        # a plain slice (a view, no copy) when the model has no joint terms
        keep = slice(0, first) if not extra else np.array(list(range(first)) + extra)
        robot._regressor_columns = keep  # cached like the compiled model
    return Y[..., keep]


# ------------------------------------------------------------------ argument checks
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


def _overflow(what: str, arrays: dict) -> ValueError:
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


def _well_conditioned(M) -> bool:
    """Every (n, n) matrix of ``M`` finite, positive definite, condition number < 1e12."""
    M = np.asarray(M, dtype=float)
    try:
        np.linalg.cholesky(M)
    except np.linalg.LinAlgError:
        return False
    return bool(np.isfinite(M).all() and np.linalg.cond(M.reshape((-1,) + M.shape[-2:])).max() < 1e12)


def _all_finite(result) -> bool:
    """No NaN or inf in ``result`` (a float or an array). Small arrays by the sum of their
    entries as Python floats (NaN and inf propagate; a sum that overflows is checked
    again entry by entry), about 4 times quicker than ``np.isfinite`` on a 6-vector."""
    if type(result) is float:
        return math.isfinite(result)
    if result.ndim == 1 and result.size <= 64 and math.isfinite(sum(result.tolist())):
        return True
    return bool(np.isfinite(result).all())


def _checked(fn):
    """``fn`` with ``threads`` checked first (for the functions whose bodies do not), and the
    core's overflow error told as :func:`_overflow` does."""

    @functools.wraps(fn)
    def call(robot, *args, threads=None, **kwargs):
        if threads is not None:
            threads = check_threads(threads)
        try:
            return fn(robot, *args, threads=threads, **kwargs)
        except FloatingPointError:
            raise _overflow(fn.__name__, dict(zip(("q", "qd", "qdd"), args))) from None

    return call


def _finite(result, what: str, **arrays):
    """``result``, or the ValueError of :func:`_overflow` if it holds NaN or inf: the core
    checks that the inputs are finite, so that is an overflow (qd = 1e300 squared in the
    velocity products), which the core would return silently."""
    if not _all_finite(result):
        raise _overflow(what, arrays)
    return result


for _name in ("forward_kinematics", "jacobian", "gravity_derivatives", "jacobian_dot", "regressor"):
    globals()[_name] = _checked(globals()[_name])


def require_fixed_base(robot, what: str) -> None:
    """Raise :class:`~armdyn.errors.FloatingBaseError` naming ``what`` if ``robot`` (a Robot
    or a compiled model) has a floating base."""
    if getattr(robot, "floating", False):
        if isinstance(robot, Robot):
            robot.require_fixed_base(what)
        raise FloatingBaseError(
            f"{what} does not support a floating base (root_joint='free-flyer') yet; rnea, crba, aba and "
            "rnea_derivatives, aba_derivatives, minverse do",
            f"robot '{robot.name}'",
        )


def _fixed_base_only(fn):
    """``fn`` refusing a floating-base robot with a FloatingBaseError naming ``fn``."""

    @functools.wraps(fn)
    def call(robot, *args, **kwargs):
        if getattr(robot, "floating", False):
            require_fixed_base(robot, f"armdyn.numeric.{fn.__name__}")
        return fn(robot, *args, **kwargs)

    return call


for _name in (
    "gravity",
    "bias",
    "coriolis_matrix",
    "kinetic_energy",
    "potential_energy",
    "forward_kinematics",
    "jacobian",
    "gravity_derivatives",
    "jacobian_dot",
    "regressor",
):
    globals()[_name] = _fixed_base_only(globals()[_name])
del _name
