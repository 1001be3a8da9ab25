"""The robot: links and joints in tree order, gravity, named parameters; immutable once built."""

from __future__ import annotations

import math
from dataclasses import replace
from typing import Iterable, Mapping

import numpy as np
import sympy as sp

from ..dispatch import call
from ..errors import FloatingBaseError, ModelError
from ..inertia import check_physical, physical_violations
from .frozen import FreezeAfterInit, FrozenDict, FrozenList
from .joints import JOINT_DYNAMICS, MULTI_DOF, Joint, Link, coordinate_symbols
from .numbers import Numbers, mat3, vec3
from .tree import resolve_mimics, tree_order

_CACHES = ("_numeric_model", "_canonical")


#: The root joints a robot's base may have: None (the base is fixed in the world) or
#: ``"free-flyer"`` (the base floats: Pinocchio's JointModelFreeFlyer at the root).
ROOT_JOINTS = (None, "free-flyer")


#: what runs on a floating base and on joints of several coordinates, named by the refusals
#: of what does not (yet)
NUMERIC_EVERYWHERE = (
    "armdyn.numeric's rnea, crba, aba, gravity, bias, their derivatives, minverse, forward_kinematics, "
    "jacobian, jacobian_dot, coriolis_matrix, regressor and the energies, and armdyn.centroidal"
)


