"""Hand transcriptions of the Newton-Euler corpus files (see truth.py)."""

from specs_common import (
    I1,
    I2,
    Eq,
    Matrix,
    c1,
    c2,
    c3,
    c12,
    c123,
    g,
    l1,
    l2,
    l3,
    lc1,
    lc2,
    m1,
    m2,
    m3,
    q1,
    q2,
    qd1,
    qd2,
    qd3,
    qdd1,
    qdd2,
    qdd3,
    s1,
    s2,
    s3,
    s12,
    s123,
    vec,
    z,
)
from sympy import cos, sin

# ---------------------------------------------------------------- planar-2r-craig-align.md
_w2, _a2 = qd1 + qd2, qdd1 + qdd2
_vd2 = vec(l1 * s2 * qdd1 - l1 * c2 * qd1**2 + g * s12, l1 * c2 * qdd1 + l1 * s2 * qd1**2 + g * c12, 0)
_vc2 = vec(_vd2[0] - lc2 * _w2**2, _vd2[1] + lc2 * _a2, 0)
_f1 = vec(
    m2 * (-l1 * qd1**2 - lc2 * c2 * _w2**2 - lc2 * s2 * _a2 + g * s1) - m1 * lc1 * qd1**2 + m1 * g * s1,
    m2 * (l1 * qdd1 - lc2 * s2 * _w2**2 + lc2 * c2 * _a2 + g * c1) + m1 * lc1 * qdd1 + m1 * g * c1,
    0,
)
_n2z = I2 * _a2 + m2 * lc2 * (l1 * c2 * qdd1 + l1 * s2 * qd1**2 + lc2 * _a2 + g * c12)
_n1z = (
    I1 * qdd1
    + _n2z
    + m1 * lc1 * (lc1 * qdd1 + g * c1)
    + m2 * l1 * (l1 * qdd1 - lc2 * s2 * _w2**2 + lc2 * c2 * _a2 + g * c1)
)
TAU1_2R = (
    (I1 + I2 + m1 * lc1**2 + m2 * (l1**2 + lc2**2 + 2 * l1 * lc2 * c2)) * qdd1
    + (I2 + m2 * (lc2**2 + l1 * lc2 * c2)) * qdd2
    - m2 * l1 * lc2 * s2 * (2 * qd1 * qd2 + qd2**2)
    + (m1 * lc1 + m2 * l1) * g * c1
    + m2 * lc2 * g * c12
)
TAU2_2R = (I2 + m2 * (lc2**2 + l1 * lc2 * c2)) * qdd1 + (I2 + m2 * lc2**2) * qdd2 + m2 * l1 * lc2 * s2 * qd1**2
TAU2_2R += m2 * lc2 * g * c12

CRAIG_ALIGN = [
    Eq(r"{}^{1}_{0}R &=", "R10", Matrix([[c1, s1, 0], [-s1, c1, 0], [0, 0, 1]])),
    Eq(r"{}^{1}_{2}R &=", "R12", Matrix([[c2, -s2, 0], [s2, c2, 0], [0, 0, 1]])),
    Eq(r"{}^{1}\omega_{1} &=", "omega1", z(qd1)),
    Eq(r"{}^{1}\dot\omega_{1} &=", "omegadot1", z(qdd1)),
    Eq(r"{}^{1}\dot v_{1} &=", "vdot1", vec(g * s1, g * c1, 0)),
    Eq(r"{}^{1}\dot v_{C_1} &=", "vcdot1", vec(-lc1 * qd1**2 + g * s1, lc1 * qdd1 + g * c1, 0), span=1),
    Eq(r"{}^{1}F_{1} &=", "F1", vec(-m1 * lc1 * qd1**2 + m1 * g * s1, m1 * lc1 * qdd1 + m1 * g * c1, 0)),
    Eq(r"{}^{1}N_{1} &=", "N1", z(I1 * qdd1)),
    Eq(r"{}^{2}\omega_{2} &=", "omega2", z(_w2)),
    Eq(r"{}^{2}\dot\omega_{2} &=", "omegadot2", z(_a2)),
    Eq(r"{}^{2}\dot v_{2} &=", "vdot2", _vd2, span=1),
    Eq(r"{}^{2}\dot v_{C_2} &=", "vcdot2", _vc2),
    Eq(r"{}^{2}F_{2} &=", "F2", m2 * _vc2),
    Eq(r"{}^{2}N_{2} &=", "N2", z(I2 * _a2)),
    Eq(r"{}^{2}f_{2} &=", "f2", m2 * _vc2),
    Eq(r"{}^{2}n_{2} &=", "n2", z(_n2z)),
    Eq(r"{}^{1}f_{1} &=", "f1", _f1, span=1),
    Eq(r"{}^{1}n_{1} &=", "n1", z(_n1z), span=1),
    Eq(r"\tau_1 &=", "tau1", TAU1_2R),
    Eq(r"\tau_2 &=", "tau2", TAU2_2R),
]

