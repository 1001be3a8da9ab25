"""Dynamic identification models: the regressor and the base parameters, symbolically.

    reg = regressor(robot)          # tau == reg.Y * reg.pi, exactly
    base = base_parameters(robot)   # tau == base.Y * base.beta, beta minimal

Standard parameters (docs/architecture.md), link by link (every link but the base, in
``list(robot.links)`` order), about the link frame's origin, in the link frame::

    [M, MX, MY, MZ, XX, XY, YY, XZ, YZ, ZZ]_j = [m, m cx, m cy, m cz, Ixx, Ixy, Iyy, Ixz, Iyz, Izz]

(Pinocchio's order; ``I = I_c + m (c.c 1 - c c^T)`` the tensor about the origin, its
entries as in URDF, so ``Ixy`` is the tensor entry), then joint by joint the terms the
joint has (``armature``, ``damping``, ``friction``, ``torque_offset`` not None):
``IA_j, FV_j, FC_j, OFF_j``. Names follow Khalil (``XX2``, ``MZ3``, ``M1``, ``FV2``), the
index being the link's frame number (``robot.link_index``; the joint's child link for
joint terms).

**Regressor.** Newton-Euler written linear in the parameters (Khalil and Dombre,
*Modeling, Identification and Control of Robots*, 2002, sec. 12.4; Atkeson, An and
Hollerbach 1986): with the link's angular velocity ``w``, acceleration ``wd`` and the
acceleration ``vd`` of its frame origin (gravity as a base acceleration, Craig's
outward recursion), the force and moment about the origin needed to move link j are

    f = M vd + wd x h + w x (w x h),      n = I wd + w x I w + h x vd      (h = m c)

both linear in ``(M, h, I)``; each parameter's column of Y is that force/moment for the
unit parameter, carried inward ``f_p = R f``, ``n_p = R n + p x R f`` and projected on
each ancestor joint's axis.

**Base parameters.** Khalil's grouping rules, written for any unit axis and any joint
placement (not only DH), applied from the leaves to the root (Gautier and Khalil 1990;
Khalil and Dombre sec. 12.5), then exact rank tests:

* revolute joint j, axis u: the part of link j that is a body of mass ``M_j``, first
  moment ``h_u u`` along the axis and inertia ``c (1 - u u^T)`` has kinetic and potential
  energy independent of q_j and qd_j, so it acts as a body fixed to the parent link:
  it is moved (rotation and parallel axis, exact) onto the parent's parameters, and
  ``M_j``, one first-moment component along u (``MZ_j`` for u = z) and one inertia
  diagonal entry (``YY_j`` for u = z) leave the model (``XXR_j = XX_j - YY_j``,
  ``ZZR_{j-1} = ZZ_{j-1} + YY_j + ...``);
* prismatic joint j: link j does not turn relative to its parent, so its whole
  inertia tensor is a pure couple moved (rotated) onto the parent;
* fixed joint: the whole link is moved onto the parent;
* what reaches the base has no effect.

What is left can still hold columns of Y that are zero (the first links' motion is
restricted) or dependent on others (e.g. a rotor inertia ``IA1`` and ``ZZ1R``). Those are
found exactly: Y is evaluated at random rational states (sin and cos given by rational
points of the unit circle, ``((1 - t^2)/(1 + t^2), 2t/(1 + t^2))``) and reduced in exact
rational arithmetic (modulo the prime 2^127 - 1, coefficients recovered by rational
reconstruction and confirmed with Fractions at a further point). A zero column is
dropped; a dependent one is added to the columns it depends on with its exact
coefficients. When those change with the geometry (two random geometries are tried:
e.g. a SCARA's prismatic joint parallel to its revolute ones, ZZ2R = ZZ2 + ZZ3 + 2 a2 MX3),
the few columns involved are evaluated with the geometry kept symbolic and the small
system solved exactly. By the Schwartz-Zippel lemma a polynomial identity that holds at
random points holds everywhere with probability 1 - O(degree / range). The exact
evaluation, ranks and reconstruction are in :mod:`armdyn.exact_evaluation`.
"""

