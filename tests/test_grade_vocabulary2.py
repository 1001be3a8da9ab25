"""`armdyn grade` reads more of the textbooks' left-hand sides: the energies' partials
(∂T/∂q̇_k, d/dt ∂K/∂q̇_k, ∂T/∂q_k, ∂V/∂q_k, by the joint vector as a column), point-mass
positions without the ``c`` (``x_1``, ``\\dot x_1``, ``v_2^2``), and the sine/cosine
shorthand's definitions (``c_1 = \\cos\\theta_1``).

The truth is derived here by hand in plain SymPy (the planar elbow arm: mass centres
written out, energies, partials by differentiation; the RP arm's point masses), never
taken from armdyn's output.
"""

from __future__ import annotations

import pytest
import sympy as sp

from armdyn.grading import grade
from armdyn.grading.notation import SymbolMap, parse_lhs
from armdyn.io import load

q1, q2, qd1, qd2, qdd1, qdd2 = sp.symbols("q1 q2 q1_dot q2_dot q1_ddot q2_ddot")
m1, m2, l1, lc1, lc2, I1, I2, g = sp.symbols("m1 m2 l1 lc1 lc2 I1 I2 g")
Q, QD, QDD = [q1, q2], [qd1, qd2], [qdd1, qdd2]
NAMES = {
    q1: r"\theta_1",
    q2: r"\theta_2",
    qd1: r"\dot{\theta}_1",
    qd2: r"\dot{\theta}_2",
    qdd1: r"\ddot{\theta}_1",
    qdd2: r"\ddot{\theta}_2",
    m1: "m_1",
    m2: "m_2",
    l1: "l_1",
    lc1: "l_{c1}",
    lc2: "l_{c2}",
    I1: "I_1",
    I2: "I_2",
}
HEAD = "---\nrobot: planar-2r\nmethod: lagrange\nsymbols:\n  'l_{c1}': lc1\n  'l_{c2}': lc2\n---\n\n"

# the planar elbow arm by hand: mass centres, their velocities, energies (gravity along -y)
PC1 = sp.Matrix([lc1 * sp.cos(q1), lc1 * sp.sin(q1)])
PC2 = sp.Matrix([l1 * sp.cos(q1) + lc2 * sp.cos(q1 + q2), l1 * sp.sin(q1) + lc2 * sp.sin(q1 + q2)])
V1, V2 = PC1.jacobian(Q) * sp.Matrix(QD), PC2.jacobian(Q) * sp.Matrix(QD)
T = (m1 * V1.dot(V1) + m2 * V2.dot(V2) + I1 * qd1**2 + I2 * (qd1 + qd2) ** 2) / 2
V = g * (m1 * PC1[1] + m2 * PC2[1])


def ddt(x):
    return sum(sp.diff(x, Q[j]) * QD[j] + sp.diff(x, QD[j]) * QDD[j] for j in range(2))


def tex(x) -> str:
    if isinstance(x, sp.MatrixBase):
        return r"\begin{pmatrix}" + r" \\ ".join(tex(e) for e in x) + r"\end{pmatrix}"
    return sp.latex(x, symbol_names=NAMES)


def _grade(tmp_path, body, head=HEAD, name="d.md"):
    path = tmp_path / name
    path.write_text(head + body)
    return grade(path)


def _status(report):
    return [(v.name, v.status) for v in report.steps]


def _lhs(text, robot="planar-2r"):
    return parse_lhs(text, SymbolMap(load(robot)).coordinate_of)


def test_the_hand_derivation_is_the_textbooks_closed_form():
    d22 = m2 * lc2**2 + I2
    assert sp.simplify(sp.diff(T, qd2, 2) - d22) == 0
    assert sp.simplify(sp.diff(V, q2) - m2 * g * lc2 * sp.cos(q1 + q2)) == 0


