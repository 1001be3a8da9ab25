"""Where the masses are, from an energy-method derivation: the mass centres' positions as
functions of q (``p_{c2} = l_1(\\cos q_1, \\sin q_1) + ...``, ``x_{c2} = l_1 c_1 + l_{c2} c_{12}``)
or their velocity Jacobians (Spong's ``J_{v_{ck}}``, integrated joint by joint and checked),
or, failing those, the heights in the potential energy ``V = m_1 g h_1 + ...``: for a planar
arm turning about z with gravity in its plane, the height ``a sin(phi) + b cos(phi)`` is the
point ``Rz(phi) (a, b)``. Positions and V stated both are checked against each other, and
against the arm's own geometry: a uniform link with its centre halfway along it (``l_2/2``)
ends at ``l_2``, so every later link hangs from that end (:func:`uniform_links`).
"""

from __future__ import annotations

import re

import sympy as sp

from .geometry import across, rz, same, vector
from .statements import POINT


def _stated(statements, q: list, conflicts: list, choices: dict | None = None) -> dict:
    """Link k -> (position in the base frame, None, statement) from p_{ck}, x_{ck}, y_{ck}, z_{ck}."""
    n = len(q)
    found: dict[int, tuple] = {}
    parts: dict[int, dict] = {}
    centres = {st.index for st in statements if st.what in ("C", "Cx", "Cy", "Cz") and st.frame == 0}
    for st in statements:
        k = st.index
        if st.what not in ("C", "Cx", "Cy", "Cz") or k is None or not 1 <= k <= n:
            continue
        if st.frame == POINT and k in centres:
            continue  # x_k beside x_{ck}: the mass centre is the one named so
        if st.what == "C":
            pos = vector(st.value)
            if pos is None:
                continue
            if k in found:
                if not same(found[k][0], pos, pos.free_symbols | found[k][0].free_symbols):
                    conflicts.append(
                        f"lines {found[k][2].line} and {st.line} place link {k}'s mass centre differently "
                        f"(line {found[k][2].line} used)"
                    )
                continue
            found[k] = (pos, None, st)
        elif not isinstance(st.value, sp.MatrixBase):
            parts.setdefault(k, {}).setdefault("xyz".index(st.what[1]), (st.value, st))
    for k, comps in parts.items():
        if k in found:
            continue
        first = min((s for _, s in comps.values()), key=lambda s: s.line)
        found[k] = (sp.Matrix([comps[i][0] if i in comps else 0 for i in range(3)]), None, first)
    _planar_pairs(found, parts, q, conflicts, choices if choices is not None else {})
    for st in statements:  # positions stated win; else the position whose Jacobian is stated
        k = st.index
        if st.what == "CJ" and k is not None and 1 <= k <= n and k not in found:
            pos = _integrated(st.value, q)
            if pos is None:
                conflicts.append(f"line {st.line}: J_v{k} is not the Jacobian of one position (not used)")
            else:
                found[k] = (pos, None, st)
    return found


def _planar_pairs(found: dict, parts: dict, q: list, conflicts: list, choices: dict) -> None:
    """A planar point turning about z has ``x = a cos(phi) - b sin(phi)`` and ``y = a sin(phi) +
    b cos(phi)``: each coordinate alone gives the other. When the two stated disagree (a slip in
    one), the reading that keeps the arm serial with its neighbours is used, named.
    ``choices``: link k -> True to take the other one (a reading kept as an alternative: the
    grading keeps the one the text's steps agree with); each link decided is added (False)."""
    turning = {x for v in found.values() for f in v[0].atoms(sp.sin, sp.cos) for x in f.free_symbols} & set(q)
    for k, comps in sorted(parts.items()):
        if 0 not in comps or 1 not in comps or found[k][2] not in (comps[0][1], comps[1][1]):
            continue
        x, y = comps[0][0], comps[1][0]
        try:
            from_x, from_y = -across(x, turning), across(y, turning)
        except ValueError:
            continue
        symbols = x.free_symbols | y.free_symbols
        if same(from_y, x, symbols):
            continue
        z = found[k][0][2]
        options = [
            (sp.Matrix([x, from_x, z]), f"x_{k}", comps[0][1]),
            (sp.Matrix([from_y, y, z]), f"y_{k}", comps[1][1]),
        ]
        scores = [_serial_score(found, k, p, q, turning) for p, _, _ in options]
        best = max(range(2), key=lambda j: (scores[j], -options[j][2].line))
        flipped = choices.setdefault(k, False)
        best = 1 - best if flipped else best
        pos, name, st = options[best]
        other = options[1 - best]
        why = (
            "the other reading, kept for the text's steps to decide"
            if flipped
            else "it keeps the arm serial, a mass at the next joint"
            if scores[best] > scores[1 - best]
            else "the first written"
        )
        conflicts.append(
            f"lines {comps[0][1].line} and {comps[1][1].line}: x_{k} and y_{k} are not one point turning in the "
            f"plane ({name} used: {why}; {other[1]} disagrees)"
        )
        found[k] = (pos, None, st)


