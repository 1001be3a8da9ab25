"""Bad model files: a corpus of broken URDFs (tests/models/broken/), generated junk, and
Hypothesis mutations of valid URDF and YAML models.

The property everywhere: reading a model either gives a Robot or raises ONE
armdyn.errors.ModelError whose one line names the file (and the element when there is
one); nothing else escapes, nothing hangs, and the CLI turns it into one line on stderr
and exit status 2.
"""

from __future__ import annotations

import copy
import io
import os
import subprocess
import sys
import time
import warnings
import xml.etree.ElementTree as ET
from contextlib import redirect_stderr, redirect_stdout
from pathlib import Path

import pytest
import yaml
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from armdyn.cli import main as cli_main
from armdyn.errors import ModelError
from armdyn.io.urdf import load_urdf
from armdyn.io.yaml import load_yaml_string
from armdyn.show import table

HERE = Path(__file__).resolve().parent
BROKEN = HERE / "models" / "broken"
ROBOTS = HERE.parent / "python" / "armdyn" / "robots"
PYTHON_DIR = HERE.parent / "python"

# file -> (element named in the error, words of the message)
EXPECTED = {
    "malformed-xml.urdf": ("line 10, column 3", "malformed XML: mismatched tag"),
    "missing-attribute.urdf": ("joint 'j1'", "no 'type' attribute"),
    "missing-inertia-value.urdf": ("link 'link1'", "no 'izz' attribute"),
    "unknown-joint-type.urdf": ("joint 'j1'", "unknown joint type 'revolve'"),
    "cycle.urdf": ("robot 'cycle'", "root link"),
    "cycle-below-root.urdf": ("robot 'cycle-below-root'", "not connected to the base"),
    "duplicate-link.urdf": ("link 'link1'", "duplicate link name"),
    "duplicate-joint.urdf": ("joint 'j1'", "duplicate joint name"),
    "nan-value.urdf": ("joint 'j1'", "'nan', not a finite number"),
    "non-physical-inertia.urdf": ("link 'link1'", "triangle inequality"),
    "negative-mass.urdf": ("link 'link1'", "negative"),
    "zero-axis.urdf": ("joint 'j1'", "axis is zero"),
    "unknown-link.urdf": ("joint 'j1'", "'link9' does not exist"),
    "mimic-missing-leader.urdf": ("joint 'j2'", "mimics joint 'j9', which does not exist"),
    "mimic-loop.urdf": ("joint 'j1'", "mimic joints form a loop (j1 -> j2 -> j1)"),
    "planar-axis.urdf": ("joint 'table'", "a planar joint moves in its joint frame's x-y plane"),
    "billion-laughs.urdf": ("<!DOCTYPE> on line 2", "entity declarations are not allowed"),
    "not-a-robot.urdf": ("<sdf>", "expected <robot>"),
    "empty.urdf": ("line 1, column 1", "malformed XML"),
}


def run_cli(*args) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    with redirect_stdout(out), redirect_stderr(err), warnings.catch_warnings():
        warnings.simplefilter("ignore")
        code = cli_main(list(args))
    return code, out.getvalue(), err.getvalue()


# ------------------------------------------------------------ the corpus


def test_corpus_is_complete():
    assert sorted(p.name for p in BROKEN.glob("*.urdf")) == sorted(EXPECTED)


@pytest.mark.parametrize("name", sorted(EXPECTED))
def test_broken_file_gives_one_clear_error(name):
    path = BROKEN / name
    element, words = EXPECTED[name]
    start = time.perf_counter()
    with pytest.raises(ModelError) as info:
        load_urdf(path)
    assert time.perf_counter() - start < 5
    err = info.value
    assert err.source == str(path) and err.element == element and words in err.message
    assert str(err) == f"{path}: {element}: {err.message}" and "\n" not in str(err)


@pytest.mark.parametrize("name", sorted(EXPECTED))
def test_cli_exits_nonzero_with_one_line(name, tmp_path):
    code, out, err = run_cli("show", str(BROKEN / name), "--out", str(tmp_path / "arm.png"))
    assert code == 2 and out == ""
    assert err.count("\n") == 1 and err.startswith("armdyn: error: ") and name in err
    assert "Traceback" not in err and not (tmp_path / "arm.png").exists()


def test_non_physical_file_loads_with_allow_nonphysical():
    with pytest.warns(UserWarning, match="triangle inequality"):
        robot = load_urdf(BROKEN / "non-physical-inertia.urdf", strict=False)
    assert robot.dof == 1
    code, out, _ = run_cli("show", str(BROKEN / "non-physical-inertia.urdf"), "--allow-nonphysical")
    assert code == 0 and "link1" in out


# ------------------------------------------------------------ megabytes of junk


