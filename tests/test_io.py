"""Model readers: expressions, the YAML format, armdyn.io.load, the bundled models and
the corpus of broken models (tests/models/bad).

Second opinions: expressions against SymPy objects built by hand; the RP arm's
geometry and potential energy against the exercise's closed forms; published values
typed here from the publications; error messages against the element and line found
in the bad file itself.
"""

from __future__ import annotations

import re
import warnings
from pathlib import Path

import pytest
import sympy as sp

from armdyn import ModelError
from armdyn.io import ROBOTS_DIR, bundled_robots, load
from armdyn.io.expressions import make_parameters, parse_expression
from armdyn.io.yaml import load_yaml_string

BAD = Path(__file__).parent / "models" / "bad"


# ------------------------------------------------------------------ expressions
P = make_parameters(["m1", "m2", "l1", "g", "a", "S", "N", "E", "I", "Q", "O", "beta", "gamma", "lambda", "zeta"])
m1, m2, l1, g, a = sp.symbols("m1 m2 l1 g a")


@pytest.mark.parametrize(
    "text, expected",
    [
        ("l1", l1),
        ("-g", -g),
        ("pi/2", sp.pi / 2),
        ("m2*l1**2/12", m2 * l1**2 / sp.Integer(12)),
        ("sqrt(2)/2", sp.sqrt(2) / 2),
        ("0.5*a^2", sp.Float(0.5) * a**2),
        ("-a**2", -(a**2)),
        ("2**3**2", sp.Integer(512)),
        ("a**-2", a ** (-2)),
        ("2*-3", sp.Integer(-6)),
        ("(m1 + m2) * g * l1", (m1 + m2) * g * l1),
        ("1/3", sp.Rational(1, 3)),
        ("1e-3", sp.Float("0.001")),
        ("atan2(1, a) + cos(pi)", sp.atan2(1, a) - 1),
        (3, sp.Integer(3)),
        (0.25, sp.Float(0.25)),
    ],
)
def test_expressions(text, expected):
    assert parse_expression(text, P) == expected


@pytest.mark.parametrize("name", ["S", "N", "E", "I", "Q", "O", "beta", "gamma", "lambda", "zeta"])
def test_names_sympy_treats_specially_are_plain_symbols(name):
    value = parse_expression(f"2*{name}", P)
    assert value == 2 * sp.Symbol(name)  # a plain Symbol, no assumptions
    (sym,) = value.free_symbols
    assert sym.assumptions0 == sp.Symbol("x").assumptions0


@pytest.mark.parametrize(
    "text, message",
    [
        ("x*2", "unknown parameter 'x' in expression 'x*2'"),
        ("__import__('os').system('true')", "cannot parse"),
        ("__import__", "unknown parameter '__import__'"),
        ("a.__class__", "cannot parse"),
        ("(lambda: 1)()", "cannot parse"),
        ("a if a else g", "cannot parse"),
        ("[1]", "cannot parse"),
        ("'s'", "cannot parse"),
        ("a; g", "cannot parse"),
        ("2*(a", "missing ')'"),
        ("sin(a, g)", "takes 1 argument"),
        ("1/0", "not finite"),
        ("", "empty expression"),
    ],
)
def test_bad_expressions(text, message):
    with pytest.raises(ModelError) as info:
        parse_expression(text, P, "link 'l1'", "arm.yaml", "mass")
    assert str(info.value).startswith("arm.yaml: link 'l1': mass: ")
    assert message in str(info.value)


def test_expressions_never_reach_eval(monkeypatch):
    import builtins

    import sympy.parsing.sympy_parser as parser

    def boom(*args, **kwargs):
        raise AssertionError("eval reached")

    monkeypatch.setattr(parser, "parse_expr", boom)
    monkeypatch.setattr(builtins, "eval", boom)
    assert parse_expression("m2*l1**2/12 + sqrt(a)", P) == m2 * l1**2 / 12 + sp.sqrt(a)


def test_reserved_and_malformed_parameter_names():
    for bad in (["pi"], ["sin"], ["2x"], ["_x"], ["a b"], ["m1", "m1"]):
        with pytest.raises(ModelError, match="parameters"):
            make_parameters(bad)


# ------------------------------------------------------------------ the RP arm
def _pose(robot, link):
    """(R, p) of ``link`` in the base frame, composed from Joint.transform."""
    chain = []
    while link != robot.base:
        joint = robot.parent_joint(link)
        chain.append(joint)
        link = joint.parent
    R, p = sp.eye(3), sp.zeros(3, 1)
    for joint in reversed(chain):
        Rj, pj = joint.transform(robot.joint_coordinate(joint))
        R, p = R * Rj, p + R * pj
    return R, p