class Robot(metaclass=FreezeAfterInit):
    """A robot: links and joints in tree order, and gravity; its base fixed in the world,
    or floating (``root_joint="free-flyer"``).

    Immutable once constructed: setting a public attribute raises AttributeError and
    its lists and dicts (``joints``, ``links``, ``parameters``, ...) refuse changes,
    so the compiled numeric model cached on it (:func:`armdyn.numeric.compile_model`)
    always describes it. Build a changed robot with :meth:`bind`, :meth:`subs` or
    ``Robot(...)``. (``copy.copy(robot)`` gives a thawed copy for ``with_*`` style
    constructors: its attributes may be set, and each set drops its cached model.)
    ``meta`` stays an ordinary dict: it describes the model and is never compiled.

    Attributes
    ----------
    name:        the robot's name.
    base:        name of the base link (the root: fixed in the world, or floating).
    root_joint:  None (a fixed base) or ``"free-flyer"``: the base is a free rigid body
                 (6 more coordinates, Pinocchio's layout; see :attr:`floating`). The
                 joints of a floating robot are then in the order Pinocchio's URDF
                 parser gives them: depth first from the base, siblings by joint name.
    links:       dict name -> :class:`Link`, base first, then each joint's child in order.
    joints:      list of :class:`Joint` in tree order (fixed ones included).
    gravity:     (3, 1) gravity vector in the base frame (m/s^2).
    parameters:  dict name -> sympy Symbol of the model's named parameters.
    defaults:    dict name -> number: the model file's published values of its parameters
                 (may be empty or partial); ``bind()`` with no argument uses them.
    meta:        free-form description (source, convention, ...).
    strict:      True (default): a link whose mass/inertia is not physical (mass < 0,
                 inertia not symmetric or not positive semi-definite, principal moments
                 breaking the triangle inequality) is a ModelError; False: a warning.
                 Symbolic values are checked once bound.

    Derived:
    movable_joints: the non-fixed joints, in order; ``dof`` is their number.
    floating:       whether the base floats (``root_joint == "free-flyer"``).
    nq, nv:         the lengths of the numeric configuration and velocity arrays
                    (:mod:`armdyn.numeric`): ``dof`` and ``dof`` for a fixed base;
                    ``7 + dof`` (base position, quaternion x y z w, joints) and ``6 + dof``
                    (base linear and angular velocity in the base frame, joints) for a
                    floating one.
    q, qd, qdd:     (dof, 1) symbol vectors named after the movable joints.
    """

    def __setattr__(self, name, value):
        if self.__dict__.get("_frozen") and not name.startswith("_"):
            raise AttributeError(
                f"Robot is immutable: cannot set '{name}' (build a new robot with bind(), subs() or Robot(...))"
            )
        if not name.startswith("_"):  # a thawed copy changing: its compiled model is stale
            for cache in _CACHES:
                self.__dict__.pop(cache, None)
        object.__setattr__(self, name, value)

    def __delattr__(self, name):
        if self.__dict__.get("_frozen") and not name.startswith("_"):
            raise AttributeError(f"Robot is immutable: cannot delete '{name}'")
        for cache in _CACHES:
            self.__dict__.pop(cache, None)
        object.__delattr__(self, name)

    def __copy__(self):
        """A thawed shallow copy without the cached numeric model (see the class doc)."""
        new = object.__new__(type(self))
        state = {k: v for k, v in self.__dict__.items() if k not in ("_frozen", *_CACHES)}
        for k, v in state.items():  # plain containers, so that a with_* constructor may edit them
            if isinstance(v, FrozenList):
                state[k] = list(v)
            elif isinstance(v, FrozenDict):
                state[k] = dict(v)
        new.__dict__.update(state)
        return new

    def __deepcopy__(self, memo):
        if self.__dict__.get("_frozen"):
            return self  # immutable: a copy is the same robot
        import copy

        new = object.__new__(type(self))
        memo[id(self)] = new
        state = {k: v for k, v in self.__dict__.items() if k not in _CACHES}
        new.__dict__.update(copy.deepcopy(state, memo))
        return new

    def __init__(
        self,
        name: str,
        links: Iterable[Link],
        joints: Iterable[Joint],
        gravity=(0, 0, -9.81),
        parameters: Mapping[str, sp.Symbol] | Iterable[sp.Symbol] | None = None,
        meta: Mapping | None = None,
        base: str | None = None,
        defaults: Mapping[str, float] | None = None,
        strict: bool = True,
        root_joint: str | None = None,
    ):
        self.name = name
        if root_joint not in ROOT_JOINTS:
            raise ModelError(
                f"root_joint={root_joint!r}: expected None (a fixed base) or 'free-flyer' (a floating base)",
                f"robot '{name}'",
            )
        self.root_joint = root_joint
        links = list(links)
        joints = list(joints)
        self.meta = dict(meta or {})  # "file" (if any) names the model file in messages
        try:
            self.gravity = vec3(gravity, "gravity")
        except ModelError as err:
            raise err.located(element=f"robot '{name}'")

        self.strict = strict
        # (link, problems) a bundled model is published with, reported once by armdyn.load:
        # not warned about again in every bound copy
        accepted = self.meta.get("nonphysical_accepted", ())
        self.links: dict[str, Link] = {}
        for link in links:
            if link.name in self.links:
                raise ModelError("duplicate link name", f"link '{link.name}'")
            # an error is located by the loader (which knows the line); a warning cannot be
            # located later, so it names the model file itself
            source = None if strict else self.meta.get("file")
            m, inertia = link.floats("mass"), link.floats("inertia")  # floats: no SymPy per link
            m, inertia = link.mass if m is None else m, link.inertia if inertia is None else inertia
            if not (accepted and not strict and (link.name, "; ".join(physical_violations(m, inertia))) in accepted):
                check_physical(m, inertia, f"link '{link.name}'", source, strict=strict)
            self.links[link.name] = link

        children = {j.child for j in joints}
        if base is None:
            roots = [ln.name for ln in links if ln.name not in children]
            if len(roots) != 1:
                raise ModelError(
                    f"expected exactly one root link (not the child of any joint), found {roots or 'none (a cycle?)'}",
                    f"robot '{name}'",
                )
            base = roots[0]
        self.base = base
        self.joints = tree_order(joints, self.links, self.base, self.name, self.root_joint)
        # links ordered base first, then children in joint order
        self.links = {base: self.links[base], **{j.child: self.links[j.child] for j in self.joints}}

        if isinstance(parameters, Mapping):
            self.parameters: dict[str, sp.Symbol] = dict(parameters)
        else:
            symbols: Iterable[sp.Symbol] = parameters or ()
            self.parameters = {s.name: s for s in symbols}
        self.defaults: dict[str, float] = dict(defaults or {})
        stray = set(self.defaults) - set(self.parameters)
        if stray:
            raise ModelError(f"default values given for unknown parameters {sorted(stray)}", f"robot '{name}'")

        # joints with a coordinate of their own; mimic joints move but follow a leader
        self.movable_joints = [j for j in self.joints if j.movable and j.mimic is None]
        self.mimic_joints = [j for j in self.joints if j.mimic is not None]
        # joints of several coordinates (spherical, planar, floating; Pinocchio's layouts)
        self.multi_dof_joints = [j for j in self.movable_joints if j.type in MULTI_DOF]
        self.dof = sum(j.nv for j in self.movable_joints)
        self.floating = root_joint == "free-flyer"
        base_q, base_v = (7, 6) if self.floating else (0, 0)
        self.nq = base_q + sum(j.nq for j in self.movable_joints)
        self.nv = base_v + self.dof
        self.coordinate_names = [c for j in self.movable_joints for c in j.coordinate_names]
        # (joint name, type, first index in q, first index in v) per movable joint
        layout, iq, iv = [], base_q, base_v
        for j in self.movable_joints:
            layout.append((j.name, j.type, iq, iv))
            iq, iv = iq + j.nq, iv + j.nv
        self.configuration_layout = tuple(layout)
        self.q, self.qd, self.qdd = coordinate_symbols(self.coordinate_names)
        clash = set(self.coordinate_names) & set(self.parameters)
        if clash:
            raise ModelError(f"names used both as joint and as parameter: {sorted(clash)}", f"robot '{name}'")
        self._link_index = {name: i for i, name in enumerate(self.links)}
        # index of each movable joint's coordinate, None for fixed joints
        coordinate = {n: i for i, n in enumerate(self.coordinate_names)}
        coordinate.update({j.name: coordinate[j.coordinate_names[0]] for j in self.multi_dof_joints})
        self._coord_index = {j.name: coordinate.get(j.name) if j.movable else None for j in self.joints}
        self._parent_joint = {j.child: j for j in self.joints}
        self._children: dict[str, list[Joint]] = {}
        for j in self.joints:
            self._children.setdefault(j.parent, []).append(j)
        self._follows = resolve_mimics(self.joints, self.movable_joints, self.mimic_joints, self._coord_index)
        self._check_defaults()
        # read-only from here on (the metaclass then freezes the attributes)
        self.joints = FrozenList(self.joints)
        self.movable_joints = FrozenList(self.movable_joints)
        self.mimic_joints = FrozenList(self.mimic_joints)
        self.multi_dof_joints = FrozenList(self.multi_dof_joints)
        self.coordinate_names = FrozenList(self.coordinate_names)
        self.links = FrozenDict(self.links)
        self.parameters = FrozenDict(self.parameters)
        self.defaults = FrozenDict(self.defaults)
        self.gravity = sp.ImmutableMatrix(self.gravity)

    def _check_defaults(self) -> None:
        """Published values must be finite real numbers (a NaN or inf default would only
        show up later, as NaN torques)."""
        for key, value in self.defaults.items():
            try:
                finite = not isinstance(value, bool) and math.isfinite(float(value))
            except (TypeError, ValueError, OverflowError):
                finite = False
            if not finite:
                raise ModelError(
                    f"the default value of parameter '{key}' is not a finite number: {value!r}", f"robot '{self.name}'"
                )

    # ------------------------------------------------------------------ queries
    def coordinate_index(self, joint: str | Joint) -> int | None:
        """Index of a joint's coordinate in ``q`` (None for a fixed joint, and for a
        mimic joint, which has none of its own: see :meth:`follows`)."""
        name = joint.name if isinstance(joint, Joint) else joint
        return self._coord_index[name]

    def link_index(self, link: str) -> int:
        """Frame number of a link: 0 for the base, then tree order (as in ``links``)."""
        return self._link_index[link]

    def joint_coordinate(self, joint: Joint):
        """The joint's coordinate: its symbol, ``multiplier * q_leader + offset`` for a
        mimic joint, 0 for a fixed joint."""
        f = self._follows.get(joint.name)
        if f is None:
            return sp.Integer(0)
        k, m, o = f
        if m is sp.S.One and o is sp.S.Zero:  # a joint's own coordinate: no SymPy arithmetic
            return self.q[k]
        return m * self.q[k] + o

    def follows(self, joint: str | Joint) -> tuple[int, sp.Expr, sp.Expr] | None:
        """``(k, multiplier, offset)``: the joint's own coordinate is
        ``multiplier * q[k] + offset``, its velocity and acceleration ``multiplier``
        times ``qd[k]``, ``qdd[k]``, and its torque (force) adds ``multiplier`` times
        itself to ``tau[k]``. ``(k, 1, 0)`` for a joint with coordinate k, the leader's
        (chains composed) for a mimic joint, None for a fixed joint."""
        return self._follows.get(joint.name if isinstance(joint, Joint) else joint)

    def parent_joint(self, link: str) -> Joint | None:
        return self._parent_joint.get(link)

    def children(self, link: str) -> list[Joint]:
        """The joints whose parent is ``link``, in tree order."""
        return list(self._children.get(link, ()))

    def free_symbols(self) -> set[sp.Symbol]:
        """Symbols the model's numbers depend on (the joint coordinates excluded)."""

        def free(obj, name):  # Numbers have none (and are not built into SymPy here)
            raw = obj.__dict__[name]  # None, Numbers or SymPy (sympify would copy a Matrix to ask it)
            return set() if raw is None or isinstance(raw, Numbers) else raw.free_symbols

        out: set = set(self.gravity.free_symbols)
        for link in self.links.values():
            out |= free(link, "mass") | free(link, "com") | free(link, "inertia")
        for j in self.joints:
            for name in ("xyz", "rotation", "axis", "frame_xyz", "frame_rotation"):
                out |= free(j, name)
            if j.mimic is not None:
                out |= j.mimic.multiplier.free_symbols | j.mimic.offset.free_symbols
            for name in JOINT_DYNAMICS:
                out |= free(j, name)
        return out

    def canonical(self) -> "Robot":
        """The same mechanism with every link frame on its joint (no ``frame`` offsets).

        Where a joint has an offset ``(Rf, pf)``, its child's inertial data are moved into
        the moved joint frame (``com' = Rf com + pf``, ``I' = Rf I Rf^T``) and the child's
        own joints are placed from there (``xyz' = pf + Rf xyz``, ``rotation' = Rf rotation``).
        The dynamics are unchanged (tau does not depend on where link frames sit); only the
        link frames differ. The numeric engines use this form. ``self`` if nothing moves.
        """
        cached = self.__dict__.get("_canonical")
        if cached is not None:
            return cached
        offsets = {j.child: (j.frame_rotation, j.frame_xyz) for j in self.joints if j.has_frame_offset}
        if not offsets:
            return self
        links = []
        for link in self.links.values():
            if link.name in offsets:
                Rf, pf = offsets[link.name]
                link = Link(link.name, link.mass, Rf * link.com + pf, Rf * link.inertia * Rf.T)
            links.append(link)
        joints = []
        for j in self.joints:
            changes = {"frame_xyz": sp.zeros(3, 1), "frame_rotation": sp.eye(3)}
            if j.parent in offsets:
                Rf, pf = offsets[j.parent]
                changes.update(xyz=pf + Rf * j.xyz, rotation=Rf * j.rotation)
            joints.append(replace(j, **changes))
        out = Robot(
            self.name,
            links,
            joints,
            self.gravity,
            self.parameters,
            self.meta,
            self.base,
            self.defaults,
            strict=self.strict,
            root_joint=self.root_joint,
        )
        self.__dict__["_canonical"] = out  # built once: the numeric engines and codegen share it
        return out

    @classmethod
    def from_urdf(cls, source, strict: bool = True) -> "Robot":
        """A robot from a URDF file path or XML string: :func:`armdyn.io.urdf.load_urdf`
        (registered with :mod:`armdyn.dispatch`; ``armdyn.load`` reads any format)."""
        return call("urdf", cls, source, strict=strict)

    @property
    def is_numeric(self) -> bool:
        return not self.free_symbols()

    # ----------------------------------------------------------- transformations
    def subs(self, values: Mapping) -> "Robot":
        """A copy with ``values`` (symbol or name -> number/expression) substituted."""
        table = {}
        for key, val in values.items():
            sym = self.parameters.get(key, sp.Symbol(key)) if isinstance(key, str) else key
            table[sym] = sp.sympify(val)
        if not table and self.__dict__.get("_frozen"):  # nothing to substitute: the same
            return self  # immutable robot (a big numeric URDF is not rebuilt in SymPy)

        def s(x):
            return None if x is None else sp.sympify(x).xreplace(table)

        links = [
            Link(ln.name, s(ln.mass), ln.com.xreplace(table), ln.inertia.xreplace(table)) for ln in self.links.values()
        ]
        joints = [
            replace(
                j,
                xyz=j.xyz.xreplace(table),
                rotation=j.rotation.xreplace(table),
                axis=j.axis.xreplace(table),
                frame_xyz=j.frame_xyz.xreplace(table),
                frame_rotation=j.frame_rotation.xreplace(table),
                **{k: s(getattr(j, k)) for k in ("lower", "upper", "velocity", "effort") + JOINT_DYNAMICS},
                mimic=None
                if j.mimic is None
                else replace(j.mimic, multiplier=s(j.mimic.multiplier), offset=s(j.mimic.offset)),
            )
            for j in self.joints
        ]
        remaining = {n: p for n, p in self.parameters.items() if p not in table}
        defaults = {n: v for n, v in self.defaults.items() if n in remaining}
        try:
            return Robot(
                self.name,
                links,
                joints,
                self.gravity.xreplace(table),
                remaining,
                self.meta,
                self.base,
                defaults,
                strict=self.strict,
                root_joint=self.root_joint,
            )
        except ModelError as err:  # e.g. a bound value that is not physical: name the model file
            raise err.located(source=self.meta.get("file")) from None

    def bind(self, values: Mapping | None = None) -> "Robot":
        """A copy with parameters bound to numbers.

        ``robot.bind()`` uses the model's ``defaults`` (its published values);
        ``robot.bind({"m1": 2.0})`` overrides some of them (keys: names or symbols).
        Unknown names are an error, so typos do not silently leave a parameter free.
        Parameters with neither a default nor a given value stay symbolic.
        """
        values = dict(values or {})
        unknown = [k for k in values if isinstance(k, str) and k not in self.parameters]
        if unknown:
            raise ModelError(
                f"unknown parameter(s) {unknown}; the model has {sorted(self.parameters)}",
                f"robot '{self.name}'",
            )
        given = {k if isinstance(k, str) else k.name for k in values}
        merged = {k: v for k, v in self.defaults.items() if k not in given}
        merged.update(values)
        return self.subs(merged)

    def with_payload(self, mass, com=(0, 0, 0), inertia=None, link: str | None = None) -> "Robot":
        """A new robot with a rigid load fixed to ``link`` (default: the last link in tree
        order, the tool of a serial arm). This robot is not changed.

        mass:    the payload's mass (kg), number or SymPy expression.
        com:     (3,) its centre of mass in ``link``'s frame (m).
        inertia: (3, 3) its inertia tensor about its own centre of mass, in ``link``'s
                 axes (kg m^2); default zero (a point mass).

        The link and the load become one body (:func:`armdyn.inertia.combine`: total
        mass, mass-weighted centre of mass, parallel axis theorem). A payload that is not
        physical (negative or non-finite mass, inertia not symmetric, not positive
        semi-definite or breaking the triangle inequality) is a ModelError naming it.
        """
        from ..inertia import Body, combine

        where = "payload"
        link = link if link is not None else list(self.links)[-1]
        if link not in self.links:
            raise ModelError(f"no link named {link!r} (links: {', '.join(self.links)})", where)
        if link == self.base:
            raise ModelError(f"the base link {link!r} does not move: a payload on it has no effect", where)
        try:
            mass = sp.sympify(mass)
            com = vec3(com, "com")
            inertia = sp.zeros(3, 3) if inertia is None else mat3(inertia, "inertia")
        except ModelError as err:
            raise err.located(element=where)
        except (sp.SympifyError, TypeError) as exc:
            raise ModelError(f"bad value ({exc})", where) from None
        for name, values in (("mass", [mass]), ("com", list(com)), ("inertia", list(inertia))):
            for v in values:
                if not v.free_symbols and not np.isfinite(complex(v.evalf())).all():
                    raise ModelError(f"{name} has a value that is not finite ({v})", where)
        check_physical(mass, inertia, where, strict=True)
        old = self.links[link]
        body = combine([Body(old.mass, old.com, old.inertia), Body(mass, com, inertia)])
        new = Link(old.name, sp.sympify(body.mass), sp.Matrix(body.com), sp.Matrix(body.inertia))
        links = [new if ln.name == link else ln for ln in self.links.values()]
        params = dict(self.parameters)
        for s in mass.free_symbols | com.free_symbols | inertia.free_symbols:
            params.setdefault(s.name, s)
        import warnings

        with warnings.catch_warnings():  # this robot's own links were warned about when it was built
            warnings.simplefilter("ignore")
            return Robot(
                self.name,
                links,
                self.joints,
                self.gravity,
                params,
                self.meta,
                self.base,
                self.defaults,
                strict=self.strict,
                root_joint=self.root_joint,
            )

    @property
    def joint_dynamics(self) -> tuple[str, ...]:
        """The joint-space terms (of ``damping``, ``friction``, ``armature``,
        ``torque_offset``) that some movable joint carries with a value other than 0:
        ``rnea``/``aba`` include them, a rigid-body library such as Pinocchio does not."""
        present = []
        for name in JOINT_DYNAMICS:
            for j in self.movable_joints:
                value = getattr(j, name)
                if value is not None and (value.free_symbols or float(value) != 0.0):
                    present.append(name)
                    break
        return tuple(present)

    def without_joint_dynamics(self) -> "Robot":
        """A copy with no joint damping, friction, armature or torque offset: the rigid-body
        dynamics alone, as Pinocchio's ``rnea``/``aba`` compute them (Robotics Toolbox's
        ``nofriction()``, with armature and offset dropped too). This robot is not changed."""
        if not self.joint_dynamics:
            return self
        joints = [replace(j, **dict.fromkeys(JOINT_DYNAMICS)) for j in self.joints]  # type: ignore[arg-type]
        import warnings

        with warnings.catch_warnings():  # this robot's own links were warned about when it was built
            warnings.simplefilter("ignore")
            return Robot(
                self.name,
                self.links.values(),
                joints,
                self.gravity,
                self.parameters,
                self.meta,
                self.base,
                self.defaults,
                strict=self.strict,
                root_joint=self.root_joint,
            )

    def require_fixed_base(self, what: str) -> None:
        """Raise :class:`~armdyn.errors.FloatingBaseError` naming ``what`` if the base
        floats: for the functions that handle a fixed base only (yet)."""
        if self.floating:
            raise FloatingBaseError(
                f"{what} does not support a floating base (root_joint='free-flyer') yet; {NUMERIC_EVERYWHERE} do",
                f"robot '{self.name}'",
                self.meta.get("file"),
            )

    def require_one_dof_joints(self, what: str) -> None:
        """Raise :class:`~armdyn.errors.ModelError` naming ``what`` if a joint has several
        coordinates (spherical, planar, floating): for what handles revolute and
        prismatic joints only (yet)."""
        if self.multi_dof_joints:
            named = ", ".join(f"'{j.name}' ({j.type})" for j in self.multi_dof_joints[:3])
            more = f" and {len(self.multi_dof_joints) - 3} more" if len(self.multi_dof_joints) > 3 else ""
            raise ModelError(
                f"{what} handles revolute and prismatic joints only (yet); this robot has joints of "
                f"several coordinates: {named}{more}. {NUMERIC_EVERYWHERE} take them",
                f"robot '{self.name}'",
                self.meta.get("file"),
            )

    def __repr__(self) -> str:
        letters = {"revolute": "R", "prismatic": "P", "fixed": "F", "spherical": "S", "planar": "L", "floating": "X"}
        kinds = "".join(letters[j.type] for j in self.joints)
        extra = f", joint_dynamics={list(self.joint_dynamics)}" if self.joint_dynamics else ""
        extra += ", root_joint='free-flyer'" if self.floating else ""
        return f"Robot({self.name!r}, dof={self.dof}, joints={kinds}, parameters={sorted(self.parameters)}{extra})"

    def _repr_html_(self) -> str:
        """Jupyter: tables of the joints and links (symbolic/report_html.py, through :mod:`armdyn.dispatch`)."""
        return call("html", self)