from __future__ import annotations

import random
from dataclasses import dataclass, field, replace

import symengine as se
import sympy as sp

from .exact_evaluation import (
    PRIME,
    angles_and_scalars,
    exact_rank,
    nonzero_fraction,
    rational,
    rref,
    stacked_exact,
)
from .model import Robot
from .programs.grouping import moved_to_parent
from .programs.vectors import rows

#: standard inertial parameter names per link, the architecture's (Pinocchio's) order
INERTIAL = ("M", "MX", "MY", "MZ", "XX", "XY", "YY", "XZ", "YZ", "ZZ")
#: joint terms: (Joint attribute, Khalil-style name)
JOINT_TERMS = (("armature", "IA"), ("damping", "FV"), ("friction", "FC"), ("torque_offset", "OFF"))
# index of each inertia tensor entry (row, col) in the 10-vector
_I_INDEX = {(0, 0): 4, (0, 1): 5, (1, 1): 6, (0, 2): 7, (1, 2): 8, (2, 2): 9}


def _tensor(p) -> sp.Matrix:
    """(3, 3) inertia tensor from a 10-vector (entries 4..9)."""
    xx, xy, yy, xz, yz, zz = p[4:10]
    return sp.Matrix([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]])


def _vector(m, h, I) -> list:
    """10-vector ``[m, h, Ixx, Ixy, Iyy, Ixz, Iyz, Izz]``."""
    return [m, h[0], h[1], h[2], I[0, 0], I[0, 1], I[1, 1], I[0, 2], I[1, 2], I[2, 2]]


def standard_parameters(robot: Robot) -> tuple[list[str], list]:
    """Names and values (SymPy expressions of the model's parameters) of the standard
    parameters, in the order described in the module docstring."""
    names, values = [], []
    for joint in robot.joints:
        link = robot.links[joint.child]
        j = robot.link_index(joint.child)
        m, c = link.mass, link.com
        I_origin = link.inertia + m * (c.dot(c) * sp.eye(3) - c * c.T)  # parallel axis
        names += [f"{n}{j}" for n in INERTIAL]
        values += _vector(m, m * c, I_origin)
    for joint in robot.movable_joints:
        j = robot.link_index(joint.child)
        for attr, prefix in JOINT_TERMS:
            if getattr(joint, attr) is not None:
                names.append(f"{prefix}{j}")
                values.append(getattr(joint, attr))
    return names, values


@dataclass
class Regressor:
    """``tau = Y * pi`` (see the module docstring for the column order).

    robot:   the robot.
    Y:       (dof, P) SymPy matrix in ``robot.q, robot.qd, robot.qdd`` and the model's
             geometric parameters (and gravity); ``sign(qd_j)`` for Coulomb friction.
    pi:      (P, 1) the standard parameters' values (expressions of the model's parameters).
    names:   P Khalil-style names (``M1, MX1, ..., ZZ1, ..., IA1, FV1, FC1, OFF1``).
    symbols: (P, 1) one plain Symbol per name (to write ``tau`` in standard parameters).
    """

    robot: Robot
    Y: sp.Matrix
    pi: sp.Matrix
    names: list[str]
    symbols: sp.Matrix = field(default=None)

    def __post_init__(self):
        if self.symbols is None:
            self.symbols = sp.Matrix([sp.Symbol(n) for n in self.names])

    @property
    def tau(self) -> sp.Matrix:
        """``Y * pi`` (dof, 1)."""
        return self.Y * self.pi


def _cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def _add(*vs):
    return [sum(x, se.Integer(0)) for x in zip(*vs)]


def _scale(s, a):
    return [s * x for x in a]


def _mul(R, a):  # R: 3x3 nested list, a: 3-list
    return [R[i][0] * a[0] + R[i][1] * a[1] + R[i][2] * a[2] for i in range(3)]


