"""Names the student gave values to, used in later values.

A derivation names its intermediate results and writes later steps through them:
``\\tau_1 = d_{11}\\ddot q_1 + d_{12}\\ddot q_2 + c_{121}\\dot q_1\\dot q_2 + \\phi_1``, ``L = KE - PE``,
``a_{c,3} = (\\cos\\theta_3 X + \\sin\\theta_3 Y, ...)`` "where ``X = ...``". In a value,

* a name the student wrote as a step earlier (``d_{11}``, ``\\phi_3``, ``c_{112}``, ``K``) is
  their own value of it;
* a name they define with an equation that names no step (``X = ...``, ``c_1 = \\cos\\theta_1``,
  ``h = ...``) is that definition, also when it is written after its use ("where X = ...");
  definitions may use definitions, at most :data:`MAX_DEPTH` deep, never themselves;
* a model quantity they did not write (a mass-matrix entry, a Christoffel symbol, a gravity
  entry) is the model's, and the verdict says so.

Each value is read twice: with the student's own values of the names (graded) and with
their right values (``right``): a wrong step that is right with the right values only
carries an earlier error (:meth:`DefinedNames.carry`).
"""

from __future__ import annotations

import re

import sympy as sp

from .latex import MAX_CALL_DEPTH, MAX_SYMBOLIC_EXPONENT, LatexError, Name, UnknownSymbol, parse
from .named import PARTIAL_MARK, Entry, keep_named, partial_value, plain, shorthand_name, simple_name
from .notation import parse_lhs
from .vocabulary import MODEL_KEYS

#: definitions read through definitions at most this deep (X through Y through Z ...)
MAX_DEPTH = 4
#: nodes of a value read through names beyond which it is refused (a chain of definitions
#: each squaring the last would otherwise grow without bound)
MAX_NODES = 20000
#: ``KE``, ``K.E.``, ``\mathrm{KE}``, ``PE``...: one name, the student's earlier energy
_ENERGY = re.compile(
    r"(?<![A-Za-z\\])(?:\\(?:mathrm|text|mathit|rm)\s*\{\s*)?([KP])(?:E|\.\s*E\.?)(?:\s*\})?(?![A-Za-z])"
)
_ENERGY_NAMES = {"K": ("KE", "K", "T"), "P": ("PE", "P", "V", "U")}


