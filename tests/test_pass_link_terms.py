"""The per-link shortcuts of the customized recursion (armdyn.programs.link_terms): the
invariant ``wx^2 + wy^2`` read off the parent's U and U's last column read off the
parent's, each against the textbook recursion (exact, and in NumPy), and what the first
saves."""

from __future__ import annotations

import numpy as np
import sympy as sp
from test_codegen import WRIST_3R, _is_zero, _load

from armdyn.programs.customized_ne import joint_frames
from armdyn.programs.link_terms import column_from_parent, parent_invariant, squares
from armdyn.programs.program import Builder, Program


def _wrist_3r(tmp_path):
    """The wrist arm of test_codegen (joints 2, 3 sharing an origin), every parameter symbolic."""
    path = tmp_path / "wrist-3r.yaml"
    path.write_text(WRIST_3R)
    return _load(str(path))


def test_child_angular_velocity_norm_is_read_off_the_parent(tmp_path):
    """On the wrist arm (joints 2, 3 sharing an origin, alpha -90 and +90 deg), the
    parent's U entry that parent_invariant reads for every moving link equals
    ``-(wx^2 + wy^2)`` of the child's angular velocity ``R^T w_parent + qd z`` formed here
    directly (exact, with sin^2 + cos^2 = 1)."""
    robot = _wrist_3r(tmp_path).canonical()
    b = Builder()
    frames = joint_frames(robot, b)
    U = {robot.base: sp.zeros(3, 3).tolist()}  # the program's 3x3 matrices are lists of rows
    w = {robot.base: sp.zeros(3, 1)}
    used = 0
    for joint in robot.joints:
        R, _ = frames[joint.child]
        k = robot.coordinate_index(joint)
        S = parent_invariant(joint, R, U[joint.parent])
        wj = sp.Matrix(R).T * w[joint.parent] + robot.qd[k] * joint.axis
        if S is not None:
            used += 1
            values = dict(b.assignments)  # c2 = cos(q2), ... of the frames
            assert _is_zero((S + wj[0] ** 2 + wj[1] ** 2).xreplace(values), robot), joint.child
        sq = {"U11": -(wj[1] ** 2) - wj[2] ** 2, "U22": -(wj[0] ** 2) - wj[2] ** 2, "U33": -(wj[0] ** 2) - wj[1] ** 2}
        U[joint.child] = sp.diag(sq["U11"], sq["U22"], sq["U33"]).tolist()
        w[joint.child] = wj
    assert used == robot.dof


def test_squares_with_the_parent_invariant_save_a_product_and_agree():
    """squares() given ``S = -(wx^2 + wy^2)`` forms one product fewer than without it, and
    its U diagonal and differences equal the plain ones where ``S`` is that value."""
    w = list(sp.symbols("wx wy wz"))
    S = sp.Symbol("S")
    plain_b, short_b = Builder(reserved=w + [S]), Builder(reserved=w + [S])
    plain, short = squares(plain_b, w, "1"), squares(short_b, w, "1", S)

    def muls(b):
        return Program(list(b.assignments), [], (0,)).operation_counts()["mul"]

    assert muls(short_b) == muls(plain_b) - 1
    at_S = {S: -(w[0] ** 2 + w[1] ** 2)}
    for key in ("U11", "U22", "U33", "d0", "d1", "d2"):
        a = Program(list(plain_b.assignments), [plain[key]], (1,)).inlined()[0]
        c = Program(list(short_b.assignments), [short[key]], (1,)).inlined()[0].xreplace(at_S)
        assert sp.expand(a - c) == 0, key


def test_U_column_read_off_the_parent_is_the_textbook_value():
    """column_from_parent's ``(U13, U23)`` of every PUMA 560 link with a revolute joint
    about a parent axis equals ``w_x w_z + wd_y`` and ``w_y w_z - wd_x`` of the textbook
    recursion ``w = R^T w_p + qd z``, ``wd = R^T wd_p + qdd z + R^T w_p x qd z``,
    ``U = skew(wd) + skew(w)^2``, done here in NumPy, at random states."""
    canon = _load("puma560-craig").canonical()
    e3 = np.array([0.0, 0.0, 1.0])
    rng = np.random.default_rng(3)

    def skew(v):
        return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])

    checked = 0
    for _ in range(3):
        w, wd, U = {canon.base: np.zeros(3)}, {canon.base: np.zeros(3)}, {canon.base: np.zeros((3, 3))}
        for joint in canon.joints:
            k = canon.coordinate_index(joint)
            q, qd, qdd = rng.uniform(-1.5, 1.5, 3)
            R = joint.transform(canon.q[k])[0].xreplace({canon.q[k]: q})
            Rn = np.array(R, dtype=float)
            wi = Rn.T @ w[joint.parent]
            w[joint.child] = wi + qd * e3
            wd[joint.child] = Rn.T @ wd[joint.parent] + qdd * e3 + np.cross(wi, qd * e3)
            U[joint.child] = skew(wd[joint.child]) + skew(w[joint.child]) @ skew(w[joint.child])
            Up = [[sp.Float(x) for x in row] for row in U[joint.parent]]
            got = column_from_parent(joint, [[sp.Float(float(x)) for x in row] for row in R.tolist()], Up)
            if got is None:
                continue
            checked += 1
            wx, wy, wz = w[joint.child]
            want = (wx * wz + wd[joint.child][1], wy * wz - wd[joint.child][0])
            got = np.array([float(x) for x in got])
            assert np.all(np.isfinite(got))
            np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-12)
    assert checked == 3 * canon.dof
