"""Denavit-Hartenberg tables, standard and modified, converted exactly into armdyn's
general joint form (:mod:`armdyn.model`).

Each row of a table describes one joint (and the link it moves)::

    {"name": "q1", "type": "revolute" | "prismatic",
     "a": ..., "alpha": ..., "d": ..., "theta": ...,      # each default 0
     "link": "link1",                                     # optional, default link<i>
     "mass": ..., "com": [x, y, z], "inertia": ...,       # optional, in the row's DH frame
     "limits": {...}, "damping": ..., "friction": ...}    # optional

For a revolute joint ``theta`` is the constant offset added to the joint coordinate;
for a prismatic joint ``d`` is. Values may be numbers, SymPy expressions, or strings
parsed by :mod:`armdyn.io.expressions` (``"pi/2"``, ``"a2"``). Write twists as exact
multiples of pi (``sp.pi/2`` or ``"pi/2"``, not ``1.5708``): then the rotations have
exact 0/1 entries.

Conventions (``x`` is the joint coordinate, Rx/Rz rotations, Tx/Tz translations):

standard (Denavit-Hartenberg; Spong, Corke), row i holds ``a_i, alpha_i, d_i, theta_i``::

    A_i = Rz(theta_i + x) Tz(d_i) Tx(a_i) Rx(alpha_i)          (revolute)

modified (Craig), row i holds ``alpha_{i-1}, a_{i-1}, d_i, theta_i``::

    T_i = Rx(alpha_{i-1}) Tx(a_{i-1}) Rz(theta_i + x) Tz(d_i)  (revolute)

(prismatic: ``d_i + x`` in place of ``d_i`` and ``theta_i`` alone.)

In armdyn's form a joint's motion comes last (the child link frame is the placement
frame after the motion), so:

* modified DH: armdyn's link frame i IS Craig's frame i. Joint i's placement is
  ``Rx(alpha_{i-1}) Tx(a_{i-1}) Rz(theta_i) Tz(d_i)`` (offsets included), then the
  motion about/along z. Inertial data given in frame i is used as it is.
* standard DH: the motion of joint i comes FIRST in A_i, so armdyn's link frame i is
  DH frame i-1 moved by joint i (``Rz(theta_i + x) Tz(d_i)``); it is not DH frame i.
  DH frame i = link frame i * ``Tx(a_i) Rx(alpha_i)``, and that constant transform goes
  into joint i+1's placement: ``Tx(a_{i-1}) Rx(alpha_{i-1}) Rz(theta_i) Tz(d_i)``
  (nothing before joint 1). The last row's ``Tx(a_n) Rx(alpha_n)`` becomes a fixed
  joint ``flange`` to a massless link ``flange`` (DH frame n), added only when that
  transform is not the identity.

  Inertial data of a standard-DH row is given in DH frame i (as in Corke's toolbox)
  and is transformed exactly into link frame i::

      com_link = (a_i, 0, 0) + Rx(alpha_i) com_dh
      I_link   = Rx(alpha_i) I_dh Rx(alpha_i)^T      (about the centre of mass)

  So armdyn's intermediate quantities (Newton-Euler steps, inertia tensors printed
  per link) are in link frame i, not in DH frame i. ``robot.meta["frames"]`` says so.

In both conventions link frame i's origin lies on joint i's axis and its z axis is
joint i's axis: exactly Craig's frame i. Converting a standard table to armdyn and a
modified table with ``alpha_{i-1}, a_{i-1}`` of the previous standard row gives the
same frames (and the same dynamics once the inertial data are moved as above).
"""

from __future__ import annotations

from typing import Iterable, Mapping, NamedTuple

import sympy as sp

from ..errors import ModelError
from ..model import Joint, Link, Robot, rot_x, rot_z
from .expressions import (
    check_name,
    is_zero,
    make_parameters,
    parse_expression,
    parse_inertials,
    parse_joint_extras,
    parse_vector,
    shown,
)

