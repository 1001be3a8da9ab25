"""A text whose robot cannot be read is never refused: each step is judged against what the
text's own earlier values give (robot_text/own_values.py). The texts here are written by
hand; what each step should be is worked out below with plain SymPy (the Lagrange equation,
Christoffel symbols), never from armdyn's output."""

from __future__ import annotations

import time

import pytest
import sympy as sp

from armdyn.errors import ModelError
from armdyn.grading import grade
from armdyn.grading.reader import read
from armdyn.grading.robot_text import robot_from_text

q1, q2, qd1, qd2, qdd1, qdd2 = sp.symbols("q1 q2 qd1 qd2 qdd1 qdd2")
a, b, c, g, m = sp.symbols("a b c g m")

# a 2-dof arm given only by its energies (its geometry is not in the text)
_T = (a + 2 * b * sp.cos(q2)) * qd1**2 / 2 + (c + b * sp.cos(q2)) * qd1 * qd2 + c * qd2**2 / 2
_V = m * g * sp.sin(q1)


def _lagrange(L):
    """d/dt dL/dqd_i - dL/dq_i by hand."""
    q, qd, qdd = (q1, q2), (qd1, qd2), (qdd1, qdd2)

    def ddt(e):
        return sum(e.diff(x) * y + e.diff(y) * z for x, y, z in zip(q, qd, qdd, strict=True))

    return [sp.expand(ddt(L.diff(qd[i])) - L.diff(q[i])) for i in range(2)]


def _write(tmp_path, text: str) -> str:
    path = tmp_path / "text.md"
    path.write_text(text, encoding="utf-8")
    return str(path)


def _statuses(report) -> dict:
    return {(v.line, v.name): v.status for v in report.steps}


_ENERGIES = r"""---
method: lagrange
---
The arm's energies (its geometry is in the figure):

$$T = \frac{1}{2}(a + 2 b \cos q_2)\dot q_1^2 + (c + b\cos q_2)\dot q_1 \dot q_2 + \frac{1}{2} c \dot q_2^2$$

$$V = m g \sin q_1$$

$$L = T - V$$

$$\frac{\partial L}{\partial \dot q_2} = (c + b \cos q_2)\dot q_1 + c \dot q_2$$

$$\frac{d}{dt}\frac{\partial L}{\partial \dot q_2} = (c + b\cos q_2)\ddot q_1 - b \sin q_2 \dot q_1 \dot q_2 + c \ddot q_2$$

$$\frac{\partial L}{\partial q_2} = -b \sin q_2 \dot q_1^2 - b \sin q_2 \dot q_1 \dot q_2$$

$$\tau_2 = TAU2$$

$$\tau_1 = TAU1$$
"""


def test_the_premise_the_text_torques_follow_from_its_energies():
    # the torques written below are the Lagrange equation applied to T - V by hand
    tau = _lagrange(_T - _V)
    assert sp.simplify(tau[1] - ((c + b * sp.cos(q2)) * qdd1 + c * qdd2 + b * sp.sin(q2) * qd1**2)) == 0
    want1 = (
        (a + 2 * b * sp.cos(q2)) * qdd1
        + (c + b * sp.cos(q2)) * qdd2
        - 2 * b * sp.sin(q2) * qd1 * qd2
        - b * sp.sin(q2) * qd2**2
        + m * g * sp.cos(q1)
    )
    assert sp.simplify(tau[0] - want1) == 0


_TAU2 = r"(c + b\cos q_2)\ddot q_1 + c\ddot q_2 + b \sin q_2 \dot q_1^2"
_TAU1 = (
    r"(a + 2b\cos q_2)\ddot q_1 + (c + b\cos q_2)\ddot q_2 - 2 b \sin q_2 \dot q_1\dot q_2"
    r" - b\sin q_2 \dot q_2^2 + m g \cos q_1"
)


def test_a_text_with_no_geometry_is_graded_on_its_own_values(tmp_path):
    path = _write(tmp_path, _ENERGIES.replace("TAU2", _TAU2).replace("TAU1", _TAU1))
    with pytest.raises(ModelError):
        robot_from_text(read(path))  # the robot cannot be read: no positions, no frames
    report = grade(path)
    assert report.model_note.startswith("no model: the robot could not be read from the text")
    assert report.notes[0] == report.model_note
    by_name = {v.name: v for v in report.steps}
    assert by_name["T"].status == "unrecognised" and "starting value" in by_name["T"].message
    for name in ("L", "dL_dqd_2", "ddt_dL_dqd_2", "dL_dq_2", "tau_2", "tau_1"):
        assert by_name[name].status == "consistent", (name, by_name[name].message)
    assert report.tau_correct == [False, False]  # agreeing with unchecked values: not right


