"""SymPy expressions as presentation MathML, in the notation of robot dynamics.

Browsers render MathML natively (MathML Core), so a report with MathML needs no
script, no CDN and no network. SymPy's ``MathMLPresentationPrinter`` does the
expression layout; this module teaches it the field's notation:

* model symbols follow :func:`armdyn.model.coordinate_symbols` and the model files:
  ``theta1`` -> θ₁, ``theta1_dot`` -> θ̇₁ (``<msub><mover accent="true"><mi>θ</mi>
  <mo>˙</mo></mover><mn>1</mn></msub>``: the accent sits on the letter, the index
  outside), ``d2_ddot`` -> d̈₂, ``l1`` -> l₁, ``I1xx`` -> I₁ₓₓ, ``Ixx1`` -> Ixx₁
  (letters in italic, as TeX sets them); Greek names become Greek letters; ``a_b`` / ``a^b`` subscripts and superscripts as SymPy splits them;
* ``sin``/``cos`` are function names applied with U+2061, with parentheses only
  around compound arguments (``sin θ₁``, ``cos(θ₁ + θ₂)``), powers written
  ``sin²θ₁``;
* parentheses are stretchy (``<mo stretchy="true">``), so they grow around
  fractions and column vectors; a (n, 1) Matrix is an ``mtable`` in parentheses;
* a mapping Symbol -> LaTeX (``GradeReport.symbol_latex``: the student's own
  ``\\dot{\\theta}_1``) prints those symbols in the student's notation; the LaTeX
  snippets are converted with the ``latex2mathml`` package.

The output is well-formed XML (numeric character references only, text escaped), so
it can be embedded in HTML5 or parsed by ``xml.etree``. Neither the student's LaTeX nor
a model's names are trusted: :func:`latex_to_mathml` and :func:`math_element` pass
every fragment through the whitelist of :mod:`armdyn.mathml_sanitize`.
"""

from __future__ import annotations

import html
import re
from functools import lru_cache
from xml.dom.minidom import Document

import sympy as sp
from sympy.printing.conventions import split_super_sub
from sympy.printing.mathml import MathMLPresentationPrinter
from sympy.printing.pretty.pretty_symbology import greek_unicode

from .mathml_sanitize import clean_mathml, sanitize_mathml

__all__ = ["MathWriter", "to_mathml", "latex_to_mathml", "math_element", "escape", "text_with_math"]

MATHML_NS = "http://www.w3.org/1998/Math/MathML"
DOT, DDOT = "\u02d9", "\u00a8"  # spacing dot above / diaeresis, as MathML Core's accents
_APPLY = "\u2061"  # FUNCTION APPLICATION (invisible)
_TIMES = "\u2062"  # INVISIBLE TIMES
_FUNCTIONS = ("sin", "cos", "tan", "cot", "sec", "csc")
# a name like I1xx or lc1: letters, an index, optional trailing letters (axes)
_INDEXED = re.compile(r"^([A-Za-z]+?)(\d+)([A-Za-z]*)$")
_ACCENTS = (DOT, DDOT, "^", "\u02dc", "\u2192", "\u20d7", "~", "\u02c6")
_XML_ENTITIES = {"amp", "lt", "gt", "quot", "apos"}


def escape(text: str) -> str:
    """Text for HTML/XML content or a quoted attribute."""
    return html.escape(str(text), quote=True)


def _numeric_entities(markup: str) -> str:
    """Replace HTML named entities (``&InvisibleTimes;``) SymPy may emit by numeric
    references, so the result parses as plain XML."""

    def sub(m):
        name = m.group(1)
        if name in _XML_ENTITIES:
            return m.group(0)
        char = html.entities.html5.get(name + ";")
        return "".join(f"&#x{ord(c):X};" for c in char) if char else m.group(0)

    return re.sub(r"&([A-Za-z][A-Za-z0-9]*);", sub, markup)


