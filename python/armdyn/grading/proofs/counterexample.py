"""A counterexample a student can check by hand: the smallest body found on which the two
sides of a wrong link differ, with both values.

Small bodies (:func:`.body.small_instances`: two, then three point masses of mass 1 to 3 at
small integer points with the mass center at integer coordinates, small integer vectors,
quarter turns about a coordinate axis) are tried first, simplest first; if none separates
the sides the random instance on which the link failed is shown instead.
"""

from __future__ import annotations

from ..latex import LatexError
from .body import Instance, small_instances
from .evaluate import NeedElement
from .matrices import Mat, ShapeError

#: small bodies tried before falling back to the random one
TRIES = 120


def _differs(a: Mat, b: Mat) -> bool:
    if a.shape == b.shape:
        return a != b
    return any(a.v) or any(b.v)


def _example(inst: Instance, pairs) -> dict | None:
    for k, a, b in pairs:
        if _differs(a, b):
            data = inst.describe()
            data["rotation_text"] = dict(inst.rotation_text)
            data["element"] = k
            data["left"] = a.tolist()
            data["right"] = b.tolist()
            return {"data": data, "left_value": a, "right_value": b}
    return None


def find(pairs_of, fallback: Instance, extra=None) -> dict | None:
    """The first small instance where ``pairs_of(instance)`` (a list of (element, left,
    right) values) has two different sides, else the fallback instance's, else None.
    ``extra(instance) -> dict`` adds the values of names the proof defined (``d``)."""
    for inst in small_instances(TRIES):
        try:
            found = _example(inst, pairs_of(inst))
        except (ArithmeticError, ShapeError, LatexError, NeedElement):
            continue
        if found is not None:
            if extra is not None:
                found["data"]["defined"] = extra(inst)
            return found
    found = _example(fallback, pairs_of(fallback))
    if found is not None and extra is not None:
        found["data"]["defined"] = extra(fallback)
    return found


def _vec(v) -> str:
    if isinstance(v, list) and v and isinstance(v[0], list):
        return "[" + "; ".join(" ".join(row) for row in v) + "]"
    if isinstance(v, list):
        return "(" + ", ".join(v) + ")"
    return str(v)


def sentence(example: dict) -> str:
    """The counterexample in one line of plain text."""
    d = example["data"]
    parts = ["masses " + ", ".join(d["masses"]) + " at " + ", ".join(_vec(p) for p in d["points"])]
    named = {k: v for k, v in d["named_points"].items()}
    if "C" in named:
        parts.append("mass center C = " + _vec(named.pop("C")))
    for name, value in named.items():
        shown = f"reference point of r_{name[4:]}" if name.startswith("ref:") else f"point {name}"
        parts.append(f"{shown} = {_vec(value)}")
    for name, value in d["vectors"].items():
        parts.append(f"{name} = {_vec(value)}")
    for name, value in d.get("defined", {}).items():
        parts.append(f"{name} = {_vec(value)}")
    for label, value in d["rotations"].items():
        text = d["rotation_text"].get(label)
        parts.append(f"R{'^' + label if label else ''} = " + (text or _vec(value)))
    if d["element"] is not None:
        parts.append(f"for the mass element at {_vec(d['points'][d['element']])}")
    parts.append(f"left side = {_vec(d['left'])}, right side = {_vec(d['right'])}")
    return "; ".join(parts)
