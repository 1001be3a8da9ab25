"""A long fuzz campaign, outside CI (pytest does not collect this file):

    PYTHONPATH=python python3 tests/fuzz_campaign.py --count 100000          # each kind
    PYTHONPATH=python python3 tests/fuzz_campaign.py --kinds arrays --count 100000
    PYTHONPATH=python python3 tests/fuzz_campaign.py --minutes 20            # stop early

Kinds of input (each from a fixed seed, so a finding can be replayed):

* ``yaml``:   the bundled frame-based YAML models (rp-arm, planar-2r, panda... the small
  ones), mutated structurally (a value replaced by a hostile one, a key dropped, an item
  duplicated) or as text (cut, spliced, bytes flipped), then loaded;
* ``dh``:     the same for the DH-table models (planar-3r, scara, puma560, ur5, ...);
* ``urdf``:   a hand-made URDF and the bundled iiwa14, mutated as XML (attributes set to
  hostile numbers, elements dropped or duplicated, names swapped) or as text;
* ``arrays``: random arrays (shapes, dtypes, NaN/inf/huge values, non-contiguous, object
  and complex arrays, odd ``threads``/``link`` values) into every numeric function of a
  few compiled robots;
* ``html``:   payloads into HTML (run it with ``--kinds html``): random strings of script
  and markup fragments (tests/html_payloads.py) as a student's LaTeX label, as raw
  MathML for the sanitizer, as symbol names in the MathML printer and as a model's
  robot/link/joint names in ``Robot._repr_html_`` and a page; the output must pass an
  HTML tokenizer's check independent of the sanitizer (no foreign element, no on*
  attribute, no link or style attribute, no ``javascript:``), parse as XML with only
  whitelisted MathML, and the sanitizer must be idempotent on it.
* ``names``:  names into codegen: hostile robot and joint names (comment and docstring
  ends, trigraphs, NFKC look-alikes) through the header printer and the identifier table
  (no compiling: the header must parse as one docstring and hold no comment end; the
  identifiers must be ASCII, unique, no keyword);
* ``aliases``: alias bombs in every field of planar-2r (and deep nesting, huge integers);
* ``serve``:  hostile sizes and timings against ``armdyn serve`` on 127.0.0.1 (a server
  per worker process): bodies of 0 B to 3 MB, NUL and invalid UTF-8, odd content types,
  query values and submission ids, and raw connections that stop mid-head, trickle,
  lie about their length or send a 200 kB head. Each answer must be below 500 (503
  with Retry-After only for previews) and ``/api/health`` 200 afterwards (the database:
  a fresh SQLite file, or ``ARMDYN_FUZZ_SERVE_DB``, e.g. a throwaway PostgreSQL). Use a small
  ``--count`` (each input is a request; ~1000 take a minute or two);
* ``towers``: power towers (powers, exponentials, products of huge numbers) in model
  expressions. For these three anything but a result or a ``ModelError`` within 5 s is a
  finding;
* ``codemodels``: model files that try to run code (run it with ``--kinds codemodels``):
  xacro ``${...}`` payloads (the ``vars()``/``type()`` bypass of xacro's filter),
  ``.xacro`` files, includes and ``package://``/``file://`` URIs in URDF, YAML tags that
  construct Python objects, Python in DH and frame expressions; loaded untrusted, each
  must end in a result or a ``ModelError`` within 5 s and leave no marker file;
* ``classes``: hostile class folders for ``armdyn grade DIR``'s discovery (spoofed
  ``student:``/``variant:``, colliding report names, models named by paths out of the
  folder, symbolic links to files outside, to /dev/zero and FIFOs): every student is
  the file's name, no link is followed, no two reports share a name, every model is
  bundled or a regular file in the folder, and no payload runs.

A model that loads is bound to its defaults and, when numeric, compiled and evaluated
once. Each input must end in a result or an expected error (``ModelError``,
``ValueError``, ``TypeError``, ``UnboundParameterError``) within ``--timeout`` seconds.
Everything else is a finding: another exception, a timeout (hang), a worker that dies
(crash), or a Rust panic message on stderr. Workers run chunks of inputs in separate
processes; stderr of each is captured at the file-descriptor level and searched for
"panicked". Prints one line of counts per kind and exits 1 if anything was found.
"""

from __future__ import annotations

import argparse
import contextlib
import copy
import json
import os
import random
import re
import signal
import subprocess
import sys
import tempfile
import time
import warnings
import xml.etree.ElementTree as ET
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
ROBOTS = ROOT / "python" / "armdyn" / "robots"
YAML_SEEDS = ["rp-arm", "planar-2r", "panda"]
DH_SEEDS = ["planar-3r", "scara", "puma560", "puma560-craig", "ur5", "stanford"]
CHUNK = 1000  # inputs per worker process (a fresh process per chunk: ~1.5 s of imports)

