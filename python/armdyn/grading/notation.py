"""The student's notation: which step an equation's left-hand side names, and which
model symbol each of their symbols is.

Left-hand sides understood (``i`` a link index, ``k`` a joint index, ``j`` a frame; a
frame given neither as a superscript nor as Craig's pre-superscript is the link's own)::

    Newton-Euler  \\omega_i^j  {}^{j}\\omega_{i}  \\dot{\\omega}_i^j  \\dot{v}_i^j  \\dot{v}_{C_i}^j
                  (also \\dot{v}_{c_i}, \\dot{v}_{ci}, a_{C_i}), F_i^j, N_i^j, f_i^j, n_i^j,
                  m_i^j (read as n_i: the exercise's name for it), \\tau_k,
                  R_a^b / {}^{b}_{a}R (maps frame-a coordinates to frame b),
                  P_i^j (frame i's origin from frame i-1's, in frame j; j = i-1 if not
                  given), P_{C_i}^j (link i's mass centre from frame i's origin, in frame j)
    Lagrange      T, V, L, \\frac{\\partial L}{\\partial \\dot q_k}, \\partial L / \\partial \\dot q_k,
                  \\frac{d}{dt}\\frac{\\partial L}{\\partial \\dot q_k}, \\frac{\\partial L}{\\partial q_k}, \\tau_k
                  (also -\\frac{\\partial L}{\\partial q_k}: the negated partial, sign = -1);
                  the energies' partials \\frac{\\partial T}{\\partial \\dot q_k} (read as L's),
                  \\frac{\\partial T}{\\partial q_k}, \\frac{\\partial V}{\\partial q_k} (any energy name;
                  by the joint vector \\Theta: index None, a column)
    Spong         \\alpha_i (ω̇_i, by shape), a_{e,i} (the end of link i: key "ae", resolved on
                  the model's frames), g_i (gravity in frame i, by shape), a 3-vector \\tau_i (n_i)
    energy method the textbooks' names of :mod:`.vocabulary`: energies K, T, KE, E_k, U, V, P,
                  PE, E_p (per link with an index), mass centres p_{c1}, x_{c1}, v_{c1},
                  v_{c1}^2, Jacobians J_{v_1}, J_{\\omega_1}, D(q) / M(q) and d_{jk},
                  c_{ijk}, C(q, \\dot q), V(\\theta, \\dot\\theta) / h, g(q) / G and g_k,
                  (\\tau_1, \\tau_2)^T; a name marked ``by_shape`` (P_1, V, L, H, f_k, a
                  scalar \\omega_i) is decided by the value's shape in the grader

Mass centres are written C, c, G, cm in the subscript (``C_1``, ``c1``, ``G_1``, ``{cm,1}``).

Bold, hat and roman wrappers (\\mathbf, \\boldsymbol, \\bm, \\mathrm, \\vec) are looked
through. Symbols map to the model's by name (``\\theta_1`` -> ``theta1``,
``\\dot{d}_2`` -> ``d2_dot``, ``l_{c1}`` -> ``lc1``), by joint index for ``\\theta_k``,
``q_k`` and ``d_k`` when the model names its coordinates otherwise, as ``sin``/``cos``
for ``s_1``, ``c_{12}`` (``s_{12} = sin(q1 + q2)``), or through an explicit mapping.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Any

import sympy as sp

from ..model import Robot
from ..symbolic.newton_euler import VECTOR_STEP_TEXT
from .latex import LatexError, Name, UnknownSymbol, parse
from .vocabulary import MODEL_KEYS, energy_lhs, mass_centre, model_name, scripts

VECTOR_KEYS = tuple(VECTOR_STEP_TEXT)  # the Newton-Euler steps, from derive's table
LAGRANGE_KEYS = ("T", "V", "L", "dL_dqd", "ddt_dL_dqd", "dL_dq", "dT_dq", "dV_dq")


@dataclass(frozen=True)
class StepRef:
    """What a left-hand side names.

    key:    "omega", "omega_dot", "v_dot", "vc_dot", "F", "N", "f", "n", "tau", "R",
            "P" (frame i's origin from frame i-1's), "Pc" (link i's mass centre from frame
            i's origin), "T", "V", "L", "dL_dqd", "ddt_dL_dqd", "dL_dq"
    index:  link index for Newton-Euler vectors (0 = base), joint index (1-based) for
            tau and the Lagrange partials, None for T, V, L; for R the source frame
    frame:  frame the vector is written in (None: the link's own); for R the target frame
    alias:  the student's own name when it is not the usual one (``m`` for ``n``)
    """

    key: str
    index: int | None = None
    frame: int | None = None
    alias: str = ""
    #: energy method: "x"/"y"/"z" (one component of a position or velocity), "sq" (a squared speed)
    part: str = ""
    #: matrix entry (1-based): (j, k) of M, (i, j, k) of a Christoffel symbol, (k,) of h or G
    entry: tuple = ()
    #: the value's shape decides between two readings (see :func:`.vocabulary.by_shape`)
    by_shape: bool = False
    #: -1 for a left-hand side written negated (``-\frac{\partial L}{\partial q_1}``)
    sign: int = 1
    #: P, Pc written with Craig's pre-superscript ``{}^{j}P_{C_i}``: the vector starts at frame j's origin
    origin: int | None = None

    @property
    def name(self) -> str:
        if self.key in MODEL_KEYS or self.key in ("Lang", "shorthand"):
            return model_name(self)
        if self.key == "R":
            return f"R_{self.index}^{self.frame}"
        if self.key in ("P", "Pc"):
            return f"P_{'C' if self.key == 'Pc' else ''}{self.index}" + (
                f"^{self.frame}" if self.frame is not None else ""
            )
        if self.index is None:
            return self.key
        return f"{self.key}_{self.index}"


_WRAP = re.compile(r"\\(?:mathbf|boldsymbol|bm|mathrm|mathit|vec|pmb|mathcal|hat)\s*\{([^{}]*)\}")
_WRAP_BARE = re.compile(r"\\(?:mathbf|boldsymbol|bm|mathrm|mathit|vec|pmb|mathcal|hat)\s*(\\[A-Za-z]+|[A-Za-z0-9])")


def normalise(lhs: str) -> str:
    """Drop spacing, \\left/\\right and typeface wrappers; ``\\dot x`` -> ``\\dot{x}``."""
    s = re.sub(r"\\(left|right)(?![A-Za-z])", "", lhs)
    s = re.sub(r"\\[,;:! ]|\\quad|\\qquad|\\displaystyle", "", s)
    for _ in range(6):
        t = _WRAP_BARE.sub(r"\1", _WRAP.sub(r"\1", s))
        if t == s:
            break
        s = t
    # Lagrange's primes for time derivatives: q_1' -> \dot{q}_1, \theta_1'' -> \ddot{\theta}_1
    s = re.sub(r"(\\[A-Za-z]+|[A-Za-z])(_\{[^{}]*\}|_[A-Za-z0-9])?('{1,2})", _primed, s)
    s = re.sub(r"\s+", "", s)
    s = re.sub(r"\\(d?dot)(\\[A-Za-z]+|[A-Za-z])", r"\\\1{\2}", s)
    s = re.sub(r"\{(\\d?dot\{[^{}]*\})\}", r"\1", s)  # {\dot q}_1 -> \dot{q}_1
    return s


def _primed(m) -> str:
    return f"\\{'dot' if len(m.group(3)) == 1 else 'ddot'}{{{m.group(1)}}}{m.group(2) or ''}"


def _int(text: str | None) -> int | None:
    if text is None:
        return None
    t = re.sub(r"[{}\s]", "", text).rstrip("T").replace("\\top", "")
    return int(t) if t.isdigit() else None


_BASES = {
    "\\omega": "omega",
    "F": "F",
    "N": "N",
    "f": "f",
    "n": "n",
    "m": "n",
    "\\tau": "tau",
    "v": "v",
    "a": "a",
    "R": "R",
    "P": "P",
    "\\alpha": "alpha",
}


_mass_centre = mass_centre


def parse_lhs(lhs: str, coordinate_of) -> StepRef | None:
    """The step an equation's left-hand side names, or None.

    ``coordinate_of(latex) -> (k, order)``: the 1-based joint index and derivative order
    (0, 1) of a coordinate symbol written in LaTeX, or None."""
    s = normalise(lhs)
    if not s:
        return None
    sign = 1
    if s.startswith("-") and len(s) > 1:  # -\frac{\partial L}{\partial q_1} = ...: the negated partial
        s, sign = s[1:], -1
    lag = _lagrange(s, coordinate_of)
    if lag is not None:
        return lag if sign == 1 else StepRef(lag.key, lag.index, alias=lag.alias, sign=-1)
    if sign == -1:
        return None
    s = re.sub(r"^\{(\\d?dot\{[^{}]*\})\}", r"\1", s)  # {\dot v}_{c_1}
    named = energy_lhs(s, lambda key, index=None, **kw: StepRef(key, index, **kw))
    if named is not None:
        return named

    # pre-scripts: {}^{j}_{a} or ^{j}
    pre_sub = pre_sup = None
    i = 0
    if s.startswith("{}"):
        i = 2
    if i < len(s) and s[i] in "_^":
        pre_sub, pre_sup, i = scripts(s, i)
    dots = 0
    m = re.match(r"\\(d?dot)\{", s[i:])
    if m:
        dots = 2 if m.group(1) == "ddot" else 1
        depth, j = 1, i + len(m.group(0))
        start = j
        while j < len(s) and depth:
            depth += {"{": 1, "}": -1}.get(s[j], 0)
            j += 1
        inner, rest = s[start : j - 1], s[j:]
        s, i = inner + rest, 0
        # scripts may sit inside the accent's braces: \dot{\omega_1}
    m = re.match(r"\\omega|\\tau|\\alpha|[A-Za-z]", s[i:])
    if not m:
        return None
    base = m.group(0)
    sub, sup, end = scripts(s, i + len(base))
    if end != len(s):
        return None
    if pre_sup is not None and sup is None:
        sup = pre_sup
    if base not in _BASES:
        return None
    key = _BASES[base]
    alias = "m" if base == "m" else ""
    if key == "R":
        if pre_sup is not None or pre_sub is not None:
            frm, to = _int(pre_sub if pre_sub is not None else sub), _int(pre_sup)
        else:
            frm, to = _int(sub), _int(sup)
        return StepRef("R", frm, to) if frm is not None and to is not None and dots == 0 else None
    if key == "tau":
        k = _int(sub)
        return StepRef("tau", k) if k is not None and dots == 0 else None
    frame = _int(sup)
    if key == "P":  # P_i^j: frame i's origin from frame i-1's; P_{C_i}^j: link i's mass centre from frame i's
        if dots or sub is None:
            return None
        origin = _int(pre_sup) if pre_sup is not None else None  # Craig's {}^{j}P: from frame j's origin
        centre = _mass_centre(sub)
        if centre is not None:
            return StepRef("Pc", centre, frame, origin=origin)
        return StepRef("P", _int(sub), frame, origin=origin) if _int(sub) is not None else None
    end_of = re.fullmatch(r"e(\d+)", _plain(sub)) if key == "a" and not dots else None
    if end_of:  # Spong's a_{e,i}: the acceleration of the end of link i (resolved on the model)
        return StepRef("ae", int(end_of.group(1)), frame)
    if key == "alpha":  # Spong's \alpha_i = \dot\omega_i; a scalar \alpha_i is a DH twist (by the value)
        index = _int(sub)
        return (
            StepRef("omega_dot", index, frame, alias="alpha", by_shape=True) if index is not None and not dots else None
        )
    if key in ("v", "a"):
        want = 1 if key == "v" else 0
        if dots != want or sub is None:
            return None
        centre = _mass_centre(sub)
        if centre is not None:
            return StepRef("vc_dot", centre, frame)
        return StepRef("v_dot", _int(sub), frame) if _int(sub) is not None else None
    if key == "omega":
        key = {0: "omega", 1: "omega_dot"}.get(dots)
    elif dots:
        return None
    index = _int(sub)
    if key is None or index is None:
        return None
    return StepRef(key, index, frame, alias)


#: the energy differentiated: the Lagrangian, the kinetic or the potential energy (any textbook's name)
_ENERGY = r"\\partial(L|K|T|KE|k|E_\{?k\}?|E_\{?kin\}?|U|V|P|PE|u|E_\{?p\}?|E_\{?pot\}?)"
_KINETIC_NAMES = re.compile(r"K|T|KE|k|E_\{?k\}?|E_\{?kin\}?")
#: the joint vector written without an index (\Theta, q, \dot\theta): a column of partials
_JOINT_VECTOR = re.compile(r"(\\dot\{)?(?:\\Theta|\\theta|\\vartheta|q)(?(1)\})")
#: (energy kind, derivative order of the coordinate, d/dt taken) -> the step (a partial of T by
#: a velocity is that of L: V does not depend on the velocities)
_PARTIAL_KEYS = {
    ("L", 1, True): "ddt_dL_dqd",
    ("L", 1, False): "dL_dqd",
    ("L", 0, False): "dL_dq",
    ("T", 1, True): "ddt_dL_dqd",
    ("T", 1, False): "dL_dqd",
    ("T", 0, False): "dT_dq",
    ("V", 0, False): "dV_dq",
}


def _lagrange(s: str, coordinate_of) -> StepRef | None:
    ddt = False
    for prefix in (r"\frac{d}{dt}", r"\dfrac{d}{dt}", "d/dt"):
        if s.startswith(prefix):
            s, ddt = s[len(prefix) :], True
            break
    if ddt and s.startswith("(") and s.endswith(")"):
        s = s[1:-1]
    if len(s) > 120:  # names no partial; bounds the expressions below
        return None
    m = re.fullmatch(r"\\d?frac\{" + _ENERGY + r"\}\{\\partial(.+)\}", s) or re.fullmatch(
        _ENERGY + r"/\\partial(.+)", s
    )
    if not m:
        return None
    energy = "L" if m.group(1) == "L" else "T" if _KINETIC_NAMES.fullmatch(m.group(1)) else "V"
    alias = "" if energy == "L" else m.group(1)
    found = coordinate_of(m.group(2))
    if found is None:
        vector = _JOINT_VECTOR.fullmatch(m.group(2))
        if vector is None:
            return None
        found = (None, 1 if vector.group(1) else 0)
    k, order = found
    key = _PARTIAL_KEYS.get((energy, order, ddt))
    return StepRef(key, k, alias=alias) if key else None


# ------------------------------------------------------------------ symbols


class SymbolMap:
    """Maps the student's symbols (:class:`~armdyn.grading.latex.Name`) to the model's.

    robot:     the model the student's frames follow
    explicit:  the student's symbol (LaTeX such as ``l_{c1}`` or a plain name such as
               ``lc_1``) -> model name (``lc1``), from the submission's front matter
    steps:     step name -> value, for right-hand sides that use earlier steps (``L = T - V``)
    """

    def __init__(self, robot: Robot, explicit: dict | None = None):
        self.robot = robot
        self.names: dict[str, sp.Symbol] = {}
        for k, name in enumerate(robot.coordinate_names):
            self.names[name] = robot.q[k]
            self.names[f"{name}_dot"] = robot.qd[k]
            self.names[f"{name}_ddot"] = robot.qdd[k]
        self.names.update(robot.parameters)
        self.explicit: dict[str, sp.Expr] = {}
        self.notes: list[str] = []
        self.steps: dict[str, object] = {}
        #: sin/cos of the angles the student wrote as shorthand -> a symbol printing as theirs (s₁₂)
        self.shorthand: dict = {}
        self.used_gravity_magnitude = False
        #: the hatted axes read as unit columns (\hat X_1), for the report's notes
        self.unit_axes: set[str] = set()
        #: the names the student gave values to (:class:`~.defined.DefinedNames`), when grading
        self.defined: Any = None  # duck-typed (lookup, model): .defined imports this module
        for student, model in (explicit or {}).items():
            key = self._key_of(str(student))
            target = self.names.get(str(model))
            if target is None:
                raise LatexError(
                    f"symbols: '{student}' maps to '{model}', which the model does not have "
                    f"(it has {', '.join(sorted(self.names))})"
                )
            self.explicit[key] = target

    @staticmethod
    def _key_of(text: str) -> str:
        """A student's symbol written in LaTeX or plainly -> the plain key ``base|dots|sub``."""
        if "\\" in text or "_" in text or "{" in text:
            try:
                names = []
                parse(text, lambda n: names.append(n) or sp.Integer(1))
                if len(names) == 1:
                    n = names[0]
                    return f"{n.base}|{n.dots}|{_plain(n.sub)}"
            except LatexError:
                pass
        return f"{text}|0|"

    def __call__(self, name: Name):
        if name.hat and not name.dots and name.base in UNIT_AXES:  # \hat X_1: the frame's own axis
            self.unit_axes.add("\\hat " + Name(name.base, sub=name.sub).latex())
            return sp.Matrix([1 if k == UNIT_AXES[name.base] else 0 for k in range(3)])
        sub = _plain(name.sub)
        key = f"{name.base}|{name.dots}|{sub}"
        if key in self.explicit:
            return self.explicit[key]
        if name.dots:
            undotted = f"{name.base}|0|{sub}"
            if undotted in self.explicit:
                return self._derivative(self.explicit[undotted], name.dots, name)
        plain = name.base + sub
        value = self.defined.lookup(name) if self.defined is not None else None
        if value is not None:  # a name the student gave a value to (.defined)
            return value
        if name.dots == 0 and plain in self.steps:
            return self.steps[plain]
        candidate = plain + {0: "", 1: "_dot", 2: "_ddot"}.get(name.dots, "?")
        if candidate in self.names:
            return self.names[candidate]
        if name.base in ("theta", "Theta", "q", "d", "vartheta") and sub.isdigit():
            k = int(sub)
            if 1 <= k <= self.robot.dof:
                return [self.robot.q, self.robot.qd, self.robot.qdd][min(name.dots, 2)][k - 1]
        if name.base in ("s", "c", "S", "C") and name.dots == 0 and sub.isdigit() and plain not in self.names:
            idx = [int(ch) for ch in sub]  # a repeated index (c_{112}) is a Christoffel symbol, not an angle sum
            if all(1 <= k <= self.robot.dof for k in idx) and len(set(idx)) == len(idx):
                angle = sum((self.robot.q[k - 1] for k in idx), sp.Integer(0))
                value = (sp.sin if name.base in "sS" else sp.cos)(angle)
                from ..symbolic.names import unicode_name

                self.shorthand[value] = sp.Symbol(unicode_name(name.base + sub) or name.base + sub)
                return value
        if name.base == "g" and not sub and name.dots == 0:
            magnitude = sp.sqrt(sum(c**2 for c in self.robot.gravity))
            if not magnitude.free_symbols:
                self.used_gravity_magnitude = True
                return sp.nsimplify(magnitude) if magnitude.is_Float else magnitude
        if name.base == "pi" and not sub:
            return sp.pi
        if name.base in JOINT_VECTOR and not sub and not name.sup and name.dots <= 2 and self.robot.dof > 1:
            # \dot q^T D(q) \dot q: the joint variables (their rates) as one column
            return sp.Matrix([self.robot.q, self.robot.qd, self.robot.qdd][name.dots])
        value = self.defined.model(name) if self.defined is not None else None
        if value is not None:  # a model quantity the student did not write (d_{11}): the model's
            return value
        raise UnknownSymbol(
            f"unknown symbol {name.latex()} (the model '{self.robot.name}' has "
            f"{', '.join(sorted(self.names))}; map it in the front matter's 'symbols')"
        )

    def _derivative(self, target, dots, name):
        for k, q in enumerate(self.robot.q):
            if target == q:
                return [self.robot.q, self.robot.qd, self.robot.qdd][dots][k]
        raise UnknownSymbol(f"unknown symbol {name.latex()}: '{target}' is not a joint coordinate")

    def coordinate_of(self, latex: str):
        """``(k, order)`` of a coordinate symbol written in LaTeX, or None."""
        try:
            value = parse(latex, self)
        except LatexError:
            return None
        for order, vec in enumerate((self.robot.q, self.robot.qd)):
            for k, sym in enumerate(vec):
                if value == sym:
                    return k + 1, order
        return None


#: the joint vector's letters, written without an index (``\dot q``, ``\ddot\theta``, ``\Theta``)
JOINT_VECTOR = ("q", "theta", "Theta", "vartheta")
#: the letters that under \hat are a frame's unit axes (Craig's X̂, Ŷ, Ẑ; x̂; î, ĵ, k̂) -> the axis
UNIT_AXES = {"X": 0, "Y": 1, "Z": 2, "x": 0, "y": 1, "z": 2, "i": 0, "j": 1, "k": 2}


def _plain(sub: str) -> str:
    """A subscript as plain text: ``{c1}``, ``c_1``, ``c,1``, ``\\mathrm{c}1`` -> ``c1``."""
    return re.sub(r"[{}\s,_]|\\mathrm|\\text", "", sub or "")
