"""Inertia tensors: parallel axis theorem, change of frame, primitives, combining
bodies and a physical-validity check.

Every function works symbolically and numerically and returns the kind it was given:
if any argument holds a SymPy object the result is SymPy (``sp.Matrix`` (3, 3) tensors,
(3, 1) vectors, ``sp.Expr`` scalars); otherwise it is NumPy (float64 arrays (3, 3) and
(3,), Python floats). Symbolic results are left unsimplified (no blanket ``simplify``).

Definitions (all tensors in kg m^2, positions in m):

* The inertia about a point O is ``I_O = sum m (|r|^2 1 - r r^T)`` over the mass
  elements, ``r`` measured from O.
* ``R`` (3x3) maps frame B to frame A: its columns are B's axes in A coordinates, so a
  vector changes frame as ``v_A = R v_B`` and a tensor as ``I_A = R I_B R^T``.

This module does not import ``armdyn.model`` so that the model can import it.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from typing import Any, Iterable

import numpy as np
import sympy as sp

from .errors import ModelError

# ----------------------------------------------------------------- kind helpers


def _is_symbolic(value) -> bool:
    """True if ``value`` is, or contains, a SymPy object."""
    if isinstance(value, (sp.Basic, sp.MatrixBase)):
        return True
    if isinstance(value, np.ndarray):
        return value.dtype == object and any(isinstance(v, sp.Basic) for v in value.flat)
    if isinstance(value, (list, tuple)):
        return any(_is_symbolic(v) for v in value)
    return False


def _any_symbolic(*values) -> bool:
    return any(_is_symbolic(v) for v in values)


def _scalar(x, sym: bool):
    return sp.sympify(x) if sym else float(x)


def _vec(v, sym: bool, what: str = "vector"):
    """(3, 1) sp.Matrix if ``sym`` else (3,) float array."""
    if sym:
        m = sp.Matrix(v)
        m = m.T if m.shape == (1, 3) else m
        if m.shape != (3, 1):
            raise ValueError(f"{what} must have 3 components, got shape {m.shape}")
        return m
    a = np.asarray(v, dtype=float)
    if a.size != 3 or a.ndim > 2:
        raise ValueError(f"{what} must have 3 components, got shape {a.shape}")
    return a.reshape(3)


def _mat(m, sym: bool, what: str = "inertia"):
    """(3, 3) sp.Matrix if ``sym`` else (3, 3) float array."""
    out = sp.Matrix(m) if sym else np.asarray(m, dtype=float)
    if out.shape != (3, 3):
        raise ValueError(f"{what} must be 3x3, got shape {out.shape}")
    return out


def _eye(sym: bool):
    return sp.eye(3) if sym else np.eye(3)


def _zeros(sym: bool):
    return sp.zeros(3, 3) if sym else np.zeros((3, 3))


def _diag(a, b, c, sym: bool):
    return sp.diag(a, b, c) if sym else np.diag([float(a), float(b), float(c)])


def _dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def _half(sym: bool):
    return sp.Rational(1, 2) if sym else 0.5


def _frac(p: int, q: int, sym: bool):
    return sp.Rational(p, q) if sym else p / q


# ----------------------------------------------------- parallel axis theorem


def point_inertia(mass, r):
    """Inertia (3x3) about the origin of a point ``mass`` at ``r`` (3,):
    ``m (|r|^2 1 - r r^T)``. It is also the parallel-axis term for an offset ``r``."""
    sym = _any_symbolic(mass, r)
    r = _vec(r, sym, "r")
    outer = r * r.T if sym else np.outer(r, r)
    return _scalar(mass, sym) * (_dot(r, r) * _eye(sym) - outer)


def parallel_axis(I_com, mass, d):
    """Inertia about the point P = C + ``d`` from the inertia ``I_com`` about the centre
    of mass C: ``I_P = I_C + m (|d|^2 1 - d d^T)`` (Steiner). Same axes throughout."""
    sym = _any_symbolic(I_com, mass, d)
    return _mat(I_com, sym) + point_inertia(_scalar(mass, sym), _vec(d, sym, "d"))


def to_com(I_P, mass, d):
    """The way back: inertia about the centre of mass C from the inertia ``I_P`` about
    P = C + ``d``: ``I_C = I_P - m (|d|^2 1 - d d^T)``."""
    sym = _any_symbolic(I_P, mass, d)
    return _mat(I_P, sym) - point_inertia(_scalar(mass, sym), _vec(d, sym, "d"))


def shift(I_Q, mass, com, q, p):
    """Inertia about point ``p`` from the inertia ``I_Q`` about point ``q``, for a body
    of ``mass`` with centre of mass ``com``; all three points (3,) in one frame.
    Goes through the centre of mass: ``I_P = I_Q - m K(q - com) + m K(p - com)``,
    ``K(v) = |v|^2 1 - v v^T``."""
    sym = _any_symbolic(I_Q, mass, com, q, p)
    com, q, p = (_vec(v, sym) for v in (com, q, p))
    return parallel_axis(to_com(_mat(I_Q, sym), mass, q - com), mass, p - com)


# ---------------------------------------------------------------- change of frame


def rotate(I, R):
    """The tensor ``I`` (3x3, in frame B) expressed in frame A: ``I_A = R I_B R^T``,
    where ``R`` (3x3) has B's axes as columns in A coordinates (``v_A = R v_B``)."""
    sym = _any_symbolic(I, R)
    R = _mat(R, sym, "R")
    return R @ _mat(I, sym) @ R.T


