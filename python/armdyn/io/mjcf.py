"""MuJoCo MJCF reader: ``load_mjcf(path_or_xml, strict=True, floating=None) -> Robot``.

What is read (the part of MJCF that fixes a fixed-base arm's rigid-body dynamics):

* ``<worldbody>``'s body tree. A body's frame is its ``pos`` and orientation (``quat``,
  ``axisangle``, ``euler``, ``xyaxes`` or ``zaxis``: at most one) in its parent's frame;
  ``<frame>`` elements (which MuJoCo itself writes) move what they hold. Angles follow
  ``<compiler angle>`` (``degree`` unless it says ``radian``, as in MuJoCo) and
  ``eulerseq`` (default ``xyz``; lower case: moving axes, upper case: fixed axes).
* ``<joint>`` of type ``hinge`` (revolute) or ``slide`` (prismatic): ``axis`` (in the
  body frame, default z, normalised), ``pos`` (a point of the axis, in the body frame),
  ``ref`` (the joint value of the body's pose as written: MuJoCo's ``qpos0``, folded into
  the placement so armdyn's q equals MuJoCo's qpos), ``range`` (kept as the limits; no
  effect on dynamics). ``damping`` becomes the joint's viscous ``damping`` Fv and
  ``armature`` its ``armature`` Ia, both exactly as MuJoCo applies them (Ia on M's
  diagonal, Fv qd in the torque); ``frictionloss`` becomes the Coulomb ``friction`` Fc
  (MuJoCo enforces it as a soft constraint that may hold the joint below Fc; armdyn adds
  ``Fc sign(qd)``). ``stiffness`` (a joint spring) has no counterpart and is reported as
  ignored. Several joints in one body act in order, each about its axis in the frame the
  previous ones moved: they become a chain through massless intermediate links named
  ``<body>_<joint>``, listed in ``robot.meta["intermediate_links"]``. A body without a
  joint is welded to its parent (a fixed joint ``<body>_fixed``).
* A ``free`` joint (``<freejoint/>`` or ``<joint type="free"/>``) of a body of the world
  body makes that body the floating base (``root_joint="free-flyer"``) when it is the one
  free body and no other body of the world body has a joint; otherwise (several free
  bodies, a free object beside a fixed arm) each free body hangs from the world on a
  ``floating`` joint. A ``ball`` joint is a ``spherical`` joint (its damping, armature
  and frictionloss on each of its three velocities, as MuJoCo's). See
  :mod:`armdyn.io.mjcf_free` for both (what is checked, refused or ignored) and
  :mod:`armdyn.io.mjcf_state` for MuJoCo's ``qpos``/``qvel`` layout against armdyn's.
  ``floating="weld"`` reads every free body as welded at its pose instead. A free joint
  anywhere else is refused (MuJoCo refuses it too).
* ``<inertial pos mass diaginertia|fullinertia>`` (with an orientation for
  ``diaginertia``). A body without one gets MuJoCo's inertia from its geoms
  (``<compiler inertiafromgeom>``: ``auto`` by default; ``true`` always; ``false``
  never): spheres, capsules, cylinders, boxes and ellipsoids (``size`` or ``fromto``) of
  uniform ``density`` (default 1000) or given ``mass``, in the groups of
  ``inertiagrouprange`` (default 0 5); any other geom there is an error naming the body.
  A box or ellipsoid given by ``fromto`` has ``size[0]`` as both half-widths (as MuJoCo).
  A body with neither is massless: listed in ``robot.meta["massless_links"]`` and warned.
* ``<default>`` classes (nested, ``class=``, ``childclass=``) for joint and geom
  attributes; ``<include file>`` (relative to the main file's directory, as in MuJoCo;
  each file once, at most 16 deep, a loop refused); ``<option gravity>`` (default
  ``0 0 -9.81``; ``<flag gravity="disable">`` makes it zero).

Everything else that MJCF describes is not rigid-body dynamics (contacts, tendons,
actuators, sensors, equality constraints, assets, sites, cameras, lights, visual and
keyframes, the geoms of bodies that have an ``<inertial>``): it is read and listed in
one :class:`MjcfIgnoredWarning` and ``robot.meta["ignored"]``, never dropped silently.
Elements that would change the body tree (``composite``, ``flexcomp``, ``replicate``,
``attach``, ``plugin``), compiler options that change masses (``boundmass``,
``boundinertia``, ``settotalmass``, ``balanceinertia``), a joint's ``springdamper`` and a
damping polynomial past its linear term are refused; so is an attribute MJCF does not
define (MuJoCo refuses it too: a misspelt ``dampng`` is not a silently absent damping).

Safety: the XML is read with expat without a DTD (no entities: see
:func:`armdyn.io.urdf.refuse_dtd`); files through :mod:`armdyn.io.textfile`, all of them
together at most ``MODEL_MAX_BYTES``; the tree is walked without recursion. Every problem
is one :class:`ModelError` ``"file:line: <element name='...'>: message"``.
"""