class DefinedNames:
    """The names of one submission (a hook of :class:`~.notation.SymbolMap`).

    symbols: the submission's SymbolMap; model_value: (Name) -> the model's value of a
    quantity the name stands for, or None; read: (text) -> (own, right) values of a
    definition's text (read with these names)."""

    def __init__(self, symbols, model_value, read):
        self.symbols = symbols
        self.model_value = model_value
        self.read = read
        self.entries: dict[str, Entry] = {}
        self.pending: dict[str, object] = {}  # key -> equation defining it, not read yet
        self.right = False  # reading with the right values of the names
        self.used: list[Entry] = []  # the entries the value being read used
        self._stack: list[str] = []
        self.failed: dict[str, str] = {}  # key -> why its definition cannot be read
        self.active = False
        self.unknown: list[Name] = []  # names no reading knew, in the equation being read (.named.Waiting)
        self.aliased: set[str] = set()  # keys given as another name of an energy (.named.keep_named)
        self.partials: dict[str, tuple] = {}  # placeholder -> (Name, variable): .named.partials_as_names
        self.links: dict[str, str] = {}  # key -> the key it was given as (M_{21} = M_{12}): .named.symmetric_entry

    # -- what may be defined
    def definable(self, name: Name) -> bool:
        """Not a symbol of the model (a length, a joint variable): those keep their meaning.
        The shorthand ``c_1``, ``s_{12}`` may be defined (and is checked)."""
        if shorthand_name(name):
            return True
        saved, self.active = self.active, False
        try:
            self.symbols(name)
            return False
        except (UnknownSymbol, LatexError):
            return True
        finally:
            self.active = saved

    def collect(self, equations) -> None:
        """Definitions written anywhere (a use may come before: "where X = ...")."""
        for eq in equations:
            if not eq.latex or eq.problem or isinstance(eq.value, list):
                continue
            name = simple_name(eq.lhs)
            if name is None or parse_lhs(eq.lhs, lambda _: None) is not None or not self.definable(name):
                continue
            if shorthand_name(name):  # c_1 means cos q_1 until the student defines it otherwise
                continue
            self.pending.setdefault(plain(name), eq)
        self.active = True

    # -- the SymbolMap hook
    def lookup(self, name: Name):
        """The value of a name given earlier (or defined anywhere), else None."""
        if not self.active or name.pre_sup or name.pre_sub:
            return None
        if name.dots:  # \dot M_{11}: the time derivative of the student's M_{11}
            from .named import differentiated

            return differentiated(self, name)
        if name.base == PARTIAL_MARK:  # \frac{\partial M_{11}}{\partial q_2}
            return partial_value(self, name)
        key = plain(name)
        key = self.links.get(key, key) if key not in self.entries else key
        if key in self.failed:
            raise LatexError(self.failed[key])
        entry = self.entries.get(key)
        if entry is None and key in self.pending:
            entry = self._read_pending(key)
        if entry is None:
            return None
        self.used.append(entry)
        return entry.right if self.right else entry.own

    def model(self, name: Name):
        """A model quantity not written (``d_{11}``, ``\\phi_3``): the model's value, said."""
        if not self.active or name.dots:
            if self.active:
                self.unknown.append(name)
            return None
        entry = self.model_value(name)
        if entry is None:
            self.unknown.append(name)
            return None
        self.used.append(entry)
        return entry.right if self.right else entry.own

    def _read_pending(self, key: str) -> Entry:
        eq = self.pending[key]
        if key in self._stack:
            chain = " → ".join([*self._stack[self._stack.index(key) :], key])
            raise LatexError(f"{eq.lhs} is defined through itself ({chain})")
        if len(self._stack) >= MAX_DEPTH:
            raise LatexError(f"definitions nested more than {MAX_DEPTH} deep ({' → '.join(self._stack)} → {key})")
        self._stack.append(key)
        used, self.used = self.used, []
        right = self.right
        try:
            own, value_right = self.read(str(eq.value))
        finally:
            self.right = right
            self._stack.pop()
            inner, self.used = self.used, used
        entry = Entry(eq.lhs, own, value_right, eq.line, note=_inner_note(inner))
        self._check_shorthand(simple_name(eq.lhs), entry)
        self.entries[key] = entry
        return entry

    def _check_shorthand(self, name: Name | None, entry: Entry) -> None:
        """``c_1 = \\sin\\theta_1``: not the model's ``c_1``; later steps use it, said. A value
        that is no sine or cosine (Lynch & Park's ``c_1``, a velocity-product entry) is another
        quantity of that name: only said in its own line."""
        if name is None or not shorthand_name(name):
            return
        saved, self.active = self.active, False
        try:
            model = self.symbols(name)
        except (UnknownSymbol, LatexError):
            return
        finally:
            self.active = saved
        own = entry.own
        if not isinstance(own, sp.Expr):
            return
        trig = isinstance(-own if own.could_extract_minus_sign() else own, (sp.sin, sp.cos))
        if not trig:
            entry.note = f"not the shorthand {name.latex()} = {model}"
            return
        entry.right = model
        if sp.simplify(sp.expand_trig(own - model)) != 0:
            entry.note = (
                f"{name.latex()} as defined at line {entry.line} is not the shorthand {name.latex()} = {model} "
                "(used as defined)"
            )

    # -- after an equation
    def define(self, eq) -> Entry | str | None:
        """``X = ...`` naming no step: the entry read (or why it cannot be read), None when
        the left-hand side is not a name that can be defined."""
        name = simple_name(eq.lhs)
        if name is None or not self.definable(name):
            return None
        key = plain(name)
        self.pending[key] = eq
        self.entries.pop(key, None)
        self.failed.pop(key, None)
        try:
            return self._read_pending(key)
        except (LatexError, TypeError, ValueError, RecursionError, sp.ShapeError) as err:
            self.pending.pop(key, None)
            why = str(err).split("\n")[0][:200]
            if "defined through itself" in why or " (defined at line " in why:
                self.failed[key] = why  # the first definition that cannot be read is named
            else:  # later uses say why, not "unknown symbol"
                self.failed[key] = f"{eq.lhs} (defined at line {eq.line}) cannot be read: {why}"
            return why

    def record(self, eq, own, right, wrong: str = "") -> None:
        """A step the student wrote under a plain name (``d_{11}``, ``\\phi_3``, ``g_3``):
        their value stands for it in later values."""
        name = simple_name(eq.lhs) if eq.latex else None
        if name is None or own is None:
            return
        self.entries[plain(name)] = Entry(eq.lhs, own, own if right is None else right, eq.line, wrong)
        self.pending.pop(plain(name), None)
        self.links.pop(plain(name), None)
        self.aliased.discard(plain(name))