def _tmul(R, a):  # R^T a
    return [R[0][i] * a[0] + R[1][i] * a[1] + R[2][i] * a[2] for i in range(3)]


def _dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def _se_vec(m):
    return [se.sympify(x) for x in m]


def _se_mat(m):
    return [[se.sympify(m[i, j]) for j in range(3)] for i in range(3)]


def _outward(robot: Robot):
    """Craig's outward recursion (as symbolic/newton_euler.py, in SymEngine for speed):
    per link, its ``w, wd, vd`` (frame origin, gravity as base acceleration) and the
    child's pose ``(R, p)`` in the parent."""
    zero = [se.Integer(0)] * 3
    w, wd, vd = {robot.base: zero}, {robot.base: zero}, {robot.base: _scale(-1, _se_vec(robot.gravity))}
    pose = {}
    qd, qdd = _se_vec(robot.qd), _se_vec(robot.qdd)
    for joint in robot.joints:
        parent, k = joint.parent, robot.coordinate_index(joint)
        R, p = joint.transform(robot.joint_coordinate(joint))
        R, p, z = _se_mat(R), _se_vec(p), _se_vec(joint.axis)
        pose[joint.child] = (R, p)
        w_in, wd_in = _tmul(R, w[parent]), _tmul(R, wd[parent])
        vd_i = _tmul(R, _add(_cross(wd[parent], p), _cross(w[parent], _cross(w[parent], p)), vd[parent]))
        if joint.type == "revolute":
            w_i = _add(w_in, _scale(qd[k], z))
            wd_i = _add(wd_in, _cross(w_in, _scale(qd[k], z)), _scale(qdd[k], z))
        else:
            w_i, wd_i = w_in, wd_in
        if joint.type == "prismatic":
            vd_i = _add(vd_i, _scale(2, _cross(w_i, _scale(qd[k], z))), _scale(qdd[k], z))
        w[joint.child], wd[joint.child], vd[joint.child] = w_i, wd_i, vd_i
    return w, wd, vd, pose


def _unit_wrenches(w, wd, vd):
    """For each of the 10 unit parameters, ``(f, n)``: force and moment about the frame
    origin that move a body of that parameter alone (Khalil and Dombre eq. 12.30)."""
    zero = [se.Integer(0)] * 3
    out = [(vd, zero)]  # M
    for i in range(3):  # MX, MY, MZ
        e = [se.Integer(int(i == j)) for j in range(3)]
        out.append((_add(_cross(wd, e), _cross(w, _cross(w, e))), _cross(e, vd)))
    for a, b in ((0, 0), (0, 1), (1, 1), (0, 2), (1, 2), (2, 2)):  # XX, XY, YY, XZ, YZ, ZZ
        E = [[se.Integer(0)] * 3 for _ in range(3)]
        E[a][b] = E[b][a] = se.Integer(1)
        out.append((zero, _add(_mul(E, wd), _cross(w, _mul(E, w)))))
    return out


