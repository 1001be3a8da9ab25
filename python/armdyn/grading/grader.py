"""The grading pass: read a submission's equations one by one, name each one's step
(:mod:`.notation`), judge it against the method (:mod:`.engine`, :mod:`.methods`) and
collect the verdicts into a :class:`~.verdict.GradeReport`. :func:`grade` is the entry
point every path uses (``armdyn.grade``, ``armdyn grade``, the class batch, the web app).
"""

from __future__ import annotations

import re

import symengine as se
import sympy as sp

from ..errors import ModelError
from ..model import Robot
from ..symbolic.names import latex_symbol_names
from .chains import check_step, relation_holds, reported_at, with_members
from .defined import DefinedNames, after_equation, definition, model_value, read_pair, read_value
from .diagnose import cannot_read, location
from .energy_steps import EnergySteps
from .engine import Sampler, Value, World, canonical, equal, judge, to_sympy
from .explain import component_name, contract, describe, pretty, tidy
from .kinematics_steps import KinematicsSteps, confirm_used
from .lagrange_terms import coriolis_entries_as_matrix
from .latex import LatexError, UnknownSymbol
from .laws import identity, indexed_step, law_statement
from .methods import lagrange_method, newton_euler_method, rotation_between
from .named import Waiting, derivative_step, form_only, plain, simple_name, symmetric_entry
from .notation import LAGRANGE_KEYS, VECTOR_KEYS, StepRef, SymbolMap, parse_lhs
from .proofs import grade_proofs
from .reader import Submission
from .setup_lines import setup_line
from .statements import FREE_END, lagrange_law, matrix_form
from .sympy_syntax import parse_sympy_syntax
from .verdict import PASSING, GradeReport, StepVerdict
from .vocabulary import MODEL_KEYS, student_names

#: step names as armdyn reports them (``v_dot_1``, ``tau_2``), accepted as left-hand sides in YAML
_NAMED = frozenset(VECTOR_KEYS) | frozenset(LAGRANGE_KEYS) - {"T", "V", "L"} | {"tau"}


def _named_ref(text: str) -> StepRef | None:
    """``v_dot_1``, ``tau_2``, ``T``: armdyn's own step names."""
    if text in ("T", "V", "L"):
        return StepRef(text)
    head, _, tail = text.rpartition("_")
    if head in _NAMED and tail.isdigit():
        return StepRef(head, int(tail))
    return None