def test_a_slip_is_wrong_and_what_follows_from_it_is_carried(tmp_path):
    # d/dt dL/dqd_2 drops its velocity term; tau_2 = (their d/dt) - (their dL/dq): follows
    slipped = _ENERGIES.replace(r"- b \sin q_2 \dot q_1 \dot q_2 + c \ddot q_2", r"+ c \ddot q_2")
    tau2 = r"(c + b\cos q_2)\ddot q_1 + c\ddot q_2 + b \sin q_2 \dot q_1^2 + b \sin q_2 \dot q_1 \dot q_2"
    report = grade(_write(tmp_path, slipped.replace("TAU2", tau2).replace("TAU1", _TAU1)))
    by_name = {v.name: v for v in report.steps}
    assert by_name["ddt_dL_dqd_2"].status == "wrong"
    assert by_name["tau_2"].status == "follows-from-earlier-error"
    assert by_name["tau_2"].caused_by == "ddt_dL_dqd_2"
    assert by_name["tau_1"].status == "consistent"
    assert report.first_wrong == "ddt_dL_dqd_2"


def test_inertia_matrix_christoffel_symbols_and_torques_from_their_own_m(tmp_path):
    # M and G given (a starting point); c_112 (Spong's, free index last) and tau by hand
    M = sp.Matrix([[a + 2 * b * sp.cos(q2), c + b * sp.cos(q2)], [c + b * sp.cos(q2), c]])
    qs = (q1, q2)

    def christoffel(i, j, k):  # free index k last
        return (M[k, j].diff(qs[i]) + M[k, i].diff(qs[j]) - M[i, j].diff(qs[k])) / 2

    assert sp.simplify(christoffel(0, 1, 0) - (-b * sp.sin(q2))) == 0  # c_121, either convention
    assert sp.simplify(christoffel(1, 0, 0) - (-b * sp.sin(q2))) == 0
    # c_112 is b sin q2 with the free index last, -b sin q2 with it first: 2 b sin q2 is neither
    assert {sp.simplify(christoffel(0, 0, 1)), sp.simplify(christoffel(0, 1, 0))} == {b * sp.sin(q2), -b * sp.sin(q2)}
    text = r"""---
method: lagrange
---
$$d_{11} = a + 2 b \cos q_2, \quad d_{12} = d_{21} = c + b \cos q_2, \quad d_{22} = c$$

$$c_{121} = -b \sin q_2$$

$$c_{112} = 2 b \sin q_2$$

$$g_1 = m g \cos q_1, \quad g_2 = 0$$

$$\tau_2 = d_{21} \ddot q_1 + d_{22}\ddot q_2 + b \sin q_2 \dot q_1^2 + g_2$$
"""
    report = grade(_write(tmp_path, text))
    status = {v.name: v.status for v in report.steps}
    assert status["c_121"] == "consistent"
    assert status["c_112"] == "wrong"  # the slip: neither convention's value (by hand above)
    assert status["tau_2"] == "consistent"
    assert status["M_11"] == "unrecognised"  # a starting value: nothing earlier decides it


def test_newton_euler_steps_from_the_links_own_vectors(tmp_path):
    # no frames stated: F = m vc_dot and tau = n_z follow from the link's own vectors
    text = r"""---
method: newton-euler
---
$${}^{2}\dot v_{C_2} = \begin{bmatrix} -l \dot\theta_2^2 \\ l \ddot\theta_2 \\ 0 \end{bmatrix}$$

$${}^{2}F_2 = \begin{bmatrix} -m_2 l \dot\theta_2^2 \\ m_2 l \ddot\theta_2 \\ 0 \end{bmatrix}$$

$${}^{2}n_2 = \begin{bmatrix} 0 \\ 0 \\ m_2 l^2 \ddot\theta_2 + k \end{bmatrix}$$

$$\tau_2 = m_2 l^2 \ddot\theta_2$$

$$\tau_1 = 3$$
"""
    report = grade(_write(tmp_path, text))
    status = {v.name: v.status for v in report.steps}
    assert status["F_2"] == "consistent"
    assert status["tau_2"] == "wrong"  # n_2's z component has + k
    assert status["tau_1"] == "unrecognised"  # no n_1: nothing decides it


def test_a_name_given_no_value_before_is_not_called_wrong(tmp_path):
    text = _ENERGIES.replace("TAU2", _TAU2 + r" + e_{17}").replace("TAU1", _TAU1)
    report = grade(_write(tmp_path, text))
    tau2 = next(v for v in report.steps if v.name == "tau_2")
    assert tau2.status == "unrecognised" and "e17" in tau2.message


