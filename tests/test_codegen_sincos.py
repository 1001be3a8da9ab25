"""Sines and cosines of the generated batch C (armdyn.printing.printers):

* the polynomial kernel's coefficients are what sincos_coefficients.fit computes;
* the compiled kernel against Python's math.sin / math.cos (libm) to 2 units of 2^-52
  (values are <= 1) on |x| <= 1e8: dense on [-50, 50], at and next to multiples of pi/2
  and halfway between them (|r| = pi/4), tiny and large arguments;
* compound angles by the addition formula: the right signs for sums and differences,
  chains; the compiled batch against the Rust core and the single-state function.
"""

from __future__ import annotations

import ctypes
import math
import os
import shutil
import warnings

import numpy as np
import pytest
import sympy as sp

import armdyn
import armdyn.printing as printing
from armdyn.printing import printers, sincos_coefficients
from armdyn.printing.compile import build_shared_library
from armdyn.programs.program import Program

HAVE_CC = shutil.which(os.environ.get("CC", "cc")) or shutil.which("gcc")
needs_cc = pytest.mark.skipif(not HAVE_CC, reason="no C compiler")
UNIT = 2.0**-52  # absolute error unit: the values are <= 1


def test_kernel_coefficients_are_the_computed_ones():
    (sin_c, cos_c), (sin_err, cos_err) = sincos_coefficients.fit()
    assert sin_c == sincos_coefficients.SIN and cos_c == sincos_coefficients.COS
    # the polynomials' own relative error, well below the double arithmetic's 2^-53
    assert 0 < sin_err < 2.0**-57 and 0 < cos_err < 2.0**-63
    assert repr(sin_c[-1]) in printers._SINCOS_KERNEL and repr(cos_c[-1]) in printers._SINCOS_KERNEL


def _kernel_library(tmp_path, flags):
    """The kernel alone over an array, compiled as the generated batch code is (with
    its AVX2 clone where the platform has them)."""
    source = "\n".join(
        [
            "#include <math.h>",
            "#include <stddef.h>",
            "#include <stdint.h>",
            "#include <string.h>",
            printers._SIMD_CLONES,
            printers._SINCOS_KERNEL,
            "ARMDYN_SIMD_CLONES void sincos_many(size_t n, const double *x, double *s, double *c)",
            "{",
            "    for (size_t k = 0; k < n; ++k) armdyn_sincos_kernel(x[k], &s[k], &c[k]);",
            "}",
        ]
    )
    lib = ctypes.CDLL(build_shared_library(source, tmp_path, name="sincos", flags=flags))
    ptr = ctypes.POINTER(ctypes.c_double)

    def sincos(x):
        x = np.ascontiguousarray(x, dtype=float)
        s, c = np.empty_like(x), np.empty_like(x)
        lib.sincos_many(ctypes.c_size_t(x.size), x.ctypes.data_as(ptr), s.ctypes.data_as(ptr), c.ctypes.data_as(ptr))
        return s, c

    return sincos


def _arguments():
    rng = np.random.default_rng(8)
    j = np.concatenate([np.arange(-300, 301), rng.integers(-63_600_000, 63_600_000, 3000)]).astype(float)
    multiples = j * (np.pi / 2)  # |j| pi/2 <= 1e8
    return {
        "dense on [-50, 50]": np.concatenate([np.linspace(-50, 50, 300_001), rng.uniform(-50, 50, 100_000)]),
        "multiples of pi/2": np.concatenate(
            [multiples, np.nextafter(multiples, np.inf), np.nextafter(multiples, -np.inf), (j + 0.5) * (np.pi / 2)]
        ),
        "tiny": np.array([0.0, -0.0, 5e-324, -5e-324, 1e-300, 2.0**-600, 1e-20, -1e-10, 2.0**-27, 1e-5, -1e-3]),
        "large": np.concatenate(
            [
                rng.uniform(-1e8, 1e8, 100_000),
                rng.uniform(-1e4, 1e4, 10_000),
                [1e8, -1e8, np.nextafter(1e8, 0), 2.0**26, 1e7 + 0.5],
            ]
        ),
    }


