"""The energy method's intermediate quantities, checked directly against the model.

Students who derive by Lagrange (Spong-Hutchinson-Vidyasagar, Craig ch. 6, Siciliano et
al., Lynch-Park) write, before the equations of motion, the mass centres' positions and
velocities in the base frame, the Jacobians of the mass centres, each link's kinetic and
potential energy, the mass matrix ``D(q)``, the Christoffel symbols, the Coriolis matrix
``C(q, q̇)``, the centrifugal/Coriolis vector and the gravity vector ``g(q)``. Each is
compared with the model's value (:class:`ModelTerms`); none is carried forward (they are
read off the model, not computed from the student's earlier steps).

Conventions accepted, each named in the verdict:

* a potential energy (per link or total) that differs from the model's by a constant
  (no dependence on q): another reference level;
* a Christoffel symbol with the free index first (Murray, Li & Sastry's ``Γ_ijk``), or Asada
  & Slotine's (Siciliano's, LaValle's) unsymmetrised ``h_ijk = ∂m_ij/∂q_k − ½ ∂m_jk/∂q_i``, when it is not Spong's
  ``c_ijk = ½(∂d_kj/∂q_i + ∂d_ki/∂q_j − ∂d_ij/∂q_k)``;
* a centrifugal/Coriolis vector with gravity added (Lynch & Park's ``h(θ, θ̇)``);
* a Coriolis matrix that is not the Christoffel one but gives the same ``C q̇`` (any
  factorisation is right; the message says whether ``Ṁ − 2C`` is still skew-symmetric).
"""

from __future__ import annotations

from functools import cached_property

import numpy as np
import sympy as sp

from ..model import Robot
from ..symbolic.lagrange import lagrange, link_energies
from ..symbolic.terms import time_derivative
from .engine import equal
from .explain import describe, pretty, tidy
from .verdict import StepVerdict

SPONG = "Spong's c_ijk = ½(∂d_kj/∂q_i + ∂d_ki/∂q_j − ∂d_ij/∂q_k)"
LAVALLE = (
    "Asada & Slotine's (Siciliano's, LaValle's) h_ijk = ∂m_ij/∂q_k − ½ ∂m_jk/∂q_i"
    " (free index first, not symmetric in j, k)"
)
FREE_FIRST = "the free index first (Murray, Li & Sastry's Γ_ijk = ½(∂M_ij/∂q_k + ∂M_ik/∂q_j − ∂M_kj/∂q_i))"


class ModelTerms:
    """The model's energy-method quantities, symbolic, built on first use.

    Links are numbered 1..n as in the model's link order; vectors are in the base frame."""

    def __init__(self, robot: Robot, newton_euler_ctx: dict, newton_euler_expected: dict):
        self.robot = robot
        self.ctx = newton_euler_ctx
        self.ne = newton_euler_expected  # ("omega", i) -> ω_i in frame i
        self.names = list(robot.links)
        self.q, self.qd = robot.q, robot.qd

    @cached_property
    def _energies(self):
        T_trans, T_rot, V, _ = link_energies(self.robot)
        return T_trans, T_rot, V

    def speed_squared(self, i: int, build):
        """Link i's squared speed as shown (``build()``, tidied once: a text may give the speed often)."""
        cache = self.__dict__.setdefault("_speed_squared", {})
        if i not in cache:
            cache[i] = build()
        return cache[i]

    def kinetic(self, i: int):
        T_trans, T_rot, _ = self._energies
        return T_trans[self.names[i]] + T_rot[self.names[i]]

    def potential(self, i: int):
        return self._energies[2][self.names[i]]

    @property
    def origins(self) -> dict:
        """Each frame's origin in the base frame (frame number -> 3-vector)."""
        return self._origins

    @cached_property
    def _origins(self) -> dict:
        p0 = {0: sp.zeros(3, 1)}
        for i in range(1, len(self.names)):
            parent = self.ctx[i]["parent"]
            p0[i] = p0[parent] + self.ctx["R0"][parent] * self.ctx[i]["P"]
        return p0

    def position(self, i: int) -> sp.Matrix:
        """Link i's mass centre in the base frame."""
        return sp.Matrix(self._origins[i] + self.ctx["R0"][i] * self.ctx[i]["c"])

    def velocity(self, i: int) -> sp.Matrix:
        return sp.Matrix(time_derivative(self.position(i), self.q, self.qd))

    def angular_velocity(self, i: int) -> sp.Matrix:
        """ω_i in the base frame."""
        return sp.Matrix(self.ctx["R0"][i] * self.ne[("omega", i)])

    def jacobian(self, kind: str, i: int) -> sp.Matrix:
        if kind == "Jv":
            return self.position(i).jacobian(self.q)
        return self.angular_velocity(i).jacobian(self.qd)

    def angular_momentum(self, i: int) -> sp.Matrix:
        """I_i ω_i about link i's mass centre, in frame i."""
        return sp.Matrix(self.ctx[i]["I"] * self.ne[("omega", i)])

    @cached_property
    def eom(self):
        return lagrange(self.robot)

    @cached_property
    def M(self) -> sp.Matrix:
        return self.eom.M

    def christoffel(self, i: int, j: int, k: int):
        """Spong's c_ijk (1-based) of the mass matrix."""
        M, q = self.M, self.q
        i, j, k = i - 1, j - 1, k - 1
        return sp.Rational(1, 2) * (sp.diff(M[k, j], q[i]) + sp.diff(M[k, i], q[j]) - sp.diff(M[i, j], q[k]))

    @cached_property
    def C(self) -> sp.Matrix:
        return self.eom.C

    @cached_property
    def h(self) -> sp.Matrix:
        """The centrifugal and Coriolis vector C(q, q̇) q̇ (Craig's V(θ, θ̇))."""
        return self.C * self.qd

    @cached_property
    def G(self) -> sp.Matrix:
        return self.eom.g