ROW_KEYS = (
    "name", "link", "type", "a", "alpha", "d", "theta",
    "mass", "com", "inertia", "limits", "damping", "friction",
    "armature", "rotor_inertia", "gear_ratio", "torque_offset",
)  # fmt: skip

CONVENTIONS = {
    "standard": "standard-dh",
    "standard-dh": "standard-dh",
    "modified": "modified-dh",
    "modified-dh": "modified-dh",
}

FRAMES_NOTE = {
    "standard-dh": (
        "standard DH: link frame i = DH frame i-1 moved by joint i (Rz(theta_i) Tz(d_i)); "
        "DH frame i = link frame i * Tx(a_i) Rx(alpha_i). Inertial data given in DH frame i "
        "were transformed exactly into link frame i: com = (a_i,0,0) + Rx(alpha_i) com_dh, "
        "I = Rx(alpha_i) I_dh Rx(alpha_i)^T."
    ),
    "modified-dh": "modified DH (Craig): link frame i is Craig's frame i; inertial data are used as given.",
}


class _Row(NamedTuple):
    """One parsed table row; ``dh`` maps a, alpha, d, theta to SymPy values."""

    joint: str
    type: str
    link: str
    dh: dict
    mass: sp.Expr
    com: sp.Matrix
    inertia: sp.Matrix
    extras: dict


def _collect_symbols(value, out: set):
    """Free symbols of SymPy values nested in rows (strings are not looked at)."""
    if isinstance(value, (sp.Basic, sp.MatrixBase)):
        out |= value.free_symbols
    elif isinstance(value, Mapping):
        for v in value.values():
            _collect_symbols(v, out)
    elif isinstance(value, (list, tuple)):
        for v in value:
            _collect_symbols(v, out)


def _placement(a, alpha, theta, d):
    """``Tx(a) Rx(alpha) Rz(theta) Tz(d)`` as (rotation (3x3), xyz (3x1)).

    Tx and Rx commute, so this is also Craig's ``Rx(alpha) Tx(a) Rz(theta) Tz(d)``.
    """
    r_alpha = rot_x(alpha)
    rotation = r_alpha * rot_z(theta)
    xyz = sp.Matrix([a, 0, 0]) + r_alpha * sp.Matrix([0, 0, d])
    return rotation, xyz


