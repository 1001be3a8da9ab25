"""armdyn's YAML model format (this docstring is the format's reference).

A model file describes one fixed-base robot: links, joints between them, gravity, and
the named parameters its numbers may use. Two forms share one loader: general frames
(``joints`` + ``links``, any placement, what the RP-arm exercise needs) and DH tables
(``dh``, standard or modified). Units are SI, angles radians.

General frames
--------------
::

    name: rp-arm                    # optional, default: the file's stem
    description: one line           # optional
    source: where the values come from (citation)      # optional, but please do
    notes: free text                # optional (caveats about the data)
    convention: frames              # optional: frames (default) | standard-dh | modified-dh
    base: base                      # optional, default "base"; need not be in `links`
    parameters: [m1, m2, l1, g]     # or a mapping: name -> published value (number) or null
    gravity: [0, -g, 0]             # optional, base frame, default [0, 0, -9.81]
    joints:                         # any order; must form a tree rooted at `base`
      - name: theta1
        type: revolute              # revolute | prismatic | fixed | continuous (= revolute)
        parent: base
        child: link1
        xyz: [0, 0, 0]              # optional placement translation in the parent frame
        rpy: [0, 0, 0]              # optional placement rotation, URDF roll-pitch-yaw:
                                    #   R = Rz(yaw) Ry(pitch) Rx(roll)
        # rotation: [[1, 0, 0], [0, 0, 1], [0, -1, 0]]
                                    # OR the placement rotation as a 3x3 matrix whose
                                    #   COLUMNS are the placement frame's axes in the
                                    #   parent frame (not both rpy and rotation)
        axis: [0, 0, 1]             # optional unit axis in the placement frame, default z
        frame_xyz: [0, 0, 0]        # optional: the child link's frame in the moved joint
        frame_rpy: [0, 0, 0]        #   frame (frame_rpy or frame_rotation as above), for
                                    #   frames off the joint's axis; default: on it
        limits: {lower: -pi, upper: pi, velocity: 2, effort: 100}   # optional, any subset
        damping: 0.1                # optional viscous friction Fv (tau += Fv qd)
        friction: 0.0               # optional Coulomb friction Fc (tau += Fc sign(qd))
        armature: 0.0               # optional rotor inertia at the joint Ia (tau += Ia qdd),
        # or rotor_inertia: Jm with gear_ratio: G  -> Ia = G^2 Jm (not both)
        torque_offset: 0.0          # optional constant offset (tau += offset)
    links:
      - name: link1
        mass: m1                    # optional, default 0
        com: [l1, 0, 0]             # optional centre of mass in the link frame, default 0
        inertia: 0                  # about the centre of mass, link-frame axes:
                                    #   0 (point mass) | 3x3 symmetric matrix |
                                    #   {ixx, iyy, izz, ixy, ixz, iyz} (products default 0)

Semantics (as :mod:`armdyn.model`): the joint sits at ``xyz`` + ``rotation`` in the
parent link's frame, then turns about (revolute) or slides along (prismatic) ``axis``;
the child link's frame is the placement frame after that motion (then moved by
``frame_xyz``/``frame_rpy`` when given: a frame of your own choosing, off the axis). The joint
coordinates are named after the movable joints, in tree order.

DH tables
---------
::

    name: puma560
    convention: standard-dh         # or modified-dh (Craig)
    parameters: {a2: 0.4318, g: 9.81, m2: 17.4, ...}
    gravity: [0, 0, -g]
    dh:
      - {name: q1, type: revolute, a: 0, alpha: pi/2, d: 0, theta: 0,
         link: link1, mass: m1, com: [cx1, cy1, cz1], inertia: {ixx: Ixx1, ...}}
      - ...

Each row: ``name`` (joint) and ``type`` (revolute | prismatic) required; ``a``,
``alpha``, ``d``, ``theta`` default 0 (``theta`` is the offset of a revolute joint,
``d`` that of a prismatic one); ``link`` defaults to ``link<i>``; ``mass``, ``com``,
``inertia``, ``limits``, ``damping``, ``friction`` as above, with ``com`` and
``inertia`` given in the row's DH frame i of that convention. A standard row holds
``a_i, alpha_i, d_i, theta_i`` (``A_i = Rz Tz Tx Rx``); a modified row holds
``alpha_{i-1}, a_{i-1}, d_i, theta_i`` (``Rx Tx Rz Tz``). See :mod:`armdyn.io.dh` for
the exact conversion; for standard DH armdyn's link frame i is not DH frame i, and the
inertial data are transformed into it exactly (``robot.meta["frames"]`` says how).
``joints``/``links`` and ``dh`` cannot be mixed.

Values
------
Every number may be a number or a string expression of the declared parameters with
``+ - * / ** ^ ( )``, the functions sin cos tan asin acos atan atan2 sinh cosh tanh
sqrt exp log abs and the constant pi: ``"pi/2"``, ``"m2*l1**2/12"``, ``"sqrt(2)/2"``
(:mod:`armdyn.io.expressions`). Parameters are plain ``sp.Symbol(name)`` with no
assumptions. Write exact values where they matter: ``pi/2`` rather than ``1.5708``,
``sqrt(2)/2`` rather than ``0.7071`` (a ``rotation`` matrix must be orthonormal to
1e-9). YAML 1.1 reads ``1e-3`` as a string; armdyn parses it as the number.

Rules (each broken rule is a :class:`~armdyn.errors.ModelError` whose one line names
the file, the line, the element and the problem, e.g.
``arm.yaml:14: joint 'j2': axis is zero``):

* unknown keys are errors (typos do not pass silently); so are duplicate keys;
* every link a joint names must be listed in ``links`` (the base link excepted), and
  every listed link must be reached by a joint;
* a link with a non-zero mass must give ``inertia`` explicitly (``0`` for a point mass);
* names of joints, of links and of parameters are unique; joints and parameters share
  one namespace (the joint coordinates are symbols too);
* with ``strict`` (default) each link must be physically valid (mass >= 0, inertia
  symmetric, positive semi-definite, triangle inequality), checked by :class:`armdyn.Robot`.

The loaded :class:`~armdyn.Robot` has ``defaults`` from the ``parameters`` mapping and
``meta`` = {description, source, notes, convention, file} (+ ``frames``, ``dh_table``
for DH models).
"""

