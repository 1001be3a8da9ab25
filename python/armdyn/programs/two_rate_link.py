"""Closed forms for the second link of an arm whose first joint turns about the base's
fixed axis (the PUMA 560's link 2, and most arms' shoulder link).

The first joint ``R`` (base-fixed, revolute about its frame's z) gives its link
``w_R = (0, 0, a)``, ``wd_R = (0, 0, a')``. The second link ``L`` turns about its own z,
perpendicular to R's axis. With ``u = R_L^T z_R`` (R's axis in L's frame, a unit vector
in L's xy plane that turns with ``q_L``; ``u = (-s2, -c2, 0)`` on the PUMA) and
``v = u x e3``, L's angular velocity and acceleration are two joint rates on two axes::

    w = a u + b e3,    wd = a' u + b' e3 + a b v                  (a = qd_R, b = qd_L)

**Two projections of the moment.** Of L's moment only ``e3 . n_L`` (L's torque) and
``u . n_L`` (R's torque: ``z_R . R_L n_L``; the base carries the rest) are ever used. For
L's Euler moment ``E = J wd + w x (J w)`` (J about L's origin, L's axes), with
``A = u^T J u``, ``B = u^T J e3``, ``C = u^T J v``, ``D = e3^T J v``::

    u . E  = a' A + b' B + 2 a b C + b^2 D
    e3 . E = a' B + b' J33 - a^2 C

(``u . (w x J w) = J w . (u x w) = b J w . v`` and ``e3 x w = -a v``). ``A`` and ``C`` are
J's xy block seen along u; with Khalil's grouping (``YY = 0``) they take 9 operations, B
and D 6, where forming E's x and y components and the coefficients only they use takes
about 25 (:func:`euler_projections`). L's own rates enter together as
``W = b' u + b^2 v``: ``b' B + b^2 D = (J e3) . W``, and a point's acceleration below
uses W too.

**Gravity on the first moment.** When the root's acceleration is ``(0, 0, gz)`` in its
frame (gravity along the base axis), L's origin accelerates by ``gz u``, and L's
``MS x vd = (gz MS) x u``: ``gz MS`` is a parameter, computed once per parameter set
(:func:`gravity_moment`).

**A point of L.** A point ``p`` fixed in L (L's axes, from its origin) accelerates, in
the basis ``(u, v, e3)``, by (``p_u = u . p``, ``p_v = v . p``)::

    U_L p = (b' p_v - b^2 p_u) u + (a' p_z - b' p_u - (a^2 + b^2) p_v) v
            + (2 a b p_u - a' p_v - a^2 p_z) e3
          = (p . (W_y, -W_x)) u + (a' p_z - p . W - a^2 p_v) v + (2 a b p_u - a' p_v - a^2 p_z) e3

(from ``U_L p = wd x p + w (w . p) - |w|^2 p`` and ``u x v = -e3``, ``e3 x u = -v``,
``v x e3 = -u``). A child that continues a run of parallel joints from R sees u and v
turned by the compound angle, so its acceleration needs neither L's U nor a rotation
by ``q_L`` (:func:`point_acceleration`).

**Further along the run.** A link that continues a run of parallel joints from L (the
PUMA's link 3) turns the same way, ``w = a u + b e3`` with its own ``u`` (R's axis turned
by the compound angle) and ``b`` the run's summed rates, and its moment's x and y
components reach only R's torque, by that compound rotation: the same two projections
apply (:func:`run_link`), the ``A`` of every such link summed before one product with
``a'``; its U's lower row then also comes from its last column (:func:`lower_column`).

All vectors are lists of 3 SymPy expressions; named temporaries go through the
customized program's :class:`~armdyn.programs.program.Builder`.
"""

from __future__ import annotations

from dataclasses import dataclass

import sympy as sp

from .program import Builder, is_value
from .vectors import ZERO, cross, dot, minus, mtv, plus, rows, times, vadd


