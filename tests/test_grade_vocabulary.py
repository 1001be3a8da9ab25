"""`armdyn grade` reads the textbooks' names for the steps (Craig; Spong, Hutchinson &
Vidyasagar; Siciliano et al.; Lynch & Park) and grades the energy method's quantities.

The truth is derived here by hand in plain SymPy (Spong's planar elbow arm, section 7.4.2:
mass-centre positions written out, energies, D as the Hessian of K, c_ijk by Spong's
formula, g = dP/dq; the RP arm's point masses), never taken from armdyn's output; the
closed forms of Spong's book are checked against it first.
"""

from __future__ import annotations

import itertools

import pytest
import sympy as sp

from armdyn.grading import grade
from armdyn.grading.notation import SymbolMap, parse_lhs
from armdyn.io import load

q1, q2, qd1, qd2 = sp.symbols("q1 q2 q1_dot q2_dot")
m1, m2, l1, lc1, lc2, I1, I2, g = sp.symbols("m1 m2 l1 lc1 lc2 I1 I2 g")
Q, QD = sp.Matrix([q1, q2]), sp.Matrix([qd1, qd2])
NAMES = {
    q1: "q_1",
    q2: "q_2",
    qd1: r"\dot{q}_1",
    qd2: r"\dot{q}_2",
    m1: "m_1",
    m2: "m_2",
    l1: "l_1",
    lc1: "l_{c1}",
    lc2: "l_{c2}",
    I1: "I_1",
    I2: "I_2",
}
HEAD = "---\nrobot: planar-2r\nmethod: lagrange\nsymbols:\n  'l_{c1}': lc1\n  'l_{c2}': lc2\n---\n\n"


def tex(x) -> str:
    """A hand-derived value as a student would write it (pmatrix for matrices)."""
    if isinstance(x, sp.MatrixBase):
        rows = [" & ".join(tex(x[i, j]) for j in range(x.shape[1])) for i in range(x.shape[0])]
        return r"\begin{pmatrix}" + r" \\ ".join(rows) + r"\end{pmatrix}"
    return sp.latex(x, symbol_names=NAMES)


# ------------------------------------------------------------ Spong's elbow arm, by hand
PC = {
    1: sp.Matrix([lc1 * sp.cos(q1), lc1 * sp.sin(q1), 0]),
    2: sp.Matrix([l1 * sp.cos(q1) + lc2 * sp.cos(q1 + q2), l1 * sp.sin(q1) + lc2 * sp.sin(q1 + q2), 0]),
}
OMEGA = {1: qd1, 2: qd1 + qd2}
JV = {i: PC[i].jacobian(Q) for i in (1, 2)}
VC = {i: JV[i] * QD for i in (1, 2)}
KIN = {
    i: sp.Rational(1, 2) * [m1, m2][i - 1] * (VC[i].T * VC[i])[0] + sp.Rational(1, 2) * [I1, I2][i - 1] * OMEGA[i] ** 2
    for i in (1, 2)
}
POT = {i: [m1, m2][i - 1] * g * PC[i][1] for i in (1, 2)}  # gravity along -y
D = sp.hessian(KIN[1] + KIN[2], QD)
GRAV = sp.Matrix([sp.diff(POT[1] + POT[2], q) for q in Q])


def c_spong(i, j, k):
    """Spong's c_ijk = 1/2 (d d_kj/dq_i + d d_ki/dq_j - d d_ij/dq_k), 1-based."""
    i, j, k = i - 1, j - 1, k - 1
    return sp.Rational(1, 2) * (sp.diff(D[k, j], Q[i]) + sp.diff(D[k, i], Q[j]) - sp.diff(D[i, j], Q[k]))


CORIOLIS = sp.Matrix(2, 2, lambda k, j: sum(c_spong(i, j + 1, k + 1) * QD[i - 1] for i in (1, 2)))


def zero(x) -> bool:
    return sp.simplify(sp.expand_trig(x)) == 0