HOSTILE = [
    float("nan"),
    float("inf"),
    -float("inf"),
    1e308,
    -1e308,
    5e-324,
    0,
    -1,
    1,
    2**63,
    -(2**64),
    True,
    None,
    "",
    " ",
    "nan",
    "inf",
    ".nan",
    "1e999999",
    "-1e999999",
    "10**10**10",
    "(" * 300 + "1" + ")" * 300,
    "-" * 2000 + "1",
    "sqrt(-1)",
    "1/0",
    "log(0)",
    "exp(exp(exp(100)))",
    "pi/2",
    "l1",
    "m1*l1**2/12",
    "__import__('os')",
    "a.b",
    "x" * 5000,
    "sin(",
    "2**(2**(2**(2**2)))",
    "(l1**1000)**1000",
    "atan2(0,0)",
    [],
    {},
    [1, 2],
    [1, 2, 3],
    [1, 2, 3, 4],
    [[1, 0, 0], [0, 1, 0], [0, 0, 1]],
    [[0] * 3] * 3,
    {"ixx": 1, "iyy": 1, "izz": 5},
    {"ixx": -1},
    {"lower": 1, "upper": 0},
    [float("nan")] * 3,
    [[1, 0], [0, 1]],
    "revolute",
    "prismatic",
    "fixed",
    "floating",
    "continuous",
    "base",
    "link1",
]
HOSTILE_XML = [
    "nan",
    "inf",
    "-inf",
    "1e999999",
    "",
    "0 0",
    "0 0 0 0",
    "a b c",
    "1e308 1e308 1e308",
    "0 0 0",
    "1 0 0",
    "0.6 0.8 0",
    "-1",
    "0",
    "5e-324",
    "1" * 400,
    "${x}",
    "continuous",
    "fixed",
    "floating",
    "planar",
    "prismatic",
    "revolute",
    "base",
    "l1",
    "l2",
    "iiwa_link_3",
]


# ------------------------------------------------------------------ mutators


def _paths(node, prefix=()):
    """Every (container, key) inside a parsed YAML document."""
    if isinstance(node, dict):
        for k, v in list(node.items()):
            yield node, k
            yield from _paths(v, prefix + (k,))
    elif isinstance(node, list):
        for i, v in enumerate(node):
            yield node, i
            yield from _paths(v, prefix + (i,))


def mutate_doc(doc, rng: random.Random):
    for _ in range(rng.randint(1, 3)):
        spots = list(_paths(doc))
        if not spots:
            return doc
        parent, key = rng.choice(spots)
        action = rng.random()
        if action < 0.6:
            parent[key] = copy.deepcopy(rng.choice(HOSTILE))
        elif action < 0.75 and isinstance(parent, dict):
            del parent[key]
        elif action < 0.85 and isinstance(parent, list):
            parent.append(copy.deepcopy(parent[key]))
        elif action < 0.95:
            other_parent, other_key = rng.choice(spots)
            parent[key] = copy.deepcopy(other_parent[other_key])  # a value from elsewhere
        elif isinstance(parent, dict):
            parent[f"{key}_extra"] = 1
    return doc


def mutate_text(text: str, rng: random.Random) -> str:
    for _ in range(rng.randint(1, 4)):
        i = rng.randrange(len(text) + 1)
        action = rng.random()
        if action < 0.3:
            text = text[:i] + text[i + rng.randint(1, 40) :]
        elif action < 0.6:
            text = (
                text[:i]
                + rng.choice(
                    [
                        "\n",
                        ":",
                        "-",
                        "[",
                        "]",
                        "{",
                        "}",
                        "&a",
                        "*a",
                        "!!python/object",
                        "\x00",
                        "<",
                        ">",
                        "/>",
                        '"',
                        "'",
                        "é",
                        "\t",
                        "  ",
                        "1e999",
                        "nan",
                    ]
                )
                + text[i:]
            )
        elif action < 0.8:
            j = rng.randrange(len(text) + 1)
            text = text[:i] + text[min(i, j) : max(i, j)][:200] + text[i:]
        else:
            text = text[:i] + chr(rng.randrange(1, 0x3000)) + text[i + 1 :]
    return text


def mutate_xml(text: str, rng: random.Random) -> str:
    try:
        root = ET.fromstring(text)
    except ET.ParseError:
        return text
    elems = list(root.iter())
    for _ in range(rng.randint(1, 3)):
        e = rng.choice(elems)
        action = rng.random()
        if action < 0.55 and e.attrib:
            e.set(rng.choice(list(e.attrib)), rng.choice(HOSTILE_XML))
        elif action < 0.7:
            for parent in root.iter():
                if e in list(parent):
                    parent.remove(e)
                    break
        elif action < 0.85:
            root.append(copy.deepcopy(rng.choice(elems)))
        else:
            e.set(rng.choice(["name", "type", "link", "joint", "xyz", "rpy", "value"]), rng.choice(HOSTILE_XML))
    return ET.tostring(root, encoding="unicode")


