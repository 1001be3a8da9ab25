"""Script-injection payloads and a static check of what armdyn writes as HTML.

Used by tests/test_html_security.py and by the ``html`` kind of tests/fuzz_campaign.py.

Every payload, if it ever ran, would append the text :data:`CANARY` to the page (built
at run time from character codes, so the payload's own source never contains it), and
the markup-only ones would create a ``<pwned-canary>`` element. Each carries a visible
token ``Q01Q``, ``Q02Q``, ... so a test can see that the payload reached the page at all.

:func:`html_findings` is a second opinion on the sanitizer, independent of it: the
standard library's HTML tokenizer (not xml.etree, which the sanitizer uses), run over
the whole page, lists every element outside armdyn's HTML and MathML vocabulary, every
event-handler, ``style``, ``src`` or link attribute, and every ``javascript:`` URL.
"""

from __future__ import annotations

import re
from html.parser import HTMLParser

#: what an executed payload writes into the page
CANARY = "XSS!"
_JS = "document.body.append(String.fromCharCode(88,83,83,33))"
_NAV = "location.replace(String.fromCharCode(97,98,111,117,116,58,98,108,97,110,107))"  # about:blank

_RAW = [
    r"\text{<script>JS</script>QnnQ}",
    r"<script>JS</script>QnnQ",
    r"\text{<img src=x onerror=JS>QnnQ}",
    r"<img src=x onerror=JS>QnnQ",
    r"\text{<svg onload=JS>QnnQ</svg>}",
    r"\href{javascript:JS}{QnnQ}",
    r"\href{JaVaScRiPt:NAV}{QnnQ}",
    r"\href{&#106;avascript&#58;JS}{QnnQ}",
    r"\style{background:url(javascript:JS)}{QnnQ}",
    r"\style{width:expression(JS)}{QnnQ}",
    r"\text{</math><script>JS</script>QnnQ}",
    r"</math><img src=x onerror=JS>QnnQ",
    r"\text{]]><script>JS</script>QnnQ}",
    r"<![CDATA[<script>JS</script>]]>QnnQ",
    r"\text{&lt;script&gt;JS&lt;/script&gt;QnnQ}",
    r"\text{&#60;img src=x onerror=JS&#62;QnnQ}",
    r"\text{<ScRiPt>JS</sCrIpT>QnnQ}",
    r"\text{\u003cscript\u003eJS\u003c/script\u003eQnnQ}",
    r"\text{<mtext><img src=x onerror=JS></mtext>QnnQ}",
    r"\text{<annotation-xml encoding='text/html'><script>JS</script></annotation-xml>QnnQ}",
    r"\text{<a href='javascript:JS'>QnnQ</a>}",
    r"\text{<iframe src='javascript:JS'></iframe>QnnQ}",
    r"\text{<meta http-equiv='refresh' content='0;url=javascript:JS'>QnnQ}",
    r"\text{<pwned-canary>QnnQ</pwned-canary>}",
    r"\text{<mi onmouseover=JS style='display:block;width:9999px;height:9999px'>QnnQ</mi>}",
    r"\unicode{x3C}script\unicode{x3E}JS\unicode{x3C}/script\unicode{x3E}QnnQ",
    r"\text{<base href='javascript:JS//'>QnnQ}",
    r"\text{<!--<script>JS</script>-->QnnQ}",
    r"\mathrm{<details open ontoggle=JS>}QnnQ",
    r"\text{<form action='javascript:JS'><button>QnnQ</button></form>}",
    r"\text{<object data='javascript:JS'></object>QnnQ}",
    "\uff1cscript\uff1eJS\uff1c/script\uff1eQnnQ",
    r"\text{<svg><a xlink:href='javascript:NAV'><text>QnnQ</text></a></svg>}",
    r"\text{<style>*{background:url(javascript:JS)}</style>QnnQ}",
    r"\text{<math><mtext><img src=x onerror=JS></mtext></math>QnnQ}",
    r"\text{<body onload=JS>QnnQ}",
    "\\text{\x00<script>JS</script>QnnQ}",
]
#: (token, payload) pairs
PAYLOADS = [
    (f"Q{i:02d}Q", p.replace("QnnQ", f"Q{i:02d}Q").replace("NAV", _NAV).replace("JS", _JS))
    for i, p in enumerate(_RAW, 1)
]
#: fragments the fuzz campaign combines at random
FRAGMENTS = [
    "<script>",
    "</script>",
    "<img src=x onerror=",
    "<svg onload=",
    "javascript:",
    "JaVaScRiPt:",
    "&#106;",
    "&lt;",
    "&gt;",
    "&amp;",
    "&#60;",
    "&#x3C;",
    "</math>",
    "<math>",
    "]]>",
    "<![CDATA[",
    "<!--",
    "-->",
    "\\text{",
    "\\href{",
    "\\style{",
    "\\mathrm{",
    "\\unicode{x3C}",
    "\\color{",
    "}",
    "{",
    "\\",
    "_",
    "^",
    "'",
    '"',
    "=",
    "<",
    ">",
    "/",
    " ",
    "\x00",
    "\x0b",
    "\ufffe",
    "\u2028",
    "\uff1c",
    "\U0001d703",
    "theta",
    "\\dot{",
    "\\frac{",
    "<annotation-xml encoding='text/html'>",
    "<mtext>",
    "<mi",
    " style=",
    " onmouseover=",
    "xlink:href=",
    "<pwned-canary>",
    "alert(1)",
    _JS,
    "\\begin{pmatrix}",
    "\\\\",
    "&",
    "\\left(",
    "\\right)",
    "<a href=",
]