# ------------------------------------------------------------ 1. the energies' partials
@pytest.mark.parametrize(
    "lhs, key, index",
    [
        (r"\frac{\partial T}{\partial \dot\theta_1}", "dL_dqd", 1),
        (r"\partial K/\partial \dot q_2", "dL_dqd", 2),
        (r"\frac{d}{dt}\left(\frac{\partial T}{\partial \dot q_1}\right)", "ddt_dL_dqd", 1),
        (r"\frac{\mathrm{d}}{\mathrm{d}t}\frac{\partial K}{\partial \dot q_1}", "ddt_dL_dqd", 1),
        (r"\frac{\partial T}{\partial \theta_2}", "dT_dq", 2),
        (r"\frac{\partial KE}{\partial q_1}", "dT_dq", 1),
        (r"\frac{\partial V}{\partial \theta_1}", "dV_dq", 1),
        (r"\frac{\partial PE}{\partial \theta_2}", "dV_dq", 2),
        (r"\frac{\partial u}{\partial\Theta_1}", "dV_dq", 1),
        (r"\frac{\partial k}{\partial\dot\Theta_1}", "dL_dqd", 1),
        (r"\frac{\partial U}{\partial q}", "dV_dq", None),
        (r"\frac{\partial k}{\partial\dot\Theta}", "dL_dqd", None),
        (r"\frac{\partial L}{\partial \theta_1}", "dL_dq", 1),
    ],
)
def test_partials_of_the_energies_are_read(lhs, key, index):
    ref = _lhs(lhs)
    assert (ref.key, ref.index) == (key, index)


@pytest.mark.parametrize(
    "lhs", [r"\frac{\partial V}{\partial \dot q_1}", r"\frac{d}{dt}\frac{\partial T}{\partial q_1}"]
)
def test_partials_that_are_no_step_are_not_read(lhs):
    assert _lhs(lhs) is None


def test_energy_partials_graded_against_the_energies(tmp_path):
    p_qd2 = sp.diff(T, qd2)
    body = [
        f"$$T = {tex(T)}$$",
        f"$$V = {tex(V)}$$",
        rf"$$\frac{{\partial T}}{{\partial \dot\theta_2}} = {tex(p_qd2)}$$",
        rf"$$\frac{{d}}{{dt}}\left(\frac{{\partial T}}{{\partial \dot\theta_2}}\right) = {tex(ddt(p_qd2))}$$",
        rf"$$\frac{{\partial T}}{{\partial \theta_2}} = {tex(sp.diff(T, q2))}$$",
        rf"$$\frac{{\partial V}}{{\partial \theta_2}} = {tex(sp.diff(V, q2))}$$",
        rf"$$\tau_2 = {tex(ddt(p_qd2) - sp.diff(T, q2) + sp.diff(V, q2))}$$",
    ]
    r = _grade(tmp_path, "\n\n".join(body) + "\n")
    assert [s for _, s in _status(r)] == ["correct"] * 7, _status(r)
    assert "read as ∂L/∂q̇" in r.steps[2].message


def test_a_slip_in_dT_dq_is_found_and_carried_into_tau(tmp_path):
    wrong = -sp.diff(T, q2)  # a sign slip
    tau = ddt(sp.diff(T, qd2)) - wrong + sp.diff(V, q2)
    body = [
        f"$$T = {tex(T)}$$",
        f"$$V = {tex(V)}$$",
        rf"$$\frac{{\partial K}}{{\partial \theta_2}} = {tex(wrong)}$$",
        rf"$$\frac{{\partial P}}{{\partial \theta_2}} = {tex(sp.diff(V, q2))}$$",
        rf"$$\tau_2 = {tex(tau)}$$",
    ]
    r = _grade(tmp_path, "\n\n".join(body) + "\n")
    assert _status(r) == [
        ("T", "correct"),
        ("V", "correct"),
        ("dT_dq_2", "wrong"),
        ("dV_dq_2", "correct"),
        ("tau_2", "follows-from-earlier-error"),
    ]


def test_a_partial_by_the_joint_vector_is_a_column(tmp_path):
    dv = sp.Matrix([sp.diff(V, q) for q in Q])
    dk = sp.Matrix([sp.diff(T, q) for q in QD])
    body = (
        rf"$$\frac{{\partial u}}{{\partial\Theta}} = {tex(dv)}$$" + "\n\n"
        rf"$$\frac{{\partial k}}{{\partial\dot\Theta}} = {tex(sp.Matrix([dk[0], dk[1] + qd1]))}$$" + "\n"
    )
    r = _grade(tmp_path, body)
    assert _status(r) == [
        ("dV_dq_1", "correct"),
        ("dV_dq_2", "correct"),
        ("dL_dqd_1", "correct"),
        ("dL_dqd_2", "wrong"),
    ]
    assert "entry 2 of the column" in r.steps[3].message


