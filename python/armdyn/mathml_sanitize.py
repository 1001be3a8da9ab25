"""A whitelist sanitizer for MathML that came from text armdyn does not control.

Students' LaTeX (step labels, their notation for symbols) is converted by the
``latex2mathml`` package, and names from a model file (robot, links, joints,
parameters) reach the MathML printer; neither the text nor the converter's output is
trusted: ``\\text{<script>...}`` comes out of latex2mathml as a live ``<script>``
element, ``\\href{javascript:...}`` and ``\\style{...}`` as live attributes.

:func:`sanitize_mathml` parses a fragment with ``xml.etree`` (no regular expressions
on markup) and writes it back keeping only

* the presentation elements of MathML Core that reports need (:data:`ELEMENTS`:
  tokens, scripts, fractions, roots, tables, ``mstyle``/``mpadded``/``mphantom``/
  ``menclose``, and ``semantics`` with a text-only ``annotation``);
* attributes from :data:`ATTRIBUTES`, each with a value matching its own pattern
  (enumerated words, ``true``/``false``, plain lengths, small integers, a colour name
  or ``#hex``, class names armdyn's stylesheet defines) -- never ``href``, ``style``,
  ``on*``, ``xlink:*``, ``src``, ``id``, or anything in another namespace;
* text, escaped (``&``, ``<``, ``>``; non-ASCII as numeric references).

An element not in the list is dropped with everything inside it (counted in
:attr:`Sanitized.dropped`, so a caller can fall back to showing the source as text);
so is anything nested deeper than :data:`MAX_DEPTH`. Comments, processing
instructions and CDATA markers do not survive parsing; a document type declaration
(entity expansion) is not well-formed inside the wrapper and is rejected; characters
XML cannot carry (C0 controls, lone surrogates) become U+FFFD. The output
is well-formed XML and parses as the same tree in an HTML5 page.
"""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET
from dataclasses import dataclass

__all__ = ["ATTRIBUTES", "CLASSES", "ELEMENTS", "MAX_DEPTH", "Sanitized", "clean_mathml", "sanitize_mathml"]

MATHML_NS = "http://www.w3.org/1998/Math/MathML"

#: MathML elements that may appear in a report (``math`` only as the outermost one)
ELEMENTS = frozenset(
    {
        "math",
        "mrow",
        "mi",
        "mn",
        "mo",
        "ms",
        "mtext",
        "mspace",
        "msub",
        "msup",
        "msubsup",
        "munder",
        "mover",
        "munderover",
        "mmultiscripts",
        "mprescripts",
        "none",
        "mfrac",
        "msqrt",
        "mroot",
        "mtable",
        "mtr",
        "mtd",
        "mstyle",
        "mpadded",
        "mphantom",
        "menclose",
        "merror",
        "semantics",
        "annotation",
    }
)
#: class names armdyn's stylesheet gives meaning to (htmlpage.CSS)
CLASSES = frozenset({"hl", "zero", "long", "left"})
#: deeper subtrees are dropped (a browser's parser gives up nesting at a few hundred)
MAX_DEPTH = 200
# characters XML 1.0 cannot carry (a NUL in a name): replaced by U+FFFD before parsing
_NOT_XML = re.compile("[\x00-\x08\x0b\x0c\x0e-\x1f\ud800-\udfff\ufffe\uffff]")

# at most 9999 units: a label cannot push the page kilometres wide
_NUMBER = r"[+-]?(?:\d{1,4}(?:\.\d{0,6})?|\.\d{1,6})"
_LENGTH = (
    rf"{_NUMBER}(?:em|ex|px|pt|pc|in|cm|mm|%|mu)?"
    r"|(?:negative)?(?:very){0,2}(?:thin|thick)mathspace|(?:negative)?mediummathspace|infinity"
)
_BOOL = r"true|false"
_ALIGN = r"left|center|right|top|bottom|baseline|axis|decimalpoint"
_LINES = r"none|solid|dashed"
_NOTATION = (
    r"longdiv|actuarial|phasorangle|radical|box|roundedbox|circle|left|right|top|bottom"
    r"|updiagonalstrike|downdiagonalstrike|verticalstrike|horizontalstrike|northeastarrow"
    r"|madruwb|updiagonalarrow"
)
_VARIANT = (
    r"normal|bold|italic|bold-italic|double-struck|bold-fraktur|script|bold-script|fraktur"
    r"|sans-serif|bold-sans-serif|sans-serif-italic|sans-serif-bold-italic|monospace|initial"
    r"|tailed|looped|stretched"
)


def _words(word: str, most: int = 64) -> str:
    """A space-separated list of up to ``most`` items each matching ``word``."""
    return rf"(?:{word})(?:\s+(?:{word})){{0,{most - 1}}}"