def test_the_hand_derivation_is_spongs_closed_form():
    h = -m2 * l1 * lc2 * sp.sin(q2)
    assert zero(D[0, 0] - (m1 * lc1**2 + m2 * (l1**2 + lc2**2 + 2 * l1 * lc2 * sp.cos(q2)) + I1 + I2))
    assert zero(D[0, 1] - (m2 * (lc2**2 + l1 * lc2 * sp.cos(q2)) + I2))
    assert zero(D[1, 1] - (m2 * lc2**2 + I2))
    # Spong (7.86): c121 = c211 = c221 = h, c112 = -h, the rest zero
    assert all(zero(c_spong(*ijk) - h) for ijk in ((1, 2, 1), (2, 1, 1), (2, 2, 1)))
    assert zero(c_spong(1, 1, 2) + h)
    assert all(zero(c_spong(*ijk)) for ijk in ((1, 1, 1), (1, 2, 2), (2, 1, 2), (2, 2, 2)))
    assert zero(GRAV[0] - ((m1 * lc1 + m2 * l1) * g * sp.cos(q1) + m2 * lc2 * g * sp.cos(q1 + q2)))


def _lhs(text, robot="planar-2r"):
    return parse_lhs(text, SymbolMap(load(robot)).coordinate_of)


@pytest.mark.parametrize(
    "lhs, key, index, frame",
    [
        (r"{}^{1}\omega_{1}", "omega", 1, 1),
        (r"{}^{2}\dot\omega_2", "omega_dot", 2, 2),
        (r"{}^{1}\dot{v}_{C_1}", "vc_dot", 1, 1),
        (r"{}^{2}F_2", "F", 2, 2),
        (r"{}^{2}N_2", "N", 2, 2),
        (r"{}^{1}f_1", "f", 1, 1),
        (r"{}^{1}n_1", "n", 1, 1),
        (r"{}^{0}P_{1}", "P", 1, 0),
        (r"{}^{1}P_{2}", "P", 2, 1),
        (r"{}^{1}P_{C_1}", "Pc", 1, 1),
        (r"\vec{\omega}_1", "omega", 1, None),
        (r"\bm{F}_2", "F", 2, None),
        (r"\boldsymbol{n}_1^1", "n", 1, 1),
        (r"\mathbf{f}_2", "f", 2, None),
        (r"\dot v_{G_1}", "vc_dot", 1, None),
        (r"\dot v_{cm,2}", "vc_dot", 2, None),
        (r"\dot{v}_{c_1}", "vc_dot", 1, None),
        (r"\dot{v}_{C_2}", "vc_dot", 2, None),
        (r"\dot{\mathbf{v}}_{G_2}^2", "vc_dot", 2, 2),
        (r"{\dot v}_{c_1}", "vc_dot", 1, None),
        (r"a_{c_1}", "vc_dot", 1, None),
    ],
)
def test_craigs_and_the_others_newton_euler_names(lhs, key, index, frame):
    ref = _lhs(lhs)
    assert ref is not None, lhs
    assert (ref.key, ref.index, ref.frame) == (key, index, frame)


def test_rotation_prescript():
    ref = _lhs(r"{}^{1}_{0}R")
    assert (ref.key, ref.index, ref.frame) == ("R", 0, 1)


@pytest.mark.parametrize(
    "lhs, key, index, extra",
    [
        ("K", "T", None, ""),
        ("KE", "T", None, ""),
        ("E_k", "T", None, ""),
        (r"\mathcal{K}", "T", None, ""),
        (r"\mathcal{T}", "T", None, ""),
        ("k", "T", None, ""),
        ("U", "V", None, ""),
        ("PE", "V", None, ""),
        ("E_p", "V", None, ""),
        (r"\mathcal{U}", "V", None, ""),
        (r"\mathcal{V}", "V", None, ""),
        ("u", "V", None, ""),
        ("K_1", "Tl", 1, ""),
        ("T_2", "Tl", 2, ""),
        ("k_1", "Tl", 1, ""),
        ("PE_1", "Vl", 1, ""),
        ("u_2", "Vl", 2, ""),
        ("P_1", "Vl", 1, ""),  # decided by the value's shape
        ("x_{c1}", "pc", 1, "x"),
        ("y_{c2}", "pc", 2, "y"),
        ("p_{c1}", "pc", 1, ""),
        ("r_{c_2}", "pc", 2, ""),
        (r"\dot x_{c1}", "vc", 1, "x"),
        ("v_{c1}", "vc", 1, ""),
        ("v_{c1}^2", "vc", 1, "sq"),
        (r"|v_{c1}|^2", "vc", 1, "sq"),
        (r"\left\|\dot{p}_{c2}\right\|^2", "vc", 2, "sq"),
        (r"\mathbf{v}_{c_1}^T \mathbf{v}_{c_1}", "vc", 1, "sq"),
        ("J_{v_1}", "Jv", 1, ""),
        ("J_{v_{c1}}", "Jv", 1, ""),
        (r"J_{\omega_2}", "Jw", 2, ""),
        ("D(q)", "M", None, ""),
        (r"M(\theta)", "M", None, ""),
        ("H(q)", "M", None, ""),
        ("d_{11}", "M", None, (1, 1)),
        ("m_{12}", "M", None, (1, 2)),
        ("D_{21}", "M", None, (2, 1)),
        ("c_{112}", "christoffel", None, (1, 1, 2)),
        (r"\Gamma_{121}", "christoffel", None, (1, 2, 1)),
        (r"C(q,\dot q)", "C", None, ""),
        (r"V(\theta,\dot\theta)", "h", None, ""),
        (r"b(q,\dot{q})", "h", None, ""),
        ("h_1", "h", None, (1,)),
        ("g(q)", "G", None, ""),
        (r"G(\theta)", "G", None, ""),
        ("g_2", "G", None, (2,)),
        (r"\phi_1", "G", None, (1,)),
        (r"(\tau_1, \tau_2)^T", "tau_vec", None, ""),
    ],
)
def test_energy_method_names(lhs, key, index, extra):
    ref = _lhs(lhs)
    assert ref is not None, lhs
    assert (ref.key, ref.index) == (key, index), lhs
    assert (ref.entry if isinstance(extra, tuple) else ref.part) == extra, lhs