def rotational_energy(I, omega):
    """``1/2 omega^T I omega``: ``I`` (3x3) about the centre of mass and the angular
    velocity ``omega`` (3,) in the same frame. Invariant under a change of frame."""
    sym = _any_symbolic(I, omega)
    w = _vec(omega, sym, "omega")
    return _half(sym) * _dot(w, _mat(I, sym) @ w)


# -------------------------------------------------------------------- primitives
# Inertia about the centre of mass, principal axes along the frame axes. Axisymmetric
# shapes take ``axis`` ('x', 'y' or 'z'): their symmetry axis.

_AXES = {"x": 0, "y": 1, "z": 2}


def _axisymmetric(axial, transverse, axis: str, sym: bool):
    if axis not in _AXES:
        raise ValueError(f"axis must be 'x', 'y' or 'z', got {axis!r}")
    moments = [transverse] * 3
    moments[_AXES[axis]] = axial
    return _diag(moments[0], moments[1], moments[2], sym)


def point_mass(m):
    """A point mass: the zero tensor (mass matters only through its position)."""
    return _zeros(_is_symbolic(m))


def rod(m, length, axis: str = "z"):
    """Thin rod of ``length`` along ``axis``: ``m L^2 / 12`` across, 0 along it."""
    sym = _any_symbolic(m, length)
    return _axisymmetric(0, _frac(1, 12, sym) * m * length**2, axis, sym)


def box(m, x, y, z):
    """Solid box with full side lengths ``x, y, z`` along the frame axes:
    ``diag(y^2 + z^2, x^2 + z^2, x^2 + y^2) m / 12``."""
    sym = _any_symbolic(m, x, y, z)
    k = _frac(1, 12, sym) * m
    return _diag(k * (y**2 + z**2), k * (x**2 + z**2), k * (x**2 + y**2), sym)


def cylinder(m, r, h, axis: str = "z", r_inner=0):
    """Solid cylinder of radius ``r`` and height ``h`` along ``axis``; a tube if
    ``r_inner`` > 0 (thin-walled as ``r_inner -> r``).
    Axial ``m (r^2 + ri^2) / 2``, transverse ``m (3 (r^2 + ri^2) + h^2) / 12``."""
    sym = _any_symbolic(m, r, h, r_inner)
    r2 = r**2 + r_inner**2
    return _axisymmetric(_half(sym) * m * r2, _frac(1, 12, sym) * m * (3 * r2 + h**2), axis, sym)


