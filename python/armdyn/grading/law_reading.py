"""Reading a law of the method as the textbooks state it: an equation in generic symbols.

A law is written before it is used, in the symbols of no particular robot: an index
(``k_i``, ``{}^{i+1}\\omega_{i+1}``, ``c_{ijk}``), a sum (``\\sum_{i=1}^{n} K_i``), names without
a link number (``\\frac12 m v^2``), the joint vector as a whole (``\\dot\\Theta^T M(\\Theta)
\\dot\\Theta``), partial derivatives (``\\frac{\\partial d_{kj}}{\\partial q_i}``). It is read
here into exact numbers: every generic quantity (a mass, a velocity, an inertia tensor, a
rotation between adjacent frames, a derivative of a mass-matrix entry...) gets a random
rational value (rotations exactly orthogonal, by the Cayley transform), every index
a number (``i = 1, 2``), and a sum is written out term by term; :mod:`.laws` compares the
result with the law's textbook form evaluated at the same values.

Nothing of the text is evaluated as code: a side is read by :func:`.latex.parse` with a
resolver (:class:`Reader`) that maps each name to its quantity; the sum and the partial
derivatives are first replaced by placeholder names (``\\mathrm{lawsum}_{0}``) whose parts
are read the same way. A name that is no generic quantity (``\\theta_1``, ``l_2``) raises
:class:`NotALaw`: the equation is then not a law statement.
"""

from __future__ import annotations

import random
import re
from dataclasses import dataclass

import sympy as sp

from .latex import LatexError, Name, UnknownSymbol, parse

#: letters that stand for an index in a law (``k_i``, ``c_{ijk}``, ``f_{n+1}``)
INDEX_LETTERS = "ijkn"
#: links a sum over ``i = 1..n`` is written out for
N_LINKS = 3
#: sums and derivatives beyond which a side is not read as a law (each is read once per index value)
MAX_SUMS, MAX_PARTIALS = 6, 24
#: commands that show a pattern, not a value (``m_1 g \\; \\cdots \\; m_n g``)
PATTERN = re.compile(r"\\(?:cdots|ldots|vdots|ddots|dots)\b")


class NotALaw(UnknownSymbol):
    """A name that is no generic quantity of the method: the equation states no law."""


@dataclass(frozen=True)
class Quantity:
    """A generic name read: ``role`` (``"m"``, ``"v"``, ``"omega"``...), the link it belongs
    to (None: the body of an unindexed law), the frame it is written in (None: its own),
    time derivatives, and for matrix entries and derivatives the indices (``entry``)."""

    role: str
    link: int | None = None
    frame: int | None = None
    dots: int = 0
    centre: bool = False
    entry: tuple = ()


# -- scripts and indices
_INDEX = re.compile(r"^\(?([ijkn]|\d)([+-]\d)?\)?$")
_CENTRE = re.compile(r"^(?:C|c|G|cm)[_,]?(.*)$")


def index_value(text: str, binding: dict) -> int | None:
    """The number an index written ``text`` stands for (``i+1`` with i = 1: 2), None when
    none is written; LatexError when it is no index."""
    text = text.replace("{", "").replace("}", "").replace(" ", "")
    if not text:
        return None
    m = _INDEX.match(text)
    if m is None:
        raise NotALaw(f"{text} is no index")
    head, shift = m.group(1), int(m.group(2) or 0)
    if head.isdigit():
        return int(head) + shift
    if head not in binding:
        raise NotALaw(f"the index {head} is not bound")
    return binding[head] + shift


def entry_indices(text: str, binding: dict, count: int) -> tuple | None:
    """``ijk`` / ``112`` / ``k,j`` as ``count`` numbers under ``binding``, or None."""
    text = re.sub(r"[{}\s,]", "", text)
    if len(text) != count:
        return None
    out = []
    for c in text:
        if c.isdigit():
            out.append(int(c))
        elif c in binding:
            out.append(binding[c])
        else:
            return None
    return tuple(out)


def script_letters(text: str) -> set[str]:
    """The index letters written in the scripts of ``text`` (``k_i``, ``c_{ijk}``, ``{}^{i+1}R``)."""
    found: set[str] = set()
    for m in re.finditer(r"[_^]\s*(\{(?:[^{}]|\{[^{}]*\})*\}|\\[A-Za-z]+|.)", text):
        body = re.sub(r"\\[A-Za-z]+", " ", m.group(1))
        body = re.sub(r"\b(?:ref|max|min|xx|yy|zz)\b", " ", body)
        for part in re.findall(r"[A-Za-z]+", body):
            if part in ("T", "top"):
                continue
            if all(c in INDEX_LETTERS for c in part) or re.fullmatch(r"[CcG][ijkn]", part):
                found.update(c for c in part if c in INDEX_LETTERS)
    return found


