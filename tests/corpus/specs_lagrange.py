"""Hand transcriptions of the Lagrange corpus files (see truth.py)."""

SPECS: dict = {}

from specs_common import (  # noqa: E402
    I1,
    I2,
    Eq,
    Matrix,
    Rational,
    a1,
    a2,
    c1,
    c2,
    c3,
    c12,
    c23,
    c123,
    d1,
    ddt,
    g,
    half,
    l1,
    l2,
    l3,
    lc1,
    lc2,
    m1,
    m2,
    m3,
    m4,
    q1,
    q2,
    q3,
    qd1,
    qd2,
    qd3,
    qd4,
    qdd1,
    qdd2,
    qdd3,
    qdd4,
    s1,
    s2,
    s3,
    s12,
    s23,
    s123,
)
from sympy import diff  # noqa: E402

# ---------------------------------------------------------------- planar-2r-energy-slip.md
_w, _a = qd1 + qd2, qdd1 + qdd2
_v2sq_slip = l1**2 * qd1**2 + lc2**2 * _w**2 + l1 * lc2 * c2 * qd1 * _w
_WHY_V2 = "the cross term of v_c2^2 is 2 l1 lc2 cos(q2) q1'(q1' + q2'): the factor 2 is missing"
_P = m1 * g * lc1 * s1 + m2 * g * (l1 * s1 + lc2 * s12)
_L_slip = half * (m1 * lc1**2 + I1) * qd1**2 + half * m2 * _v2sq_slip + half * I2 * _w**2 - _P


def _follow(anchor, quantity, rhs, carried, id=""):
    return Eq(anchor, quantity, rhs, id=id, after="v2sq", carried=carried)


