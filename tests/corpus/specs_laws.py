"""Hand transcriptions of the corpus files that state the laws of the method before they
instantiate them (see truth.py): each law a :class:`~specs_common.Stated` (right as the
textbook states it, or a slip with ``why``), each step an :class:`~specs_common.Eq`."""

from specs_common import I1, I2, Eq, Stated, c1, c2, c12, g, l1, lc1, lc2, m1, m2, qd1, qd2, qdd1, qdd2, s1, s2, vec, z
from specs_newton_euler import TAU1_2R, TAU2_2R

SPECS: dict = {}

# ---------------------------------------------------------------- planar-2r-laws-energy.md
_h = -m2 * l1 * lc2 * s2
_d11 = m1 * lc1**2 + m2 * l1**2 + m2 * lc2**2 + 2 * m2 * l1 * lc2 * c2 + I1 + I2
_d12 = m2 * lc2**2 + m2 * l1 * lc2 * c2 + I2
_d22 = m2 * lc2**2 + I2
_phi1 = (m1 * lc1 + m2 * l1) * g * c1 + m2 * lc2 * g * c12
_phi2 = m2 * lc2 * g * c12
LAWS_ENERGY = [
    Stated(r"$$K_i =", "kinetic energy of link i, Spong's R_i I_i R_i^T"),
    Stated(r"$$K = \sum", "total kinetic energy, and 1/2 qd^T D qd"),
    Stated(r"$$D(q) =", "the mass matrix from the Jacobians"),
    Stated(r"$$P_i =", "potential energy, g pointing up (Spong)"),
    Stated(r"$$\mathcal{L} =", "the Lagrangian"),
    Stated(r"$$\tau_k =", "the Lagrange equation in the index k"),
    Stated(
        r"$$c_{ijk} =",
        "the Christoffel symbols",
        why="the derivative by the free index k must be subtracted: c_ijk = 1/2 (dd_kj/dq_i + dd_ki/dq_j - dd_ij/dq_k)",
    ),
    Stated(r"$$\phi_k =", "the gravity terms"),
    Eq(r"$$d_{11} =", "d11", _d11),
    Eq(r"$$d_{12} =", "d12", _d12),
    Eq(r"$$d_{22} =", "d22", _d22),
    Eq(r"$$c_{121} =", "c121", _h),
    Eq(r"$$c_{221} =", "c221", _h),
    Eq(r"$$c_{112} =", "c112", -_h),
    Eq(r"$$\phi_1 =", "phi1", _phi1),
    Eq(r"$$\phi_2 =", "phi2", _phi2),
    Eq(r"$$\tau_1 =", "tau1", TAU1_2R),
    Eq(r"$$\tau_2 =", "tau2", TAU2_2R),
]
SPECS["planar-2r-laws-energy.md"] = {"robot": "planar-2r", "eqs": LAWS_ENERGY}

# ---------------------------------------------------------------- planar-2r-laws-craig-ne.md
LAWS_CRAIG = [
    Stated(r"$${}^{i+1}\omega_{i+1} =", "angular velocity, outward (revolute)"),
    Stated(r"$${}^{i+1}\dot\omega_{i+1} =", "angular acceleration, outward (revolute)"),
    Stated(r"$${}^{i+1}\dot v_{i+1} =", "acceleration of the frame's origin, outward"),
    Stated(r"$${}^{i+1}\dot v_{C_{i+1}} =", "acceleration of the mass centre"),
    Stated(
        r"$${}^{i+1}F_{i+1} =",
        "Newton's equation",
        why="F = m times the acceleration of the mass centre, not its velocity",
    ),
    Stated(r"$${}^{i+1}N_{i+1} =", "Euler's equation"),
    Stated(r"$${}^{i}f_{i} =", "force balance, inward"),
    Stated(r"$${}^{i}n_{i} =", "moment balance, inward"),
    Stated(r"$$\tau_i =", "joint torque, n^T Z"),
    Eq(r"$${}^{1}\omega_{1} =", "omega1", z(qd1)),
    Eq(r"$${}^{2}\omega_{2} =", "omega2", z(qd1 + qd2)),
    Eq(r"$${}^{2}\dot\omega_{2} =", "omegadot2", z(qdd1 + qdd2)),
    Eq(r"$${}^{1}F_{1} =", "F1", vec(-m1 * lc1 * qd1**2 + m1 * g * s1, m1 * lc1 * qdd1 + m1 * g * c1, 0)),
    Eq(r"$$\tau_2 =", "tau2", TAU2_2R),
    Eq(r"$$\tau_1 =", "tau1", TAU1_2R),
]
SPECS["planar-2r-laws-craig-ne.md"] = {"robot": "planar-2r", "eqs": LAWS_CRAIG}