# -- the text before reading: sums, derivatives, argument lists
#: one argument a quantity depends on: the joint vector or its rates (``\dot\Theta``, ``\mathbf q``)
_ARG = (
    r"(?>(?:\\d?dot\s*)?\{?\s*(?:\\mathbf\s*\{\s*q\s*\}|\\boldsymbol\s*\{\s*\\?\w+\s*\}|\\Theta|\\theta|q"
    r"|\\mathbf\s*q)\s*\}?)"
)
#: atomic groups: a long list that does not close is refused in linear time
_ARGS = re.compile(
    r"(?P<head>(?<![A-Za-z\\])[A-Za-z]|(?<=_)\w|\\Gamma|\\phi|\}|\\mathbf\s*\{[A-Za-z]\})"
    r"\s*(?>\\left)?\(\s*" + _ARG + r"(?>\s*,\s*" + _ARG + r")*\s*(?>\\right)?\)"
)
#: a squared norm, \|v\|^2 or \lVert v \rVert^2 (its content without bars or groups)
_NORM = re.compile(
    r"(?:\\\||\\lVert)\s*([^|{}\\]*(?:\\[A-Za-z]+[^|{}\\]*|\{[^{}|]*\}[^|{}\\]*)*?)\s*(?:\\\||\\rVert)\s*\^\s*(?:\{\s*2\s*\}|2)"
)
_SUM = re.compile(r"\\sum\s*(?:\\limits|\\nolimits)?\s*")


def strip_arguments(text: str) -> str:
    """``M(\\Theta)`` -> ``M``, ``C(q, \\dot q)`` -> ``C``: the joint vector a quantity depends on."""
    return _ARGS.sub(lambda m: m.group("head"), text)


def _group_end(text: str, i: int) -> int:
    """The index just past the balanced group opening at ``text[i]`` (``{``, ``(``, ``[``)."""
    depth = 0
    j = i
    while j < len(text):
        c = text[j]
        if c == "\\":
            j += 2
            continue
        if c in "{([":
            depth += 1
        elif c in "})]":
            depth -= 1
            if depth == 0:
                return j + 1
        j += 1
    raise LatexError("unbalanced group")


def _script(text: str, i: int) -> tuple[str, int]:
    """The script starting at ``text[i]`` (after ``_``/``^``): its content and the end."""
    while i < len(text) and text[i] == " ":
        i += 1
    if i < len(text) and text[i] == "{":
        end = _group_end(text, i)
        return text[i + 1 : end - 1], end
    if text.startswith("\\", i):
        m = re.match(r"\\[A-Za-z]+", text[i:])
        if m:
            return m.group(0), i + len(m.group(0))
    return text[i : i + 1], i + 1


def _term_end(text: str, i: int) -> int:
    """Where the term starting at ``i`` ends: the next ``+``/``-`` at its depth, or the end
    of its group."""
    depth, j = 0, i
    while j < len(text):
        c = text[j]
        if c == "\\":
            m = re.match(r"\\(?:left|right|big|Big|bigg|Bigg)[lr]?", text[j:])
            j += len(m.group(0)) if m else 2
            continue
        if c in "{([":
            depth += 1
        elif c in "})]":
            if depth == 0:
                return j
            depth -= 1
        elif c in "+-=" and depth == 0 and j > i and text[j - 1] not in "_^":
            return j
        j += 1
    return j