URDF_SMALL = """<?xml version="1.0"?>
<robot name="arm">
  <link name="base"/>
  <link name="l1"><inertial><origin xyz="0 0 0.1" rpy="0 0 0"/><mass value="2"/>
    <inertia ixx="0.02" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.01"/></inertial></link>
  <link name="l2"><inertial><origin xyz="0.2 0 0" rpy="0.1 0.2 0.3"/><mass value="1"/>
    <inertia ixx="0.01" ixy="0.001" ixz="0" iyy="0.02" iyz="0" izz="0.02"/></inertial></link>
  <link name="l3"><inertial><mass value="0.5"/>
    <inertia ixx="0.001" ixy="0" ixz="0" iyy="0.001" iyz="0" izz="0.001"/></inertial></link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="10" velocity="2"/></joint>
  <joint name="j2" type="prismatic"><parent link="l1"/><child link="l2"/><origin xyz="0 0 0.3" rpy="1.5707963267948966 0 0"/>
    <axis xyz="0 0.6 0.8"/><limit lower="0" upper="0.5" effort="10" velocity="1"/></joint>
  <joint name="j3" type="continuous"><parent link="l2"/><child link="l3"/><origin xyz="0.4 0 0"/><axis xyz="1 0 0"/>
    <dynamics damping="0.1" friction="0.2"/></joint>
</robot>"""


# ------------------------------------------------------------------ one input

EXPECTED = ("ModelError", "UnboundParameterError", "ValueError", "TypeError")


def exercise_robot(robot, rng: random.Random):
    """Bind to defaults and, when numeric, compile and evaluate once."""
    import numpy as np

    import armdyn.numeric as numeric

    if robot.free_symbols():
        robot = robot.bind()
        if robot.free_symbols():
            robot = robot.bind({p: rng.uniform(0.5, 2.0) for p in robot.parameters})
    n = robot.dof
    q = np.array([rng.uniform(-3, 3) for _ in range(n)])
    numeric.rnea(robot, q, q, q)
    numeric.crba(robot, q)


_TEXTS: dict = {}


def _seed_text(name: str) -> str:
    if name not in _TEXTS:
        _TEXTS[name] = (ROBOTS / name).read_text() if name.endswith(".urdf") else (ROBOTS / f"{name}.yaml").read_text()
    return _TEXTS[name]


try:  # the mutator's parse/dump only; the reader under test keeps its own loader
    from yaml import CSafeDumper as _SAFE_DUMPER
    from yaml import CSafeLoader as _SAFE_LOADER
except ImportError:  # PyYAML without libyaml
    from yaml import SafeDumper as _SAFE_DUMPER
    from yaml import SafeLoader as _SAFE_LOADER


def run_yaml(seed: int, rng: random.Random, seeds: list[str]):
    import yaml

    from armdyn.io.yaml import load_yaml_string

    text = _seed_text(rng.choice(seeds))
    if rng.random() < 0.7:  # libyaml (C) for the mutation's own parse and dump: 10x faster
        doc = mutate_doc(yaml.load(text, Loader=_SAFE_LOADER), rng)
        text = yaml.dump(doc, Dumper=_SAFE_DUMPER, sort_keys=False, allow_unicode=True)
    else:
        text = mutate_text(text, rng)
    robot = load_yaml_string(text, source="fuzz.yaml", strict=rng.random() < 0.5)
    exercise_robot(robot, rng)


def run_urdf(seed: int, rng: random.Random):
    from armdyn.io.urdf import load_urdf

    text = URDF_SMALL if rng.random() < 0.7 else _seed_text("iiwa14.urdf")
    text = mutate_xml(text, rng) if rng.random() < 0.7 else mutate_text(text, rng)
    robot = load_urdf(text, strict=rng.random() < 0.5)
    exercise_robot(robot, rng)


_ROBOTS_CACHE = {}


def _fill_robots_cache():
    """The compiled robots the arrays are fed to (built once per worker)."""
    if not _ROBOTS_CACHE:
        import armdyn
        from armdyn.io.urdf import load_urdf

        _ROBOTS_CACHE["ur5"] = armdyn.load("ur5").bind()
        _ROBOTS_CACHE["small"] = load_urdf(URDF_SMALL)
        _ROBOTS_CACHE["iiwa14"] = armdyn.load("iiwa14")


