"""The terms of one link in the customized Newton-Euler recursion, shortened.

``U = skew(wd) + skew(w)^2`` (Khalil eq. 9.79) is formed once per link and serves both
the link's own force and its children's accelerations. Its entries, and the Euler
moment ``J wd + w x (J w)``, are built from named products of the angular velocity
(:func:`squares`), with two shortcuts of a child whose z axis is a parent axis ``+-e_k``
(every DH frame, :func:`axis_in_parent`):

* the invariant ``wx^2 + wy^2`` is read off the parent's U (:func:`parent_invariant`), so
  ``wy^2`` is never formed;
* the last column of U above the diagonal is the parent's column k turned by the joint
  (:func:`column_from_parent`).

All vectors are lists of 3 SymPy expressions, matrices lists of rows (link axes);
temporaries are named through the program's :class:`~armdyn.programs.program.Builder`.
"""

from __future__ import annotations

from ..model import Robot
from .parallel_joints import about_z
from .program import Builder, is_value
from .vectors import minus, plus, times


def squares(b: Builder, w, tag, S=None) -> dict:
    """The products of w's components that U and the Euler moment use (named once):
    ``xy, xz, yz``, the diagonal of ``skew(w)^2`` (``U11 = -wy^2 - wz^2``, ``U22``,
    ``U33``) and the differences ``d0 = wy^2 - wz^2, d1 = wz^2 - wx^2, d2 = wx^2 - wy^2``.

    S: ``-(wx^2 + wy^2)`` when it is already known from the parent (see
    :func:`parent_invariant`): a rotation about the joint axis z leaves ``wx^2 + wy^2``
    unchanged, so ``wy^2`` is not needed (one multiplication less per link)::

        U22 = -wx^2 - wz^2,  d1 = wz^2 - wx^2,  U33 = S,  U11 = S - d1,  d0 = U22 - S,
        d2 = -d0 - d1

    (``d2`` from the other two differences, not from ``U11``: a link that needs no
    ``U11`` does not pay for it; never more operations than without ``S``, given ``S``.)
    """
    w1, w2, w3 = w
    xx, zz = b.let(w1 * w1, f"w{tag}xx"), b.let(w3 * w3, f"w{tag}zz")
    out = {"xy": b.let(w1 * w2, f"w{tag}xy"), "xz": b.let(w1 * w3, f"w{tag}xz"), "yz": b.let(w2 * w3, f"w{tag}yz")}
    if S is None:
        yy = b.let(w2 * w2, f"w{tag}yy")
        out.update(
            U11=b.let(-yy - zz, f"U{tag}_11"),
            U22=b.let(-xx - zz, f"U{tag}_22"),
            U33=b.let(-xx - yy, f"U{tag}_33"),
            d0=b.let(yy - zz, f"w{tag}_yy_zz"),
            d1=b.let(zz - xx, f"w{tag}_zz_xx"),
            d2=b.let(xx - yy, f"w{tag}_xx_yy"),
        )
    else:
        U22, d1 = b.let(-xx - zz, f"U{tag}_22"), b.let(zz - xx, f"w{tag}_zz_xx")
        U11 = b.let(S - d1, f"U{tag}_11")
        out_d0 = b.let(U22 - S, f"w{tag}_yy_zz")
        out.update(U11=U11, U22=U22, U33=S, d0=out_d0, d1=d1, d2=b.let(-out_d0 - d1, f"w{tag}_xx_yy"))
    return out


def axis_in_parent(joint, R):
    """``(k, sign)`` when the joint moves about or along its child's z axis and that axis
    is the parent's ``sign e_k`` (``R e_z = sign e_k``, as in every DH frame), else None."""
    axis = joint.axis
    if joint.type not in ("revolute", "prismatic") or not (
        is_value(axis[0], 0) and is_value(axis[1], 0) and is_value(abs(axis[2]), 1)
    ):
        return None
    col = [R[i][2] for i in range(3)]
    hits = [i for i, e in enumerate(col) if not is_value(e, 0)]
    if len(hits) != 1 or not is_value(abs(col[hits[0]]), 1):
        return None
    return hits[0], 1 if float(col[hits[0]]) > 0 else -1


def parent_invariant(joint, R, U_parent):
    """``-(wx^2 + wy^2)`` of the child's angular velocity, read off the parent's U, or
    None. When the joint moves about (or along) the child's z axis and that axis is a
    parent axis ``+-e_k`` (:func:`axis_in_parent`), the child's x and y components are
    the parent's other two components rotated about it, so
    ``wx^2 + wy^2 = sum_{i != k} wp_i^2 = -U_parent[k, k]`` (the norm is unchanged by a
    rotation; the parent's U diagonal holds these sums)."""
    found = axis_in_parent(joint, R)
    return None if found is None else U_parent[found[0]][found[0]]