def test_rp_arm_geometry_and_potential_energy_match_the_exercise():
    robot = load("rp-arm")
    th, d2 = sp.symbols("theta1 d2")
    m1, m2, l1, g = (sp.Symbol(n) for n in ("m1", "m2", "l1", "g"))  # users' own symbols
    assert robot.coordinate_names == ["theta1", "d2"]
    assert [j.type for j in robot.movable_joints] == ["revolute", "prismatic"]
    assert set(robot.parameters.values()) == {m1, m2, l1, g}
    assert list(robot.gravity) == [0, -g, 0]

    R2, p2 = _pose(robot, "link2")
    expected = l1 * sp.Matrix([sp.cos(th), sp.sin(th), 0]) + d2 * sp.Matrix([-sp.sin(th), sp.cos(th), 0])
    assert sp.simplify(p2 - expected) == sp.zeros(3, 1)
    # R_1^2 of the exercise maps frame-1 to frame-2 coordinates: R_2^1 = (R_1^2)^T
    R12 = sp.Matrix([[1, 0, 0], [0, 0, -1], [0, 1, 0]])
    R1, _ = _pose(robot, "link1")
    assert sp.simplify(R1.T * R2 - R12.T) == sp.zeros(3, 3)

    V = 0
    for name, link in robot.links.items():
        if name == robot.base:
            continue
        R, p = _pose(robot, name)
        V += -link.mass * (robot.gravity.T * (p + R * link.com))[0]
    V_exercise = m1 * g * l1 * sp.sin(th) + m2 * g * (l1 * sp.sin(th) + d2 * sp.cos(th))
    assert sp.simplify(V - V_exercise) == 0
    for link in list(robot.links.values())[1:]:
        assert link.inertia == sp.zeros(3, 3)  # point masses


# ------------------------------------------------------------------ load / bundled
def test_bundled_models_load_and_cite_their_source():
    entries = {e["name"]: e for e in bundled_robots()}
    expected = {
        "rp-arm": (2, "frames"),
        "planar-2r": (2, "frames"),
        "puma560": (6, "standard-dh"),
        "puma560-craig": (6, "modified-dh"),
    }
    for name, (dof, convention) in expected.items():
        entry = entries[name]
        assert (entry["dof"], entry["convention"]) == (dof, convention), entry
        assert entry["source"] and entry["description"] and Path(entry["path"]).is_file()
        robot = load(name)  # strict: all symbolic, nothing to reject
        assert robot.dof == dof and robot.meta["file"] == entry["path"]
    for entry in entries.values():
        assert "error" not in entry, entry


def test_load_by_path_and_by_name_agree():
    by_name = load("planar-2r")
    by_path = load(ROBOTS_DIR / "planar-2r.yaml")
    assert [j.xyz for j in by_name.joints] == [j.xyz for j in by_path.joints]
    assert by_name.defaults == by_path.defaults == {"g": 9.81}


def test_load_errors(tmp_path):
    with pytest.raises(ModelError) as info:
        load("no-such-robot")
    assert "unknown robot 'no-such-robot'" in str(info.value)
    assert "rp-arm" in str(info.value) and "puma560" in str(info.value)  # lists bundled names
    with pytest.raises(ModelError, match=r"^models/missing\.yaml: no such file"):
        load("models/missing.yaml")
    other = tmp_path / "model.txt"
    other.write_text("name: x\n")
    with pytest.raises(ModelError, match="unknown model file type '.txt'"):
        load(other)


def test_puma560_defaults_are_the_published_values():
    """Corke, mdl_puma560.m (standard DH): m, r, I = [Ixx Iyy Izz ...] per link."""
    published = {
        1: (0, (0, 0, 0), (0, 0.35, 0)),
        2: (17.4, (-0.3638, 0.006, 0.2275), (0.13, 0.524, 0.539)),
        3: (4.8, (-0.0203, -0.0141, 0.070), (0.066, 0.086, 0.0125)),
        4: (0.82, (0, 0.019, 0), (1.8e-3, 1.3e-3, 1.8e-3)),
        5: (0.34, (0, 0, 0), (0.3e-3, 0.4e-3, 0.3e-3)),
        6: (0.09, (0, 0, 0.032), (0.15e-3, 0.15e-3, 0.04e-3)),
    }
    d = load("puma560").defaults
    for i, (m, r, inertia) in published.items():
        assert d[f"m{i}"] == pytest.approx(m)
        assert [d[f"c{x}{i}"] for x in "xyz"] == pytest.approx(list(r))
        assert [d[f"I{x}{i}"] for x in ("xx", "yy", "zz")] == pytest.approx(list(inertia))
        assert [d[f"I{x}{i}"] for x in ("xy", "xz", "yz")] == [0, 0, 0]
    assert (d["a2"], d["a3"], d["d3"], d["d4"], d["g"]) == (0.4318, 0.0203, 0.15005, 0.4318, 9.81)
    craig = load("puma560-craig").defaults
    assert craig == {"a2": 0.4318, "a3": 0.02032, "d3": 0.14909, "d4": 0.43307, "g": 9.81}