ENERGY_SLIP = [
    Eq(r"x_{c1} =", "pc1[0]", lc1 * c1),
    Eq(r"y_{c1} =", "pc1[1]", lc1 * s1),
    Eq(r"x_{c2} =", "pc2[0]", l1 * c1 + lc2 * c12),
    Eq(r"y_{c2} =", "pc2[1]", l1 * s1 + lc2 * s12),
    Eq(r"\dot x_{c2} =", "vc2[0]", -l1 * s1 * qd1 - lc2 * s12 * _w),
    Eq(r"\dot y_{c2} =", "vc2[1]", l1 * c1 * qd1 + lc2 * c12 * _w),
    Eq(r"v_{c1}^2 =", "vc1_sq", lc1**2 * qd1**2),
    Eq(r"v_{c2}^2 =", "vc2_sq", _v2sq_slip, id="v2sq", why=_WHY_V2),
    Eq(r"K_1 =", "K1", half * m1 * lc1**2 * qd1**2 + half * I1 * qd1**2, id="K1"),
    _follow(
        r"K_2 =",
        "K2",
        half * m2 * _v2sq_slip + half * I2 * _w**2,
        lambda v: half * m2 * v["v2sq"] + half * I2 * _w**2,
        "K2",
    ),
    Eq(r"P_1 =", "P1", m1 * g * lc1 * s1, id="P1"),
    Eq(r"P_2 =", "P2", m2 * g * (l1 * s1 + lc2 * s12), id="P2"),
    _follow(r"\mathcal{L} =", "L", _L_slip, lambda v: v["K1"] + v["K2"] - v["P1"] - v["P2"], "L"),
    _follow(
        r"\[ \frac{\partial \mathcal{L}}{\partial \dot\theta_1} =",
        "dL_dqd1",
        (m1 * lc1**2 + I1) * qd1 + m2 * (l1**2 * qd1 + lc2**2 * _w + half * l1 * lc2 * c2 * (2 * qd1 + qd2)) + I2 * _w,
        lambda v: diff(v["L"], qd1),
        "p1",
    ),
    _follow(
        r"\[ \frac{d}{dt}\frac{\partial \mathcal{L}}{\partial \dot\theta_1} =",
        "ddt_dL_dqd1",
        (m1 * lc1**2 + I1) * qdd1
        + m2
        * (
            l1**2 * qdd1
            + lc2**2 * _a
            + half * l1 * lc2 * c2 * (2 * qdd1 + qdd2)
            - half * l1 * lc2 * s2 * qd2 * (2 * qd1 + qd2)
        )
        + I2 * _a,
        lambda v: ddt(v["p1"]),
        "d1",
    ),
    Eq(
        r"\[ \frac{\partial \mathcal{L}}{\partial \theta_1} =",
        "dL_dq1",
        -m1 * g * lc1 * c1 - m2 * g * (l1 * c1 + lc2 * c12),
        id="q1",
    ),
    _follow(
        r"\[ \frac{\partial \mathcal{L}}{\partial \dot\theta_2} =",
        "dL_dqd2",
        m2 * (lc2**2 * _w + half * l1 * lc2 * c2 * qd1) + I2 * _w,
        lambda v: diff(v["L"], qd2),
        "p2",
    ),
    _follow(
        r"\[ \frac{d}{dt}\frac{\partial \mathcal{L}}{\partial \dot\theta_2} =",
        "ddt_dL_dqd2",
        m2 * (lc2**2 * _a + half * l1 * lc2 * c2 * qdd1 - half * l1 * lc2 * s2 * qd1 * qd2) + I2 * _a,
        lambda v: ddt(v["p2"]),
        "d2",
    ),
    _follow(
        r"\[ \frac{\partial \mathcal{L}}{\partial \theta_2} =",
        "dL_dq2",
        -half * m2 * l1 * lc2 * s2 * qd1 * _w - m2 * g * lc2 * c12,
        lambda v: diff(v["L"], q2),
        "q2",
    ),
    _follow(
        r"\[ \tau_1 =",
        "tau1",
        (m1 * lc1**2 + I1 + I2 + m2 * (l1**2 + lc2**2 + l1 * lc2 * c2)) * qdd1
        + (I2 + m2 * (lc2**2 + half * l1 * lc2 * c2)) * qdd2
        - half * m2 * l1 * lc2 * s2 * (2 * qd1 * qd2 + qd2**2)
        + (m1 * lc1 + m2 * l1) * g * c1
        + m2 * g * lc2 * c12,
        lambda v: v["d1"] - v["q1"],
    ),
    _follow(
        r"\[ \tau_2 =",
        "tau2",
        (I2 + m2 * (lc2**2 + half * l1 * lc2 * c2)) * qdd1
        + (I2 + m2 * lc2**2) * qdd2
        + half * m2 * l1 * lc2 * s2 * qd1**2
        + m2 * g * lc2 * c12,
        lambda v: v["d2"] - v["q2"],
    ),
]

SPECS["planar-2r-energy-slip.md"] = {"robot": "planar-2r", "eqs": ENERGY_SLIP}

# ---------------------------------------------------------------- planar-2r-spong-christoffel.md
_h = -m2 * l1 * lc2 * s2
_d11 = m1 * lc1**2 + m2 * (l1**2 + lc2**2 + 2 * l1 * lc2 * c2) + I1 + I2
_d12 = m2 * (lc2**2 + l1 * lc2 * c2) + I2
_d22 = m2 * lc2**2 + I2
_phi1 = (m1 * lc1 + m2 * l1) * g * c1 + m2 * lc2 * g * c12
_phi2 = m2 * lc2 * g * c12
SPONG_CHRISTOFFEL = [
    Eq(r"d_{11} &=", "d11", _d11),
    Eq(r"d_{12} &=", "d12", _d12),
    Eq(r"d_{21} &=", "d21", _d12),
    Eq(r"d_{22} &=", "d22", _d22),
    Eq(r"c_{111} &=", "c111", 0),
    Eq(r"c_{121} &=", "c121", _h),
    Eq(r"c_{221} &=", "c221", _h),
    Eq(r"c_{112} &=", "c112", -_h),
    Eq(r"c_{122} &=", "c122", 0),
    Eq(r"c_{222} &=", "c222", 0),
    Eq(r"$$\phi_1 =", "phi1", _phi1),
    Eq(r"$$\phi_2 =", "phi2", _phi2),
    Eq(r"$$C(q,\dot q) =", "C", Matrix([[_h * qd2, _h * (qd1 + qd2)], [-_h * qd1, 0]])),
    Eq(r"$$g(q) =", "G", Matrix([_phi1, _phi2])),
    Eq(r"\tau_1 &=", "tau1", _d11 * qdd1 + _d12 * qdd2 + 2 * _h * qd1 * qd2 + _h * qd2**2 + _phi1),
    Eq(r"\tau_2 &=", "tau2", _d12 * qdd1 + _d22 * qdd2 - _h * qd1**2 + _phi2),
]
SPECS["planar-2r-spong-christoffel.md"] = {"robot": "planar-2r", "eqs": SPONG_CHRISTOFFEL}

