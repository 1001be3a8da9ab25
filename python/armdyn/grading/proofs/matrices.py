"""Exact small matrices over the rationals: the values a proof line takes on one body.

Every value is a :class:`Mat` of :class:`fractions.Fraction` entries with a shape
``(rows, cols)``: a scalar is (1, 1), a column vector (3, 1), a row vector (1, 3) (a
transposed vector), a tensor or rotation (3, 3). A (1, 1) factor multiplies as a scalar,
so ``d^T r_C I`` reads as ``(d . r_C) I``. Arithmetic is exact: two values are equal or
they are not, with no tolerance to choose.
"""

from __future__ import annotations

from fractions import Fraction

#: bits of a numerator or denominator beyond which a value is refused (bounded time)
MAX_BITS = 20_000


class ShapeError(ValueError):
    """Two values whose shapes cannot be combined (a student's missing transpose, say)."""


class SizeError(ValueError):
    """A value whose numbers grew beyond :data:`MAX_BITS` (hostile powers)."""


def _check(x: Fraction) -> Fraction:
    if x.numerator.bit_length() > MAX_BITS or x.denominator.bit_length() > MAX_BITS:
        raise SizeError(f"a number with more than {MAX_BITS} bits")
    return x


class Mat:
    """A rows x cols matrix of Fractions, stored row-major in ``v``."""

    __slots__ = ("c", "r", "v")

    def __init__(self, r: int, c: int, v):
        self.r, self.c, self.v = r, c, tuple(v)

    # -- constructors
    @staticmethod
    def scalar(x) -> Mat:
        return Mat(1, 1, (Fraction(x),))

    @staticmethod
    def col(xs) -> Mat:
        return Mat(len(xs), 1, (Fraction(x) for x in xs))

    @staticmethod
    def identity(n: int = 3) -> Mat:
        return Mat(n, n, (Fraction(int(i == j)) for i in range(n) for j in range(n)))

    @staticmethod
    def zeros(r: int, c: int) -> Mat:
        return Mat(r, c, (Fraction(0),) * (r * c))

    @staticmethod
    def rows(rows) -> Mat:
        rows = [list(row) for row in rows]
        return Mat(len(rows), len(rows[0]), (Fraction(x) for row in rows for x in row))

    # -- shape
    @property
    def shape(self) -> tuple[int, int]:
        return (self.r, self.c)

    @property
    def is_scalar(self) -> bool:
        return self.r == 1 and self.c == 1

    def kind(self) -> str:
        return {
            (1, 1): "a scalar",
            (3, 1): "a vector",
            (1, 3): "a row vector (transposed vector)",
            (3, 3): "a 3x3 matrix",
        }.get(self.shape, f"a {self.r}x{self.c} matrix")

    def __getitem__(self, ij):
        i, j = ij
        return self.v[i * self.c + j]

    # -- arithmetic
    def __add__(self, o: Mat) -> Mat:
        if self.shape != o.shape:
            if self.is_scalar and self.v[0] == 0 or o.is_scalar and o.v[0] == 0:
                return o if self.is_scalar and self.v[0] == 0 else self  # a bare 0 is any shape's zero
            raise ShapeError(f"adds {self.kind()} to {o.kind()}")
        return Mat(self.r, self.c, (_check(a + b) for a, b in zip(self.v, o.v)))

    def __neg__(self) -> Mat:
        return Mat(self.r, self.c, (-a for a in self.v))

    def __sub__(self, o: Mat) -> Mat:
        return self + (-o)

    def scale(self, k: Fraction) -> Mat:
        return Mat(self.r, self.c, (_check(k * a) for a in self.v))

    def __matmul__(self, o: Mat) -> Mat:
        """Juxtaposition: a matrix product, or scalar times anything."""
        if self.is_scalar:
            return o.scale(self.v[0])
        if o.is_scalar:
            return self.scale(o.v[0])
        if self.c != o.r:
            raise ShapeError(f"multiplies {self.kind()} by {o.kind()}")
        out = []
        for i in range(self.r):
            for j in range(o.c):
                out.append(_check(sum((self[i, k] * o[k, j] for k in range(self.c)), Fraction(0))))
        return Mat(self.r, o.c, out)

    @property
    def T(self) -> Mat:
        return Mat(self.c, self.r, (self[i, j] for j in range(self.c) for i in range(self.r)))

    def cross(self, o: Mat) -> Mat:
        a, b = self.as_vector("a cross product"), o.as_vector("a cross product")
        return Mat.col((a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]))

    def as_vector(self, what: str) -> tuple:
        if self.shape not in ((3, 1), (1, 3)):
            raise ShapeError(f"{what} needs vectors, not {self.kind()}")
        return self.v

    def dot(self, o: Mat) -> Fraction:
        return sum((a * b for a, b in zip(self.as_vector("a norm"), o.as_vector("a norm"))), Fraction(0))

    def power(self, n: int) -> Mat:
        if not self.is_scalar:
            if self.r != self.c or n < 1:  # S(r)^2 = S(r) S(r); no inverses
                raise ShapeError(f"raises {self.kind()} to a power")
            out = self
            for _ in range(n - 1):
                out = out @ self
            return out
        x = self.v[0]
        if x == 0 and n < 0:
            raise ZeroDivisionError("0 to a negative power")
        bits = max(x.numerator.bit_length(), x.denominator.bit_length())
        if bits * abs(n) > MAX_BITS:
            raise SizeError(f"a power with more than {MAX_BITS} bits")
        return Mat.scalar(x**n)

    def __eq__(self, o) -> bool:
        return isinstance(o, Mat) and self.shape == o.shape and self.v == o.v

    def __hash__(self):
        return hash((self.r, self.c, self.v))

    def tolist(self) -> list:
        """Entries as strings ("1/2"): a scalar, a list (vector) or a list of rows."""
        if self.is_scalar:
            return str(self.v[0])
        if self.c == 1 or self.r == 1:
            return [str(x) for x in self.v]
        return [[str(self[i, j]) for j in range(self.c)] for i in range(self.r)]

    def __repr__(self) -> str:
        return f"Mat{self.shape}{self.tolist()}"