# ------------------------------------------------------------ 2. positions without the c
RP_HEAD = "---\nrobot: rp-arm\nmethod: lagrange\n---\n\n"
th, d2, thd, d2d = sp.symbols("theta1 d2 theta1_dot d2_dot")
RP_NAMES = {th: r"\theta_1", d2: "d_2", thd: r"\dot{\theta}_1", d2d: r"\dot{d}_2"}
# the RP arm's point masses by hand: m1 at l1 (c, s), m2 a further d2 along (-s, c)
RP_P1 = sp.Matrix([l1 * sp.cos(th), l1 * sp.sin(th)])
RP_P2 = RP_P1 + d2 * sp.Matrix([-sp.sin(th), sp.cos(th)])
RP_V2 = RP_P2.jacobian([th, d2]) * sp.Matrix([thd, d2d])


def tex_rp(x) -> str:
    return sp.latex(x, symbol_names=RP_NAMES)


def test_point_mass_positions_without_the_c(tmp_path):
    body = [
        f"$$x_1 = {tex_rp(RP_P1[0])}$$",
        f"$$y_2 = {tex_rp(RP_P2[1])}$$",
        rf"$$\dot x_2 = {tex_rp(RP_V2[0])}$$",
        f"$$v_2^2 = {tex_rp(sp.expand(RP_V2.dot(RP_V2)))}$$",
        f"$$v_{{2}}^2 = {tex_rp(sp.expand(RP_V2.dot(RP_V2)) + d2d**2)}$$",
        f"$$x_2 = {tex_rp(RP_P2[0] + d2 * sp.sin(th))}$$",
    ]
    r = _grade(tmp_path, "\n\n".join(body) + "\n", head=RP_HEAD)
    assert [s for _, s in _status(r)] == ["correct"] * 4 + ["wrong"] * 2, _status(r)
    assert "read as link 1's mass centre" in r.steps[0].message
    assert "squared speed of link 2's mass centre" in r.steps[3].message
    assert "missing term" in r.steps[5].message


def test_a_position_that_does_not_move_or_a_vector_names_no_step(tmp_path):
    body = "$$z_2 = 0$$\n\n$$x_1 = l_1$$\n\n$$v_2^2 = \\begin{pmatrix} 0 \\\\ l_1 \\\\ 0 \\end{pmatrix}$$\n"
    r = _grade(tmp_path, body + "\n$$y_1 = l_1\\sin\\theta_1$$\n", head=RP_HEAD)
    assert [v.status for v in r.steps] == ["unrecognised"] * 3 + ["correct"]
    assert [v.name for v in r.steps[:2]] == ["", ""]
    assert "Craig's velocity of frame 2's origin" in r.steps[2].message


def test_the_end_of_a_link_is_said_so(tmp_path):
    # planar elbow arm: x_1 = l1 cos q1 is joint 2 (the end of link 1), not its mass centre lc1 cos q1
    end = (PC2 - lc2 * sp.Matrix([sp.cos(q1 + q2), sp.sin(q1 + q2)]))[0]
    r = _grade(tmp_path, f"$$x_1 = {tex(end)}$$\n\n$$x_1 = {tex(2 * end)}$$\n")
    assert _status(r) == [("x_c1", "correct"), ("x_c1", "wrong")]
    assert "end of link 1" in r.steps[0].message


# ------------------------------------------------------------ 4. the shorthand's definitions
def test_shorthand_definitions_are_checked(tmp_path):
    c1c2 = sp.cos(q1) * sp.cos(q2)
    body = [
        rf"$$c_1 = {tex(sp.cos(q1))}, \quad s_{{12}} = {tex(sp.sin(q1 + q2))}$$",
        rf"$$C_{{12}} = {tex(c1c2 - sp.sin(q1) * sp.sin(q2))}$$",  # the angle sum expanded: still cos(q1 + q2)
        rf"$$S_1 = {tex(sp.cos(q1))}$$",
        rf"$$c_{{12}} = {tex(c1c2)}$$",
        r"$$c_1 = l_1$$",
    ]
    r = _grade(tmp_path, "\n\n".join(body) + "\n")
    assert _status(r) == [
        ("c_1", "correct"),
        ("s_12", "correct"),
        ("C_12", "correct"),
        ("S_1", "wrong"),
        ("c_12", "wrong"),
        ("", "unrecognised"),
    ]
    assert "sine and cosine swapped" in r.steps[3].message
    assert "missing term" in r.steps[4].message