@dataclass
class TwoRateLink:
    """L's motion as two rates on two axes (module docstring).

    root: R's link; u, v (3,): R's axis and ``u x e3`` in L's frame (``u[2] = v[2] = 0``);
    a, ad: R's joint rate and acceleration; b, bd: L's; aa, bb, ab2: ``a^2``, ``b^2``,
    ``2 a b`` (named); W (2,): ``b' u + b^2 v`` in L's xy plane (named; L's own rates on
    the two in-plane axes, used by the moment's projection on u and by a point's
    acceleration, both only with ``gz``; None without it); gz: the root's acceleration
    along its axis (``g``) when that is all of it, else None."""

    root: str
    u: list
    v: list
    a: sp.Expr
    ad: sp.Expr
    b: sp.Expr
    bd: sp.Expr
    aa: sp.Expr
    bb: sp.Expr
    ab2: sp.Expr
    W: list | None
    gz: sp.Expr | None


def second_link(builder: Builder, joint, R, root_joint, w_root, wd_root, origin, qd, qdd, tag) -> TwoRateLink | None:
    """The closed-form description of ``joint``'s child, or None when it is not a second
    link: ``joint`` revolute about its frame's +z (frame ``R`` in the parent's, 3x3 rows),
    its parent ``root_joint``'s child, fixed to the base by a revolute joint about +z
    (``w_root = (0, 0, a)``, ``wd_root = (0, 0, a')``), the two axes perpendicular.
    ``qd``, ``qdd``: L's joint rate and acceleration; ``origin``: the acceleration of L's
    origin in the root's axes (3,), gravity included (``gz`` when it lies on the root's
    axis: L's origin on that axis, gravity along it)."""
    if root_joint is None or joint.type != "revolute" or root_joint.type != "revolute":
        return None
    gz = origin[2] if is_value(origin[0], 0) and is_value(origin[1], 0) else None
    return _two_rates(builder, root_joint, R, w_root, wd_root, qd, qdd, tag, gz)


def run_link(builder: Builder, root_joint, w_root, wd_root, Ra, w, wd, tag) -> TwoRateLink | None:
    """The same description for a link further along a run of parallel joints that starts
    at the second link (the PUMA's link 3: ``w3 = qd1 u3 + (qd2 + qd3) e3``), or None.
    ``Ra`` (3x3 rows): the link's frame in the root's (the run's compound rotation), so
    ``u = Ra^T z_R``; ``w``, ``wd`` (3,): the link's own, whose z components are its ``b``,
    ``b'``. No gravity term (its origin is not on the root's axis)."""
    return _two_rates(builder, root_joint, Ra, w_root, wd_root, w[2], wd[2], tag, None)


def root_axes(R) -> tuple | None:
    """``(u, v)`` (3,) each: the root's axis ``u = R^T z_R`` in the frame ``R`` (3x3 rows,
    that frame in the root's) and ``v = u x e3``; None when u has a z part (the frame's z
    axis not perpendicular to the root's)."""
    u = mtv(R, [ZERO, ZERO, sp.S.One])
    if not is_value(u[2], 0):
        return None
    return [u[0], u[1], ZERO], [u[1], -u[0], ZERO]


def _two_rates(builder: Builder, root_joint, R, w_root, wd_root, b, bd, tag, gz) -> TwoRateLink | None:
    """A link turning as ``w = a u + b e3`` on a base-fixed root (``w_root = (0, 0, a)``):
    its :class:`TwoRateLink`, with ``u = R^T z_R`` (``R``: its frame in the root's), or
    None when u has a z part (its axis not perpendicular to the root's) or the root moves
    otherwise."""
    axes = root_axes(R)
    if axes is None or not all(is_value(x, 0) for x in (*w_root[:2], *wd_root[:2])):
        return None
    (u, v), a, ad = axes, w_root[2], wd_root[2]
    bb = builder.let(times(b, b), f"w{tag}bb")
    W = (
        None
        if gz is None
        else [builder.let(plus(times(bd, u[i]), times(bb, v[i])), f"W{tag}{'xy'[i]}") for i in range(2)]
    )
    return TwoRateLink(
        root_joint.child,
        u,
        v,
        a,
        ad,
        b,
        bd,
        builder.let(times(a, a), f"w{tag}aa"),
        bb,
        builder.let(times(2, times(a, b)), f"w{tag}ab2"),
        W,
        gz,
    )