from __future__ import annotations

import math
import os
from pathlib import Path
from typing import Mapping

import yaml

from ..errors import ModelError
from ..model import Joint, Link, Robot, rpy_matrix
from .dh import from_dh
from .expressions import (
    check_name,
    check_rotation,
    make_parameters,
    parse_expression,
    parse_inertials,
    parse_joint_extras,
    parse_matrix3,
    parse_vector,
    quoted,
    shown,
)
from .textfile import MODEL_MAX_BYTES, read_text
from .yaml_screen import screen

TOP_KEYS = (
    "name", "description", "source", "notes", "convention", "base",
    "parameters", "gravity", "joints", "links", "dh",
)  # fmt: skip
JOINT_KEYS = (
    "name",
    "type",
    "parent",
    "child",
    "xyz",
    "rpy",
    "rotation",
    "axis",
    "frame_xyz",
    "frame_rpy",
    "frame_rotation",
    "limits",
    "damping",
    "friction",
    "armature",
    "rotor_inertia",
    "gear_ratio",
    "torque_offset",
)
LINK_KEYS = ("name", "mass", "com", "inertia")
JOINT_TYPES = {"revolute": "revolute", "continuous": "revolute", "prismatic": "prismatic", "fixed": "fixed"}
MODEL_CONVENTIONS = ("frames", "standard-dh", "modified-dh")


# ------------------------------------------------------------------ YAML with lines
class _Map(dict):
    """A YAML mapping that remembers its line (1-based) in the file."""

    line: int | None = None


class _LineLoader(yaml.SafeLoader):
    """``yaml.SafeLoader`` (no object construction) whose mappings record their line
    and reject duplicate keys."""


