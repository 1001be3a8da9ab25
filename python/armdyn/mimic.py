"""Numeric dynamics of robots with mimic joints, over the Rust core's unconstrained model.

A mimic joint (URDF ``<mimic>``, :class:`armdyn.model.Mimic`) follows its leader:
``q_m = multiplier * q_leader + offset``. The constraint is linear with constant
coefficients, so the coordinates of every non-fixed joint (``n_full`` of them, mimic
joints included, in tree order) are an affine function of the robot's ``dof``
independent coordinates::

    q_full = G q + o,      qd_full = G qd,      qdd_full = G qdd

with ``G`` (n_full, dof) holding one entry per row: 1 in the joint's own column, or
the multiplier in its leader's (chains composed). By the principle of virtual work
(d'Alembert), the generalised forces of the reduced system are ``G^T`` times the full
ones, which gives every quantity from the Rust core's algorithms run unchanged on the
full tree (the model where mimic joints are ordinary joints):

    tau = G^T rnea_full(q_full, qd_full, qdd_full)         inverse dynamics
    M   = G^T M_full(q_full) G                              T = 1/2 qd^T M qd
    h   = G^T h_full(q_full, qd_full),  g = G^T g_full
    C   = G^T C_full(q_full, qd_full) G                     Christoffel symbols of M
    J   = J_full(q_full) G                                  [v; w] = J qd

(the Christoffel symbols of ``M`` transform as a tensor under a linear map with
constant coefficients, so ``C`` stays the one with ``Mdot - 2C`` skew-symmetric).
Forward dynamics cannot run Featherstone's ABA on the full tree (the constraint couples
bodies in different branches); it solves the reduced equations instead,

    (G^T M_full G) qdd = tau - G^T h_full,

by a Cholesky factorisation of the (dof, dof) mass matrix, O(dof^3) per state instead
of ABA's O(dof). Pinocchio 4.1 builds the same constrained model
(``buildModelFromUrdf(path, mimic=True)``) and likewise has no ABA for it.

The mapping runs in NumPy over the Rust core's batched calls (one call per quantity for
a whole batch); robots without mimic joints never come here, so their path is unchanged.
"""

from __future__ import annotations

import numpy as np

from . import _core
from .model import Robot

__all__ = ["MimicModel"]


