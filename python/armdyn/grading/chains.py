"""Every member of a chain ``LHS = formula = ... = value`` checked, not only the value.

A Newton-Euler step is often written with its formula before its value::

    \\dot v_{C_1}^1 = \\dot\\omega_1^1 \\times P_{C_1}^1 + \\omega_1^1 \\times (\\omega_1^1 \\times P_{C_1}^1)
                     + \\dot v_1^1 = (value)

Each member between the left-hand side and the value is read with the step names in it
standing for the student's OWN earlier values (:class:`StepNames`: ``\\omega_1^1``,
``{}^{1}\\dot\\omega_1``, ``\\dot v_1^1``, ``F_2^2``, ``f_2^2``, ``n_2^2`` / ``m_2^2``,
``R_0^1`` / ``{}^{1}_{0}R`` (``R_2^1`` the transpose of a written ``R_1^2``), ``P_{C_1}^1``,
``P_2^1``, ``I_1^{C_1}`` / ``{}^{C_1}I_1``, the unit axes ``\\hat Z_1^1``, ``\\hat z``, ``z``,
a trailing ``T`` in the frame (``n_1^{1T}``) a transpose, ``\\mathbf{0}`` the zero vector,
Spong's ``r_{i,c_i}``, ``r_{i,i+1}`` read as ``P_{C_i}^i``, ``P_{i+1}^i`` and said) and the
model's where the student did not write that step; ``T``, ``V``, ``L`` are the student's
(:attr:`~.notation.SymbolMap.steps`); every other symbol is the model's
(:class:`~.notation.SymbolMap`).
A member that differs from the value is a slip of its own unless the difference is only
inherited: read with the right values of every step it names, it gives the step's right
value (:func:`check`). A member that cannot be read is skipped with a note saying why.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field

import sympy as sp

from .equations import top_level
from .latex import LatexError, Name, UnknownSymbol, parse, sides
from .notation import VECTOR_KEYS, StepRef, parse_lhs

#: the placeholder a step name is replaced by before parsing (a name no student writes)
PLACEHOLDER = "armdynstep"
#: step names in one member beyond which it is not checked (a formula names a handful;
#: each costs a matrix operation, so this bounds a hostile member's work)
MAX_NAMES = 100
#: characters of a member quoted in a message
QUOTE = 80

_GROUP = r"\{(?:[^{}]|\{(?:[^{}]|\{[^{}]*\})*\})*\}"
_ARG = rf"(?:{_GROUP}|\\[A-Za-z]+|[A-Za-z0-9])"
# a superscript that is a bare transpose (n^T, z^{T}) is left to the parser
_SCRIPT = rf"\s*(?:_\s*{_ARG}|\^(?!\s*(?:T(?![A-Za-z0-9])|\{{\s*T\s*\}}|\\top|\{{\s*\\top\s*\}}))\s*{_ARG})"
_DECOR = r"\\(?:d?dot|mathbf|boldsymbol|bm|vec|hat|mathrm|pmb)(?![A-Za-z])"
_STEP = re.compile(
    rf"(?<![A-Za-z\\])(?P<pre>\{{\}}(?:{_SCRIPT})+\s*)?"
    rf"(?P<core>(?:{_DECOR}\s*\{{?\s*)*(?:\\omega(?![A-Za-z])|[vaFNfnmRPIZzXxYr](?![A-Za-z]))(?:\s*\}})*)"
    rf"(?P<scripts>(?:{_SCRIPT})*)"
)
_UNIT = {"x": 0, "y": 1, "z": 2}
#: a bold zero: the zero vector
_ZERO = re.compile(r"\\(?:mathbf|boldsymbol|bm|vec)\s*\{\s*0\s*\}")


@dataclass
class Meaning:
    """What a step name in a member stands for: ``ref`` (a step, rotation or position), or
    ``("I", i)`` the link's inertia about its mass centre, or ``("unit", k)`` a unit axis;
    ``transpose``: written with a trailing T."""

    what: object
    transpose: bool = False
    note: str = ""  # how a name outside the usual ones was read, said in the verdict


def _balanced(text: str) -> bool:
    depth = 0
    for c in text:
        depth += {"{": 1, "}": -1}.get(c, 0)
        if depth < 0:
            return False
    return depth == 0


def meaning(text: str, pre: str, core: str, scripts: str, coordinate_of) -> Meaning | None:
    """The step a name written in a member names, or None (an ordinary symbol)."""
    transpose = bool(re.search(r"\^\s*\{[^{}]*?(?:T|\\top)\s*\}\s*$", scripts))
    base = re.sub(r"\\(?:d?dot|mathbf|boldsymbol|bm|vec|hat|mathrm|pmb)|[{}\s]", "", core)
    hat = "\\hat" in core
    if base in ("Z", "z") or (hat and base in ("X", "x", "Y")):
        return Meaning(("unit", _UNIT[base.lower()]), transpose)
    if base == "I":
        links = {int(d) for d in re.findall(r"\d+", pre + scripts)}  # I_1^{C_1}, {}^{C_1}I_1, I_{C_1}
        return Meaning(("I", links.pop()), transpose) if len(links) == 1 else None
    if base == "r":
        return _spong_r(text, scripts, transpose)
    if base == "a" and not re.search(r"_\s*\{?\s*[Cc]", scripts):
        return None  # a_i is a link length (Spong); a_{C_i} an acceleration
    ref = parse_lhs(text, coordinate_of)
    if ref is None or (ref.key in VECTOR_KEYS and ref.index is None):
        return None
    if ref.alias == "m" and ref.frame is None:
        return None  # m_i without a frame: the mass
    return Meaning(ref, transpose)


def _spong_r(text: str, scripts: str, transpose: bool) -> Meaning | None:
    """Spong's ``r_{i,c_i}`` (link i's mass centre from joint i) and ``r_{i,i+1}`` (joint
    i+1 from joint i), in frame i: with frame i on joint i's axis, ``P_{C_i}^i`` and
    ``P_{i+1}^i``."""
    m = re.fullmatch(r"_\s*\{\s*(\d+)\s*,\s*(?:([Cc])_?\{?(\d+)\}?|(\d+))\s*\}", scripts.strip())
    if m is None:
        return None
    i = int(m.group(1))
    if m.group(2) and int(m.group(3)) == i:
        ref, what = StepRef("Pc", i, i), f"link {i}'s mass centre from frame {i}'s origin"
    elif m.group(4) and int(m.group(4)) == i + 1:
        ref, what = StepRef("P", i + 1, i), f"frame {i + 1}'s origin from frame {i}'s"
    else:
        return None
    return Meaning(ref, transpose, f"{text} read as {ref.name} ({what}, in frame {i})")


@dataclass
class Reading:
    """A member read twice: with the student's own values (``own``) and with the right
    value of every step it names (``right``); ``names``: the step names found."""

    own: object
    right: object
    names: list = field(default_factory=list)
    assumed: list = field(default_factory=list)  # what was assumed in reading it, said in the verdict


class StepNames:
    """Reads members: step names resolve through ``values(meaning, own) -> value or None``
    (None: a step this robot does not have), every other symbol through ``symbols``."""

    def __init__(self, symbols, values, prepare=None):
        self.symbols = symbols
        self.values = values
        self.prepare = prepare  # (text) -> text: names with arguments, partials (.named), before reading
        robot = symbols.robot
        #: joint indices (1-based) of prismatic joints: their angle, if written, is a constant
        self.prismatic = {
            robot.coordinate_index(j) + 1
            for j in robot.joints
            if j.type == "prismatic" and robot.coordinate_index(j) is not None
        }
        self.assumed: list[str] = []

    def symbol(self, name: Name):
        """A model symbol; ``\\dot\\theta_k`` of a prismatic joint k (the revolute formula
        written for every joint) is 0, said in the verdict."""
        sub = re.sub(r"[{}\s]", "", name.sub)
        if (
            name.base in ("theta", "vartheta")
            and name.dots
            and sub.isdigit()
            and int(sub) in self.prismatic
            and f"{name.base}|{name.dots}|{sub}" not in self.symbols.explicit
            and f"{name.base}{sub}" not in self.symbols.names
        ):
            self.assumed.append(f"{name.latex()} read as 0 (joint {sub} is prismatic: no joint angle moves)")
            return sp.Integer(0)
        return self.symbols(name)

    def _substitute(self, text: str):
        """``text`` with each step name replaced by a numbered placeholder, and their meanings."""
        found: list[Meaning] = []
        out, last = [], 0
        text = _ZERO.sub(lambda m: f" \\mathrm{{{PLACEHOLDER}}}_{{z}} ", text)
        for m in _STEP.finditer(text):
            name = m.group(0)
            if not _balanced(name):
                continue
            pre, core, scripts = m.group("pre") or "", m.group("core"), m.group("scripts")
            if not pre and "^" not in scripts:
                try:  # written without a frame: a model symbol (m_1, I_1, a_2) wins when there is one
                    parse(name, self.symbols)
                    continue
                except (LatexError, TypeError, ValueError):
                    pass
            what = meaning(name.strip(), pre, core, scripts, self.symbols.coordinate_of)
            if what is None:
                continue
            out.append(text[last : m.start()] + f" \\mathrm{{{PLACEHOLDER}}}_{{{len(found)}}} ")
            last = m.end()
            found.append(what)
            if len(found) > MAX_NAMES:
                raise LatexError(f"it names more than {MAX_NAMES} steps")
        out.append(text[last:])
        return "".join(out), found

    def read(self, text: str) -> Reading:
        """The member ``text`` read; raises LatexError (UnknownSymbol) when it cannot be."""
        body, found = self._substitute(self.prepare(text) if self.prepare else text)

        def resolver(own: bool):
            def resolve(name: Name):
                if name.base == PLACEHOLDER and name.sub == "z":
                    return sp.zeros(3, 1)
                if name.base == PLACEHOLDER:
                    what = found[int(name.sub)]
                    if what.note:
                        self.assumed.append(what.note)
                    value = self.values(what.what, own)
                    if value is None:
                        raise UnknownSymbol(f"unknown symbol {_shown(what.what)}")
                    return value.T if what.transpose else value
                if not own and not name.dots and not name.sub and name.base in ("T", "V", "L"):
                    if name.base in self.symbols.steps:  # the student's T, V, L: read right, the right ones
                        return self.values(("lagrange", name.base), False)
                return self.symbol(name)

            return resolve

        self.assumed = []
        defined = getattr(self.symbols, "defined", None)  # names the student defined: their right values too
        own = parse(body, resolver(True))
        saved = defined is not None and defined.right
        if defined is not None:
            defined.right = True
        try:
            right = parse(body, resolver(False))
        finally:
            if defined is not None:
                defined.right = saved
        reading = Reading(own, right, found)
        reading.assumed = sorted(set(self.assumed))
        return reading


class Values:
    """The value a step name in a member stands for, in the frame it names.

    world:    () -> the Newton-Euler world (its context: the model's kinematics), made when needed
    lagrange: () -> the Lagrange world (the right T, V, L), made when needed
    written:  (key, index) -> (the student's value, the right value in their convention),
              both in the link's own frame, for the steps they wrote
    verdicts: the verdicts so far (the rotations and positions the student wrote)
    """

    def __init__(self, world, written: dict, verdicts: list, lagrange=None):
        self._world, self.written, self.verdicts, self._lagrange = world, written, verdicts, lagrange

    def __call__(self, what, own: bool):
        from .engine import to_sympy
        from .methods import position, rotation_between

        if isinstance(what, tuple) and what[0] == "lagrange":
            return to_sympy(self._lagrange().expected[(what[1], None)].sym())
        self.world = self._world()
        ctx = self.world.ctx
        n = len(self.world.method.robot.links) - 1
        if isinstance(what, tuple):
            kind, k = what
            if kind == "unit":
                return sp.Matrix([int(k == 0), int(k == 1), int(k == 2)])
            return ctx[k]["I"] if 1 <= k <= n else None
        ref: StepRef = what
        if ref.key in VECTOR_KEYS:
            key = (ref.key, ref.index)
            if key not in self.world.method.refs or (ref.frame is not None and not 0 <= ref.frame <= n):
                return None
            if key in self.written:
                value = to_sympy(self.written[key][0 if own else 1])
            else:  # not written: what the method gives from the student's values (or the right one)
                value = to_sympy((self.world.candidates(key)[0] if own else self.world.expected[key]).sym())
            frame = ref.index if ref.frame is None else ref.frame
            return value if frame == ref.index else rotation_between(ctx, ref.index, frame) * value
        if ref.key == "R":
            if not (0 <= ref.index <= n and 0 <= ref.frame <= n):
                return None
            right = rotation_between(ctx, ref.index, ref.frame)
            if own:
                for v in reversed(self.verdicts):
                    if v.key == "R" and v.status != "correct-by-convention" and v.got is not None:
                        if v.frame == f"{ref.index}->{ref.frame}":
                            return v.got
                        if v.frame == f"{ref.frame}->{ref.index}":
                            return v.got.T
            return right
        if ref.key in ("P", "Pc"):
            if not 1 <= ref.index <= n:
                return None
            if ref.frame is not None and not 0 <= ref.frame <= n:
                return None
            right, _, frame = position(ctx, ref.key, ref.index, ref.frame, ref.origin)
            if own:
                for v in reversed(self.verdicts):
                    if v.key == ref.key and v.got is not None and v.name.split("^")[0] == ref.name.split("^")[0]:
                        if v.frame == str(frame):
                            return v.got
            return right
        return None


def _shown(what) -> str:
    return what.name if isinstance(what, StepRef) else str(what)


def _shaped(value, like):
    """A member's value in the shape of the step's value (0 for a zero vector, a row)."""
    if isinstance(like, sp.MatrixBase):
        if not isinstance(value, sp.MatrixBase):
            return sp.zeros(*like.shape) if value == 0 else value
        if value.shape == (like.shape[1], like.shape[0]) and like.shape[1] == 1:
            return value.T
        return value
    if isinstance(value, sp.MatrixBase) and value.shape == (1, 1):
        return value[0, 0]
    return value


@dataclass
class MemberFinding:
    """One member that is not simply equal to the value: ``kind`` is "wrong" (a slip of
    its own), "source" (equal to a value wrong on its own, and wrong with the right values
    too: the slip is already in this member), "right" (right, but the value differs from
    it: the value holds the slip),
    "inherited" (it differs only through earlier errors), "skipped" (cannot be read:
    ``why``) or "assumed" (equal, read with an assumption: ``why``); ``components`` the
    differing components, ``member`` its value."""

    number: int
    text: str
    kind: str
    why: str = ""
    components: list = field(default_factory=list)
    member: object = None
    line: int = 0  # where it was written, when the chain spans several rows or blocks (0: not said)
    column: int = 0


def quoted(text: str) -> str:
    """A member as quoted in a message: at most :data:`QUOTE` characters."""
    return text if len(text) <= QUOTE else text[: QUOTE - 1].rstrip() + "…"


def members(source: str) -> list[str]:
    """The members between the left-hand side and the value of ``A = B = ... = value``
    (alignment ``&`` and line breaks ``\\\\`` of a chain written over several rows blanked)."""
    chars = list(source)
    for i, mark in top_level(source):
        if mark in ("&", "\\\\"):
            chars[i : i + len(mark)] = " " * len(mark)
    return sides("".join(chars))[1:-1]


def check(source: str, value, expected, names: StepNames, fingerprint, equal, value_wrong=False, at=()) -> list:
    """Each member of the equation ``source`` against the step's ``value`` (as written:
    its frame, its convention) and, when it differs, against ``expected`` (the right value
    in the same frame and convention): a member right in itself is "right" when the value
    is wrong on its own (``value_wrong``), else "inherited". ``at``: (line, column) of each
    member, when the chain spans several rows or blocks (each finding then says where)."""
    out = []
    value = _matrixish(value)
    texts = members(source)
    at = at if len(at) == len(texts) else [(0, 0)] * len(texts)
    for number, text in enumerate(texts, start=1):
        if not text.strip():  # "a =" closing a block, "= b" opening the next: no member between
            continue
        finding = _member(number, text, value, expected, names, fingerprint, equal, value_wrong)
        if finding is not None:
            finding.line, finding.column = at[number - 1]
            out.append(finding)
    return out


def _member(number, text, value, expected, names, fingerprint, equal, value_wrong) -> MemberFinding | None:
    """One member checked (see :func:`check`): a finding, or None (equal, nothing to say)."""
    try:
        reading = names.read(text)
        own, right = _shaped(reading.own, value), _shaped(reading.right, value)
        ok = equal(fingerprint(own), fingerprint(value))
    except UnknownSymbol as err:
        return MemberFinding(number, quoted(text), "skipped", str(err).split(" (")[0][:QUOTE])
    except (LatexError, TypeError, ValueError, AttributeError, sp.ShapeError, RecursionError) as err:
        why = str(err).split("\n")[0][:120] or type(err).__name__
        return MemberFinding(number, quoted(text), "skipped", f"cannot read it ({why})")
    assumed = "; ".join(reading.assumed)
    if ok.all():
        if value_wrong and not equal(fingerprint(right), fingerprint(expected)).all():
            return MemberFinding(number, quoted(text), "source", assumed)  # the slip is already here
        return MemberFinding(number, quoted(text), "assumed", assumed) if assumed else None
    bad = [int(i) for i in range(ok.size) if not ok.ravel()[i]]
    if not equal(fingerprint(right), fingerprint(expected)).all():
        kind = "wrong"
    else:
        kind = "right" if value_wrong else "inherited"
    return MemberFinding(number, quoted(text), kind, assumed, bad, own)


def _matrixish(value):
    from .engine import to_sympy

    return to_sympy(value)


def check_step(grader, eq, value, expected, value_wrong: bool) -> list:
    """The members of ``eq`` (a step the grader just judged) checked against its ``value``
    (as written) and ``expected`` (right, same frame and convention): :func:`check` with the
    grader's symbols, its student's steps so far and its worlds."""
    from .engine import equal

    names, fingerprint = step_names(grader), grader.sampler.fingerprint
    return check(eq.source, value, expected, names, fingerprint, equal, value_wrong, member_places(grader.sub, eq))


def member_places(sub, eq) -> list:
    """(line, column) of each member of a chain joined from rows or blocks written on
    several lines (:attr:`~.reader.Equation.sides_at`), else [] (a chain on one line)."""
    if eq.rows < 2 or len(eq.sides_at) < 3:
        return []
    places = [sub.locate(offset) for offset in eq.sides_at]
    return places[1:-1] if len({line for line, _ in places}) > 1 else []


def reported_at(sub, eq, findings: list) -> tuple[int, int]:
    """(line, column) a step's verdict is reported at: for a chain split over display blocks,
    the member holding its slip (one wrong on its own, or the first already holding the
    value's slip), else where its value is written; else the equation's (a chain in one
    block: at its left-hand side)."""
    if eq.blocks < 2 or eq.offset < 0 or len(eq.sides_at) < 2:
        return eq.line, eq.column
    for f in findings:
        if f.kind in ("wrong", "source") and f.line:
            return f.line, f.column
    return sub.locate(eq.offset)


def relation_holds(grader, eq, expected) -> bool:
    """Is ``eq``'s value (just read) another step's name alone (``{}^3\\dot v_{C_3} =
    {}^3\\dot v_3``, ``{}^3f_3 = {}^3F_3``: the two are the same quantity here), right when
    that step takes its right value? Then the equation is an identity that holds, whatever
    the named step carries. A formula in names (``F_2 = m_2 \\dot v_{C_2}``) is not: its
    value is what it gives. ``expected``: the step's right value as written."""
    from .engine import equal, to_sympy

    last = grader.last_read
    if last is None or last[0] is not eq or last[3] or last[1] is last[2] or not isinstance(eq.value, str):
        return False
    try:
        body, found = step_names(grader)._substitute(eq.value)
    except LatexError:
        return False
    if len(found) != 1 or body.strip() != f"\\mathrm{{{PLACEHOLDER}}}_{{0}}":
        return False
    right = _shaped(to_sympy(last[2]), expected)
    try:
        fingerprint = grader.sampler.fingerprint
        return bool(equal(fingerprint(right), fingerprint(to_sympy(expected))).all())
    except (TypeError, ValueError, sp.ShapeError):
        return False


def _at(f: MemberFinding) -> str:
    """A member named in a message: its number, and its line when the chain spans several."""
    return f"member {f.number}" + (f" at line {f.line}" if f.line else "")


def step_names(grader) -> StepNames:
    """A reader of step names with the grader's symbols, its student's steps so far and its worlds."""
    values = Values(
        lambda: grader.world("newton-euler"), grader.written, grader.verdicts, lambda: grader.world("lagrange")
    )
    from .named import drop_arguments, partials_as_names

    return StepNames(grader.symbols, values, lambda t: partials_as_names(grader, drop_arguments(grader, t)))


def with_members(findings: list, verdict: tuple, value, grader) -> tuple:
    """``verdict`` = (status, message, difference, components, caused_by) with what the
    chain's members add: a formula member that differs from the value on its own makes the
    step wrong (an already wrong step keeps its message first); a right member of a wrong
    value, an inherited difference, a member read with an assumption or not read at all
    are said. ``value``: the step's value as a matrix; ``grader``: its ``_describe`` and
    ``robot`` word the differences."""
    from .explain import component_name, tidy

    status, message, difference, components, caused_by = verdict
    said = []
    for f in findings:
        if f.kind == "skipped":
            said.append(f"{_at(f)} not checked: {f.why}")
            continue
        if f.why:  # read with an assumption
            said.append(f"{_at(f)}: {f.why}")
        if f.kind == "assumed":
            continue
        if f.kind == "source":
            said.append(f"the slip is already in its formula member `{f.text}` ({_at(f)})")
            continue
        if f.kind == "right":
            said.append(f"its formula member `{f.text}` ({_at(f)}) is right: the slip is in the value")
            continue
        member = f.member if isinstance(f.member, sp.MatrixBase) else sp.Matrix([[f.member]])
        shared = [i for i in f.components if i < min(len(member), len(value))]  # a member of another shape
        where = [component_name(i, value.shape) for i in shared[:3]]
        what = "; ".join(
            grader._describe(member[i], value[i]) + (f" in {w}" if w else "") for i, w in zip(shared, where)
        )
        if len(what) > 160:  # a long difference: where, not what
            what = "a long difference" + (f" in {', '.join(w for w in where if w)}" if any(where) else "")
        if f.kind == "inherited":
            said.append(f"{_at(f)} `{f.text}` differs from the value only through earlier errors: {what}")
            continue
        said.append(f"the formula member `{f.text}` ({_at(f)}) differs from the value: {what}")
        if status != "wrong":
            status, caused_by, components, message = "wrong", None, list(f.components), ""
            difference = sp.Matrix([tidy(member[i] - value[i], grader.robot) for i in range(len(value))])
            difference = difference if value.shape != (1, 1) else difference[0]
    return status, "; ".join(x for x in [message, *said] if x), difference, components, caused_by