# ---------------------------------------------------------------- rp-arm-kepe-slip.md
# theta1 -> q1, d2 -> q2
_v2sq = (l1**2 + q2**2) * qd1**2 + 2 * l1 * qd1 * qd2 + qd2**2
_KE = half * m1 * l1**2 * qd1**2 + half * m2 * _v2sq
_PE = m1 * g * l1 * s1 + m2 * g * (l1 * s1 + q2 * c1)
_WHY_RP = "d/dt of m1 l1^2 theta1' is m1 l1^2 theta1'': theta1' written where theta1'' belongs"
RP_KEPE = [
    Eq(r"$$x_1 =", "pc1[0]", l1 * c1),
    Eq(r"$$y_1 =", "pc1[1]", l1 * s1),
    Eq(r"$$x_2 =", "pc2[0]", l1 * c1 - q2 * s1),
    Eq(r"$$y_2 =", "pc2[1]", l1 * s1 + q2 * c1),
    Eq(r"$$v_2^2 =", "vc2_sq", _v2sq, span=2),
    Eq(r"$$KE =", "K", _KE),
    Eq(r"$$PE =", "P", _PE),
    Eq(r"$$L = KE - PE$$", "L", _KE - _PE),
    Eq(
        r"$$\frac{\partial L}{\partial\dot\theta_1} =",
        "dL_dqd1",
        m1 * l1**2 * qd1 + m2 * (l1**2 + q2**2) * qd1 + m2 * l1 * qd2,
    ),
    Eq(
        r"$$\frac{d}{dt}\left(\frac{\partial L}{\partial\dot\theta_1}\right) =",
        "ddt_dL_dqd1",
        m1 * l1**2 * qd1 + m2 * (l1**2 + q2**2) * qdd1 + 2 * m2 * q2 * qd2 * qd1 + m2 * l1 * qdd2,
        id="rd1",
        why=_WHY_RP,
    ),
    Eq(r"$$\frac{\partial L}{\partial\theta_1} =", "dL_dq1", -(m1 + m2) * g * l1 * c1 + m2 * g * q2 * s1, id="rq1"),
    Eq(
        r"$$\tau_1 =",
        "tau1",
        m1 * l1**2 * qd1
        + m2 * (l1**2 + q2**2) * qdd1
        + 2 * m2 * q2 * qd2 * qd1
        + m2 * l1 * qdd2
        + (m1 + m2) * g * l1 * c1
        - m2 * g * q2 * s1,
        after="rd1",
        carried=lambda v: v["rd1"] - v["rq1"],
    ),
    Eq(r"$$\frac{\partial L}{\partial\dot d_2} =", "dL_dqd2", m2 * l1 * qd1 + m2 * qd2),
    Eq(r"$$\frac{d}{dt}\left(\frac{\partial L}{\partial\dot d_2}\right) =", "ddt_dL_dqd2", m2 * l1 * qdd1 + m2 * qdd2),
    Eq(r"$$\frac{\partial L}{\partial d_2} =", "dL_dq2", m2 * q2 * qd1**2 - m2 * g * c1),
    Eq(r"$$\tau_2 =", "tau2", m2 * l1 * qdd1 + m2 * qdd2 - m2 * q2 * qd1**2 + m2 * g * c1),
]
SPECS["rp-arm-kepe-slip.md"] = {"robot": "rp-arm", "eqs": RP_KEPE}