class MimicModel:
    """A compiled robot with mimic joints: the methods of :class:`armdyn.numeric.NumericModel`
    (same names, arguments, shapes and errors) in the robot's ``dof`` independent
    coordinates.

    Attributes: ``dof``, ``nlinks``, ``name``, ``link_names``, ``coordinate_names``,
    ``gravity`` (3,); ``full``: the NumericModel of the whole tree with every non-fixed
    joint free (coordinates ``full.coordinate_names``); ``G`` (n_full, dof) and
    ``offset`` (n_full,): ``q_full = G q + offset``.
    """

    def __init__(self, full: _core.NumericModel, robot: Robot):
        moving = [j for j in robot.joints if j.movable]  # mimic joints included, tree order
        if [j.name for j in moving] != list(full.coordinate_names):
            raise ValueError("the full model's coordinates are not the robot's non-fixed joints")
        self.full = full
        self.dof = robot.dof
        self.coordinate_names = list(robot.coordinate_names)
        self.G = np.zeros((len(moving), robot.dof))
        self.offset = np.zeros(len(moving))
        source = np.zeros(len(moving), dtype=np.intp)  # the coordinate each full joint follows
        for a, joint in enumerate(moving):
            k, multiplier, offset = robot.follows(joint)
            self.G[a, k] = float(multiplier)
            self.offset[a] = float(offset)
            source[a] = k
        # G has one entry per row: products by G are gathers, and products by G^T the
        # coordinates' own entries plus, one mimic joint at a time, multiplier times its
        # entry: elementwise, in a fixed order, so that a batch gives the single calls'
        # results bit for bit.
        self._source = source
        self._multiplier = self.G[np.arange(len(moving)), source]
        self._own = np.array([a for a, j in enumerate(moving) if j.mimic is None], dtype=np.intp)  # (dof,)
        self._terms = [
            (a, int(source[a]), float(self._multiplier[a])) for a, j in enumerate(moving) if j.mimic is not None
        ]

    # ---------------------------------------------------------------- description
    @property
    def nlinks(self) -> int:
        return self.full.nlinks

    @property
    def name(self) -> str:
        return self.full.name

    @property
    def link_names(self) -> list[str]:
        return self.full.link_names

    @property
    def gravity(self):
        return self.full.gravity

    @property
    def _numeric_model(self) -> "MimicModel":
        return self

    def __repr__(self) -> str:
        return f"MimicModel({self.name!r}, dof={self.dof}, mimic joints={len(self.offset) - self.dof}, nlinks={self.nlinks})"

    # ---------------------------------------------------------------- input
    def _states(self, *named: tuple[str, object]) -> list[np.ndarray]:
        """Each ``(name, value)`` as a float64 array of shape (dof,) or (N, dof), all of
        one shape; else ValueError naming it (as the Rust bindings do). NaN and inf are
        caught by the Rust core on the full arrays (a gather copies them), and named in
        these coordinates by :meth:`_finite` when it refuses them."""
        n, out, first = self.dof, [], None
        for name, x in named:
            a = x
            if type(a) is not np.ndarray or a.dtype != np.float64:
                a = np.asarray(x)
                if a.dtype.kind not in "fiu":
                    raise ValueError(f"{name}: expected real numbers, got an array of dtype {a.dtype}")
                a = a.astype(np.float64)
            if not (a.ndim in (1, 2) and a.shape[-1] == n):
                raise ValueError(f"{name}: expected shape ({n},) for one state or (N, {n}) for a batch, got {a.shape}")
            if first is None:
                first = (name, a.shape)
            elif a.shape != first[1]:
                raise ValueError(f"{name}: shape {a.shape} does not match {first[0]}'s {first[1]}")
            out.append(a)
        return out

    @staticmethod
    def _finite(named: dict[str, np.ndarray]) -> None:
        for name, a in named.items():
            if not np.isfinite(a).all():
                at = np.argwhere(~np.isfinite(a))[0]
                raise ValueError(f"{name} contains NaN or inf (at {name}[{', '.join(map(str, at))}])")

    def _call(self, method: str, named: dict[str, np.ndarray], *args):
        """``self.full.<method>(*args)``; a refusal of NaN/inf is re-worded for ``named``."""
        return self._guarded(lambda: getattr(self.full, method)(*args), method, named)

    def _guarded(self, call, method: str, named: dict[str, np.ndarray]):
        """``call()``; a refusal of NaN/inf is re-worded for ``named`` (see :meth:`_call`)."""
        try:
            return call()
        except ValueError as err:
            self._finite(named)
            if "NaN or inf" not in str(err):
                raise
            raise ValueError(
                f"{method}: a mimic joint's coordinate (multiplier * q + offset) or rate overflows to inf "
                f"at this state of '{self.name}'"
            ) from None

    def _position(self, q: np.ndarray) -> np.ndarray:
        """``G q + o`` (..., n_full)."""
        return q[..., self._source] * self._multiplier + self.offset

    def _rate(self, x: np.ndarray) -> np.ndarray:
        """``G x`` (..., n_full)."""
        return x[..., self._source] * self._multiplier

    def _reduce(self, x: np.ndarray) -> np.ndarray:
        """``x G`` over the last axis, (..., n_full) -> (..., dof): ``G^T tau`` row by row."""
        out = np.take(x, self._own, axis=-1)
        for a, k, m in self._terms:
            out[..., k] += m * x[..., a]
        return out

    def _reduce_rows(self, A: np.ndarray) -> np.ndarray:
        """``G^T A`` for each matrix of ``A`` (..., n_full, m) -> (..., dof, m); rows are
        contiguous, which makes this pass the fast one."""
        out = np.take(A, self._own, axis=-2)
        for a, k, m in self._terms:
            out[..., k, :] += m * A[..., a, :]
        return out

    def _reduce_matrix(self, A: np.ndarray) -> np.ndarray:
        """``G^T A G`` for each (n_full, n_full) matrix of ``A`` (..., n_full, n_full)."""
        GA = self._reduce_rows(A)  # (..., dof, n_full)
        GAG_T = self._reduce_rows(np.ascontiguousarray(np.swapaxes(GA, -1, -2)))  # (G^T A G)^T
        return np.ascontiguousarray(np.swapaxes(GAG_T, -1, -2))

    # ---------------------------------------------------------------- dynamics
    def rnea(self, q, qd, qdd, threads=None):
        q, qd, qdd = self._states(("q", q), ("qd", qd), ("qdd", qdd))
        named = {"q": q, "qd": qd, "qdd": qdd}
        return self._reduce(self._call("rnea", named, self._position(q), self._rate(qd), self._rate(qdd), threads))

    def crba(self, q, threads=None):
        (q,) = self._states(("q", q))
        return self._reduce_matrix(self._call("crba", {"q": q}, self._position(q), threads))

    def gravity_torques(self, q, threads=None):
        (q,) = self._states(("q", q))
        return self._reduce(self._call("gravity_torques", {"q": q}, self._position(q), threads))

    def bias(self, q, qd, threads=None):
        q, qd = self._states(("q", q), ("qd", qd))
        return self._reduce(self._call("bias", {"q": q, "qd": qd}, self._position(q), self._rate(qd), threads))

    def aba(self, q, qd, tau, threads=None):
        """qdd solving ``(G^T M_full G) qdd = tau - G^T h_full`` (Cholesky; see the module)."""
        q, qd, tau = self._states(("q", q), ("qd", qd), ("tau", tau))
        if not np.isfinite(tau).all():  # tau does not go through the Rust core
            self._finite({"tau": tau})
        named = {"q": q, "qd": qd}
        qf = self._position(q)
        M = self._reduce_matrix(self._call("crba", named, qf, threads))
        rhs = tau - self._reduce(self._call("bias", named, qf, self._rate(qd), threads))
        L = self._cholesky(M, "aba")
        y = np.linalg.solve(L, rhs[..., None])
        return np.linalg.solve(np.swapaxes(L, -1, -2), y)[..., 0]

    def coriolis_matrix(self, q, qd, threads=None):
        q, qd = self._states(("q", q), ("qd", qd))
        C = self._call("coriolis_matrix", {"q": q, "qd": qd}, self._position(q), self._rate(qd), threads)
        return self._reduce_matrix(C)

    def kinetic_energy(self, q, qd, threads=None):
        q, qd = self._states(("q", q), ("qd", qd))
        return self._call("kinetic_energy", {"q": q, "qd": qd}, self._position(q), self._rate(qd), threads)

    def potential_energy(self, q, threads=None):
        (q,) = self._states(("q", q))
        return self._call("potential_energy", {"q": q}, self._position(q), threads)

    # ---------------------------------------------------------------- kinematics
    def forward_kinematics(self, q, threads=None):
        (q,) = self._states(("q", q))
        return self._call("forward_kinematics", {"q": q}, self._position(q), threads)

    def jacobian(self, q, link, threads=None):
        (q,) = self._states(("q", q))
        return self._reduce(self._call("jacobian", {"q": q}, self._position(q), link, threads))

    # ---------------------------------------------------------------- centre of mass
    # armdyn.centroidal's quantities: the full tree's at (G q + o, G v, G a); a matrix over
    # the velocities times G (h_G = A_full G v).
    def center_of_mass(self, q, threads=None):
        (q,) = self._states(("q", q))
        return self._call_core("center_of_mass", {"q": q}, self._position(q), threads)

    def com_jacobian(self, q, threads=None):
        (q,) = self._states(("q", q))
        return self._reduce(self._call_core("com_jacobian", {"q": q}, self._position(q), threads))

    def centroidal_map(self, q, threads=None):
        (q,) = self._states(("q", q))
        return self._reduce(self._call_core("centroidal_map", {"q": q}, self._position(q), threads))

    def centroidal_map_rate(self, q, v, threads=None):
        q, v = self._states(("q", q), ("v", v))
        named = {"q": q, "v": v}
        return self._reduce(self._call_core("centroidal_map_rate", named, self._position(q), self._rate(v), threads))

    def centroidal_momentum(self, q, v, threads=None):
        q, v = self._states(("q", q), ("v", v))
        named = {"q": q, "v": v}
        return self._call_core("centroidal_momentum", named, self._position(q), self._rate(v), threads)

    def centroidal_momentum_rate(self, q, v, a, threads=None):
        q, v, a = self._states(("q", q), ("v", v), ("a", a))
        named = {"q": q, "v": v, "a": a}
        full = (self._position(q), self._rate(v), self._rate(a))
        return self._call_core("centroidal_momentum_rate", named, *full, threads)

    # ---------------------------------------------------------------- derivatives
    # With q_full = G q + o (G constant), tau(q, qd, qdd) = G^T tau_full(G q + o, G qd, G qdd),
    # so by the chain rule every derivative is the full tree's, reduced on both sides:
    #     dtau/dx = G^T (dtau_full/dx_full) G     (x = q, qd, qdd; the last is M)
    # and forward dynamics follows from ID(q, qd, FD(q, qd, tau)) = tau (Carpentier & Mansard,
    # RSS 2018, IV.C): dqdd/dx = -M^-1 dID/dx at qdd = FD(q, qd, tau), dqdd/dtau = M^-1, with
    # M = G^T M_full G inverted by Cholesky (the full tree's ABA-based M^-1 is not the
    # constrained one). Joint friction and rotor inertia sit on the independent coordinates
    # only (a mimic joint's own are zero in `full`), so G^T diag(Fv_full) G = diag(Fv).

    def _call_core(self, function: str, named: dict[str, np.ndarray], *args, **kwargs):
        """``armdyn._core.<function>(self.full, *args, **kwargs)``; NaN/inf re-worded as in :meth:`_call`."""
        return self._guarded(lambda: getattr(_core, function)(self.full, *args, **kwargs), function, named)

    def _cholesky(self, M: np.ndarray, what: str) -> np.ndarray:
        """L with ``M = L L^T`` for (..., dof, dof) mass matrices; ValueError naming
        ``what`` when M is not positive definite."""
        try:
            return np.linalg.cholesky(M)
        except np.linalg.LinAlgError:
            raise ValueError(
                f"{what}: the mass matrix of '{self.name}' is not positive definite at this state "
                "(a coordinate that moves no mass or inertia?)"
            ) from None

    def _inverse_mass_matrix(self, M: np.ndarray, what: str) -> np.ndarray:
        """``M^-1`` of (..., dof, dof) symmetric positive definite matrices, by Cholesky
        (``M = L L^T``, ``M^-1 = L^-T L^-1``); ValueError when M is not positive definite."""
        L = self._cholesky(M, what)
        Linv = np.linalg.solve(L, np.broadcast_to(np.eye(self.dof), M.shape))
        return np.swapaxes(Linv, -1, -2) @ Linv

    def rnea_derivatives(self, q, qd, qdd, threads=None):
        """``(dtau_dq, dtau_dqd, M)``, each (dof, dof) or (N, dof, dof): the full tree's
        analytical derivatives reduced, ``G^T D_full G``."""
        q, qd, qdd = self._states(("q", q), ("qd", qd), ("qdd", qdd))
        named = {"q": q, "qd": qd, "qdd": qdd}
        full = self._call_core(
            "rnea_derivatives", named, self._position(q), self._rate(qd), self._rate(qdd), threads=threads
        )
        return tuple(self._reduce_matrix(D) for D in full)

    def aba_derivatives(self, q, qd, tau, threads=None):
        """``(dqdd_dq, dqdd_dqd, Minv)``, each (dof, dof) or (N, dof, dof), at
        ``qdd = aba(q, qd, tau)``: ``-M^-1 dID/dq``, ``-M^-1 dID/dqd``, ``M^-1``."""
        q, qd, tau = self._states(("q", q), ("qd", qd), ("tau", tau))
        qdd = self.aba(q, qd, tau, threads)
        dq, dqd, M = self.rnea_derivatives(q, qd, qdd, threads)
        Minv = self._inverse_mass_matrix(M, "aba_derivatives")
        return -(Minv @ dq), -(Minv @ dqd), Minv

    def minverse(self, q, threads=None):
        """``(G^T M_full G)^-1``, (dof, dof) or (N, dof, dof), by Cholesky."""
        return self._inverse_mass_matrix(self.crba(q, threads), "minverse")

    def gravity_derivatives(self, q, threads=None):
        """``dg/dq = G^T (dg_full/dq_full) G``, (dof, dof) or (N, dof, dof)."""
        (q,) = self._states(("q", q))
        return self._reduce_matrix(self._call_core("gravity_derivatives", {"q": q}, self._position(q), threads))

    def jacobian_dot(self, q, qd, link, threads=None):
        """``dJ/dt = Jdot_full(q_full, G qd) G`` (J = J_full G with G constant), (6, dof)
        or (N, 6, dof), rows as :meth:`jacobian`."""
        q, qd = self._states(("q", q), ("qd", qd))
        Jd = self._call_core("jacobian_dot", {"q": q, "qd": qd}, self._position(q), self._rate(qd), link, threads)
        return self._reduce(Jd)
