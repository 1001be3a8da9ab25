"""Hostile or careless input to the numeric API gets a clear error, never a silent
conversion, a hang or a crash; and the test-suite rules that keep checks honest."""

from __future__ import annotations

import re
import threading
import time
from pathlib import Path

import numpy as np
import pytest

from armdyn import Joint, Link, Robot, numeric

TESTS = Path(__file__).resolve().parent


def arm(tip_mass=1.0, tip_inertia=0.01):
    """A 3R arm; link3 (after joint j3) gets ``tip_mass`` and a diagonal tensor."""
    links = [
        Link("base"),
        Link("l1", 2.0, [0, 0, 0.1], np.diag([0.02, 0.02, 0.01]).tolist()),
        Link("l2", 1.5, [0.2, 0, 0], np.diag([0.01, 0.03, 0.03]).tolist()),
        Link("l3", tip_mass, [0.1, 0, 0], (tip_inertia * np.eye(3)).tolist()),
    ]
    joints = [
        Joint("j1", "revolute", "base", "l1"),
        Joint("j2", "revolute", "l1", "l2", xyz=[0, 0, 0.3], axis=[0, 1, 0]),
        Joint("j3", "revolute", "l2", "l3", xyz=[0.4, 0, 0], axis=[0, 1, 0]),
    ]
    return Robot("arm3", links, joints)


@pytest.mark.parametrize(
    "bad, words",
    [
        (np.array([0.1, 0.2, 0.3 + 1j]), "dtype complex128"),
        (np.array([True, False, True]), "dtype bool"),
        (np.array(["0.1", "0.2", "0.3"]), "dtype <U3"),
        (np.array([b"1", b"2", b"3"]), "dtype |S1"),
        ([0.1, 0.2, 0.3j], "dtype complex128"),
        (np.array([0.1, True, 0.3], dtype=object), "element of type bool"),
        (np.array([0.1, "x", 0.3], dtype=object), "element of type str"),
        (np.array([0.1, 2j, 0.3], dtype=object), "element of type complex"),
        (np.zeros(3, dtype="datetime64[s]"), "dtype datetime64[s]"),
    ],
    ids=lambda x: None if isinstance(x, str) else type(x).__name__,
)
def test_non_real_arrays_are_refused(bad, words):
    robot = arm()
    with pytest.raises(ValueError, match=r"^q(dd)?: expected real numbers") as info:
        numeric.rnea(robot, np.zeros(3), np.zeros(3), bad)
    assert words in str(info.value)
    with pytest.raises(ValueError, match=r"^q: expected real numbers"):
        numeric.crba(robot, np.stack([bad, bad]) if isinstance(bad, np.ndarray) else [bad, bad])


def test_real_arrays_of_every_width_are_accepted():
    robot = arm()
    q = np.array([0.1, -0.4, 0.7])
    want = numeric.crba(robot, q)
    for dtype in (np.float32, np.float16, np.int8, np.int64, np.uint16, np.longdouble):
        got = numeric.crba(robot, q.astype(dtype))
        np.testing.assert_allclose(got, numeric.crba(robot, q.astype(dtype).astype(float)), rtol=0, atol=0)
    np.testing.assert_array_equal(numeric.crba(robot, np.array(list(q), dtype=object)), want)
    np.testing.assert_array_equal(numeric.crba(robot, [0.1, -0.4, 0.7]), want)


@pytest.mark.parametrize("threads", [0, -1, 257, 10**6, 2**63 - 1])
def test_threads_out_of_bounds_are_refused(threads):
    robot = arm()
    q = np.zeros((200, 3))
    with pytest.raises(ValueError, match="threads: expected None or an integer from 1 to 256"):
        numeric.crba(robot, q, threads=threads)


def _process_threads() -> int:
    return int(re.search(r"^Threads:\s+(\d+)", Path("/proc/self/status").read_text(), re.M).group(1))


