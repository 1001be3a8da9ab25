"""Printers: a set of :class:`~armdyn.programs.program.Program` as C99, Python or NumPy source.

Every function evaluates one quantity at one state (C, Python) or at a batch (NumPy,
and C's ``_batch`` entry point). Inputs per quantity (``INPUTS``, by role): tau and the
regressor take ``q, qd, qdd``; C and bias take ``q, qd``; M and g take ``q``; a code
names them (:meth:`GeneratedCode.inputs`: ``q, v, a`` for a floating base or spherical
joints, whose ``q`` is wider than ``v``). Every function also takes the parameter vector
``p`` (the generated code's ``parameters``, in order; unused when the model has none).
Outputs are row-major: a vector (dof,), a matrix (rows, cols).
"""

from __future__ import annotations

import keyword

import sympy as sp
from sympy.printing.c import C99CodePrinter
from sympy.printing.numpy import NumPyPrinter
from sympy.printing.pycode import PythonCodePrinter

from ..programs.program import Program
from .safe_names import comment_text, identifier_base
from .sincos_coefficients import COS, SIN

INPUTS = {
    "tau": ("q", "qd", "qdd"),
    "M": ("q",),
    "C": ("q", "qd"),
    "g": ("q",),
    "bias": ("q", "qd"),
    "regressor": ("q", "qd", "qdd"),
}

_C_RESERVED = set(
    "auto break case char const continue default do double else enum extern float for goto if inline int long "
    "register restrict return short signed sizeof static struct switch typedef union unsigned void volatile while "
    "_Bool _Complex _Imaginary sin cos tan pow sqrt exp log fabs M_PI out p q qd qdd v a n k math numpy np "
    # what else the generated code names: headers' functions, types and macros, the batch
    # loops' locals (a variable of that name would not compile or would shadow them)
    "bool true false asm typeof memcpy size_t uint64_t int64_t errno NULL INFINITY NAN HUGE_VAL EOF "
    "l j r t z ps pc swap sv cv sb cb quadrant wide flat armdyn_sincos_kernel ARMDYN_SIMD_CLONES".split()
)


class Names:
    """Identifier for every symbol: its name made an ASCII identifier
    (:func:`~armdyn.printing.safe_names.identifier_base`), unique, none a keyword or a
    name the generated code uses itself (``taken``: e.g. its function names)."""

    def __init__(self, symbols, taken=()):
        self.map: dict = {}
        used = set(_C_RESERVED) | set(keyword.kwlist) | set(taken)
        for s in symbols:
            base = identifier_base(s.name)
            name, k = base, 1
            while name in used:
                k += 1
                name = f"{base}_{k}"
            used.add(name)
            self.map[s] = sp.Symbol(name)

    def __call__(self, expr):
        return sp.sympify(expr).xreplace(self.map)

    def name(self, s) -> str:
        return self.map[s].name

    def renamed(self, symbols) -> list[tuple[str, str]]:
        """``[(name, identifier)]`` of those of ``symbols`` whose identifier differs."""
        return [(s.name, self.map[s].name) for s in symbols if s in self.map and self.map[s].name != s.name]


class FastPrinter:
    """Prints the expressions generated code is made of (sums, products, integer
    powers, sin, cos of symbols and numbers) directly; anything else goes to SymPy's
    printer for the language. Floats are printed with ``repr`` (round-trip exact)."""

    def __init__(self, lang: str, names: "Names"):
        self.lang = lang
        self.names = names
        self.fallback = {"c": C99CodePrinter, "python": PythonCodePrinter, "numpy": NumPyPrinter}[lang]()
        self.fn = {"c": "", "python": "math.", "numpy": "numpy."}[lang]

    def __call__(self, e) -> str:
        e = sp.sympify(e)
        if e.is_Symbol:
            return self.names.name(e)
        if e.is_Integer:
            return str(int(e))
        if e.is_Float:
            return repr(float(e))
        if e.is_Add:
            out = []
            for k, t in enumerate(e.args):
                text = self(t)
                if k == 0:
                    out.append(text)
                elif text.startswith("-"):
                    out.append(" - " + text[1:])
                else:
                    out.append(" + " + text)
            return "".join(out)
        if e.is_Mul:
            coeff, rest = e.as_coeff_Mul()
            factors = sp.Mul.make_args(rest)
            if coeff.is_Rational and not coeff.is_Integer or any(f.is_Pow and f.exp.is_negative for f in factors):
                return self.fallback.doprint(self.names(e))
            parts = [f"({self(f)})" if f.is_Add else self(f) for f in factors]
            sign = "-" if coeff < 0 else ""
            if abs(coeff) != 1:
                parts.insert(0, self(abs(coeff)))
            return sign + "*".join(parts)
        if e.is_Pow and e.exp.is_Integer and 2 <= int(e.exp) <= 3:
            base = self(e.base)
            base = base if e.base.is_Symbol else f"({base})"
            return "*".join([base] * int(e.exp)) if self.lang == "c" else f"{base}**{int(e.exp)}"
        if isinstance(e, (sp.sin, sp.cos)):
            return f"{self.fn}{type(e).__name__}({self(e.args[0])})"
        return self.fallback.doprint(self.names(e))