def test_puma560_published_inertias_are_flagged_as_the_file_says():
    """The file notes that links 1 and 3 break the triangle inequality as published:
    link 1 (0, 0.35, 0), link 3 (0.066, 0.086, 0.0125) -> 0.066 + 0.0125 < 0.086."""
    with pytest.raises(ModelError, match="link 'link1'.*triangle"):
        load("puma560", strict=True).bind()
    with pytest.warns(UserWarning) as record:
        load("puma560", strict=False).bind()
    flagged = sorted(re.search(r"link '(\w+)'", str(w.message))[1] for w in record)
    assert flagged == ["link1", "link3"]
    # by default the published model loads and binds with ONE warning naming its source
    with warnings.catch_warnings(record=True) as record:
        warnings.simplefilter("always")
        load("puma560").bind({"m2": 17.4}).bind()
    assert len(record) == 1
    message = str(record[0].message)
    assert "Corke" in message and re.findall(r"link '(\w+)'", message) == ["link1", "link3"]


# ------------------------------------------------------------------ YAML format
TWO_LINKS = """
name: t
parameters: {{m: 2.0, L: 1e-3, h: "pi/4", k: null}}
joints:
  - name: j1
    type: {jtype}
    parent: base
    child: l1
    {placement}
links:
  - name: l1
    mass: m
    com: [L, 0, 0]
    inertia: [[1, 0, 0], [0, 1, 0], [0, 0, 1]]
"""


def test_rpy_and_rotation_matrix_give_the_same_placement():
    by_rpy = load_yaml_string(TWO_LINKS.format(jtype="revolute", placement="rpy: [pi/2, 0, 0]"))
    by_matrix = load_yaml_string(
        TWO_LINKS.format(jtype="revolute", placement="rotation: [[1, 0, 0], [0, 0, -1], [0, 1, 0]]")
    )
    assert by_rpy.joints[0].rotation == by_matrix.joints[0].rotation  # exact: pi/2 stays exact
    both = TWO_LINKS.format(
        jtype="revolute", placement="rpy: [0, 0, 0]\n    rotation: [[1, 0, 0], [0, 1, 0], [0, 0, 1]]"
    )
    with pytest.raises(ModelError, match="either rpy or rotation"):
        load_yaml_string(both)


def test_yaml_details():
    robot = load_yaml_string(TWO_LINKS.format(jtype="continuous", placement="axis: [0, 1, 0]"), "t.yaml")
    assert robot.joints[0].type == "revolute"  # continuous = revolute without limits
    assert robot.defaults == {"m": 2.0, "L": 0.001, "h": pytest.approx(0.785398163397448)}
    assert robot.parameters["m"] == sp.Symbol("m")
    assert robot.meta["convention"] == "frames"
    assert list(robot.gravity) == [0, 0, sp.Float(-9.81)]
    with pytest.raises(ModelError, match=r"^t\.yaml:2: duplicate key 'name' \(first on line 1\)"):
        load_yaml_string("name: a\nname: b\njoints: []\nlinks: []\n", "t.yaml")
    with pytest.raises(ModelError, match="a 'dh' table needs convention"):
        load_yaml_string("dh: []\n")
    with pytest.raises(ModelError, match="'joints' cannot be used with convention standard-dh"):
        load_yaml_string("convention: standard-dh\njoints: []\ndh: []\n")


def test_dh_yaml_rows():
    text = """
name: two
convention: modified-dh
parameters: [L]
dh:
  - {name: q1, type: revolute, alpha: 0, a: 0}
  - {name: q2, type: prismatic, alpha: -pi/2, a: L, theta: pi/2, link: slider}
"""
    robot = load_yaml_string(text)
    assert list(robot.links) == ["base", "link1", "slider"]
    j2 = robot.joints[1]
    assert j2.type == "prismatic" and list(j2.xyz) == [sp.Symbol("L"), 0, 0]
    # Rx(-pi/2) Rz(pi/2): columns are the placement axes in frame 1, worked by hand
    assert j2.rotation == sp.Matrix([[0, -1, 0], [0, 0, 1], [-1, 0, 0]])


