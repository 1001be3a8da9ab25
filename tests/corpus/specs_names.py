"""Hand transcriptions of the corpus files that use quantities by name (see truth.py):
totals before their parts, entries with their arguments, time derivatives of entries."""

SPECS: dict = {}

from specs_common import I1, I2, Eq, c1, c2, c12, g, half, l1, lc1, lc2, m1, m2, qd1, qd2, qdd1, qdd2, s1, s2, s12  # noqa: E402

# ---------------------------------------------------------------- planar-2r-exam-names.md
_w = qd1 + qd2
_v2sq = l1**2 * qd1**2 + lc2**2 * _w**2 + 2 * l1 * lc2 * c2 * qd1 * _w
_K1 = half * m1 * lc1**2 * qd1**2 + half * I1 * qd1**2
_K2 = half * m2 * _v2sq + half * I2 * _w**2
_M11 = m1 * lc1**2 + m2 * (l1**2 + lc2**2 + 2 * l1 * lc2 * c2) + I1 + I2
_M12 = m2 * (lc2**2 + l1 * lc2 * c2) + I2
_M22 = m2 * lc2**2 + I2
_V1 = m1 * g * lc1 * s1
_V2 = m2 * g * (l1 * s1 + lc2 * s12)
# \dot M_{ij} in a value is the chain rule through theta_2 (the student's own entries, right here)
_M11dot = -2 * m2 * l1 * lc2 * s2 * qd2
_M12dot = -m2 * l1 * lc2 * s2 * qd2
EXAM_NAMES = [
    Eq(r"$T = T_1 + T_2$", "K", _K1 + _K2),
    Eq(r"$T_1 =", "K1", _K1),
    Eq(r"$v_{c2}^2 =", "vc2_sq", _v2sq),
    Eq(r"$T_2 =", "K2", _K2),
    Eq(r"$M_{11}(\theta_2) =", "d11", _M11),
    Eq(
        r"$M_{12}(\theta_2) =",
        "d12",
        m2 * (lc2**2 + 2 * l1 * lc2 * c2) + I2,
        why="the cross term of M_12 is m2 l1 lc2 cos(q2): the factor 2 belongs to M_11 only",
    ),
    Eq(r"$M_{12}(\theta_2) =", "d12", _M12),
    Eq(r"$M_{22} =", "d22", _M22),
    Eq(r"$V = V_1 + V_2$", "P", _V1 + _V2),
    Eq(r"$V_1 =", "P1", _V1),
    Eq(r"$V_2 =", "P2", _V2),
    Eq(r"$L =", "L", half * _M11 * qd1**2 + _M12 * qd1 * qd2 + half * _M22 * qd2**2 - (_V1 + _V2)),
    Eq(r"\frac{\partial L}{\partial \dot\theta_1} =", "dL_dqd1", _M11 * qd1 + _M12 * qd2),
    Eq(
        r"\frac{d}{dt}\frac{\partial L}{\partial \dot\theta_1} =",
        "ddt_dL_dqd1",
        _M11 * qdd1 + _M11dot * qd1 + _M12 * qdd2 + _M12dot * qd2,
    ),
    Eq(r"$\dot M_{11} =", "d11dot", -2 * m2 * l1 * lc2 * s2 * qd2),
    Eq(
        r"$\dot M_{12} =",
        "d12dot",
        -m2 * l1 * lc2 * s2 * qd1,
        why="M_12 depends on theta_2 only: its time derivative carries theta_2-dot, not theta_1-dot",
    ),
    Eq(r"\frac{\partial L}{\partial \theta_1} =", "dL_dq1", -(m1 * lc1 + m2 * l1) * g * c1 - m2 * g * lc2 * c12),
    Eq(r"\frac{\partial L}{\partial \dot\theta_2} =", "dL_dqd2", _M12 * qd1 + _M22 * qd2),
    Eq(
        r"\frac{d}{dt}\frac{\partial L}{\partial \dot\theta_2} =",
        "ddt_dL_dqd2",
        _M12 * qdd1 + _M12dot * qd1 + _M22 * qdd2,
    ),
    Eq(r"$\dot M_{22} =", "d22dot", 0),
    Eq(
        r"\frac{\partial L}{\partial \theta_2} =",
        "dL_dq2",
        -m2 * l1 * lc2 * s2 * qd1 * _w - m2 * g * lc2 * c12,
    ),
    Eq(r"$\tau_2 =", "tau2", _M12 * qdd1 + _M22 * qdd2 + m2 * l1 * lc2 * s2 * qd1**2 + m2 * g * lc2 * c12),
]
SPECS["planar-2r-exam-names.md"] = {"robot": "planar-2r", "eqs": EXAM_NAMES}