def test_g_alone_stays_the_gravity_constant():
    assert _lhs("g") is None


def test_negated_partial_is_read():
    ref = _lhs(r"-\frac{\partial L}{\partial q_1}")
    assert (ref.key, ref.index, ref.sign) == ("dL_dq", 1, -1)


def _grade(tmp_path, body, head=HEAD, name="d.md"):
    path = tmp_path / name
    path.write_text(head + body)
    return grade(path)


def _status(report):
    return [(v.name, v.status) for v in report.steps]


def test_spong_energy_method_all_right(tmp_path):
    h = -m2 * l1 * lc2 * sp.sin(q2)
    body = [
        f"$$x_{{c1}} = {tex(PC[1][0])}$$",
        f"$$y_{{c2}} = {tex(PC[2][1])}$$",
        f"$$p_{{c2}} = {tex(PC[2])}$$",
        f"$$r_{{c_1}} = {tex(PC[1][:2, 0])}$$",
        f"$$\\dot x_{{c2}} = {tex(VC[2][0])}$$",
        f"$$v_{{c2}} = {tex(VC[2])}$$",
        f"$$|v_{{c2}}|^2 = {tex(sp.expand((VC[2].T * VC[2])[0]))}$$",
        f"$$\\omega_2 = {tex(OMEGA[2])}$$",
        f"$$J_{{v_{{c2}}}} = {tex(JV[2])}$$",
        f"$$J_{{\\omega_2}} = {tex(sp.Matrix([[0, 0], [0, 0], [1, 1]]))}$$",
        f"$$K_1 = {tex(KIN[1])}$$",
        f"$$K_2 = {tex(KIN[2])}$$",
        f"$$P_1 = {tex(POT[1])}$$",
        f"$$P_2 = {tex(POT[2])}$$",
        "$$K = K_1 + K_2$$",
        "$$P = P_1 + P_2$$",
        r"$$\mathcal{L} = K - P$$",
        f"$$D(q) = {tex(D)}$$",
        f"$$d_{{12}} = {tex(D[0, 1])}$$",
        f"$$c_{{121}} = {tex(h)}$$",
        f"$$c_{{112}} = {tex(-h)}$$",
        "$$c_{222} = 0$$",
        f"$$C(q,\\dot q) = {tex(CORIOLIS)}$$",
        f"$$g(q) = {tex(GRAV)}$$",
        f"$$\\phi_2 = {tex(GRAV[1])}$$",
        r"$$D(q)\ddot q + C(q,\dot q)\dot q + g(q) = \tau$$",
    ]
    r = _grade(tmp_path, "\n\n".join(body) + "\n")
    got = _status(r)
    assert all(s == "correct" for _, s in got), got
    names = [n for n, _ in got]
    assert names[:3] == ["x_c1", "y_c2", "p_c2"] and "c_112" in names and names[-1] == "matrix_form"
    p1 = next(v for v in r.steps if v.name == "V_1")
    assert "potential energy (a scalar)" in p1.message  # P_1 read as an energy, and said so