# ------------------------------------------------------------------ the bad corpus
# file -> (element named in the message, substring of the message)
CORPUS = {
    "unknown-joint-type.yaml": ("joint 'j2'", "unknown joint type 'rotary'"),
    "zero-axis.yaml": ("joint 'j2'", "axis is zero"),
    "non-unit-axis.yaml": ("joint 'j2'", "not a unit vector"),
    "negative-mass.yaml": ("link 'l2'", "negative"),
    "triangle-inequality.yaml": ("link 'l2'", "triangle inequality"),
    "missing-parent.yaml": ("joint 'j2'", "parent link 'l7' does not exist"),
    "unparseable-expression.yaml": ("link 'l1'", "cannot parse expression '2*(l1'"),
    "unknown-parameter.yaml": ("link 'l1'", "unknown parameter 'x' in expression 'x*2'"),
    "duplicate-joint.yaml": ("joint 'j1'", "duplicate joint name"),
    "duplicate-link.yaml": ("link 'l1'", "duplicate link name"),
    "cycle.yaml": ("robot 'cycle'", "a cycle?"),
    "missing-inertia.yaml": ("link 'l1'", "no inertia"),
    "yaml-syntax.yaml": ("", "YAML syntax error"),
    "unknown-key.yaml": ("link 'l2'", "unknown key(s) 'masss'"),
    "unknown-top-key.yaml": ("model", "unknown key(s) 'jionts'"),
    "wrong-vector-length.yaml": ("joint 'j2'", "xyz: expected 3 values, got 2"),
    "injection.yaml": ("link 'l2'", "cannot parse expression '__import__"),
    "bad-rotation.yaml": ("joint 'j2'", "not orthonormal"),
    "reserved-parameter.yaml": ("parameters", "parameter name 'pi' is reserved"),
    "unconnected-link.yaml": ("link 'l3'", "not the child of any joint"),
    "not-finite.yaml": ("link 'l1'", "not finite"),
    "dh-unknown-key.yaml": ("joint 'q2'", "unknown key(s) 'alfa'"),
    "dh-prismatic-typo.yaml": ("joint 'q2'", "unknown joint type 'prismatc'"),
}


def test_corpus_is_complete():
    assert sorted(CORPUS) == sorted(p.name for p in BAD.glob("*.yaml"))


def _element_lines(path: Path, element: str) -> list[int]:
    """1-based lines of the `name: X` entries of a joint/link element in the file."""
    m = re.match(r"(joint|link) '(.+)'", element)
    if not m:
        return []
    pattern = rf"name: {re.escape(m[2])}\b"
    return [i for i, line in enumerate(path.read_text().splitlines(), 1) if re.search(pattern, line)]


@pytest.mark.parametrize("filename", sorted(CORPUS))
def test_bad_model_gives_one_line_naming_file_and_element(filename):
    element, message = CORPUS[filename]
    path = BAD / filename
    with pytest.raises(ModelError) as info:
        load(path)
    text = str(info.value)
    assert "\n" not in text
    assert text.startswith(str(path)), text
    assert element in text and message in text, text
    lines = _element_lines(path, element)
    if lines:  # the line given is that of the element's entry
        assert int(re.match(rf"{re.escape(str(path))}:(\d+): ", text)[1]) in lines, text


def test_yaml_syntax_error_names_the_line():
    path = BAD / "yaml-syntax.yaml"
    with pytest.raises(ModelError) as info:
        load(path)
    # the unclosed list starts on line 8 and the parser trips on line 9
    assert f"{path}:9:" in str(info.value) and "line 8" in str(info.value)


@pytest.mark.parametrize("filename", ["negative-mass.yaml", "triangle-inequality.yaml"])
def test_physical_checks_are_the_strict_ones(filename):
    with pytest.warns(UserWarning):
        robot = load(BAD / filename, strict=False)
    assert robot.dof == 2


def test_bundled_models_keep_their_names():
    """Each bundled file's `name:` is the robot's name (a DH table must not overwrite it)."""
    import yaml as pyyaml

    for entry in bundled_robots():
        if str(entry["path"]).endswith(".yaml"):
            with open(entry["path"]) as fh:
                declared = pyyaml.safe_load(fh)["name"]
            assert load(entry["name"], strict=False).name == declared