SPECS = {
    "planar-2r-craig-align.md": {"robot": "planar-2r", "eqs": CRAIG_ALIGN},
}

# ---------------------------------------------------------------- planar-2r-craig-transposed.md
_R21_slip = Matrix([[c2, -s2, 0], [s2, c2, 0], [0, 0, 1]])
_s1m2, _c1m2 = sin(q1 - q2), cos(q1 - q2)
_vd2_slip = vec(-l1 * s2 * qdd1 - l1 * c2 * qd1**2 + g * _s1m2, l1 * c2 * qdd1 - l1 * s2 * qd1**2 + g * _c1m2, 0)
_vc2_slip = _vd2_slip + vec(-lc2 * _w2**2, lc2 * _a2, 0)
_n2z_slip = I2 * _a2 + m2 * lc2 * _vc2_slip[1]
CRAIG_TRANSPOSED = [
    Eq(
        r"$${}^{2}_{1}R =",
        "R21",
        _R21_slip,
        id="R",
        why="this is {}^{1}_{2}R: {}^{2}_{1}R, mapping frame-1 coordinates into frame 2, is its transpose "
        "(+S_2 in the first row, -S_2 in the second)",
    ),
    Eq(r"$${}^{1}\dot v_{1} =", "vdot1", vec(g * s1, g * c1, 0)),
    Eq(
        r"$${}^{2}\dot v_{2} =",
        "vdot2",
        _vd2_slip,
        id="vd2",
        after="R",
        carried=lambda v: v["R"] * vec(-l1 * qd1**2 + g * s1, l1 * qdd1 + g * c1, 0),
    ),
    Eq(
        r"$${}^{2}\dot v_{C_2} =",
        "vcdot2",
        _vc2_slip,
        id="vc2",
        after="R",
        carried=lambda v: v["vd2"] + vec(-lc2 * _w2**2, lc2 * _a2, 0),
    ),
    Eq(r"$${}^{2}F_{2} =", "F2", m2 * _vc2_slip, id="F2", after="R", carried=lambda v: m2 * v["vc2"]),
    Eq(r"$${}^{2}N_{2} =", "N2", z(I2 * _a2), id="N2"),
    Eq(
        r"$${}^{2}n_{2} =",
        "n2",
        z(_n2z_slip),
        id="n2",
        after="R",
        carried=lambda v: v["N2"] + vec(lc2, 0, 0).cross(v["F2"]),
    ),
    Eq(
        r"$$\tau_2 =",
        "tau2",
        (I2 + m2 * lc2**2) * _a2 + m2 * l1 * lc2 * (c2 * qdd1 - s2 * qd1**2) + m2 * lc2 * g * _c1m2,
        after="R",
        carried=lambda v: v["n2"][2],
    ),
]
SPECS["planar-2r-craig-transposed.md"] = {"robot": "planar-2r", "eqs": CRAIG_TRANSPOSED}

