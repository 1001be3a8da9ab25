"""Fuzz kinds html, names, aliases and towers (driven by fuzz_campaign.py, whose docstring
says what each kind sends and what counts as a finding)."""

from __future__ import annotations

import json
import random
import re
import time
import xml.etree.ElementTree as ET

from fuzz_models import _SAFE_DUMPER, _SAFE_LOADER, _paths, _seed_text

# ------------------------------------------------------------------ kind "html": payloads into HTML


def _html_text(rng: random.Random) -> str:
    """A random string of payload fragments, whole payloads and random characters."""
    from html_payloads import FRAGMENTS, PAYLOADS

    parts = []
    for _ in range(rng.randint(1, 8)):
        r = rng.random()
        if r < 0.6:
            parts.append(rng.choice(FRAGMENTS))
        elif r < 0.75:
            parts.append(rng.choice(PAYLOADS)[1])
        elif r < 0.9:
            parts.append(
                "".join(
                    chr(rng.choice([rng.randrange(32, 127), rng.randrange(0, 0x3000)]))
                    for _ in range(rng.randint(1, 6))
                )
            )
        else:
            parts.append(rng.choice(["Q", "theta1", "l_1", "\\omega", "x"]))
    return "".join(parts)


def _check_math(markup: str) -> None:
    """A ``<math>`` element armdyn wrote: safe by the independent check, well-formed,
    whitelisted, and a fixed point of the sanitizer."""
    from html_payloads import html_findings

    from armdyn.mathml_sanitize import ATTRIBUTES, ELEMENTS, sanitize_mathml

    found = html_findings(markup)
    if found:
        raise AssertionError(f"live markup {found[:3]} in {markup[:200]!r}")
    root = ET.fromstring(markup)
    for el in root.iter():
        if el.tag.split("}")[-1] not in ELEMENTS:
            raise AssertionError(f"element {el.tag} in {markup[:200]!r}")
        for name, value in el.attrib.items():
            if name not in ATTRIBUTES or not ATTRIBUTES[name].fullmatch(value):
                raise AssertionError(f"attribute {name}={value!r} in {markup[:200]!r}")
    inner = markup[markup.index(">") + 1 : markup.rindex("</math>")]
    if sanitize_mathml(inner) != inner:
        raise AssertionError(f"the sanitizer is not idempotent on {inner[:200]!r}")


def run_html(seed: int, rng: random.Random):
    text = _html_text(rng)
    r = rng.random()
    try:  # only a model may be refused (ModelError): any other error here is a finding
        _html_case(text, r, rng)
    except (ValueError, TypeError) as err:
        if type(err).__name__ == "ModelError":
            raise
        raise AssertionError(f"{type(err).__name__}: {err}") from None


def _html_case(text: str, r: float, rng: random.Random):
    import sympy as sp
    from html_payloads import html_findings

    from armdyn.htmlpage import page
    from armdyn.mathml import MathWriter, escape, latex_to_mathml, math_element

    if r < 0.4:  # a student's LaTeX label (grade report, derive step label)
        inner = latex_to_mathml(text)
        _check_math(math_element(inner if inner is not None else f"<mtext>{escape(text)}</mtext>"))
    elif r < 0.7:  # raw markup: the sanitizer alone
        _check_math(math_element(text))
    elif r < 0.95:  # names in the printer, and a student's notation for a symbol
        a, b = sp.Symbol(text), sp.Symbol("theta1_dot")
        w = MathWriter({b: _html_text(rng)} if rng.random() < 0.5 else None)
        _check_math(math_element(w.expr(rng.choice([a, a**2 * b, sp.sin(a) + b / a, sp.Matrix([a, b])]))))
    else:  # a model's names in Robot._repr_html_ and a page's title
        from armdyn.io.yaml import load_yaml_string

        names = {"name: rp-arm": None, "name: link1": "link1", "name: theta1": None}
        model = _seed_text("rp-arm")
        for old, ref in names.items():
            new = json.dumps(_html_text(rng))
            model = model.replace(old, f"name: {new}")
            if ref:
                model = model.replace(f"child: {ref}", f"child: {new}").replace(f"parent: {ref}", f"parent: {new}")
        robot = load_yaml_string(model, source="fuzz.yaml")
        for markup in (robot._repr_html_(), page(robot.name, f"<p>{escape(robot.name)}</p>")):
            found = html_findings(markup)
            if found:
                raise AssertionError(f"live markup {found[:3]} for names {robot.name!r}, {list(robot.links)}")


