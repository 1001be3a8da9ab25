"""Generating code: the driver :func:`codegen` and what it returns, :class:`GeneratedCode`.

:func:`codegen` builds a straight-line program per quantity (``programs/``) and prints
it (printers.py); where each quantity comes from is in the docstring of the package
:mod:`armdyn.printing`, which re-exports everything here. compile.py builds the C.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import sympy as sp

from ..model import Robot
from ..programs.program import Builder, Program, from_expressions
from ..symbolic import dag
from .printers import INPUTS, Names, print_c, print_python
from .safe_names import identifier_base

QUANTITIES = ("tau", "M", "C", "g", "bias", "regressor")
#: what codegen generates when not told: C only where it applies (a fixed base, joints of
#: one coordinate); elsewhere the bias C v + g (generate_floating.py)
DEFAULT_WHAT = ("tau", "M", "C", "g")
LANGUAGES = ("c", "python", "numpy")
_SUFFIX = {"c": ".c", "python": ".py", "numpy": ".py"}


@dataclass
class GeneratedCode:
    """Generated source for some quantities of one robot.

    source:      the whole source text (one file).
    lang:        "c", "python" or "numpy".
    functions:   quantity -> function name (C: also ``<name>_batch``).
    op_counts:   quantity -> {'mul', 'add', 'sin_cos', 'other', 'total'} per state.
    parameters:  Symbols of the parameter vector ``p``, in order (empty for numbers).
    definitions: [(Symbol, expression of the model's parameters)] of the barycentric ones.
    programs:    quantity -> :class:`~armdyn.programs.program.Program`.
    q, qd, qdd:  the symbols each input array holds, in order (:meth:`inputs`).
    input_names: what the functions call the three arrays: ``q, qd, qdd``, or ``q, v, a``
                 for a floating base or joints of several coordinates (``q`` (nq,) in Pinocchio's
                 layout, ``v`` and ``a`` (nv,): :mod:`.generate_floating`).
    quaternions: ``[(first index in q, whose)]`` of the quaternions among the inputs.
    conventions: header lines saying what the arrays hold (the fixed base's when empty).
    """

    robot_name: str
    lang: str
    dof: int
    coordinate_names: list
    q: sp.Matrix
    qd: sp.Matrix
    qdd: sp.Matrix
    programs: dict
    sources: dict
    parameters: list
    definitions: list
    base: bool = False
    source: str = ""
    functions: dict = field(default_factory=dict)
    op_counts: dict = field(default_factory=dict)
    names: Names | None = None
    input_names: tuple = ("q", "qd", "qdd")
    quaternions: list = field(default_factory=list)
    conventions: list = field(default_factory=list)

    def inputs(self, what: str) -> list[tuple[str, list]]:
        """``[(argument name, its symbols in order)]`` of the function of ``what``."""
        arrays = {"q": self.q, "qd": self.qd, "qdd": self.qdd}
        role = {"q": 0, "qd": 1, "qdd": 2}
        return [(self.input_names[role[r]], list(arrays[r])) for r in INPUTS[what]]

    def input_widths(self) -> str:
        """The arrays' widths, e.g. ``"q: 11, v: 10, a: 10"``."""
        return ", ".join(f"{n}: {len(a)}" for n, a in zip(self.input_names, (self.q, self.qd, self.qdd)))

    def output_size(self, what: str) -> int:
        return int(np.prod(self.programs[what].shape))

    def describe(self, what: str) -> str:
        shape = " x ".join(str(d) for d in self.programs[what].shape)
        return f"({shape}) of {', '.join(a for a, _ in self.inputs(what))}; {self.sources[what]}"

    @property
    def filename(self) -> str:
        return f"{identifier(self.robot_name)}_dynamics{_SUFFIX[self.lang]}"

    def parameter_values(self, values: dict | None = None) -> np.ndarray:
        """The vector ``p`` (len(parameters),) from values of the model's parameters
        (name or Symbol -> number); barycentric entries are computed from their
        definitions. Missing values are an error naming them."""
        table = {}
        for k, v in (values or {}).items():
            table[k if isinstance(k, str) else k.name] = float(v)
        defs = dict(self.definitions)
        out, missing = [], []
        for s in self.parameters:
            expr = defs.get(s, s)
            subs = {f: table[f.name] for f in expr.free_symbols if f.name in table}
            absent = [f.name for f in expr.free_symbols if f.name not in table]
            if absent:
                missing += absent
                continue
            out.append(float(expr.xreplace(subs)))
        if missing:
            raise ValueError(f"parameter_values: no value for {sorted(set(missing))}")
        return np.array(out)

    def write(self, directory) -> str:
        """Write :attr:`source` to ``directory/filename`` (all or nothing); returns the path."""
        return write_files([self], directory)[0]


def identifier(name: str) -> str:
    """The robot's name as an ASCII identifier: the functions' prefix and the file's stem
    (a long name cut, with a digest of the whole: a file name has at most 255 bytes)."""
    base = identifier_base(name, fallback="robot")
    if len(base) > 48:
        import hashlib

        base = f"{base[:39]}_{hashlib.sha1(name.encode('utf-8', 'surrogatepass')).hexdigest()[:8]}"
    return base


def write_files(codes, directory) -> list[str]:
    """Write each code's source into ``directory`` (created if missing) all or nothing,
    through :func:`armdyn._io_atomic.atomic_writes` (files get the umask's permissions; an
    existing destination that is not a writable regular file is refused)."""
    import os
    from pathlib import Path

    from .._io_atomic import OutputPathError, atomic_writes

    shown = os.fspath(directory)
    if not shown:
        raise OutputPathError("output directory is empty")
    if os.path.lexists(shown) and not os.path.isdir(shown):
        raise OutputPathError(f"{shown}: exists and is not a directory (--out takes a directory)")
    try:
        os.makedirs(shown, exist_ok=True)
    except OSError as exc:
        raise OutputPathError(f"{shown}: cannot create the directory ({exc.strerror})") from None
    paths = [os.path.join(shown, code.filename) for code in codes]
    atomic_writes(
        [
            (path, lambda tmp, c=code: Path(tmp).write_text(c.source, encoding="utf-8"))  # type: ignore[misc]
            for path, code in zip(paths, codes)
        ]
    )
    return paths


def _identification(what: str):
    try:
        from .. import identification  # provided by the regressor/base-parameter work
    except ImportError:
        raise ValueError(
            f"codegen: {what} is not available: armdyn.identification is not installed in this version of armdyn"
        ) from None
    return identification


def _parse_what(what) -> list[str]:
    if what is None:
        what = DEFAULT_WHAT
    if isinstance(what, str):
        what = [w.strip() for w in what.split(",") if w.strip()]
    what = list(what)
    if not what:
        raise ValueError("codegen: 'what' is empty; choose from " + ", ".join(QUANTITIES))
    bad = [w for w in what if w not in QUANTITIES]
    if bad:
        raise ValueError(f"codegen: unknown quantity {bad[0]!r} in 'what'; choose from {', '.join(QUANTITIES)}")
    return list(dict.fromkeys(what))


def _in_model_parameters(extra, definitions, chained: bool = False) -> list:
    """New definitions with the barycentric symbols in them replaced by theirs
    (``chained``: also the symbols of earlier entries of ``extra``)."""
    table = dict(definitions)
    out = []
    for s, e in extra:
        if s in table:
            continue
        value = sp.expand(e.xreplace(table))
        out.append((s, value))
        if chained:
            table[s] = value
    return out


def _standard_programs(robot: Robot, what) -> tuple[dict, dict, list]:
    from ..programs.composite_mass_matrix import composite_mass_matrix
    from ..programs.coriolis_program import christoffel_program
    from ..programs.customized_ne import customized_newton_euler, standard_parameters
    from ..programs.grouping import grouped_parameters

    params, definitions = standard_parameters(robot)
    # Khalil's grouping (exact): what of a link's inertia rides on its parent is moved
    # there once per parameter set, and the zeros it leaves propagate per state
    params, grouped = grouped_parameters(robot, params, definitions)
    definitions = definitions + grouped
    # tau and g: each leaf link's frame turned about its joint axis to put its first
    # moment on y (exact; per parameter set); M and C keep the link frames
    ne_params, turned, turns = _turned_leaves(robot, params, definitions)
    definitions = definitions + turned
    reserved = robot.free_symbols() | {s for s, _ in definitions}
    programs, sources = {}, {}
    n = robot.dof
    M_prog = None
    for w in what:
        if w == "tau":
            programs[w], extra = customized_newton_euler(robot, parameters=ne_params, turns=turns)
            definitions += _in_model_parameters(extra, definitions)
            sources[w] = "customized Newton-Euler"
        elif w == "g":
            programs[w], extra = customized_newton_euler(robot, [0] * n, [0] * n, parameters=ne_params, turns=turns)
            definitions += _in_model_parameters(extra, definitions)
            sources[w] = "customized Newton-Euler at qd = qdd = 0"
        elif w == "bias":
            programs[w], extra = customized_newton_euler(robot, qdd=[0] * n, parameters=ne_params, turns=turns)
            definitions += _in_model_parameters(extra, definitions)
            sources[w] = "customized Newton-Euler at qdd = 0"
        elif w in ("M", "C"):
            if M_prog is None:
                builder = Builder(reserved=reserved | set(robot.q) | set(robot.qd))
                M_prog, _ = composite_mass_matrix(robot, parameters=params, builder=builder)
            if w == "M":
                programs[w] = M_prog
                sources[w] = "composite links"
            else:
                programs[w] = christoffel_program(robot, M_prog, builder)
                sources[w] = "Christoffel symbols of the composite-link M, differentiated line by line"
        if w != "regressor":
            sources[w] += ", grouped parameters"
        if w == "regressor":
            ident = _identification("the regressor")
            reg = ident.regressor(robot)
            Y = sp.Matrix(reg.Y)
            programs[w] = from_expressions(list(Y), Y.shape, reserved=reserved)
            sources[w] = "armdyn.identification.regressor, CSE"
    _add_joint_terms(robot, programs)
    return programs, sources, definitions


def _turned_leaves(robot: Robot, params: dict, definitions: list, taken=()):
    """:func:`armdyn.programs.leaf_frames.turn_leaf_frames`, with the new definitions in
    the model's parameters (``definitions``' symbols replaced by theirs)."""
    from ..programs.leaf_frames import turn_leaf_frames

    turned, new, turns = turn_leaf_frames(robot, params, definitions, taken)
    return turned, _in_model_parameters(new, definitions), turns


def _add_joint_terms(robot: Robot, programs: dict) -> None:
    """Joint friction, rotor inertia and torque offsets (docs/architecture.md: ``tau = M qdd + C qd +
    g + Ia qdd + Fv qd + Fc sign(qd) + offset``; :mod:`armdyn.symbolic.joint_terms`) added
    to the rigid-body outputs: all of them to tau, ``Ia`` to M's diagonal, the offset to
    g (``g = tau(qd = 0, qdd = 0)``), friction and offset to the bias (``tau(qdd = 0)``);
    C has none."""
    from ..symbolic import joint_terms

    if not joint_terms.has_joint_terms(robot):
        return
    n = robot.dof
    extra = {
        "tau": list(joint_terms.joint_torques(robot, robot.qd, robot.qdd)),
        "g": list(joint_terms.offsets(robot)),
        "bias": list(joint_terms.joint_torques(robot, robot.qd, [0] * n)),
    }
    ia = joint_terms.armature(robot)
    extra["M"] = [ia[k // n] if k // n == k % n else 0 for k in range(n * n)]
    for w, terms in extra.items():
        if w in programs:
            prog = programs[w]
            programs[w] = Program(list(prog.assignments), [o + t for o, t in zip(prog.outputs, terms)], prog.shape)


def _base_programs(robot: Robot, what) -> tuple[dict, dict, list]:
    from ..symbolic.terms import christoffel_coriolis

    ident = _identification("base parameters (--base)")
    bp = ident.base_parameters(robot)
    Yb = sp.Matrix(bp.Y)
    beta = [sp.Symbol(str(nm)) for nm in bp.names]
    definitions = list(zip(beta, list(sp.Matrix(bp.beta))))
    n = robot.dof
    reserved = robot.free_symbols() | set(beta)
    programs, sources = {}, {}
    custom = _customized_base_programs(
        robot, ident, Yb, beta, definitions, [w for w in what if w != "regressor"], bp.regressor
    )
    if custom is not None:
        programs, sources, extra_defs = custom
        definitions = definitions + extra_defs
    tau = None
    shape: tuple[int, ...]
    for w in what:
        if w in programs:
            continue
        if w == "regressor":
            expr, shape = list(Yb), Yb.shape
        else:
            if tau is None:  # only for what the customized algorithms did not give
                tau = Yb * sp.Matrix(beta)
            if w == "tau":
                expr, shape = list(tau), (n,)
            elif w == "g":
                expr, shape = list(tau.xreplace({s: 0 for s in list(robot.qd) + list(robot.qdd)})), (n,)
            elif w == "bias":
                expr, shape = list(tau.xreplace({s: 0 for s in robot.qdd})), (n,)
            elif w == "M":
                expr, shape = list(tau.jacobian(robot.qdd)), (n, n)
            else:  # "C"
                expr, shape = list(christoffel_coriolis(tau.jacobian(robot.qdd), robot.q, robot.qd)), (n, n)
        programs[w] = from_expressions(expr, shape, reserved=reserved)
        sources[w] = "base regressor x base parameters, CSE" if w != "regressor" else "base regressor, CSE"
    return programs, sources, definitions


def _customized_base_programs(robot, ident, Yb, beta, definitions, what, reg=None):
    """tau, g, M, C by the customized algorithms at the base-parameter point
    (:mod:`armdyn.programs.base_parameters`), checked against ``Yb beta`` at random points; None if
    the base parameters are not a grouping onto standard columns."""
    from ..programs.base_parameters import base_inertials
    from ..programs.composite_mass_matrix import composite_mass_matrix
    from ..programs.coriolis_program import christoffel_program, partial_derivative
    from ..programs.customized_ne import customized_newton_euler

    if not what:
        return None
    reg = reg if reg is not None else ident.regressor(robot)  # base_parameters' own: not derived twice
    found = base_inertials(robot, sp.Matrix(reg.Y), list(sp.Matrix(reg.pi)), Yb, beta)
    if found is None:
        return None
    params, extra = found
    n = robot.dof
    states = list(robot.qd) + list(robot.qdd)
    programs, sources, defs = {}, {}, []
    M_prog = builder = None
    reserved = robot.free_symbols() | set(beta) | set(robot.q) | set(robot.qd) | set(robot.qdd)
    # tau and g with the leaf links' frames turned (first moment on y), in the betas
    from ..programs.leaf_frames import turn_leaf_frames

    ne_params, leaf_defs, turns = turn_leaf_frames(robot, params, [], taken=beta)
    tau_prog, d = customized_newton_euler(robot, parameters=ne_params, turns=turns)
    d = leaf_defs + d  # in the betas; later ones may use earlier ones
    defs += d
    tau_prog.outputs = [o + extra[i] for i, o in enumerate(tau_prog.outputs)]
    # the check: tau of the program == Yb beta at random points (q, qd, qdd, parameters)
    rng = np.random.default_rng(11)
    free = sorted(dag.free_symbols(Yb) | set(beta) | set(robot.q) | set(states), key=str)
    samples = 2
    values = {s: rng.uniform(-1.2, 1.2, samples) for s in free}
    Ybn = dag.evaluate(Yb, values)  # (dof, n_beta, samples), numerically (no xreplace of Yb)
    for k in range(samples):
        env = {s: float(v[k]) for s, v in values.items()}
        for s, e in d:
            env[s] = float(e.xreplace(env))
        want = Ybn[:, :, k] @ np.array([env[b] for b in beta])
        got = np.array(tau_prog.evaluate(env))
        if not (
            np.all(np.isfinite(want)) and np.allclose(got, want, rtol=1e-9, atol=1e-9 * max(1.0, np.abs(want).max()))
        ):
            return None
    for w in what:
        if w == "tau":
            programs[w] = tau_prog
        elif w in ("g", "bias"):
            rest = states if w == "g" else list(robot.qdd)
            qd = [0] * n if w == "g" else None
            programs[w], _ = customized_newton_euler(robot, qd, [0] * n, parameters=ne_params, turns=turns)
            w_extra = extra.xreplace({s: 0 for s in rest})
            programs[w].outputs = [o + w_extra[i] for i, o in enumerate(programs[w].outputs)]
        elif w in ("M", "C") and M_prog is None:
            builder = Builder(reserved=reserved | {s for s, _ in defs})
            M_prog, _ = composite_mass_matrix(robot, parameters=params, builder=builder)
            # d extra / d qdd by the program differentiator's rules (SymPy's jacobian
            # recomputes free symbols at every level of these large sums: seconds per entry)
            M_extra = [partial_derivative(extra[k // n], robot.qdd[k % n]) for k in range(n * n)]
            M_prog.outputs = [o + M_extra[k] for k, o in enumerate(M_prog.outputs)]
        if w == "M":
            programs[w] = M_prog
        elif w == "C":
            programs[w] = christoffel_program(robot, M_prog, builder)
        sources[w] = {
            "tau": "customized Newton-Euler",
            "g": "customized Newton-Euler at qd = qdd = 0",
            "bias": "customized Newton-Euler at qdd = 0",
            "M": "composite links",
            "C": "Christoffel symbols of the composite-link M",
        }[w] + ", at the base parameters"
    return programs, sources, _in_model_parameters(defs, definitions, chained=True)


def codegen(robot: Robot | str, what=None, lang: str = "c", base: bool = False) -> GeneratedCode:
    """Generate code for ``what`` (quantities from ``QUANTITIES``, a sequence or a
    comma-separated string; default tau, M, C, g, or tau, M, g, bias where C does not
    apply) of ``robot`` (a Robot, bundled name or model file) in ``lang`` ("c",
    "python", "numpy"). ``base=True``: in the base parameters (needs
    :mod:`armdyn.identification`). Returns a :class:`GeneratedCode`.

    A floating base or joints of several coordinates: :mod:`.generate_floating` (inputs ``q, v, a``
    in Pinocchio's layout; C, the regressor and ``base=True`` refused).

    Raises ValueError for an unknown quantity or language, or a robot that does not move;
    :class:`~armdyn.errors.ModelError` naming the joint for a joint codegen does not take.
    """
    if isinstance(robot, str):
        from ..io import load

        robot = load(robot)
    if not isinstance(robot, Robot):
        raise TypeError(f"codegen: expected an armdyn.Robot or a model name, got {type(robot).__name__}")
    quasi = robot.floating or bool(robot.multi_dof_joints)
    if quasi:
        from . import generate_floating

        generate_floating.check_robot(robot)
        what = _parse_what(generate_floating.DEFAULT_WHAT if what is None else what)
    else:
        what = _parse_what(what)
    if lang not in LANGUAGES:
        raise ValueError(f"codegen: unknown language {lang!r}; choose from {', '.join(LANGUAGES)}")
    if robot.nv == 0:
        raise ValueError(f"codegen: robot '{robot.name}' has no movable joint")
    layout = None
    if quasi:
        generate_floating.check_what(robot, what, base)
        programs, sources, layout = generate_floating.programs(robot, what)
        definitions: list = []
        q, qd, qdd = layout.q, layout.v, layout.a
    else:
        programs, sources, definitions = (_base_programs if base else _standard_programs)(robot, what)
        q, qd, qdd = robot.q, robot.qd, robot.qdd

    states = set(q) | set(qd) | set(qdd)
    used = set()
    for prog in programs.values():
        for e in [e for _, e in prog.assignments] + list(prog.outputs):
            used |= sp.sympify(e).free_symbols
        used -= {s for s, _ in prog.assignments}
    free = used - states
    order = [s for s in robot.parameters.values() if s in free] + [s for s, _ in definitions if s in free]
    order += sorted(free - set(order), key=str)
    defs = [(s, e) for s, e in definitions if s in free]

    temps = [s for prog in programs.values() for s, _ in prog.assignments]
    prefix = identifier(robot.name)
    functions = {w: f"{prefix}_{w}" for w in programs}
    taken = [*functions.values(), *(f + "_batch" for f in functions.values())]
    names = Names(list(dict.fromkeys([*q, *qd, *qdd, *order, *temps])), taken=taken)
    code = GeneratedCode(
        robot.name,
        lang,
        robot.dof,
        list(robot.coordinate_names),
        sp.Matrix(list(q)),
        sp.Matrix(list(qd)),
        sp.Matrix(list(qdd)),
        programs,
        sources,
        order,
        defs,
        base,
        functions=functions,
        op_counts={w: p.operation_counts() for w, p in programs.items()},
        names=names,
    )
    if layout is not None:
        code.input_names, code.quaternions, code.conventions = ("q", "v", "a"), layout.quaternions, layout.conventions
    code.source = print_c(code) if lang == "c" else print_python(code, numpy=(lang == "numpy"))
    return code
