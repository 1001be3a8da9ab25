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
* Every result belongs to the caller alone. For one state armdyn may write the result
  into a small array it made for an earlier call once nothing refers to that array any
  more (no name, view or weak reference; it spares the allocation, a fifth of a
  6-joint crba): a result held is never changed. The one visible trace is that
  ``result.resize(...)`` in place needs ``refcheck=False``.
* ``aba`` raises ``ValueError`` when the joint-space inertia matrix is singular: a
  movable joint whose subtree has no mass and no inertia (named in the message), or
  a state where the result is not finite.

Conventions (docs/architecture.md): SI units, radians; ``M(q) qdd + C(q, qd) qd + g(q) = tau``;
gravity is the robot's vector in the base frame; frames as in :mod:`armdyn.model`.

A floating base (``armdyn.load(path, root_joint="free-flyer")``, ``robot.floating``):
``rnea``, ``crba``, ``aba``, ``rnea_derivatives``, ``aba_derivatives`` and ``minverse`` (and
``gravity``, ``bias``, ``gravity_derivatives``: theirs at rest) take Pinocchio's arrays, unchanged: ``q`` is
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
here). ``forward_kinematics`` (poses in the world frame), ``jacobian`` (``(6, nv)``, its
frames in the world frame), ``kinetic_energy`` and ``potential_energy`` (of the whole
robot, the base's too) take them as well, and :mod:`armdyn.centroidal` gives the centre
of mass and the centroidal momentum. Every other function here raises
:class:`~armdyn.errors.FloatingBaseError` (a ``ModelError`` and ``NotImplementedError``)
for a floating robot, naming itself.
"""

from __future__ import annotations

from .. import _core  # noqa: F401  (armdyn.numeric._core: the extension, for benchmarks comparing builds)
from ..configuration import difference, integrate, neutral, random_configuration
from .checks import MAX_THREADS, check_threads, require_fixed_base  # noqa: F401  (shared with simulate, dask)
from .compiled import ModelBuilder, NumericModel, RobotLike, compile_model, compiled_model, core_model  # noqa: F401
from .derivatives import aba_derivatives, gravity_derivatives, minverse, rnea_derivatives
from .dynamics import aba, bias, coriolis_matrix, crba, gravity, kinetic_energy, potential_energy, regressor, rnea
from .kinematics import REFERENCE_FRAMES, forward_kinematics, jacobian, jacobian_dot  # noqa: F401

__all__ = [
    "NumericModel",
    "ModelBuilder",
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
