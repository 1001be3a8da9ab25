"""Fuzz kinds yaml, dh, urdf and arrays, and the seeds and mutators the other kinds share
(driven by fuzz_campaign.py, whose docstring says what each kind sends)."""

from __future__ import annotations

import copy
import random
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