from __future__ import annotations

import math
import os
import warnings
import xml.etree.ElementTree as ET
from collections import Counter
from pathlib import Path

import numpy as np

from ..errors import ModelError
from ..model import Joint, Link, Numbers, Robot, exact_number
from .expressions import check_name
from .mjcf_free import ball_joint_dynamics, base_pose, floating_tree, free_joint
from .mjcf_inertia import ORIENTATIONS, geom, inertial
from .mjcf_math import (
    axis_angle_quat,
    combine,
    euler_quat,
    quat_matrix,
    xyaxes_matrix,
    zaxis_quat,
)
from .mjcf_xml import MjcfDocument, clip
from .textfile import MODEL_MAX_BYTES, read_bytes

__all__ = ["load_mjcf", "MjcfIgnoredWarning"]

MAX_DEFAULT_DEPTH = 100
WORLD = "world"

#: top-level sections that hold no rigid-body dynamics
IGNORED_SECTIONS = {"visual", "statistic", "asset", "contact", "tendon", "actuator", "sensor", "equality"}
IGNORED_SECTIONS |= {"keyframe", "custom", "size", "extension"}
#: body children that hold no rigid-body dynamics
IGNORED_IN_BODY = {"site", "camera", "light"}
#: elements that would change the body tree, which this reader does not expand
REFUSED = {"composite", "flexcomp", "replicate", "attach", "plugin", "deformable", "skin", "flex"}
#: default-class children other than joint and geom (none of them dynamics)
IGNORED_DEFAULTS = {"site", "camera", "light", "mesh", "material", "pair", "equality", "tendon", "general"}
IGNORED_DEFAULTS |= {"motor", "position", "velocity", "intvelocity", "damper", "cylinder", "adhesion", "muscle"}
#: compiler options that change masses or inertias: refused when set
MASS_OPTIONS = {"boundmass": "0", "boundinertia": "0", "settotalmass": "-1", "balanceinertia": "false"}


class MjcfIgnoredWarning(UserWarning):
    """Elements of an MJCF file that are not rigid-body dynamics, read and not used."""


def load_mjcf(path_or_xml, strict: bool = True, floating: str | None = None) -> Robot:
    """Read an MJCF file (a path) or MJCF text (a string holding ``<`` or a line break).

    Returns a numeric :class:`Robot` whose base is the world body (link ``"world"``),
    its coordinates in MuJoCo's order (depth-first through the bodies as written): with
    hinge and slide joints only, q is MuJoCo's ``qpos``. With a free root body the robot
    floats, its base that body; floating base, free bodies and ball joints have their
    arrays in Pinocchio's layout (:mod:`armdyn.io.mjcf_state` converts). Unnamed joints
    and bodies are called ``joint_<n>``, ``body_<n>``.
    ``strict=False`` loads physically invalid inertias with a warning instead of an error.
    ``floating="weld"``: a ``free`` joint of a body of the world body is read as a fixed
    base (the body welded at its pose); without it that body floats.
    ``robot.meta``: ``convention`` ("mjcf"), ``file``, ``ignored`` (what was not used),
    ``massless_links``, ``intermediate_links``, ``mujoco_joints`` (the movable joints in
    MuJoCo's order) and, floating, ``base_pose`` (the body's pose as written, MuJoCo's
    ``qpos0``: position and quaternion ``w x y z``); with free bodies on floating joints,
    ``free_poses`` (the same, per floating joint's name).
    """
    if floating not in (None, "weld"):
        raise ModelError(f"floating={floating!r}: the one option is floating='weld'")
    if isinstance(path_or_xml, bytes):
        text, source, directory = path_or_xml, "<mjcf>", None
    elif isinstance(path_or_xml, str) and any(c in path_or_xml for c in "<\n\r"):
        text, source, directory = path_or_xml.encode("utf-8", "surrogatepass"), "<mjcf>", None
    elif isinstance(path_or_xml, (str, os.PathLike)):
        source = os.fspath(path_or_xml)
        text, directory = read_bytes(source, "model", MODEL_MAX_BYTES), Path(source).parent
    else:
        raise ModelError(f"expected a file path or MJCF text, got {type(path_or_xml).__name__}")
    return _Reader(source, directory, strict, floating).robot(text)