#: attribute -> the whole value must match this pattern (any element of ELEMENTS)
ATTRIBUTES = {
    name: re.compile(rf"\s*(?:{pattern})\s*")
    for name, pattern in {
        "display": r"block|inline",
        "mathvariant": _VARIANT,
        "displaystyle": _BOOL,
        "stretchy": _BOOL,
        "fence": _BOOL,
        "separator": _BOOL,
        "symmetric": _BOOL,
        "largeop": _BOOL,
        "movablelimits": _BOOL,
        "accent": _BOOL,
        "accentunder": _BOOL,
        "bevelled": _BOOL,
        "equalrows": _BOOL,
        "equalcolumns": _BOOL,
        "form": r"prefix|infix|postfix",
        "lspace": _LENGTH,
        "rspace": _LENGTH,
        "width": _LENGTH,
        "height": _LENGTH,
        "depth": _LENGTH,
        "voffset": _LENGTH,
        "minsize": _LENGTH,
        "maxsize": _LENGTH,
        "linethickness": _LENGTH + r"|thin|medium|thick",
        "mathsize": _LENGTH + r"|small|normal|big",
        "scriptlevel": r"[+-]?\d{1,2}",
        "columnalign": _words(r"left|center|right"),
        "rowalign": _words(_ALIGN),
        "align": _words(_ALIGN),
        "columnlines": _words(_LINES),
        "rowlines": _words(_LINES),
        "frame": _LINES,
        "columnspacing": _words(_LENGTH),
        "rowspacing": _words(_LENGTH),
        "framespacing": _words(_LENGTH, 2),
        "columnspan": r"\d{1,3}",
        "rowspan": r"\d{1,3}",
        "notation": _words(_NOTATION, 8),
        "mathcolor": r"#[0-9A-Fa-f]{3,8}|[A-Za-z]{1,20}",
        "mathbackground": r"#[0-9A-Fa-f]{3,8}|[A-Za-z]{1,20}",
        "dir": r"ltr|rtl",
        "encoding": r"[A-Za-z0-9.+/-]{1,40}",
        "class": _words("|".join(sorted(CLASSES)), 4),
    }.items()
}


@dataclass
class Sanitized:
    """The sanitizer's output: ``markup`` (well-formed, whitelisted MathML) and what
    it took out: ``dropped`` elements (with their subtrees), ``stripped`` attributes."""

    markup: str
    dropped: int = 0
    stripped: int = 0


def _text(s: str | None) -> str:
    if not s:
        return ""
    s = s.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;")
    return s.encode("ascii", "xmlcharrefreplace").decode()


def _attr(s: str) -> str:
    return _text(s).replace('"', "&quot;")


def _local(name: str) -> str | None:
    """The local name of a tag/attribute in no namespace or MathML's; None otherwise."""
    if name.startswith("{"):
        ns, _, local = name[1:].partition("}")
        return local if ns == MATHML_NS else None
    return name


class _Writer:
    def __init__(self):
        self.out: list[str] = []
        self.dropped = 0
        self.stripped = 0

    def element(self, el: ET.Element, depth: int, top: bool) -> None:
        tag = _local(el.tag) if isinstance(el.tag, str) else None
        if tag not in ELEMENTS or (tag == "math" and not top) or depth > MAX_DEPTH:
            self.dropped += 1
            return
        attrs = []
        if tag == "math":
            attrs.append(f'xmlns="{MATHML_NS}"')
        for key, value in el.attrib.items():
            name = _local(key)
            pattern = ATTRIBUTES.get(name) if name is not None else None
            if pattern is None or not pattern.fullmatch(value) or (name == "display" and tag != "math"):
                self.stripped += 1
                continue
            attrs.append(f'{name}="{_attr(value.strip())}"')
        self.out.append(f"<{tag}" + "".join(" " + a for a in attrs) + ">")
        self.out.append(_text(el.text))
        for child in el:
            if tag == "annotation":  # text only: markup in an annotation is dropped
                self.dropped += 1
            else:
                self.element(child, depth + 1, False)
            self.out.append(_text(child.tail))
        self.out.append(f"</{tag}>")


def clean_mathml(markup: str) -> Sanitized:
    """Sanitize a MathML fragment (content of ``<math>``, or whole ``<math>`` elements):
    see the module's docstring. Raises ValueError when it is not well-formed XML
    (numeric character references only: no HTML named entities)."""
    try:
        root = ET.fromstring(f"<armdyn-fragment>{_NOT_XML.sub(chr(0xFFFD), markup)}</armdyn-fragment>")
    except ET.ParseError as exc:
        raise ValueError(f"MathML is not well-formed: {exc}") from None
    w = _Writer()
    w.out.append(_text(root.text))
    for child in root:
        w.element(child, 1, True)
        w.out.append(_text(child.tail))
    return Sanitized("".join(w.out), w.dropped, w.stripped)


def sanitize_mathml(markup: str) -> str:
    """:func:`clean_mathml`'s markup; a fragment that is not well-formed becomes an
    ``<merror>`` saying so (never the input)."""
    try:
        return clean_mathml(markup).markup
    except ValueError:
        return "<merror><mtext>unprintable (not well-formed MathML)</mtext></merror>"
