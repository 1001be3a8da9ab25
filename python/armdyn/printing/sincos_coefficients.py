"""The polynomials of the generated batch C's sin/cos kernel, and how they were computed.

The kernel (``printers._SINCOS_KERNEL``) reduces ``x = j pi/2 + r``, ``|r| <= pi/4``, and
with ``z = r^2`` evaluates

    sin r = r + r z P(z)           P = SIN[0] + SIN[1] z + ... + SIN[5] z^5  (degree 13 in r)
    cos r = 1 - z/2 + z^2 Q(z)     Q = COS[0] + COS[1] z + ... + COS[5] z^5  (degree 14 in r)

P and Q are minimax polynomials for the relative error of sin and cos on
``0 < z <= (pi/4)^2``: the error of ``r + r z P`` is ``r z (P - f)`` with
``f = (sin r / r - 1) / z``, so P minimises ``max |z (P - f) / (sin r / r)|``; for cos
``g = (cos r - 1 + z/2) / z^2`` and the weight ``z^2 / cos r``. They are found by the
Remez exchange in 60-digit arithmetic (mpmath), the coefficients rounded to doubles one
at a time with the later ones refitted. With those doubles the polynomials' relative
error is 2^-57.9 (sin) and 2^-63.9 (cos), below the rounding of the double arithmetic
that evaluates them, so the kernel is good to about 1 ulp. Taylor polynomials of these
degrees would be off by up to 2^-45 and 2^-49 at pi/4; the Rust core's kernel
(``crates/armdyn-core/src/real.rs``) uses Taylor polynomials of degree 17 and 16.

    python3 python/armdyn/printing/sincos_coefficients.py     # computes and prints SIN, COS (~3 s)

``tests/test_codegen_sincos.py`` checks that :func:`fit` gives SIN and COS below.
"""

from __future__ import annotations

import functools

import mpmath as mp

# printed by main(); tests/test_codegen_sincos.py recomputes them
SIN = (
    -0.1666666666666663,
    0.00833333333332184,
    -0.00019841269829358528,
    2.7557313538514234e-06,
    -2.5050734389257543e-08,
    1.5895433289345187e-10,
)
COS = (
    0.041666666666666595,
    -0.0013888888888873342,
    2.480158728900208e-05,
    -2.755731421703886e-07,
    2.087570539602921e-09,
    -1.1358749239936787e-11,
)

DEGREE = 5  # of P and Q in z
DIGITS = 60  # working precision of the fit (the refits divide by z^k)
GRID = 200  # points per scan for the error's extrema


def _targets():
    """(f, weight) for sin and for cos, as functions of z > 0 (mpf); sin and cos of
    sqrt(z) cached, as the Remez iterations scan the same grid again and again."""

    @functools.lru_cache(maxsize=None)
    def trig(z):
        r = mp.sqrt(z)
        return r, mp.sin(r), mp.cos(r)

    def sin_f(z):
        r, s, _ = trig(z)
        return (s / r - 1) / z

    def sin_w(z):
        r, s, _ = trig(z)
        return z * r / s

    def cos_f(z):
        return (trig(z)[2] - 1 + z / 2) / (z * z)

    def cos_w(z):
        return z * z / trig(z)[2]

    return (sin_f, sin_w), (cos_f, cos_w)


def _polyval(c, z):
    out = 0
    for ck in reversed(c):
        out = out * z + ck
    return out


def _extrema(err, b):
    """The points of (0, b] where ``err`` is largest in magnitude between its sign
    changes, in order (so their signs alternate): one per run of equal sign on a
    Chebyshev grid, refined by golden-section search between the neighbouring grid
    points (the end point b taken as it is)."""
    grid = [b * (1 - mp.cos(mp.pi * k / GRID)) / 2 for k in range(1, GRID + 1)]
    values = [err(z) for z in grid]
    runs = []  # (index of the largest |err| in a run of one sign)
    for k, v in enumerate(values):
        if runs and mp.sign(v) == mp.sign(values[runs[-1]]):
            if abs(v) > abs(values[runs[-1]]):
                runs[-1] = k
        else:
            runs.append(k)
    points = []
    for k in runs:
        if k == GRID - 1:
            points.append(b)  # the end point itself
            continue
        points.append(_golden_max(err, grid[max(k - 1, 0)], grid[k + 1]))
    return points


