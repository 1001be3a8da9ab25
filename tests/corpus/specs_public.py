"""Hand transcriptions of the corpus files written in notations learnt from public course
material (see README.md, "Notations learnt from public material"; truth.py decides)."""

SPECS: dict = {}

from specs_common import (  # noqa: E402
    I1,
    I2,
    Eq,
    Matrix,
    c1,
    c2,
    c12,
    ddt,
    g,
    half,
    l1,
    lc1,
    lc2,
    m1,
    m2,
    q2,
    qd1,
    qd2,
    qdd1,
    qdd2,
    s1,
    s2,
    s12,
)
from sympy import diff  # noqa: E402

# ---------------------------------------------------------------- planar-2r-sympy-printed.md
_WHY_DQ2 = "dL/dq2 holds -g lc2 m2 cos(q1 + q2) (P grows with q2): the sign of the gravity term is flipped"
_dq2_slip = g * lc2 * m2 * c12 - l1 * lc2 * m2 * s2 * qd1**2 - l1 * lc2 * m2 * s2 * qd1 * qd2
_ddt2 = I2 * qdd1 + I2 * qdd2 - l1 * lc2 * m2 * s2 * qd1 * qd2 + l1 * lc2 * m2 * c2 * qdd1 + lc2**2 * m2 * (qdd1 + qdd2)
SPECS["planar-2r-sympy-printed.md"] = {
    "robot": "planar-2r",
    "eqs": [
        Eq(r"\displaystyle x_{2} =", "pc2[0]", l1 * c1 + lc2 * c12),
        Eq(r"\displaystyle y_{2} =", "pc2[1]", l1 * s1 + lc2 * s12),
        Eq(r"\displaystyle \dot{x}_{2} =", "vc2[0]", -l1 * s1 * qd1 - lc2 * (qd1 + qd2) * s12),
        Eq(
            r"\displaystyle T =",
            "K",
            I1 * qd1**2 / 2
            + I2 * qd1**2 / 2
            + I2 * qd1 * qd2
            + I2 * qd2**2 / 2
            + l1**2 * m2 * qd1**2 / 2
            + l1 * lc2 * m2 * c2 * qd1**2
            + l1 * lc2 * m2 * c2 * qd1 * qd2
            + lc1**2 * m1 * qd1**2 / 2
            + lc2**2 * m2 * qd1**2 / 2
            + lc2**2 * m2 * qd1 * qd2
            + lc2**2 * m2 * qd2**2 / 2,
        ),
        Eq(r"\displaystyle V =", "P", g * lc1 * m1 * s1 + g * m2 * (l1 * s1 + lc2 * s12)),
        Eq(
            r"\displaystyle \frac{\partial L}{\partial \dot{\theta}_{1}} =",
            "dL_dqd1",
            I1 * qd1
            + I2 * qd1
            + I2 * qd2
            + l1**2 * m2 * qd1
            + 2 * l1 * lc2 * m2 * c2 * qd1
            + l1 * lc2 * m2 * c2 * qd2
            + lc1**2 * m1 * qd1
            + lc2**2 * m2 * qd1
            + lc2**2 * m2 * qd2,
        ),
        Eq(
            r"\displaystyle \frac{d}{d t} \frac{\partial L}{\partial \dot{\theta}_{1}} =",
            "ddt_dL_dqd1",
            I1 * qdd1
            + I2 * qdd1
            + I2 * qdd2
            + l1**2 * m2 * qdd1
            - 2 * l1 * lc2 * m2 * s2 * qd1 * qd2
            - l1 * lc2 * m2 * s2 * qd2**2
            + 2 * l1 * lc2 * m2 * c2 * qdd1
            + l1 * lc2 * m2 * c2 * qdd2
            + lc1**2 * m1 * qdd1
            + lc2**2 * m2 * qdd1
            + lc2**2 * m2 * qdd2,
        ),
        Eq(
            r"\displaystyle \frac{\partial L}{\partial \theta_{1}} =",
            "dL_dq1",
            -g * l1 * m2 * c1 - g * lc1 * m1 * c1 - g * lc2 * m2 * c12,
        ),
        Eq(
            r"\displaystyle \tau_{1} =",
            "tau1",
            g * l1 * m2 * c1
            + g * lc1 * m1 * c1
            + g * lc2 * m2 * c12
            - 2 * l1 * lc2 * m2 * s2 * qd1 * qd2
            - l1 * lc2 * m2 * s2 * qd2**2
            + (I2 + l1 * lc2 * m2 * c2 + lc2**2 * m2) * qdd2
            + (I1 + I2 + l1**2 * m2 + 2 * l1 * lc2 * m2 * c2 + lc1**2 * m1 + lc2**2 * m2) * qdd1,
        ),
        Eq(r"\displaystyle \frac{\partial L}{\partial \theta_{2}} =", "dL_dq2", _dq2_slip, id="dq2", why=_WHY_DQ2),
        Eq(
            r"\displaystyle \tau_{2} =",
            "tau2",
            -g * lc2 * m2 * c12
            + l1 * lc2 * m2 * s2 * qd1**2
            + (I2 + lc2**2 * m2) * qdd2
            + (I2 + l1 * lc2 * m2 * c2 + lc2**2 * m2) * qdd1,
            after="dq2",
            carried=lambda v: _ddt2 - v["dq2"],
        ),
    ],
}

