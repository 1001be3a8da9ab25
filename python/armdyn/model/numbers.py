"""Numbers in a model: exact (SymPy) when read, floats when computed with, built lazily.

A model read from a file keeps its numbers as float64 arrays (:class:`Numbers`) and builds
the SymPy form of a field only when it is read (``LazyField``), so a 10^4-joint URDF loads
in seconds; :func:`exact_number` turns a float into the rational or surd it stands for."""

from __future__ import annotations

import numpy as np
import sympy as sp

from ..errors import ModelError


def vec3(value, what: str) -> sp.Matrix:
    if isinstance(value, sp.MatrixBase) and value.shape == (3, 1):
        return sp.Matrix(value)  # entries are SymPy objects already (readers pass these)
    try:
        m = sp.Matrix(value)
    except Exception as exc:  # noqa: BLE001 - re-raised with context
        raise ModelError(f"{what} is not a 3-vector ({exc})") from None
    if m.shape == (1, 3):
        m = m.T
    if m.shape != (3, 1):
        raise ModelError(f"{what} must have 3 components, got shape {m.shape}")
    return m.applyfunc(sp.sympify)


def mat3(value, what: str) -> sp.Matrix:
    if isinstance(value, sp.MatrixBase) and value.shape == (3, 3):
        return sp.Matrix(value)
    try:
        m = sp.Matrix(value)
    except Exception as exc:  # noqa: BLE001
        raise ModelError(f"{what} is not a 3x3 matrix ({exc})") from None
    if m.shape != (3, 3):
        raise ModelError(f"{what} must be 3x3, got shape {m.shape}")
    return m.applyfunc(sp.sympify)


def is_zero(expr) -> bool | None:
    """True/False if decidable, None if it depends on free symbols."""
    expr = sp.sympify(expr)
    if expr.free_symbols:
        return None
    return bool(abs(complex(expr.evalf())) < 1e-12)


def exact_number(value: float) -> sp.Expr:
    """A float read from a file as SymPy: whole numbers exact (0 and 1 stay exact, which
    keeps zero tests and axis-aligned rotations exact), others as Float (all 53 bits)."""
    value = float(value)
    return sp.Integer(int(value)) if value.is_integer() and abs(value) < 2**53 else sp.Float(value)


class Numbers:
    """A numeric model field held as floats, its SymPy form built only when asked for.

    Readers of big numeric models (a URDF with 10^4 joints) pass these instead of SymPy
    matrices: building a SymPy ``Matrix``/``Float`` costs ~10 ms per joint, and the
    numeric engines never need it (they read :meth:`Joint.floats` / :meth:`Link.floats`).

    floats: array of the field's shape: ``()`` for a scalar, ``(3,)`` for a vector
            (``(3, 1)`` as SymPy), ``(3, 3)`` for a matrix. Must be finite.
    exact:  optional picklable zero-argument callable giving the SymPy form (e.g. a
            rotation with exact pi/2 angles); default :func:`exact_number` per entry.
    """

    __slots__ = ("floats", "exact")

    def __init__(self, floats, exact=None):
        f = np.array(floats, dtype=float)
        if not np.isfinite(f).all():
            raise ModelError(f"value {f.tolist()} is not finite")
        f.setflags(write=False)
        self.floats = f
        self.exact = exact

    def sympy(self):
        if self.exact is not None:
            return self.exact()
        f = self.floats
        if f.ndim == 0:
            return exact_number(f)
        rows, cols = (f.shape[0], 1) if f.ndim == 1 else f.shape
        return sp.Matrix(rows, cols, [exact_number(x) for x in f.ravel()])

    def __reduce__(self):
        return (Numbers, (self.floats, self.exact))


_DEFAULT = object()  # a lazy field not given: __post_init__ puts its default in


class LazyField:
    """Data descriptor for a numeric field of Link/Joint: the instance keeps what it was
    given (SymPy, or :class:`Numbers`) under the field's name and reading the attribute
    always gives SymPy, built from Numbers on first read and cached (``_sym_<name>``)."""

    def __init__(self, optional: bool = False):
        self.optional = optional  # an optional field's default is None

    def __set_name__(self, owner, name):
        self.name = name

    def __get__(self, obj, owner=None):
        if obj is None:
            return None if self.optional else _DEFAULT  # the dataclass default
        d = obj.__dict__
        raw = d[self.name]
        if not isinstance(raw, Numbers):
            return raw
        key = "_sym_" + self.name
        if key not in d:
            d[key] = raw.sympy()
        return d[key]

    def __set__(self, obj, value):
        obj.__dict__[self.name] = value


def field_floats(obj, name: str):
    """Float array of a Link/Joint field (shape () / (3,) / (3, 3)), None when it has
    free symbols; cached on the instance."""
    d = obj.__dict__
    raw = d[name]
    if isinstance(raw, Numbers):
        return raw.floats
    if raw is None:
        return None
    key = "_floats_" + name
    if key not in d:
        if raw.free_symbols:
            d[key] = None
        else:
            try:
                if isinstance(raw, sp.MatrixBase):  # (3, 1) -> (3,), (3, 3) stays
                    f = np.array([float(x) for x in raw], dtype=float).reshape(raw.shape)
                    f = f.reshape(-1) if raw.shape[1] == 1 else f
                else:
                    f = np.array(float(raw), dtype=float)
                f.setflags(write=False)
            except (TypeError, ValueError):
                f = None  # complex or not a number: the SymPy-side checks report it
            d[key] = f
    return d[key]


def lazy_init(obj, name: str, convert, default: "Numbers", shape: tuple) -> None:
    """Normalise a lazy field in ``__post_init__``: the default when not given, a
    :class:`Numbers` of the right shape kept as it is, anything else converted to SymPy."""
    raw = obj.__dict__.get(name, _DEFAULT)
    if raw is _DEFAULT:
        raw = default
    elif raw is None and default is None:  # an optional field left out
        pass
    elif isinstance(raw, Numbers):
        if raw.floats.shape != shape:
            raise ModelError(f"{name} must have shape {shape}, got {raw.floats.shape}")
    else:
        raw = convert(raw)
    obj.__dict__[name] = raw


I3 = np.eye(3)
ZERO3 = Numbers(np.zeros(3))
EYE3 = Numbers(np.eye(3))
ZERO33 = Numbers(np.zeros((3, 3)))
Z_AXIS = Numbers(np.array([0.0, 0.0, 1.0]))
ZERO = Numbers(0.0)