def _golden_max(err, lo, hi):
    """Where |err| is largest on [lo, hi] (unimodal there), by golden-section search to
    about 1e-8 of the interval: the level of the error depends on the point only to
    second order."""
    g = (mp.sqrt(5) - 1) / 2
    a, b = hi - g * (hi - lo), lo + g * (hi - lo)
    fa, fb = abs(err(a)), abs(err(b))
    for _ in range(40):
        if fa > fb:
            hi, b, fb = b, a, fa
            a = hi - g * (hi - lo)
            fa = abs(err(a))
        else:
            lo, a, fa = a, b, fb
            b = lo + g * (hi - lo)
            fb = abs(err(b))
    return (lo + hi) / 2


def remez(f, w, degree: int, b):
    """Coefficients c_0..c_degree (mpf) of the polynomial p minimising
    ``max over 0 < z <= b of |w(z) (p(z) - f(z))|``, and that maximum."""
    n = degree + 2
    nodes = [b * (1 - mp.cos(mp.pi * (i + mp.mpf(0.5)) / n)) / 2 for i in range(n)]
    for _ in range(30):
        # p(z_i) - f(z_i) = (-1)^i E / w(z_i): degree + 1 coefficients and the level E
        A = mp.matrix(n, n)
        rhs = mp.matrix(n, 1)
        for i, z in enumerate(nodes):
            for k in range(degree + 1):
                A[i, k] = z**k
            A[i, degree + 1] = -((-1) ** i) / w(z)
            rhs[i] = f(z)
        sol = mp.lu_solve(A, rhs)
        c, level = [sol[k] for k in range(degree + 1)], abs(sol[degree + 1])

        def err(z):
            return w(z) * (_polyval(c, z) - f(z))

        nodes = _extrema(err, b)
        if len(nodes) < n:
            raise RuntimeError(f"{len(nodes)} alternating extrema, {n} needed")
        while len(nodes) > n:  # drop the end point with the smaller error
            nodes.pop(0 if abs(err(nodes[0])) < abs(err(nodes[-1])) else -1)
        worst = max(abs(err(z)) for z in nodes)
        if worst - level <= mp.mpf(10) ** -12 * worst:  # equioscillation: the minimax
            return c, worst
    raise RuntimeError("Remez exchange did not converge")


def rounded_minimax(f, w, b):
    """The coefficients (floats) of a polynomial of degree DEGREE close to the minimax one
    for ``w (p - f)`` on (0, b], rounded to doubles one at a time, lowest first, each
    Remez fit redone for the coefficients still free after the rounding of the ones
    before (rounding the minimax coefficients all at once loses 1.5 bits on sin: its
    leading ~ -1/6 alone carries an error of up to 2^-56.6), and the maximum of
    ``|w (p - f)|`` with them."""
    fixed: list = []
    for k in range(DEGREE + 1):
        # p = fixed(z) + z^k rest(z), rest minimising |w z^k (rest - (f - fixed(z)) / z^k)|
        head = [mp.mpf(ck) for ck in fixed]
        c, _ = remez(lambda z: (f(z) - _polyval(head, z)) / z**k, lambda z: w(z) * z**k, DEGREE - k, b)
        fixed.append(float(c[0]))
    final = [mp.mpf(ck) for ck in fixed]

    def err(z):
        return w(z) * (_polyval(final, z) - f(z))

    return tuple(fixed), float(max(abs(err(z)) for z in _extrema(err, b)))


def fit():
    """((SIN, COS), (relative error of sin, of cos)) computed: the coefficients as
    floats, the errors of the polynomials with them (in exact arithmetic) as floats."""
    with mp.workdps(DIGITS):
        b = (mp.pi / 4) ** 2
        (sin_c, sin_e), (cos_c, cos_e) = (rounded_minimax(f, w, b) for f, w in _targets())
    return (sin_c, cos_c), (sin_e, cos_e)


def main() -> None:
    import math

    (sin_c, cos_c), (sin_e, cos_e) = fit()
    print(f"SIN = {sin_c!r}")
    print(f"COS = {cos_c!r}")
    print(
        f"# relative error on |r| <= pi/4 (rounded coefficients, exact arithmetic): "
        f"sin 2^{math.log2(sin_e):.1f}, cos 2^{math.log2(cos_e):.1f}"
    )


if __name__ == "__main__":
    main()
