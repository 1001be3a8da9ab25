"""Numeric checks and small geometry for reading a robot from a text; the YAML writing."""

from __future__ import annotations

import os
import random
import re

import symengine as se
import sympy as sp

from .statements import Statement


def same(a, b, symbols=(), trials: int = 3) -> bool:
    """a == b at random values of every symbol in them (both scalars or both matrices of one
    shape), evaluated with SymEngine; a value that is not a finite number never passes."""
    diff = a - b
    items = list(diff) if isinstance(diff, sp.MatrixBase) else [diff]
    free = sorted(set(symbols).union(*(sp.sympify(x).free_symbols for x in items)), key=str)
    try:
        exprs = [se.sympify(x) for x in items]
    except (TypeError, ValueError, RuntimeError):
        return False
    for seed in range(trials):
        rng = random.Random(seed)
        at = {se.Symbol(s.name): rng.uniform(0.3, 1.7) for s in free}
        for e in exprs:
            try:
                if not abs(complex(e.subs(at))) < 1e-8:
                    return False
            except (TypeError, ValueError, RuntimeError, OverflowError):
                return False
    return True


def rotation_ok(m, symbols) -> bool:
    return isinstance(m, sp.MatrixBase) and m.shape == (3, 3) and same(m.T * m, sp.eye(3), symbols)


def vector(value) -> sp.Matrix | None:
    if value == 0 and not isinstance(value, sp.MatrixBase):
        return sp.zeros(3, 1)
    if isinstance(value, sp.MatrixBase) and value.shape in ((3, 1), (1, 3)):
        return sp.Matrix(value).reshape(3, 1)
    if isinstance(value, sp.MatrixBase) and value.shape in ((2, 1), (1, 2)):
        return sp.Matrix([value[0], value[1], 0])
    return None


def rz(angle) -> sp.Matrix:
    c, s = sp.cos(angle), sp.sin(angle)
    return sp.Matrix([[c, -s, 0], [s, c, 0], [0, 0, 1]])


def across(height: sp.Expr, revolute: set) -> sp.Expr:
    """The in-plane coordinate across the height: ``a sin(phi) + b cos(phi)`` -> ``a cos(phi) - b sin(phi)``."""
    total = sp.Integer(0)
    for term in sp.Add.make_args(sp.expand(height)):
        trig = [f for f in sp.Mul.make_args(term) if isinstance(f, (sp.sin, sp.cos))]
        if len(trig) > 1:
            raise ValueError("a product of sines and cosines")
        if not trig:
            if term.free_symbols & revolute:
                raise ValueError("a joint angle outside a sine or cosine")
            continue
        f = trig[0]
        rest = term / f
        total += rest * (sp.cos(f.args[0]) if isinstance(f, sp.sin) else -sp.sin(f.args[0]))
    return total


def frame_of(st: Statement, default: int) -> int:
    return default if st.frame is None else st.frame


def rot_into(R0, frm: int, to: int) -> sp.Matrix:
    """The rotation taking frame-``frm`` coordinates to frame ``to``."""
    return R0[to].T * R0[frm]


def axis_angle(axis, angle) -> sp.Matrix:
    x, y, z = axis
    K = sp.Matrix([[0, -z, y], [z, 0, -x], [-y, x, 0]])
    return sp.eye(3) + sp.sin(angle) * K + (1 - sp.cos(angle)) * K * K


def yaml_expr(e) -> str:
    text = str(sp.nsimplify(e) if e.is_Float else e)
    return text if re.fullmatch(r"-?[\w.]+", text) else f'"{text}"'


def yaml_vec(v) -> str:
    return "[" + ", ".join(yaml_expr(c) for c in v) + "]"


def yaml_matrix(m) -> str:
    return "[" + ", ".join(yaml_vec(m.row(i)) for i in range(3)) + "]"


def pretty_vector(v) -> str:
    return "(" + ", ".join(str(c) for c in v) + ")"


def model_name(path: str) -> str:
    stem = re.sub(r"[^A-Za-z0-9_-]", "-", os.path.splitext(os.path.basename(path))[0])[:40] or "submission"
    return f"{stem}-from-text"