_WHAT = {
    "Tl": "link {i}'s kinetic energy ½ m v_c·v_c + ½ ωᵀ I ω",
    "Vl": "link {i}'s potential energy",
    "pc": "link {i}'s mass centre in the base frame",
    "vc": "the velocity of link {i}'s mass centre in the base frame",
    "w": "link {i}'s angular velocity",
    "Jv": "the Jacobian of link {i}'s mass-centre velocity (3 x n)",
    "Jw": "the Jacobian of link {i}'s angular velocity (3 x n)",
    "Lang": "link {i}'s angular momentum I ω about its mass centre, in frame {i}",
    "M": "the mass matrix",
    "christoffel": "the Christoffel symbol (" + SPONG + ")",
    "C": "the Coriolis matrix",
    "h": "the centrifugal and Coriolis vector C(q, q̇) q̇",
    "G": "the gravity vector ∂V/∂q",
}


def expected_of(terms: ModelTerms, ref):
    """The model's value of ``ref`` (StepRef with a key of MODEL_KEYS or "Lang")."""
    i, key = ref.index, ref.key
    axis = "xyz".index(ref.part) if ref.part in ("x", "y", "z") else None
    if key == "Tl":
        return terms.kinetic(i)
    if key == "Vl":
        return terms.potential(i)
    if key == "pc":
        p = terms.position(i)
        return p if axis is None else p[axis]
    if key == "vc":
        v = terms.velocity(i)
        if ref.part in ("sq", "speed"):
            return (v.T * v)[0, 0] if ref.part == "sq" else sp.sqrt((v.T * v)[0, 0])
        return v if axis is None else v[axis]
    if key == "w":
        return terms.angular_velocity(i)
    if key in ("Jv", "Jw"):
        return terms.jacobian(key, i)
    if key == "Lang":
        return terms.angular_momentum(i)
    if key == "christoffel":
        return terms.christoffel(*ref.entry)
    whole = {"M": lambda: terms.M, "C": lambda: terms.C, "h": lambda: terms.h, "G": lambda: terms.G}[key]()
    if ref.entry:
        return whole[ref.entry[0] - 1, ref.entry[1] - 1] if len(ref.entry) == 2 else whole[ref.entry[0] - 1]
    return whole


def _entries_ok(ref, n: int) -> str:
    """Why ``ref``'s indices do not fit an ``n``-joint robot ("" when they do)."""
    if ref.entry and not all(1 <= k <= n for k in ref.entry):
        return f"{ref.name}: index out of range (the robot has {n} joints)"
    return ""