# ---------------------------------------------------------------- planar-2r-lynch-park.md
_c_vec = Matrix([2 * _h * qd1 * qd2 + _h * qd2**2, -_h * qd1**2])
LYNCH_PARK = [
    Eq(r"M(\theta) = \begin{bmatrix}", "D", Matrix([[_d11, _d12], [_d12, _d22]])),
    Eq(r"c(\theta,\dot\theta) = \begin{bmatrix}", "Cqd", _c_vec),
    Eq(r"g(\theta) = \begin{bmatrix}", "G", Matrix([_phi1, _phi2])),
    Eq(r"\tau_1 =", "tau1", _d11 * qdd1 + _d12 * qdd2 + _c_vec[0] + _phi1),
    Eq(r"\tau_2 =", "tau2", _d12 * qdd1 + _d22 * qdd2 + _c_vec[1] + _phi2),
]
SPECS["planar-2r-lynch-park.md"] = {"robot": "planar-2r", "eqs": LYNCH_PARK}

# ---------------------------------------------------------------- planar-3r-rods-energy.md
_phi3 = half * m3 * g * l3 * c123
RODS = [
    Eq(r"$$x_{c1} =", "pc1[0]", l1 / 2 * c1),
    Eq(r"$$y_{c3} =", "pc3[1]", l1 * s1 + l2 * s12 + l3 / 2 * s123),
    Eq(
        r"$$K_1 =",
        "K1",
        half * Rational(1, 3) * m1 * l1**2 * qd1**2 + half * m1 * l1**2 / 4 * qd1**2,
        why="the rod's inertia about its end (m1 l1^2/3) used with the translation of its centre: "
        "the centroidal m1 l1^2/12 belongs with it (K1 = m1 l1^2 q1'^2/6)",
    ),
    Eq(r"$$P_1 =", "P1", m1 * g * l1 / 2 * s1),
    Eq(r"$$P_3 =", "P3", m3 * g * (l1 * s1 + l2 * s12 + l3 / 2 * s123)),
    Eq(r"$$\phi_3 =", "phi3", _phi3),
    Eq(r"$$\phi_2 =", "phi2", (m2 / 2 + m3) * g * l2 * c12 + half * m3 * g * l3 * c123),
    Eq(r"$$d_{33} =", "d33", Rational(1, 3) * m3 * l3**2),
    Eq(r"$$d_{23} =", "d23", Rational(1, 3) * m3 * l3**2 + half * m3 * l2 * l3 * c3),
    Eq(
        r"$$\tau_3 =",
        "tau3",
        m3 * l3**2 / 3 * (qdd1 + qdd2 + qdd3)
        + m3 * l3 / 2 * (l1 * c23 * qdd1 + l1 * s23 * qd1**2 + l2 * c3 * (qdd1 + qdd2) + l2 * s3 * (qd1 + qd2) ** 2)
        + _phi3,
    ),
]
SPECS["planar-3r-rods-energy.md"] = {"robot": "planar-3r", "eqs": RODS}