class _DuplicateKey(yaml.constructor.ConstructorError):
    pass


def _construct_mapping(loader: _LineLoader, node: yaml.MappingNode) -> _Map:
    loader.flatten_mapping(node)
    seen = {}
    for key_node, _ in node.value:
        key = loader.construct_object(key_node, deep=True)
        try:
            hash(key)
        except TypeError:
            continue  # construct_mapping reports the unhashable key
        if key in seen:
            message = f"duplicate key {shown(key)} (first on line {seen[key]})"
            raise _DuplicateKey(None, None, message, key_node.start_mark)
        seen[key] = key_node.start_mark.line + 1
    out = _Map(loader.construct_mapping(node, deep=True))
    out.line = node.start_mark.line + 1
    return out


_LineLoader.add_constructor(yaml.resolver.BaseResolver.DEFAULT_MAPPING_TAG, _construct_mapping)


def _at(source: str, node) -> str:
    """``file:line`` of a mapping read from YAML (just ``file`` otherwise)."""
    line = getattr(node, "line", None)
    return f"{source}:{line}" if line else source


def parse_text(text: str, source: str):
    """A model file's YAML text parsed (screened first, keys unique, line numbers kept);
    a syntax error is a ModelError naming ``source`` and the line."""
    screen(text, source)  # aliases, deep nesting, huge integers: refused before anything is built
    try:
        return yaml.load(text, Loader=_LineLoader)  # noqa: S506 - a SafeLoader subclass
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark or exc.context_mark
        line = f":{mark.line + 1}" if mark else ""
        context = exc.context or ""
        if context and exc.context_mark and exc.context_mark is not mark:
            context += f" started on line {exc.context_mark.line + 1}"
        what = ": ".join(str(p) for p in (context, exc.problem) if p)
        kind = "" if isinstance(exc, _DuplicateKey) else "YAML syntax error: "
        raise ModelError(f"{kind}{what}", None, f"{source}{line}") from None
    except yaml.YAMLError as exc:  # e.g. a ReaderError: a control character in the text
        raise ModelError(f"YAML error: {' '.join(str(exc).split())}", None, source) from None


# ------------------------------------------------------------------ checks
def _rotation(item, rpy_key, matrix_key, params, element, where):
    """A rotation given as roll-pitch-yaw angles or as a 3x3 matrix (not both)."""
    if rpy_key in item and matrix_key in item:
        raise ModelError(f"give either {rpy_key} or {matrix_key}, not both", element, where)
    if matrix_key in item:
        rotation = parse_matrix3(item[matrix_key], params, element, where, matrix_key)
        check_rotation(rotation, element, where, what=matrix_key)
        return rotation
    return rpy_matrix(*parse_vector(item.get(rpy_key, [0, 0, 0]), params, element, where, rpy_key))


def _check_keys(data, allowed, element, where, only_mapping=False):
    """ModelError unless ``data`` is a mapping whose keys are all in ``allowed``."""
    if not isinstance(data, Mapping):
        raise ModelError(f"expected a mapping, got {type(data).__name__} {shown(data)}", element, where)
    if only_mapping:
        return
    unknown = [k for k in data if k not in allowed]
    if unknown:
        raise ModelError(
            f"unknown key(s) {', '.join(map(shown, unknown))} (expected {', '.join(allowed)})", element, where
        )


def _name(data, what, where, element):
    if "name" not in data:
        raise ModelError(f"{what} without a 'name'", element, where)
    return check_name(data["name"], "name", element, where)


def _list(data, key, where):
    value = data.get(key)
    if not isinstance(value, list):
        raise ModelError(f"expected a list, got {type(value).__name__}", key, where)
    return value


