"""The laws of the method as the textbooks state them (Craig; Spong, Hutchinson & Vidyasagar;
Siciliano et al.; Lynch & Park), in generic quantities: :data:`LAWS`, each with its textbook
forms (sums of :class:`Term`) and the vocabulary of generic names (:func:`classify`) a
statement of it is read with. :mod:`.laws` judges a statement against them; Craig's
iterations are :mod:`.law_table_ne`'s.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass, field

import sympy as sp

from .latex import Name
from .law_reading import NotALaw, Quantity, Values, entry_indices, index_value

_SCALAR_ROLES = {"m", "h", "const", "KE", "PE", "L", "q", "Mentry", "chr", "Centry", "gterm", "tau", "dM", "dP"}
_VECTOR_ROLES = {"v", "omega", "F", "N", "f", "n", "pc", "po", "g"}
_CENTRE = ("C", "c", "G", "cm")


def _centre_split(sub: str) -> tuple[bool, str]:
    """``C_i`` -> (True, "i"); ``c1`` -> (True, "1"); ``i+1`` -> (False, "i+1")."""
    s = sub.replace("{", "").replace("}", "").replace(" ", "")
    for mark in ("cm", "C", "c", "G"):
        if s.startswith(mark) and s != mark[:1] or s == mark:
            rest = s[len(mark) :].lstrip("_,")
            if rest == "" or rest[0] in "ijkn0123456789(":
                return True, rest
    return False, s


def add_terms(a, b):
    """a + b, None the empty sum (0 + a matrix is no sum in SymPy)."""
    if a is None:
        return b
    if isinstance(a, sp.MatrixBase) != isinstance(b, sp.MatrixBase):
        zero = a if not isinstance(a, sp.MatrixBase) else b
        if zero == 0:
            return b if zero is a else a
    return a + b


def _kind(role: str, world: str, entry: tuple = ()) -> str:
    if role in _SCALAR_ROLES:
        return "scalar"
    if role in _VECTOR_ROLES:
        return "vector" if world == "space" else "scalar"
    if role == "I":
        return "tensor" if world == "space" else "scalar"
    return {
        "Z": "axis",
        "qvec": "joints",
        "Mmat": "joint-matrix",
        "Jv": "jacobian",
        "Jw": "jacobian",
        "Gvec": "joints",
    }.get(role, "rotation")


def _energy(base: str, sub: str, family: str) -> tuple[str, str] | None:
    """``K_i``, ``T``, ``k``, ``\\mathrm{KE}``, ``E_{K_i}``: ("KE" | "PE", the link's index text)
    (a bare ``T`` only where no transpose can be meant: a left-hand side, the Lagrangian)."""
    if base in ("K", "k", "KE", "Ek") or base == "T" and (sub or family in ("lhs", "L")):
        return "KE", sub
    if base in ("U", "u", "PE", "Ep"):
        return "PE", sub
    if base == "E" and sub[:1] in ("K", "k", "P", "p"):
        return ("KE" if sub[0] in "Kk" else "PE"), sub[1:].lstrip("_,")
    return None


def classify(name: Name, family: str, world: str, binding: dict) -> tuple[Quantity, str]:
    """The quantity a generic name stands for in a law of ``family`` (``"lhs"`` for the
    left-hand side), and the kind of its value; :class:`NotALaw` when it is none."""
    base, sub, dots = name.base, name.sub.replace(" ", ""), name.dots
    frame = None
    if name.pre_sup and not name.pre_sup.startswith(("C", "c")) and family in ("NE", "lhs"):
        frame = index_value(name.pre_sup, binding)
    centre, rest = _centre_split(sub)

    def q(role, link_text=rest, **kw):
        link = index_value(link_text, binding)
        quantity = Quantity(role, link, kw.pop("frame", frame), kw.pop("dots", dots), kw.pop("centre", False), **kw)
        return quantity, _kind(role, world, quantity.entry)

    letters = sub.replace("{", "").replace("}", "").replace(",", "")
    pair = entry_indices(letters, binding, 2) if len(letters) == 2 else None
    triple = entry_indices(letters, binding, 3) if len(letters) == 3 else None
    if base in ("u", "U", "V", "P") and sub in ("ref", "0", "o", "{ref}") and family in ("PE", "L"):
        return q("const", "", frame=None)
    if base in ("c", "C", "Gamma") and triple is not None:
        return Quantity("chr", None, None, 0, False, triple), "scalar"
    if base in ("c", "C") and pair is not None and family in ("lhs", "Centry"):
        return Quantity("Centry", None, None, 0, False, pair), "scalar"
    if base in ("M", "D", "H", "B", "d", "m") and pair is not None:
        return Quantity("Mentry", None, None, 0, False, tuple(sorted(pair))), "scalar"
    if base in ("M", "D", "H", "B") and not sub and family in ("lhs", "KE", "M"):
        return q("Mmat", "")
    if base in ("phi", "g", "G") and family in ("lhs", "gterm") and sub and not centre:
        return q("gterm")
    if base == "G" and not sub and family == "lhs":  # the gravity vector g(q) of the equations of motion
        return q("Gvec", "", frame=None)
    if base == "m" and not centre:
        return q("m", frame=None, dots=0)
    if base in ("omega", "w") and not centre:
        return q("omega")
    if base == "I":
        if name.pre_sup.startswith(("C", "c")) and not rest:
            _, rest = _centre_split(name.pre_sup)
        return q("I", rest, dots=0)
    if base == "J" and sub:
        head = sub.replace("{", "").replace("}", "")
        for mark, role in (("omega", "Jw"), ("w", "Jw"), ("v", "Jv")):
            if head.startswith(mark):
                return q(role, head[len(mark) :].lstrip("_,"), frame=None)
        raise NotALaw(f"J_{{{sub}}}")
    if base in ("theta", "q", "d", "Theta") and (dots or family != "lhs"):
        if not sub:
            return q("qvec", "", frame=None)
        return q("q", frame=None)
    if base in ("Z", "z") and (name.hat or base == "Z"):
        return q("Z", dots=0)
    if base == "R":
        if name.pre_sup and name.pre_sub:
            to, frm = index_value(name.pre_sup, binding), index_value(name.pre_sub, binding)
        elif sub:
            to, frm = 0, index_value(sub, binding)
        else:
            raise NotALaw("a rotation without its frames")
        return Quantity("R", None, None, 0, False, (to, frm)), "rotation"
    if family == "lhs" and base == "L" and not sub:
        return q("L", "")
    energy = _energy(base, sub, family) if family in ("lhs", "KE", "PE", "L", "gterm") else None
    if energy is None and base in ("P", "V") and family in ("lhs", "L", "gterm", "PE") and not centre:
        energy = ("PE", sub)
    if energy is not None and not (family == "KE" and base == "V") and not (family == "PE" and base == "P" and centre):
        role, link = energy
        return q(role, link, frame=None, dots=0)
    if base in ("v", "V") and family in ("KE", "NE", "lhs"):
        return q("v", centre=centre or family == "KE")
    if base == "g" and not sub:
        return q("g", "", frame=None, dots=0)
    if base in ("P", "p", "r") and (centre or name.pre_sup):
        return q("pc" if centre else "po", dots=0)
    if base == "P" and family == "NE":
        return q("po", dots=0)
    if base in ("y", "z") and family == "PE":  # the height of a mass centre, y or z up
        return q("h", frame=None, dots=0, centre=False)
    if base == "h":
        return q("h", frame=None, dots=0)
    if base in ("F", "N", "f", "n") and family in ("lhs", "NE") and sub:
        return q(base, dots=0)
    if base == "tau" and sub:
        return q("tau", frame=None, dots=0)
    raise NotALaw(f"{name.latex()} is not a generic quantity of the method")


# -- the laws
@dataclass
class Term:
    """One term of a law's form: what it is (for messages) and its value."""

    what: str
    value: object  # (Ctx) -> value
    optional: bool = False  # may be left out (a point mass's rotation; a reference level)


@dataclass
class Form:
    """A textbook form of a law: whose, and its terms (summed)."""

    source: str
    terms: list
    note: str = ""  # said with a correct verdict (a convention assumed)


@dataclass
class Law:
    """A law: the role its left-hand side names, the family of names its right-hand side
    uses, how it is stated, its forms, and slips that are no term's (``(message, form)``)."""

    role: str
    family: str
    name: str
    stated: str
    forms: list
    slips: list = field(default_factory=list)
    indexed: bool | None = None  # the left-hand side carries a link index (None: either)
    method: str = "lagrange"


class Ctx:
    """The values a form is evaluated at: the same as the student's names read there."""

    def __init__(self, values: Values, world: str, link: int | None, entry: tuple, transpose: bool = False):
        self.values, self.world, self.link, self.entry = values, world, link, entry
        self.transpose = transpose  # a slip: the rotations transposed

    def __call__(self, role: str, link=None, dots: int = 0, centre: bool = False, entry: tuple = (), frame=None):
        kind = _kind(role, self.world, entry)
        quantity = Quantity(role, link, frame, dots, centre, entry)
        value = self.values.get((role, link, dots, centre, entry), kind)
        if kind in ("vector", "axis") and frame is not None and native_frame(quantity) not in (None, frame):
            value = self.values.rotation(frame, native_frame(quantity)) * value
        return value

    def at(self, link: int) -> Ctx:
        """The same values, for link ``link`` (a law's term summed over the links)."""
        return Ctx(self.values, self.world, link, self.entry, self.transpose)

    def rot(self, to: int, frm: int):
        return self.values.rotation(frm, to) if self.transpose else self.values.rotation(to, frm)


def native_frame(q: Quantity) -> int | None:
    """The frame a vector's value is drawn in: its link's (an origin: the frame before)."""
    if q.link is None:
        return None
    return q.link - 1 if q.role == "po" else q.link


def dot(a, b):
    if isinstance(a, sp.MatrixBase):
        return (a.T * b)[0, 0]
    return a * b


def cross(a, b):
    return a.cross(b) if isinstance(a, sp.MatrixBase) else sp.Integer(0)


def quad(w, inertia, u):
    if isinstance(w, sp.MatrixBase):
        return (w.T * inertia * u)[0, 0]
    return inertia * w * u


def _n(c: Ctx) -> int:
    return c.values.n


HALF = sp.Rational(1, 2)
_KE_LINK = Law(
    "KE",
    "KE",
    "the kinetic energy of a body",
    "K = ½ m v_Cᵀ v_C + ½ ωᵀ I ω",
    [
        Form(
            "Craig, Siciliano",
            [
                Term(
                    "the translational term ½ m vᵀv",
                    lambda c: HALF * c("m", c.link) * dot(*[c("v", c.link, centre=True)] * 2),
                ),
                Term(
                    "the rotational term ½ ωᵀ I ω",
                    lambda c: HALF * quad(c("omega", c.link), c("I", c.link), c("omega", c.link)),
                    optional=True,
                ),
            ],
        ),
        Form(
            "Spong (inertia in the body frame)",
            [
                Term(
                    "the translational term ½ m vᵀv",
                    lambda c: HALF * c("m", c.link) * dot(*[c("v", c.link, centre=True)] * 2),
                ),
                Term(
                    "the rotational term ½ ωᵀ R I Rᵀ ω",
                    lambda c: (
                        HALF
                        * quad(
                            c("omega", c.link), c.rot(0, c.link) * c("I", c.link) * c.rot(c.link, 0), c("omega", c.link)
                        )
                    ),
                ),
            ],
        ),
        Form(
            "Spong, Lynch & Park (the mass matrix)",
            [Term("½ q̇ᵀ M q̇", lambda c: HALF * quad(c("qvec", dots=1), c("Mmat"), c("qvec", dots=1)))],
        ),
    ],
)
_KE_SUM = Law(
    "KE",
    "KE",
    "the total kinetic energy",
    "K = Σᵢ Kᵢ",
    [Form("", [Term("Σᵢ Kᵢ", lambda c: _sum_links(c, lambda i: c("KE", i)))])],
    indexed=False,
)
_PE = Law(
    "PE",
    "PE",
    "the potential energy of a body",
    "u = −m gᵀ P_C + u_ref (g along gravity), P = m g h",
    [
        Form(
            "Craig (g along gravity)",
            [
                Term("−m gᵀ P_C", lambda c: -c("m", c.link) * dot(c("g"), c("pc", c.link))),
                Term("a reference level", lambda c: c("const"), optional=True),
            ],
            note="g the gravity vector (pointing down)",
        ),
        Form(
            "Spong (g against gravity)",
            [
                Term("m gᵀ r_c", lambda c: c("m", c.link) * dot(c("g"), c("pc", c.link))),
                Term("a reference level", lambda c: c("const"), optional=True),
            ],
            note="g read as pointing up, as Spong's gᵀ r_c (Craig's −m gᵀP with g pointing down is the same)",
        ),
        Form(
            "m g h",
            [
                Term("m g h", lambda c: c("m", c.link) * c("g") * c("h", c.link)),
                Term("a reference level", lambda c: c("const"), optional=True),
            ],
        ),
        Form(
            "the sum over the links",
            [
                Term("Σᵢ Pᵢ", lambda c: _sum_links(c, lambda i: c("PE", i))),
                Term("a reference level", lambda c: c("const"), optional=True),
            ],
        ),
    ],
)


def _summed(form: Form) -> Form:
    """A link's form summed over the links (``K = \\sum_i \\frac12 m_i v_i^T v_i + …``); a
    reference level is added once."""

    def term(t: Term) -> Term:
        if "reference" in t.what:
            return t
        return Term(f"{t.what}, summed over the links", lambda c: _sum_links(c, lambda i: t.value(c.at(i))), t.optional)

    return Form(f"{form.source}, summed over the links", [term(t) for t in form.terms], form.note)


_KE_SUM.forms += [_summed(f) for f in _KE_LINK.forms[:2]]
_PE.forms += [_summed(f) for f in _PE.forms[:3]]


_LAGRANGIAN = Law(
    "L",
    "L",
    "the Lagrangian",
    "L = K − P",
    [
        Form(
            "", [Term("the kinetic energy K", lambda c: c("KE")), Term("the potential energy −P", lambda c: -c("PE"))]
        ),
        Form(
            "per link",
            [
                Term("the kinetic energies Σ Kᵢ", lambda c: _sum_links(c, lambda i: c("KE", i))),
                Term("the potential energies −Σ Pᵢ", lambda c: -_sum_links(c, lambda i: c("PE", i))),
            ],
        ),
    ],
)
_MASS_MATRIX = Law(
    "Mmat",
    "M",
    "the mass matrix from the Jacobians",
    "D(q) = Σᵢ mᵢ J_vᵢᵀ J_vᵢ + J_ωᵢᵀ Rᵢ Iᵢ Rᵢᵀ J_ωᵢ",
    [
        Form(
            "Spong",
            [
                Term(
                    "the translational part Σ m J_vᵀ J_v",
                    lambda c: _sum_links(c, lambda i: c("m", i) * _jj(c, "Jv", i)),
                ),
                Term(
                    "the rotational part Σ J_ωᵀ R I Rᵀ J_ω",
                    lambda c: _sum_links(
                        c, lambda i: c("Jw", i).T * c.rot(0, i) * c("I", i) * c.rot(i, 0) * c("Jw", i)
                    ),
                ),
            ],
        ),
        Form(
            "inertia in the base frame",
            [
                Term(
                    "the translational part Σ m J_vᵀ J_v",
                    lambda c: _sum_links(c, lambda i: c("m", i) * _jj(c, "Jv", i)),
                ),
                Term(
                    "the rotational part Σ J_ωᵀ I J_ω",
                    lambda c: _sum_links(c, lambda i: c("Jw", i).T * c("I", i) * c("Jw", i)),
                ),
            ],
        ),
    ],
    indexed=False,
)


def _sum_links(c: Ctx, f):
    return sum((f(i) for i in range(2, _n(c) + 1)), f(1))


def _jj(c: Ctx, role: str, i: int):
    return c(role, i).T * c(role, i)


def _christoffel(free: int):
    """The Christoffel symbol with its free index in slot ``free`` (0, 1, 2) of the entry."""

    def terms():
        def dm(c, a, b, by):
            return c("dM", entry=(tuple(sorted((c.entry[a], c.entry[b]))), c.entry[by]))

        x, y = [s for s in range(3) if s != free]
        return [
            Term("a derivative by a paired index (added)", lambda c: HALF * dm(c, free, x, y)),
            Term("the other derivative by a paired index (added)", lambda c: HALF * dm(c, free, y, x)),
            Term("the derivative by the free index (subtracted)", lambda c: -HALF * dm(c, x, y, free)),
        ]

    return Form(["free index first", "free index second", "free index last"][free], terms())


_CHRISTOFFEL = Law(
    "chr",
    "chr",
    "the Christoffel symbol",
    "c_ijk = ½(∂d_kj/∂q_i + ∂d_ki/∂q_j − ∂d_ij/∂q_k)",
    [_christoffel(0), _christoffel(1), _christoffel(2)],
)


def _coriolis(order: tuple):
    def value(c):
        row, col = c.entry
        total = None
        for k in range(1, _n(c) + 1):
            slots = {"r": row, "c": col, "k": k}
            total = add_terms(total, c("chr", entry=tuple(slots[s] for s in order)) * c("q", k, dots=1))
        return total

    return Form("", [Term("Σ_k c q̇_k", value)])


_CORIOLIS = Law(
    "Centry",
    "Centry",
    "the Coriolis matrix from the Christoffel symbols",
    "c_kj = Σᵢ c_ijk q̇ᵢ",
    [_coriolis(p) for p in itertools.permutations("rck")],
)
_GRAVITY_TERM = Law(
    "gterm",
    "gterm",
    "the gravity term",
    "g_k = ∂P/∂q_k",
    [Form("", [Term("∂P/∂q_k", lambda c: c("dP", entry=(c.link,)))])],
)


_GRAVITY_VECTOR = Law(
    "Gvec",
    "Gvec",
    "the gravity vector from the Jacobians",
    "G(q) = −Σᵢ J_vᵢᵀ mᵢ g (g along gravity)",
    [
        Form(
            "g along gravity",
            [Term("−Σ J_vᵀ m g", lambda c: -_sum_links(c, lambda i: c("Jv", i).T * c("m", i) * c("g")))],
            note="g the gravity vector (pointing down)",
        ),
        Form(
            "g against gravity (Spong)",
            [Term("Σ J_vᵀ m g", lambda c: _sum_links(c, lambda i: c("Jv", i).T * c("m", i) * c("g")))],
            note="g read as pointing up, as Spong's",
        ),
    ],
    indexed=False,
)
_ROTATION = Law(
    "R",
    "R",
    "the inverse rotation",
    "{}^{B}_{A}R = ({}^{A}_{B}R)^T",
    [Form("", [Term("the rotation", lambda c: c.rot(*c.entry))])],
)
#: the laws of the energy method (Craig's iterations: :mod:`.law_table_ne`)
LAGRANGE_LAWS = [
    _KE_LINK,
    _KE_SUM,
    _PE,
    _LAGRANGIAN,
    _MASS_MATRIX,
    _CHRISTOFFEL,
    _CORIOLIS,
    _GRAVITY_TERM,
    _GRAVITY_VECTOR,
    _ROTATION,
]