# ---------------------------------------------------------------- scara-mathfence-slip.md
_vs = a1**2 * qd1**2 + a2**2 * (qd1 + qd2) ** 2 + 2 * a1 * a2 * c2 * qd1 * (qd1 + qd2) + qd3**2
_izz = Rational(45, 100000) * m4
SCARA_FENCE = [
    Eq(r"z_{c3} =", "pc3[2]", d1 - q3),
    Eq(r"PE =", "P", (m1 + m2) * g * d1 + (m3 + m4) * g * (d1 - q3)),
    Eq(r"v_{c3}^2 =", "vc3_sq", _vs),
    Eq(r"K_3 =", "K3", half * m3 * _vs),
    Eq(
        r"K_4 =",
        "K4",
        half * m4 * _vs + half * _izz * (qd1 + qd2 + qd4) ** 2,
        id="K4",
        why="z4 points down: the tool turns at q1' + q2' - q4' about the vertical, not q1' + q2' + q4'",
    ),
    Eq(
        r"\frac{\partial L}{\partial\dot\theta_4} =",
        "dL_dqd4",
        _izz * (qd1 + qd2 + qd4),
        id="p4",
        after="K4",
        carried=lambda v: diff(v["K4"], qd4),
    ),
    Eq(r"\tau_4 =", "tau4", _izz * (qdd1 + qdd2 + qdd4), after="K4", carried=lambda v: ddt(v["p4"])),
    Eq(r"\tau_3 =", "tau3", (m3 + m4) * qdd3 - (m3 + m4) * g),
]
SPECS["scara-mathfence-slip.md"] = {"robot": "scara", "eqs": SCARA_FENCE}

# ---------------------------------------------------------------- planar-2r-siciliano.md
# Siciliano's c_ijk names the equation first: his c_ijk is Spong's c_jki (truth_models' key).
SICILIANO = [
    Eq(r"$$b_{11} =", "d11", _d11),
    Eq(r"$$b_{12} =", "d12", _d12),
    Eq(r"$$b_{22} =", "d22", _d22),
    Eq(r"$$c_{112} =", "c121", _h),
    Eq(r"$$c_{211} =", "c112", -_h),
    Eq(r"$$g_1 =", "phi1", _phi1),
    Eq(r"$$g_2 =", "phi2", _phi2),
    Eq(r"$$\tau_1 =", "tau1", _d11 * qdd1 + _d12 * qdd2 + 2 * _h * qd1 * qd2 + _h * qd2**2 + _phi1),
    Eq(r"$$\tau_2 =", "tau2", _d12 * qdd1 + _d22 * qdd2 - _h * qd1**2 + _phi2),
]
SPECS["planar-2r-siciliano.md"] = {"robot": "planar-2r", "eqs": SICILIANO}

# ---------------------------------------------------------------- planar-2r-continuation.md
_T = (
    half * (m1 * lc1**2 + I1) * qd1**2
    + half * m2 * (l1**2 * qd1**2 + lc2**2 * _w**2 + 2 * l1 * lc2 * c2 * qd1 * _w)
    + half * I2 * _w**2
)
CONTINUATION = [
    Eq(r"$$T = \frac{1}{2} m_1 v_{c1}^2", "K", _T, span=2),
    Eq(r"$$V = ", "P", m1 * g * lc1 * s1 + m2 * g * (l1 * s1 + lc2 * s12)),
    Eq(
        r"$$\frac{\partial T}{\partial \dot{\theta}_2} =",
        "dL_dqd2",
        m2 * lc2**2 * _w + m2 * l1 * lc2 * c2 * qd1 + I2 * _w,
    ),
    Eq(
        r"$$\frac{d}{dt}\left(\frac{\partial T}{\partial \dot{\theta}_2}\right) =",
        "ddt_dL_dqd2",
        (m2 * lc2**2 + I2) * _a + m2 * l1 * lc2 * c2 * qdd1 - m2 * l1 * lc2 * s2 * qd1 * qd2,
    ),
    Eq(r"$$\frac{\partial T}{\partial \theta_2} =", "dK_dq2", -m2 * l1 * lc2 * s2 * qd1 * _w),
    Eq(r"$$\frac{\partial V}{\partial \theta_2} =", "phi2", m2 * g * lc2 * c12),
    Eq(
        r"$$\tau_2 =",
        "tau2",
        (m2 * (lc2**2 + l1 * lc2 * c2) + I2) * qdd1
        + (m2 * lc2**2 + I2) * qdd2
        + m2 * l1 * lc2 * s2 * qd1**2
        + m2 * g * lc2 * c12,
        span=2,
    ),
]
SPECS["planar-2r-continuation.md"] = {"robot": "planar-2r", "eqs": CONTINUATION}

