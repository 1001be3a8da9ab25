"""Compile generated C with the system C compiler and call it through ctypes.

    lib = armdyn.printing.compile(robot.bind(), what=("tau", "M"))
    lib.tau(q, qd, qdd)          # (dof,) -> (dof,);  (N, dof) -> (N, dof)
    lib.M(q)                     # (dof,) -> (dof, dof); (N, dof) -> (N, dof, dof)

The compiler is ``cc`` (or ``$CC``, or the ``cc=`` argument), run as
``cc -std=c99 -O2 -fPIC -shared file.c -o lib.so -lm``. A missing compiler or a failed
build raises :class:`CompilerError` with the compiler's own message.
"""

from __future__ import annotations

import ctypes
import hashlib
import os
import shutil
import subprocess
import tempfile

import numpy as np

from .generate import GeneratedCode, codegen, identifier

_DOUBLE_P = ctypes.POINTER(ctypes.c_double)


class CompilerError(RuntimeError):
    """The C compiler is missing or failed; the message includes its output."""


def _find_compiler(cc: str | None) -> str:
    candidates = [cc] if cc else [c for c in (os.environ.get("CC"), "cc", "gcc", "clang") if c]
    for c in candidates:
        path = shutil.which(c)
        if path:
            return path
    raise CompilerError(
        f"no C compiler found (tried {', '.join(candidates)}); install one (e.g. gcc) or pass cc=/path/to/cc"
    )


def build_shared_library(
    source: str, directory=None, cc: str | None = None, name: str = "armdyn_generated", flags=()
) -> str:
    """Compile C ``source`` into a shared library in ``directory`` (a new temporary
    directory if None); returns its path. ``flags``: extra compiler arguments (e.g.
    ``["-DARMDYN_NO_CLONES"]`` for baseline SIMD only). Raises CompilerError."""
    compiler = _find_compiler(cc)
    directory = directory or tempfile.mkdtemp(prefix="armdyn-codegen-")
    os.makedirs(directory, exist_ok=True)
    digest = hashlib.sha1((source + "\0".join(flags)).encode()).hexdigest()[
        :12
    ]  # a new path per source: dlopen caches by path
    c_path = os.path.join(directory, f"{name}_{digest}.c")
    so_path = os.path.join(directory, f"lib{name}_{digest}.so")
    with open(c_path, "w") as fh:
        fh.write(source)
    cmd = [compiler, "-std=c99", "-O2", "-fPIC", "-shared", *flags, c_path, "-o", so_path, "-lm"]
    try:
        res = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
    except subprocess.TimeoutExpired:
        raise CompilerError(f"{os.path.basename(compiler)} took more than 600 s on {c_path}") from None
    except OSError as err:
        raise CompilerError(f"could not run {compiler}: {err}") from None
    if res.returncode != 0:
        msg = (res.stderr or res.stdout).strip()
        raise CompilerError(f"{os.path.basename(compiler)} failed on {c_path}: {msg}")
    return so_path