# ---------------------------------------------------------------- planar-3r-spong-ne-slip.md
_w3, _a3 = qd1 + qd2 + qd3, qdd1 + qdd2 + qdd3
_X = l1 * s2 * qdd1 - l1 * c2 * qd1**2 - l2 * _w2**2
_Y = l1 * c2 * qdd1 + l1 * s2 * qd1**2 + l2 * _a2
_ac3_slip = vec(c3 * _X + s3 * _Y - l3 * _w3**2, -s3 * _X + c3 * _Y + l3 / 2 * _a3, 0)
_g3 = vec(-g * s123, -g * c123, 0)
SPONG_NE = [
    Eq(r"$$\omega_1 =", "omega1", z(qd1)),
    Eq(r"$$a_{c,1} =", "ac1", vec(-l1 / 2 * qd1**2, l1 / 2 * qdd1, 0)),
    Eq(r"$$a_{e,1} =", "ae1", vec(-l1 * qd1**2, l1 * qdd1, 0)),
    Eq(r"$$g_1 =", "g1", vec(-g * s1, -g * c1, 0)),
    Eq(r"$$\alpha_2 =", "omegadot2", z(_a2)),
    Eq(r"$$a_{e,2} =", "ae2", vec(_X, _Y, 0)),
    Eq(
        r"$$a_{c,3} =",
        "ac3",
        _ac3_slip,
        id="ac3",
        why="the centre of link 3 is l3/2 from joint 3: its centripetal term is -(l3/2)(q1' + q2' + q3')^2, "
        "not -l3 (...)^2",
    ),
    Eq(r"$$X =", "ae2[0]", _X),
    Eq(r"$$Y =", "ae2[1]", _Y),
    Eq(r"$$g_3 =", "g3", _g3, id="g3"),
    Eq(r"$$f_3 =", "f3", m3 * _ac3_slip - m3 * _g3, after="ac3", carried=lambda v: m3 * v["ac3"] - m3 * v["g3"]),
    Eq(
        r"$$\tau_3 =",
        "n3",
        z(m3 * l3**2 / 12 * _a3 + m3 * l3 / 2 * (-s3 * _X + c3 * _Y + l3 / 2 * _a3 + g * c123)),
    ),
]
SPECS["planar-3r-spong-ne-slip.md"] = {"robot": "planar-3r", "eqs": SPONG_NE}

# ---------------------------------------------------------------- planar-3r-spong-superscripts.md
SPONG_SUPERSCRIPTS = [
    Eq(r"$$R_2^1 =", "R12", Matrix([[c2, -s2, 0], [s2, c2, 0], [0, 0, 1]])),
    Eq(r"$$\omega_2^2 =", "omega2", z(_w2)),
    Eq(r"$$\alpha_2^2 =", "omegadot2", z(_a2)),
    Eq(r"$$a_{e,1}^1 =", "ae1", vec(-l1 * qd1**2, l1 * qdd1, 0)),
    Eq(
        r"$$a_{c,2}^2 =",
        "ac2",
        vec(
            l1 * s2 * qdd1 - l1 * c2 * qd1**2 - l2 / 2 * _w2**2,
            l1 * c2 * qdd1 + l1 * s2 * qd1**2 + l2 / 2 * _a2,
            0,
        ),
    ),
    Eq(r"$$g_2^2 =", "g2", vec(-g * s12, -g * c12, 0)),
]
SPECS["planar-3r-spong-superscripts.md"] = {"robot": "planar-3r", "eqs": SPONG_SUPERSCRIPTS}