# ---------------------------------------------------------------- rp-arm-matrix-form.md
RP_MATRIX = [
    Eq(r"$$M(\mathbf{q}) =", "D", Matrix([[(m1 + m2) * l1**2 + m2 * q2**2, m2 * l1], [m2 * l1, m2]])),
    Eq(r"$$C(\mathbf{q},\dot{\mathbf{q}}) =", "C", Matrix([[m2 * q2 * qd2, m2 * q2 * qd1], [-m2 * q2 * qd1, 0]])),
    Eq(r"$$G(\mathbf{q}) =", "G", Matrix([(m1 + m2) * g * l1 * c1 - m2 * g * q2 * s1, m2 * g * c1])),
    Eq(
        r"$$\boldsymbol{\tau} =",
        "tau",
        Matrix(
            [
                ((m1 + m2) * l1**2 + m2 * q2**2) * qdd1
                + m2 * l1 * qdd2
                + 2 * m2 * q2 * qd1 * qd2
                + (m1 + m2) * g * l1 * c1
                - m2 * g * q2 * s1,
                m2 * l1 * qdd1 + m2 * qdd2 - m2 * q2 * qd1**2 + m2 * g * c1,
            ]
        ),
    ),
]
SPECS["rp-arm-matrix-form.md"] = {"robot": "rp-arm", "eqs": RP_MATRIX}

# ---------------------------------------------------------------- planar-2r-craig-ku.md
CRAIG_KU = [
    Eq(r"{}^{0}P_{C_2} = \begin{bmatrix}", "pc2", Matrix([l1 * c1 + lc2 * c12, l1 * s1 + lc2 * s12, 0])),
    Eq(r"k_1 =", "K1", half * m1 * lc1**2 * qd1**2 + half * I1 * qd1**2),
    Eq(
        r"k_2 =",
        "K2",
        half * m2 * (l1**2 * qd1**2 + 2 * l1 * lc2 * c2 * qd1 * _w + lc2**2 * _w**2) + half * I2 * _w**2,
    ),
    Eq(r"u_1 =", "P1", m1 * g * lc1 * s1),
    Eq(r"u_2 =", "P2", m2 * g * (l1 * s1 + lc2 * s12)),
    Eq(
        r"\frac{\partial k}{\partial\dot\Theta} =",
        "dL_dqd",
        Matrix(
            [
                (m1 * lc1**2 + I1) * qd1 + m2 * (l1**2 * qd1 + l1 * lc2 * c2 * (2 * qd1 + qd2) + lc2**2 * _w) + I2 * _w,
                m2 * (l1 * lc2 * c2 * qd1 + lc2**2 * _w) + I2 * _w,
            ]
        ),
    ),
    Eq(r"\frac{\partial k}{\partial\Theta} =", "dK_dq", Matrix([0, -m2 * l1 * lc2 * s2 * qd1 * _w])),
    Eq(r"\frac{\partial u}{\partial\Theta} =", "G", Matrix([_phi1, _phi2])),
    Eq(
        r"\tau_1 =",
        "tau1",
        (m1 * lc1**2 + I1 + I2 + m2 * (l1**2 + 2 * l1 * lc2 * c2 + lc2**2)) * qdd1
        + (I2 + m2 * (l1 * lc2 * c2 + lc2**2)) * qdd2
        - m2 * l1 * lc2 * s2 * qd2 * (2 * qd1 + qd2)
        + _phi1,
    ),
]
SPECS["planar-2r-craig-ku.md"] = {"robot": "planar-2r", "eqs": CRAIG_KU}