@pytest.mark.skipif(not Path("/proc/self/status").is_file(), reason="needs Linux /proc")
def test_thread_pools_are_reused_not_one_per_count():
    """Before: one rayon pool per distinct count, kept for ever (2 + 3 + ... + 40 =
    819 threads for this loop). Now: the global pool, plus one extra pool grown to the
    largest count asked for."""
    robot = arm()
    q = np.random.default_rng(3).uniform(-1, 1, (400, 3))
    want = numeric.crba(robot, q, threads=1)
    numeric.crba(robot, q)  # starts rayon's global pool, which is not counted
    before = _process_threads()
    for k in range(2, 41):
        np.testing.assert_array_equal(numeric.crba(robot, q, threads=k), want)
    # a replaced (smaller) pool's threads exit once told to: give them a moment
    for _ in range(100):
        grown = _process_threads() - before
        if grown <= 40:
            break
        time.sleep(0.05)
    assert grown <= 40, f"{grown} new threads for counts 2..40"
    for k in range(2, 41):  # asking again starts nothing new
        numeric.crba(robot, q, threads=k)
    assert _process_threads() - before == grown


def test_thread_counts_give_identical_results():
    robot = arm()
    rng = np.random.default_rng(4)
    q, qd, tau = rng.uniform(-1, 1, (3, 1000, 3))
    want = numeric.aba(robot, q, qd, tau, threads=1)
    for threads in (2, 3, 7, 64, 256, None):
        np.testing.assert_array_equal(numeric.aba(robot, q, qd, tau, threads=threads), want)


def test_aba_of_a_massless_subtree_names_the_joints():
    """Before: aba returned inf/NaN for the undetermined joint."""
    robot = arm(tip_mass=0.0, tip_inertia=0.0)
    q = np.array([0.1, 0.2, 0.3])
    np.testing.assert_allclose(numeric.crba(robot, q)[2], 0, atol=0)  # M is singular
    for args in ((q, q, q), (np.stack([q, q]),) * 3):
        with pytest.raises(ValueError, match=r"aba: .*singular: joints \['j3'\] move no mass"):
            numeric.aba(robot, *args)
    # rnea and crba are still defined
    assert np.all(np.isfinite(numeric.rnea(robot, q, q, q)))


def test_aba_singular_at_a_state_is_an_error():
    """A point mass on the last joint's axis: M is singular although no subtree is
    massless; aba must not hand back inf or NaN."""
    links = [
        Link("base"),
        Link("l1", 1.0, [0, 0, 0], np.diag([0.01, 0.01, 0.01]).tolist()),
        Link("l2", 1.0, [0, 0, 0.5], np.zeros((3, 3)).tolist()),
    ]
    joints = [
        Joint("j1", "revolute", "base", "l1", axis=[1, 0, 0]),
        Joint("j2", "revolute", "l1", "l2", axis=[0, 0, 1]),
    ]  # the point mass sits on j2's axis
    robot = Robot("on-axis", links, joints)
    q = np.zeros(2)
    try:
        qdd = numeric.aba(robot, q, q, np.array([0.0, 1.0]))
    except ValueError as err:
        assert "singular at this state" in str(err)
    else:  # rounding may leave a tiny but non-zero pivot: then the result must be finite
        assert np.all(np.isfinite(qdd))


def test_seeds_are_fixed_not_hashed():
    """hash(str) changes with every process (PYTHONHASHSEED): a failure seeded from it
    cannot be reproduced."""
    offenders = [
        f"{p.name}:{i}"
        for p in sorted(TESTS.glob("*.py"))
        if p.name != Path(__file__).name
        for i, line in enumerate(p.read_text().splitlines(), 1)
        if re.search(r"(seed|default_rng|Random)\(.*\bhash\(", line)
    ]
    assert offenders == []


def test_concurrent_single_calls_agree():
    robot = arm()
    q = np.array([0.3, -0.2, 0.5])
    want = numeric.rnea(robot, q, q, q)
    results = []

    def work():
        results.append(all(np.array_equal(numeric.rnea(robot, q, q, q), want) for _ in range(200)))

    ts = [threading.Thread(target=work) for _ in range(4)]
    for t in ts:
        t.start()
    for t in ts:
        t.join()
    assert results == [True] * 4