def _header_lines(code, comment: str) -> list[str]:
    lines = [
        f"Generated by armdyn from robot '{code.robot_name}' ({code.dof} dof). Do not edit.",
        *(
            code.conventions
            or [
                "Equation of motion: M(q) qdd + C(q, qd) qd + g(q) = tau (SI units, radians).",
                f"Joints (q order): {', '.join(code.coordinate_names)}.",
            ]
        ),
        "Operations per state (count_ops(visual=True) after common-subexpression elimination;",
        "mul = MUL+DIV+POW, add = ADD+SUB):",
    ]
    for what, c in code.op_counts.items():
        lines.append(
            f"  {code.functions[what]}: {c['mul']} mul, {c['add']} add, {c['sin_cos']} sin/cos"
            + (f", {c['other']} other" if c["other"] else "")
            + f"  ({code.sources[what]})"
        )
    if code.parameters:
        lines.append(f"Parameters p[0..{len(code.parameters) - 1}]:")
        defs = dict(code.definitions)
        for k, s in enumerate(code.parameters):
            d = defs.get(s)
            lines.append(f"  p[{k}] = {s.name}" + (f" = {sp.sstr(d)}" if d is not None else ""))
    else:
        lines.append("Parameters: none (numeric model); p may be NULL/None.")
    renamed = code.names.renamed([*code.q, *code.qd, *code.qdd, *code.parameters]) if code.names else []
    if renamed:
        lines.append("Identifiers of the names that are not one (name -> identifier):")
        lines += [f"  {name} -> {ident}" for name, ident in renamed]
    # every name from the model is untrusted text: printable ASCII, nothing that ends the comment
    return [comment + (" " + comment_text(ln) if ln else "") for ln in lines]


def _used_symbols(prog) -> set:
    """The symbols the program's lines and outputs read (inputs, parameters, temporaries)."""
    used = set()
    for e in [e for _, e in prog.assignments] + list(prog.outputs):
        used |= sp.sympify(e).free_symbols
    return used


def _unpack(code, what, names: Names, fmt) -> list[str]:
    out = []
    used = _used_symbols(code.programs[what])
    for arg, symbols in code.inputs(what):
        for k, s in enumerate(symbols):
            if s in used:
                out.append(fmt(names.name(s), arg, k))
    for k, s in enumerate(code.parameters):
        if s in used:
            out.append(fmt(names.name(s), "p", k))
    return out


def print_c(code) -> str:
    names = code.names
    printer = FastPrinter("c", names)
    lines = [
        "/*",
        *_header_lines(code, " *"),
        " */",
        "#include <math.h>",
        "#include <stddef.h>",
        "#include <stdint.h>",
        "#include <string.h>",
        "",
        "#ifndef M_PI",
        "#define M_PI 3.14159265358979323846",
        "#endif",
        "",
        _SIMD_CLONES,
        _SINCOS_KERNEL,
    ]
    for what, prog in code.programs.items():
        fn = code.functions[what]
        args = ", ".join(f"const double *{a}" for a, _ in code.inputs(what))
        size = code.output_size(what)
        lines.append(f"/* {what}: {comment_text(code.describe(what))} */")
        lines.append(f"void {fn}({args}, const double *p, double *out)")
        lines.append("{")
        lines.append("    (void)p;")
        lines += _unpack(code, what, names, lambda n, a, k: f"    const double {n} = {a}[{k}];")
        for s, e in prog.assignments:
            lines.append(f"    const double {names.name(s)} = {printer(e)};")
        for k, e in enumerate(prog.outputs):
            lines.append(f"    out[{k}] = {printer(e)};")
        lines.append("}")
        lines.append("")
        lines += _c_batch(code, what, prog, fn, args, size)
    return "\n".join(lines)