def grade_model_step(grader, ref, eq, value) -> StepVerdict:
    """The verdict of an energy-method quantity ``ref`` whose value (SymPy) the student gave."""
    robot, sampler = grader.robot, grader.sampler
    n_links = len(robot.links) - 1
    base = dict(name=ref.name, key=ref.key, label=eq.lhs, source=eq.source, line=eq.line)
    if ref.index is not None and not 1 <= ref.index <= n_links:
        problem = f"{ref.name} names link {ref.index}, but '{robot.name}' has links 1..{n_links}"
        return StepVerdict(link="", status="unrecognised", message=problem, **base)
    if _entries_ok(ref, robot.dof):
        return StepVerdict(link="", status="unrecognised", message=_entries_ok(ref, robot.dof), **base)
    terms = grader.model_terms()
    expected = expected_of(terms, ref)
    link = list(robot.links)[ref.index] if ref.index is not None else ""
    what = _WHAT[ref.key].format(i=ref.index)
    got, expected, note = _fit(ref, value, expected, sampler)
    if got is None:
        return StepVerdict(link=link, status="unrecognised", message=f"{ref.name}: {note} ({what})", **base)
    fp = sampler.fingerprint
    ok = equal(fp(got), fp(expected)).ravel()
    status, convention, message = ("correct", None, note) if ok.all() else ("wrong", None, "")
    if not ok.all():
        convention = _convention(ref, got, expected, terms, sampler)
        if convention:
            status, message = "correct-by-convention", convention
    components = [int(k) for k in range(len(ok)) if not ok[k]] if status == "wrong" else []
    speed = ref.key == "vc" and ref.part == "speed"  # a speed: its square is shown (no roots to expand)
    squared = terms.speed_squared(ref.index, lambda: tidy(expected**2, robot)) if speed else None
    if status == "wrong" and speed:
        message = f"squared, it is not the squared speed {pretty(squared)} ({what})"
    elif status == "wrong":
        g_m, e_m = _matrix(got), _matrix(expected)
        message = (
            "; ".join(
                _where(k, e_m.shape) + describe(g_m[k], e_m[k], robot, sampler, shorthand=grader.symbols.shorthand)
                for k in components[:3]
            )
            + f" ({what})"
        )
        if ref.key == "C":
            message = _coriolis_wrong(got, terms, sampler) + f" ({what})"
    diff = None
    if status == "wrong" and not speed:
        d = g_m - e_m
        diff = d.applyfunc(lambda x: tidy(x, robot)) if d.shape != (1, 1) else tidy(d[0], robot)
    shown = (
        (expected.applyfunc(lambda x: tidy(x, robot)) if isinstance(expected, sp.MatrixBase) else tidy(expected, robot))
        if not speed
        else sp.sqrt(squared)
    )
    return StepVerdict(
        link=link,
        status=status,
        expected=shown,
        got=got,
        difference=diff,
        components=components,
        convention=convention,
        message=message,
        **base,
    )


def _where(k: int, shape) -> str:
    if shape == (1, 1):
        return ""
    if shape[1] == 1:
        return f"entry {k + 1}: "
    return f"entry ({k // shape[1] + 1}, {k % shape[1] + 1}): "


def _matrix(x) -> sp.Matrix:
    return x if isinstance(x, sp.MatrixBase) else sp.Matrix([[x]])


def _fit(ref, value, expected, sampler):
    """(got, expected, note) with the value shaped as the expected one, or (None, _, why)."""
    exp_shape = expected.shape if isinstance(expected, sp.MatrixBase) else (1, 1)
    if isinstance(value, sp.MatrixBase) and value.shape == (1, 1):
        value = value[0, 0]
    shape = value.shape if isinstance(value, sp.MatrixBase) else (1, 1)
    if ref.key == "w" and shape == (1, 1):  # planar: ω about the one axis all joints share
        fp = sampler.fingerprint
        zero = [k for k in range(3) if np.allclose(fp(expected[k]), 0)]
        if len(zero) != 2:
            return None, expected, "a scalar angular velocity, but this robot's link turns about more than one axis"
        axis = ({0, 1, 2} - set(zero)).pop()
        return value, expected[axis], f"the scalar read as the {'xyz'[axis]} component in the base frame"
    if shape == exp_shape:
        return value, expected, ""
    if exp_shape[1] == 1 and shape == (1, exp_shape[0]):
        return value.T, expected, ""
    if exp_shape == (3, 1) and shape in ((2, 1), (1, 2)) and ref.key in ("pc", "vc"):  # a planar (x, y)
        if not np.allclose(sampler.fingerprint(expected[2]), 0):
            return None, expected, "two components given, but the model's z component is not zero"
        return sp.Matrix(list(value)), expected[:2, 0], "(x, y) compared: z is 0 in the model"
    if shape == (1, 1) and value == 0 and exp_shape != (1, 1):
        return sp.zeros(*exp_shape), expected, ""
    if ref.key == "Tl" and shape == (4, 4):
        return None, expected, "a 4x4 matrix is a homogeneous transform, not graded (a scalar T_i is a kinetic energy)"
    what = "a scalar" if shape == (1, 1) else f"a {shape[0]}x{shape[1]} matrix"
    want = "a scalar" if exp_shape == (1, 1) else f"{exp_shape[0]}x{exp_shape[1]}"
    return None, expected, f"the value is {what}; expected {want}"