@pytest.mark.parametrize(
    "body",
    [
        # 10^4 frames: joint variables numbered far past a hand derivation's
        "\n".join(rf"$$\tau_{{{k}}} = \theta_{{{k}}}$$" for k in range(1, 10_001, 97))
        + "\n$$\\theta_{10000} = 1$$\n$$\\Gamma_{111} = 0$$\n$$h_1 = 0$$",
        # a huge entry
        "$$T = " + " + ".join(rf"a_{{{k}}} \dot q_1^2" for k in range(6000)) + "$$\n$$L = T$$",
        # circular definitions: each names the other, neither ever has a value
        "$$T = T_1 + T_2$$\n$$T_1 = T - T_2$$\n$$T_2 = T - T_1$$\n$$L = T - V$$\n$$V = L - T$$",
    ],
    ids=["10k-frames", "huge-entry", "circular"],
)
def test_hostile_texts_end_in_bounded_time_and_are_not_refused(tmp_path, body):
    path = _write(tmp_path, "---\nmethod: lagrange\n---\n" + body + "\n")
    t0 = time.perf_counter()
    report = grade(path)
    assert time.perf_counter() - t0 < 30
    assert report.model_note.startswith("no model")
    assert report.steps and all(v.status != "correct" or v.name for v in report.steps)


def test_a_reading_most_steps_disagree_with_gives_way_to_the_own_values(tmp_path):
    # the text places a point mass (x_1, y_1) but its energies are of a body of inertia J:
    # every step from T on disagrees with the point mass read, and follows from the text's T
    th, thd, thdd, J, m1, l = sp.symbols("th thd thdd J m1 l")
    L = J * thd**2 / 2 - m1 * g * l * sp.sin(th)
    tau = sp.diff(L, thd).diff(thd) * thdd - L.diff(th)  # dL/dthd = J thd has no th in it
    assert sp.simplify(tau - (J * thdd + m1 * g * l * sp.cos(th))) == 0
    text = r"""---
method: lagrange
---
$$x_1 = l \cos\theta_1, \qquad y_1 = l \sin\theta_1$$

$$T = \frac{1}{2} J \dot\theta_1^2$$

$$V = m_1 g l \sin\theta_1$$

$$L = T - V$$

$$\frac{\partial L}{\partial \dot\theta_1} = J \dot\theta_1$$

$$\frac{d}{dt}\frac{\partial L}{\partial \dot\theta_1} = J \ddot\theta_1$$

$$\tau_1 = J \ddot\theta_1 + m_1 g l \cos\theta_1$$
"""
    path = _write(tmp_path, text)
    robot_from_text(read(path))  # a model is read: the point mass
    report = grade(path)
    assert report.model_note.startswith("no model: the robot could not be read from the text (the model read")
    assert "disagrees with most of its steps" in report.model_note
    status = {v.name: v.status for v in report.steps}
    assert status["tau_1"] == "consistent" and status["L"] == "consistent"
    assert not any(v.status in ("wrong", "follows-from-earlier-error") for v in report.steps)


def test_the_christoffel_index_order_is_kept_once_a_symbol_decides_it(tmp_path):
    M = sp.Matrix([[a + 2 * b * sp.cos(q2), c + b * sp.cos(q2)], [c + b * sp.cos(q2), c]])
    qs = (q1, q2)

    def last(i, j, k):  # Spong: c_ijk with the free index k last
        return sp.simplify((M[k, j].diff(qs[i]) + M[k, i].diff(qs[j]) - M[i, j].diff(qs[k])) / 2)

    # c_211 is -b sin q2 only with the free index last (first: c_{1,12} by Spong's = b sin q2)
    assert last(1, 0, 0) == -b * sp.sin(q2) and last(0, 0, 1) == b * sp.sin(q2)
    text = r"""---
method: lagrange
---
$$m_{11} = a + 2 b \cos q_2, \quad m_{12} = c + b \cos q_2, \quad m_{22} = c$$

$$c_{211} = -b \sin q_2$$

$$c_{112} = -b \sin q_2$$
"""
    status = {v.name: v.status for v in grade(_write(tmp_path, text)).steps}
    assert status["c_211"] == "consistent"
    assert status["c_112"] == "wrong"  # the other order's value: a slip once the order is known