def regressor(robot: Robot) -> Regressor:
    """The symbolic joint torque regressor of ``robot``: ``tau = Y pi`` (Newton-Euler
    linear in the parameters; see the module docstring). Exact: ``Y * pi`` equals
    the Newton-Euler and Lagrange torques (tests). Inertial parameters are about each
    link's frame on its joint (:meth:`armdyn.model.Robot.canonical`: the same as the
    link frame unless the model places a link frame off its joint's axis)."""
    robot.require_fixed_base("armdyn.identification.regressor")
    robot.require_one_dof_joints("armdyn.identification.regressor")
    robot = robot.canonical()
    names, values = standard_parameters(robot)
    n = robot.dof
    w, wd, vd, pose = _outward(robot)
    cols = []
    chain: dict[str, list] = {}  # link -> its joints from itself to the base
    for joint in robot.joints:
        chain[joint.child] = [joint] + chain.get(joint.parent, [])
    for joint in robot.joints:
        name = joint.child
        for f, m in _unit_wrenches(w[name], wd[name], vd[name]):
            col = [sp.Integer(0)] * n
            for jt in chain[name]:
                k = robot.coordinate_index(jt)
                if k is not None:
                    col[k] = sp.sympify(_dot(m if jt.type == "revolute" else f, _se_vec(jt.axis)))
                R, p = pose[jt.child]
                f = _mul(R, f)
                m = _add(_mul(R, m), _cross(p, f))
            cols.append(col)
    for joint in robot.movable_joints:
        k = robot.coordinate_index(joint)
        assert k is not None  # a movable joint has a coordinate
        coefficient = {
            "armature": robot.qdd[k],
            "damping": robot.qd[k],
            "friction": sp.sign(robot.qd[k]),
            "torque_offset": sp.Integer(1),
        }
        for attr, _ in JOINT_TERMS:
            if getattr(joint, attr) is not None:
                col = [sp.Integer(0)] * n
                col[k] = coefficient[attr]
                cols.append(col)
    Y = sp.Matrix(n, len(cols), lambda i, c: cols[c][i]) if cols else sp.zeros(n, 0)
    return Regressor(robot, Y, sp.Matrix(values), names)


# ------------------------------------------------------------------ base parameters


@dataclass
class BaseParameters:
    """The base (minimal identifiable) parameters: ``tau = Y * beta``.

    Y:              (dof, B) base regressor (columns of the standard regressor).
    beta:           (B, 1) base parameters as exact linear combinations of the standard
                    parameter symbols (``regressor.symbols``), e.g. ``ZZ2 + XX3 + ...``.
    names:          B names: the standard name of the kept column, with ``R`` appended
                    when other parameters were grouped into it (Khalil: ``ZZ2R``).
    unidentifiable: standard parameter names whose column of Y is identically zero.
    values:         (B, 1) ``beta`` with the robot's own parameter values substituted.
    regressor:      the standard :class:`Regressor`.
    columns:        B indices of the base columns in the standard regressor
                    (``Y == regressor.Y[:, columns]``; also the columns of
                    ``armdyn.numeric.regressor(robot, ...)``).
    """

    Y: sp.Matrix
    beta: sp.Matrix
    names: list[str]
    unidentifiable: list[str]
    values: sp.Matrix
    regressor: Regressor
    columns: list[int] = field(default_factory=list)


def _group_revolute(vec, u):
    """Split link j's 10 parameters (list of expressions) for a revolute joint with unit
    axis ``u``: returns (eliminated indices, group body (m, h, I) moving to the parent,
    the parameters left on link j)."""
    uu = [sp.nsimplify(x) if x.is_Float else x for x in u]
    k = max(range(3), key=lambda i: (abs(float(uu[i])), i))  # first moment along the axis
    l = max(range(3), key=lambda i: (-abs(float(uu[i])), i))  # the inertia entry to drop
    m = vec[0]
    h_u = vec[1 + k] / uu[k]
    c = vec[[4, 6, 9][l]] / (1 - uu[l] ** 2)  # XX, YY or ZZ
    U = sp.Matrix(uu)
    h = h_u * U
    I = c * (sp.eye(3) - U * U.T)
    left = [sp.expand(a - b) for a, b in zip(vec, _vector(m, h, I))]
    return {0, 1 + k, [4, 6, 9][l]}, (m, h, I), left


