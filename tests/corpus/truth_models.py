"""The corpus robots' dynamics from first principles, in plain SymPy (no armdyn).

Each arm is written out by hand from its model's geometry: the rotation of every link
frame, the position of its origin, of the joint it turns about, and of its mass centre,
all in the base frame, as functions of time. Everything else follows from definitions:

* angular velocity from ``S(omega) = dR/dt R^T``, accelerations by differentiating
  positions twice in time (gravity entered as the base accelerating upwards, as Craig and
  Spong do: ``vdot = R^T (p'' - g_vec)``);
* ``F = m vdot_C``, ``N = I wdot + w x I w`` about the mass centre, in the link's frame;
* ``f_i``, ``n_i``: the momentum balance of the whole subtree beyond joint ``i`` (no
  recursion), the moment taken about joint ``i``'s point, written in frame ``i``;
* Lagrange: ``K``, ``P``, ``L = K - P`` and its derivatives by SymPy differentiation;
  ``D(q)`` as the Hessian of ``K`` in the rates, Christoffel symbols and ``phi_k = dP/dq_k``.

The joint torques are Lagrange's; :func:`Arm.check` asserts Newton-Euler gives the same.
"""

from __future__ import annotations

import sympy as sp

t = sp.Symbol("t")


def rot_z(a):
    """Rotation by angle a about z (columns: the turned frame's axes)."""
    c, s = sp.cos(a), sp.sin(a)
    return sp.Matrix([[c, -s, 0], [s, c, 0], [0, 0, 1]])


def rot_x(a):
    """Rotation by angle a about x."""
    c, s = sp.cos(a), sp.sin(a)
    return sp.Matrix([[1, 0, 0], [0, c, -s], [0, s, c]])


def vee(S):
    """The vector of a skew-symmetric matrix."""
    return sp.Matrix([S[2, 1], S[0, 2], S[1, 0]])


class Link:
    """One link: R (frame in base), p (frame origin), a (joint point), pc (mass centre), all
    in the base frame and functions of t; mass m, inertia Ic about pc in the link frame; the
    joint's unit axis in the base frame (default z0) and whether it slides."""

    def __init__(self, R, p, a, pc, m, Ic, axis=None, prismatic=False):
        self.R, self.p, self.a, self.pc, self.m, self.Ic = R, p, a, pc, m, Ic
        self.axis = sp.Matrix([0, 0, 1]) if axis is None else axis
        self.prismatic = prismatic


class Quantities(dict):
    """The arm's quantities by name; some (Christoffel symbols, C) computed when first asked."""

    def __init__(self):
        super().__init__()
        self._later = {}

    def later(self, key, make):
        """Compute ``key`` with ``make()`` when it is first looked up."""
        self._later[key] = make

    def __missing__(self, key):
        if key not in self._later:
            raise KeyError(key)
        self[key] = value = self._later.pop(key)()
        return value


