"""Symbol names as the field writes them: ``theta1_dot`` is θ̇₁ in text and
``\\dot{\\theta}_{1}`` in LaTeX (and so in MathML). The derivation report (text, LaTeX,
HTML) and the grade report take their names from here, so both print the same symbols.
"""

from __future__ import annotations

import re
import weakref

import sympy as sp
from sympy.printing.precedence import precedence

SUBSCRIPT_DIGITS = str.maketrans("0123456789", "₀₁₂₃₄₅₆₇₈₉")

#: the one table of Greek letters: LaTeX name -> Unicode letter (the grader's reader, its
#: messages and every printed name use it)
GREEK = {
    "alpha": "α",
    "beta": "β",
    "gamma": "γ",
    "delta": "δ",
    "epsilon": "ε",
    "zeta": "ζ",
    "eta": "η",
    "theta": "θ",
    "iota": "ι",
    "kappa": "κ",
    "lambda": "λ",
    "mu": "μ",
    "nu": "ν",
    "xi": "ξ",
    "pi": "π",
    "rho": "ρ",
    "sigma": "σ",
    "tau": "τ",
    "phi": "φ",
    "chi": "χ",
    "psi": "ψ",
    "omega": "ω",
    "Gamma": "Γ",
    "Delta": "Δ",
    "Theta": "Θ",
    "Lambda": "Λ",
    "Xi": "Ξ",
    "Pi": "Π",
    "Sigma": "Σ",
    "Phi": "Φ",
    "Psi": "Ψ",
    "Omega": "Ω",
    "varepsilon": "ϵ",
    "vartheta": "ϑ",
    "varphi": "ϕ",
    "upsilon": "υ",
}
_DOTS = {"": "", "_dot": "\u0307", "_ddot": "\u0308"}  # combining dot / diaeresis above
_SUP = str.maketrans("0123456789-", "⁰¹²³⁴⁵⁶⁷⁸⁹⁻")
_NAME_PARTS = re.compile(r"([A-Za-z]+?)_?(\d*)")


def unicode_name(name: str, dots: str = "") -> str | None:
    """``theta1`` -> ``θ₁``, with ``dots`` "_dot"/"_ddot": ``θ̇₁``, ``d̈₂``; ``m2`` -> ``m₂``.
    None for names that are not letters + optional digits (``shoulder_pan_joint``):
    those are printed as they are."""
    m = _NAME_PARTS.fullmatch(name)
    if not m:
        return None
    base, digits = m.groups()
    return GREEK.get(base, base) + _DOTS[dots] + digits.translate(SUBSCRIPT_DIGITS)


class UnicodeTextPrinter(sp.printing.str.StrPrinter):
    """SymPy's str printer with θ̇₁-style symbol names, superscript integer powers and
    factors side by side as written by hand (``d₂² m₂ θ̈₁``, not ``d₂**2*m₂*θ̈₁``). A
    visible ``·`` stays where juxtaposition would merge two numbers (``2·3^x``)."""

    def __init__(self, names: dict, **settings):
        super().__init__(settings)
        self._names = names

    def _print_Symbol(self, expr):
        return self._names.get(expr) or expr.name

    def _print_Pow(self, expr, rational=False):
        exp = expr.exp
        if exp.is_Integer and 2 <= exp <= 9:
            # a compound base keeps its parentheses: (m₁ + m₂)²
            return self.parenthesize(expr.base, precedence(expr), strict=True) + str(exp).translate(_SUP)
        return super()._print_Pow(expr, rational)

    def _print_Mul(self, expr):
        return _juxtapose(super()._print_Mul(expr))


def _juxtapose(text: str) -> str:
    """``a*b`` -> ``a b`` in printed text (``**`` untouched), ``2*3`` -> ``2·3``."""

    def sub(m):
        left, right = m.group(1), m.string[m.end()]
        return f"{left}{'·' if left.isdigit() and right.isdigit() else ' '}"

    return _STAR.sub(sub, text)


# a lone "*" (not part of "**") between two printed factors
_STAR = re.compile(r"([^*\s])\*(?=[^*\s])")


def latex_name(name: str, dots: str = "") -> str | None:
    """``theta1`` -> ``\\theta_{1}``, with ``dots`` "_dot"/"_ddot": ``\\dot{\\theta}_{1}``,
    ``\\ddot{d}_{2}`` (the accent on the letter, the index outside); ``l1`` -> ``l_{1}``,
    ``lc1`` -> ``l_{c1}``.
    None for names that are not letters + optional digits."""
    m = _NAME_PARTS.fullmatch(name)
    if not m:
        return None
    base, digits = m.groups()
    if len(base) == 2 and base not in GREEK and not dots:
        return f"{base[0]}_{{{base[1]}{digits}}}"  # lc1 -> l_{c1}, as the field writes it
    letter = f"\\{base}" if base in GREEK else base
    if len(base) > 1 and base not in GREEK:
        letter = rf"\mathit{{{base}}}"  # a multi-letter name is one symbol, not a product
    if dots:
        letter = {"_dot": r"\dot", "_ddot": r"\ddot"}[dots] + f"{{{letter}}}"
    return f"{letter}_{{{digits}}}" if digits else letter


_LATEX_NAMES: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def latex_symbol_names(robot) -> dict:
    """Symbol -> LaTeX for a robot's q, qd, qdd and parameters, for SymPy's printer:
    ``sp.latex(expr, symbol_names=latex_symbol_names(robot))`` writes
    ``\\dot{\\theta}_{1}`` where SymPy alone writes ``\\theta_{1 dot}``. Built once per
    robot. In Jupyter, ``sympy.init_printing(symbol_names=latex_symbol_names(robot))``
    displays every SymPy result of that robot this way. A coordinate whose name is not
    letters + digits (``shoulder_pan``) keeps SymPy's name, dotted as a whole."""
    try:
        return _LATEX_NAMES[robot]
    except (KeyError, TypeError):
        pass
    names = {}
    for q, qd, qdd in zip(robot.q, robot.qd, robot.qdd):
        plain = sp.latex(q)
        for sym, dots in ((q, ""), (qd, "_dot"), (qdd, "_ddot")):
            tex = latex_name(q.name, dots)
            if tex is None and dots:
                tex = {"_dot": r"\dot", "_ddot": r"\ddot"}[dots] + f"{{{plain}}}"
            if tex is not None:
                names[sym] = tex
    for sym in robot.parameters.values():
        tex = latex_name(sym.name)
        if tex is not None:
            names[sym] = tex
    try:
        _LATEX_NAMES[robot] = names
    except TypeError:  # not weak-referenceable: rebuilt on each call
        pass
    return names