def _grouped(robot: Robot, reg: Regressor):
    """Khalil's general grouping rules from the leaves to the root. Returns the list of
    candidate (kept) standard-parameter indices and, for each, its grouped expression in
    the standard parameter symbols."""
    nlinks = len(robot.joints)
    vec = {j.child: list(reg.symbols[10 * i : 10 * i + 10]) for i, j in enumerate(robot.joints)}
    dropped = set()
    for i in reversed(range(nlinks)):
        joint = robot.joints[i]
        v = vec[joint.child]
        R, p = joint.transform(0)
        if joint.type == "revolute":
            gone, (m, h, I), left = _group_revolute(v, list(joint.axis))
        elif joint.type == "prismatic":
            gone, (m, h, I), left = {4, 5, 6, 7, 8, 9}, (sp.Integer(0), sp.zeros(3, 1), _tensor(v)), v[:4] + [0] * 6
        else:
            gone, (m, h, I), left = set(range(10)), (v[0], sp.Matrix(v[1:4]), _tensor(v)), [0] * 10
        vec[joint.child] = left
        dropped |= {10 * i + g for g in gone}
        if joint.parent != robot.base:
            mp, hp, Ip = moved_to_parent(m, list(h), rows(I), rows(R), list(p))
            add = _vector(mp, hp, sp.Matrix(Ip))
            vec[joint.parent] = [sp.expand(a + b) for a, b in zip(vec[joint.parent], add)]
    keep, exprs = [], []
    for i, joint in enumerate(robot.joints):
        for k in range(10):
            if 10 * i + k not in dropped:
                keep.append(10 * i + k)
                exprs.append(vec[joint.child][k])
    for c in range(10 * nlinks, len(reg.names)):  # joint terms are kept as they are
        keep.append(c)
        exprs.append(reg.symbols[c])
    return keep, exprs