# ------------------------------------------------------------ hostile model files


from security_support import deadline  # noqa: E402

from armdyn.cli import main  # noqa: E402
from armdyn.errors import ModelError  # noqa: E402
from armdyn.io.expressions import parse_expression  # noqa: E402
from armdyn.io.yaml import load_yaml_string  # noqa: E402

PLANAR = (TESTS.parent / "python" / "armdyn" / "robots" / "planar-2r.yaml").read_text()


HOSTILE_EXPRESSIONS = {
    "200 nested parentheses": ("(" * 200 + "l1" + ")" * 200, "nested more than 100 levels"),
    "1000 unary minuses": ("-" * 1000 + "l1", "nested more than 100 levels"),
    "150 nested calls": ("sin(" * 150 + "l1" + ")" * 150, "function calls nested more than 6 deep"),
    "nested calls, parentheses between": ("sin((" * 7 + "l1" + "))" * 7, "function calls nested more than 6 deep"),
    "10**10**10": ("10**10**10", "too large"),
    "10^10^10": ("10^10^10", "too large"),
    "(2**999)**999": ("(2**999)**999", "too large"),
    "10**-(10**10)": ("10**-(10**10)", "too large"),
    "sqrt(2)**(10**10)": ("sqrt(2)**(10**10)", "too large"),
    "l1**(10**20)": ("l1**(10**20)", "too large"),
    "(l1**100)**100": ("(l1**100)**100", "exponent beyond 100"),
    "l1**101": ("l1**101", "too large"),
    "1e999999": ("1e999999", "beyond the float64 range"),
    "exp(exp(exp(100)))": ("exp(exp(exp(100)))", "the value exp(exp(100)) is beyond the float64 range"),
    "20000 characters": ("l1+" * 6667 + "1", "longer than 10000"),
}


@pytest.mark.parametrize("text, words", HOSTILE_EXPRESSIONS.values(), ids=HOSTILE_EXPRESSIONS.keys())
def test_hostile_expressions_are_one_line_errors(text, words):
    """Before: RecursionError (parentheses, minuses), or minutes to hours of SymPy
    arithmetic (10**10**10, sp.Float('1e999999'), evalf of exp(exp(exp(100))))."""
    l1 = __import__("sympy").Symbol("l1")
    with deadline(20):
        with pytest.raises(ModelError) as info:
            parse_expression(text, {"l1": l1}, "link 'link1'", "arm.yaml", "mass")
    message = str(info.value)
    assert words in message and "\n" not in message and len(message) < 400
    assert message.startswith("arm.yaml: link 'link1': mass:")


@pytest.mark.parametrize("text", [v[0] for v in HOSTILE_EXPRESSIONS.values()][:6], ids=list(HOSTILE_EXPRESSIONS)[:6])
def test_hostile_expression_in_a_file_is_one_cli_line(tmp_path, capsys, text):
    path = tmp_path / "arm.yaml"
    path.write_text(PLANAR.replace("com: [lc1, 0, 0]", f"com: ['{text}', 0, 0]"))
    with deadline(30):
        code = main(["show", str(path)])
    err = capsys.readouterr().err
    assert code == 2 and err.startswith(f"armdyn: error: {path}") and err.count("\n") == 1


def test_ordinary_expressions_still_parse():
    import sympy as sp

    l1 = sp.Symbol("l1")
    for text, want in [
        ("2**3**2", 512),
        ("-l1**2", -(l1**2)),
        ("(((l1)))", l1),
        ("l1**100", l1**100),
        ("0.4318", sp.Float(0.4318)),
        ("1/12", sp.Rational(1, 12)),
        ("2**-3", sp.Rational(1, 8)),
        ("-" * 50 + "l1", l1),
        ("(" * 50 + "l1" + ")" * 50, l1),
        ("sqrt(2)**100", 2**50),
        ("sin(cos(tan(sinh(cosh(tanh(l1))))))", sp.sin(sp.cos(sp.tan(sp.sinh(sp.cosh(sp.tanh(l1))))))),
    ]:
        assert parse_expression(text, {"l1": l1}) == want, text


