"""Names from a model file made safe to print into generated source.

A model's names (robot, links, joints) come from files armdyn may not trust: a student's
submission, a URDF found online. Generated code is compiled and loaded, or imported, so
a name must never end the comment or docstring it is printed in, and two names must
never become one variable. Two transformations, both pure functions of the name:

* :func:`comment_text`: text for a C block comment or a Python docstring. Printable
  ASCII only; every other character, and every character that could end or bend the
  comment (``"``, ``\\``, ``?``, a ``/`` next to a ``*``), is written ``<U+XXXX>``.
* :func:`identifier_base`: an ASCII identifier stem (``[A-Za-z_][A-Za-z0-9_]*``), not
  starting with ``_`` (reserved in C); :class:`~armdyn.printing.printers.Names` makes the
  stems unique, so names that differ only under Unicode normalisation (``q1`` and the
  fullwidth ``ｑ1``, one name to Python, which reads identifiers in NFKC) stay two.
"""

from __future__ import annotations

import re

_PLAIN = set(map(chr, range(0x20, 0x7F))) - set('"\\?')
_NOT_IDENTIFIER = re.compile(r"[^A-Za-z0-9_]")


def _escaped(ch: str) -> str:
    return f"<U+{ord(ch):04X}>"


def comment_text(text) -> str:
    """``text`` (anything; ``str()`` of it) as printable ASCII that cannot end a C block
    comment (``*/``), a Python docstring (``\"\"\"``), start an escape (``\\``) or a C
    trigraph (``??/``): each other character is written ``<U+XXXX>``."""
    text = str(text)
    out = []
    for k, ch in enumerate(text):
        near_star = ch == "/" and ((k > 0 and text[k - 1] == "*") or (k + 1 < len(text) and text[k + 1] == "*"))
        out.append(ch if ch in _PLAIN and not near_star else _escaped(ch))
    return "".join(out)


def identifier_base(name: str, fallback: str = "v") -> str:
    """An ASCII identifier stem for ``name``: every character outside ``[A-Za-z0-9_]``
    becomes ``_``; ``fallback + "_"`` goes in front of a stem that is empty, starts with a
    digit or with ``_``. Not unique by itself (``a-b`` and ``a_b`` give ``a_b``)."""
    base = _NOT_IDENTIFIER.sub("_", str(name))
    if not base or base[0].isdigit() or base[0] == "_":
        base = f"{fallback}_{base}"
    return base


__all__ = ["comment_text", "identifier_base"]