def test_a_slip_in_the_mass_matrix_makes_the_matrix_form_wrong(tmp_path):
    wrong = D.copy()
    wrong[0, 0] = D[0, 0] - I2  # I_2 forgotten in d11
    r = _grade(tmp_path, f"$$M = {tex(wrong)}$$\n\n$$M\\ddot q + C\\dot q + g = \\tau$$\n")
    assert _status(r) == [("M", "wrong"), ("matrix_form", "follows-from-earlier-error")]
    assert r.steps[0].components == [0]
    assert r.steps[1].caused_by == "M" and "M (line" in r.steps[1].message


def test_christoffel_other_index_order_is_named(tmp_path):
    # c_{112} written with the value of Spong's c_{121}: Murray, Li & Sastry's order
    r = _grade(tmp_path, f"$$\\Gamma_{{112}} = {tex(c_spong(1, 2, 1))}$$\n\n$$c_{{111}} = {tex(l1)}$$\n")
    assert _status(r) == [("c_112", "correct-by-convention"), ("c_111", "wrong")]
    assert "free index first" in r.steps[0].message and "Spong" in r.steps[0].message


def test_coriolis_matrix_any_factorisation(tmp_path):
    # C + S with S q̇ = 0 gives the same C q̇; S is not skew-symmetric, so Ṁ - 2C is not
    S = sp.Matrix([[qd2, -qd1], [0, 0]])
    assert zero((S * QD)[0])
    r = _grade(tmp_path, f"$$C = {tex(CORIOLIS + S)}$$\n\n$$C = {tex(CORIOLIS + sp.Matrix([[qd1, 0], [0, 0]]))}$$\n")
    assert _status(r) == [("C", "correct-by-convention"), ("C", "wrong")]
    assert "not the Christoffel" in r.steps[0].message and "not skew-symmetric" in r.steps[0].message
    assert "entry 1" in r.steps[1].message


def test_craigs_V_is_told_from_the_potential_energy_by_shape(tmp_path):
    h = CORIOLIS * QD
    body = f"$$V = {tex(POT[1] + POT[2])}$$\n\n$$V = {tex(h)}$$\n\n$$V(\\theta,\\dot\\theta) = {tex(h)}$$\n"
    r = _grade(tmp_path, body)
    assert _status(r) == [("V", "correct"), ("h", "correct"), ("h", "correct")]
    assert "centrifugal and Coriolis vector" in r.steps[1].message


def test_potential_energy_up_to_a_constant(tmp_path):
    total = POT[1] + POT[2]
    body = (
        f"$$U = {tex(total + (m1 + m2) * g * l1)}$$\n\n"
        f"$$PE_1 = {tex(POT[1] - m1 * g * lc1)}$$\n\n"
        f"$$u_2 = {tex(POT[2] + m2 * g * l1 * sp.cos(q1))}$$\n"
    )
    r = _grade(tmp_path, body)
    assert _status(r) == [("V", "correct-by-convention"), ("V_1", "correct-by-convention"), ("V_2", "wrong")]
    assert "reference level" in r.steps[0].message and "reference level" in r.steps[1].message


def test_lagrangian_with_the_students_names(tmp_path):
    body = (
        f"$$\\mathcal{{K}} = {tex(KIN[1] + KIN[2])}$$\n\n$$\\mathcal{{P}} = {tex(POT[1] + POT[2])}$$\n\n"
        "$$L = \\mathcal{K} - \\mathcal{P}$$\n\n"
        f"$$-\\frac{{\\partial L}}{{\\partial q_2}} = {tex(-sp.diff(KIN[1] + KIN[2] - POT[1] - POT[2], q2))}$$\n\n"
        f"$$-\\frac{{\\partial L}}{{\\partial q_1}} = {tex(sp.diff(KIN[1] + KIN[2] - POT[1] - POT[2], q1))}$$\n"
    )
    r = _grade(tmp_path, body)
    assert _status(r) == [
        ("T", "correct"),
        ("V", "correct"),
        ("L", "correct"),
        ("dL_dq_2", "correct"),
        ("dL_dq_1", "wrong"),
    ]
    assert "negated partial" in r.steps[3].message


def test_an_angular_momentum_is_not_the_lagrangian(tmp_path):
    r = _grade(
        tmp_path, f"$$L = {tex(sp.Matrix([0, 0, I1 * qd1]))}$$\n\n$$H_1 = {tex(sp.Matrix([0, 0, I1 * qd1]))}$$\n"
    )
    assert r.steps[0].status == "unrecognised" and "angular momentum" in r.steps[0].message
    assert (r.steps[1].name, r.steps[1].status) == ("H_1", "correct")


