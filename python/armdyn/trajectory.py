"""What a simulation takes and gives: its controllers, its samples, the joint limits it reports.

:class:`PD` and :class:`ComputedTorque` are the controllers :func:`armdyn.simulate.simulate`
runs in Rust at every integrator stage; :class:`Trajectory` holds a run's stored samples
(states, torques, energies, where it left the joint limits or diverged); :func:`joint_limits`
reads the limits from the robot. Conventions as in :mod:`armdyn.simulate`, which exports
them all.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .numeric import compiled_model


@dataclass(frozen=True)
class PD:
    """Joint PD control toward ``target``: ``tau = Kp (q* - q) + Kd (qd* - qd)``, plus
    ``g(q)`` when ``gravity_compensation`` (PD with gravity compensation drives an arm
    without friction to any set point: Takegaki & Arimoto 1981). Scale the gains with the
    joint inertias (e.g. ``kp = w**2 * diag(M)``): a light wrist with a large ``kd`` is a
    stiff system that RK4 at dt = 1e-3 cannot integrate stably.

    kp, kd: scalars or (dof,) diagonal gains (N m/rad, N m s/rad); target: (dof,) or
    (N, dof); target_qd: same shapes, default zero. Evaluated in Rust at every stage.
    Joints of several coordinates: ``q* - q`` is ``difference(q, q*)`` on the tangent
    space, target (nq,), the others per velocity coordinate (nv,); a floating base: the
    joints' arrays, the base's rows of tau zero (:mod:`armdyn.simulate`).
    """

    kp: object
    kd: object
    target: object
    target_qd: object = None
    gravity_compensation: bool = True


@dataclass(frozen=True)
class ComputedTorque:
    """Computed-torque control (inverse dynamics): ``tau = rnea(q, qd, Kp e + Kd ed)``
    with ``e = q* - q``, ``ed = qd* - qd``; the closed loop is ``e'' + Kd e' + Kp e = 0``
    when ``qd* = 0`` and the model is exact (Spong, Hutchinson & Vidyasagar, eq. 8.58).

    kp, kd: scalars or (dof,) (1/s^2, 1/s); target, target_qd: (dof,) or (N, dof).
    Joints of several coordinates: ``e = difference(q, q*)``, target (nq,), the others
    (nv,); a floating base: the joints' arrays, the joints' closed loop as above and the
    unactuated base moving as it then must (:mod:`armdyn.simulate_control`).
    """

    kp: object
    kd: object
    target: object
    target_qd: object = None


@dataclass
class Trajectory:
    """A simulation's stored samples.

    For a single initial state (``q0`` of shape ``(dof,)``) arrays are ``(S, dof)`` and
    ``(S,)``; for a batch they are ``(N, S, dof)`` and ``(N, S)``. ``S`` samples at times
    ``t`` (``(S,)``, seconds). ``qdd`` and ``tau`` are the acceleration and torque at each
    stored state; ``work`` (J) the work done by the torque since t = 0,
    ``W(t) = integral of tau . qd dt``, integrated with the state by the same method
    (RK4: to the same order), not from the stored samples. Joint damping/friction of the
    model are not in ``tau``: their dissipation shows in :meth:`energy_balance`.
    Energies (J): kinetic ``1/2 qd^T M qd``, potential ``-sum m g . p_c``, and their sum
    ``energy``; None when ``energies=False``.
    """

    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    tau: np.ndarray
    q_final: np.ndarray
    qd_final: np.ndarray
    limit_step: np.ndarray
    limit_joint: np.ndarray
    nonfinite_step: np.ndarray
    dt: float
    stride: int
    method: str
    coordinate_names: list = field(default_factory=list)
    kinetic: np.ndarray | None = None
    potential: np.ndarray | None = None
    #: joint index whose q or qd was first not finite (-1: never); see nonfinite_step
    nonfinite_joint: np.ndarray | int = -1
    work: np.ndarray | None = None

    @property
    def energy(self):
        """Total energy ``kinetic + potential`` (J), or None."""
        return None if self.kinetic is None else self.kinetic + self.potential

    def energy_drift(self):
        """Largest ``|E(t) - E(0)| / max(|E(0)|, max_t T(t))`` per state (a float for a single
        state): the relative drift of the total energy. The denominator guards against
        ``E(0) = 0`` (a zero of potential energy is arbitrary)."""
        e = self.energy
        if e is None:
            raise ValueError("energies were not computed (energies=False)")
        scale = np.maximum(np.abs(e[..., :1]), np.nanmax(self.kinetic, axis=-1, keepdims=True))
        out = np.nanmax(np.abs(e - e[..., :1]) / scale, axis=-1)  # NaN: samples after a divergence
        return float(out) if out.ndim == 0 else out

    def energy_balance(self):
        """Largest ``|E(t) - E(0) - W(t)| / max(|E(0)|, max_t T(t), max_t |W(t)|)`` per state
        (a float for one state): how far the run is from the work-energy theorem
        ``E(t) - E(0) = W(t)`` (:attr:`work`). For a passive run ``W = 0`` and this is
        :meth:`energy_drift`; with torques applied the drift measures the torques' work,
        the balance the integration (and the trapezoid rule's) error."""
        e = self.energy
        if e is None:
            raise ValueError("energies were not computed (energies=False)")
        if self.work is None:
            raise ValueError("this trajectory has no record of the torques' work")
        w = self.work
        scale = np.maximum(
            np.maximum(np.abs(e[..., :1]), np.nanmax(self.kinetic, axis=-1, keepdims=True)),
            np.nanmax(np.abs(w), axis=-1, keepdims=True),
        )
        out = np.nanmax(np.abs(e - e[..., :1] - w) / scale, axis=-1)
        return float(out) if out.ndim == 0 else out

    @property
    def passive(self) -> bool:
        """True when no torque acted (every stored ``tau`` is zero)."""
        return not np.any(np.nan_to_num(self.tau))

    def limit_crossings(self) -> list[tuple[int, int, float, str]]:
        """``(state, step, time, joint name)`` for every state that crossed a joint limit
        (its first crossing)."""
        steps = np.atleast_1d(self.limit_step)
        joints = np.atleast_1d(self.limit_joint)
        return [
            (int(i), int(steps[i]), float(steps[i] * self.dt), self.coordinate_names[joints[i]])
            for i in np.flatnonzero(steps >= 0)
        ]


def joint_limits(robot) -> tuple[np.ndarray, np.ndarray]:
    """``(lower, upper)`` (dof,) of the robot's movable joints (``-inf``/``inf`` where a
    joint has none, or when ``robot`` is a compiled model without the description)."""
    from .model import Robot

    model = compiled_model(robot)
    lower, upper = np.full(model.dof, -np.inf), np.full(model.dof, np.inf)
    if isinstance(robot, Robot):
        for j in robot.joints:
            i = robot.coordinate_index(j)
            if i is None:
                continue
            for bound, out in ((j.lower, lower), (j.upper, upper)):
                if bound is None:
                    continue
                try:
                    out[i] = float(bound.subs(robot.defaults) if hasattr(bound, "subs") else bound)
                except (TypeError, ValueError):  # a symbolic limit without a value: none
                    pass
    return lower, upper