def sphere(m, r, hollow: bool = False):
    """Solid sphere ``2/5 m r^2`` or, with ``hollow``, thin spherical shell ``2/3 m r^2``."""
    sym = _any_symbolic(m, r)
    k = _frac(2, 3, sym) if hollow else _frac(2, 5, sym)
    moment = k * m * r**2
    return _diag(moment, moment, moment, sym)


# ------------------------------------------------------------------------ bodies


@dataclass(frozen=True, eq=False)
class Body:
    """A rigid body described in some frame.

    mass:    scalar.
    com:     centre of mass (3,) in the frame ((3, 1) sp.Matrix when symbolic).
    inertia: (3, 3) tensor about the centre of mass, in the frame's axes.
    """

    mass: Any
    com: Any
    inertia: Any

    @property
    def symbolic(self) -> bool:
        return _any_symbolic(self.mass, self.com, self.inertia)

    def as_kind(self, sym: bool) -> "Body":
        """The same body in SymPy (``sym``) or NumPy form."""
        return Body(_scalar(self.mass, sym), _vec(self.com, sym, "com"), _mat(self.inertia, sym))

    def in_frame(self, R, p) -> "Body":
        """The body described in frame A, given frame B (the current one) has axes ``R``
        (3x3, B's axes in A) and origin ``p`` (3,) in A: ``com_A = R com + p``,
        ``I_A = R I R^T``."""
        sym = _any_symbolic(self.mass, self.com, self.inertia, R, p)
        b = self.as_kind(sym)
        R = _mat(R, sym, "R")
        return Body(b.mass, R @ b.com + _vec(p, sym, "p"), rotate(b.inertia, R))

    def inertia_about(self, point):
        """Inertia (3x3) about ``point`` (3,), same frame: parallel axis theorem."""
        sym = _any_symbolic(self.mass, self.com, self.inertia, point)
        b = self.as_kind(sym)
        return parallel_axis(b.inertia, b.mass, _vec(point, sym, "point") - b.com)


def combine(bodies: Iterable[Body]) -> Body:
    """One body equal to rigidly joined ``bodies`` (all described in one common frame).

    Total mass; centre of mass the mass-weighted mean (the origin, 0, when the total
    mass is exactly zero; a symbolic total mass is divided by as it stands); inertia the
    sum of each body's inertia moved to the new centre of mass by the parallel axis
    theorem.
    """
    bodies = list(bodies)
    if not bodies:
        raise ValueError("combine() needs at least one body")
    sym = any(b.symbolic for b in bodies)
    bodies = [b.as_kind(sym) for b in bodies]
    mass = sum((b.mass for b in bodies), _scalar(0, sym))
    moment = sum((b.mass * b.com for b in bodies), _vec([0, 0, 0], sym))
    com = _vec([0, 0, 0], sym) if mass == 0 else moment / mass
    inertia = sum((b.inertia_about(com) for b in bodies), _zeros(sym))
    return Body(mass, com, inertia)


def kinetic_energy(body: Body, v_com, omega):
    """``1/2 m |v_com|^2 + 1/2 omega^T I omega``: velocity of the centre of mass and
    angular velocity (3,), both in the body's frame."""
    sym = _any_symbolic(body.mass, body.inertia, v_com, omega)
    v = _vec(v_com, sym, "v_com")
    return _half(sym) * _scalar(body.mass, sym) * _dot(v, v) + rotational_energy(body.inertia, omega)


# ------------------------------------------------------------ physical validity


def _fmt(x: float) -> str:
    return f"{x:.6g}"