class Placeholders:
    """Sums and derivatives of a side replaced by names ``\\mathrm{lawsum}_{k}``,
    ``\\mathrm{lawpd}_{k}`` (read by :class:`Reader`)."""

    def __init__(self):
        self.sums: list[tuple[str, int | str, str]] = []  # (index letter, upper bound, summand)
        self.partials: list[tuple[bool, str, str]] = []  # (d/dt before it, numerator, denominator)

    def prepare(self, text: str, bound: set) -> str:
        """``text`` with its sums and derivative fractions replaced (``bound``: index letters
        the left-hand side binds, which a sum's summand does not take)."""
        if text.count("\\sum") > MAX_SUMS or text.count("\\partial") > 2 * MAX_PARTIALS:
            raise NotALaw("too many sums or derivatives to read as a law")
        text = re.sub(r"\\space\b|\\,|\\;|\\!|\\quad", " ", text)
        text = re.sub(r"\{\s*(?=[\^_])", "{{}", text)  # {^i\omega_i}: the prescript of a group's name
        text = re.sub(r"\^\s*\{\s*(?:T|\\top)\s*\}\s*_\s*(\{[^{}]*\}|\w)", r"_\1^{T}", text)  # n^{T}_i: n_i^T
        text = _NORM.sub(lambda m: f"({m[1]})^T({m[1]})", text)  # \|v\|^2 = v^T v
        text = strip_arguments(text)
        text = self._partials(text)
        return self._sums(text, bound)

    def _partials(self, text: str) -> str:
        pat = re.compile(
            r"(?P<ddt>\\d?frac\s*\{\s*(?:d|\\mathrm\s*\{d\})\s*\}\s*\{\s*(?:d|\\mathrm\s*\{d\})\s*t\s*\}\s*"
            r"(?:\\left)?[(\[]?\s*)?\\d?frac\s*\{\s*\\partial\s*"
        )
        out, pos = [], 0
        for m in pat.finditer(text):
            if m.start() < pos:
                continue
            num_start = m.end()
            num_end = _group_end(text, m.end() - len(m.group(0)) + m.group(0).rindex("{")) - 1
            den_open = num_end + 1
            while den_open < len(text) and text[den_open] == " ":
                den_open += 1
            if den_open >= len(text) or text[den_open] != "{":
                continue
            den_end = _group_end(text, den_open)
            den = text[den_open + 1 : den_end - 1].strip()
            if not den.startswith("\\partial"):
                continue
            end = den_end
            if m.group("ddt") and re.search(r"[(\[]\s*$", m.group("ddt")):
                close = re.match(r"\s*(?:\\right)?[)\]]", text[end:])
                if close is None:
                    continue
                end += close.end()
            if len(self.partials) >= MAX_PARTIALS:
                raise NotALaw(f"more than {MAX_PARTIALS} derivatives")
            out.append(text[pos : m.start()])
            out.append(f" \\mathrm{{lawpd}}_{{{len(self.partials)}}} ")
            self.partials.append((bool(m.group("ddt")), text[num_start:num_end].strip(), den[len("\\partial") :]))
            pos = end
        out.append(text[pos:])
        return "".join(out)

    def _sums(self, text: str, bound: set) -> str:
        m = _SUM.search(text)
        if m is None:
            return text
        i, letter, upper = m.end(), "", "n"
        while i < len(text) and text[i] in "_^":
            mark = text[i]
            content, i = _script(text, i + 1)
            if mark == "_":
                letter = content.split("=")[0].strip()
            else:
                upper = content.strip()
            while i < len(text) and text[i] == " ":
                i += 1
        if len(letter) != 1 or letter not in INDEX_LETTERS:
            raise NotALaw(f"a sum over {letter or 'an unnamed index'}")
        end = _term_end(text, i)
        while end < len(text) and text[end] in "+-":  # a term using the index still belongs to the sum
            nxt = _term_end(text, end + 1)
            if letter in bound or letter not in script_letters(text[end + 1 : nxt]):
                break
            end = nxt
        summand = self._sums(text[i:end], bound | {letter})
        self.sums.append((letter, upper, summand))
        placeholder = f" \\mathrm{{lawsum}}_{{{len(self.sums) - 1}}} "
        return self._sums(text[: m.start()] + placeholder + text[end:], bound)


def cayley(rng: random.Random) -> sp.Matrix:
    """A random rotation with rational entries: (I - S)^-1 (I + S), S skew-symmetric."""
    a, b, c = (sp.Rational(rng.randint(-5, 5), rng.randint(1, 4)) for _ in range(3))
    s = sp.Matrix([[0, -c, b], [c, 0, -a], [-b, a, 0]])
    return (sp.eye(3) - s).inv() * (sp.eye(3) + s)