class Arm:
    """A serial arm: ``n`` joint coordinates ``q1..qn`` (rates ``qd``, accelerations ``qdd``),
    links built by ``build(qt)`` from the coordinates as functions of time, gravity vector
    ``g_vec`` (the acceleration of gravity, base frame)."""

    def __init__(self, name, n, params, build, g_vec):
        self.name = name
        self.q = sp.symbols(f"q1:{n + 1}")
        self.qd = sp.symbols(f"qd1:{n + 1}")
        self.qdd = sp.symbols(f"qdd1:{n + 1}")
        self.params = params
        self.qt = [sp.Function(f"q{i + 1}")(t) for i in range(n)]
        self.links = build(self.qt)
        self.g_vec = g_vec
        self.Q = Quantities()
        self._newton_euler()
        self._lagrange()

    def state(self, expr):
        """Replace q(t) and its derivatives by the symbols q, qd, qdd."""
        rep = {}
        for qt, q, qd, qdd in zip(self.qt, self.q, self.qd, self.qdd, strict=True):
            rep[sp.Derivative(qt, (t, 2))] = qdd
            rep[sp.Derivative(qt, t)] = qd
            rep[qt] = q
        # xreplace matches whole nodes first: a derivative is replaced before the q(t) in it
        return expr.xreplace(rep)

    def _newton_euler(self):
        Q, L, g = self.Q, self.links, self.g_vec
        n = len(L)
        for i, lk in enumerate(L, start=1):
            RT = lk.R.T
            w0 = vee(lk.R.diff(t) * lk.R.T)
            w = RT * w0
            wd = RT * w0.diff(t)
            Q[f"R{i}"] = lk.R  # frame i's axes in the base frame
            Q[f"omega{i}"] = w
            Q[f"omegadot{i}"] = wd
            Q[f"vdot{i}"] = RT * (lk.p.diff(t, 2) - g)
            Q[f"vcdot{i}"] = RT * (lk.pc.diff(t, 2) - g)
            # Spong's a_{c,i}, a_{e,i}: the true accelerations (gravity kept apart as g_i)
            Q[f"ac{i}"] = RT * lk.pc.diff(t, 2)
            Q[f"ae{i}"] = RT * lk.p.diff(t, 2)
            Q[f"g{i}"] = RT * g
            Q[f"F{i}"] = lk.m * Q[f"vcdot{i}"]
            Q[f"N{i}"] = lk.Ic * wd + w.cross(lk.Ic * w)
        for i, lk in enumerate(L, start=1):
            f0 = sp.zeros(3, 1)
            n0 = sp.zeros(3, 1)
            for j in range(i, n + 1):
                lj = L[j - 1]
                Fj = lj.R * Q[f"F{j}"]
                f0 += Fj
                n0 += lj.R * Q[f"N{j}"] + (lj.pc - lk.a).cross(Fj)
            Q[f"f{i}"] = lk.R.T * f0
            Q[f"n{i}"] = lk.R.T * n0
            Q[f"n{i}_z"] = Q[f"n{i}"][2]
            Q[f"f{i}_z"] = Q[f"f{i}"][2]
        for i in range(1, n + 1):
            prev = sp.eye(3) if i == 1 else L[i - 2].R
            Q[f"R{i - 1}{i}"] = prev.T * L[i - 1].R  # frame i's axes in frame i-1
            Q[f"R{i}{i - 1}"] = Q[f"R{i - 1}{i}"].T
        for k, v in list(Q.items()):
            Q[k] = self.state(v)

    def _lagrange(self):
        Q, L, g = self.Q, self.links, self.g_vec
        K = 0
        P = 0
        for i, lk in enumerate(L, start=1):
            v = lk.pc.diff(t)
            w = Q[f"omega{i}"]
            Ki = self.state(sp.Rational(1, 2) * lk.m * v.dot(v)) + sp.Rational(1, 2) * (w.T * lk.Ic * w)[0]
            Pi = self.state(-lk.m * g.dot(lk.pc))
            Q[f"K{i}"], Q[f"P{i}"] = Ki, Pi
            Q[f"Ktrans{i}"] = self.state(sp.Rational(1, 2) * lk.m * v.dot(v))
            Q[f"Krot{i}"] = sp.Rational(1, 2) * (w.T * lk.Ic * w)[0]
            Q[f"vc{i}"] = self.state(v)
            Q[f"pc{i}"] = self.state(lk.pc)
            Q[f"vc{i}_sq"] = self.state(v.dot(v))
            # Spong's Jacobians of the mass centre's velocity and of the angular velocity (base frame)
            Q[f"Jvc{i}"] = self.state(lk.pc).jacobian(self.q)
            Q[f"Jw{i}"] = self.state(lk.R * w).jacobian(self.qd)
            K += Ki
            P += Pi
        Lag = K - P
        Q["K"], Q["P"], Q["L"] = K, P, Lag
        n = len(L)
        qd_t = {qd: sp.Derivative(qt, t) for qd, qt in zip(self.qd, self.qt, strict=True)}
        q_t = dict(zip(self.q, self.qt, strict=True))
        for i in range(n):
            dqd = sp.diff(Lag, self.qd[i])
            Q[f"dL_dqd{i + 1}"] = dqd
            ddt = self.state(dqd.subs(qd_t).subs(q_t).diff(t).doit())
            Q[f"ddt_dL_dqd{i + 1}"] = ddt
            Q[f"dL_dq{i + 1}"] = sp.diff(Lag, self.q[i])
            Q[f"tau{i + 1}"] = ddt - Q[f"dL_dq{i + 1}"]
            Q[f"phi{i + 1}"] = sp.diff(P, self.q[i])
            Q[f"dK_dq{i + 1}"] = sp.diff(K, self.q[i])
        D = sp.hessian(K, self.qd)
        for i in range(n):
            for j in range(n):
                Q[f"d{i + 1}{j + 1}"] = D[i, j]
                # its time derivative along the motion (the chain rule through each joint angle)
                Q[f"d{i + 1}{j + 1}dot"] = sum(sp.diff(D[i, j], self.q[k]) * self.qd[k] for k in range(n))
        Q["D"] = D
        Q.later("C", lambda: self._coriolis(D))
        for i in range(n):
            for j in range(n):
                for k in range(n):
                    Q.later(f"c{i + 1}{j + 1}{k + 1}", lambda i=i, j=j, k=k: self._christoffel(D, i, j, k))
                    # Asada & Slotine's h_ijk = dD_ij/dq_k - 1/2 dD_jk/dq_i (i the equation; not symmetric)
                    Q.later(f"h{i + 1}{j + 1}{k + 1}", lambda i=i, j=j, k=k: self._asada(D, i, j, k))
        Q.later("Cqd", lambda: Q["C"] * sp.Matrix(self.qd))
        Q["G"] = sp.Matrix([Q[f"phi{k + 1}"] for k in range(n)])
        Q["dL_dqd"] = sp.Matrix([Q[f"dL_dqd{k + 1}"] for k in range(n)])
        Q["dK_dq"] = sp.Matrix([Q[f"dK_dq{k + 1}"] for k in range(n)])
        Q["tau"] = sp.Matrix([Q[f"tau{k + 1}"] for k in range(n)])
        Q["qdd"] = sp.Matrix(self.qdd)
        Q["qd"] = sp.Matrix(self.qd)

    def check(self, trials: int = 3, seed: int = 0) -> None:
        """Assert that Newton-Euler's joint loads (the axis component of n_i, or of f_i for a
        sliding joint) equal Lagrange's torques at random states: two methods, one answer."""
        import random

        rng = random.Random(seed)
        for _ in range(trials):
            vals = {s: sp.Float(rng.uniform(0.3, 1.7)) for s in self.symbols()}
            for i, lk in enumerate(self.links, start=1):
                load = self.Q[f"f{i}"] if lk.prismatic else self.Q[f"n{i}"]
                ne = (self.state(lk.axis).T * self.state(lk.R) * load)[0]
                a, b = float(ne.xreplace(vals)), float(self.Q[f"tau{i}"].xreplace(vals))
                assert abs(a - b) <= 1e-8 * max(1.0, abs(a), abs(b)), f"{self.name} joint {i}: NE {a} != Lagrange {b}"

    def _christoffel(self, D, i, j, k):
        """Spong's c_ijk (k names the equation), from D(q)."""
        q = self.q
        return (sp.diff(D[k, j], q[i]) + sp.diff(D[k, i], q[j]) - sp.diff(D[i, j], q[k])) / 2

    def _asada(self, D, i, j, k):
        """Asada & Slotine's h_ijk (i names the equation), from D(q)."""
        return sp.diff(D[i, j], self.q[k]) - sp.diff(D[j, k], self.q[i]) / 2

    def _coriolis(self, D):
        """C(q, qd) with C_kj = sum_i c_ijk qd_i."""
        n = len(self.q)
        C = sp.zeros(n, n)
        for k in range(n):
            for j in range(n):
                C[k, j] = sum(self.Q[f"c{i + 1}{j + 1}{k + 1}"] * self.qd[i] for i in range(n))
        return C

    def symbols(self):
        """Every symbol a value of this arm may hold."""
        return list(self.q) + list(self.qd) + list(self.qdd) + list(self.params)


