"""The gravity a text states: Newton-Euler's base acceleration (gravity its opposite), the
gravity vector itself (``g = (-g, 0, 0)^T``), or a sentence ("gravity acts along $-y_0$");
several stated: the one most statements give, the others kept as alternative readings."""

from __future__ import annotations

import re

import sympy as sp

from .geometry import pretty_vector, same, vector

#: "gravity acts along $-y_0$", "Gravity pulls along $-\\hat Y_0$", "gravity along -z"
_GRAVITY_WORDS = re.compile(
    r"[Gg]ravity\b[^.\n]{0,40}?\b(?:along|towards?|in the direction of)\s*\$?\s*(-|−|\+)?\s*"
    r"(?:\\hat\s*\{?\s*|\\mathbf\s*\{\s*)?([xyzXYZ])(?![A-Za-z])"
)


def _gravity_in_words(text: str):
    """(axis, sign, line) of the first sentence saying along which base axis gravity acts, or None."""
    m = _GRAVITY_WORDS.search(text[:200_000])
    if m is None:
        return None
    sign = 1 if m.group(1) in (None, "+") else -1
    return "xyz".index(m.group(2).lower()), sign, text.count("\n", 0, m.start()) + 1


def read_gravity(reader, statements):
    """(gravity vector, line or None) for ``reader`` (a :class:`~.reader.TextReader`):
    its assumptions and conflicts get what was read; see the module's docstring."""
    # Newton-Euler's base acceleration (gravity its opposite) or the gravity vector itself;
    # a text may show other cases in passing ("for gravity along -z, set ..."): the one
    # most statements give is used (a tie: the first written), the others named and kept
    # as alternatives (:attr:`TextModel.alternatives`: the grading keeps the reading the
    # text's later steps agree with)
    options: list[list] = []  # [gravity, statements giving it]
    for st in statements:
        v = vector(st.value) if st.what in ("g", "gv") else None
        if v is None or (st.what == "gv" and (v == sp.zeros(3, 1) or not v.free_symbols)):
            continue
        g = -v if st.what == "g" else v
        for option in options:
            if same(option[0], g, reader.free):
                option[1].append(st)
                break
        else:
            options.append([g, [st]])
    if options:
        ranked = sorted(options, key=lambda o: (-len(o[1]), o[1][0].line))
        reader.gravity_options = len(ranked)
        best = ranked[min(reader.gravity_choice, len(ranked) - 1)]
        g, first = best[0], best[1][0]
        lines = ", ".join(str(x) for x in dict.fromkeys(st.line for st in best[1]))
        for option in ranked:
            if option is not best:
                reader.conflicts.append(
                    f"line {option[1][0].line} states another gravity, {pretty_vector(option[0])}, than "
                    f"line{'s' if ',' in lines else ''} {lines} ({pretty_vector(g)} used)"
                )
        how = (
            f"the base accelerates by {pretty_vector(-g)} (Newton-Euler's way of putting in gravity)"
            if first.what == "g"
            else "the gravity vector stated"
        )
        reader.assumptions.append(f"gravity {pretty_vector(g)}, from line {first.line}: {how}")
        reader.gravity_source = f"line {first.line}: {first.source[:70]}"
        return g, first.line
    worded = _gravity_in_words(getattr(reader, "text", ""))
    if worded is not None:
        axis, sign, line = worded
        g = sp.zeros(3, 1)
        g[axis] = sign * sp.Symbol(reader.names.named("g", ""))
        reader.assumptions.append(
            f"gravity {pretty_vector(g)}, from line {line}'s words (along {'-' if sign < 0 else '+'}{'xyz'[axis]}0)"
        )
        reader.gravity_source = f"line {line}: in words"
        return g, line
    g = sp.Matrix([0, -sp.Symbol("g"), 0])
    reader.assumptions.append("gravity (0, -g, 0), along -y0: no base acceleration or gravity vector is stated")
    return g, None