class Values:
    """The random values of one evaluation point: each quantity (and each rotation between
    frames) drawn once, by a seeded generator (the same for every reading)."""

    def __init__(self, seed: int, n: int = N_LINKS):
        self.rng = random.Random(seed)
        self.n = n
        self.cache: dict = {}

    def number(self):
        return sp.Rational(self.rng.choice([-1, 1]) * self.rng.randint(1, 29), self.rng.randint(1, 11))

    def get(self, key, kind: str):
        if (key, kind) not in self.cache:
            self.cache[(key, kind)] = self._draw(kind)
        return self.cache[(key, kind)]

    def _draw(self, kind: str):
        n = self.n
        if kind == "scalar":
            return self.number()
        if kind == "vector":
            return sp.Matrix(3, 1, lambda i, j: self.number())
        if kind == "tensor":  # symmetric (an inertia tensor)
            a = sp.Matrix(3, 3, lambda i, j: self.number())
            return a + a.T
        if kind == "rotation":
            return cayley(self.rng)
        if kind == "axis":  # a joint axis, z of its own frame
            return sp.Matrix([0, 0, 1])
        if kind == "joints":
            return sp.Matrix(n, 1, lambda i, j: self.number())
        if kind == "joint-matrix":  # symmetric n x n (a mass matrix)
            a = sp.Matrix(n, n, lambda i, j: self.number())
            return a + a.T
        if kind == "jacobian":
            return sp.Matrix(3, n, lambda i, j: self.number())
        raise ValueError(kind)

    def rotation(self, to: int, frm: int):
        """The rotation taking frame ``frm``'s coordinates into frame ``to``'s (adjacent
        frames drawn, others composed)."""
        if to == frm:
            return sp.eye(3)
        if abs(to - frm) == 1:
            lo, hi = min(to, frm), max(to, frm)
            r = self.get(("R", hi, lo), "rotation")  # frame lo into frame hi
            return r if to == hi else r.T
        step = 1 if frm > to else -1
        return self.rotation(to, frm - step) * self.rotation(frm - step, frm)


class Reader:
    """Reads the sides of one law at one evaluation point and one binding of its indices.

    vocabulary: (Name, binding) -> (Quantity, kind) or raises :class:`NotALaw`;
    values: the point's :class:`Values`; placeholders: the side's sums and derivatives;
    partial: (numerator Quantity, denominator Quantity, d/dt) -> the derivative's value."""

    def __init__(self, vocabulary, values: Values, placeholders: Placeholders, partial, native):
        self.vocabulary = vocabulary
        self.values = values
        self.ph = placeholders
        self.partial = partial
        self.native = native  # Quantity -> the frame its value is drawn in (None: no frame)
        self.used: list[Quantity] = []

    def read(self, text: str, binding: dict):
        return parse(text, lambda name: self.resolve(name, binding))

    def resolve(self, name: Name, binding: dict):
        if name.base == "lawsum":
            letter, upper, summand = self.ph.sums[int(name.sub)]
            top = index_value(upper, {**binding, "n": self.values.n}) if upper not in ("n", "N") else self.values.n
            if top is None or not 0 < top <= 6:
                raise NotALaw(f"a sum up to {upper}")
            total = self.read(summand, {**binding, letter: 1})
            for k in range(2, top + 1):
                total = total + self.read(summand, {**binding, letter: k})
            return total
        if name.base == "lawpd":
            ddt, num, den = self.ph.partials[int(name.sub)]
            top = self._one_name(num, binding)
            by = self._one_name(den, binding)
            return self.partial(top, by, ddt, self.values)
        quantity, kind = self.vocabulary(name, binding)
        self.used.append(quantity)
        if kind == "rotation":  # entry: (to, from) frames
            return self.values.rotation(*quantity.entry)
        value = self.values.get(_drawn(quantity), kind)
        if kind in ("vector", "axis") and quantity.frame is not None:
            native = self.native(quantity)
            if native is not None and native != quantity.frame:
                value = self.values.rotation(quantity.frame, native) * value
        return value

    def _one_name(self, text: str, binding: dict) -> Quantity:
        names: list[Name] = []
        marker = sp.Symbol("law_marker")
        try:
            value = parse(text, lambda n: names.append(n) or marker)
        except LatexError:
            raise NotALaw(f"cannot read the derivative's {text}") from None
        if value != marker or len(names) != 1:
            raise NotALaw(f"a derivative of {text}")
        quantity, _ = self.vocabulary(names[0], binding)
        self.used.append(quantity)
        return quantity


def _drawn(q: Quantity):
    """The key a quantity's value is drawn under (not its frame: that only rotates it)."""
    return (q.role, q.link, q.dots, q.centre, q.entry)