def _parameters(value, where):
    """``(parameters dict name -> Symbol, defaults dict name -> number)``."""
    if value is None:
        return {}, {}
    if isinstance(value, list):
        return make_parameters(value, "parameters", where), {}
    if isinstance(value, Mapping):
        params = make_parameters(list(value), "parameters", where)
        defaults = {}
        for name, default in value.items():
            if default is None:
                continue
            if isinstance(default, str):  # "1e-3" (a string to YAML 1.1), "pi/2"
                value = parse_expression(default, {}, "parameters", where, f"value of '{name}'")
                if value.free_symbols or not value.is_real:
                    raise ModelError(f"the published value of '{name}' must be a number", "parameters", where)
                default = float(value)
            if isinstance(default, bool) or not isinstance(default, (int, float)):
                message = f"the published value of '{name}' must be a number or null, got {shown(default)}"
                raise ModelError(message, "parameters", where)
            try:  # .nan, .inf, 1.0e999999 (read as inf), an int beyond float64
                finite = math.isfinite(float(default))
            except OverflowError:
                finite = False
            if not finite:
                message = f"the published value of '{name}' is not a finite number, got {shown(default)}"
                raise ModelError(message, "parameters", where)
            defaults[name] = default
        return params, defaults
    raise ModelError("expected a list of names or a mapping name -> value", "parameters", where)


# ------------------------------------------------------------------ the two forms
def _frames_robot(data, name, params, defaults, gravity, base, meta, source, strict):
    lines: dict[str, str] = {}  # element -> "file:line", to locate the Robot's errors
    links: dict[str, Link] = {}
    for item in _list(data, "links", source):
        where = _at(source, item)
        _check_keys(item, (), "links", where, only_mapping=True)
        lname = _name(item, "a link", where, "links")
        element = f"link '{lname}'"
        _check_keys(item, LINK_KEYS, element, where)
        if lname in links:
            raise ModelError("duplicate link name", element, where)
        lines[element] = where
        mass, com, inertia = parse_inertials(item, params, element, where)
        links[lname] = Link(lname, mass, com, inertia)
    if base not in links:
        links[base] = Link(base)

    joints = []
    for item in _list(data, "joints", source):
        where = _at(source, item)
        _check_keys(item, (), "joints", where, only_mapping=True)
        jname = _name(item, "a joint", where, "joints")
        element = f"joint '{jname}'"
        _check_keys(item, JOINT_KEYS, element, where)
        if element in lines:
            raise ModelError("duplicate joint name", element, where)
        lines[element] = where
        extras = parse_joint_extras(item, params, element, where)
        jtype = item.get("type")
        if not isinstance(jtype, str) or jtype not in JOINT_TYPES:
            raise ModelError(
                f"unknown joint type {shown(jtype)} (expected one of {', '.join(JOINT_TYPES)})", element, where
            )
        for key in ("parent", "child"):
            link = check_name(item.get(key), key, element, where)
            if link not in links:
                raise ModelError(f"{key} link {quoted(link)} does not exist (not listed in links)", element, where)
        rotation = _rotation(item, "rpy", "rotation", params, element, where)
        xyz = parse_vector(item.get("xyz", [0, 0, 0]), params, element, where, "xyz")
        if "frame_xyz" in item or "frame_rpy" in item or "frame_rotation" in item:
            extras["frame_xyz"] = parse_vector(item.get("frame_xyz", [0, 0, 0]), params, element, where, "frame_xyz")
            extras["frame_rotation"] = _rotation(item, "frame_rpy", "frame_rotation", params, element, where)
        axis = parse_vector(item.get("axis", [0, 0, 1]), params, element, where, "axis")
        try:
            joints.append(
                Joint(jname, JOINT_TYPES[jtype], item["parent"], item["child"], xyz, rotation, axis, **extras)
            )
        except ModelError as err:
            raise err.located(source=where)

    reached = {base} | {j.child for j in joints}
    stray = [n for n in links if n not in reached]
    if stray:
        element = f"link '{stray[0]}'"
        raise ModelError("link is not the child of any joint (not connected)", element, lines.get(element, source))

    try:
        return Robot(name, links.values(), joints, gravity, params, meta, base, defaults, strict=strict)
    except ModelError as err:
        raise err.located(source=lines.get(err.element or "", source))