def from_dh(
    name: str,
    rows: Iterable[Mapping],
    convention: str = "standard",
    gravity=(0, 0, -9.81),
    parameters=None,
    defaults: Mapping[str, float] | None = None,
    base: str = "base",
    meta: Mapping | None = None,
    strict: bool = True,
    source: str | None = None,
) -> Robot:
    """A :class:`~armdyn.Robot` from a DH table (conventions in the module docstring).

    name:       the robot's name.
    rows:       one mapping per joint, keys :data:`ROW_KEYS` (``name`` and ``type``
                required; ``a, alpha, d, theta`` default 0).
    convention: ``"standard"`` / ``"standard-dh"`` or ``"modified"`` / ``"modified-dh"``.
    gravity:    (3,) gravity in the base frame, default (0, 0, -9.81).
    parameters: names (or Symbols) of the parameters the values may use. When None, the
                free symbols of the SymPy values given are the parameters (strings may
                then only use those names).
    defaults:   name -> published value of parameters (see ``Robot.defaults``).
    base:       name of the base link (DH frame 0).
    meta:       extra entries for ``robot.meta`` (``convention``, ``frames`` and
                ``dh_table`` are set here).
    strict:     passed to :class:`~armdyn.Robot` (physical validity of each link).
    source:     file name for error messages.

    Returns a Robot whose link frame i is Craig's frame i (see module docstring), plus
    a fixed ``flange`` link for a standard table whose last row has ``a`` or ``alpha``
    non-zero.
    """
    if not isinstance(convention, str) or convention not in CONVENTIONS:
        raise ModelError(
            f"unknown DH convention {shown(convention)} (expected standard or modified)", "convention", source
        )
    convention = CONVENTIONS[convention]
    rows = list(rows)
    if not rows:
        raise ModelError("the DH table has no rows", "dh", source)

    if parameters is None:
        found: set = set()
        _collect_symbols(rows, found)
        _collect_symbols(gravity, found)
        names = sorted(s.name for s in found)
    elif isinstance(parameters, Mapping):
        names = list(parameters)
    else:
        names = [p.name if isinstance(p, sp.Symbol) else p for p in parameters]
    params = make_parameters(names, "parameters", source)
    gravity = parse_vector(gravity, params, "gravity", source)

    parsed = []
    for i, row in enumerate(rows, start=1):
        if not isinstance(row, Mapping):
            raise ModelError(f"row {i} of the DH table is not a mapping", "dh", source)
        if "name" not in row:
            raise ModelError(f"row {i} of the DH table has no joint name ('name')", "dh", source)
        jname = check_name(row["name"], f"row {i}: name", "dh", source)
        where = f"joint '{jname}'"
        unknown = [k for k in row if k not in ROW_KEYS]
        if unknown:
            raise ModelError(
                f"unknown key(s) {', '.join(map(shown, unknown))} (expected {', '.join(ROW_KEYS)})", where, source
            )
        jtype = row.get("type")
        if jtype not in ("revolute", "prismatic"):
            raise ModelError(
                f"unknown joint type {shown(jtype)} in a DH table (expected revolute or prismatic)", where, source
            )
        link = check_name(row.get("link", f"link{i}"), "link", where, source)
        values = {k: parse_expression(row.get(k, 0), params, where, source, k) for k in ("a", "alpha", "d", "theta")}
        mass, com, inertia = parse_inertials(row, params, f"link '{link}'", source)
        extras = parse_joint_extras(row, params, where, source)
        parsed.append(_Row(jname, jtype, link, values, mass, com, inertia, extras))

    links = [Link(base)]
    joints = []
    parent = base
    for i, row in enumerate(parsed):
        v, com, inertia = row.dh, row.com, row.inertia
        if convention == "modified-dh":
            # this row holds alpha_{i-1}, a_{i-1}: the placement is the row itself
            a, alpha = v["a"], v["alpha"]
        elif i == 0:
            a, alpha = 0, 0
        else:
            # standard: the previous row's Tx(a) Rx(alpha) sits between the joints
            a, alpha = parsed[i - 1].dh["a"], parsed[i - 1].dh["alpha"]
        rotation, xyz = _placement(a, alpha, v["theta"], v["d"])
        if convention == "standard-dh":
            # DH frame i = link frame i * Tx(a_i) Rx(alpha_i): move the data given in it
            r_alpha = rot_x(v["alpha"])
            com = sp.Matrix([v["a"], 0, 0]) + r_alpha * com
            inertia = r_alpha * inertia * r_alpha.T
        joints.append(Joint(row.joint, row.type, parent, row.link, xyz, rotation, sp.Matrix([0, 0, 1]), **row.extras))
        links.append(Link(row.link, row.mass, com, inertia))
        parent = row.link

    if convention == "standard-dh":
        last = parsed[-1].dh
        if not (is_zero(last["a"]) and is_zero(last["alpha"])):
            links.append(Link("flange"))
            joints.append(
                Joint("flange", "fixed", parent, "flange", sp.Matrix([last["a"], 0, 0]), rot_x(last["alpha"]))
            )

    info = dict(meta or {})
    info["convention"] = convention
    info["frames"] = FRAMES_NOTE[convention]
    info["dh_table"] = [{"joint": row.joint, "type": row.type, "link": row.link, **row.dh} for row in parsed]
    try:
        return Robot(name, links, joints, gravity, params, info, base, defaults, strict=strict)
    except ModelError as err:
        raise err.located(source=source)


__all__ = ["from_dh", "ROW_KEYS", "CONVENTIONS"]