def bounded(value):
    """``value`` (read through names) within the parser's own limits: functions nested at most
    :data:`~.latex.MAX_CALL_DEPTH` deep, symbolic exponents at most
    :data:`~.latex.MAX_SYMBOLIC_EXPONENT`, at most :data:`MAX_NODES` nodes; else LatexError."""
    items = list(value) if isinstance(value, sp.MatrixBase) else [value]
    stack = [(x, 0) for x in items if isinstance(x, sp.Basic)]
    nodes = 0
    while stack:
        x, calls = stack.pop()
        nodes += 1
        if nodes > MAX_NODES:
            raise LatexError(f"the value read through its names has more than {MAX_NODES} terms")
        if isinstance(x, sp.Function) or (isinstance(x, sp.Pow) and not x.exp.is_Integer):
            calls += 1
            if calls > MAX_CALL_DEPTH:
                raise LatexError(f"nesting of functions deeper than {MAX_CALL_DEPTH} levels (through its names)")
        if isinstance(x, sp.Pow) and x.exp.is_Number and x.base.free_symbols and abs(x.exp) > MAX_SYMBOLIC_EXPONENT:
            raise LatexError(f"an exponent over {MAX_SYMBOLIC_EXPONENT} (through its names)")
        stack.extend((a, calls) for a in x.args)
    return value


def _inner_note(used: list) -> str:
    return "; ".join(dict.fromkeys(e.note for e in used if e.note))


def energy_names(text: str, steps: dict) -> str:
    """``KE - PE``, ``K.E.``, ``\\mathrm{KE}``: the student's earlier energies by one name
    (a product K·E otherwise)."""

    def one(m):
        if text[m.end() : m.end() + 1] == "_":  # KE_1, PE_{2}: a link's energy by one name
            return f"\\mathrm{{{m.group(1)}E}}"
        for name in _ENERGY_NAMES[m.group(1)]:
            if name in steps:
                return f" \\mathrm{{{name}}} "
        return m.group(0)

    return _ENERGY.sub(one, text)


# -- the grader's side (functions of armdyn.grading.grader.Grader, as chains.check_step)
def read_pair(grader, text: str):
    """(own, right) values of one LaTeX value: its names read with the student's values and
    with their right ones; step names (``{}^{2}F_2``, ``n_1^{1T}``) through
    :class:`~.chains.StepNames` when the plain reading does not know them."""
    from .chains import step_names
    from .named import drop_arguments, partials_as_names

    names = grader.names
    text = partials_as_names(grader, drop_arguments(grader, energy_names(text, grader.symbols.steps)))
    saved = names.right
    start = len(names.used)
    try:
        names.right = False
        try:
            own = parse(text, grader.symbols)
        except UnknownSymbol as err:
            try:
                reading = step_names(grader).read(text)
            except (LatexError, TypeError, ValueError, AttributeError, sp.ShapeError):
                raise err from None
            if not reading.names:
                raise
            grader._assumed.extend(reading.assumed)
            return reading.own, reading.right
        if len(names.used) == start:
            return own, own
        names.right = True
        return bounded(own), bounded(parse(text, grader.symbols))
    finally:
        names.right = saved


def read_value(grader, eq, raw):
    """The value of ``eq`` (its text ``raw``, a list for a YAML column) as the student
    wrote it; kept, with its right reading, for :func:`after_equation`."""
    grader.names.used, grader._assumed = [], []
    items = raw if isinstance(raw, list) else [raw]
    pairs = [read_pair(grader, str(v)) for v in items]
    if isinstance(raw, list):
        own, right = sp.Matrix([p[0] for p in pairs]), sp.Matrix([p[1] for p in pairs])
    else:
        own, right = pairs[0]
    grader.last_read = (eq, own, right, list(grader.names.used), list(grader._assumed))
    return own