_SIMD_CLONES = """\
/* The batch entry points work on blocks of lanes that the compiler vectorises. With GCC
 * or Clang on x86-64 Linux they are also compiled for AVX2 (4 doubles a vector instead
 * of SSE2's 2), the version picked at load time by the CPU; plain C99 elsewhere. No FMA:
 * results are the same to the last bit either way. Their sines and cosines come from the
 * polynomial kernel below, and those of a compound angle (q23 = q2 + q3) from its parts'
 * by the addition formula (s23 = s2 c3 + c2 s3, c23 = c2 c3 - s2 s3) instead of a kernel
 * call; the operation counts above are the program's, as the single-state functions run
 * it with libm's sin and cos. Batch and single-state results agree to a few ulp, not to
 * the bit. */
#if defined(__GNUC__) && defined(__x86_64__) && defined(__linux__) && !defined(ARMDYN_NO_CLONES)
#define ARMDYN_SIMD_CLONES __attribute__((target_clones("avx2", "default")))
#else
#define ARMDYN_SIMD_CLONES
#endif
"""


def _horner(coefficients) -> str:
    """``c0 + z * (c1 + z * (... + z * cn))`` one coefficient a line, printed with ``repr``
    (exact)."""
    *inner, last = coefficients
    return "\n        + z * (".join(repr(c) for c in inner) + f"\n        + z * {last!r}" + ")" * (len(inner) - 1)


_SINCOS_KERNEL = f"""\
/* (sin x, cos x) to about 1 ulp for |x| <= 1e8, branch-free so that loops over lanes
 * vectorise: x = j pi/2 + r (three-part Cody-Waite split of pi/2, exact for |j| < 2^29),
 * minimax polynomials of degree 13 / 14 on |r| <= pi/4 (their coefficients computed by
 * python/armdyn/printing/sincos_coefficients.py), picked and signed by j mod 4. armdyn's
 * Rust core (crates/armdyn-core/src/real.rs) reduces x the same way but uses Taylor
 * polynomials of degree 17 / 16: the two agree to about 1 ulp, not to the bit. */
static inline void armdyn_sincos_kernel(double x, double *s, double *c)
{{
    const double t = x * 0.6366197723675814 + 6755399441055744.0;
    uint64_t quadrant;
    memcpy(&quadrant, &t, 8);
    const double j = t - 6755399441055744.0;
    const double r = ((x - j * 1.570796251296997) - j * 7.549789415861596e-08) - j * 5.390302858158119e-15;
    const double z = r * r;
    const double ps = r + r * z * ({_horner(SIN)});
    const double pc = (1.0 - 0.5 * z) + z * z * ({_horner(COS)});
    const int swap = (int)(quadrant & 1);
    const double sv = swap ? pc : ps, cv = swap ? ps : pc;
    uint64_t sb, cb;
    memcpy(&sb, &sv, 8);
    memcpy(&cb, &cv, 8);
    sb ^= (quadrant & 2) << 62;
    cb ^= ((quadrant + 1) & 2) << 62;
    memcpy(s, &sb, 8);
    memcpy(c, &cb, 8);
}}
"""

LANES = 8


class _LaneNames:
    """Symbol -> ``name[l]`` for per-state values (inputs, temporaries), ``name`` for
    the parameters (the same for every lane)."""

    def __init__(self, names: Names, scalars):
        self.names = names
        self.scalars = set(scalars)
        self.map = {s: sp.Symbol(self.name(s)) for s in names.map}

    def name(self, s) -> str:
        return self.names.name(s) + ("" if s in self.scalars else "[l]")

    def __call__(self, expr):
        return sp.sympify(expr).xreplace(self.map)


def _as_sum(angle, known: dict):
    """``(g1, a, g2, b)`` with ``angle = g1 a + g2 b`` (signs g = +-1) for two keys a, b
    of ``known``, else None. Angles are expressions in the inputs and parameters, which
    SymPy keeps in one canonical form for sums of terms (``(q2 + q3 + q4) - (q2 + q3)``
    is ``q4``)."""
    for a in known:
        for g1 in (1, -1):
            rest = angle - g1 * a
            for g2 in (1, -1):
                if g2 * rest in known:
                    return g1, a, g2, g2 * rest
    return None