#: the HTML elements armdyn's pages and fragments use
HTML_ELEMENTS = frozenset(
    {
        "html",
        "head",
        "meta",
        "title",
        "style",
        "body",
        "main",
        "div",
        "span",
        "p",
        "b",
        "h1",
        "h2",
        "h3",
        "ol",
        "ul",
        "li",
        "a",
        "pre",
        "code",
        "details",
        "summary",
        "section",
        "table",
        "tr",
        "th",
        "td",
    }
)
#: the MathML elements the sanitizer lets through (written out again: a second opinion)
MATHML_ELEMENTS = frozenset(
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
_LINK_ATTRS = {
    "href",
    "src",
    "xlink:href",
    "action",
    "formaction",
    "data",
    "srcdoc",
    "background",
    "poster",
    "style",
    "srcset",
    "ping",
    "codebase",
    "lowsrc",
    "dynsrc",
}
_CONTROL = re.compile(r"[\x00-\x20\x7f]+")


class _Scan(HTMLParser):
    def __init__(self):
        super().__init__(convert_charrefs=True)
        self.findings: list[str] = []
        self.text: list[str] = []
        self.meta: list[dict] = []
        self._in_style = False

    def handle_starttag(self, tag, attrs):
        if tag not in HTML_ELEMENTS | MATHML_ELEMENTS:
            self.findings.append(f"element <{tag}>")
        if tag == "meta":
            self.meta.append(dict(attrs))
            if (dict(attrs).get("http-equiv") or "").lower() == "refresh":
                self.findings.append("meta refresh")
        self._in_style = tag == "style"
        for name, value in attrs:
            value = value or ""
            squashed = _CONTROL.sub("", value).lower()
            if name.startswith("on"):
                self.findings.append(f"<{tag} {name}=...>")
            if "javascript:" in squashed or "vbscript:" in squashed or "data:text/html" in squashed:
                self.findings.append(f"<{tag} {name}={value[:40]!r}>")
            if name in _LINK_ATTRS and not (name == "href" and tag == "a" and re.fullmatch(r"#step-\d+", value)):
                self.findings.append(f"<{tag} {name}={value[:40]!r}>")

    handle_startendtag = handle_starttag

    def handle_endtag(self, tag):
        self._in_style = False

    def handle_data(self, data):
        if not self._in_style:
            self.text.append(data)

    def handle_comment(self, data):
        self.findings.append(f"comment <!--{data[:40]}-->")

    def handle_decl(self, decl):
        if decl.lower() != "doctype html":
            self.findings.append(f"declaration <!{decl[:40]}>")

    def unknown_decl(self, data):
        self.findings.append(f"declaration <![{data[:40]}")

    def handle_pi(self, data):
        self.findings.append(f"processing instruction <?{data[:40]}")


def scan(markup: str) -> _Scan:
    """Tokenize ``markup`` as HTML (see :func:`html_findings`)."""
    s = _Scan()
    s.feed(markup)
    s.close()
    return s


def html_findings(markup: str) -> list[str]:
    """What in ``markup`` (a page or a fragment) could run script or load anything: an
    empty list for a safe page."""
    s = scan(markup)
    found = list(s.findings)
    if re.search(r"<\s*/?\s*script", markup, re.IGNORECASE):
        found.append("'<script' in the markup")
    return found


def visible_text(markup: str) -> str:
    """The page's text content (entities decoded, stylesheet left out)."""
    return "".join(scan(markup).text)