@needs_cc
@pytest.mark.parametrize("flags", [[], ["-DARMDYN_NO_CLONES"]], ids=["as-built", "sse2"])
def test_kernel_equals_libm_within_two_units(tmp_path, flags):
    sincos = _kernel_library(tmp_path, flags)
    for name, x in _arguments().items():
        s, c = sincos(x)
        err_s = np.abs(s - np.array([math.sin(v) for v in x])) / UNIT
        err_c = np.abs(c - np.array([math.cos(v) for v in x])) / UNIT
        # NaN never passes: a NaN error compares False
        assert (err_s <= 2).all() and (err_c <= 2).all(), (name, np.nanmax(err_s), np.nanmax(err_c))
    s, c = sincos(np.array([0.0, -0.0, 1e-300]))
    assert list(s) == [0.0, 0.0, 1e-300] and list(c) == [1.0, 1.0, 1.0]


def test_addition_formula_signs_and_chains():
    """Sums and differences, a chain, a sine alone by the formula; an angle that is no
    sum of two known ones goes to the kernel, and one of other temporaries stays a line
    of the program (libm), as does a lone sine of an angle that is no such sum."""
    a, b, c, t = sp.symbols("a b c t")
    known = {a, b, c, t}  # the inputs
    lines = [
        ("d", a - b),
        ("e", -a - b),
        ("f", a - b + c),
        ("g", c - a),
        ("u", t * a),
        ("w", a * b),
        ("h", sp.Symbol("w") + c),
        ("v", t + a),
    ]
    alone = {"g", "v"}  # only the sine needed
    assignments = []
    for x in (a, b, c):
        assignments += [(sp.Symbol(f"s{x}"), sp.sin(x)), (sp.Symbol(f"c{x}"), sp.cos(x))]
    for name, e in lines:
        x = sp.Symbol(name)
        assignments.append((x, e))
        if name != "w":
            assignments.append((sp.Symbol(f"s{name}"), sp.sin(x)))
            if name not in alone:
                assignments.append((sp.Symbol(f"c{name}"), sp.cos(x)))
    prog = Program(assignments, [s for s, _ in assignments], (len(assignments),))
    kernel, formulas = printers._batch_sincos(prog, known)
    assert [x for x, _, _ in kernel] == [a, b, c, sp.Symbol("u")]
    assert [str(x) for x, _ in formulas] == ["sd", "cd", "se", "ce", "sf", "cf", "sg"]
    ready = {x for _, sn, cn in kernel for x in (sn, cn)}
    for x, e in formulas:  # in an order that computes each before its use
        assert e.free_symbols <= ready
        ready.add(x)
    rng = np.random.default_rng(3)
    for _ in range(5):
        env = {x: float(rng.uniform(-4, 4)) for x in known}
        for x, e in assignments:
            env[x] = float(e.xreplace(env))
        for x, e in formulas:
            assert abs(float(e.xreplace(env)) - env[x]) <= 4 * UNIT, (x, e)


def _load(name):
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", message=".*(triangle inequality|positive semi-definite)")
        return armdyn.load(name, strict=False).bind()


@needs_cc
def test_batch_forms_compound_angles_by_the_addition_formula(tmp_path):
    """The UR5's tau has q23 = q2 + q3 and q234 = q2 + q3 + q4 (three parallel joints):
    their sines and cosines come from s2, c2, ... in the batch, no kernel call and no
    range check on them. The batch equals the Rust core to 1e-12 and the single-state
    function (libm's sin and cos of q2 + q3 rounded to a double) to 1e-14, not to the
    bit; a block with an angle beyond the kernel's range is the single-state function's,
    bit for bit."""
    robot = _load("ur5")
    lib = printing.compile(robot, what="tau", directory=tmp_path)
    source = lib.code.source
    batch = source[source.index("_batch(") :]
    for angle, sin in (("q23", "s23"), ("q234", "s234")):
        assert f"armdyn_sincos_kernel({angle}[l]" not in batch and f"fabs({angle}[l])" not in batch
        assert f"{sin}[l] = " in batch
    rng = np.random.default_rng(5)
    n = 8 * 40 + 5
    q, qd, qdd = (rng.uniform(-6, 6, (n, robot.dof)) for _ in range(3))
    q[17, 2] = 3e8  # the third block goes to libm, state by state
    got = lib.tau(q, qd, qdd)
    single = np.array([lib.tau(q[k], qd[k], qdd[k]) for k in range(n)])
    assert np.array_equal(got[16:24], single[16:24])
    scale = np.abs(single).max()
    assert np.all(np.isfinite(got)) and np.abs(got - single).max() <= 1e-14 * scale
    rows = np.arange(n) != 17  # q2 + q3 of 3e8 is rounded to 6e-8 in the single-state code
    want = armdyn.rnea(robot, q[rows], qd[rows], qdd[rows])
    np.testing.assert_allclose(got[rows], want, rtol=1e-12, atol=1e-12 * np.abs(want).max())