def test_positions_in_the_base_frame_allow_no_offset(tmp_path):
    r = _grade(tmp_path, f"$$x_{{c1}} = {tex(PC[1][0] + l1)}$$\n\n$$P_1 = {tex(PC[1])}$$\n")
    assert _status(r)[0] == ("x_c1", "wrong")
    # a 3-vector P_1 is Craig's position (frame 1's origin from frame 0's), not an energy
    assert r.steps[1].key == "P" and "position" in r.steps[1].message


# ------------------------------------------------------------ the RP arm (a prismatic joint)
th, d2, thd, d2d, thdd, d2dd = sp.symbols("theta1 d2 theta1_dot d2_dot theta1_ddot d2_ddot")
RP_HEAD = "---\nrobot: rp-arm\nmethod: lagrange\n---\n\n"


def _rp_tau():
    """τ of the RP arm by hand: point masses m1 at l1(c, s), m2 at l1(c, s) + d2(-s, c)."""
    rm1, rm2, rl1, rg = sp.symbols("m1 m2 l1 g")
    x = sp.Matrix([th, d2])
    xd = sp.Matrix([thd, d2d])
    xdd = sp.Matrix([thdd, d2dd])
    p1 = sp.Matrix([rl1 * sp.cos(th), rl1 * sp.sin(th)])
    p2 = p1 + d2 * sp.Matrix([-sp.sin(th), sp.cos(th)])
    v1, v2 = p1.jacobian(x) * xd, p2.jacobian(x) * xd
    L = sp.Rational(1, 2) * (rm1 * v1.dot(v1) + rm2 * v2.dot(v2)) - rg * (rm1 * p1[1] + rm2 * p2[1])
    out = []
    for k in range(2):
        p = sp.diff(L, xd[k])
        ddt = sum(sp.diff(p, x[j]) * xd[j] + sp.diff(p, xd[j]) * xdd[j] for j in range(2))
        out.append(sp.expand(ddt - sp.diff(L, x[k])))
    return out


def test_prismatic_joint_force_f2_is_tau2_by_shape(tmp_path):
    tau = _rp_tau()
    body = f"$$f_2 = {tex_rp(tau[1])}$$\n\n$$(\\tau_1, \\tau_2)^T = {tex_rp(sp.Matrix(tau))}$$\n"
    r = _grade(tmp_path, body, head=RP_HEAD, name="rp.md")
    assert _status(r) == [("tau_2", "correct"), ("tau_1", "correct"), ("tau_2", "correct")]
    assert "generalised force" in r.steps[0].message
    assert r.tau_correct == [True, True]


RP_NAMES = {
    th: r"\theta_1",
    d2: "d_2",
    thd: r"\dot{\theta}_1",
    d2d: r"\dot{d}_2",
    thdd: r"\ddot{\theta}_1",
    d2dd: r"\ddot{d}_2",
}


def tex_rp(x):
    if isinstance(x, sp.MatrixBase):
        return r"\begin{pmatrix}" + r" \\ ".join(tex_rp(e) for e in x) + r"\end{pmatrix}"
    return sp.latex(x, symbol_names=RP_NAMES)


def test_every_christoffel_symbol_of_the_elbow_arm(tmp_path):
    body = "\n\n".join(
        f"$$c_{{{i}{j}{k}}} = {tex(c_spong(i, j, k))}$$" for i, j, k in itertools.product((1, 2), repeat=3)
    )
    r = _grade(tmp_path, body + "\n")
    assert all(s == "correct" for _, s in _status(r)), _status(r)


def test_lavalles_unsymmetrised_coriolis_coefficients(tmp_path):
    # h_ijk = dm_ij/dq_k - 1/2 dm_jk/dq_i: for (1, 1, 2) it is dm_11/dq_2 (m_12 has no q_1),
    # which is neither Spong's c_112 nor its free-index-first reading c_121
    value = sp.diff(D[0, 0], q2)
    assert not zero(value - c_spong(1, 1, 2)) and not zero(value - c_spong(1, 2, 1))
    r = _grade(tmp_path, f"$$h_{{112}} = {tex(value)}$$\n\n$$h_{{112}} = {tex(value / 2)}$$\n")
    assert _status(r) == [("c_112", "correct-by-convention"), ("c_112", "correct-by-convention")]
    assert "LaValle" in r.steps[0].message and "free index first" in r.steps[1].message