#: kinds that are one function (seed, rng) each
RUNNERS = {"html": run_html}
# ------------------------------------------------------------------ untrusted names and values
# Kinds "names", "aliases" and "towers": self-contained (one function an input each) and
# registered in SECURITY_KINDS; each input must end in a result or a ModelError (anything
# else, or more than SECURITY_SECONDS, is raised as an AssertionError: a finding).
SECURITY_SECONDS = 5.0
NAME_PIECES = [
    "*/",
    "/*",
    '"""',
    "'''",
    '"',
    "'",
    "\\",
    "??/",
    "?",
    "*",
    "/",
    "#",
    "\\n",
    "`",
    "$",
    "{",
    "}",
    "q1",
    "\uff51\uff11",
    "\u0131",
    "\u212a",
    "\ufb01",
    "\u00b5",
    "\u03bc",
    "\u202e",
    "\u00e9",
    "e\u0301",
    "\U0001d42a",
    "_",
    "__",
    "0",
    "9",
    " ",
    "-",
    ".",
    "x",
    "int",
    "return",
    "None",
    "l",
    "k",
    "memcpy",
    "M_PI",
    "p",
    "q",
    "out",
    'system("id")',
    "__import__('os')",
    "\u3000",
    "\ufeff",
    "\ud7ff",
]


def _random_name(rng: random.Random) -> str:
    name = "".join(rng.choice(NAME_PIECES) for _ in range(rng.randint(1, 6)))
    return name if name.isprintable() else "x" + name.encode("unicode_escape").decode()


def run_names(seed: int, rng: random.Random):
    """Random hostile robot and joint names into the header printer and the identifier
    table, without compiling: the header as a Python docstring must parse to exactly
    that docstring, as a C comment hold no comment end; every identifier is ASCII,
    unique (also after NFKC normalisation) and no keyword."""
    import ast
    import keyword
    import types
    import unicodedata

    import sympy as sp

    from armdyn.printing.generate import identifier
    from armdyn.printing.printers import _C_RESERVED, Names, _header_lines

    names = [_random_name(rng) for _ in range(rng.randint(1, 5))]
    if rng.random() < 0.3:  # a pair equal under NFKC, or under case
        names.append(unicodedata.normalize("NFKC", names[0]) if rng.random() < 0.5 else names[0].upper())
    names = list(dict.fromkeys(names))
    q = [sp.Symbol(n) for n in names]
    qd = [sp.Symbol(f"{n}_dot") for n in names]
    robot_name = _random_name(rng)
    prefix = identifier(robot_name)
    table = Names(q + qd, taken=[f"{prefix}_tau"])
    idents = [table.name(s) for s in q + qd]
    for ident in idents:
        if not re.fullmatch(r"[A-Za-z][A-Za-z0-9_]*", ident) or keyword.iskeyword(ident) or ident in _C_RESERVED:
            raise AssertionError(f"identifier {ident!r}")
    if len({unicodedata.normalize("NFKC", i) for i in idents} | {f"{prefix}_tau"}) != len(idents) + 1:
        raise AssertionError(f"identifiers not unique: {idents}")
    if not re.fullmatch(r"[A-Za-z][A-Za-z0-9_]*", prefix) or len(prefix) > 48:
        raise AssertionError(f"function prefix {prefix!r}")
    code = types.SimpleNamespace(
        robot_name=robot_name,
        dof=len(q),
        coordinate_names=names,
        q=q,
        qd=qd,
        qdd=[],
        op_counts={"tau": {"mul": 1, "add": 1, "sin_cos": 0, "other": 0}},
        functions={"tau": f"{prefix}_tau"},
        sources={"tau": _random_name(rng)},
        parameters=q[:1],
        definitions=[(q[0], sp.Symbol(names[-1]) ** 2)],
        names=table,
    )
    python = '"""\n' + "\n".join(_header_lines(code, "")) + '\n"""\nx = 1\n'
    tree = ast.parse(python)
    if len(tree.body) != 2 or not isinstance(tree.body[1], ast.Assign) or not python.isascii():
        raise AssertionError("the docstring header is not one docstring")
    c = "\n".join(_header_lines(code, " *"))
    if "*/" in c or "??" in c or "\\" in c or not c.isascii():
        raise AssertionError("the C header holds a comment end, a trigraph or a backslash")