def lower_column(s: TwoRateLink, column) -> tuple:
    """``(U31, U32)`` of the link's ``U = skew(wd) + skew(w)^2`` from its last column
    ``(U13, U23)``: ``U31 = -U13 + 2 a b u1``, ``U32 = -U23 + 2 a b u2`` (``U13 = a' u2``,
    ``U23 = -a' u1``, and ``w x (w x .)`` adds ``a b (u_i e3 + e3 u_i)``). Where the Euler
    moment's x and y components are not formed, ``w_y w_z`` and ``wd_x`` (or ``w_x w_z``
    and ``wd_y``) are needed for nothing else than the generic ``U32 = w_y w_z + wd_x``:
    one operation less, if no child needs ``wd_x``."""
    return minus(times(s.ab2, s.u[0]), column[0]), minus(times(s.ab2, s.u[1]), column[1])


def euler_projections(b: Builder, J, s: TwoRateLink, tag: str, root_J33=ZERO, gravity=None) -> tuple:
    """``(A, rest, e3 . E)`` of L's Euler moment ``E = J wd + w x (J w)`` (module
    docstring), J (3x3 rows) about L's origin in L's axes: ``u . E = a' A + rest``, A
    unnamed, so that the caller adds the A of every link on the same root before one
    product with ``a'``.

    root_J33: the root link's inertia about its axis; its own Euler moment on that axis,
    ``J33_R a'``, is added inside ``A`` (one product less).
    gravity: None, or ``(gz MX, gz MY)`` (:func:`gravity_moment`) when a child's
    acceleration uses ``W`` too (:func:`point_acceleration`): then the terms of L's own
    rates are taken together, ``b' B + b^2 D = (J e3) . W``, and L's ``((gz MS) x u)_z``
    joins the second projection with ``a' B``, ``u1 (a' J13 - gz MY) + u2 (a' J23 + gz
    MX)``, so that neither B nor D is formed (one operation less than with them; without
    a child sharing W, three more)."""
    (J00, J01, J02), (_, J11, J12), (_, _, J22) = J
    u1, u2 = s.u[0], s.u[1]
    t = b.let(times(J01, u2), f"J{tag}_xy_u")
    Ju1 = b.let(plus(times(J00, u1), t), f"J{tag}_u_x")  # (J u)_x
    Ju2 = b.let(plus(times(J01, u1), times(J11, u2)), f"J{tag}_u_y")
    # u^T J u = u1 (J u)_x + u2 (J u)_y; with YY = 0 (J11), u2 (J u)_y = u1 (J01 u2) = u1 t
    if is_value(J11, 0):
        A = plus(root_J33, times(u1, plus(Ju1, t)))
    else:
        A = plus(root_J33, times(u1, Ju1), times(u2, Ju2))
    C = b.let(minus(times(u2, Ju1), times(u1, Ju2)), f"C{tag}")  # v . J u, v = (u2, -u1, 0)
    if gravity is None:
        B = b.let(plus(times(J02, u1), times(J12, u2)), f"B{tag}")  # (J e3) . u
        D = b.let(minus(times(J02, u2), times(J12, u1)), f"D{tag}")  # (J e3) . v
        rest = plus(times(s.bd, B), times(s.ab2, C), times(s.bb, D))
        along_z = plus(times(s.ad, B), times(s.bd, J22), -times(s.aa, C))
    else:
        rest = plus(times(s.ab2, C), times(J02, s.W[0]), times(J12, s.W[1]))
        along_z = plus(
            times(u1, minus(times(s.ad, J02), gravity[1])),
            times(u2, plus(times(s.ad, J12), gravity[0])),
            times(s.bd, J22),
            -times(s.aa, C),
        )
    return A, rest, along_z