class Grader(EnergySteps, KinematicsSteps):
    def __init__(self, sub: Submission, robot: Robot, symbols: dict | None):
        self.sub = sub
        self.robot = robot
        try:
            self.symbols = SymbolMap(robot, {**sub.symbols, **(symbols or {})})
        except LatexError as err:
            raise ModelError(str(err), source=sub.path) from None
        free = set(robot.q) | set(robot.qd) | set(robot.qdd) | robot.free_symbols()
        self.sampler = Sampler(free, robot)
        self._worlds: dict = {}
        self.verdicts: list[StepVerdict] = []
        self.notes: list[str] = list(sub.notes)  # what the reader set aside comes first
        self.refusals: list[tuple[str, str]] = []  # (file:line:column, why) of equations not graded
        self._refused_before = 0  # refusals before the current equation
        self._primes_noted = False
        self.written: dict = {}  # (key, index) -> (their value, the right one in their convention), link frame
        # names the student gave values to (d_{11}, X, c_1), read in later values
        self.names = DefinedNames(self.symbols, lambda n: model_value(self, n), lambda t: read_pair(self, t))
        self.symbols.defined = self.names
        self.last_read = None  # (equation, own value, right value, names used): defined.after_equation
        self._assumed: list[str] = []

    def world(self, name: str) -> World:
        if name not in self._worlds:
            if name == "newton-euler":
                method, ctx = newton_euler_method(self.robot)
                self._worlds[name] = World(method, ctx, self.sampler, numeric=True)
            else:
                method, ctx = lagrange_method(self.robot)
                self._worlds[name] = World(method, ctx, self.sampler, numeric=False)
        return self._worlds[name]

    # -- reading one equation
    def _unrecognised(self, eq, message: str, name: str = "", key: str = "") -> None:
        """Record ``eq`` as unrecognised (shown, skipped), with why."""
        self.verdicts.append(
            StepVerdict(
                name=name,
                key=key,
                link="",
                status="unrecognised",
                label=eq.lhs,
                source=eq.source,
                line=eq.line,
                message=message,
            )
        )

    def _locate(self, eq, pos: int | None) -> tuple[int, int]:
        """(line, column) of offset ``pos`` in ``eq``'s value (its start if not known)."""
        if pos is not None and eq.offset >= 0 and isinstance(eq.value, str):
            return self.sub.locate(eq.offset_of(pos))
        return eq.line, eq.column

    def _unreadable(self, eq, problem: str, pos: int | None = None) -> str:
        """The message for an equation that cannot be read: file:line:column, a hint."""
        return self._refuse(eq, cannot_read(problem), pos)

    def _refuse(self, eq, problem: str, pos: int | None = None, column: bool = True) -> str:
        """The message for an equation that names a step but cannot be graded (a link
        the robot does not have, a value of the wrong shape, an unknown symbol):
        ``file:line:column: problem`` (no column: the left-hand side is the problem).
        Kept in :attr:`refusals` (the file's error when nothing else can be graded)."""
        line, col = self._locate(eq, pos)
        where = location(self.sub.path, line, col if column else 0)
        self.refusals.append((where, problem))
        return f"{where}: {problem}"

    def value(self, eq, ref: StepRef):
        if eq.problem:
            return None, self._unreadable(eq, eq.problem)
        try:
            if eq.latex:
                raw = eq.value
                value = read_value(self, eq, raw)
            else:
                names = dict(self.symbols.names)
                names.update({k: v for k, v in self.symbols.steps.items() if not isinstance(v, sp.MatrixBase)})
                raw = eq.value
                items = raw if isinstance(raw, list) else [raw]
                parsed = [
                    se.sympify(v) if isinstance(v, (int, float)) else parse_sympy_syntax(str(v), names, symengine=True)
                    for v in items
                ]
                value = se.DenseMatrix(len(parsed), 1, parsed) if isinstance(raw, list) else parsed[0]
        except UnknownSymbol as err:
            return None, self._refuse(eq, f"{ref.name}: {err}", err.pos)
        except ModelError as err:
            return None, self._refuse(eq, f"{ref.name}: {err.message}")
        except LatexError as err:
            return None, self._unreadable(eq, str(err), err.pos)
        except RecursionError:
            return None, self._unreadable(eq, "nested too deeply to read")
        except (TypeError, ValueError) as err:
            return None, self._unreadable(eq, str(err).split("\n")[0][:200])
        if eq.latex and "'" in str(eq.value) and not self._primes_noted:
            self._primes_noted = True
            self.notes.append(
                "a prime on a joint coordinate (\\theta_1') read as its time derivative (\\dot{\\theta}_1)"
            )
        shaped = self._shape(value, ref)
        if isinstance(shaped, str):
            return None, self._refuse(eq, shaped)
        return shaped, None

    def _shape(self, value, ref: StepRef):
        """``value`` in the shape ``ref`` has (a 3-vector, a 3x3 matrix, a scalar), or why
        it cannot be (a str)."""
        if ref.by_shape or ref.key in MODEL_KEYS or ref.key in ("Lang", "tau_vec"):
            return to_sympy(value)  # shaped where it is read (vocabulary.by_shape, lagrange_terms)
        vector = ref.key in VECTOR_KEYS or ref.key in ("P", "Pc")
        if ref.key == "R":
            want = (3, 3)
        elif vector:
            want = (3, 1)
        else:
            want = None
        if isinstance(value, se.DenseMatrix) and (want is None or value.shape == (1, 1) or value.shape[1] != 1):
            value = to_sympy(value)  # small: shaped by the SymPy rules below
        elif isinstance(value, se.Basic) and not isinstance(value, se.DenseMatrix) and want is not None:
            value = to_sympy(value)
        if isinstance(value, se.DenseMatrix):
            if value.shape != want:
                return f"{ref.name} must be a vector of 3 components, but it has {value.shape[0]}"
            return value
        if want is None:
            if isinstance(value, sp.MatrixBase):
                if value.shape == (1, 1):
                    return value[0, 0]
                return f"{ref.name} is a scalar, but the value is a {value.shape[0]}x{value.shape[1]} matrix"
            return value
        if not isinstance(value, sp.MatrixBase):
            if value == 0:
                return sp.zeros(*want)
            return f"{ref.name} is a {'vector' if vector else '3x3 matrix'}, but the value is a scalar"
        if vector and value.shape == (1, 3):
            value = value.T
        if value.shape != want:
            kind = "vector of 3 components" if vector else "3x3 matrix"
            return f"{ref.name} must be a {kind}, but it has shape {value.shape[0]}x{value.shape[1]}"
        return value

    # -- grading
    def run(self, method_hint: str | None) -> GradeReport:
        context = method_hint if method_hint in ("newton-euler", "lagrange") else None
        seen_methods: list[str] = []
        self.names.collect(self.sub.equations)
        waiting = Waiting(self)  # equations that use a name given further on

        def one(eq):
            done = len(self.verdicts)
            self.names.unknown = []
            self._equation(eq, seen_methods, context)
            after_equation(self, eq, self.verdicts[done:])
            for v in self.verdicts[done:]:
                v.part, v.task, v.column = eq.part, eq.task, v.column or eq.column  # a chain's: where reported
            return self.verdicts[done:]

        for eq in self.sub.equations:
            new = one(eq)
            if new and new[-1].key not in ("", "R", "P", "Pc", "law", "tau", "shorthand", "dt"):
                last = new[-1].key
                context = "lagrange" if last in LAGRANGE_KEYS or last in MODEL_KEYS else "newton-euler"
            waiting.hold(eq, new)
            waiting.retry(one)
        waiting.finish()
        self.verdicts = grade_proofs(self.sub, self.verdicts)  # rigid-body proofs: every link checked
        for v in self.verdicts:  # proof links (also bare expressions) carry the part they are in
            if v.part is None and not v.task:
                v.part, v.task = self.sub.part_at(v.line)
        return self._report(seen_methods, method_hint)

    def _equation(self, eq, seen_methods: list, context: str | None) -> None:
        """Grade one equation: append its verdict."""
        self._refused_before = len(self.refusals)  # a law read after a refusal takes it back
        ref = parse_lhs(eq.lhs, self.symbols.coordinate_of) if eq.latex or "\\" in eq.lhs else None
        if ref is None:
            ref = _named_ref(eq.lhs) or (parse_lhs(eq.lhs, self.symbols.coordinate_of) if not eq.latex else None)
        if eq.problem:  # cannot be split into sides: shown with where and why, named if its start names a step
            self._unrecognised(
                eq, self._unreadable(eq, eq.problem), name=ref.name if ref else "", key=ref.key if ref else ""
            )
            return
        if self._law(eq, seen_methods):  # a law stated in general symbols (k_i = ..., \sum, c_{ijk})
            return
        indexed = indexed_step(self, eq) if ref is None else None  # {}^{i+1}_{i}R = ...: every i
        if indexed is not None:
            self.verdicts.append(indexed)
            return
        if ref is None:
            law = lagrange_law(eq.lhs, str(eq.value)) if eq.latex else None
            if law is None and eq.latex:
                law = lagrange_law(str(eq.value), eq.lhs)
            if law is not None:
                if "lagrange" not in seen_methods:
                    seen_methods.append("lagrange")
                self.verdicts.append(
                    StepVerdict(
                        name="lagrange_equation",
                        key="law",
                        link="",
                        status="correct" if law[0] else "wrong",
                        label=eq.lhs,
                        source=eq.source,
                        line=eq.line,
                        message=law[1],
                    )
                )
                return
            if eq.latex and matrix_form(eq.lhs, str(eq.value)):
                self._matrix_form(eq)
                return
            if derivative_step(self, eq):  # \dot M_{12} = ..., \frac{\partial M_{11}}{\partial q_2} = ...
                return
            if self._law(eq, seen_methods, fallback=True):  # L = K - P, E_K = ½ m v^2 + ...
                return
            defined = definition(self, eq) or setup_line(self, eq)
            if defined:  # a name given a value used later, a setup line: read, not judged
                self._unrecognised(eq, defined)
                self.verdicts[-1].status = "definition"
                return
            same = identity(self, eq)  # cos a cos b + sin a sin b = cos(a - b)
            if same is not None:
                self.verdicts.append(same)
                return
            self._unrecognised(eq, "not a step of Newton-Euler or Lagrange (skipped)")
            return
        if ref.key in ("tau", "tau_vec") and eq.latex and matrix_form(eq.lhs, str(eq.value)):  # τ = M q̈ + C q̇ + g
            self._matrix_form(eq)
            return
        if ref.key == "tau_vec" and form_only(self, eq) or symmetric_entry(self, eq, ref):  # τ = M q̈; M_21 = M_12
            return
        ref, assumed = self._vocabulary(ref, eq, seen_methods)  # energy-method names; by the value's shape
        if ref is None:
            if self.verdicts and self.verdicts[-1].line == eq.line and self.verdicts[-1].status == "unrecognised":
                if not self._this_arms_names(eq) and self._law(eq, seen_methods, fallback=True):  # D = m J^T J
                    del self.verdicts[-2]
            return
        n_links = len(self.robot.links) - 1
        if ref.key in ("f", "n") and ref.index == n_links + 1:
            if "newton-euler" not in seen_methods:
                seen_methods.append("newton-euler")
            self._free_end(ref, eq)
            return
        method = (
            "lagrange"
            if ref.key in LAGRANGE_KEYS
            else (context or "newton-euler" if ref.key == "tau" else "newton-euler")
        )
        if method not in seen_methods:
            seen_methods.append(method)
        problem = self._check_index(ref)
        if problem:
            self._unrecognised(eq, self._refuse(eq, problem, column=False), name=ref.name, key=ref.key)
            return
        value, problem = self.value(eq, ref)
        if value is None:
            if not self._this_arms_names(eq) and self._law(eq, seen_methods, fallback=True):  # T = ½ m v^2
                return
            self._unrecognised(eq, problem, name=ref.name, key=ref.key)
            return
        own_value = value
        value, assumed, shift = self._adjust(ref, value, assumed)
        if ref.key == "R":
            self._rotation(ref, eq, value)
        elif ref.key in ("P", "Pc"):
            self._position(ref, eq, value)
        else:
            self._step(self.world(method), ref, eq, value, method)
        self._note(assumed, shift)
        if ref.key in ("T", "V", "L"):
            for name in student_names(ref):
                self.symbols.steps[name] = own_value

    def _this_arms_names(self, eq) -> bool:
        """Does the value use a name a later equation gives (``K = K_1 + K_2`` before ``K_1 = ...``),
        or names the text gave beside a link's name it never gives (``L = K_1 + K_2 - ...``, K_1
        given)? Then it is this arm's step, waiting for them (:class:`.named.Waiting`) or saying
        which is never given, not a law stated in generic names (``T = ½ m v^2``, ``D = m_1 J_{v_1}^T
        J_{v_1} + ...`` with no Jacobian given)."""
        given = {m.group(0) for e in self.names.used for m in [re.match(r"\\?[A-Za-z]+", e.name)] if m}
        if any(n.base in given and parse_lhs(n.latex(), lambda _: None) is not None for n in self.names.unknown):
            return True  # K_1 given, K_2 not: this arm's Lagrangian missing a part
        later = {
            plain(n) for e in self.sub.equations if e.line > eq.line and e.latex for n in [simple_name(e.lhs)] if n
        }
        return any(plain(n) in later for n in self.names.unknown)

    def _law(self, eq, seen_methods: list, fallback: bool = False) -> bool:
        """Record ``eq`` as the statement of a law (:mod:`.laws`) if it is one."""
        found = law_statement(self, eq, fallback)
        if found is None:
            return False
        verdict, method = found
        del self.refusals[self._refused_before :]
        if method not in seen_methods:
            seen_methods.append(method)
        self.verdicts.append(verdict)
        return True

    def _report(self, seen_methods: list, method_hint: str | None) -> GradeReport:
        if not any(v.key or v.name in ("law", "identity") for v in self.verdicts):  # nothing graded
            if self.refusals:  # the reason is the first equation that could not be read
                where, why = self.refusals[0]
                raise ModelError(why, source=where)
            raise ModelError(
                "no step of Newton-Euler or Lagrange recognised (expected equations such as "
                "\\omega_1^1 = ..., F_2^2 = ..., \\tau_1 = ..., T = ...)",
                source=self.sub.path,
            )
        if any(v.key == "C" for v in self.verdicts):
            coriolis_entries_as_matrix(self.verdicts, self.model_terms(), self.sampler)
        first_wrong = next((v.name for v in self.verdicts if v.status == "wrong"), None)
        tau_correct = [False] * self.robot.dof
        for v in self.verdicts:
            if v.key == "tau" and 1 <= int(v.name.split("_")[1]) <= self.robot.dof:  # tau_3 of 2: unrecognised
                tau_correct[int(v.name.split("_")[1]) - 1] = v.status in (*PASSING, "correct-but-unsupported")
        self.notes.extend(n for n in self.symbols.notes if n not in self.notes)  # how names were read
        if self.symbols.used_gravity_magnitude:
            self.notes.append("g read as the magnitude of the model's gravity vector")
        if self.symbols.unit_axes:
            self.notes.append(
                f"{', '.join(sorted(self.symbols.unit_axes))} read as unit axes, (1, 0, 0), (0, 1, 0), (0, 0, 1), "
                "in the frame of the vector they are written in"
            )
        method_name = "+".join(seen_methods) or (method_hint or "newton-euler")
        return GradeReport(
            robot=self.robot.name,
            method=method_name,
            submission=self.sub.path,
            steps=self.verdicts,
            first_wrong=first_wrong,
            tau_correct=tau_correct,
            symbol_latex=dict(latex_symbol_names(self.robot)),
            notes=self.notes,
            shorthand=dict(self.symbols.shorthand),
        )

    def _check_index(self, ref: StepRef) -> str | None:
        """Why ``ref`` names a link, joint or frame the robot does not have, or None."""
        n = len(self.robot.links) - 1
        if ref.key in VECTOR_KEYS:
            if (
                ref.index is None
                or not 0 <= ref.index <= n
                or (ref.index == 0 and ref.key not in ("omega", "omega_dot", "v_dot"))
            ):
                return f"{ref.name} names link {ref.index}, but '{self.robot.name}' has links 1..{n}"
            if ref.frame is not None and not 0 <= ref.frame <= n:
                return (
                    f"{ref.name} is written in frame {ref.frame}, which '{self.robot.name}' does not "
                    f"have (frames 0..{n})"
                )
        elif ref.key in ("P", "Pc"):
            if not 1 <= ref.index <= n:  # type: ignore[operator]
                return f"{ref.name} names link {ref.index}, but '{self.robot.name}' has links 1..{n}"
            if ref.frame is not None and not 0 <= ref.frame <= n:
                return f"{ref.name}: frame {ref.frame} does not exist (frames 0..{n})"
        elif ref.key == "R":
            for k in (ref.index, ref.frame):
                if k is None or not 0 <= k <= n:
                    return f"{ref.name}: frame {k} does not exist (frames 0..{n})"
        elif ref.index is not None and not 1 <= ref.index <= self.robot.dof:
            return f"{ref.name} names joint {ref.index}, but '{self.robot.name}' has joints 1..{self.robot.dof}"
        return None

    def _free_end(self, ref: StepRef, eq):
        """``f_{n+1} = 0``, ``n_{n+1} = 0``: the load at the free end, zero."""
        value, problem = self.value(eq, StepRef(ref.key, ref.index, ref.frame))
        name = f"{ref.key}_{ref.index}"
        if value is None:
            self._unrecognised(eq, problem, name=name, key="free_end")
            return
        zero = sp.zeros(3, 1)
        ok = equal(self.sampler.fingerprint(value), self.sampler.fingerprint(zero)).ravel()
        bad = [int(i) for i in range(3) if not ok[i]]
        self.verdicts.append(
            StepVerdict(
                name=name,
                key="free_end",
                link="",
                status="wrong" if bad else "correct",
                label=eq.lhs,
                source=eq.source,
                line=eq.line,
                expected=zero,
                got=value,
                difference=value if bad else None,
                components=bad,
                message=FREE_END if bad else "the free end: no load beyond the last link",
            )
        )

    def _step(self, world: World, ref: StepRef, eq, value, method: str):
        key = (ref.key, ref.index)
        if key not in world.method.refs:
            self._unrecognised(eq, f"{method} has no step {ref.name} for this robot", name=ref.name, key=ref.key)
            return
        link = ""
        own = as_written = value
        if ref.key in VECTOR_KEYS:
            assert ref.index is not None  # _check_index ran
            link = list(self.robot.links)[ref.index]
            if ref.frame is not None and ref.frame != ref.index:
                value = own = to_sympy(value)
                own = rotation_between(world.ctx, ref.frame, ref.index) * value  # into the link's own frame
        got = Value(self.sampler.fingerprint(own), own)
        candidates = lambda r: world.candidates(r)  # noqa: E731
        j = judge(world, key, got, candidates)
        name = ref.name
        origins_names = sorted(j.origins, key=self._order)
        caused_by = origins_names[0] if j.status == "follows-from-earlier-error" and origins_names else None
        if caused_by is not None:
            confirm_used(self.verdicts, world, j.origins, name, eq.line, self.robot)
        extras = [world.candidates(r)[0] for r in j.conv.extra]
        if j.status in ("correct", "correct-by-convention"):
            world.given[key] = [canonical(world, j.conv, got, extras, frozenset())]
        elif j.status == "correct-but-unsupported":
            world.given[key] = [canonical(world, j.conv, got, extras, frozenset())] + world.carried(key)
        elif j.status == "follows-from-earlier-error":
            world.given[key] = [canonical(world, j.conv, got, extras, j.origins)]
        else:
            world.given[key] = [canonical(world, j.conv, got, extras, j.origins | {name})]
            if j.canon is not None:  # what it should have been: a repair, never support (engine._supported)
                c = j.canon
                world.given[key].append(Value(c.fp, c.build, c.origins, c.repaired | {name}))
        world.invalidate()

        # what is shown: expected in the student's convention, the difference against
        # what their own earlier values give (wrong) or the expected value
        exp_shown = j.conv.forward(
            world.expected[key].sym(), world.ctx, *(world.expected[r].sym() for r in j.conv.extra)
        )
        self.written[key] = (own, exp_shown)  # read by chain members (SymPy when used)
        if ref.key in VECTOR_KEYS and ref.frame is not None and ref.index is not None and ref.frame != ref.index:
            exp_shown = rotation_between(world.ctx, ref.index, ref.frame) * exp_shown
        findings = check_step(self, eq, as_written, exp_shown, j.status == "wrong") if eq.latex else []
        difference, components, message = None, [], ""
        if j.status in ("wrong", "follows-from-earlier-error", "correct-but-unsupported"):
            value = to_sympy(value)
            ref_value = (
                j.reference.sym() if j.status != "correct-but-unsupported" and j.reference is not None else exp_shown
            )
            if j.status == "correct-but-unsupported":
                carried = world.carried(key)
                ref_value = carried[0].sym() if carried else exp_shown
                ref_value = j.conv.forward(ref_value, world.ctx, *(e.sym() for e in extras))
            if ref.key in VECTOR_KEYS and ref.frame is not None and ref.index is not None and ref.frame != ref.index:
                ref_value = rotation_between(world.ctx, ref.index, ref.frame) * ref_value
            got_m, ref_m = _matrix(value), _matrix(ref_value)
            ok = equal(self.sampler.fingerprint(got_m), self.sampler.fingerprint(ref_m)).ravel()
            components = [int(i) for i in range(len(ok)) if not ok[i]]
            if j.status == "wrong":
                parts = []
                for i in components[:3]:
                    text = self._describe(got_m[i], ref_m[i])
                    where = component_name(i, got_m.shape)
                    parts.append(f"{text} in {where}" if where else text)
                against = ["compared with what your own earlier steps give"] if j.origins else []
                against += [f"in the convention: {j.convention}"] if j.convention else []  # the closest: said
                message = "; ".join(parts) + (f" ({', '.join(against)})" if against else "")
                diff = sp.Matrix([tidy(got_m[i] - ref_m[i], self.robot) for i in range(len(got_m))])
                difference = diff if got_m.shape != (1, 1) else diff[0]
                exp_shown = contract(_tidied(exp_shown, self.robot), self.symbols.shorthand)  # their s₁₂, c₁₂
            elif j.status == "follows-from-earlier-error":
                message = f"follows from the error in {caused_by}" + (f" ({j.convention})" if j.convention else "")
                diff = _matrix(value) - _matrix(exp_shown)
                difference = (
                    sp.Matrix([tidy(x, self.robot) for x in diff])
                    if diff.shape != (1, 1)
                    else tidy(diff[0], self.robot)
                )
            else:
                # the consistent carry-through: the candidate inheriting the fewest slips
                carried = sorted(world.carried(key), key=lambda v: len(v.origins))
                message = "right, but not what your own earlier steps give"
                if carried:
                    through = j.conv.forward(carried[0].sym(), world.ctx, *(e.sym() for e in extras))
                    d = _matrix(through) - _matrix(exp_shown)
                    bad = [i for i in range(len(d)) if tidy(d[i], self.robot) != 0]
                    if bad:
                        src = sorted(carried[0].origins, key=self._order)
                        where = component_name(bad[0], d.shape)
                        left = pretty(tidy(d[bad[0]], self.robot), shorthand=self.symbols.shorthand)
                        message += (
                            f": carried through they leave {left}"
                            + (f" in {where}" if where else "")
                            + (f" (from the error in {src[0]})" if src else "")
                            + " (copied, or two slips that cancel?)"
                        )
        elif j.status == "correct-by-convention":
            message = j.convention or ""
        status = j.status
        line, column = reported_at(self.sub, eq, findings) if eq.latex else (eq.line, eq.column)
        if status == "follows-from-earlier-error" and ref.key != "tau" and relation_holds(self, eq, exp_shown):
            status = "correct"  # a relation between steps that holds: what it names carries the error
            message = f"right as a relation between steps; the value it names {message}"
        if findings:
            status, message, difference, components, caused_by = with_members(
                findings, (status, message, difference, components, caused_by), _matrix(to_sympy(as_written)), self
            )
        self.verdicts.append(
            StepVerdict(
                name=name,
                key=ref.key,
                link=link,
                status=status,
                label=eq.lhs,
                source=eq.source,
                line=line,
                column=column,
                expected=exp_shown,
                got=value,
                difference=difference,
                components=components,
                convention=j.convention,
                caused_by=caused_by,
                message=message,
                frame="" if ref.key not in VECTOR_KEYS else str(ref.frame if ref.frame is not None else ref.index),
            )
        )

    def _describe(self, got, ref) -> str:
        """What differs, in the student's shorthand."""
        return describe(got, ref, self.robot, self.sampler, shorthand=self.symbols.shorthand)

    def _order(self, name: str) -> int:
        for k, v in enumerate(self.verdicts):
            if v.name == name:
                return k
        return len(self.verdicts)


def _tidied(value, robot):
    """A value as shown: each entry simplified (a convention's added terms cancel)."""
    return value.applyfunc(lambda x: tidy(x, robot)) if isinstance(value, sp.MatrixBase) else tidy(value, robot)


def _matrix(value) -> sp.Matrix:
    return value if isinstance(value, sp.MatrixBase) else sp.Matrix([[value]])