def physical_violations(mass, inertia, rtol: float = 1e-6) -> list[str]:
    """What is physically wrong with a body of ``mass`` and ``inertia`` (3x3 about
    its centre of mass): a list of short messages, empty when all is well.

    Checks mass >= 0, inertia symmetric, positive semi-definite and the triangle
    inequality on the principal moments (eigenvalues; ``I1 + I2 >= I3`` for every
    permutation, which for sorted moments is ``I1 + I2 >= I3`` with I3 the largest).
    The diagonal-entry version of the triangle inequality is necessary but weaker.
    Tolerances are relative to the largest entry (``rtol``), so rounded file values of
    a thin plate (``Ixx + Iyy == Izz``) pass. A check that depends on free symbols is
    skipped (not reported).
    """
    out = []
    # float input (big numeric models) is checked without building SymPy objects
    mass = np.asarray(mass, dtype=float) if isinstance(mass, (float, np.ndarray)) else sp.sympify(mass)
    if isinstance(mass, np.ndarray) or not mass.free_symbols:
        m = complex(mass) if isinstance(mass, np.ndarray) else complex(mass.evalf())
        if m.imag != 0 or not np.isfinite(m.real):
            out.append(f"mass {mass} is not a finite real number")
        elif m.real < 0:
            out.append(f"mass {_fmt(m.real)} is negative")

    if isinstance(inertia, np.ndarray) and inertia.dtype == float:
        I = inertia
        if I.shape != (3, 3):
            return out + [f"inertia must be 3x3, got shape {I.shape}"]
    else:
        I = sp.Matrix(inertia)
        if I.shape != (3, 3):
            return out + [f"inertia must be 3x3, got shape {I.shape}"]
        if I.free_symbols:
            return out
    I = (
        I.astype(complex)
        if isinstance(I, np.ndarray)
        else np.array([complex(x) for x in I], dtype=complex).reshape(3, 3)
    )
    if np.any(I.imag != 0) or not np.all(np.isfinite(I.real)):
        return out + ["inertia has entries that are not finite real numbers"]
    I = I.real
    tol = rtol * np.abs(I).max()
    names = "xyz"
    for i, j in ((0, 1), (0, 2), (1, 2)):
        if abs(I[i, j] - I[j, i]) > tol:
            a, b = names[i] + names[j], names[j] + names[i]
            out.append(f"inertia is not symmetric: I{a} {_fmt(I[i, j])} != I{b} {_fmt(I[j, i])}")
    scale = np.abs(I).max()
    if scale == 0:
        return out
    # eigenvalues of the scaled tensor: entries near 1e308 must not overflow to inf
    moments = np.linalg.eigvalsh((I / scale + I.T / scale) / 2) * scale  # ascending
    listed = ", ".join(_fmt(x) for x in moments)
    if moments[0] < -tol:
        out.append(f"inertia is not positive semi-definite (principal moments {listed})")
    if moments[0] + moments[1] < moments[2] - tol:
        # name diagonal entries when the tensor is diagonal, principal moments otherwise
        if np.all(np.abs(I - np.diag(np.diag(I))) <= tol):
            a, b, c = (f"I{names[k] * 2}" for k in np.argsort(np.diag(I)))
        else:
            a, b, c = "I1", "I2", "I3"
        out.append(f"inertia breaks the triangle inequality: {a} + {b} < {c} (principal moments {listed})")
    return out


def check_physical(
    mass, inertia, where: str | None = None, source: str | None = None, strict: bool = True, rtol: float = 1e-6
):
    """Raise :class:`ModelError` (``strict``) or warn (``UserWarning``) if
    :func:`physical_violations` finds anything; ``where``/``source`` locate the message
    (e.g. ``"link 'l2'"``, ``"arm.yaml"``)."""
    problems = physical_violations(mass, inertia, rtol)
    if not problems:
        return
    err = ModelError("; ".join(problems), where, source)
    if strict:
        raise err
    warnings.warn(str(err), UserWarning, stacklevel=2)
