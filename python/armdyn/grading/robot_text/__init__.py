"""The robot a derivation describes, read from its own statements.

When no model is named (neither ``--robot`` nor the front matter's ``robot:``), the
submission's equations are read for what they state about the arm, and a model in
armdyn's YAML format (docs/model-format.md) is built from them:

- rotations between successive frames: ``R_a^b`` / ``{}^{b}_{a}R`` (maps frame-a
  coordinates to frame b, so frame b's axes in frame a are its transpose); a joint
  variable inside a rotation makes that joint revolute;
- positions: ``P_i^j`` (frame i's origin from frame i-1's, in frame j) and ``P_{C_i}^j``
  (link i's mass centre from frame i's origin, in frame j);
- gravity: the base acceleration ``\\dot v_0^0 = (0, g, 0)`` of Newton-Euler means gravity
  ``(0, -g, 0)``; a stated ``g = (-g, 0, 0)^T`` is gravity itself; else a sentence "gravity
  acts along -y0" (:mod:`.gravity`); several stated: each is read, the grading keeps the
  reading the text's steps agree with (:mod:`.support`);
- mass centres in the base frame: ``p_{ck}``, ``x_{ck}`` (``x_k``: a point mass), Craig's
  ``{}^{0}P_{C_k}``, or Spong's velocity Jacobians ``J_{v_{ck}}`` (:mod:`.energy`); DH
  tables in Markdown or LaTeX (:mod:`.dh`);
- Craig's ``{}^{i}P_{C_i}``, ``{}^{i}P_{i+1}`` and inertias used only in products: the
  constant vectors (and diagonal tensor) that give the text's own accelerations and ``N_i``
  (:mod:`.recursion`);
- the potential energy ``V = m_1 g h_1 + ...`` (each mass's height) of an energy-method
  derivation; for a planar arm whose joints turn about z, a height ``a sin(phi) + b cos(phi)``
  is the point ``Rz(phi) (a, b)`` (``a cos(phi) - b sin(phi)`` across);
- the kinetic energy ``T`` (and each link's ``T_k``/``K_k``): its ``I_k`` terms are link k's
  moment of inertia about z; the whole ``T`` is checked against the positions read;
- a text with proofs and no joint variable: an arm of no joints (its proofs need none).

A text whose robot cannot be read is graded on its own earlier values (:mod:`.own_values`).

Symbols keep the text's names (``l_1`` -> ``l1``, ``l_{c1}`` -> ``lc1``, ``\\theta_1`` ->
``theta1``). Nothing from the text is evaluated as code: the LaTeX is parsed by
:mod:`.latex`, unknown names become parameters. What is not stated is assumed and named
(:attr:`TextModel.assumptions`); statements that disagree are named with their lines
(:attr:`TextModel.conflicts`) and the reading most statements support is used.
"""

from __future__ import annotations

from ...errors import ModelError
from ..reader import Submission
from .reader import TextModel, TextReader
from .statements import MAX_FRAMES, MAX_INLINE

__all__ = ["MAX_FRAMES", "MAX_INLINE", "TextModel", "robot_from_text", "show_model"]


def robot_from_text(sub: Submission) -> TextModel:
    """The robot ``sub``'s own statements describe (see the module's docstring); a
    :class:`ModelError` naming the file when they do not fix one."""
    try:
        first = TextReader(sub)
        model = first.read()
        others = []  # the other readings the statements allow: other gravities, x_k or y_k
        for choice in range(1, min(first.gravity_options, 3)):
            others.append(TextReader(sub))
            others[-1].gravity_choice = choice
        for k in list(first.pair_choices)[:2]:
            others.append(TextReader(sub))
            others[-1].pair_choices = {k: True}
        for other in others:
            try:
                model.alternatives.append(other.read())
            except ModelError:
                continue
        return model
    except ModelError:
        raise
    except (ArithmeticError, TypeError, ValueError, AttributeError, IndexError, KeyError, RecursionError) as err:
        # a statement shaped like none the reading knows: one line, never a traceback
        what = " ".join(str(err).split())[:160] or type(err).__name__
        raise ModelError(f"cannot read the robot from the text: {what}", source=sub.path) from None


def show_model(sub: Submission, robot: str | None = None) -> str:
    """``armdyn grade --show-model``: the model read from the text as YAML (loadable with
    :func:`armdyn.load`), its assumptions and conflicts as comments; or, when a model is
    named, a line saying that one is used and the text's statements only checked."""
    named = robot or sub.robot
    if named:
        return f"# the model named ({named}) is used: the text's statements are checked as steps, not read\n"
    model = robot_from_text(sub)
    head = [f"# assumed: {a}" for a in model.assumptions]
    head += [f"# statements that disagree: {c}" for c in model.conflicts]
    return "\n".join(head) + ("\n" if head else "") + model.yaml