# ---------------------------------------------------------------- scara-inertia-matrix-slip.md
_k = m2 / 3 + m3 + m4
_b11 = Rational(1, 3) * m1 * a1**2 + (m2 + m3 + m4) * a1**2 + _k * a2**2 + (m2 + 2 * m3 + 2 * m4) * a1 * a2 * c2 + _izz
_b12_slip = _k * a2**2 + (m2 + m3 + m4) * a1 * a2 * c2 + _izz
SCARA_B = [
    Eq(r"b_{11} &=", "d11", _b11, id="b11"),
    Eq(
        r"b_{12} &=",
        "d12",
        _b12_slip,
        id="b12",
        why="link 2's centre is at a2/2: its share of the coupling is (1/2) a1 a2 m2 cos q2, not a1 a2 m2 cos q2",
    ),
    Eq(r"b_{22} &=", "d22", _k * a2**2 + _izz, id="b22"),
    Eq(r"b_{33} &=", "d33", m3 + m4),
    Eq(r"b_{14} &=", "d14", -_izz),
    Eq(r"b_{24} &=", "d24", -_izz, id="b24"),
    Eq(r"b_{44} &=", "d44", _izz),
    Eq(
        r"\tau_2 &=",
        "tau2",
        _b12_slip * qdd1
        + (_k * a2**2 + _izz) * qdd2
        - _izz * qdd4
        + half * (m2 + 2 * m3 + 2 * m4) * a1 * a2 * s2 * qd1**2,
        after="b12",
        carried=lambda v: v["b12"] * qdd1 + v["b22"] * qdd2 + v["b24"] * qdd4 - half * diff(v["b11"], q2) * qd1**2,
    ),
    Eq(r"\tau_4 &=", "tau4", _izz * (qdd4 - qdd1 - qdd2)),
]
SPECS["scara-inertia-matrix-slip.md"] = {"robot": "scara", "eqs": SCARA_B}

# ---------------------------------------------------------------- planar-3r-gravity-slip.md
_P3_slip = m3 * g * (l1 * s1 + l3 / 2 * s123)
_WHY_P3 = "link 3's centre is at height l1 sin q1 + l2 sin(q1 + q2) + (l3/2) sin(q1 + q2 + q3): the l2 term is dropped"
_Pall = (m1 / 2 + m2 + m3) * g * l1 * s1 + m2 / 2 * g * l2 * s12 + m3 / 2 * g * l3 * s123
_ph1 = (m1 / 2 + m2 + m3) * g * l1 * c1 + m2 / 2 * g * l2 * c12 + m3 / 2 * g * l3 * c123
_ph2 = m2 / 2 * g * l2 * c12 + m3 / 2 * g * l3 * c123
GRAVITY_3R = [
    Eq(r"P_1 = m_1 g", "P1", m1 * g * l1 / 2 * s1, id="P1"),
    Eq(r"P_2 = m_2 g", "P2", m2 * g * (l1 * s1 + l2 / 2 * s12), id="P2"),
    Eq(r"P_3 = m_3 g", "P3", _P3_slip, id="P3", why=_WHY_P3),
    Eq(r"$$P = ", "P", _Pall, id="P", after="P3", carried=lambda v: v["P1"] + v["P2"] + v["P3"]),
    Eq(r"$$\phi_1 =", "phi1", _ph1, after="P3", carried=lambda v: diff(v["P"], q1)),
    Eq(r"$$\phi_2 =", "phi2", _ph2, after="P3", carried=lambda v: diff(v["P"], q2)),
    Eq(r"$$\phi_3 =", "phi3", m3 / 2 * g * l3 * c123),
    Eq(
        r"$$g(q) =",
        "G",
        Matrix([_ph1, _ph2, m3 / 2 * g * l3 * c123]),
        after="P3",
        carried=lambda v: Matrix([diff(v["P"], q) for q in (q1, q2, q3)]),
    ),
]
SPECS["planar-3r-gravity-slip.md"] = {"robot": "planar-3r", "eqs": GRAVITY_3R}

