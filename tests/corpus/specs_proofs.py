"""Hand transcriptions of the proof corpus files (see truth.py): both sides of every link
as functions of a random body of particles (``truth.body``)."""

import sympy as sp
from specs_common import Proof

SPECS: dict = {}


def _pts(b):
    """(m_i, x_i, y_i) about the mass centre."""
    return [(mi, r[0], r[1]) for mi, r in zip(b["m"], b["rc"], strict=True)]


def _inertia(b, about):
    out = sp.zeros(3, 3)
    for mi, ri in zip(b["m"], b["r"], strict=True):
        d = ri - about
        out += mi * ((d.T * d)[0] * sp.eye(3) - d * d.T)
    return out


def _ab(b):
    return b["p"][0], b["p"][1]


def _A(b):
    """The point A = C + (a, b, 0)."""
    return b["c"] + sp.Matrix([b["p"][0], b["p"][1], 0])


def _IA_sum(b):
    a, bb = _ab(b)
    return sum(m * ((x - a) ** 2 + (y - bb) ** 2) for m, x, y in _pts(b))


def _IA_split(b):
    a, bb = _ab(b)
    P = _pts(b)
    return (
        sum(m * (x**2 + y**2) for m, x, y in P)
        - 2 * a * sum(m * x for m, x, y in P)
        - 2 * bb * sum(m * y for m, x, y in P)
        + (a**2 + bb**2) * sum(m for m, x, y in P)
    )


def _IC(b):
    return sum(m * (x**2 + y**2) for m, x, y in _pts(b))


def _pvec(b):
    return sp.Matrix([b["p"][0], b["p"][1], 0])


PARALLEL_PARTICLES = [
    Proof(r"I_A &= \sum_i", lambda b: _inertia(b, _A(b))[2, 2], _IA_sum),
    Proof(r"&= \sum_i m_i (x_i^2 + y_i^2) - 2a", _IA_sum, _IA_split),
    Proof(r"$$\sum_i m_i x_i = 0$$", lambda b: sum(m * x for m, x, y in _pts(b)), lambda b: 0),
    Proof(r"$$\sum_i m_i y_i = 0$$", lambda b: sum(m * y for m, x, y in _pts(b)), lambda b: 0),
    Proof(r"$$I_C = ", lambda b: _inertia(b, b["c"])[2, 2], _IC),
    Proof(r"$$\sum_i m_i = M$$", lambda b: sum(b["m"]), lambda b: b["M"]),
    Proof(r"I_A &= I_C + M(a^2 + b^2)", _IA_split, lambda b: _IC(b) + b["M"] * (_ab(b)[0] ** 2 + _ab(b)[1] ** 2)),
    Proof(
        r"&= I_C + M d^2",
        lambda b: _IC(b) + b["M"] * (_ab(b)[0] ** 2 + _ab(b)[1] ** 2),
        lambda b: _IC(b) + b["M"] * (b["p"][0] ** 2 + b["p"][1] ** 2),
    ),
    Proof(
        r"$$\mathbf{I}_A = \mathbf{I}_C",
        lambda b: _inertia(b, _A(b)),
        lambda b: _inertia(b, b["c"]) + b["M"] * ((_pvec(b).T * _pvec(b))[0] * sp.eye(3) - _pvec(b) * _pvec(b).T),
    ),
]
SPECS["parallel-axis-particles.md"] = {"robot": "planar-2r", "eqs": PARALLEL_PARTICLES}


# ---------------------------------------------------------------- rotational-energy-particles.md
def _skew(v):
    return sp.Matrix([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])


def _rot_K(b):
    return sum(mi * (b["w"].cross(r)).dot(b["w"].cross(r)) for mi, r in zip(b["m"], b["rc"], strict=True)) / 2


def _SS(b):
    return sum((mi * _skew(r).T * _skew(r) for mi, r in zip(b["m"], b["rc"], strict=True)), sp.zeros(3, 3))


def _I_def(b):
    return sum(
        (mi * ((r.T * r)[0] * sp.eye(3) - r * r.T) for mi, r in zip(b["m"], b["rc"], strict=True)), sp.zeros(3, 3)
    )


ROT_PARTICLES = [
    Proof(r"$$K_{rot} = \frac{1}{2}\sum_i", _rot_K, _rot_K),
    Proof(
        r"$$\frac{1}{2}\sum_i m_i (\boldsymbol{\omega} \times r_i)^T",
        _rot_K,
        lambda b: (
            sum(mi * (b["w"].T * _skew(r).T * _skew(r) * b["w"])[0] for mi, r in zip(b["m"], b["rc"], strict=True)) / 2
        ),
    ),
    Proof(r"$$I = \sum_i m_i S(r_i)^T", lambda b: _inertia(b, b["c"]), [_SS, _I_def]),
    Proof(r"$$K_{rot} = \frac{1}{2}\boldsymbol{\omega}^T I", _rot_K, lambda b: (b["w"].T * _I_def(b) * b["w"])[0] / 2),
]
SPECS["rotational-energy-particles.md"] = {"robot": "planar-2r", "eqs": ROT_PARTICLES}


# ---------------------------------------------------------------- parallel-axis-integral.md
# A = C - p, so d (from A to C) = p; r_i = position from A.
def _r_A(b):
    return [ri - (b["c"] - b["p"]) for ri in b["r"]]


def _tensor(ms, vs):
    return sum((mi * ((v.T * v)[0] * sp.eye(3) - v * v.T) for mi, v in zip(ms, vs, strict=True)), sp.zeros(3, 3))


PARALLEL_INTEGRAL = [
    Proof(r"$$\mathbf{I}_A = \int_B", lambda b: _inertia(b, b["c"] - b["p"]), lambda b: _tensor(b["m"], _r_A(b))),
    Proof(r"$$\mathbf{r} = \boldsymbol{\rho} + \mathbf{d}$$", _r_A, lambda b: [rc + b["p"] for rc in b["rc"]]),
    Proof(
        r"$$\int_B \boldsymbol{\rho}\, dm",
        lambda b: sum((mi * rc for mi, rc in zip(b["m"], b["rc"], strict=True)), sp.zeros(3, 1)),
        lambda b: sp.zeros(3, 1),
    ),
    Proof(
        r"$$\mathbf{r}^T\mathbf{r} =",
        lambda b: [(r.T * r)[0] for r in _r_A(b)],
        lambda b: [(rc.T * rc)[0] + 2 * (b["p"].T * rc)[0] + (b["p"].T * b["p"])[0] for rc in b["rc"]],
    ),
    Proof(
        r"$$\mathbf{r}\,\mathbf{r}^T =",
        lambda b: [r * r.T for r in _r_A(b)],
        lambda b: [rc * rc.T + rc * b["p"].T + b["p"] * rc.T + b["p"] * b["p"].T for rc in b["rc"]],
    ),
    Proof(
        r"$$\mathbf{I}_A = \mathbf{I}_C",
        lambda b: _inertia(b, b["c"] - b["p"]),
        lambda b: _inertia(b, b["c"]) + b["M"] * ((b["p"].T * b["p"])[0] * sp.eye(3) - b["p"] * b["p"].T),
    ),
    Proof(
        r"$$I_{end} =",
        lambda b: b["M"] * b["u"][0] ** 2 / 12 + b["M"] * (b["u"][0] / 2) ** 2,
        lambda b: b["M"] * b["u"][0] ** 2 / 3,
    ),
]
SPECS["parallel-axis-integral.md"] = {"robot": "planar-2r", "eqs": PARALLEL_INTEGRAL}