def model_value(grader, name: Name) -> Entry | None:
    """A mass-matrix entry, Christoffel symbol or gravity entry named ``name`` (``d_{11}``,
    ``c_{112}``, ``\\phi_3``) that was not written by itself: the entry of the student's
    matrix ``D(q)`` or vector ``g(q)`` when written, else the model's value (said); or None."""
    from .lagrange_terms import expected_of

    if name.pre_sup or name.pre_sub or not name.sub:
        return None
    try:
        ref = parse_lhs(name.latex(), lambda _: None)
    except (LatexError, TypeError, ValueError):
        return None
    if ref is None or ref.key not in MODEL_KEYS or ref.key not in ("M", "christoffel", "G") or not ref.entry:
        return None
    if any(not 1 <= k <= grader.robot.dof for k in ref.entry):
        return None
    try:
        value = expected_of(grader.model_terms(), ref)
    except (KeyError, IndexError, TypeError, ValueError):
        return None
    if isinstance(value, sp.MatrixBase):
        return None
    if ref.key in ("M", "G"):  # an entry of the student's whole D(q) or g(q)
        at = (ref.entry[0] - 1, ref.entry[1] - 1) if ref.key == "M" else (ref.entry[0] - 1, 0)
        shape = (grader.robot.dof, grader.robot.dof) if ref.key == "M" else (grader.robot.dof, 1)
        for v in reversed(grader.verdicts):
            if v.key == ref.key and isinstance(v.got, sp.MatrixBase) and v.got.shape == shape:
                own = v.got[at]
                right = v.expected[at] if isinstance(v.expected, sp.MatrixBase) else own
                wrong = v.name if v.status == "wrong" else ""
                note = f"{name.latex()} read as the entry of {v.label} (line {v.line})"
                return Entry(name.latex(), own, right if v.status == "wrong" else own, v.line, wrong, note)
    return Entry(name.latex(), value, value, note=f"{name.latex()} not written: the model's value used")


def definition(grader, eq) -> str | None:
    """``X = ...`` naming no step: read as a definition ("defines X"), or None."""
    grader.names.used = []
    entry = grader.names.define(eq) if eq.latex else None
    if not isinstance(entry, Entry):
        return None
    if entry.note and f"as defined at line {eq.line}" in entry.note:
        grader.notes.append(f"line {eq.line}: {entry.note}")
    return f"defines {eq.lhs} (used in later steps)" + (f"; {entry.note}" if entry.note else "")


def _fingerprints_equal(grader, a, b) -> bool:
    from .engine import equal, to_sympy

    a, b = to_sympy(a), to_sympy(b)
    a = a if isinstance(a, sp.MatrixBase) else sp.Matrix([[a]])
    b = b if isinstance(b, sp.MatrixBase) else sp.Matrix([[b]])
    if a.shape != b.shape and a.shape == (b.shape[1], b.shape[0]):
        a = a.T
    if a.shape != b.shape:
        return False
    fp = grader.sampler.fingerprint
    return bool(equal(fp(a), fp(b)).all())


def after_equation(grader, eq, new: list) -> None:
    """What the names an equation's value used add to its verdict (an earlier error carried,
    a model value used, a definition that is not the model's), and its value kept under its
    name for later values."""
    read, grader.last_read = grader.last_read, None
    if read is None or read[0] is not eq or len(new) != 1:
        return
    _, own, right, used, assumed = read
    v = new[0]
    said = list(dict.fromkeys([*(e.note for e in used if e.note), *assumed]))
    wrong = next((e for e in used if e.wrong), None)
    if v.status == "wrong" and used and v.expected is not None and _fingerprints_equal(grader, right, v.expected):
        if wrong is not None and wrong.line > eq.line:  # a formula above the wrong step it names
            v.status, v.difference, v.components = "correct", None, []
            v.message = f"right in its names; {wrong.name} is wrong further on (line {wrong.line})"
        elif wrong is not None:  # right with the right value of the step it names: the error is carried
            v.status, v.caused_by = "follows-from-earlier-error", wrong.wrong
            v.message = f"follows from the error in {wrong.wrong} (line {wrong.line}), used by name"
        elif said:
            v.message = "right with the model's values of the names it uses" + ("; " + v.message if v.message else "")
    if said:
        v.message = "; ".join(x for x in [v.message, *said] if x)
    if v.status in ("wrong", "follows-from-earlier-error") and v.expected is not None and v.got is not None:
        right_value = v.expected
    elif v.status in ("unrecognised", "definition"):
        right_value = right
    else:
        right_value = own
    wrong = v.name if v.status == "wrong" else (v.caused_by or "") if v.status == "follows-from-earlier-error" else ""
    name = simple_name(eq.lhs) if eq.latex else None
    if name is not None and grader.names.definable(name):
        grader.names.record(eq, own, right_value, wrong)
    keep_named(grader, eq, v, own, right_value, wrong)
