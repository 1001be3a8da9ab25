"""The kind of a wrong step, read from the grader's message (``armdyn.grading.explain``),
when :mod:`.slipkinds` (the values themselves) cannot tell.

``describe`` writes one sentence per wrong component; its opening words name the slip:

=====================  ==========================================================
kind                   message starts with
=====================  ==========================================================
missing term           ``missing term(s) …``
extra term             ``extra term(s) …``
wrong sign             ``sign flipped`` / ``wrong sign on the term …``
derivative mixed up    ``θ̇1 written where θ̈1 belongs`` (any two of q, q̇, q̈)
factor missing         ``a factor l1 missing on …``
extra factor           ``an extra factor …``
wrong shape            ``… must be a vector …`` / a scalar for a vector
other                  ``differs by …`` and anything else
=====================  ==========================================================
"""

from __future__ import annotations

import re

#: the kinds, in the order a summary lists them when counts tie
KINDS = (
    "missing term",
    "extra term",
    "wrong sign",
    "derivative mixed up",
    "factor missing",
    "extra factor",
    "inertia about the wrong point",
    "transposed rotation",
    "wrong shape",
    "proof: sign",
    "proof: transpose",
    "proof: mass-centre fact about the wrong point",
    "proof: factor",
    "proof: dropped term",
    "other",
)

_PATTERNS = (
    ("missing term", re.compile(r"^missing terms?\b")),
    ("extra term", re.compile(r"^extra terms?\b")),
    ("wrong sign", re.compile(r"^(sign flipped|wrong sign)\b")),
    ("derivative mixed up", re.compile(r"\bwritten where\b.*\bbelongs\b")),
    ("factor missing", re.compile(r"^a factor\b.*\bmissing\b")),
    ("extra factor", re.compile(r"^an extra factor\b")),
    ("wrong shape", re.compile(r"\b(must be a|is a scalar|is a vector)\b")),
)


def classify(message: str) -> str:
    """The kind of slip a wrong step's message describes (the first component's)."""
    first = (message or "").split("; ")[0].strip()
    for kind, pattern in _PATTERNS:
        if pattern.search(first):
            return kind
    return "other"