def run_arrays(seed: int, rng: random.Random):
    import numpy as np

    import armdyn.numeric as numeric

    _fill_robots_cache()
    robot = _ROBOTS_CACHE[rng.choice(list(_ROBOTS_CACHE))]
    n = robot.dof
    nrng = np.random.default_rng(seed)

    def arr():
        r = rng.random()
        rows = rng.choice([None, None, 0, 1, 3, 129, 300])
        shape = (n,) if rows is None else (rows, n)
        if r < 0.05:
            shape = rng.choice([(n + 1,), (n - 1,), (2, n + 1), (), (2, 2, n), (n, 1)])
        a = nrng.uniform(-10, 10, shape)
        r = rng.random()
        if r < 0.1 and a.size:
            a.flat[rng.randrange(a.size)] = rng.choice([np.nan, np.inf, -np.inf])
        elif r < 0.15:
            a = a * 1e300
        elif r < 0.2:
            a = a.astype(rng.choice([np.float32, np.int64, np.complex128, bool, object, np.uint8, "U5"]))
        elif r < 0.25 and a.ndim == 2 and a.shape[0] > 1:
            a = np.asfortranarray(a)
        elif r < 0.3 and a.ndim == 2:
            a = np.repeat(a, 2, axis=0)[::2]  # a non-contiguous view
        elif r < 0.33:
            return a.tolist()
        elif r < 0.35:
            return rng.choice(["abc", None, 3.0, [1, "x"], {}, [[1, 2], [3]]])
        return a

    threads = rng.choice([None, None, 1, 2, 3, 0, -1, 256, 257, 2**40])
    name = rng.choice(
        [
            "rnea",
            "aba",
            "crba",
            "gravity",
            "bias",
            "coriolis_matrix",
            "kinetic_energy",
            "potential_energy",
            "forward_kinematics",
            "jacobian",
        ]
    )
    nargs = {"rnea": 3, "aba": 3, "bias": 2, "coriolis_matrix": 2, "kinetic_energy": 2}.get(name, 1)
    args = [arr() for _ in range(nargs)]
    if rng.random() < 0.7:  # mostly consistent shapes, so that the computation itself runs
        args = [args[0]] * nargs if not isinstance(args[0], (str, type(None))) else args
    f = getattr(numeric, name)
    if name == "jacobian":
        link = rng.choice([*robot.links][:3] + [0, -1, 10**9, "nope", None, 1.5])
        out = f(robot, args[0], link, threads=threads)
    else:
        out = f(robot, *args, threads=threads)
    out = np.asarray(out)
    if name != "aba" and out.size and not np.all(np.isfinite(out)):
        # finite inputs within 1e300 can overflow to inf legitimately (a**2); NaN from
        # finite inputs is a finding
        small = all(
            isinstance(a, np.ndarray)
            and a.dtype.kind in "fiu"
            and np.all(np.isfinite(a))
            and np.max(np.abs(a), initial=0) < 1e100
            for a in args
        )
        if np.any(np.isnan(out)) and small:
            raise AssertionError(f"{name} returned NaN for finite inputs")


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
RUNNERS.update(SECURITY_KINDS)


# ------------------------------------------------------------------ armdyn serve's endpoints
# Kind "serve": hostile sizes and timings against a real `armdyn serve` on 127.0.0.1 (one
# per worker process, started before the first input, with one grading worker and a
# throwaway SQLite file). Each input is one request (or one raw connection that stops,
# trickles or lies about its length); afterwards the answer must be below 500 (503 with
# Retry-After only for previews), and /api/health must answer 200 within 5 s. A 5xx, a
# dropped answer to a well-formed request or an unhealthy server is a finding.
SERVE_PATHS = ["/api/grade", "/api/preview", "/grade", "/instructor/login", "/instructor/logout", "/api/health"]
SERVE_IDS = ["x", "a" * 25, "ab%00cd", "..%2F..%2Fetc", "%C3%A9t%C3%A9", "%FF%FE", "A" * 4000, "%0d%0aX:y"]
_SERVE: dict = {}