def _must_be_model_error(load, what: str):
    """``load()`` returns or raises ModelError, within SECURITY_SECONDS."""
    from armdyn.errors import ModelError

    start = time.monotonic()
    refused = None
    try:
        load()
    except ModelError as err:
        refused = err  # counted as a clear error (below), once the time is checked
    except Exception as err:  # noqa: BLE001 - anything else is the finding
        raise AssertionError(f"{what}: {type(err).__name__}: {str(err)[:200]}") from None
    seconds = time.monotonic() - start
    if seconds > SECURITY_SECONDS:
        raise AssertionError(f"{what}: {seconds:.1f} s")
    if refused is not None:
        raise refused


def run_aliases(seed: int, rng: random.Random):
    """An alias bomb (or deep nesting, or a huge integer) as the value of a random field
    of planar-2r (top-level, joint or link key, list item; scalar- or mapping-valued)."""
    import yaml

    from armdyn.io.yaml import load_yaml_string

    doc = yaml.load(_seed_text("planar-2r"), Loader=_SAFE_LOADER)
    container, key = rng.choice(list(_paths(doc)))
    marker = "FUZZ_VALUE_MARKER"
    container[key] = marker
    text = yaml.dump(doc, Dumper=_SAFE_DUMPER, sort_keys=False, allow_unicode=True, width=10**6)
    r = rng.random()
    if r < 0.6:
        width, levels = rng.randint(2, 10), rng.randint(1, 14)
        items = [f"&a0 [{', '.join(['lol'] * width)}]"]
        items += [f"&a{i} [{', '.join([f'*a{i - 1}'] * width)}]" for i in range(1, levels)]
        if rng.random() < 0.5:
            value = "{" + ", ".join(f"k{i}: {v}" for i, v in enumerate(items)) + "}"
        else:
            value = "[" + ", ".join(items) + "]"
    elif r < 0.85:
        depth = rng.choice([10, 63, 64, 65, 100, 1000, 3000, 10_000])
        value = "[" * depth + "1" + "]" * depth if rng.random() < 0.5 else "{a: " * depth + "1" + "}" * depth
    else:
        size = rng.choice([300, 400, 401, 4300, 4301, 5000, 20_000])
        value = ("-" if rng.random() < 0.3 else "") + "".join(rng.choice("0123456789") for _ in range(size))
    text = text.replace(marker, value, 1)
    _must_be_model_error(lambda: load_yaml_string(text, source="fuzz.yaml"), f"seed {seed}")


TOWER_ATOMS = [
    "2",
    "999",
    "999.0",
    "2.0",
    "1e300",
    "1e-300",
    "0.5",
    "10",
    "m1",
    "l1",
    "pi",
    "-1",
    "0",
    "1",
    "7" * 400,
    "7" * 401,
    "1.5e308",
]
TOWER_FUNCTIONS = ["sin", "cos", "tan", "exp", "sinh", "cosh", "log", "sqrt", "atan", "abs"]


def _tower(rng: random.Random, depth: int) -> str:
    if depth == 0 or rng.random() < 0.2:
        return rng.choice(TOWER_ATOMS)
    r = rng.random()
    a, b = _tower(rng, depth - 1), _tower(rng, depth - 1)
    if r < 0.5:
        return f"({a})**({b})" if rng.random() < 0.5 else f"{a}**{b}"
    if r < 0.75:
        return f"{rng.choice(TOWER_FUNCTIONS)}({a})"
    return f"({a}){rng.choice(['*', '/', '+', '-', '^'])}({b})"


def run_towers(seed: int, rng: random.Random):
    """A random tower of powers, exponentials and products in a model expression: the
    expression parser on its own (99 inputs in 100), or a whole planar-2r model with the
    expression as a link's mass (1 in 100)."""
    import sympy as sp

    from armdyn.io.expressions import parse_expression
    from armdyn.io.yaml import load_yaml_string

    expr = _tower(rng, rng.randint(1, 6))
    if rng.random() < 0.99:
        params = {"m1": sp.Symbol("m1"), "l1": sp.Symbol("l1")}
        _must_be_model_error(
            lambda: parse_expression(expr, params, "link 'l'", "fuzz.yaml:3", "mass"), f"seed {seed}: {expr[:80]}"
        )
        return
    text = _seed_text("planar-2r").replace("mass: m2", f"mass: {json.dumps(expr)}", 1)
    _must_be_model_error(lambda: load_yaml_string(text, source="fuzz.yaml"), f"seed {seed}: {expr[:80]}")


SECURITY_KINDS = {"names": run_names, "aliases": run_aliases, "towers": run_towers}