def math_element(inner: str, display: bool = False) -> str:
    """Wrap MathML content in a ``<math>`` element (block when ``display``), after the
    whitelist sanitizer (:func:`armdyn.mathml_sanitize.sanitize_mathml`): the content
    may carry a model's names or a student's LaTeX."""
    mode = "block" if display else "inline"
    return f'<math xmlns="{MATHML_NS}" display="{mode}">{sanitize_mathml(inner)}</math>'


@lru_cache(maxsize=1024)
def latex_to_mathml(latex: str) -> str | None:
    """The content (without ``<math>``) of a LaTeX snippet as MathML, or None when it
    cannot be converted (``latex2mathml`` missing, or LaTeX it does not parse) or when
    the whitelist sanitizer had to drop an element of the conversion (``\\text{<b>}``
    comes out of latex2mathml as a live ``<b>``): the caller then shows the LaTeX
    source as escaped text. Disallowed attributes (``\\href``, ``\\style``) are
    dropped and the rest kept."""
    try:
        from latex2mathml.converter import convert
    except ImportError:
        return None
    try:
        out = convert(latex)
    except Exception:  # noqa: BLE001 - any parse failure: caller falls back to text
        return None
    m = re.match(r"^<math[^>]*>(.*)</math>$", out, re.S)
    if not m:
        return None
    inner = m.group(1)
    # an accent sits on its base (no gap): MathML Core wants accent="true" on the mover
    from xml.dom.minidom import parseString

    try:
        doc = parseString(f"<mrow>{_numeric_entities(inner)}</mrow>")
    except Exception:  # noqa: BLE001 - not well-formed: do not embed it
        return None
    for mover in doc.getElementsByTagName("mover"):
        kids = [k for k in mover.childNodes if k.nodeType == k.ELEMENT_NODE]
        if (
            len(kids) == 2
            and kids[1].tagName == "mo"
            and kids[1].firstChild is not None
            and kids[1].firstChild.data in _ACCENTS
        ):
            mover.setAttribute("accent", "true")
    root = doc.documentElement
    inner = "".join(k.toxml() for k in root.childNodes)
    try:
        clean = clean_mathml(_numeric_entities(inner))
    except ValueError:
        return None
    return None if clean.dropped else clean.markup


# math delimited in running text: $...$ or \(...\) (an escaped \$ is not a delimiter)
_DELIMITED = re.compile(r"(?<!\\)\$(?!\$)(.+?)(?<!\\)\$|\\\((.+?)\\\)", re.S)


def text_with_math(text: str) -> str:
    """HTML of running text (a grader's message) with its math as inline MathML, through
    the whitelist sanitizer like all math here: delimited math (``$...$``, ``\\(...\\)``),
    a formula quoted in backticks, and LaTeX written bare in the text (a run of words
    holding a command such as ``\\dot{v}_{1}`` or a group ``E_{rot}``, with the short
    symbols, numbers and operators around it, see :func:`_bare_math`). Math cut short
    (``\\frac{1}{2}\\omega...``) is closed and shown followed by an ellipsis. The rest is
    escaped text; math that does not convert is shown in ``<code>``."""
    out, at = [], 0
    for m in _DELIMITED.finditer(text):
        inner = latex_to_mathml(m.group(1) if m.group(1) is not None else m.group(2))
        out.append(_with_bare_math(text[at : m.start()]))
        out.append(math_element(inner) if inner is not None else escape(m.group(0)))
        at = m.end()
    out.append(_with_bare_math(text[at:]))
    return "".join(out)


_QUOTED = re.compile(r"`([^`\n]{1,400})`")
_COMMAND = re.compile(r"\\[A-Za-z]+|[_^]\{")  # a TeX command or a braced script
_GLUE = re.compile(r"^[A-Za-z0-9_^{}()\[\]|=+\-*/<>'\u2212\u00d7\u00b7]{1,16}$")
_WORDS = {"a", "an", "as", "at", "be", "by", "if", "in", "is", "it", "no", "of", "on", "or", "so", "to", "we"}
_CUT = ("\\...", "...", "\u2026")