def _symbolic_coefficients(Yk, d, pivots, Rs, geometry, robot, seed):
    """Column d of Yk as a combination of the pivot columns with coefficients that
    depend on the geometry (Khalil's special rules, e.g. a prismatic joint parallel to a
    revolute one): the columns involved are evaluated at random rational states with the
    geometry kept symbolic, and the small linear system solved exactly (rational
    functions of the geometry). Checked against the coefficients found at the two random
    geometries."""
    support = [r for r in range(len(pivots)) if any(R[r][d] != 0 for R in Rs)]
    cols = [pivots[r] for r in support] + [d]
    sub = Yk[:, cols]
    rng = random.Random(seed + 55)
    state = [s for s in angles_and_scalars(sub)[0] + angles_and_scalars(sub)[1] if s not in set(geometry)]
    rows = []
    for _ in range(len(support) // max(robot.dof, 1) + 3):
        values = {}
        for x in state:
            t = nonzero_fraction(rng)
            if any(x in (a.args[0],) for a in sub.atoms(sp.sin, sp.cos)):
                values[sp.sin(x)] = sp.Rational(2 * t.numerator * t.denominator, t.denominator**2 + t.numerator**2)
                values[sp.cos(x)] = sp.Rational(t.denominator**2 - t.numerator**2, t.denominator**2 + t.numerator**2)
            values[x] = sp.Rational(t.numerator, t.denominator)
        signs = {sp.sign(x): sp.sign(values[x]) for x in state if x in values}
        rows += [
            [sp.expand(sp.sympify(e).xreplace(signs).xreplace(values)) for e in sub.row(i)] for i in range(sub.rows)
        ]
    A = sp.Matrix([r[:-1] for r in rows])
    b = sp.Matrix([r[-1] for r in rows])
    # least squares normal equations are exact here: the system is consistent
    k_support = (A.T * A).LUsolve(A.T * b).applyfunc(sp.factor)
    k = [sp.Integer(0)] * len(pivots)
    for r, value in zip(support, k_support):
        k[r] = value
    # the same numbers as found at the random geometries
    for trial, R in enumerate(Rs):
        rng_g = random.Random(seed + 1)
        fixed = None
        for t in range(trial + 1):
            fixed = {s: nonzero_fraction(rng_g) for s in geometry}
        for r in range(len(pivots)):
            value = sp.sympify(k[r]).xreplace({s: sp.Rational(v.numerator, v.denominator) for s, v in fixed.items()})
            if value != sp.Rational(R[r][d].numerator, R[r][d].denominator):
                raise ArithmeticError("base_parameters: geometry-dependent grouping not confirmed")
    return k


def rationalized(robot: Robot) -> Robot:
    """A copy of ``robot`` whose geometry (joint placements, axes, gravity) has every
    Float replaced by the exact decimal it prints as (0.4318 -> 2159/5000). Products of
    lengths then stay exact (0.0825**2 in floating point is not (0.0825)^2), so the exact
    rank tests see the true dependencies. Inertial values are left as they are."""
    from dataclasses import replace as _replace

    def exact(m):
        return m.xreplace({f: sp.Rational(repr(float(f))) for f in m.atoms(sp.Float)})

    joints = [_replace(j, xyz=exact(j.xyz), rotation=exact(j.rotation), axis=exact(j.axis)) for j in robot.joints]
    import warnings

    with warnings.catch_warnings():  # the links were checked when the robot was built
        warnings.simplefilter("ignore")
        return Robot(
            robot.name,
            robot.links.values(),
            joints,
            exact(robot.gravity),
            robot.parameters,
            robot.meta,
            robot.base,
            robot.defaults,
            strict=robot.strict,
        )


def base_parameters(robot: Robot, seed: int = 0) -> BaseParameters:
    """The base parameters of ``robot`` (see the module docstring): exact, symbolic
    combinations of the standard parameters, for any tree of revolute, prismatic and
    fixed joints, with symbolic geometry. Decimal numbers of the geometry are taken as
    the exact decimals they are (:func:`rationalized`): ``base.regressor`` and ``base.Y``
    are those of that copy (equal to the robot's to the last bit of its floats).

    Raises ValueError if the set of identifiable parameters itself changes between two
    random geometries (not met on the bundled arms; bind the geometry then).
    """
    robot.require_fixed_base("armdyn.identification.base_parameters")
    robot.require_one_dof_joints("armdyn.identification.base_parameters")
    robot = rationalized(robot.canonical())  # parameters about the frames on the joints
    reg = regressor(robot)
    Y = reg.Y
    keep, exprs = _grouped(robot, reg)
    P = Y.shape[1]
    states = P // max(robot.dof, 1) + 3
    # exact rank tests on the kept columns at random rational points
    Yk = Y[:, keep] if keep else sp.zeros(robot.dof, 0)
    angles, scalars = angles_and_scalars(Y)
    state_syms = set(robot.q) | set(robot.qd) | set(robot.qdd)
    geometry = [s for s in angles + scalars if s not in state_syms]
    rng = random.Random(seed + 1)
    coefficient_sets = []
    for trial in range(2 if geometry else 1):
        fixed = {s: nonzero_fraction(rng) for s in geometry}
        rows = stacked_exact(Yk, states, seed + trial, fixed, PRIME)
        R, pivots = rref(rows, len(keep), PRIME)
        R = [[rational(x) for x in row] for row in R]
        coefficient_sets.append((R, pivots))
        # the dependencies, checked in exact rational arithmetic at a fresh random state
        check = stacked_exact(Yk, 1, seed + 100 + trial, fixed)
        for row in check:
            for d in range(len(keep)):
                if d not in pivots and row[d] != sum(R[r][d] * row[c] for r, c in enumerate(pivots)):
                    raise ArithmeticError(f"base_parameters: dependency of {reg.names[keep[d]]} not confirmed")
    R, pivots = coefficient_sets[0]
    if len(coefficient_sets) > 1 and coefficient_sets[1][1] != pivots:
        raise ValueError(
            "base_parameters: the identifiable set changes with the geometry at random values; "
            "bind the geometric parameters to numbers (robot.bind) and retry"
        )
    # dependent column d: Y_d = sum_r k[r] Y_pivot(r); its parameter joins those pivots
    beta = [exprs[c] for c in pivots]
    grouped = [exprs[c] != reg.symbols[keep[c]] for c in pivots]
    for d in range(len(keep)):
        if d in pivots:
            continue
        k = [sp.Rational(R[r][d].numerator, R[r][d].denominator) for r in range(len(pivots))]
        if len(coefficient_sets) > 1 and any(R[r][d] != coefficient_sets[1][0][r][d] for r in range(len(pivots))):
            k = _symbolic_coefficients(Yk, d, pivots, [coefficient_sets[t][0] for t in range(2)], geometry, robot, seed)
        for r in range(len(pivots)):
            if k[r] != 0:
                beta[r] = beta[r] + k[r] * exprs[d]
                grouped[r] = True
    names = [reg.names[keep[c]] + ("R" if g else "") for c, g in zip(pivots, grouped)]
    Yb = Y[:, [keep[c] for c in pivots]] if pivots else sp.zeros(robot.dof, 0)
    # a column that is not structurally zero can still vanish identically: test exactly
    rows = stacked_exact(Y, 3, seed + 7, None, PRIME)
    zero = [reg.names[c] for c in range(P) if all(row[c] == 0 for row in rows)]
    subs = dict(zip(reg.symbols, reg.pi))
    values = sp.Matrix([sp.sympify(b).xreplace(subs) for b in beta])
    return BaseParameters(Yb, sp.Matrix(beta), names, zero, values, reg, [keep[c] for c in pivots])


def with_symbolic_joint_terms(robot: Robot, terms=("armature", "damping", "friction")) -> Robot:
    """A copy of ``robot`` whose movable joints have the given terms as plain symbols
    ``IA<j>``, ``FV<j>``, ``FC<j>``, ``OFF<j>`` (j: the joint's child link frame number);
    handy to write the identification model with friction and rotor inertia."""
    prefix = dict(JOINT_TERMS)
    joints, params = [], dict(robot.parameters)
    for joint in robot.joints:
        if joint.movable:
            j = robot.link_index(joint.child)
            new = {}
            for attr in terms:
                s = sp.Symbol(f"{prefix[attr]}{j}")
                new[attr] = s
                params[s.name] = s
            joint = replace(joint, **new)
        joints.append(joint)
    return Robot(
        robot.name,
        robot.links.values(),
        joints,
        robot.gravity,
        params,
        robot.meta,
        robot.base,
        robot.defaults,
        strict=robot.strict,
    )


def symbolic_inertias(robot: Robot) -> Robot:
    """A copy of ``robot`` whose every link has fully symbolic inertial parameters: mass
    ``m<j>``, centre of mass ``(cx<j>, cy<j>, cz<j>)`` and the six entries of the tensor
    about the centre of mass ``Ixx<j>``, ... (the benchmark's "all 60 parameters symbolic")."""
    from .model import Link

    links, params = [], dict(robot.parameters)
    for name, link in robot.links.items():
        if name == robot.base:
            links.append(link)
            continue
        j = robot.link_index(name)
        s = {k: sp.Symbol(f"{k}{j}") for k in ("m", "cx", "cy", "cz", "Ixx", "Ixy", "Iyy", "Ixz", "Iyz", "Izz")}
        params.update({v.name: v for v in s.values()})
        I = sp.Matrix([[s["Ixx"], s["Ixy"], s["Ixz"]], [s["Ixy"], s["Iyy"], s["Iyz"]], [s["Ixz"], s["Iyz"], s["Izz"]]])
        links.append(Link(name, s["m"], sp.Matrix([s["cx"], s["cy"], s["cz"]]), I))
    defaults = {k: v for k, v in robot.defaults.items()}
    return Robot(
        robot.name, links, robot.joints, robot.gravity, params, robot.meta, robot.base, defaults, strict=robot.strict
    )


__all__ = [
    "Regressor",
    "BaseParameters",
    "regressor",
    "base_parameters",
    "standard_parameters",
    "exact_rank",
    "stacked_exact",
    "with_symbolic_joint_terms",
    "symbolic_inertias",
    "rationalized",
    "INERTIAL",
]