class CompiledFunction:
    """One generated quantity, callable on (w,) or (N, w) float64 arrays (w: each
    input's width, ``dof``; for a floating base or spherical joints ``nq`` and ``nv``).

    ``f(q, [qd, [qdd]], p=None)``: the inputs of :meth:`GeneratedCode.inputs` (``q, v, a``
    for a floating base or spherical joints); ``p`` (len(parameters),) is required when
    the code has parameters. Wrong shapes, NaN or inf, and a zero quaternion in ``q``
    raise ValueError naming the argument."""

    def __init__(self, lib, code, what):
        self.what = what
        inputs = code.inputs(what)
        self.inputs = tuple(a for a, _ in inputs)
        self.widths = tuple(len(symbols) for _, symbols in inputs)
        self.quaternions = list(code.quaternions)
        self.shape = code.programs[what].shape
        self.n_parameters = len(code.parameters)
        self._fn = getattr(lib, code.functions[what] + "_batch")
        self._fn.restype = None
        self._fn.argtypes = [ctypes.c_size_t] + [_DOUBLE_P] * (len(self.inputs) + 2)

    def __call__(self, *arrays, p=None):
        if len(arrays) != len(self.inputs):
            raise TypeError(
                f"{self.what} takes {', '.join(self.inputs)} ({len(self.inputs)} arrays), got {len(arrays)}"
            )
        checked, shape = [], None
        for name, width, a in zip(self.inputs, self.widths, arrays):
            a = np.ascontiguousarray(a, dtype=np.float64)
            if a.ndim not in (1, 2) or a.shape[-1] != width:
                raise ValueError(f"{name} must have shape ({width},) or (N, {width}), got {a.shape}")
            if shape is not None and a.shape[:-1] != shape:
                raise ValueError(f"{name} has shape {a.shape}, but {self.inputs[0]} has shape {checked[0].shape}")
            if not np.all(np.isfinite(a)):
                raise ValueError(f"{name} contains NaN or inf")
            if name == "q":
                for k, whose in self.quaternions:
                    if np.any(np.all(a[..., k : k + 4] == 0, axis=-1)):
                        raise ValueError(f"q[{k}:{k + 4}], the quaternion of {whose}, is zero: it is no rotation")
            shape = a.shape[:-1]
            checked.append(a)
        if self.n_parameters:
            if p is None:
                raise ValueError(f"p is required: this code has {self.n_parameters} parameters (see code.parameters)")
            p = np.ascontiguousarray(p, dtype=np.float64)
            if p.shape != (self.n_parameters,):
                raise ValueError(f"p must have shape ({self.n_parameters},), got {p.shape}")
            if not np.all(np.isfinite(p)):
                raise ValueError("p contains NaN or inf")
        else:
            p = np.zeros(1)
        batch = shape
        n = int(np.prod(batch)) if batch else 1
        out = np.empty(batch + tuple(self.shape))
        self._fn(
            n,
            *(a.ctypes.data_as(_DOUBLE_P) for a in checked),
            p.ctypes.data_as(_DOUBLE_P),
            out.ctypes.data_as(_DOUBLE_P),
        )
        return out


class CompiledCode:
    """The shared library built from a :class:`GeneratedCode`: one
    :class:`CompiledFunction` per quantity as an attribute (``lib.tau``, ``lib.M``, ...)
    and in ``functions``; callable itself when it holds one quantity."""

    def __init__(self, code, path):
        self.code = code
        self.path = path
        self._lib = ctypes.CDLL(path)
        self.functions = {w: CompiledFunction(self._lib, code, w) for w in code.programs}
        for w, f in self.functions.items():
            setattr(self, w, f)

    def __call__(self, *arrays, p=None):
        if len(self.functions) != 1:
            raise TypeError(
                f"this library holds {', '.join(self.functions)}: call one of them, e.g. lib.{next(iter(self.functions))}(...)"
            )
        return next(iter(self.functions.values()))(*arrays, p=p)

    def __repr__(self):
        return f"CompiledCode({self.code.robot_name!r}, {list(self.functions)}, path={self.path!r})"


def compile(code, what=None, *, base: bool = False, directory=None, cc: str | None = None, flags=()) -> CompiledCode:
    """Build C code into a shared library and load it.

    code: a :class:`~armdyn.printing.GeneratedCode` in C, or a Robot / model name (then
          :func:`armdyn.printing.codegen` generates ``what`` in C, with ``base``; by default
          tau, M, C, g, or tau, M, g, bias where C does not apply).
    directory: where the .c and .so go (a new temporary directory if None).
    cc: the compiler (default ``$CC``, then cc, gcc, clang); flags: extra arguments.
    Raises CompilerError when no compiler is found or it fails.
    """
    if not isinstance(code, GeneratedCode):
        code = codegen(code, what=what, lang="c", base=base)
    elif code.lang != "c":
        raise ValueError(f"compile needs C code, got lang={code.lang!r}; generate it with lang='c'")
    path = build_shared_library(code.source, directory, cc, name=identifier(code.robot_name), flags=list(flags))
    return CompiledCode(code, path)
