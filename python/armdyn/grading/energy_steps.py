"""The grader's handling of the textbooks' energy-method vocabulary (a mixin of
:class:`armdyn.grading.grader._Grader`): names whose step depends on the value's shape
(:func:`.vocabulary.by_shape`), the quantities checked directly against the model
(:mod:`.lagrange_terms`), the joint torques given as one column, and the equations of
motion stated in matrix form."""

from __future__ import annotations

import sympy as sp

from ..errors import ModelError
from .defined import definition
from .lagrange_terms import ModelTerms, grade_model_step, potential_shift
from .notation import StepRef
from .text import NOT_A_STEP
from .verdict import PASSING, StepVerdict
from .vocabulary import MODEL_KEYS, SOFT, by_shape, student_names

#: the steps whose values the matrix form M q̈ + C q̇ + g = τ states
_MATRICES = ("M", "C", "h", "G", "christoffel")


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
        # which step it is depends on the value's shape (a frame written, or YAML: a vector)
        if ref.by_shape or (ref.key in ("omega", "f") and ref.frame is None and eq.latex):
            ref, assumed = self._by_shape(ref, eq)
            if ref is None:
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
        soft = ref.key in SOFT  # a bare M, C, G, h: unnamed unless its value is a matrix or vector
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
        new, assumed = by_shape(
            ref, value, lambda key, index=None, **kw: StepRef(key, index, **kw), prismatic, self.robot.dof
        )
        if new is None:
            named = not (soft and assumed == NOT_A_STEP)
            if not named:  # a bare h = (scalar): the student's own name, used in later values
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
        if assumed:
            verdict.message = assumed + ("; " + verdict.message if verdict.message else "")
        self.verdicts.append(verdict)
        if ref.key in ("Tl", "Vl") and not isinstance(value, sp.MatrixBase):
            for name in student_names(ref):
                self.symbols.steps[name] = value

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
            v.message = assumed + ("; " + v.message if v.message else "")

    def _matrix_form(self, eq) -> None:
        """``M q̈ + C q̇ + g = τ`` stated: right when every matrix given before it is, else
        it follows from the first wrong one."""
        given = [v for v in self.verdicts if v.key in _MATRICES]
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