def _dh_robot(data, name, params, defaults, gravity, base, meta, source, strict, convention):
    rows = _list(data, "dh", source)
    lines = {}
    for i, row in enumerate(rows, start=1):
        if isinstance(row, Mapping):
            for kind, label in (("joint", row.get("name")), ("link", row.get("link", f"link{i}"))):
                if isinstance(label, str):
                    lines[f"{kind} '{label}'"] = _at(source, row)
    try:
        return from_dh(name, rows, convention, gravity, list(params), defaults, base, meta, strict=strict, source=None)
    except ModelError as err:
        raise err.located(source=lines.get(err.element or "", source))


# ------------------------------------------------------------------ entry points
def robot_from_dict(data, source: str = "<model>", strict: bool = True, default_name: str = "robot") -> Robot:
    """A Robot from a model already read into Python objects (the YAML format above).

    source: file name used in error messages. Mappings read by :func:`load_yaml` know
    their line numbers; plain dicts do not, and errors then name only ``source``.
    """
    _check_keys(data, TOP_KEYS, "model", _at(source, data))
    name = check_name(data.get("name", default_name), "name", "model", source)
    convention = data.get("convention", "frames")
    if convention not in MODEL_CONVENTIONS:
        message = f"unknown convention {shown(convention)} (expected one of {', '.join(MODEL_CONVENTIONS)})"
        raise ModelError(message, "convention", source)
    base = check_name(data.get("base", "base"), "base", "model", source)
    params, defaults = _parameters(data.get("parameters"), source)
    gravity = parse_vector(data.get("gravity", [0, 0, -9.81]), params, "gravity", source)
    meta = {k: data[k] for k in ("description", "source", "notes") if k in data}
    for key, text in meta.items():
        # text only: a list or mapping here (say a YAML alias bomb) would be printed by
        # `armdyn show` / `robots`, exponentially
        if not isinstance(text, str):
            raise ModelError(f"expected text, got {type(text).__name__} {shown(text)}", key, source)
    meta["convention"] = convention
    if source:
        meta["file"] = source  # so that warnings during construction name the file

    if convention == "frames":
        if "dh" in data:
            raise ModelError("a 'dh' table needs convention: standard-dh or modified-dh", "dh", source)
        for key in ("joints", "links"):
            if key not in data:
                raise ModelError(f"missing '{key}'", "model", source)
        return _frames_robot(data, name, params, defaults, gravity, base, meta, source, strict)
    for key in ("joints", "links"):
        if key in data:
            raise ModelError(f"'{key}' cannot be used with convention {convention} (use the 'dh' rows)", key, source)
    if "dh" not in data:
        raise ModelError(f"convention {convention} needs a 'dh' table", "model", source)
    return _dh_robot(data, name, params, defaults, gravity, base, meta, source, strict, convention)


def load_yaml_string(text: str, source: str = "<string>", strict: bool = True) -> Robot:
    """A Robot from YAML text (errors name ``source``)."""
    data = parse_text(text, source)
    if data is None:
        raise ModelError("the file is empty", None, source)
    return robot_from_dict(data, source, strict)


def load_yaml(path, strict: bool = True, source: str | None = None) -> Robot:
    """A Robot from a YAML model file.

    path:   the file (str or PathLike).
    strict: check each link's physical validity (see :class:`armdyn.Robot`).
    source: how errors name the file (default: ``path`` as given).
    """
    path = Path(path)
    source = source or os.fspath(path)
    text = read_text(path, "model", MODEL_MAX_BYTES, name=source)
    data = parse_text(text, source)
    if data is None:
        raise ModelError("the file is empty", None, source)
    robot = robot_from_dict(data, source, strict, default_name=path.stem)
    robot.meta["file"] = os.fspath(path)
    return robot


__all__ = ["load_yaml", "load_yaml_string", "robot_from_dict", "TOP_KEYS", "JOINT_KEYS", "LINK_KEYS"]