def _batch_sincos(prog, known):
    """How the batch computes the sines and cosines of the program's angles (symbols).

    An angle that is the sum or difference of two angles whose sine and cosine are both
    computed before it (``q23 = q2 + q3``; ``q234 = q2 + q3 + q4`` from q23 and q4) gets
    them by the addition formula, ``s23 = s2 c3 + c2 s3``, ``c23 = c2 c3 - s2 s3`` (4 mul
    and 2 add against ~40 flops of the kernel; a few ulp). Else an angle whose sine and
    cosine are both needed, an input or a temporary of the inputs and the parameters
    (``known``), goes to the polynomial kernel. Any other (one of sin, cos needed; an
    angle of other temporaries) stays a line of the program (libm).

    Returns (kernel, formulas): ``[(angle, sin symbol, cos symbol)]`` and ``[(sin or
    cos symbol, expression in the kernel's and earlier formulas' symbols)]``, the
    formulas in an order that computes every symbol before its use."""
    assigned = dict(prog.assignments)
    order = {s: k for k, (s, _) in enumerate(prog.assignments)}
    trig: dict = {}
    for s, e in prog.assignments:
        if isinstance(e, (sp.sin, sp.cos)) and e.args[0].is_Symbol:
            trig.setdefault(e.args[0], {})[type(e).__name__] = s

    def value(e):
        """e with the temporaries in it replaced by their expressions."""
        inner = e.free_symbols & assigned.keys()
        return e.xreplace({t: value(assigned[t]) for t in inner}) if inner else e

    kernel, formulas = [], []
    pairs: dict = {}  # an angle's value -> (its sin, its cos), both computed
    for x in sorted(trig, key=lambda a: order.get(a, -1)):  # the inputs, then as assigned
        need, angle = trig[x], value(x)
        split = _as_sum(angle, pairs)
        if split:
            g1, a, g2, b = split
            (s1, c1), (s2, c2) = pairs[a], pairs[b]
            by_formula = {"sin": g1 * s1 * c2 + g2 * c1 * s2, "cos": c1 * c2 - g1 * g2 * s1 * s2}
            formulas += [(need[f], by_formula[f]) for f in ("sin", "cos") if f in need]
        elif len(need) == 2 and (x not in assigned or assigned[x].free_symbols <= known):
            kernel.append((x, need["sin"], need["cos"]))
        else:
            continue
        if len(need) == 2:
            pairs[angle] = (need["sin"], need["cos"])
    return kernel, formulas


