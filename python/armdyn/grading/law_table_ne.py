"""Craig's iterations as laws (Introduction to Robotics, ch. 6): the outward velocities and
accelerations, Newton's and Euler's equations and the inward force and moment balances, each
with its revolute and prismatic forms, in the frames Craig writes them in (a vector of link
``i`` in frame ``i``, the origin ``{}^{i}P_{i+1}`` in frame ``i``; :mod:`.law_table`)."""

from __future__ import annotations

from .law_table import Form, Law, Term, cross, dot


def _ne(role, name, stated, forms, slips=()):
    return Law(role, "NE", name, stated, forms, list(slips), indexed=True, method="newton-euler")


def _z(c, link):
    return c("Z", link, frame=link)


_ORIGIN_TERMS = [
    Term("R(ω̇ × P)", lambda c: c.rot(c.link, c.link - 1) * cross(c("omega", c.link - 1, dots=1), c("po", c.link))),
    Term(
        "R(ω × (ω × P))",
        lambda c: (
            c.rot(c.link, c.link - 1) * cross(c("omega", c.link - 1), cross(c("omega", c.link - 1), c("po", c.link)))
        ),
    ),
    Term("R v̇_i", lambda c: c.rot(c.link, c.link - 1) * c("v", c.link - 1, dots=1)),
]
#: Craig's iterations
NE_LAWS = [
    _ne(
        "omega",
        "the angular velocity (outward)",
        "ω_{i+1} = R ω_i + θ̇_{i+1} Z_{i+1}",
        [
            Form(
                "revolute",
                [
                    Term("R ω_i", lambda c: c.rot(c.link, c.link - 1) * c("omega", c.link - 1, frame=c.link - 1)),
                    Term("θ̇ Z", lambda c: c("q", c.link, dots=1) * _z(c, c.link)),
                ],
            ),
            Form("prismatic", [Term("R ω_i", lambda c: c.rot(c.link, c.link - 1) * c("omega", c.link - 1))]),
        ],
    ),
    _ne(
        "omega1",
        "the angular acceleration (outward)",
        "ω̇_{i+1} = R ω̇_i + R ω_i × θ̇_{i+1} Z + θ̈_{i+1} Z",
        [
            Form(
                "revolute",
                [
                    Term("R ω̇_i", lambda c: c.rot(c.link, c.link - 1) * c("omega", c.link - 1, dots=1)),
                    Term(
                        "R ω_i × θ̇ Z",
                        lambda c: cross(
                            c.rot(c.link, c.link - 1) * c("omega", c.link - 1),
                            c("q", c.link, dots=1) * _z(c, c.link),
                        ),
                    ),
                    Term("θ̈ Z", lambda c: c("q", c.link, dots=2) * _z(c, c.link)),
                ],
            ),
            Form("prismatic", [Term("R ω̇_i", lambda c: c.rot(c.link, c.link - 1) * c("omega", c.link - 1, dots=1))]),
        ],
    ),
    _ne(
        "v1",
        "the acceleration of a frame's origin (outward)",
        "v̇_{i+1} = R(ω̇_i × P_{i+1} + ω_i × (ω_i × P_{i+1}) + v̇_i)",
        [
            Form("revolute", _ORIGIN_TERMS),
            Form(
                "prismatic",
                [
                    *_ORIGIN_TERMS,
                    Term("2 ω × ḋ Z", lambda c: 2 * cross(c("omega", c.link), c("q", c.link, dots=1) * _z(c, c.link))),
                    Term("d̈ Z", lambda c: c("q", c.link, dots=2) * _z(c, c.link)),
                ],
            ),
        ],
    ),
    _ne(
        "vc1",
        "the acceleration of a mass centre",
        "v̇_C = ω̇ × P_C + ω × (ω × P_C) + v̇",
        [
            Form(
                "",
                [
                    Term("ω̇ × P_C", lambda c: cross(c("omega", c.link, dots=1), c("pc", c.link))),
                    Term(
                        "ω × (ω × P_C)", lambda c: cross(c("omega", c.link), cross(c("omega", c.link), c("pc", c.link)))
                    ),
                    Term("v̇ of the frame's origin", lambda c: c("v", c.link, dots=1)),
                ],
            )
        ],
    ),
    _ne(
        "F",
        "Newton's equation",
        "F = m v̇_C",
        [Form("", [Term("m v̇_C", lambda c: c("m", c.link) * c("v", c.link, dots=1, centre=True))])],
        [
            (
                "the mass times the velocity: Newton's equation is F = m v̇_C",
                lambda c: c("m", c.link) * c("v", c.link, centre=True),
            )
        ],
    ),
    _ne(
        "N",
        "Euler's equation",
        "N = I ω̇ + ω × I ω",
        [
            Form(
                "",
                [
                    Term("I ω̇", lambda c: c("I", c.link) * c("omega", c.link, dots=1)),
                    Term("ω × I ω", lambda c: cross(c("omega", c.link), c("I", c.link) * c("omega", c.link))),
                ],
            )
        ],
    ),
    _ne(
        "f",
        "the force balance (inward)",
        "f_i = R f_{i+1} + F_i",
        [
            Form(
                "",
                [
                    Term("R f_{i+1}", lambda c: c.rot(c.link, c.link + 1) * c("f", c.link + 1)),
                    Term("F_i", lambda c: c("F", c.link)),
                ],
            )
        ],
    ),
    _ne(
        "n",
        "the moment balance (inward)",
        "n_i = N_i + R n_{i+1} + P_C × F_i + P_{i+1} × R f_{i+1}",
        [
            Form(
                "",
                [
                    Term("N_i", lambda c: c("N", c.link)),
                    Term("R n_{i+1}", lambda c: c.rot(c.link, c.link + 1) * c("n", c.link + 1)),
                    Term("P_C × F_i", lambda c: cross(c("pc", c.link), c("F", c.link))),
                    Term(
                        "P_{i+1} × R f_{i+1}",
                        lambda c: cross(
                            c("po", c.link + 1, frame=c.link), c.rot(c.link, c.link + 1) * c("f", c.link + 1)
                        ),
                    ),
                ],
            )
        ],
    ),
    _ne(
        "tau",
        "the joint torque from the moment",
        "τ_i = n_iᵀ Z_i",
        [
            Form("revolute", [Term("n_iᵀ Z_i", lambda c: dot(c("n", c.link), _z(c, c.link)))]),
            Form("prismatic", [Term("f_iᵀ Z_i", lambda c: dot(c("f", c.link), _z(c, c.link)))]),
        ],
    ),
]