def test_the_letters_with_joint_rates_are_coriolis_terms(tmp_path):
    # the Coriolis matrix by hand: Christoffel symbols of D = Hessian of T
    D = sp.hessian(T, QD)
    C = sp.Matrix(
        2,
        2,
        lambda k, j: sum(
            (sp.diff(D[k, j], Q[i]) + sp.diff(D[k, i], Q[j]) - sp.diff(D[i, j], Q[k])) / 2 * QD[i] for i in range(2)
        ),
    )
    cq = C * sp.Matrix(QD)
    body = f"$$c_1 = {tex(sp.expand(cq[0]))}$$\n\n$$C_{{12}} = {tex(C[0, 1])}$$\n\n$$c_2 = {tex(2 * cq[1])}$$\n"
    r = _grade(tmp_path, body)
    assert _status(r) == [("h_1", "correct"), ("C_12", "correct"), ("h_2", "wrong")]
    assert "Lynch & Park's velocity-product vector" in r.steps[0].message


# ------------------------------------------------------------ 3. Spong's Newton-Euler names
SPONG_HEAD = "---\nrobot: planar-3r\nmethod: newton-euler\n---\n\n"
t = sp.Symbol("t")
l2, l3, m3 = sp.symbols("l2 l3 m3")
Q3 = sp.symbols("q1 q2 q3")
QD3 = sp.symbols("q1_dot q2_dot q3_dot")
QDD3 = sp.symbols("q1_ddot q2_ddot q3_ddot")
N3 = {**{Q3[k]: rf"\theta_{k + 1}" for k in range(3)}, **{QD3[k]: rf"\dot{{\theta}}_{k + 1}" for k in range(3)}}
N3.update({QDD3[k]: rf"\ddot{{\theta}}_{k + 1}" for k in range(3)})
N3.update({l1: "l_1", l2: "l_2", l3: "l_3", m3: "m_3"})


def _spong_arm():
    """The planar 3R arm of rods by hand: link i turned by φ_i = q1 + ... + qi, joint i+1 at
    the end of link i, the centre halfway; accelerations by differentiating in time."""
    qt = [sp.Function(f"q{k + 1}")(t) for k in range(3)]
    phi = [sum(qt[: i + 1]) for i in range(3)]
    ends, p = [], sp.zeros(2, 1)
    for i, length in enumerate((l1, l2, l3)):
        p = p + length * sp.Matrix([sp.cos(phi[i]), sp.sin(phi[i])])
        ends.append(p)
    centre3 = ends[1] + l3 / 2 * sp.Matrix([sp.cos(phi[2]), sp.sin(phi[2])])

    def plain(x):
        x = x.subs({sp.diff(qt[k], t, 2): QDD3[k] for k in range(3)})
        x = x.subs({sp.diff(qt[k], t): QD3[k] for k in range(3)})
        return x.subs({qt[k]: Q3[k] for k in range(3)})

    def in_frame(i, v):  # a base-frame planar vector written in frame i (R_i^T v)
        c, s = sp.cos(phi[i - 1]), sp.sin(phi[i - 1])
        return sp.Matrix([c * v[0] + s * v[1], -s * v[0] + c * v[1], 0])

    acc = {i: plain(in_frame(i, ends[i - 1].diff(t, 2))) for i in (1, 2)}
    gravity = {i: plain(in_frame(i, sp.Matrix([0, -g]))) for i in (1, 2, 3)}
    ac3 = plain(in_frame(3, centre3.diff(t, 2)))
    # the moment on link 3 at joint 3: I ω̇ + r × m (a_c − g), r = (l3/2, 0, 0) in frame 3
    n3 = m3 * l3**2 / 12 * sum(QDD3) + l3 / 2 * m3 * (ac3[1] - gravity[3][1])
    return acc, gravity, sp.Matrix([0, 0, sp.expand(n3)])


def tex3(x) -> str:
    return r"\begin{pmatrix}" + r" \\ ".join(sp.latex(e, symbol_names=N3) for e in x) + r"\end{pmatrix}"


