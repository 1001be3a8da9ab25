"""Kinematics steps (a mixin of :class:`armdyn.grading.grader.Grader`): rotations
``R_a^b`` and positions ``P_i^j``, ``P_{C_i}^j``, checked against the model's frames
directly, and a rotation decided by how it is used.

A rotation ``R_a^b`` written transposed is Craig's other reading of the name (the columns
are frame b's axes in frame a) only when the student goes on to use it that way. When a
later step is exactly what the method gives with the matrix as written mapping frame-a
coordinates to frame b, the transposition is a slip: the rotation is ``wrong`` (said with
the step that used it) and that step follows from it. A wrong rotation is carried the
same way, so the steps it feeds are not slips of their own.
"""

from __future__ import annotations

import sympy as sp

from .engine import equal
from .explain import component_name, tidy
from .methods import position, rotation_between
from .notation import StepRef
from .verdict import StepVerdict


class KinematicsSteps:
    """Mixin: needs ``robot``, ``sampler``, ``verdicts``, ``world``, ``_describe`` of the grader."""

    def _rotation(self, ref: StepRef, eq, value):
        ctx = self.world("newton-euler").ctx
        assert ref.index is not None and ref.frame is not None  # _check_index ran
        expected = rotation_between(ctx, ref.index, ref.frame).applyfunc(lambda x: tidy(x, self.robot))
        fp = self.sampler.fingerprint
        got_fp = fp(value)
        status, conv, message = "correct", None, ""
        ok = equal(got_fp, fp(expected))
        if not ok.all():
            if equal(got_fp, fp(expected.T)).all():
                status = "correct-by-convention"
                conv = (
                    f"transposed: the columns are frame {ref.frame}'s axes in frame {ref.index} "
                    f"(R_{ref.index}^{ref.frame} here maps frame-{ref.index} coordinates to frame {ref.frame})"
                )
            else:
                status = "wrong"
                bad = [int(i) for i in range(9) if not ok.ravel()[i]]
                message = "; ".join(
                    f"{component_name(i, (3, 3))}: " + self._describe(value[i], expected[i]) for i in bad[:3]
                )
        self.verdicts.append(
            StepVerdict(
                name=ref.name,
                key="R",
                link="",
                status=status,
                label=eq.lhs,
                source=eq.source,
                line=eq.line,
                expected=expected,
                got=value,
                difference=None if status != "wrong" else value - expected,
                convention=conv,
                message=message or ("" if status == "correct" else conv or ""),
                frame=f"{ref.index}->{ref.frame}",
            )
        )
        carry_rotation(self.world("newton-euler"), ref.index, ref.frame, ref.name, value, status)

    def _position(self, ref: StepRef, eq, value):
        """A kinematics step: P_i^j, frame i's origin seen from frame i-1's, or P_{C_i}^j,
        link i's mass centre seen from frame i's origin, both written in frame j; Craig's
        ``{}^{j}P`` seen from frame j's origin. A right superscript j names only the frame,
        but a value that is the point seen from frame j's origin is read so, and said."""
        ctx = self.world("newton-euler").ctx
        vector, what, frame = position(ctx, ref.key, ref.index, ref.frame, ref.origin)
        expected = sp.Matrix(vector).applyfunc(lambda x: tidy(x, self.robot))
        fp = self.sampler.fingerprint
        ok = equal(fp(value), fp(expected)).ravel()
        bad = [int(i) for i in range(3) if not ok[i]]
        message = "; ".join(f"{self._describe(value[i], expected[i])} in {component_name(i, (3, 1))}" for i in bad)
        if bad:
            message += f" ({what}, in frame {frame})"
            if ref.origin is None and ref.frame is not None:  # P_{C_2}^0: the point in frame 0, as Craig's {}^{0}P?
                seen, craig, _ = position(ctx, ref.key, ref.index, ref.frame, ref.frame)
                if equal(fp(value), fp(seen)).all():
                    expected, bad = sp.Matrix(seen).applyfunc(lambda x: tidy(x, self.robot)), []
                    message = f"read as Craig's {{}}^{{{frame}}}P: {craig}, in frame {frame} (not {what})"
        self.verdicts.append(
            StepVerdict(
                name=ref.name,
                key=ref.key,
                link=list(self.robot.links)[ref.index],  # type: ignore[index]
                status="wrong" if bad else "correct",
                label=eq.lhs,
                source=eq.source,
                line=eq.line,
                expected=expected,
                got=value,
                difference=sp.Matrix([tidy(value[i] - expected[i], self.robot) for i in range(3)]) if bad else None,
                components=bad,
                message=message,
                frame=str(frame),
            )
        )


def carry_rotation(world, frm: int, to: int, name: str, value, status: str) -> None:
    """Let ``world``'s formulas also use the student's ``value`` of ``R_frm^to`` (step
    ``name``), when it turns one frame into its neighbour and is not the right one."""
    if status not in ("wrong", "correct-by-convention"):
        return
    ctx = world.ctx
    if isinstance(ctx.get(to), dict) and ctx[to]["parent"] == frm:  # parent -> child: ctx holds child -> parent
        world.use_rotation(name, to, sp.Matrix(value).T, confirmed=status == "wrong")
    elif isinstance(ctx.get(frm), dict) and ctx[frm]["parent"] == to:
        world.use_rotation(name, frm, sp.Matrix(value), confirmed=status == "wrong")


def confirm_used(verdicts: list, world, origins, step: str, line: int, robot) -> None:
    """``step`` (at ``line``) follows from ``origins``: a transposed rotation among them was
    used as written, so it is a slip (its verdict becomes ``wrong``, saying where it was used)."""
    for name in sorted(origins & world.unconfirmed):
        world.unconfirmed.discard(name)
        for v in verdicts:
            if v.key == "R" and v.name == name and v.status == "correct-by-convention":
                frm, to = v.frame.split("->")
                diff = sp.Matrix([tidy(x, robot) for x in v.got - v.expected]).reshape(3, 3)
                bad = [i for i in range(9) if diff[i] != 0]
                v.status, v.convention = "wrong", None
                v.difference, v.components = diff, bad
                v.message = (
                    f"written transposed (this is R_{to}^{frm}: its columns are frame {to}'s axes in frame {frm}), "
                    f"and used as written to map frame-{frm} coordinates to frame {to} in {step} (line {line}), "
                    f"which makes {step} wrong; R_{frm}^{to} is its transpose "
                    f"(wrong entries: {', '.join(component_name(i, (3, 3)) for i in bad[:4])})"
                )