def _planar_2r():
    m1, m2, l1, lc1, lc2, I1, I2, g = sp.symbols("m1 m2 l1 lc1 lc2 I1 I2 g")

    def build(qt):
        q1, q2 = qt
        R1, R2 = rot_z(q1), rot_z(q1 + q2)
        o = sp.zeros(3, 1)
        p2 = R1 * sp.Matrix([l1, 0, 0])
        return [
            Link(R1, o, o, R1 * sp.Matrix([lc1, 0, 0]), m1, sp.diag(0, I1, I1)),
            Link(R2, p2, p2, p2 + R2 * sp.Matrix([lc2, 0, 0]), m2, sp.diag(0, I2, I2)),
        ]

    return Arm("planar-2r", 2, [m1, m2, l1, lc1, lc2, I1, I2, g], build, sp.Matrix([0, -g, 0]))


def _planar_3r():
    m1, m2, m3, l1, l2, l3, g = sp.symbols("m1 m2 m3 l1 l2 l3 g")

    def build(qt):
        # DH: frame i at the far end of link i; joint i at frame i-1's origin
        links, R, p = [], sp.eye(3), sp.zeros(3, 1)
        for qi, li, mi in zip(qt, (l1, l2, l3), (m1, m2, m3), strict=True):
            a = p
            R = R * rot_z(qi)
            p = a + R * sp.Matrix([li, 0, 0])
            pc = a + R * sp.Matrix([li / 2, 0, 0])
            links.append(Link(R, p, a, pc, mi, sp.diag(0, mi * li**2 / 12, mi * li**2 / 12)))
        return links

    return Arm("planar-3r", 3, [m1, m2, m3, l1, l2, l3, g], build, sp.Matrix([0, -g, 0]))