def skew2(b: Builder, w, wd, tag, sq: dict, column=None, lower=None) -> list:
    """U = skew(wd) + skew(w) skew(w) (3x3 rows), Khalil eq. 9.79, from the named
    products ``sq`` of :func:`squares`; ``column``: ``(U13, U23)`` when already known
    (:func:`column_from_parent`); ``lower``: ``(U31, U32)`` where known otherwise
    (:func:`armdyn.programs.two_rate_link.lower_column`; None entries: the generic ones)."""
    xy, xz, yz = sq["xy"], sq["xz"], sq["yz"]
    U13, U23 = column if column is not None else (plus(xz, wd[1]), minus(yz, wd[0]))
    U31, U32 = lower if lower is not None else (None, None)
    U = [
        [sq["U11"], minus(xy, wd[2]), U13],
        [plus(xy, wd[2]), sq["U22"], U23],
        [minus(xz, wd[1]) if U31 is None else U31, plus(yz, wd[0]) if U32 is None else U32, sq["U33"]],
    ]
    return [[b.let(U[r][s], f"U{tag}_{r + 1}{s + 1}") for s in range(3)] for r in range(3)]


def column_from_parent(joint, R, U_parent):
    """``(U13, U23)`` of a revolute child, from its parent's U, or None.

    With ``wi = R^T w_p`` and the joint rate ``qd`` about z, the child's
    ``U = skew(wd) + skew(w)^2`` is the parent's seen in the child frame plus terms of
    the joint's own motion::

        U = R^T U_p R + qdd skew(z) + 2 qd z wi^T - (2 qd wi_z + qd^2) (1 - z z^T)

    (expand ``skew(wi + qd z)^2`` and ``skew(R^T wd_p + qdd z + qd wi x z)``; the
    ``qd wi z^T`` parts of the two cancel). Its last column above the diagonal has no
    such term: ``(U13, U23)`` are the first two entries of ``R^T U_p R z = +-R^T U_p[:, k]``
    when ``R z = +-e_k``, a rotation of two entries of the parent's column k (4 products,
    2 sums) instead of ``R^T wd_p`` and ``qd (wi_y, -wi_x)`` (6 products, 4 sums); the
    child's ``wd_x = w_y w_z - U23`` and ``wd_y = U13 - w_x w_z`` then follow with one
    sum each."""
    found = axis_in_parent(joint, R)
    if found is None or joint.type != "revolute" or not about_z(joint):
        return None
    k, sign = found
    return tuple(plus(*[times(R[m][i] if sign > 0 else -R[m][i], U_parent[m][k]) for m in range(3)]) for i in range(2))


def euler_moment(J, differences, wd, U, sq) -> list:
    """J wd + w x (J w) (3,) for a symmetric J (3x3 rows), as linear in J's six entries,
    with the coefficients taken from U (whose off-diagonal entries are wd_k +- w_i w_j)
    and the squares of w::

        x: XX wdx + XY (wdy - wx wz) + XZ (wdz + wx wy) + YZ (wy^2 - wz^2) + (ZZ - YY) wy wz
        y: XY (wdx + wy wz) + YY wdy + YZ (wdz - wx wy) + XZ (wz^2 - wx^2) + (XX - ZZ) wx wz
        z: XZ (wdx - wy wz) + YZ (wdy + wx wz) + ZZ wdz + XY (wx^2 - wy^2) + (YY - XX) wx wy

    (15 products instead of the 24 of J wd, J w and the cross product). ``differences``
    are (ZZ - YY, XX - ZZ, YY - XX), parameters of their own (:func:`moment_differences`)."""
    (XX, XY, XZ), (_, YY, YZ), (_, _, ZZ) = J
    ZZ_YY, XX_ZZ, YY_XX = differences
    wxy, wxz, wyz = sq["xy"], sq["xz"], sq["yz"]
    d = [sq["d0"], sq["d1"], sq["d2"]]
    return [
        plus(times(XX, wd[0]), -times(XY, U[2][0]), times(XZ, U[1][0]), times(YZ, d[0]), times(ZZ_YY, wyz)),
        plus(times(XY, U[2][1]), times(YY, wd[1]), -times(YZ, U[0][1]), times(XZ, d[1]), times(XX_ZZ, wxz)),
        plus(-times(XZ, U[1][2]), times(YZ, U[0][2]), times(ZZ, wd[2]), times(XY, d[2]), times(YY_XX, wxy)),
    ]


def children_need_wd(robot: Robot, name, frames) -> set:
    """The components of link ``name``'s angular acceleration its children read: ``k``
    for a revolute child about the link's ``+-e_k`` (only its ``wd_z`` takes it), all
    three for any other child."""
    out = set()
    for child in robot.children(name):
        found = axis_in_parent(child, frames[child.child][0])
        out |= {found[0]} if found is not None and child.type == "revolute" else {0, 1, 2}
    return out