# ---------------------------------------------------------------- planar-2r-cases-zh.md
_WHY_P2 = "link 2's mass centre is at height l1 sin(q1) + lc2 sin(q1 + q2): the absolute angle q2 is used"
_P2_slip = m2 * g * (l1 * s1 + lc2 * s2)
_K_zh = half * (m1 * lc1**2 + I1) * qd1**2
_K_zh += half * m2 * (l1**2 * qd1**2 + lc2**2 * (qd1 + qd2) ** 2 + 2 * l1 * lc2 * c2 * (qd1**2 + qd1 * qd2))
_K_zh += half * I2 * (qd1 + qd2) ** 2


def _tau_from(P, k):
    """tau_k of K_zh - P, by Lagrange's equation (what the method gives from a student's P)."""
    from specs_common import QDS, QS

    L = _K_zh - P
    return ddt(diff(L, QDS[k - 1])) - diff(L, QS[k - 1])


SPECS["planar-2r-cases-zh.md"] = {
    "robot": "planar-2r",
    "eqs": [
        Eq("x_1=", "pc1[0]", lc1 * c1),
        Eq("y_1=", "pc1[1]", lc1 * s1),
        Eq("x_2=", "pc2[0]", l1 * c1 + lc2 * c12),
        Eq("y_2=", "pc2[1]", l1 * s1 + lc2 * s12),
        Eq(r"\dot{x}_2=", "vc2[0]", -l1 * s1 * qd1 - lc2 * s12 * (qd1 + qd2)),
        Eq(r"\dot{y}_2=", "vc2[1]", l1 * c1 * qd1 + lc2 * c12 * (qd1 + qd2)),
        Eq("E_{K1}=", "K1", half * (m1 * lc1**2 + I1) * qd1**2),
        Eq(
            "E_{K2}=",
            "K2",
            half * m2 * (l1**2 * qd1**2 + lc2**2 * (qd1 + qd2) ** 2 + 2 * l1 * lc2 * c2 * (qd1**2 + qd1 * qd2))
            + half * I2 * (qd1 + qd2) ** 2,
        ),
        Eq("E_{P1}=", "P1", m1 * g * lc1 * s1, id="P1"),
        Eq("E_{P2}=", "P2", _P2_slip, id="P2", why=_WHY_P2),
        Eq(
            r"\tau _1=",
            "tau1",
            (m1 * lc1**2 + I1 + I2 + m2 * (l1**2 + lc2**2 + 2 * l1 * lc2 * c2)) * qdd1
            + (I2 + m2 * (lc2**2 + l1 * lc2 * c2)) * qdd2
            - m2 * l1 * lc2 * s2 * (2 * qd1 * qd2 + qd2**2)
            + (m1 * lc1 + m2 * l1) * g * c1,
            after="P2",
            carried=lambda v: _tau_from(v["P1"] + v["P2"], 1),
        ),
        Eq(
            r"\tau _2=",
            "tau2",
            (I2 + m2 * (lc2**2 + l1 * lc2 * c2)) * qdd1
            + (I2 + m2 * lc2**2) * qdd2
            + m2 * l1 * lc2 * s2 * qd1**2
            + m2 * g * lc2 * c2,
            after="P2",
            carried=lambda v: _tau_from(v["P1"] + v["P2"], 2),
        ),
    ],
}