@pytest.mark.parametrize(
    "omega2, status", [(r"\dot\theta_1 + \dot\theta_2", "correct"), (r"\dot\theta_2", "unrecognised")]
)
def test_angular_velocities_from_the_texts_rotation_confirm_never_condemn(tmp_path, omega2, status):
    # Rz(theta2)^T (0, 0, w1) + theta2_dot z = (0, 0, w1 + theta2_dot): turning about z keeps z
    t2, w1 = sp.symbols("t2 w1")
    Rz = sp.Matrix([[sp.cos(t2), -sp.sin(t2), 0], [sp.sin(t2), sp.cos(t2), 0], [0, 0, 1]])
    assert list(Rz.T * sp.Matrix([0, 0, w1])) == [0, 0, w1]
    text = rf"""---
method: newton-euler
---
$$R_2^1 = \begin{{bmatrix}} \cos\theta_2 & -\sin\theta_2 & 0 \\ \sin\theta_2 & \cos\theta_2 & 0 \\ 0 & 0 & 1 \end{{bmatrix}}$$

$$\omega_1^1 = \begin{{bmatrix}} 0 \\ 0 \\ \dot\theta_1 \end{{bmatrix}}$$

$$\omega_2^2 = \begin{{bmatrix}} 0 \\ 0 \\ {omega2} \end{{bmatrix}}$$
"""
    found = {v.name: v.status for v in grade(_write(tmp_path, text)).steps}
    assert found["omega_1"] == "correct"
    # the joint axis is the convention's, not read: a difference is not called wrong
    assert found["omega_2"] == status


def test_a_slip_carried_through_keeps_the_model_read(tmp_path):
    # one slip in T, carried through L and tau: the reading stands (one wrong, then follows)
    text = r"""---
method: lagrange
---
$$x_1 = l \cos\theta_1, \qquad y_1 = l \sin\theta_1$$

$$T = m_1 l^2 \dot\theta_1^2$$

$$V = m_1 g l \sin\theta_1$$

$$L = T - V$$

$$\frac{\partial L}{\partial \dot\theta_1} = 2 m_1 l^2 \dot\theta_1$$

$$\frac{d}{dt}\frac{\partial L}{\partial \dot\theta_1} = 2 m_1 l^2 \ddot\theta_1$$

$$\tau_1 = 2 m_1 l^2 \ddot\theta_1 + m_1 g l \cos\theta_1$$
"""
    report = grade(_write(tmp_path, text))
    assert report.model_note.startswith("model read from the text")
    status = {v.name: v.status for v in report.steps}
    assert status["T"] == "wrong"  # a point mass m1 at l: T = m1 l^2 thd^2 / 2
    assert status["tau_1"] == "follows-from-earlier-error"


_SPONG_OWN = r"""---
method: lagrange
---
$$K = \frac{1}{2}\dot q^T D(q)\dot q$$

$$\mathcal{L} = K - P$$

$$d_{11} = a + 2b\cos q_2$$

$$d_{12} = c + b\cos q_2$$

$$d_{22} = c$$

$$c_{121} = -b\sin q_2$$

$$c_{221} = -b\sin q_2$$

$$c_{112} = b\sin q_2$$

$$\phi_1 = e\cos q_1$$

$$\phi_2 = f\cos(q_1 + q_2)$$

$$\tau_1 = d_{11}\ddot q_1 + d_{12}\ddot q_2 + 2c_{121}\dot q_1\dot q_2 + c_{221}\dot q_2^2 + \phi_1$$

$$\tau_2 = d_{12}\ddot q_1 + d_{22}\ddot q_2 + SIGN c_{112}\dot q_1^2 + \phi_2$$
"""


def test_laws_stated_first_and_named_christoffel_symbols_on_own_values(tmp_path):
    """No arm is stated (a, b, c lump it): the laws (K, L) are judged as laws, never taken for
    this arm's values, and c_{121} in tau_1 is the text's own symbol, not the cosine shorthand.
    By hand, for d = [[a + 2b cos q2, c + b cos q2], [., c]]: c_121 = c_211 = -b sin q2,
    c_221 = -b sin q2, c_112 = b sin q2, so tau_2 = d_12 q1'' + d_22 q2'' + c_112 q1'^2 + phi_2."""
    right = _write(tmp_path, _SPONG_OWN.replace("SIGN ", ""))
    got = {v.line: (v.name, v.status) for v in grade(right).steps}
    assert got[4] == ("law", "correct") and got[6][1] != "wrong"
    assert got[24] == ("tau_1", "consistent") and got[26] == ("tau_2", "consistent")
    slip = tmp_path / "slip"
    slip.mkdir()
    wrong = _write(slip, _SPONG_OWN.replace("SIGN ", "- "))
    got = {v.line: (v.name, v.status) for v in grade(wrong).steps}
    assert got[24] == ("tau_1", "consistent") and got[26] == ("tau_2", "wrong")