def _cli_subprocess(path: Path) -> subprocess.CompletedProcess:
    env = dict(os.environ, PYTHONPATH=str(PYTHON_DIR) + os.pathsep + os.environ.get("PYTHONPATH", ""))
    return subprocess.run(
        [sys.executable, "-m", "armdyn.cli", "show", str(path)],
        capture_output=True, text=True, timeout=120, env=env,
    )  # fmt: skip


@pytest.mark.parametrize("kind", ["random-bytes", "xml-garbage", "deep-nesting", "huge-attribute"])
def test_megabytes_of_junk(kind, tmp_path):
    """Generated here (not committed): each a few megabytes. One ModelError, quickly,
    and the real command line (a subprocess) exits 2 with one line, no traceback."""
    import random

    rnd = random.Random(kind)
    if kind == "random-bytes":
        data = rnd.randbytes(4_000_000)
    elif kind == "xml-garbage":  # well-formed XML, wrong vocabulary, then cut off mid-way
        data = b'<robot name="junk">' + b"<blob a='1'>junk</blob>" * 200_000
    elif kind == "deep-nesting":
        data = b'<robot name="deep">' + b"<link>" * 200_000 + b"</link>" * 200_000 + b"</robot>"
    else:  # a valid file whose number is megabytes long
        head = b'<robot name="big"><link name="a"><inertial><mass value="'
        data = head + b"9" * 3_000_000 + b'"/></inertial></link></robot>'
    path = tmp_path / f"{kind}.urdf"
    path.write_bytes(data)
    assert path.stat().st_size > 1_000_000
    start = time.perf_counter()
    with pytest.raises(ModelError) as info:
        load_urdf(path)
    assert time.perf_counter() - start < 10
    assert info.value.source == str(path) and "\n" not in str(info.value)
    assert len(str(info.value)) < 300  # the junk is not echoed back
    done = _cli_subprocess(path)
    assert done.returncode == 2, done.stderr
    assert done.stderr.startswith("armdyn: error: ") and done.stderr.count("\n") == 1
    assert "Traceback" not in done.stderr


# ------------------------------------------------------------ Hypothesis: URDF

VALID_URDF = """<?xml version="1.0"?>
<robot name="fuzz">
  <link name="base"/>
  <joint name="j1" type="revolute">
    <parent link="base"/><child link="l1"/>
    <origin xyz="0 0 0.3" rpy="0 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="10" velocity="1"/>
    <dynamics damping="0.1" friction="0.2"/>
  </joint>
  <link name="l1">
    <inertial>
      <origin xyz="0 0 0.1" rpy="0.1 0.2 0.3"/>
      <mass value="1.5"/>
      <inertia ixx="0.02" iyy="0.02" izz="0.01" ixy="0" ixz="0" iyz="0"/>
    </inertial>
  </link>
  <joint name="j2" type="prismatic">
    <parent link="l1"/><child link="l2"/>
    <origin xyz="0.2 0 0" rpy="1.5707963267948966 0 0"/><axis xyz="1 0 0"/>
    <limit lower="0" upper="0.5" effort="100" velocity="1"/>
  </joint>
  <link name="l2">
    <inertial><mass value="0.5"/><inertia ixx="0.001" iyy="0.001" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  <joint name="tool" type="fixed">
    <parent link="l2"/><child link="tcp"/><origin xyz="0 0 0.05"/>
  </joint>
  <link name="tcp"/>
  <joint name="j3" type="continuous">
    <parent link="tcp"/><child link="l3"/><axis xyz="0 1 0"/>
  </joint>
  <link name="l3">
    <inertial><mass value="0.2"/><inertia ixx="0.0001" iyy="0.0001" izz="0.0001" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
</robot>
"""

GARBAGE = st.one_of(
    st.sampled_from(["", " ", "nan", "inf", "-inf", "-1", "0", "1e999", "1 2", "1 2 3 4", "0 0 0", "${x}",
                     "revolute", "floating", "planar", "fixed", "base", "l1", "l2", "tcp", "é", "1,2,3",
                     "0x10", "1_000", "--1", ".", "e5", "1e-400"]),
    st.text(max_size=12),
    st.floats(allow_nan=True, allow_infinity=True).map(repr),
    st.lists(st.floats(-10, 10), min_size=0, max_size=5).map(lambda v: " ".join(map(str, v))),
)  # fmt: skip