@pytest.mark.parametrize("value", [".nan", ".inf", "-.inf", "1.0e999999", "1e999999", str(10**400)])
def test_published_defaults_must_be_finite(value):
    text = PLANAR.replace("g: 9.81}", f"g: {value}}}")
    with deadline(20):
        with pytest.raises(ModelError, match="g") as info:
            load_yaml_string(text, source="arm.yaml")
    assert "finite" in str(info.value) or "float64" in str(info.value), str(info.value)


@pytest.mark.parametrize("key", ["source", "description", "notes"])
def test_source_and_description_must_be_text(tmp_path, capsys, key):
    """Before: a list of 9**8 (43 million) aliased strings was accepted as the source,
    and `armdyn show` printing it never finished. Now any alias is refused first."""
    kept, skipping = [], False
    for ln in PLANAR.splitlines():  # drop `key` (and a folded block under it)
        if ln.startswith(f"{key}:"):
            skipping = True
            continue
        if skipping and ln.startswith("  "):
            continue
        skipping = False
        kept.append(ln)
    doc = "\n".join(kept).replace("name: planar-2r", "name: planar-2r\n" + _inline_bomb(key))
    path = tmp_path / "bomb.yaml"
    path.write_text(doc)
    with deadline(20):
        code = main(["show", str(path)])
    err = capsys.readouterr().err
    assert code == 2 and err.startswith(f"armdyn: error: {path}:") and "aliases" in err, err
    assert err.count("\n") == 1 and len(err) < 500


def _inline_bomb(key: str) -> str:
    """``key:`` holding 9**8 strings through nested aliases, in one YAML value."""
    inner = '&a ["lol", "lol", "lol", "lol", "lol", "lol", "lol", "lol", "lol"]'
    levels = [inner]
    for k, name in enumerate("bcdefgh"):
        prev = "abcdefgh"[k]
        levels.append(f"&{name} [{', '.join([f'*{prev}'] * 9)}]")
    # each level must be defined before use: a list whose first element defines the
    # anchors, the last the bomb
    return f"{key}: [{', '.join(levels)}]"


# ------------------------------------------------------------ data as published


def test_version_matches_pyproject():
    import armdyn

    text = (TESTS.parent / "pyproject.toml").read_text()
    try:
        import tomllib  # Python 3.11+

        version = tomllib.loads(text)["project"]["version"]
    except ImportError:  # 3.10: the [project] table's version line
        version = re.search(r'^\[project\][^\[]*?^version\s*=\s*"([^"]+)"', text, re.M | re.S).group(1)
    assert armdyn.__version__ == version


def test_readme_points_only_inside_the_repository():
    """The README is read by users of the repository, who do not have ../shared."""
    root = TESTS.parent
    text = (root / "README.md").read_text()
    assert "../shared" not in text and "shared/reference" not in text
    for target in re.findall(r"\]\(([^)#]+)\)", text):  # relative Markdown links resolve
        if "://" not in target:
            assert (root / target).exists(), target
    assert "(docs/exercise.md)" in text


def test_bundled_data_cite_what_they_are():
    robots = TESTS.parent / "python" / "armdyn" / "robots"
    puma = (robots / "puma560-craig.yaml").read_text()
    assert "Fu, Gonzalez" in puma and "not Craig's own numbers" in puma
    panda = (robots / "panda.yaml").read_text()
    assert "-0.04762) is franka_ros's value" in panda
    iiwa = (robots / "iiwa14.urdf").read_text()
    assert "Drake's model values, not data published" in iiwa
    ur5 = (robots / "ur5.yaml").read_text()
    assert "recomputed for UR's 2.33 kg" in ur5