def _convention(ref, got, expected, terms: ModelTerms, sampler) -> str | None:
    """The named convention under which ``got`` is right, or None."""
    fp = sampler.fingerprint
    if ref.key == "Vl" or (ref.key == "V"):
        d = sp.sympify(got - expected)
        if all(np.allclose(fp(sp.diff(d, q)), 0) for q in list(terms.q) + list(terms.qd)):
            return f"another reference level for the potential energy (yours = the model's + {tidy(d, terms.robot)})"
    if ref.key == "christoffel":
        i, j, k = ref.entry
        if equal(fp(got), fp(terms.christoffel(j, k, i))).all():
            return f"Christoffel symbol with {FREE_FIRST}, not {SPONG}"
        M, q = terms.M, terms.q
        lavalle = sp.diff(M[i - 1, j - 1], q[k - 1]) - sp.diff(M[j - 1, k - 1], q[i - 1]) / 2
        if equal(fp(got), fp(lavalle)).all():
            return f"{LAVALLE}, not {SPONG} (the same Coriolis terms once summed over j and k)"
    if ref.key == "h":
        with_gravity = terms.h + terms.G
        if ref.entry:
            with_gravity = with_gravity[ref.entry[0] - 1]
        if equal(fp(got), fp(with_gravity)).all():
            return "Lynch & Park's h(θ, θ̇) = c(θ, θ̇) + g(θ): the Coriolis and centrifugal terms with gravity"
    if ref.key == "C":
        if equal(fp(got * terms.qd), fp(terms.h)).all():
            Mdot = time_derivative(terms.M, terms.q, terms.qd)
            N = Mdot - 2 * got
            skew = equal(fp(N + N.T), fp(sp.zeros(*N.shape))).all()
            return "C q̇ is the Coriolis/centrifugal vector, but C is not the Christoffel factorisation" + (
                " (Ṁ − 2C is still skew-symmetric)" if skew else " (Ṁ − 2C is not skew-symmetric)"
            )
    return None


def _coriolis_wrong(got, terms: ModelTerms, sampler) -> str:
    """What is wrong with a Coriolis matrix: its product with q̇, entry by entry."""
    fp = sampler.fingerprint
    cq = got * terms.qd
    ok = equal(fp(cq), fp(terms.h)).ravel()
    bad = [k + 1 for k in range(len(ok)) if not ok[k]]
    return f"C q̇ differs from the centrifugal and Coriolis vector in entr{'y' if len(bad) == 1 else 'ies'} " + (
        ", ".join(map(str, bad))
    )


def potential_shift(value, expected, q, sampler):
    """The constant by which a potential energy (or Lagrangian) ``value`` differs from
    ``expected`` when the difference does not depend on any of ``q``; else None."""
    d = sp.sympify(value - expected)
    fp = sampler.fingerprint
    if np.allclose(fp(d), 0):
        return None
    if all(np.allclose(fp(sp.diff(d, x)), 0) for x in q):
        return d
    return None


def coriolis_entries_as_matrix(verdicts: list, terms: "ModelTerms", sampler) -> None:
    """Every entry ``C_{ij}`` written one by one and the matrix they make gives ``C q̇ = h``:
    a Coriolis matrix other than the Christoffel one (C is not unique; ``C q̇`` is), so an
    entry that differs from the Christoffel entry is right by that convention, not wrong.
    Changes ``verdicts`` in place; nothing when an entry is missing or the product differs."""
    n = terms.M.shape[0]
    entries = {}
    for v in verdicts:  # the latest value of each entry, as the student restates it
        if v.key == "C" and v.got is not None and not isinstance(v.got, sp.MatrixBase):
            parts = v.name.split("_")[-1]
            if len(parts) == 2 and parts.isdigit() and all(1 <= int(k) <= n for k in parts):
                entries[(int(parts[0]) - 1, int(parts[1]) - 1)] = v
    if len(entries) != n * n or not any(v.status == "wrong" for v in entries.values()):
        return
    C = sp.Matrix(n, n, lambda i, j: entries[(i, j)].got)
    fp = sampler.fingerprint
    if not equal(fp(C * terms.qd), fp(terms.h)).all():
        return
    for v in entries.values():
        if v.status == "wrong":
            v.status, v.convention = "correct-by-convention", "a Coriolis matrix other than the Christoffel one"
            v.message = (
                "your entries make a Coriolis matrix whose C q̇ is the centrifugal and Coriolis vector: not the "
                "Christoffel factorisation, which this entry's expected value is (C is not unique; C q̇ is)"
            )