# ---------------------------------------------------------------- planar-2r-mls-constants.md
_al = I1 + I2 + m1 * lc1**2 + m2 * (l1**2 + lc2**2)
_be = m2 * l1 * lc2
_de = I2 + m2 * lc2**2
_WHY_C21 = "C_21 = Gamma_211 q1' = beta sin(q2) q1': the sign is that of C_11, not its own"
_C_slip = Matrix([[-_be * s2 * qd2, -_be * s2 * (qd1 + qd2)], [-_be * s2 * qd1, 0]])
_N = Matrix([(m1 * lc1 + m2 * l1) * g * c1 + m2 * lc2 * g * c12, m2 * lc2 * g * c12])
_M = Matrix([[_al + 2 * _be * c2, _de + _be * c2], [_de + _be * c2, _de]])
SPECS["planar-2r-mls-constants.md"] = {
    "robot": "planar-2r",
    "eqs": [
        Eq(r"$$M(\theta) =", "D", _M),
        Eq(r"$$\Gamma_{112} =", "c121", -_be * s2),
        Eq(r"$$\Gamma_{122} =", "c221", -_be * s2),
        Eq(r"$$\Gamma_{211} =", "c112", _be * s2),
        Eq(r"$$C(\theta,\dot\theta) =", "C", _C_slip, id="C", why=_WHY_C21),
        Eq(r"$$N(\theta,\dot\theta) =", "G", _N),
        Eq(
            r"$$\tau_1 =",
            "tau1",
            (_al + 2 * _be * c2) * qdd1
            + (_de + _be * c2) * qdd2
            - _be * s2 * (2 * qd1 * qd2 + qd2**2)
            + (m1 * lc1 + m2 * l1) * g * c1
            + m2 * lc2 * g * c12,
        ),
        Eq(
            r"$$\tau_2 =",
            "tau2",
            (_de + _be * c2) * qdd1 + _de * qdd2 - _be * s2 * qd1**2 + m2 * lc2 * g * c12,
            after="C",
            carried=lambda v: (_M * Matrix([qdd1, qdd2]) + v["C"] * Matrix([qd1, qd2]) + _N)[1],
        ),
    ],
}

# ---------------------------------------------------------------- planar-2r-asada-slotine.md
_WHY_H22 = "H_22 = m2 lc2^2 + I2: the l1 lc2 cos(q2) term belongs to H_12 only"
_H11 = m1 * lc1**2 + I1 + m2 * (l1**2 + lc2**2 + 2 * l1 * lc2 * c2) + I2
_H12 = m2 * (lc2**2 + l1 * lc2 * c2) + I2
_H22_slip = m2 * (lc2**2 + l1 * lc2 * c2) + I2
_h = m2 * l1 * lc2 * s2
_G1 = m1 * g * lc1 * c1 + m2 * g * (l1 * c1 + lc2 * c12)
_G2 = m2 * g * lc2 * c12
SPECS["planar-2r-asada-slotine.md"] = {
    "robot": "planar-2r",
    "eqs": [
        Eq("$$H_{11} =", "d11", _H11),
        Eq("$$H_{12} =", "d12", _H12),
        Eq("$$H_{22} =", "d22", _H22_slip, id="H22", why=_WHY_H22),
        Eq("$$h_{112} =", "h112", -2 * _h),
        Eq("$$h_{122} =", "h122", -_h),
        Eq("$$h_{211} =", "h211", _h),
        Eq("$$G_1 =", "phi1", _G1),
        Eq("$$G_2 =", "phi2", _G2),
        Eq(r"$$\tau_1 =", "tau1", _H11 * qdd1 + _H12 * qdd2 - _h * qd2**2 - 2 * _h * qd1 * qd2 + _G1),
        Eq(
            r"$$\tau_2 =",
            "tau2",
            _H22_slip * qdd2 + _H12 * qdd1 + _h * qd1**2 + _G2,
            after="H22",
            carried=lambda v: v["H22"] * qdd2 + _H12 * qdd1 + _h * qd1**2 + _G2,
        ),
    ],
}