# ------------------------------------------------------------ Robot is immutable


def test_robot_cannot_change_under_its_compiled_model():
    """Before: robot.gravity = ... (or joints.append, links[...] = ...) succeeded and
    numeric calls kept using the stale compiled model."""
    import copy

    import sympy as sp

    robot = arm()
    q = np.array([0.1, 0.2, 0.3])
    g0 = numeric.gravity(robot, q)
    with pytest.raises(AttributeError, match="Robot is immutable: cannot set 'gravity'"):
        robot.gravity = sp.Matrix([0, 0, 0])
    with pytest.raises(AttributeError, match="immutable"):
        robot.joints = []
    with pytest.raises(AttributeError, match="immutable"):
        del robot.links
    with pytest.raises(TypeError, match="immutable"):
        robot.joints.append(robot.joints[0])
    with pytest.raises(TypeError, match="immutable"):
        robot.links["l3"] = Link("l3", 100.0)
    with pytest.raises(TypeError, match="immutable"):
        robot.defaults["x"] = 1.0
    with pytest.raises(TypeError):
        robot.gravity[2] = 0  # an ImmutableMatrix
    np.testing.assert_array_equal(numeric.gravity(robot, q), g0)

    # building new robots still works: bind/subs, list + list, a with_* style copy
    lighter = Robot(
        "arm3b", [*robot.links.values()][:-1] + [Link("l3", 0.5, [0.1, 0, 0], np.eye(3) * 0.01)], robot.joints + []
    )
    assert numeric.gravity(lighter, q)[1] != g0[1]
    thawed = copy.copy(robot)
    assert "_numeric_model" not in thawed.__dict__
    thawed.gravity = sp.ImmutableMatrix([0, 0, 0])  # a with_* constructor may set fields
    np.testing.assert_array_equal(numeric.gravity(thawed, q), np.zeros(3))
    thawed.gravity = sp.ImmutableMatrix([0, 0, -1.0])  # ... and each set drops the cache
    np.testing.assert_allclose(numeric.gravity(thawed, q), g0 / 9.81, rtol=1e-12)
    np.testing.assert_array_equal(numeric.gravity(robot, q), g0)  # the original is untouched


def test_robot_pickles_and_stays_frozen():
    """Before: pickle.loads refilled the frozen lists/dicts item by item and raised
    TypeError, so a Robot could not be sent to a process pool or cached to disk."""
    import pickle

    import armdyn

    for name in ("ur5", "panda"):
        robot = armdyn.load(name)
        q = np.linspace(-0.6, 0.7, robot.dof)
        expect = numeric.rnea(robot, q, 0.5 * q, -q)
        copy = pickle.loads(pickle.dumps(robot))
        assert type(copy.joints).__name__ == "FrozenList" and type(copy.links).__name__ == "FrozenDict"
        np.testing.assert_array_equal(numeric.rnea(copy, q, 0.5 * q, -q), expect)
        with pytest.raises(TypeError, match="immutable"):
            copy.joints.append(copy.joints[0])
        with pytest.raises(AttributeError, match="immutable"):
            copy.gravity = None
    # symbolic: the pickled rp-arm derives the same equations, term for term
    rp = armdyn.load("rp-arm")
    assert armdyn.derive(pickle.loads(pickle.dumps(rp))).tau == armdyn.derive(rp).tau


def test_published_defaults_in_the_api_must_be_finite():
    import sympy as sp

    m = sp.Symbol("m")
    links = [Link("base"), Link("l1", m, [0.1, 0, 0], np.eye(3) * 0.01)]
    joints = [Joint("j1", "revolute", "base", "l1")]
    for bad in (float("nan"), float("inf"), "heavy", None):
        with pytest.raises(ModelError, match="default value of parameter 'm' is not a finite number"):
            Robot("r", links, joints, parameters=[m], defaults={"m": bad})
    assert Robot("r", links, joints, parameters=[m], defaults={"m": 2}).bind().is_numeric