def _serial_score(found: dict, k: int, p, q: list, turning: set) -> int:
    """How many neighbours of link k's point ``p`` hang from it as a serial arm's do: the step to
    the next point, seen in the earlier link's frame, moves only with the later joints."""
    score = 0
    for a, b, pa, pb in ((k - 1, k, found.get(k - 1, (None,))[0], p), (k, k + 1, p, found.get(k + 1, (None,))[0])):
        if pa is None or pb is None or a < 1:
            continue
        phi = sum((x for x in q[:a] if x in turning), sp.Integer(0))
        c, s_ = sp.cos(phi), sp.sin(phi)
        back = sp.Matrix([[c, s_, 0], [-s_, c, 0], [0, 0, 1]]) * (pb - pa)
        earlier = q[:a]
        if all(same(back.diff(x), sp.zeros(3, 1), back.free_symbols) for x in earlier):
            score += 2
    after = found.get(k + 1, (None,))[0]
    if after is not None and k < len(q):  # a point mass at the next joint, as a double pendulum's
        joint = after.applyfunc(
            lambda e: sum((t for t in sp.Add.make_args(sp.expand(e)) if q[k] not in t.free_symbols), sp.Integer(0))
        )
        score += same(joint, p, joint.free_symbols | p.free_symbols)
    return score


def _integrated(J, q: list):
    """The position p(q) (up to a constant) whose Jacobian dp/dq is ``J`` (3 x n, a column
    per joint), or None when no position has it (checked at random values)."""
    if not isinstance(J, sp.MatrixBase) or J.shape[0] not in (2, 3) or J.shape[1] > len(q):
        return None
    J = J if J.shape[0] == 3 else J.col_join(sp.zeros(1, J.shape[1]))
    p = sp.zeros(3, 1)
    for j in range(J.shape[1]):  # each column's part that the earlier joints' did not give
        rest = (J[:, j] - p.diff(q[j])).applyfunc(sp.expand)
        p += rest.applyfunc(lambda e, x=q[j]: sp.integrate(e, x))
    p = p.applyfunc(sp.expand)
    symbols = p.free_symbols | J.free_symbols
    for j in range(len(q)):
        column = J[:, j] if j < J.shape[1] else sp.zeros(3, 1)
        if not same(p.diff(q[j]), column, symbols):
            return None
    return p