def _mutate_xml(root: ET.Element, data) -> None:
    elements = [e for e in root.iter() if e is not root]
    parents = {c: p for p in root.iter() for c in p}
    op = data.draw(st.sampled_from(["delete", "duplicate", "del-attr", "set-attr", "rename", "move"]))
    target = elements[data.draw(st.integers(0, len(elements) - 1))]
    if op == "delete":
        parents[target].remove(target)
    elif op == "duplicate":
        parents[target].append(copy.deepcopy(target))
    elif op == "rename":
        tags = ["link", "joint", "origin", "axis", "inertial", "mass", "limit", "mimic", "x"]
        target.tag = data.draw(st.sampled_from(tags))
    elif op == "move":  # re-hang an element under another one
        other = elements[data.draw(st.integers(0, len(elements) - 1))]
        if other is not target and target not in other.iter():
            parents[target].remove(target)
            other.append(target)
    elif target.attrib:
        key = data.draw(st.sampled_from(sorted(target.attrib)))
        if op == "del-attr":
            del target.attrib[key]
        else:
            target.set(key, data.draw(GARBAGE))
    else:
        target.set(data.draw(st.sampled_from(["name", "type", "link", "xyz", "value"])), data.draw(GARBAGE))


def _loads_or_model_error(load, text):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            robot = load(text)
        except ModelError as err:
            assert "\n" not in str(err), str(err)
            return None
    table(robot)  # a loaded robot can be shown
    return robot


@settings(max_examples=250, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(data=st.data(), rounds=st.integers(1, 4))
def test_mutated_urdf_gives_robot_or_model_error(data, rounds):
    root = ET.fromstring(VALID_URDF)
    for _ in range(rounds):
        _mutate_xml(root, data)
    _loads_or_model_error(load_urdf, ET.tostring(root, encoding="unicode"))


@settings(max_examples=100, deadline=None)
@given(cut=st.integers(0, len(VALID_URDF)), insert=st.text(max_size=8))
def test_cut_or_spliced_urdf_text(cut, insert):
    _loads_or_model_error(load_urdf, VALID_URDF[:cut] + insert + VALID_URDF[cut:][len(insert) :])


# ------------------------------------------------------------ Hypothesis: YAML

YAML_MODELS = [ROBOTS / "rp-arm.yaml", ROBOTS / "panda.yaml", ROBOTS / "puma560.yaml"]


def test_seed_models_exist():
    # the mutation tests below draw from these: a missing one is a failure, not a skip
    assert all(p.is_file() for p in YAML_MODELS), [str(p) for p in YAML_MODELS if not p.is_file()]


YAML_GARBAGE = st.one_of(
    GARBAGE,
    st.none(),
    st.booleans(),
    st.integers(-5, 5),
    st.floats(allow_nan=True, allow_infinity=True),
    st.lists(st.integers(-2, 2), max_size=4),
    st.dictionaries(st.sampled_from(["ixx", "a", "name", "x"]), st.integers(-1, 1), max_size=2),
    st.sampled_from(["pi/2", "m1*", "sqrt(-1)", "1/0", "l1**l1**l1", "__import__('os')", "q1", "zoo", "E", "nan"]),
)  # fmt: skip


def _paths(node, prefix=()):
    """Every (container path, key) inside nested YAML data."""
    items = node.items() if isinstance(node, dict) else enumerate(node) if isinstance(node, list) else ()
    for key, value in items:
        yield prefix, key
        yield from _paths(value, prefix + (key,))


def _mutate_yaml(doc, data) -> None:
    paths = list(_paths(doc))
    prefix, key = paths[data.draw(st.integers(0, len(paths) - 1))]
    parent = doc
    for k in prefix:
        parent = parent[k]
    op = data.draw(st.sampled_from(["delete", "replace", "duplicate"]))
    if op == "delete":
        del parent[key]
    elif op == "replace":
        parent[key] = data.draw(YAML_GARBAGE)
    elif isinstance(parent, list):
        parent.append(copy.deepcopy(parent[key]))
    else:
        parent[f"{key}_copy"] = copy.deepcopy(parent[key])


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(data=st.data(), rounds=st.integers(1, 3))
def test_mutated_yaml_gives_robot_or_model_error(data, rounds):
    path = data.draw(st.sampled_from(YAML_MODELS))
    doc = yaml.safe_load(path.read_text())
    for _ in range(rounds):
        _mutate_yaml(doc, data)
    text = yaml.safe_dump(doc, sort_keys=False)
    robot = _loads_or_model_error(lambda t: load_yaml_string(t, source=path.name), text)
    if robot is not None and robot.free_symbols():
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            try:
                robot.bind()
            except ModelError:
                pass


@settings(max_examples=100, deadline=None)
@given(data=st.data(), insert=st.text(max_size=6))
def test_cut_or_spliced_yaml_text(data, insert):
    text = data.draw(st.sampled_from(YAML_MODELS)).read_text()
    cut = data.draw(st.integers(0, len(text)))
    _loads_or_model_error(load_yaml_string, text[:cut] + insert + text[cut:][len(insert) :])