class _Reader(MjcfDocument):
    """One reading of an MJCF document and its includes: the body tree to a Robot."""

    def __init__(self, source: str, directory: Path | None, strict: bool, floating: str | None):
        super().__init__(source, directory)
        self.strict, self.floating = strict, floating
        self.ignored: Counter[str] = Counter()
        self.classes: dict[str, dict[str, dict[str, str]]] = {}
        self.names: set[str] = {WORLD}
        self.joint_names: set[str] = set()
        self.links: list[Link] = [Link(WORLD)]
        self.joints: list[Joint] = []
        self.massless: list[str] = []
        self.intermediate: list[str] = []
        self.base: str | None = None  # the floating base's body, once read
        self.base_pose: tuple = ()
        self.free_joints = False  # free bodies on floating joints from the world (mjcf_free)
        self.free_poses: dict[str, tuple] = {}

    def rotation(self, elem, attrs) -> np.ndarray:
        """The orientation ``attrs`` give (identity when none)."""
        given = [k for k in ORIENTATIONS if k in attrs]
        if len(given) > 1:
            raise self.error(elem, f"more than one orientation ({', '.join(given)}): at most one may be given")
        if not given:
            return np.eye(3)
        key = given[0]
        sizes = {"quat": 4, "axisangle": 4, "euler": 3, "xyaxes": 6, "zaxis": 3}
        v = self.numbers(elem, attrs, key, sizes[key])
        if key == "euler":
            return quat_matrix(euler_quat(v * self.unit, self.eulerseq))
        if key == "xyaxes":
            matrix = xyaxes_matrix(v[:3], v[3:])
            if matrix is None:
                raise self.error(elem, "xyaxes: x is zero or y is parallel to x")
            return matrix
        vector = {"quat": v, "axisangle": v[:3], "zaxis": v}[key]
        if np.linalg.norm(vector) < 1e-10:
            raise self.error(elem, f"{key} {'axis ' if key == 'axisangle' else ''}is zero")
        if key == "quat":
            return quat_matrix(v)
        if key == "zaxis":
            return quat_matrix(zaxis_quat(v))
        return quat_matrix(axis_angle_quat(v[:3], v[3] * self.unit))

    def pose(self, elem, attrs) -> tuple[np.ndarray, np.ndarray]:
        return self.rotation(elem, attrs), self.numbers(elem, attrs, "pos", 3, [0, 0, 0])

    # ----------------------------------------------------- compiler, option

    def compiler(self, root: ET.Element) -> None:
        self.unit, self.eulerseq, self.fromgeom, self.groups = math.pi / 180, "xyz", "auto", (0, 5)
        for elem in root.findall("compiler"):
            attrs = elem.attrib
            if "angle" in attrs:
                if attrs["angle"] not in ("degree", "radian"):
                    raise self.error(elem, f"angle is {clip(attrs['angle'])!r}, expected 'degree' or 'radian'")
                self.unit = math.pi / 180 if attrs["angle"] == "degree" else 1.0
            if "eulerseq" in attrs:
                seq = attrs["eulerseq"]
                if len(seq) != 3 or any(c not in "xyzXYZ" for c in seq):
                    raise self.error(elem, f"eulerseq is {clip(seq)!r}: expected three of x y z X Y Z")
                self.eulerseq = seq
            if "inertiafromgeom" in attrs:
                if attrs["inertiafromgeom"] not in ("auto", "true", "false"):
                    raise self.error(elem, "inertiafromgeom must be 'auto', 'true' or 'false'")
                self.fromgeom = attrs["inertiafromgeom"]
            if "inertiagrouprange" in attrs:
                low, high = self.numbers(elem, attrs, "inertiagrouprange", 2)
                self.groups = (low, high)
            if attrs.get("coordinate", "local") != "local":
                raise self.error(elem, "coordinate='global' is not supported (MuJoCo dropped it too)")
            for key, neutral in MASS_OPTIONS.items():
                if key in attrs and attrs[key].strip() not in (neutral, neutral + ".0"):
                    raise self.error(elem, f"{key} (which changes the masses MuJoCo compiles) is not supported")

    def gravity(self, root: ET.Element) -> np.ndarray:
        gravity = np.array([0.0, 0.0, -9.81])
        for elem in root.findall("option"):
            gravity = self.numbers(elem, elem.attrib, "gravity", 3, gravity)
            for key in sorted(set(elem.attrib) - {"gravity"}):
                self.ignored[f"<option {key}>"] += 1
            for child in elem:
                if child.tag != "flag":
                    self.ignored[f"<option><{child.tag}>"] += 1
                    continue
                for key, value in sorted(child.attrib.items()):
                    if key == "gravity" and value == "disable":
                        gravity = np.zeros(3)
                    elif key != "gravity":
                        self.ignored[f"<flag {key}>"] += 1
        return gravity

    # -------------------------------------------------------------- defaults

    def defaults(self, root: ET.Element) -> None:
        self.classes["main"] = {}
        stack = [(elem, None, 0) for elem in reversed(root.findall("default"))]
        while stack:
            elem, parent, depth = stack.pop()
            name = elem.get("class", "main" if parent is None else None)
            if not name:
                raise self.error(elem, "a nested <default> needs a 'class'")
            if depth > MAX_DEFAULT_DEPTH:
                raise self.error(elem, f"default classes nested deeper than {MAX_DEFAULT_DEPTH}")
            if parent is not None and name in self.classes or parent is None and self.classes["main"]:
                raise self.error(elem, f"default class '{clip(name)}' is defined twice")
            merged = {tag: dict(values) for tag, values in self.classes.get(parent or "", {}).items()}
            for child in elem:
                if child.tag == "default":
                    stack.append((child, name, depth + 1))
                elif child.tag in ("joint", "geom"):
                    self.check_attributes(child)
                    own = {k: v for k, v in child.attrib.items() if k != "class"}
                    if child.tag == "geom" and set(own) & set(ORIENTATIONS):  # the latest orientation wins
                        merged.setdefault("geom", {}).update(dict.fromkeys(ORIENTATIONS))
                    merged.setdefault(child.tag, {}).update(own)
                elif child.tag == "inertial":
                    raise self.error(child, "MJCF has no inertial defaults (MuJoCo refuses them too)")
                elif child.tag in IGNORED_DEFAULTS:
                    self.ignored[f"<default><{child.tag}>"] += 1
                else:
                    raise self.error(child, f"unknown element <{child.tag}> in <default>")
            self.classes[name] = {t: {k: v for k, v in d.items() if v is not None} for t, d in merged.items()}

    def attrs(self, elem: ET.Element, childclass: str) -> dict[str, str]:
        """The element's attributes over those of its class (its own, else the
        ``childclass`` in force, else ``main``)."""
        name = elem.get("class", childclass)
        if name not in self.classes:
            raise self.error(elem, f"unknown default class '{clip(name)}'")
        self.check_attributes(elem)
        out = dict(self.classes[name].get(elem.tag, {}))
        own = {k: v for k, v in elem.attrib.items() if k != "class"}
        if set(own) & set(ORIENTATIONS) or "fromto" in own:
            for key in ORIENTATIONS:
                out.pop(key, None)
        out.update(own)
        return out

    def childclass(self, elem: ET.Element, inherited: str) -> str:
        name = elem.get("childclass", inherited)
        if name not in self.classes:
            raise self.error(elem, f"unknown default class '{clip(name)}'")
        return name

    # ---------------------------------------------------------------- names

    def unique(self, wanted: str, used: set[str]) -> str:
        """``wanted``, or with ``_`` appended until it is neither used nor a name the file
        gives (so a made-up name never takes one the file uses further on)."""
        name = wanted
        while name in used or name in self.given:
            name += "_"
        used.add(name)
        return name

    def name(self, elem: ET.Element, used: set[str], fallback: str) -> str:
        given = elem.get("name")
        if given is None:
            return self.unique(fallback, used)
        try:
            name = check_name(given, "name", None)
        except ModelError as err:
            raise self.error(elem, err.message) from None
        if name in used:
            raise self.error(elem, f"the name '{clip(name)}' is used twice")
        used.add(name)
        return name

    # ------------------------------------------------------------------ tree

    def robot(self, text: bytes) -> Robot:
        root = self.parse(text, self.source)
        self.expand_includes(root)
        self.given = {e.get("name") for e in root.iter() if e.tag in ("body", "joint", "freejoint")}
        self.compiler(root)
        gravity = self.gravity(root)
        self.defaults(root)
        known = {"compiler", "option", "default", "worldbody"}
        for elem in root:
            if elem.tag in IGNORED_SECTIONS:
                self.ignored[f"<{elem.tag}>"] += 1
            elif elem.tag in REFUSED:
                raise self.error(elem, f"<{elem.tag}> is not supported")
            elif elem.tag not in known:
                raise self.error(elem, f"unknown element <{elem.tag}> in <mujoco>")
        bodies: list = []
        for world in root.findall("worldbody"):
            bodies += self.contents(world, WORLD, np.eye(3), np.zeros(3), "main", world=True)[2]
        if self.floating is None:
            bodies = floating_tree(self, root, bodies)
        stack = list(reversed(bodies))
        count = 0
        while stack:
            elem, parent, R0, p0, cls = stack.pop()
            count += 1
            children = self.body(elem, parent, R0, p0, cls, count)
            stack += reversed(children)
        meta = {
            "convention": "mjcf",
            "ignored": tuple(f"{k} x{n}" if n > 1 else k for k, n in sorted(self.ignored.items())),
            "massless_links": self.massless,
            "intermediate_links": self.intermediate,
            "mujoco_joints": [j.name for j in self.joints if j.type != "fixed"],
        }
        if self.base is not None:
            del self.links[0]  # the world: the floating base's joint is the free-flyer
            meta["base_pose"] = self.base_pose
        if self.free_poses:
            meta["free_poses"] = self.free_poses
        if self.directory is not None:
            meta["file"] = self.source
        name = root.get("model") or (Path(self.source).stem if self.directory is not None else "mjcf")
        try:
            name = check_name(name, "model", "<mujoco>")
            robot = Robot(
                name,
                self.links,
                self.joints,
                [exact_number(g) for g in gravity],
                meta=meta,
                base=self.base or WORLD,
                strict=self.strict,
                root_joint=None if self.base is None else "free-flyer",
            )
        except ModelError as err:
            raise err.located(source=self.source)
        if self.ignored:
            warnings.warn(
                f"{self.source}: ignored (not rigid-body dynamics): {', '.join(meta['ignored'])}",
                MjcfIgnoredWarning,
                stacklevel=3,
            )
        if self.massless:
            warnings.warn(
                f"{self.source}: bodies without <inertial> or geoms to infer it from are massless: {self.massless}",
                UserWarning,
                stacklevel=3,
            )
        return robot

    def contents(self, elem, link, R0, p0, cls, world=False):
        """What a body (or the world) holds, through its ``<frame>``s: ``(joints,
        geoms, bodies)``; geoms and bodies with the pose of the frame they sit in."""
        joints, geoms, bodies, inertials = [], [], [], []
        stack = [(child, R0, p0, cls, False) for child in reversed(elem)]
        while stack:
            child, R, p, klass, in_frame = stack.pop()
            tag = child.tag
            if tag == "body":
                bodies.append((child, link, R, p, klass))
            elif tag == "frame":
                self.check_attributes(child)
                Rf, pf = self.pose(child, child.attrib)
                inner = self.childclass(child, klass)
                stack += [(c, R @ Rf, p + R @ pf, inner, True) for c in reversed(child)]
            elif tag == "geom":
                geoms.append((child, R, p, klass))
            elif tag in ("joint", "freejoint", "inertial"):
                if world:
                    raise self.error(child, f"<{tag}> cannot be in the world body")
                # in a <frame>, its pos and axis are in the frame's axes (MuJoCo 3.2 on)
                (inertials if tag == "inertial" else joints).append((child, klass, R, p))
            elif tag in IGNORED_IN_BODY:
                self.ignored[f"<{tag}>"] += 1
            elif tag in REFUSED:
                raise self.error(child, f"<{tag}> is not supported")
            else:
                raise self.error(child, f"unknown element <{tag}> in <{elem.tag}>")
        if world:
            self.ignored["<geom> of the world body"] += len(geoms)
            if not geoms:
                del self.ignored["<geom> of the world body"]
        return joints, geoms, bodies, inertials

    def body(self, elem, parent, R0, p0, inherited, number) -> list:
        """Read one body: its link and joints; returns its child bodies."""
        self.check_attributes(elem)
        cls = self.childclass(elem, inherited)
        name = self.name(elem, self.names, f"body_{number}")
        Rb, pb = self.pose(elem, elem.attrib)
        Rb, pb = R0 @ Rb, p0 + R0 @ pb
        for key in ("gravcomp",):
            if float(self.number(elem, elem.attrib, key, 0.0)) != 0:
                self.ignored[f"body {key}"] += 1
        joints, geoms, bodies, inertials = self.contents(elem, name, np.eye(3), np.zeros(3), cls)
        if len(inertials) > 1:
            raise self.error(inertials[1][0], "more than one <inertial> in the body")
        read = self.body_joints(elem, name, parent, Rb, pb, joints)
        if read is None:  # the floating base: its pose is its free joint's coordinates
            self.base, self.base_pose = name, base_pose(Rb, pb)
        self.joints += read or []
        self.links.append(self.link(elem, name, inertials, geoms))
        return bodies

    def body_joints(self, elem, name, parent, Rb, pb, joints) -> list[Joint] | None:
        """The joints from ``parent`` to body ``name`` at pose ``(Rb, pb)``; None for the
        floating base (a free joint, see :func:`floating_tree`)."""
        read = [(j, self.attrs(j, cls) if j.tag == "joint" else self.free_attrs(j), R, p) for j, cls, R, p in joints]
        for j, attrs, _, _ in read:
            kind = "free" if j.tag == "freejoint" else attrs.get("type", "hinge")
            if kind == "free":
                free_joint(self, j, attrs, parent == WORLD, len(read))
                if self.floating != "weld" and not self.free_joints:
                    return None
                if self.floating != "weld":  # a free body beside others: a floating joint from the world
                    jname = self.name(j, self.joint_names, f"joint_{len(self.joint_names) + 1}")
                    self.free_poses[jname] = base_pose(Rb, pb)
                    return [self.joint(j, jname, "floating", parent, name, np.zeros(3), np.eye(3), {})]
                self.ignored["free joint read as a fixed base (floating='weld')"] += 1
                read = []
            elif kind not in ("hinge", "slide", "ball"):
                raise self.error(j, f"unknown joint type '{clip(kind)}' (expected hinge, slide, ball or free)")
        if not read:
            fixed = self.unique(f"{name}_fixed", self.joint_names)
            return [self.joint(elem, fixed, "fixed", parent, name, pb, Rb, {})]
        out, previous = [], parent
        for k, (j, attrs, Rf, pf) in enumerate(read):
            jname = self.name(j, self.joint_names, f"joint_{len(self.joint_names) + 1}")
            kind = attrs.get("type", "hinge")
            point = pf + Rf @ self.numbers(j, attrs, "pos", 3, [0, 0, 0])
            if kind == "ball":  # turns the body frame about the point (see mjcf_free)
                R, shift, extra, kind = np.eye(3), point, ball_joint_dynamics(self, j, attrs), "spherical"
            else:
                R, shift, extra = self.axis_joint(j, attrs, kind == "hinge", Rf, point)
                kind = "revolute" if kind == "hinge" else "prismatic"
            R, xyz = (Rb @ R, pb + Rb @ shift) if k == 0 else (R, shift)
            child = name if k == len(read) - 1 else self.unique(f"{name}_{jname}", self.names)
            if child != name:
                self.links.append(Link(child))
                self.intermediate.append(child)
            extra["frame_xyz"] = Numbers(-point)
            out.append(self.joint(j, jname, kind, previous, child, xyz, R, extra))
            previous = child
        return out

    def axis_joint(self, j, attrs, hinge: bool, Rf, point) -> tuple[np.ndarray, np.ndarray, dict]:
        """A hinge's or slide's ``(R, shift, extra)``: the placement's turn and origin in
        the body frame, its axis and joint dynamics."""
        axis = self.numbers(j, attrs, "axis", 3, [0, 0, 1])
        if np.linalg.norm(axis) < 1e-10:
            raise self.error(j, "axis is zero")
        axis = Rf @ axis / np.linalg.norm(axis)
        ref = self.number(j, attrs, "ref", 0.0) * (self.unit if hinge else 1.0)
        # the body is drawn at q = ref: fold the turn (shift) by -ref into the placement
        R = quat_matrix(axis_angle_quat(axis, -ref)) if hinge else np.eye(3)
        shift = point if hinge else point - axis * ref
        return R, shift, {"axis": Numbers(axis), **self.joint_dynamics(j, attrs, hinge)}

    def free_attrs(self, elem) -> dict[str, str]:
        self.check_attributes(elem)
        return dict(elem.attrib, type="free")

    def joint_dynamics(self, j, attrs, hinge) -> dict:
        out = {}
        if np.any(self.numbers(j, attrs, "springdamper", 2, [0, 0])):
            raise self.error(j, "springdamper (a spring and damper MuJoCo sizes from the masses) is not supported")
        # damping and stiffness may be polynomials (MuJoCo 4): armdyn's damping is linear
        damping = self.numbers(j, attrs, "damping", 3, [0], at_least=1)
        if np.any(damping[1:]):
            raise self.error(j, f"damping {damping.tolist()}: a nonlinear damping polynomial is not supported")
        for mine, theirs in (("damping", "damping"), ("armature", "armature"), ("friction", "frictionloss")):
            value = float(damping[0]) if theirs == "damping" else self.number(j, attrs, theirs, 0.0)
            if value < 0:
                raise self.error(j, f"{theirs} {value} is negative")
            if value:
                out[mine] = Numbers(value)
        if np.any(self.numbers(j, attrs, "stiffness", 3, [0], at_least=1)):
            self.ignored["joint stiffness (springs are not modelled)"] += 1
        limits = self.numbers(j, attrs, "range", 2)
        if limits is not None and limits[0] < limits[1] and attrs.get("limited", "auto") != "false":
            limits = limits * (self.unit if hinge else 1.0)
            out.update(lower=Numbers(limits[0]), upper=Numbers(limits[1]))
        return out

    def joint(self, elem, name, kind, parent, child, xyz, R, extra) -> Joint:
        try:
            return Joint(name, kind, parent, child, xyz=Numbers(xyz), rotation=Numbers(R), **extra)
        except ModelError as err:
            raise self.error(elem, err.message) from None

    # ---------------------------------------------------------------- inertia

    def link(self, elem, name, inertials, geoms) -> Link:
        if inertials and self.fromgeom != "true":
            mass, com, inertia = inertial(self, *inertials[0])
            self.ignored["<geom> (contact and visual shapes)"] += len(geoms)
        elif self.fromgeom != "false" and geoms:
            if inertials:
                self.ignored["<inertial> (inertiafromgeom='true')"] += 1
            parts = [geom(self, g, R, p, cls, name) for g, R, p, cls in geoms]
            mass, com, inertia = combine([part for part in parts if part is not None])
        else:
            mass, com, inertia = 0.0, np.zeros(3), np.zeros((3, 3))
            self.ignored["<geom> (contact and visual shapes)"] += len(geoms)
        if not self.ignored["<geom> (contact and visual shapes)"]:
            del self.ignored["<geom> (contact and visual shapes)"]
        if mass == 0 and not inertials:
            self.massless.append(name)
        try:
            return Link(name, Numbers(mass), Numbers(com), Numbers((inertia + inertia.T) / 2))
        except ModelError as err:
            raise self.error(elem, err.message) from None