def _serve_base() -> str:
    """The worker's server (started once; stopped when the worker exits)."""
    if "base" not in _SERVE:
        import atexit
        import shutil
        import socket
        import urllib.request

        with socket.socket() as sock:
            sock.bind(("127.0.0.1", 0))
            port = sock.getsockname()[1]
        tmp = tempfile.mkdtemp(prefix="armdyn-fuzz-serve-")
        token = "fuzz-" + os.urandom(12).hex()
        cmd = [sys.executable, "-m", "armdyn", "serve", "--port", str(port), "--workers", "1"]
        db = os.environ.get("ARMDYN_FUZZ_SERVE_DB") or f"sqlite:///{tmp}/fuzz.db"  # e.g. a throwaway PostgreSQL
        cmd += ["--db", db, "--instructor-token", token, "--timeout", "10"]
        env = dict(os.environ, PYTHONPATH=str(ROOT / "python"))
        proc = subprocess.Popen(cmd, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        atexit.register(lambda: (proc.terminate(), proc.wait(30), shutil.rmtree(tmp, ignore_errors=True)))
        base = f"http://127.0.0.1:{port}"
        for _ in range(600):  # at most 2 minutes
            try:
                with urllib.request.urlopen(base + "/api/health", timeout=5) as r:
                    if r.status == 200:
                        break
            except OSError:
                time.sleep(0.2)
        else:
            raise RuntimeError("the fuzz server did not start")
        _SERVE.update(base=base, port=port, proc=proc)
    return _SERVE["base"]


def _serve_body(rng: random.Random) -> bytes:
    size = rng.choice([0, 1, 100, 10_000, 199_999, 200_001, 999_999, 1_000_001, 3_000_000])
    pieces = [b"$$", b"\\frac{", b"}", b"{", b"\x00", b"\xff", b"\n", b"---\nrobot: rp-arm\n---\n", b"\\tau_1 = "]
    piece = rng.choice(pieces) if rng.random() < 0.5 else os.urandom(rng.randint(1, 64))
    return (piece * (size // max(1, len(piece)) + 1))[:size]


def _serve_raw(port: int, rng: random.Random) -> None:
    """A connection that misbehaves: stops mid-head, trickles its head, lies about its
    length, sends an oversized head or broken chunks. The server may close it or answer
    4xx; it must stay healthy."""
    import socket

    how = rng.choice(["stop", "trickle", "short-body", "huge-head", "bad-chunks", "garbage"])
    with socket.create_connection(("127.0.0.1", port), timeout=5) as sock:
        head = b"POST /api/grade?wait=0 HTTP/1.1\r\nHost: x\r\nContent-Type: text/markdown\r\n"
        if how == "stop":
            sock.sendall(head[: rng.randint(1, len(head))])
        elif how == "trickle":  # at most 1 s of trickling
            for i in range(0, len(head), 8):
                sock.sendall(head[i : i + 8])
                time.sleep(0.02)
        elif how == "short-body":
            sock.sendall(head + b"Content-Length: 5000\r\n\r\n" + b"$$x=1$$")
        elif how == "huge-head":
            sock.sendall(head + b"X-Big: " + b"a" * rng.choice([70_000, 200_000]) + b"\r\n\r\n")
        elif how == "bad-chunks":
            sock.sendall(head + b"Transfer-Encoding: chunked\r\n\r\nzz\r\nabc\r\n0\r\n\r\n")
        else:
            sock.sendall(os.urandom(rng.randint(1, 4096)))
        sock.settimeout(1.0)
        try:
            answer = sock.recv(64)
        except OSError:
            answer = b""
    if answer.startswith(b"HTTP/1.1 5") and not answer.startswith(b"HTTP/1.1 503"):
        raise AssertionError(f"raw {how}: {answer!r}")


def run_serve(seed: int, rng: random.Random):
    import http.client
    import urllib.parse

    base = _serve_base()
    port = _SERVE["port"]
    if rng.random() < 0.25:
        _serve_raw(port, rng)
    else:
        if rng.random() < 0.3:
            sid = rng.choice(SERVE_IDS)
            path = rng.choice([f"/api/submissions/{sid}", f"/submissions/{sid}", f"/submissions/{sid}/report.html"])
            method, body = "GET", b""
        else:
            path, method, body = rng.choice(SERVE_PATHS), "POST", _serve_body(rng)
        query = {
            "wait": rng.choice(["0", "-1", "nan", "inf", "1e308", "0.1"]),
            "student": rng.choice(["Ada", "a\x00b", "\u202e" * 50, "x" * 5000]),
            "robot": rng.choice(["rp-arm", "../../etc/passwd", "rp\x00arm", ""]),
        }
        kind = rng.choice(["text/markdown", "text/plain", "application/x-www-form-urlencoded", "multipart/form-data"])
        headers = {"Content-Type": kind, "Authorization": rng.choice(["", "Bearer " + "x" * 300, "Bearer short"])}
        conn = http.client.HTTPConnection("127.0.0.1", port, timeout=30)
        try:
            conn.request(method, path + "?" + urllib.parse.urlencode(query), body=body, headers=headers)
            r = conn.getresponse()
            r.read()
            status, retry = r.status, r.getheader("retry-after")
        except (ConnectionResetError, BrokenPipeError):
            status, retry = 413, None  # the server may close on a body past its limit
        finally:
            conn.close()
        if status >= 500 and not (status == 503 and path == "/api/preview" and retry):
            raise AssertionError(f"{method} {path} ({len(body)} bytes, {kind}): {status}")
    import urllib.request

    with urllib.request.urlopen(base + "/api/health", timeout=5) as r:
        if r.status != 200:
            raise AssertionError(f"/api/health {r.status} after seed {seed}")


RUNNERS["serve"] = run_serve
PREPARE = {"serve": _serve_base}  # kinds whose set-up must not count against an input's timeout

# ------------------------------------------------------------------ model files that run code, hostile classes
# Kinds "codemodels" and "classes" (registered in IO_KINDS): each input gets a fresh
# folder and a marker path in it that the input's payload would create if any of it ran;
# the input must end in a result or a ModelError within SECURITY_SECONDS, and the marker
# must not exist afterwards.

#: ways a model file could reach code: xacro's eval (with the vars()/type() bypass of its
#: ``__`` filter), includes, YAML tags that construct objects, Python in DH expressions
CODE_SNIPPETS = [
    "${python.vars(python.type(python.vars(python.type(xacro.arg))['__globals__']))['__get__']"
    "(python.vars(python.type(xacro.arg))['__globals__'], xacro.arg)['os'].mkdir('MARKER')}",
    "${__import__('os').mkdir('MARKER')}",
    "$(eval __import__('os').mkdir('MARKER'))",
    "__import__('os').mkdir('MARKER')",
    "eval(\"__import__('os').mkdir('MARKER')\")",
    "(lambda: 0)()",
    "().__class__.__base__.__subclasses__()",
    "m1.__class__",
    "os.mkdir('MARKER')",
    "exec('1')",
    "getattr(m1, 'x')",
]
CODE_TAGS = [
    "!!python/object/apply:os.mkdir ['MARKER']",
    "!!python/name:os.mkdir",
    "!!python/object/new:os.mkdir ['MARKER']",
    "!!python/module:os",
    "!<tag:yaml.org,2002:python/object/apply:os.mkdir> ['MARKER']",
]
URDF_INCLUDES = [
    '<xacro:include filename="MARKER.xacro"/>',
    '<mesh filename="package://armdyn/MARKER"/>',
    '<mesh filename="file://MARKER"/>',
    '<?xml-stylesheet href="file://MARKER"?>',
    '<xi:include href="file://MARKER" xmlns:xi="http://www.w3.org/2001/XInclude"/>',
    '<!DOCTYPE r [<!ENTITY e SYSTEM "file://MARKER">]><robot name="&e;"/>',
]


def _planted(marker: str, text: str) -> str:
    return text.replace("MARKER", marker)


def run_codemodels(seed: int, rng: random.Random):
    """A model file that tries to run code: a snippet as a YAML field's value (frame model
    or DH table), a tag as a value, an include or URI in a URDF, or a whole ``.xacro``
    file; loaded through ``armdyn.load`` untrusted (never with the opt-in)."""
    import yaml

    import armdyn

    with tempfile.TemporaryDirectory() as tmp:
        marker = os.path.join(tmp, "MARKER-RAN")
        r = rng.random()
        if r < 0.45:
            base = rng.choice(YAML_SEEDS + DH_SEEDS)
            doc = yaml.load(_seed_text(base), Loader=_SAFE_LOADER)
            container, key = rng.choice(list(_paths(doc)))
            container[key] = "FUZZ_VALUE_MARKER"
            text = yaml.dump(doc, Dumper=_SAFE_DUMPER, sort_keys=False, allow_unicode=True, width=10**6)
            value = (
                rng.choice(CODE_TAGS) if rng.random() < 0.3 else json.dumps(_planted(marker, rng.choice(CODE_SNIPPETS)))
            )
            path = os.path.join(tmp, "m.yaml")
            Path(path).write_text(text.replace("FUZZ_VALUE_MARKER", _planted(marker, value), 1))
        elif r < 0.75:
            text = _seed_text("iiwa14.urdf")
            cut = rng.choice([m.end() for m in re.finditer(r"<robot[^>]*>|</link>|</joint>", text)])
            piece = rng.choice(URDF_INCLUDES + CODE_SNIPPETS)
            text = text[:cut] + _planted(marker, piece) + text[cut:]
            path = os.path.join(tmp, rng.choice(["m.urdf", "m.urdf", "m.xacro"]))
            Path(path).write_text(text)
        else:
            lines = [f'<link name="l{k}"/>' for k in range(3)]
            lines.insert(rng.randrange(len(lines) + 1), f'<link name="{_planted(marker, rng.choice(CODE_SNIPPETS))}"/>')
            path = os.path.join(tmp, "m.xacro")
            Path(path).write_text(
                '<robot name="x" xmlns:xacro="http://www.ros.org/wiki/xacro">' + "".join(lines) + "</robot>"
            )
        try:
            _must_be_model_error(lambda: armdyn.load(path), f"seed {seed}: {os.path.basename(path)}")
        finally:
            if os.path.exists(marker) or os.path.exists(marker + ".xacro"):
                raise AssertionError(f"seed {seed}: a model file ran code ({os.path.basename(path)})")


#: front matters of hostile submissions in a class folder
CLASS_FRONTS = [
    "student: bob\n",
    "student: ../../x\n",
    "student: a_b\n",
    "variant: bob\n",
    "robot: ../outside.yaml\n",
    "robot: /etc/hostname\n",
    "robot: attachment.xacro\n",
    "robot: link.yaml\n",
    "robot: rp-arm\n",
    "robot: planar-2r\n",
    "student: &a [*a]\n",
    "student: !!python/object/apply:os.mkdir ['MARKER']\n",
]
CLASS_NAMES = ["alice", "bob", "a b", "a_b", "Ada", "ada", "x.y", "-rf", "=cmd", "\u00e9", "e\u0301", "..x"]


def run_classes(seed: int, rng: random.Random):
    """A class folder of hostile submissions: spoofed ``student:`` and ``variant:``, names
    whose reports collide, models named by paths out of the folder, a ``.xacro`` payload,
    symbolic links (to files outside, to /dev/zero, to a FIFO) and FIFOs. :func:`discover`
    must keep each student's identity to the file name, follow no link, give every task
    its own report name and a model that is bundled or a regular file in the folder; and
    no payload may run (loading each task's model untrusted)."""
    import armdyn
    from armdyn.course.batch import discover, safe_file_name
    from armdyn.errors import ModelError

    with tempfile.TemporaryDirectory() as tmp:
        marker = os.path.join(tmp, "MARKER-RAN")
        subs = os.path.join(tmp, "subs")
        variants = os.path.join(tmp, "variants")
        os.makedirs(subs)
        Path(tmp, "outside.yaml").write_text(_seed_text("rp-arm"))
        Path(subs, "attachment.xacro").write_text(
            '<robot name="x" xmlns:xacro="http://www.ros.org/wiki/xacro"><link name="'
            + _planted(marker, CODE_SNIPPETS[0])
            + '"/></robot>'
        )
        for name in rng.sample(CLASS_NAMES, rng.randint(1, len(CLASS_NAMES))):
            ext = rng.choice([".md", ".md", ".yaml"])
            path = os.path.join(subs, name + ext)
            r = rng.random()
            if r < 0.1:
                os.symlink(os.path.join(tmp, "outside.yaml"), path)
            elif r < 0.15:
                os.symlink("/dev/zero", path)
            elif r < 0.2:
                os.mkfifo(path)
            else:
                front = "".join(rng.sample(CLASS_FRONTS, rng.randint(0, 3)))
                front = _planted(marker, front)
                text = f"---\n{front}---\n$$\\tau_1 = 0$$\n" if ext == ".md" else front + "steps: {}\n"
                Path(path).write_text(text)
        if rng.random() < 0.5:
            os.symlink(os.path.join(tmp, "outside.yaml"), os.path.join(subs, "link.yaml"))
        if rng.random() < 0.5:
            for vid in ("alice", "bob"):
                os.makedirs(os.path.join(variants, vid))
                Path(variants, vid, "model.yaml").write_text(_seed_text("rp-arm"))
        found = discover(subs, variants if os.path.isdir(variants) else None)
        reports = set()
        for t in found.tasks:
            stem = os.path.splitext(os.path.basename(t.path))[0]
            if t.student != stem or os.path.islink(t.path):
                raise AssertionError(f"seed {seed}: {t.path} graded as {t.student!r}")
            report = safe_file_name(t.student).casefold()
            if report in reports:
                raise AssertionError(f"seed {seed}: two tasks write {report}.html")
            reports.add(report)
            if t.robot and os.sep in t.robot:
                inside = os.path.dirname(t.robot) in (subs, os.path.join(variants, t.variant or ""))
                if not inside or os.path.islink(t.robot):
                    raise AssertionError(f"seed {seed}: {t.path} graded against {t.robot}")
            if t.robot:
                with contextlib.suppress(ModelError):
                    armdyn.load(t.robot, strict=False)
        if os.path.exists(marker):
            raise AssertionError(f"seed {seed}: a class folder ran code")


IO_KINDS = {"codemodels": run_codemodels, "classes": run_classes}
RUNNERS.update(IO_KINDS)


# ------------------------------------------------------------------ worker / driver


def worker(kind: str, first: int, count: int, timeout: float) -> dict:
    warnings.simplefilter("ignore")
    sys.setrecursionlimit(10_000)
    counts = {"inputs": 0, "loaded_or_ok": 0, "expected_error": 0, "unexpected": 0, "timeout": 0}
    findings = []

    def expired(*_):
        raise TimeoutError

    signal.signal(signal.SIGALRM, expired)
    # imports before the first timer: under load (nice 19 behind other jobs) importing
    # SymPy and armdyn took > 20 s and was counted as the chunk's first input timing out
    import armdyn.io.urdf  # noqa: F401
    import armdyn.io.yaml  # noqa: F401
    import armdyn.numeric  # noqa: F401

    if kind == "arrays":  # likewise the robots it feeds (the first input built them)
        _fill_robots_cache()
    if kind in PREPARE:
        PREPARE[kind]()
    for seed in range(first, first + count):
        rng = random.Random(seed)
        counts["inputs"] += 1
        signal.setitimer(signal.ITIMER_REAL, timeout)
        try:
            if kind == "yaml":
                run_yaml(seed, rng, YAML_SEEDS)
            elif kind == "dh":
                run_yaml(seed, rng, DH_SEEDS)
            elif kind == "urdf":
                run_urdf(seed, rng)
            elif kind in RUNNERS:
                RUNNERS[kind](seed, rng)
            else:
                run_arrays(seed, rng)
            counts["loaded_or_ok"] += 1
        except TimeoutError:
            counts["timeout"] += 1
            findings.append({"seed": seed, "kind": kind, "what": f"no result after {timeout} s"})
        except Exception as err:  # noqa: BLE001 - classified here
            name = type(err).__name__
            message = str(err)
            if name in EXPECTED and "internal error" not in message and "\n" not in message:
                counts["expected_error"] += 1
            else:
                counts["unexpected"] += 1
                findings.append({"seed": seed, "kind": kind, "what": f"{name}: {message[:300]}"})
        finally:
            signal.setitimer(signal.ITIMER_REAL, 0)
    return {"counts": counts, "findings": findings[:20]}


def drive(kinds: list[str], count: int, timeout: float, minutes: float | None, jobs: int, first_seed: int = 0) -> int:
    """Run seeds ``first_seed`` .. ``first_seed + count - 1`` of each kind (``--first N --count 1``
    replays seed N)."""
    total = {}
    found = []
    start = time.monotonic()
    for kind in kinds:
        deadline = time.monotonic() + minutes * 60 if minutes else None
        total[kind] = {
            "inputs": 0,
            "loaded_or_ok": 0,
            "expected_error": 0,
            "unexpected": 0,
            "timeout": 0,
            "crash": 0,
            "panic_on_stderr": 0,
        }
        chunks = [
            (first, min(CHUNK, first_seed + count - first)) for first in range(first_seed, first_seed + count, CHUNK)
        ]
        running = []
        t_kind = time.monotonic()
        while chunks or running:
            while chunks and len(running) < jobs and not (deadline and time.monotonic() > deadline):
                first, n = chunks.pop(0)
                err = tempfile.TemporaryFile()
                cmd = [
                    sys.executable,
                    __file__,
                    "--worker",
                    kind,
                    "--first",
                    str(first),
                    "--count",
                    str(n),
                    "--timeout",
                    str(timeout),
                ]
                running.append((subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=err, text=True), err, first))
            if not running:
                break
            proc, err, first = running.pop(0)
            out, _ = proc.communicate()
            err.seek(0)
            stderr = err.read().decode("utf-8", "replace")
            t = total[kind]
            if proc.returncode != 0:
                t["crash"] += 1
                found.append({"kind": kind, "chunk": first, "what": f"worker exit {proc.returncode}: {stderr[-300:]}"})
                continue
            result = json.loads(out)
            for k, v in result["counts"].items():
                t[k] += v
            found += result["findings"]
            if re.search(r"panicked", stderr):
                t["panic_on_stderr"] += 1
                found.append({"kind": kind, "chunk": first, "what": stderr[-300:]})
        seconds = time.monotonic() - t_kind
        t = total[kind]
        print(
            f"{kind:>6}: {t['inputs']} inputs in {seconds:.0f} s: {t['loaded_or_ok']} loaded/evaluated, "
            f"{t['expected_error']} clear errors, {t['unexpected']} unexpected exceptions, {t['timeout']} "
            f"timeouts (>{timeout} s), {t['crash']} crashed workers, {t['panic_on_stderr']} chunks with a "
            f"panic message on stderr",
            flush=True,
        )
        for f in [f for f in found if f["kind"] == kind][:30]:
            print("finding:", json.dumps(f), flush=True)
    print(f"total {sum(t['inputs'] for t in total.values())} inputs in {time.monotonic() - start:.0f} s")
    bad = sum(t["unexpected"] + t["timeout"] + t["crash"] + t["panic_on_stderr"] for t in total.values())
    return 1 if bad else 0


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--kinds", default="yaml,dh,urdf,arrays")
    ap.add_argument("--count", type=int, default=100_000, help="inputs per kind")
    ap.add_argument("--timeout", type=float, default=20.0, help="seconds one input may take")
    ap.add_argument("--minutes", type=float, help="per kind: stop starting new chunks after this long")
    ap.add_argument("--jobs", type=int, default=max(1, (os.cpu_count() or 1)))
    ap.add_argument("--worker")
    ap.add_argument("--first", type=int, default=0)
    args = ap.parse_args()
    if args.worker:
        print(json.dumps(worker(args.worker, args.first, args.count, args.timeout)))
        return 0
    if args.count < 1:
        ap.error("--count must be at least 1")
    return drive(args.kinds.split(","), args.count, args.timeout, args.minutes, args.jobs, args.first)


if __name__ == "__main__":
    sys.exit(main())
