"""The grader's handling of the textbooks' energy-method vocabulary (a mixin of
:class:`armdyn.grading.grader.Grader`): names whose step depends on the value's shape
(:func:`.vocabulary.by_shape`), the quantities checked directly against the model
(:mod:`.lagrange_terms`), the joint torques given as one column, and the equations of
motion stated in matrix form."""

from __future__ import annotations

import sympy as sp

from ..errors import ModelError
from .defined import definition
from .engine import equal
from .explain import describe, tidy
from .lagrange_terms import ModelTerms, grade_model_step, potential_shift
from .notation import StepRef
from .shorthand import grade_shorthand, shorthand_reading
from .text import NOT_A_STEP
from .verdict import PASSING, StepVerdict
from .vocabulary import MODEL_KEYS, POINT, SOFT, by_shape, student_names

#: the steps whose values the matrix form M q̈ + C q̇ + g = τ states
_MATRICES = ("M", "C", "h", "G", "christoffel")
#: the partial derivatives of the energies (of L, T by q and q̇, V by q)
_PARTIALS = ("dL_dqd", "ddt_dL_dqd", "dL_dq", "dT_dq", "dV_dq")


class EnergySteps:
    """Mixin: needs ``robot``, ``sampler``, ``symbols``, ``verdicts``, ``value``,
    ``world``, ``_unrecognised``, ``_step`` of the grader."""

    def model_terms(self) -> ModelTerms:
        """The model's energy-method quantities (mass centres, M, C, g...), built once."""
        if getattr(self, "_model_terms", None) is None:
            world = self.world("newton-euler")
            ne = {ref: world.expected[ref].sym() for ref in world.method.refs if ref[0] == "omega"}
            self._model_terms = ModelTerms(self.robot, world.ctx, ne)
        return self._model_terms

    def _vocabulary(self, ref: StepRef, eq, seen_methods: list):
        """(the step ``ref`` names, what was assumed), or (None, "") when the equation was
        graded here (an energy-method quantity) or could not be."""
        assumed = ""
        if ref.key == "ae":  # Spong's a_{e,i}: the end of link i, a frame origin of the model
            ref, assumed = self._end_of_link_frame(ref, eq)
            if ref is None:
                return None, ""
        # which step it is depends on the value's shape (a frame written, or YAML: a vector)
        if ref.by_shape or (ref.key in ("omega", "f", "tau") and ref.frame is None and eq.latex):
            ref, assumed = self._by_shape(ref, eq)
            if ref is None:
                return None, ""
        if ref.key in _PARTIALS:
            if ref.index is None:  # ∂k/∂Θ: the column of partials, one per joint
                self._partial_column(ref, eq, seen_methods)
                return None, ""
            if ref.alias and ref.key.startswith(("dL_", "ddt_dL_")):
                assumed = f"∂{ref.alias}/∂q̇ read as ∂L/∂q̇ (the potential energy does not depend on the velocities)"
        if ref.key == "gvec":
            self._gravity_in_frame(ref, eq, assumed)
            return None, ""
        if ref.key == "shorthand":
            value, _ = self.value(eq, ref)
            self.verdicts.append(grade_shorthand(ref, eq, value, self.robot, self.sampler))
            return None, ""
        if ref.key in MODEL_KEYS or ref.key in ("Lang", "tau_vec"):
            if "lagrange" not in seen_methods:
                seen_methods.append("lagrange")
            self._model_step(ref, eq, assumed)
            return None, ""
        return ref, assumed

    def _by_shape(self, ref: StepRef, eq):
        """(the reading of ``ref`` its value's shape gives, what was assumed); (None, _)
        after recording an unrecognised equation."""
        probe = StepRef(ref.key, ref.index, ref.frame, ref.alias, ref.part, ref.entry, True, ref.sign)
        soft = ref.key in SOFT and not ref.entry  # a bare M, C, G, h: unnamed unless its value is a matrix or vector
        try:
            value, problem = self.value(eq, probe)
        except ModelError as err:
            if not soft:
                raise
            value, problem = None, f"{NOT_A_STEP}; read as the {ref.name} of the method: {err.message}"
        if value is None:
            self._unrecognised(eq, problem, name="" if soft else ref.name, key="" if soft else ref.key)
            return None, ""
        prismatic = None
        if ref.key == "f" and ref.index is not None and 1 <= ref.index <= self.robot.dof:
            prismatic = _prismatic(self.robot, ref.index)
        if ref.key == "shorthand":  # c_1 = \cos\theta_1, or a Coriolis term by its value
            new, assumed = shorthand_reading(ref, value, self.robot, lambda key, **kw: StepRef(key, **kw))
            if new is None:
                self._unrecognised(eq, assumed)
            return new, assumed
        rates = {*self.robot.q, *self.robot.qd}
        moves = bool(rates & value.free_symbols) if isinstance(value, sp.Basic) else True
        if (
            ref.key == "Vl"
            and ref.alias == "u"
            and isinstance(value, sp.Expr)
            and set(self.robot.qdd) & value.free_symbols
        ):
            # u_k holding joint accelerations: the commanded torque of the Rome course (De Luca), not an energy
            return StepRef("tau", ref.index), (
                f"u_{ref.index} read as joint {ref.index}'s input torque or force τ_{ref.index} "
                "(its value holds joint accelerations; a potential energy u_i does not)"
            )
        new, assumed = by_shape(
            ref, value, lambda key, index=None, **kw: StepRef(key, index, **kw), prismatic, self.robot.dof, moves
        )
        if new is None:
            named = assumed != NOT_A_STEP
            if not named:  # a bare h = (scalar), a constant x_1: the student's own name, used later
                assumed = definition(self, eq) or assumed
            self._unrecognised(eq, assumed, name=ref.name if named else "", key=ref.key if named else "")
            return None, ""
        return new, assumed

    def _model_step(self, ref: StepRef, eq, assumed: str) -> None:
        """Grade an energy-method quantity (or the torques as one column)."""
        value, problem = self.value(eq, ref)
        if value is None:
            self._unrecognised(eq, problem, name=ref.name, key=ref.key)
            return
        if ref.key == "tau_vec":
            self._torque_column(ref, eq, value)
            return
        verdict = grade_model_step(self, ref, eq, value)
        if verdict.status == "wrong" and ref.alias == POINT and ref.key == "pc":
            self._end_of_link(ref, value, verdict)
        if verdict.status == "wrong" and ref.alias == POINT and ref.part == "speed":
            self._speed_of_joint(ref, value, verdict)
        if assumed:
            verdict.message = assumed + ("; " + verdict.message if verdict.message else "")
        self.verdicts.append(verdict)
        if ref.key in ("Tl", "Vl") and not isinstance(value, sp.MatrixBase):
            for name in student_names(ref):
                self.symbols.steps[name] = value

    def _partial_column(self, ref: StepRef, eq, seen_methods: list) -> None:
        """``\\frac{\\partial k}{\\partial\\dot\\Theta} = (...)``: each entry graded as its joint's partial."""
        if "lagrange" not in seen_methods:
            seen_methods.append("lagrange")
        value, problem = self.value(eq, StepRef(ref.key, alias=ref.alias, by_shape=True))
        n = self.robot.dof
        if value is not None and n == 1 and not isinstance(value, sp.MatrixBase):
            value = sp.Matrix([value])  # one joint: the column is one entry
        if value is not None and (not isinstance(value, sp.MatrixBase) or len(value) != n or min(value.shape) != 1):
            value, problem = None, f"{ref.name}: a partial by the joint vector is a column of {n} entries"
        if value is None:
            self._unrecognised(eq, problem, name=ref.name, key=ref.key)
            return
        for k in range(n):
            self._step(self.world("lagrange"), StepRef(ref.key, k + 1, alias=ref.alias), eq, value[k], "lagrange")
            self.verdicts[-1].message = f"entry {k + 1} of the column, read as joint {k + 1}'s partial" + (
                "; " + self.verdicts[-1].message if self.verdicts[-1].message else ""
            )

    def _end_of_link(self, ref: StepRef, value, verdict) -> None:
        """``x_1`` that is not link 1's mass centre but its far end (frame 2's origin, where
        the next joint sits): right for that point, and said so."""
        origins = self.model_terms().origins
        i, axis = ref.index, "xyz".index(ref.part)
        if i + 1 not in origins or not isinstance(value, sp.Basic):
            return
        fp = self.sampler.fingerprint
        if equal(fp(value), fp(origins[i + 1][axis])).all():
            verdict.status, verdict.difference, verdict.components = "correct", None, []
            verdict.message = (
                f"{ref.part}_{i} read as the end of link {i} (frame {i + 1}'s origin, joint {i + 1}), "
                f"not its mass centre: right for that point"
            )

    def _speed_of_joint(self, ref: StepRef, value, verdict) -> None:
        """``v_i`` that is not link i's mass-centre speed but that of frame i's or i+1's origin (a
        joint: Craig's v_i): right for that point, and said so."""
        from .named import time_derivative

        origins, fp = self.model_terms().origins, self.sampler.fingerprint
        for k in (ref.index, ref.index + 1):
            if k in origins and isinstance(value, sp.Basic):
                v = time_derivative(origins[k], self.robot)
                if equal(fp(value**2), fp((v.T * v)[0, 0])).all():
                    verdict.status, verdict.difference, verdict.components = "correct", None, []
                    verdict.message = (
                        f"v_{ref.index} read as the speed of frame {k}'s origin (joint {k}), "
                        f"not link {ref.index}'s mass centre: right for that point"
                    )
                    return

    def _end_of_link_frame(self, ref: StepRef, eq):
        """(Spong's ``a_{e,i}`` as the model's step, what was assumed): the end of link i is
        the origin of the one frame that link i carries (joint i+1's, or the flange's), and
        its acceleration is that frame's v̇, written in frame i (or the frame given)."""
        ctx = self.world("newton-euler").ctx
        n = len(self.robot.links) - 1
        i = ref.index
        kids = ctx[i]["children"] if i is not None and 1 <= i <= n else []
        if len(kids) != 1:
            why = "has no link beyond it" if not kids else "carries more than one frame"
            problem = f"a_e{i}: the end of link {i} is not one frame's origin of '{self.robot.name}' (link {i} {why})"
            if i is None or not 1 <= i <= n:
                problem = f"a_e{i} names link {i}, but '{self.robot.name}' has links 1..{n}"
            self._unrecognised(eq, self._refuse(eq, problem, column=False), name=f"a_e{i}", key="ae")
            return None, ""
        frame = i if ref.frame is None else ref.frame
        point = f"joint {kids[0]}" if kids[0] <= self.robot.dof else "the flange"
        return StepRef("v_dot", kids[0], frame), (
            f"a_e{i} read as the acceleration of the end of link {i}: frame {kids[0]}'s origin "
            f"({point}), v̇_{kids[0]}, written in frame {frame}"
        )

    def _gravity_in_frame(self, ref: StepRef, eq, assumed: str) -> None:
        """Spong's ``g_i``: the gravity vector written in frame i (R_0^i g_0)."""
        value, problem = self.value(eq, StepRef("gvec", ref.index, ref.frame, by_shape=True))
        n = len(self.robot.links) - 1
        if value is not None and not 0 <= ref.index <= n:
            value, problem = None, self._refuse(eq, f"g_{ref.index}: frame {ref.index} does not exist (frames 0..{n})")
        if value is None:
            self._unrecognised(eq, problem, name=f"g_{ref.index}", key="gvec")
            return
        ctx = self.world("newton-euler").ctx
        frame = ref.index if ref.frame is None else ref.frame
        expected = sp.Matrix(ctx["R0"][frame].T * ctx["gravity"]).applyfunc(lambda x: tidy(x, self.robot))
        fp = self.sampler.fingerprint
        ok = equal(fp(value), fp(expected)).ravel()
        status, convention, message = "correct", None, ""
        if not ok.all() and equal(fp(value), fp(-expected)).all():
            status = "correct-by-convention"
            convention = message = "the base acceleration −g (Craig's v̇_0 = −g), not gravity itself"
        bad = [k for k in range(3) if not ok[k]] if status == "wrong" or not ok.all() and not convention else []
        if bad:
            status = "wrong"
            message = "; ".join(
                f"{describe(value[k], expected[k], self.robot, self.sampler)} in {'xyz'[k]}" for k in bad
            )
            message += f" (gravity in frame {frame})"
        message = assumed + ("; " + message if message else "")
        self.verdicts.append(
            StepVerdict(
                name=f"g_{ref.index}",
                key="gvec",
                link="",
                status=status,
                label=eq.lhs,
                source=eq.source,
                line=eq.line,
                expected=expected,
                got=value,
                difference=(value - expected) if bad else None,
                components=bad,
                convention=convention,
                message=message,
                frame=str(frame),
            )
        )

    def _torque_column(self, ref: StepRef, eq, value) -> None:
        """``(\\tau_1, \\tau_2)^T = ...``: each entry graded as its joint's τ_k."""
        n = self.robot.dof
        if not isinstance(value, sp.MatrixBase) or len(value) != n or min(value.shape) != 1:
            self._unrecognised(eq, f"τ as a column has {n} entries (one per joint)", name="tau", key="tau")
            return
        method = "lagrange" if "lagrange" in [v.key for v in self.verdicts[-1:]] else None
        method = method or ("lagrange" if any(v.key in ("T", "V", "L", "M") for v in self.verdicts) else "newton-euler")
        for k in range(n):
            self._step(self.world(method), StepRef("tau", k + 1), eq, value[k], method)

    def _adjust(self, ref: StepRef, value, assumed: str):
        """(value as the method's step, what was assumed, a potential energy's constant):
        ``-∂L/∂q_k`` negated back; a potential energy or Lagrangian that differs from the
        model's by a constant shifted to the model's reference level."""
        if ref.sign == -1:
            value = -value
            assumed = "read as the negated partial (the sign moved across)"
        shift = None
        if ref.key in ("V", "L"):
            expected = self.world("lagrange").expected[(ref.key, None)].sym()
            shift = potential_shift(value, expected, [*self.robot.q, *self.robot.qd], self.sampler)
            if shift is not None:
                value = value - shift
        return value, assumed, shift

    def _note(self, assumed: str, shift) -> None:
        """Add what was assumed (and a potential energy's reference level) to the last verdict."""
        v = self.verdicts[-1] if self.verdicts else None
        if v is None:
            return
        if shift is not None:
            level = f"another reference level for the potential energy (yours = the model's + {shift})"
            if v.status == "correct":
                v.status, v.convention = "correct-by-convention", level
            v.message = level + ("; " + v.message if v.message else "")
        if assumed:
            same = v.message == v.convention  # the convention is shown beside the status already
            v.message = assumed + ("; " + v.message if v.message and not same else "")

    def _matrix_form(self, eq) -> None:
        """``M q̈ + C q̇ + g = τ`` stated: right when every matrix given before it is, else
        it follows from the first wrong one."""
        latest: dict = {}  # each matrix as last graded (one that could not be read says nothing)
        for v in self.verdicts:
            if v.key in _MATRICES and v.status != "unrecognised":
                latest[v.name] = v
        given = list(latest.values())
        bad = [v for v in given if v.status not in PASSING]
        caused_by = None
        if bad:  # the law is stated right; it inherits the wrong matrices
            status, caused_by = "follows-from-earlier-error", bad[0].name
            message = f"follows from the error in {caused_by}: the matrices given earlier are not all right: " + (
                ", ".join(f"{v.name} (line {v.line})" for v in bad[:4])
            )
        else:
            status = "correct"
            message = (
                "the equations of motion in matrix form, with the matrices given earlier"
                if given
                else "the equations of motion in matrix form (no matrix given before it to check)"
            )
        self.verdicts.append(
            StepVerdict(
                name="matrix_form",
                key="law",
                link="",
                status=status,
                label=eq.lhs,
                source=eq.source,
                line=eq.line,
                message=message,
                caused_by=caused_by,
            )
        )


def _prismatic(robot, k: int) -> bool:
    """Is the joint of coordinate k (1-based) prismatic?"""
    for joint in robot.joints:
        if robot.coordinate_index(joint) == k - 1:
            return joint.type == "prismatic"
    return False