def mass_centres(
    statements, gravity, q: list, revolute: set, free: set, conflicts: list, choices: dict | None = None
) -> dict:
    """Link k's mass centre in the base frame -> (position, mass symbol or None, statement)."""
    n = len(q)
    found = _stated(statements, q, conflicts, choices)
    for st in statements:
        if st.what not in ("V", "Vl") or isinstance(st.value, sp.MatrixBase):  # V, or one link's V_k
            continue
        axis = [i for i in range(3) if gravity[i] != 0]
        if len(axis) != 1 or axis[0] == 2:
            if not found:
                conflicts.append(f"line {st.line}: V read only for gravity along x0 or y0 (not used)")
            continue
        c = gravity[axis[0]]
        sign = 1 if sp.N(c.subs({x: 1 for x in c.free_symbols})) > 0 else -1
        g_mag = sign * c  # the magnitude, the parameters taken positive
        up = sp.zeros(3, 1)
        up[axis[0]] = -sign
        side = up.cross(sp.Matrix([0, 0, 1]))
        V = sp.expand(st.value)
        masses = sorted((s for s in V.free_symbols if re.fullmatch(r"m(\d+)", s.name)), key=lambda s: int(s.name[1:]))
        in_trig = {s for f in V.atoms(sp.sin, sp.cos) for s in f.free_symbols}
        all_rev = (in_trig & set(q)) | revolute
        for m in masses:
            k = int(m.name[1:])
            height = sp.expand(V.coeff(m) / g_mag)
            if k < 1 or k > n or height.has(m):
                continue
            if k in found:  # stated: V must give its height
                if not same(up.dot(found[k][0]), height, free):
                    conflicts.append(
                        f"line {st.line} (V) and line {found[k][2].line} place link {k}'s mass centre at different "
                        f"heights (line {found[k][2].line} used)"
                    )
                continue
            turning = height.atoms(sp.sin, sp.cos)
            fixed = sum((t for t in sp.Add.make_args(height) if not (t.free_symbols & set(q))), sp.Integer(0))
            if turning and fixed != 0:  # a constant in a turning link's height: V's zero, not a place
                height = sp.expand(height - fixed)
                conflicts.append(
                    f"line {st.line}: the constant {fixed} in the height of m{k} read as where V is zero "
                    "(a point turning with its link has none)"
                )
            try:
                w = across(height, all_rev)
            except ValueError as err:
                conflicts.append(f"line {st.line}: the height of m{k} is not a planar arm's ({err})")
                continue
            found[k] = (up * height + side * w, m, st)
        rest = sp.expand(
            V - sum(m * g_mag * (up.dot(found[int(m.name[1:])][0])) for m in masses if int(m.name[1:]) in found)
        )
        rest = sum((t for t in sp.Add.make_args(rest) if t.free_symbols & set(q)), sp.Integer(0))  # V's zero aside
        if rest != 0 and found and not same(rest, sp.Integer(0), free):
            conflicts.append(f"line {st.line}: V has a term not of one mass's height: {rest}")
    uniform_links(found, q, revolute, conflicts)
    return found


def _along(p: sp.Matrix, phi) -> tuple | None:
    """The constant ``(a, b)`` with ``Rz(phi) (a, b)`` the part of the planar point ``p`` that
    turns with the angle ``phi`` (None when that part is not such a rotation)."""
    x, y = sp.expand(p[0]), sp.expand(p[1])
    c, s = sp.cos(phi), sp.sin(phi)
    a, b = x.coeff(c), -x.coeff(s)
    if (a, b) == (0, 0):
        return (0, 0) if y.coeff(c) == 0 and y.coeff(s) == 0 else None
    if sp.expand(y.coeff(s) - a) != 0 or sp.expand(y.coeff(c) - b) != 0:
        return None
    return a, b


def uniform_links(found: dict, q: list, revolute: set, conflicts: list) -> None:
    """A planar arm of uniform links: link k's centre at ``S/2`` along it (``S`` one symbol,
    its length) puts joint k+1, and so every later link, at ``S`` along it. A later centre
    placed without that reach, or with half of it, drops a term of the chain (the slip of a
    position written link by link, which every step after it carries): the chain's reading
    is used, and the conflict named with the lines."""
    trig = {x for v in found.values() for f in v[0].atoms(sp.sin, sp.cos) for x in f.free_symbols}
    turning = (trig & set(q)) | revolute
    angles, total = [], sp.Integer(0)
    for x in q:
        total = total + x if x in turning else total
        angles.append(total)
    for k in sorted(found):
        if not 1 <= k <= len(q) or angles[k - 1] == 0:
            continue
        phi = angles[k - 1]
        mine = _along(found[k][0], phi)
        if mine is None or mine[1] != 0:
            continue
        half = sp.nsimplify(mine[0]) * 2
        if not isinstance(half, sp.Symbol):
            continue
        for j in sorted(found):
            if j <= k or j > len(q) or angles[j - 1] == phi:  # a slider on link k moves along it
                continue
            theirs = _along(found[j][0], phi)
            if theirs is None or theirs[1] != 0 or theirs[0] == half:
                continue
            if theirs[0] != 0 and sp.simplify(theirs[0] / half).free_symbols:
                continue  # some other length along link k: not this slip
            pos, mass, st = found[j]
            found[j] = (pos + rz(phi) * sp.Matrix([half - theirs[0], 0, 0]), mass, st)
            reach = "nothing" if theirs[0] == 0 else str(theirs[0])
            conflicts.append(
                f"line {st.line} places link {j}'s mass centre with {reach} along link {k}, where line "
                f"{found[k][2].line} makes link {k} uniform and {half} long (its centre at {half}/2): "
                f"read with {half} along link {k}, where link {k} ends"
            )
