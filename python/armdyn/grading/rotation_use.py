"""A rotation decided by how it is used.

A rotation ``R_a^b`` written transposed is Craig's other reading of the name (the columns
are frame b's axes in frame a) only when the student goes on to use it that way. When a
later step is exactly what the method gives with the matrix as written mapping frame-a
coordinates to frame b, the transposition is a slip: the rotation is ``wrong`` (said with
the step that used it) and that step follows from it. A wrong rotation is carried the
same way, so the steps it feeds are not slips of their own.
"""

from __future__ import annotations

import sympy as sp

from .explain import component_name, tidy


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