# ---------------------------------------------------------------- rp-arm-deluca-u.md
# q1 is the angle, q2 the slider (the model's theta1, d2)
_WHY_C2 = "c_2 = q'^T C_2 q' with C_2 = -m2 q2 e1 e1^T: -m2 q2 q1'^2, the minus sign is lost"
_c2_slip = m2 * q2 * qd1**2
_M_rp = Matrix([[m1 * l1**2 + m2 * (l1**2 + q2**2), m2 * l1], [m2 * l1, m2]])
_g_rp = Matrix([(m1 + m2) * g * l1 * c1 - m2 * g * q2 * s1, m2 * g * c1])
SPECS["rp-arm-deluca-u.md"] = {
    "robot": "rp-arm",
    "eqs": [
        Eq("$$T_1 =", "K1", half * m1 * l1**2 * qd1**2),
        Eq("$$T_2 =", "K2", half * m2 * ((l1**2 + q2**2) * qd1**2 + 2 * l1 * qd1 * qd2 + qd2**2)),
        Eq("$$M(q) =", "D", _M_rp),
        Eq(r"$$c_1(q,\dot q) =", "Cqd[0]", 2 * m2 * q2 * qd1 * qd2),
        Eq(r"$$c_2(q,\dot q) =", "Cqd[1]", _c2_slip, id="c2", why=_WHY_C2),
        Eq("$$U =", "P", m1 * g * l1 * s1 + m2 * g * (l1 * s1 + q2 * c1)),
        Eq("$$g(q) =", "G", _g_rp),
        Eq(
            "$$u_1 =",
            "tau1",
            (m1 * l1**2 + m2 * (l1**2 + q2**2)) * qdd1
            + m2 * l1 * qdd2
            + 2 * m2 * q2 * qd1 * qd2
            + (m1 + m2) * g * l1 * c1
            - m2 * g * q2 * s1,
        ),
        Eq(
            "$$u_2 =",
            "tau2",
            m2 * l1 * qdd1 + m2 * qdd2 + m2 * q2 * qd1**2 + m2 * g * c1,
            after="c2",
            carried=lambda v: (_M_rp * Matrix([qdd1, qdd2]))[1] + v["c2"] + _g_rp[1],
        ),
    ],
}

# ---------------------------------------------------------------- planar-2r-jekyll-array.md
_WHY_YDOT = "d/dt of l1 sin(q1) is l1 cos(q1) q1': the sine is kept"
SPECS["planar-2r-jekyll-array.md"] = {
    "robot": "planar-2r",
    "eqs": [
        Eq(r"P_{1,x} \\", "pc1[0]", lc1 * c1),
        Eq(r"P_{1,y} \end", "pc1[1]", lc1 * s1),
        Eq(r"P_{2,x} \\", "pc2[0]", l1 * c1 + lc2 * c12),
        Eq(r"P_{2,y} \end", "pc2[1]", l1 * s1 + lc2 * s12),
        Eq(r"\dot P_{2,x} \\", "vc2[0]", -l1 * s1 * qd1 - lc2 * s12 * (qd1 + qd2)),
        Eq(r"\dot P_{2,y} \end", "vc2[1]", l1 * s1 * qd1 + lc2 * c12 * (qd1 + qd2), why=_WHY_YDOT),
        Eq(
            "$$ KE =",
            "K",
            half * m1 * lc1**2 * qd1**2
            + half * I1 * qd1**2
            + half * m2 * (l1**2 * qd1**2 + lc2**2 * (qd1 + qd2) ** 2 + 2 * l1 * lc2 * c2 * qd1 * (qd1 + qd2))
            + half * I2 * (qd1 + qd2) ** 2,
        ),
        Eq("$$ PE =", "P", m1 * g * lc1 * s1 + m2 * g * (l1 * s1 + lc2 * s12)),
        Eq(
            "$$ D(q) =",
            "D",
            Matrix(
                [
                    [
                        I1 + I2 + m1 * lc1**2 + m2 * (l1**2 + lc2**2 + 2 * l1 * lc2 * c2),
                        I2 + m2 * (lc2**2 + l1 * lc2 * c2),
                    ],
                    [I2 + m2 * (lc2**2 + l1 * lc2 * c2), I2 + m2 * lc2**2],
                ]
            ),
        ),
        Eq(
            r"$$ C(q,\dot{q}) =",
            "C",
            Matrix(
                [
                    [-m2 * l1 * lc2 * s2 * qd2, -m2 * l1 * lc2 * s2 * (qd1 + qd2)],
                    [m2 * l1 * lc2 * s2 * qd1, 0],
                ]
            ),
        ),
        Eq("$$ G(q) =", "G", Matrix([(m1 * lc1 + m2 * l1) * g * c1 + m2 * lc2 * g * c12, m2 * lc2 * g * c12])),
    ],
}