@pytest.mark.parametrize(
    "lhs, key, index",
    [
        (r"\frac{\partial L}{\partial q_1'}", "dL_dqd", 1),
        (r"\frac{\partial \mathcal{L}}{\partial \theta_2'}", "dL_dqd", 2),
        (r"\frac{\partial L}{\partial {\dot q}_1}", "dL_dqd", 1),
        (r"\frac{\partial L}{\partial \dot{q_2}}", "dL_dqd", 2),
        (r"\partial L/\partial\dot q_{2}", "dL_dqd", 2),
        (r"\frac{d}{dt}\left(\frac{\partial L}{\partial \dot{q}_{1}}\right)", "ddt_dL_dqd", 1),
        (r"\frac{\partial L}{\partial q_{2}}", "dL_dq", 2),
    ],
)
def test_coordinates_in_every_order_of_dots_primes_and_indices(lhs, key, index):
    ref = _lhs(lhs)
    assert ref is not None and (ref.key, ref.index) == (key, index), lhs


def test_a_hostile_left_hand_side_is_read_in_bounded_time():
    import time

    start = time.perf_counter()
    for lhs in ("(" + "a" * 100000 + "!", "|" + "v" * 100000, "x^T" * 30000, "-" + "{" * 5000, "q'" * 50000):
        assert _lhs(lhs) is None
    assert time.perf_counter() - start < 5


def test_siciliano_and_lynch_park_names(tmp_path):
    h = CORIOLIS * QD
    body = (
        f"$$B(q) = {tex(D)}$$\n\n$$b_{{22}} = {tex(D[1, 1])}$$\n\n"
        f"$$c(\\theta,\\dot\\theta) = {tex(h)}$$\n\n$$C(q,\\dot q)\\dot q = {tex(h)}$$\n\n"
        f"$$h(\\theta,\\dot\\theta) = {tex(h + GRAV)}$$\n\n"
        r"$$M(\theta)\ddot\theta + c(\theta,\dot\theta) + g(\theta) = \tau$$" + "\n"
    )
    r = _grade(tmp_path, body)
    assert _status(r) == [
        ("M", "correct"),
        ("M_22", "correct"),
        ("h", "correct"),
        ("h", "correct"),
        ("h", "correct-by-convention"),
        ("matrix_form", "correct"),
    ]
    assert "Lynch & Park" in r.steps[4].message


def test_a_bare_letter_names_a_matrix_only_when_its_value_is_one(tmp_path):
    # M = m_1 + m_2 (a total mass in a proof), C = 3: not the mass or Coriolis matrix
    r = _grade(tmp_path, f"$$M = m_1 + m_2$$\n\n$$C = 3$$\n\n$$G = {tex(GRAV)}$$\n")
    assert [(v.key, v.status) for v in r.steps] == [("", "unrecognised"), ("", "unrecognised"), ("G", "correct")]


def test_the_spong_matrices_example_gives_its_known_verdict():
    from pathlib import Path

    r = grade(Path(__file__).resolve().parent.parent / "examples" / "grading" / "planar-2r-spong-matrices.md")
    assert r.first_wrong == "M_12"
    assert [v.name for v in r.steps if v.status == "wrong"] == ["M_12"]
    follows = [(v.name, v.caused_by) for v in r.steps if v.status == "follows-from-earlier-error"]
    assert follows == [("matrix_form", "M_12")]
    assert sum(v.name.startswith("c_") and v.status == "correct" for v in r.steps) == 8
    assert all(v.status == "correct" for v in r.steps if v.name not in ("M_12", "matrix_form"))
    assert r.tau_correct == [False, False]


def test_a_scalar_angular_velocity_only_on_a_planar_arm(tmp_path):
    # the PUMA's links turn about axes that are not parallel: a scalar ω_2 is no reading of it
    r = _grade(tmp_path, r"$$\omega_2 = \dot{q}_2$$" + "\n", head="---\nrobot: puma560\n---\n\n")
    assert r.steps[0].status == "unrecognised" and "more than one axis" in r.steps[0].message


def test_tau_as_one_bold_column_with_a_slip(tmp_path):
    tau = _rp_tau()
    slipped = sp.Matrix([tau[0], tau[1] + d2])  # a stray d_2 in τ_2
    r = _grade(tmp_path, f"$$\\boldsymbol{{\\tau}} = {tex_rp(slipped)}$$\n", head=RP_HEAD, name="rp.md")
    assert _status(r) == [("tau_1", "correct"), ("tau_2", "wrong")]
    assert r.tau_correct == [True, False]