def gravity_moment(b: Builder, MS, s: TwoRateLink, tag: str) -> tuple[list, list]:
    """``gz MS`` (3,) for L's ``MS x vd = (gz MS) x u`` when its origin accelerates by
    ``gz u`` (``s.gz`` not None): new parameters where it is not a number (named ``gMX2``
    after the first moment's symbol; the builder keeps the names unique), and their
    definitions ``[(Symbol, gz MS_k)]``."""
    gMS, new = [], []
    for k, m in enumerate(MS):
        value = times(s.gz, m)
        if value.is_Number:
            gMS.append(value)
            continue
        sym = b.name(f"g{m}" if m.is_Symbol else f"gM{'XYZ'[k]}{tag}")
        new.append((sym, value))
        gMS.append(sym)
    return gMS, new


def point_acceleration(b: Builder, s: TwoRateLink, p, tag: str) -> tuple:
    """``(A_u, A_v, A_z)``: the acceleration of the point ``p`` (3,) of L (L's axes, from
    its origin), gravity included, in the basis ``(u, v, e3)`` (module docstring); needs
    ``s.gz`` (L's origin then accelerates by ``gz u``)."""
    pu = b.let(dot(s.u, p), f"p{tag}_u")
    pv = b.let(dot(s.v, p), f"p{tag}_v")
    pz = p[2]
    # L's own rates: b' p_v - b^2 p_u = p . (W_y, -W_x), b' p_u + b^2 p_v = p . W
    A_u = plus(times(p[0], s.W[1]), -times(p[1], s.W[0]), s.gz)
    A_v = plus(times(s.ad, pz), -times(p[0], s.W[0]), -times(p[1], s.W[1]), -times(s.aa, pv))
    A_z = plus(times(s.ab2, pu), -times(s.ad, pv), -times(s.aa, pz))
    # named: each is used twice, turned into the child's x and y
    return b.let(A_u, f"a{tag}_u"), b.let(A_v, f"a{tag}_v"), A_z


def in_frame(A, u, v) -> list:
    """``A_u u + A_v v + A_z e3`` (3,) for components ``A`` in the basis ``(u, v, e3)``
    given in some frame (u, v with no z part)."""
    return [plus(times(A[0], u[0]), times(A[1], v[0])), plus(times(A[0], u[1]), times(A[1], v[1])), A[2]]


def second_link_moment(b: Builder, s: TwoRateLink, MS, vd, tag: str, root, root_J) -> tuple:
    """A second link's moment without its Euler part (only its projections are used,
    :func:`euler_projections`): ``(MS x vd (3,), gMS, J33_R, definitions)``.

    ``MS x vd`` is ``(g MS) x u`` when gravity is all of the root's acceleration; ``gMS``
    (3,) is then ``g MS`` (new parameters, whose definitions are returned), else None.
    J33_R: the root's inertia about its axis (``root_J``: the root's J, 3x3), taken out
    of the root's moment (``root``: the root link's state, whose ``euler_and_ms`` and
    ``N`` this rewrites; its Euler moment on its axis is ``J33_R a'``, added inside the
    second link's ``A`` instead), or 0 when another second link took it already or the
    root's moment is not that."""
    gMS, new = None, []
    if s.gz is not None:
        gMS, new = gravity_moment(b, MS, s, tag)
        ms = cross(gMS, s.u)
    else:
        ms = cross(MS, vd)
    root_J33 = ZERO
    if root.euler_and_ms is not None:
        (euler, root_ms), root.euler_and_ms = root.euler_and_ms, None
        J33 = rows(root_J)[2][2]
        if euler[2] == times(J33, s.ad):
            root_J33 = J33
            root.N = b.vector(vadd([euler[0], euler[1], ZERO], root_ms), f"N{root.tag}")
    return ms, gMS, root_J33, new