def _glue(word: str) -> bool:
    """A short symbol, number or operator that belongs to the formula beside it (not an
    English word, not a step name such as ``v_dot_1``)."""
    if not _GLUE.match(word) or word.lower() in _WORDS or word.count("_") > 1:
        return False
    if re.search(r"[A-Za-z]{3,}", word) or word.count("(") != word.count(")") or word.count("[") != word.count("]"):
        return False  # a word, or half of a parenthesis of the text around
    return len(word) == 1 or not word.isalpha() or bool(re.fullmatch(r"d[A-Za-z]", word))


def _bare_math(tex: str) -> str | None:
    """Inline MathML of bare LaTeX (closed first if it was cut short), or None."""
    tex = tex.replace("$", "")  # a delimiter left unpaired by a cut (a title shortened)
    cut = tex.endswith(_CUT)
    if cut:
        for end in _CUT:
            tex = tex.removesuffix(end)
        tex += "}" * max(0, tex.count("{") - tex.count("}"))
    inner = latex_to_mathml(tex)
    if inner is None:
        return None
    return math_element(inner) + ("\u2026" if cut else "")


def _with_bare_math(text: str) -> str:
    """Escaped ``text`` with its backtick-quoted and bare LaTeX as MathML."""
    out, at = [], 0
    for m in _QUOTED.finditer(text):
        out.append(_bare_runs(text[at : m.start()]))
        quoted = m.group(1)
        shown = _bare_math(quoted) if any(c in quoted for c in "\\_^{") else None
        out.append(shown if shown is not None else f"<code>{escape(quoted)}</code>")
        at = m.end()
    out.append(_bare_runs(text[at:]))
    return "".join(out)


def _bare_runs(text: str) -> str:
    """Escaped ``text`` with each run of words that holds a TeX command as MathML (a run
    ends at a word that is neither TeX nor :func:`_glue`, or at a word's trailing , ; : .)."""
    spans, run = [], []  # run: (start, end, is_tex) of its words

    def flush():
        while run and not run[-1][2] and not _glue_end(text[run[-1][0] : run[-1][1]]):
            run.pop()
        while run and not run[0][2]:
            run.pop(0)
        if run:
            spans.append((run[0][0], run[-1][1]))
        run.clear()

    for m in re.finditer(r"\S+", text):
        word, start = m.group(0), m.start()
        core = word.rstrip(",;:")
        if core.endswith(".") and not core.endswith(_CUT):
            core = core[:-1]
        if not core:
            flush()
            continue
        tex = bool(_COMMAND.search(core))
        if tex or _glue(core):
            run.append((start, start + len(core), tex))
            if core != word:  # trailing punctuation: the formula ends here
                flush()
        else:
            flush()
    flush()
    out, at = [], 0
    for start, end in spans:
        shown = _bare_math(text[start:end])
        out.append(escape(text[at:start]))
        out.append(shown if shown is not None else f"<code>{escape(text[start:end])}</code>")
        at = end
    out.append(escape(text[at:]))
    return "".join(out)


def _glue_end(word: str) -> bool:
    """May a formula end with this glue word? (a number or a symbol: not an operator)"""
    return not re.fullmatch(r"[=+\-*/<>\u2212\u00d7\u00b7]+", word)