# ---------------------------------------------------------------- planar-2r-craig-split-blocks.md
_n2z_split = I2 * _a2 + m2 * l1 * lc2 * c2 * qdd1 + m2 * l1 * lc2 * s2 * qd1**2 + m2 * lc2 * _a2 + m2 * g * lc2 * c12
_inward1 = m2 * l1 * (l1 * qdd1 - lc2 * s2 * _w2**2 + lc2 * c2 * _a2 + g * c1)  # P_2 x R f_2, its z
CRAIG_SPLIT = [
    Eq(r"$${}^{1}\omega_{1} =", "omega1", z(qd1), span=1),
    Eq(r"$${}^{1}\dot\omega_{1} =", "omegadot1", z(qdd1)),
    Eq(r"$${}^{1}\dot v_{1} =", "vdot1", vec(g * s1, g * c1, 0), span=6),
    Eq(r"$${}^{1}\dot v_{C_1} =", "vcdot1", vec(-lc1 * qd1**2 + g * s1, lc1 * qdd1 + g * c1, 0), span=1),
    Eq(r"$${}^{1}F_{1} =", "F1", vec(-m1 * lc1 * qd1**2 + m1 * g * s1, m1 * lc1 * qdd1 + m1 * g * c1, 0), span=1),
    Eq(r"$${}^{1}N_{1} =", "N1", z(I1 * qdd1)),
    Eq(r"$${}^{2}\omega_{2} =", "omega2", z(_w2), span=1),
    Eq(r"$${}^{2}\dot\omega_{2} =", "omegadot2", z(_a2)),
    Eq(r"$${}^{2}\dot v_{2} =", "vdot2", _vd2, span=4),
    Eq(r"$${}^{2}\dot v_{C_2} =", "vcdot2", _vc2, span=1),
    Eq(r"$${}^{2}F_{2} =", "F2", m2 * _vc2),
    Eq(r"$${}^{2}N_{2} =", "N2", z(I2 * _a2)),
    Eq(r"$${}^{2}f_{2} =", "f2", m2 * _vc2, span=1),
    # the formula block and the product block are right; the slip is in the value block
    Eq(r"$${}^{2}n_{2} =", "n2", z(I2 * _a2 + m2 * lc2 * _vc2[1])),
    Eq(r"$$= \begin{bmatrix} 0 \\ 0 \\ I_2", "n2", z(I2 * _a2) + vec(lc2, 0, 0).cross(m2 * _vc2)),
    Eq(
        r"$$= \begin{bmatrix} 0 \\ 0 \\ I_2",
        "n2",
        z(_n2z_split),
        id="n2",
        why="the value block has m_2 l_{c2}(q1'' + q2'') where l_{c2} x (m_2 l_{c2}(q1'' + q2'')) gives "
        "m_2 l_{c2}^2(q1'' + q2''); its formula and product blocks are right",
    ),
    Eq(r"$${}^{1}f_{1} =", "f1", _f1, span=2),
    Eq(
        r"$${}^{1}n_{1} =",
        "n1",
        z(I1 * qdd1 + m1 * lc1**2 * qdd1 + m1 * g * lc1 * c1 + _n2z_split + _inward1),
        id="n1",
        span=3,
        after="n2",
        carried=lambda v: z(I1 * qdd1 + m1 * lc1 * (lc1 * qdd1 + g * c1) + v["n2"][2] + _inward1),
    ),
    Eq(r"$$\tau_2 =", "tau2", _n2z_split, span=1, after="n2", carried=lambda v: v["n2"][2]),
    Eq(
        r"$$\tau_1 =",
        "tau1",
        (I1 + m1 * lc1**2 + m2 * l1**2) * qdd1
        + I2 * _a2
        + m2 * lc2 * _a2
        + m2 * l1 * lc2 * c2 * (2 * qdd1 + qdd2)
        - m2 * l1 * lc2 * s2 * (2 * qd1 * qd2 + qd2**2)
        + (m1 * lc1 + m2 * l1) * g * c1
        + m2 * g * lc2 * c12,
        span=2,
        after="n2",
        carried=lambda v: v["n1"][2],
    ),
]
SPECS["planar-2r-craig-split-blocks.md"] = {"robot": "planar-2r", "eqs": CRAIG_SPLIT}