def _c_batch(code, what, prog, fn, args, size) -> list[str]:
    """The batch entry point: blocks of LANES states, every temporary an array over the
    lanes and the lines in one loop over them (which the compiler turns into SIMD), sin and
    cos by the polynomial kernel, or from those of two other angles by the addition formula
    (:func:`_batch_sincos`); the last n mod LANES states, and any block with a kernel angle
    |x| > 1e8, by the single-state function (libm's sin and cos)."""
    names = code.names
    lanes = _LaneNames(names, code.parameters)
    printer = FastPrinter("c", lanes)
    inputs = code.inputs(what)
    width = {a: len(symbols) for a, symbols in inputs}
    known = {s for _, symbols in inputs for s in symbols} | set(code.parameters)
    kernel, formulas = _batch_sincos(prog, known)
    L = LANES
    shapes = ", ".join(f"{a} (n, {w})" for a, w in width.items())
    out = [
        f"/* {what} over n states: inputs row-major {shapes}, out row-major (n, {size}) */",
        f"ARMDYN_SIMD_CLONES void {fn}_batch(size_t n, {args}, const double *p, double *out)",
        "{",
        "    (void)p;",
    ]
    out += _unpack(code, what, names, lambda n_, a, k: f"    const double {n_} = {a}[{k}];" if a == "p" else None)
    out = [ln for ln in out if ln is not None]
    out.append("    size_t k = 0;")
    out.append(f"    for (; k + {L} <= n; k += {L}) {{")
    out.append("        int wide = 0;  /* some angle beyond the kernel's range: libm, state by state */")
    used = _used_symbols(prog)
    for a, symbols in inputs:
        for j, s in enumerate(symbols):
            if s in used:
                nm = names.name(s)
                out.append(f"        double {nm}[{L}];")
                out.append(f"        for (int l = 0; l < {L}; ++l) {nm}[l] = {a}[(k + l) * {width[a]} + {j}];")
    # a kernel angle that is a temporary of the inputs and parameters (a turned leaf
    # frame's q + th): computed before the range check
    assigned = dict(prog.assignments)
    early = [x for x, _, _ in kernel if x in assigned]
    for x in early:
        out.append(f"        double {names.name(x)}[{L}];")
        out.append(f"        for (int l = 0; l < {L}; ++l) {lanes.name(x)} = {printer(assigned[x])};")
    for x, _, _ in kernel:
        out.append(f"        for (int l = 0; l < {L}; ++l) wide |= !(fabs({lanes.name(x)}) <= 1e8);")
    out.append("        if (wide) {")
    call = ", ".join(f"{a} + (k + l) * {w}" for a, w in width.items())
    out.append(f"            for (size_t l = 0; l < {L}; ++l) {fn}({call}, p, out + (k + l) * {size});")
    out.append("            continue;")
    out.append("        }")
    # the program's other lines, less those that only the replaced sin and cos lines used
    # (a compound angle whose sine and cosine come from the addition formula)
    handled = {s for _, sn, cn in kernel for s in (sn, cn)} | {s for s, _ in formulas} | set(early)
    rest = Program([(s, e) for s, e in prog.assignments if s not in handled], prog.outputs, prog.shape).pruned()
    lines = formulas + rest.assignments
    body = [
        f"armdyn_sincos_kernel({lanes.name(x)}, &{names.name(sn)}[l], &{names.name(cn)}[l]);" for x, sn, cn in kernel
    ]
    body += [f"{lanes.name(s)} = {printer(e)};" for s, e in lines]
    body += [f"out[(k + l) * {size} + {j}] = {printer(e)};" for j, e in enumerate(prog.outputs)]
    declared = [names.name(s) for _, sn, cn in kernel for s in (sn, cn)] + [names.name(s) for s, _ in lines]
    for i in range(0, len(declared), 8):
        out.append("        double " + ", ".join(f"{d}[{L}]" for d in declared[i : i + 8]) + ";")
    # one loop over the lanes holding every line: the compiler vectorises it as a whole
    # (measured faster than one loop per line or per few dozen lines, and as quick to build)
    out.append(f"        for (int l = 0; l < {L}; ++l) {{")
    out += [f"            {b}" for b in body]
    out.append("        }")
    out.append("    }")
    call = ", ".join(f"{a} + k * {w}" for a, w in width.items())
    out.append(f"    for (; k < n; ++k) {fn}({call}, p, out + k * {size});")
    out += ["}", ""]
    return out


def print_python(code, numpy: bool = False) -> str:
    names = code.names
    printer = FastPrinter("numpy" if numpy else "python", names)
    lines = ['"""', *_header_lines(code, ""), ""]
    widths = code.input_widths()
    if numpy:
        lines += [
            f"Each input is (w,) for one state or (N, w) for N states ({widths}); outputs follow",
            "((..., rows) or (..., rows, cols)).",
            '"""',
            "",
            "import numpy",
            "",
        ]
    else:
        lines += [
            f"Each input is a sequence of w floats ({widths}); outputs are flat lists, row-major.",
            '"""',
            "",
            "import math",
            "",
        ]
    for what, prog in code.programs.items():
        fn = code.functions[what]
        inputs = [a for a, _ in code.inputs(what)]
        args = ", ".join(inputs)
        lines.append("")
        lines.append(f"def {fn}({args}, p=None):")
        lines.append(f'    """{what}: {comment_text(code.describe(what))}"""')
        if numpy:
            lines += [f"    {a} = numpy.asarray({a}, dtype=float)" for a in inputs]
            if code.parameters:
                lines.append("    p = numpy.asarray(p, dtype=float)")
            lines += _unpack(code, what, names, lambda n, a, k: f"    {n} = {a}[..., {k}]")
        else:
            lines += _unpack(code, what, names, lambda n, a, k: f"    {n} = {a}[{k}]")
        for s, e in prog.assignments:
            lines.append(f"    {names.name(s)} = {printer(e)}")
        if numpy:
            shape = ", ".join(str(d) for d in prog.shape)
            lines.append(f"    out = numpy.empty({inputs[0]}.shape[:-1] + ({shape},))")
            flat = "out.reshape(out.shape[:-2] + (-1,))" if len(prog.shape) == 2 else "out"
            lines.append(f"    flat = {flat}")
            for k, e in enumerate(prog.outputs):
                lines.append(f"    flat[..., {k}] = {printer(e)}")
            lines.append("    return out")
        else:
            lines.append("    return [")
            for e in prog.outputs:
                lines.append(f"        {printer(e)},")
            lines.append("    ]")
        lines.append("")
    return "\n".join(lines)