class _Printer(MathMLPresentationPrinter):
    """SymPy's presentation printer with the field's symbol and function notation."""

    _default_settings = {**MathMLPresentationPrinter._default_settings, "display_names": {}}

    def __init__(self, settings=None):
        settings = dict(settings or {})
        settings.setdefault("mat_delim", "(")
        settings.setdefault("mul_symbol", _TIMES)
        super().__init__(settings)

    # -- small DOM helpers (SymPy's createTextNode writes text unescaped)
    def _el(self, tag, *children, text=None, **attrs):
        node = self.dom.createElement(tag)
        for k, v in attrs.items():
            node.setAttribute(k, v)
        if text is not None:
            node.appendChild(Document.createTextNode(self.dom, text))  # escaped on output
        for c in children:
            node.appendChild(c)
        return node

    def _mo(self, text, **attrs):
        return self._el("mo", text=text, **attrs)

    def _l_paren(self):
        return self._mo("(", stretchy="true")

    def _r_paren(self):
        return self._mo(")", stretchy="true")

    def _name_node(self, text: str):
        """A symbol name part: Greek names to letters; multi-letter ASCII as italic letters."""
        if text in greek_unicode:
            return self._el("mi", text=greek_unicode[text])
        if text.isdigit():
            return self._el("mn", text=text)
        m = re.match(r"^(\d+)([A-Za-z]+)$", text)  # "1xx": index then axes
        if m:
            return self._el("mrow", self._el("mn", text=m.group(1)), *[self._el("mi", text=ch) for ch in m.group(2)])
        if len(text) > 1 and text.isascii() and text.isalpha():
            # Ixx, cx: italic letters as TeX sets them (a multi-letter <mi> would be upright)
            return self._el("mrow", *[self._el("mi", text=ch) for ch in text])
        return self._el("mi", text=text)

    def _print_Symbol(self, sym, style="plain"):
        names = self._settings["display_names"]
        if sym in names:
            return self._foreign(names[sym])
        name, accent = sym.name, None
        for suffix, char in (("_ddot", DDOT), ("_dot", DOT)):
            if name.endswith(suffix) and len(name) > len(suffix):
                name, accent = name[: -len(suffix)], char
                break
        m = _INDEXED.match(name)
        if m and (m.group(1) in greek_unicode or len(m.group(1)) == 1):
            base, subs, supers = m.group(1), [m.group(2) + m.group(3)], []
        else:
            base, supers, subs = split_super_sub(name)
        node = self._name_node(base)
        if accent:
            node = self._el("mover", node, self._mo(accent), accent="true")

        def group(parts):
            nodes = [self._name_node(p) for p in parts]
            return nodes[0] if len(nodes) == 1 else self._el("mrow", *nodes)

        if subs and supers:
            return self._el("msubsup", node, group(subs), group(supers))
        if subs:
            return self._el("msub", node, group(subs))
        if supers:
            return self._el("msup", node, group(supers))
        return node

    _print_Dummy = _print_Symbol

    def _foreign(self, markup: str):
        """A MathML fragment (string) as a node of this document."""
        from xml.dom.minidom import parseString

        doc = parseString(f'<mrow xmlns="{MATHML_NS}">{markup}</mrow>')
        node = self.dom.importNode(doc.documentElement, True)
        node.removeAttribute("xmlns")
        while node.tagName == "mrow":  # unwrap single-child rows, so a power can see an msub
            kids = [k for k in node.childNodes if k.nodeType == k.ELEMENT_NODE or k.nodeValue.strip()]
            if len(kids) != 1 or kids[0].nodeType != kids[0].ELEMENT_NODE:
                break
            node = kids[0]
        return node

    def _apply(self, head, arg):
        """``head ⁡ arg``: parentheses only around a compound argument."""
        if arg.is_Symbol or arg.is_Number:
            inner = self._print(arg)
        else:
            inner = self._el("mrow", self._l_paren(), self._print(arg), self._r_paren())
        # thin spaces around the name, as TeX sets \sin (an operator between ordinary atoms)
        return self._el(
            "mrow", self._el("mspace", width="0.1667em"), head, self._mo(_APPLY, lspace="0", rspace="0.1667em"), inner
        )

    def _print_Function(self, e):
        name = type(e).__name__
        if name in _FUNCTIONS and len(e.args) == 1:
            return self._apply(self._el("mi", text=name), e.args[0])
        head = self._el("mi", text=name if name not in greek_unicode else greek_unicode[name])
        args = self._el("mrow", self._l_paren())
        for i, a in enumerate(e.args):
            if i:
                args.appendChild(self._mo(","))
            args.appendChild(self._print(a))
        args.appendChild(self._r_paren())
        return self._el("mrow", head, self._mo(_APPLY), args)

    def _print_Pow(self, e):
        base, exp = e.base, e.exp
        if isinstance(base, sp.Function) and type(base).__name__ in _FUNCTIONS and exp.is_Integer and exp > 0:
            head = self._el("msup", self._el("mi", text=type(base).__name__), self._print(exp))
            return self._apply(head, base.args[0])  # sin²θ₁, as written by hand
        if base.is_Symbol and exp.is_Integer and exp > 1:
            node = self._print(base)
            if node.tagName == "msub":  # θ̇₁²: index and power stacked, not the power on the index
                kids = [k for k in node.childNodes if k.nodeType == k.ELEMENT_NODE]
                return self._el("msubsup", kids[0], kids[1], self._print(exp))
        return super()._print_Pow(e)

    def _print_Number(self, e):
        if e.is_negative:  # −1 with a minus sign, not <mn>-1</mn> (a hyphen)
            return self._el("mrow", self._mo("\u2212"), self._print(-e))
        return super()._print_Number(e)

    def _print_int(self, p):
        if p < 0:
            return self._el("mrow", self._mo("\u2212"), self._print(-p))
        return super()._print_int(p)

    def _print_Float(self, e):
        if e.is_negative:
            return self._el("mrow", self._mo("\u2212"), self._print(-e))
        return super()._print_Float(e)

    def _print_MatrixBase(self, m, highlight=()):
        table = self._el("mtable")
        for i in range(m.rows):
            attrs = {"class": "hl"} if i in highlight else {}
            row = self._el("mtr", **attrs)
            for j in range(m.cols):
                row.appendChild(self._el("mtd", self._print(m[i, j]), **attrs))
            table.appendChild(row)
        if m.rows == 1:  # a row in running text or a table: parentheses of the text's size
            return self._el("mrow", self._mo("(", stretchy="false"), table, self._mo(")", stretchy="false"))
        return self._el("mrow", self._l_paren(), table, self._r_paren())

    def to_string(self, node) -> str:
        out = node.toxml().encode("ascii", "xmlcharrefreplace").decode()
        # a minus sign, not a hyphen: browsers draw <mo>-</mo> as the hyphen it is
        return _numeric_entities(out).replace("<mo>-</mo>", "<mo>&#x2212;</mo>")