def _rp_arm():
    m1, m2, l1, g = sp.symbols("m1 m2 l1 g")

    def build(qt):
        th, d2 = qt
        R1 = rot_z(th)
        p1 = R1 * sp.Matrix([l1, 0, 0])
        # frame 2: x2 = x1, y2 = -z1, z2 = y1; origin d2 along y1 from frame 1's origin
        R2 = R1 * sp.Matrix([[1, 0, 0], [0, 0, 1], [0, -1, 0]])
        p2 = p1 + R1 * sp.Matrix([0, d2, 0])
        return [
            Link(R1, p1, sp.zeros(3, 1), p1, m1, sp.zeros(3, 3)),
            Link(R2, p2, p1, p2, m2, sp.zeros(3, 3), axis=R2[:, 2], prismatic=True),
        ]

    return Arm("rp-arm", 2, [m1, m2, l1, g], build, sp.Matrix([0, -g, 0]))


def _scara():
    m1, m2, m3, m4, a1, a2, d1, lq, g = sp.symbols("m1 m2 m3 m4 a1 a2 d1 lq g")

    def build(qt):
        q1, q2, q3, q4 = qt

        # standard DH rows: (theta, d, a, alpha) = (q1, d1, a1, 0), (q2, 0, a2, pi), (0, q3, 0, 0), (q4, 0, 0, 0)
        def A(th, d, a, al):
            return rot_z(th), sp.Matrix([0, 0, d]) + rot_z(th) * sp.Matrix([a, 0, 0]), rot_x(al)

        R, p = sp.eye(3), sp.zeros(3, 1)
        rows = [(q1, d1, a1, 0, m1, [-a1 / 2, 0, 0], sp.diag(0, m1 * a1**2 / 12, m1 * a1**2 / 12))]
        rows.append((q2, 0, a2, sp.pi, m2, [-a2 / 2, 0, 0], sp.diag(0, m2 * a2**2 / 12, m2 * a2**2 / 12)))
        rows.append((0, q3, 0, 0, m3, [0, 0, 0], sp.diag(m3 * lq**2 / 12, m3 * lq**2 / 12, 0)))
        r = sp.Rational(3, 100)
        rows.append((q4, 0, 0, 0, m4, [0, 0, 0], sp.diag(m4 * r**2 / 4, m4 * r**2 / 4, m4 * r**2 / 2)))
        links = []
        for k, (th, d, a, al, m, com, Ic) in enumerate(rows):
            a_pt, axis = p, R[:, 2]
            Rz, off, Rx = A(th, d, a, al)
            p = p + R * off
            R = R * Rz * Rx
            links.append(Link(R, p, a_pt, p + R * sp.Matrix(com), m, Ic, axis=axis, prismatic=k == 2))
        return links

    return Arm("scara", 4, [m1, m2, m3, m4, a1, a2, d1, lq, g], build, sp.Matrix([0, 0, -g]))


BUILDERS = {"planar-2r": _planar_2r, "planar-3r": _planar_3r, "rp-arm": _rp_arm, "scara": _scara}
_CACHE: dict[str, Arm] = {}


def arm(name: str) -> Arm:
    """The arm called ``name`` (built once)."""
    if name not in _CACHE:
        _CACHE[name] = BUILDERS[name]()
    return _CACHE[name]