# ---------------------------------------------------------------- planar-2r-spong-jacobians.md
SPONG_JACOBIANS = [
    Eq(r"$$J_{v_{c1}} =", "Jvc1", Matrix([[-lc1 * s1, 0], [lc1 * c1, 0], [0, 0]])),
    Eq(
        r"$$J_{v_{c2}} =",
        "Jvc2",
        Matrix([[-l1 * s1 - lc2 * s12, -lc2 * s12], [l1 * c1 + lc2 * c12, lc2 * c12], [0, 0]]),
    ),
    Eq(r"$$J_{\omega_1} =", "Jw1", Matrix([[0, 0], [0, 0], [1, 0]])),
    Eq(r"$$J_{\omega_2} =", "Jw2", Matrix([[0, 0], [0, 0], [1, 1]])),
    Eq(r"D(q) = \begin{pmatrix}", "D", Matrix([[_d11, _d12], [_d12, _d22]])),
    Eq(r"K = \frac{1}{2}\left(", "K", half * _d11 * qd1**2 + _d12 * qd1 * qd2 + half * _d22 * qd2**2),
    Eq(
        r"$$\frac{\mathrm{d}}{\mathrm{d}t}\frac{\partial K}{\partial\dot q_2} =",
        "ddt_dL_dqd2",
        _d12 * qdd1 - m2 * l1 * lc2 * s2 * qd1 * qd2 + _d22 * qdd2,
    ),
]
SPECS["planar-2r-spong-jacobians.md"] = {"robot": "planar-2r", "eqs": SPONG_JACOBIANS}

# ---------------------------------------------------------------- rp-arm-slash-notation.md
_A = m1 * l1**2 + m2 * (l1**2 + q2**2)
RP_SLASH = [
    Eq(r"$$\partial L/\partial\dot q_1 =", "dL_dqd1", _A * qd1 + m2 * l1 * qd2),
    Eq(
        r"$$\frac{\mathrm{d}}{\mathrm{d}t}\left(\partial L/\partial\dot q_1\right) =",
        "ddt_dL_dqd1",
        _A * qdd1 + 2 * m2 * q2 * qd2 * qd1 + m2 * l1 * qdd2,
    ),
    Eq(r"$$\partial L/\partial q_1 =", "dL_dq1", -(m1 + m2) * g * l1 * c1 + m2 * g * q2 * s1),
    Eq(r"$$\partial L/\partial q_2 =", "dL_dq2", m2 * q2 * qd1**2 - m2 * g * c1),
    Eq(
        r"$$\tau_1 =",
        "tau1",
        _A * qdd1 + m2 * l1 * qdd2 + 2 * m2 * q2 * qd1 * qd2 + (m1 + m2) * g * l1 * c1 - m2 * g * q2 * s1,
    ),
    Eq(r"$$\tau_2 =", "tau2", m2 * l1 * qdd1 + m2 * qdd2 - m2 * q2 * qd1**2 + m2 * g * c1),
]
SPECS["rp-arm-slash-notation.md"] = {"robot": "rp-arm", "eqs": RP_SLASH}

# ---------------------------------------------------------------- planar-2r-lynch-park-gamma.md
# Lynch & Park's Gamma_ijk names the equation first: it is Spong's c_jki (truth_models' key).
LP_GAMMA = [
    Eq(r"\Gamma_{112} &=", "c121", _h),
    Eq(r"\Gamma_{121} &=", "c211", _h),
    Eq(r"\Gamma_{122} &=", "c221", _h),
    Eq(r"\Gamma_{211} &=", "c112", -_h),
    Eq(r"\Gamma_{222} &=", "c222", 0),
    Eq(r"c_1 &=", "Cqd[0]", _h * (2 * qd1 * qd2 + qd2**2)),
    Eq(r"c_2 &=", "Cqd[1]", -_h * qd1**2),
]
SPECS["planar-2r-lynch-park-gamma.md"] = {"robot": "planar-2r", "eqs": LP_GAMMA}