def typeset_width(expr) -> float:
    """A rough width of ``expr`` as typeset, in letters-with-index units: enough to
    decide where to break a long sum into lines."""
    e = sp.sympify(expr)
    if e.is_Symbol:
        return 1.0
    if e.is_Number:
        return max(1.0, 0.6 * len(str(abs(e))))
    if isinstance(e, sp.Function):
        args = sum(typeset_width(a) for a in e.args)
        return 2.2 + args + (0 if all(a.is_Atom for a in e.args) else 1.0)
    if e.is_Pow:
        if e.exp.is_negative:
            return typeset_width(e.base**-e.exp)
        return typeset_width(e.base) + 0.5
    if e.is_Mul:
        num, den = sp.fraction(e)
        if den != 1:
            return max(typeset_width(num), typeset_width(den)) + 0.5
        return sum(typeset_width(a) for a in e.args if a != -1)
    if e.is_Add:
        return sum(typeset_width(a) for a in e.args) + 1.5 * len(e.args) + 1.0
    return float(len(str(e)))


class MathWriter:
    """Writes expressions of one report as MathML strings (content of ``<math>``).

    symbol_latex: optional mapping Symbol -> LaTeX (the student's notation for model
                  symbols, e.g. ``{theta1_dot: r"\\dot{\\theta}_1"}``); a LaTeX snippet
                  that cannot be converted falls back to the model's name.
    """

    def __init__(self, symbol_latex: dict | None = None):
        names = {}
        for sym, latex in (symbol_latex or {}).items():
            sym = sp.Symbol(sym) if isinstance(sym, str) else sym
            inner = latex_to_mathml(str(latex))
            if inner is not None:
                names[sym] = inner
        self._printer = _Printer({"display_names": names})

    def expr(self, expr) -> str:
        """One expression (scalar or matrix)."""
        p = self._printer
        return p.to_string(p._print(sp.sympify(expr)))

    def column(self, cells: list[str], highlight=(), muted=()) -> str:
        """A column vector from already-written cells, in stretchy parentheses;
        rows whose 0-based index is in ``highlight`` get ``class="hl"``, cells in
        ``muted`` ``class="zero"`` (drawn grey)."""
        rows = []
        for i, cell in enumerate(cells):
            cls = ' class="hl"' if i in highlight else ""
            td = cls or (' class="zero"' if i in muted else "")
            rows.append(f"<mtr{cls}><mtd{td}>{cell}</mtd></mtr>")
        return '<mrow><mo stretchy="true">(</mo><mtable>' + "".join(rows) + '</mtable><mo stretchy="true">)</mo></mrow>'

    def terms(self, terms: list[tuple], width: float | None = None) -> str:
        """``(coefficient, monomial)`` terms (see :func:`armdyn.symbolic.tidy.tidy_terms`)
        written coefficient first with folded signs: ``(m₁ + m₂) l₁² θ̈₁ − m₂ g d₂ sin θ₁``.

        width: break into lines (a left-aligned ``mtable``, continuation lines starting
        with their sign) where the sum is wider than this many units of
        :func:`typeset_width` (about one letter with its index each); None: one line.
        MathML Core has no automatic line breaking."""
        if not terms:
            return "<mn>0</mn>"
        pieces = []  # (sign or "", body, width estimate)
        for k, (coef, mono) in enumerate(terms):
            negative = coef.could_extract_minus_sign()
            if negative:
                coef = -coef
            if mono == 1:
                body = self.expr(coef)
            elif coef == 1:
                body = self.expr(mono)
            elif isinstance(coef, sp.Add):
                body = (
                    f'<mrow><mo stretchy="true">(</mo>{self.expr(coef)}<mo stretchy="true">)</mo></mrow>'
                    f"<mo>{_TIMES}</mo>{self.expr(mono)}"
                )
            elif any((f.is_Rational and f.q != 1) or (f.is_Pow and f.exp.is_negative) for f in sp.Mul.make_args(coef)):
                body = self.expr(coef * mono)
            else:
                body = f"{self.expr(coef)}<mo>{_TIMES}</mo>{self.expr(mono)}"
            sign = "\u2212" if negative else ("+" if k else "")
            pieces.append((sign, body, typeset_width(coef * mono) + 1.5))
        if width is None or sum(p[2] for p in pieces) <= width:
            return "<mrow>" + "".join((f"<mo>{sg}</mo>" if sg else "") + b for sg, b, _ in pieces) + "</mrow>"
        lines, line, used = [], [], 0.0
        for sg, b, w in pieces:
            if line and used + w > width:
                lines.append(line)
                line, used = [], 0.0
            line.append((sg, b))
            used += w
        lines.append(line)
        rows = []
        for k, line in enumerate(lines):
            # a line's leading sign is a prefix operator (no gap as after a binary one)
            cells = "".join(
                (f'<mo form="{"prefix" if i == 0 else "infix"}">{sg}</mo>' if sg else "") + b
                for i, (sg, b) in enumerate(line)
            )
            indent = '<mspace width="1.5em"/>' if k else ""
            rows.append(f'<mtr><mtd class="left">{indent}<mrow>{cells}</mrow></mtd></mtr>')
        return "<mtable>" + "".join(rows) + "</mtable>"

    def value(self, value, highlight=(), scalar=None) -> str:
        """A scalar or an (n, 1) vector; ``scalar`` (optional) writes each component
        (e.g. tidied terms), default :meth:`expr`."""
        scalar = scalar or self.expr
        if isinstance(value, sp.MatrixBase) and value.shape[1] == 1:
            return self.column([scalar(v) for v in value], highlight)
        if isinstance(value, sp.MatrixBase):
            p = self._printer
            return p.to_string(p._print_MatrixBase(value, highlight))
        return scalar(value)


def to_mathml(expr, symbol_latex: dict | None = None, display: bool = False, highlight=()) -> str:
    """``expr`` (SymPy expression or Matrix) as a complete ``<math>`` element.

    symbol_latex: Symbol -> LaTeX, to print those symbols in a student's notation.
    highlight:    0-based rows of a matrix to mark with ``class="hl"``.
    """
    return math_element(MathWriter(symbol_latex).value(sp.sympify(expr), highlight), display)