def test_spongs_newton_euler_names(tmp_path):
    acc, gravity, n3 = _spong_arm()
    body = [
        rf"$$\alpha_2 = {tex3(sp.Matrix([0, 0, QDD3[0] + QDD3[1]]))}$$",
        rf"$$\alpha_2^2 = {tex3(sp.Matrix([0, 0, QDD3[0]]))}$$",
        rf"$$a_{{e,1}} = {tex3(acc[1])}$$",
        rf"$$a_{{e,2}}^2 = {tex3(acc[2] + sp.Matrix([l2 * QD3[0], 0, 0]))}$$",
        rf"$$g_1 = {tex3(gravity[1])}$$",
        rf"$$g_2^2 = {tex3(gravity[1])}$$",
        rf"$$\tau_3 = {tex3(n3)}$$",
        r"$$\alpha_1 = 0$$",
    ]
    r = _grade(tmp_path, "\n\n".join(body) + "\n", head=SPONG_HEAD)
    assert _status(r) == [
        ("omega_dot_2", "correct"),
        ("omega_dot_2", "wrong"),
        ("v_dot_2", "correct-by-convention"),  # Spong keeps gravity as a force
        ("v_dot_3", "wrong"),
        ("g_1", "correct"),
        ("g_2", "wrong"),
        ("n_3", "correct-but-unsupported"),  # right, but not from the a_{e,2} written above
        ("", "unrecognised"),  # a scalar α_1 is a DH twist
    ]
    assert "end of link 1: frame 2's origin (joint 2)" in r.steps[2].message
    assert "gravity expressed in frame 1" in r.steps[4].message
    assert "Spong's moment on link 3" in r.steps[6].message


def test_a_scalar_g_k_stays_the_gravity_vectors_entry(tmp_path):
    # planar elbow arm: g_2 = ∂V/∂q2 by hand
    r = _grade(tmp_path, f"$$g_2 = {tex(sp.diff(V, q2))}$$\n\n$$g_1 = -g$$\n")
    assert _status(r) == [("G_2", "correct"), ("G_1", "wrong")]


def test_spongs_moment_vector_alone_is_right(tmp_path):
    n3 = _spong_arm()[2]
    r = _grade(tmp_path, rf"$$\tau_3 = {tex3(n3)}$$" + "\n", head=SPONG_HEAD)
    assert _status(r) == [("n_3", "correct")]


def test_an_unreadable_column_of_partials_is_named(tmp_path):
    r = _grade(tmp_path, r"$$\frac{\partial V}{\partial q} = \begin{pmatrix} m_1 \\ x_7 \end{pmatrix}$$" + "\n")
    assert [(v.name, v.status) for v in r.steps] == [("dV_dq", "unrecognised")]
    assert "dV_dq: unknown symbol x_{7}" in r.steps[0].message


def test_a_hostile_partial_is_read_in_bounded_time():
    import time

    start = time.perf_counter()
    for lhs in (r"\frac{\partial T}{\partial " + "\\dot{" * 3000 + "q", r"\partial K/\partial " + "q_1" * 5000):
        assert _lhs(lhs) is None
    assert time.perf_counter() - start < 2.0


def test_craigs_position_of_a_mass_centre_in_the_base_frame(tmp_path):
    # Craig's {}^{0}P_{C_2}: link 2's mass centre seen from frame 0's origin (by hand: PC2);
    # the usual reading (from frame 2's origin, written in frame 0) is lc2 (c12, s12)
    from_frame_2 = lc2 * sp.Matrix([sp.cos(q1 + q2), sp.sin(q1 + q2), 0])
    base = sp.Matrix([PC2[0], PC2[1], 0])
    body = "\n\n".join(
        rf"$${{}}^{{0}}P_{{C_2}} = \begin{{bmatrix}} {tex(v[0])} \\ {tex(v[1])} \\ 0 \end{{bmatrix}}$$"
        for v in (base, from_frame_2, base + from_frame_2)
    )
    r = _grade(tmp_path, body + "\n", head=HEAD.replace("lagrange", "newton-euler"))
    # the pre-superscript names where the vector starts (Craig): only the base reading is right,
    # and a wrong one says which reading was checked
    assert [v.status for v in r.steps] == ["correct", "wrong", "wrong"]
    assert "from frame 0's origin" in r.steps[1].message, r.steps[1].message
