"""The formulas in the derivations' step notes, in each notation a report prints.

A step's note (``Step.note``: "inertial force m vcd") is plain ASCII, so that
``armdyn derive --ascii`` keeps it; the text report shows its formulas in Unicode
(:func:`note_text`: "inertial force m v̇_C") and the HTML report as MathML from their
LaTeX (``report_html.caption``). Both split a note with :func:`note_parts`.
"""

from __future__ import annotations

#: formulas in the derivations' step notes (plain ASCII there, so --ascii keeps them):
#: (ASCII, Unicode for the text report, LaTeX for HTML/MathML captions)
NOTE_FORMULAS = (
    ("m vcd", "m v̇_C", r"m \dot{v}_C"),
    ("vbd + wb x vb - gb", "v̇_b + ω_b × v_b − g_b", r"\dot{v}_b + \omega_b \times v_b - g_b"),
    ("I wd + w x I w", "I ω̇ + ω × I ω", r"I \dot{\omega} + \omega \times I \omega"),
    ("1/2 m vc.vc", "½ m v_Cᵀ v_C", r"\tfrac{1}{2} m \, v_C^{\mathsf{T}} v_C"),
    ("1/2 w^T I w", "½ ωᵀ I ω", r"\tfrac{1}{2} \omega^{\mathsf{T}} I \omega"),
    ("1/2 Ia qd^2", "½ I_a q̇²", r"\tfrac{1}{2} I_a \dot{q}^{2}"),
    ("-m gravity.pc", "−m gᵀ p_C", r"-m \, g^{\mathsf{T}} p_C"),
    (
        "d/dt dL/dqd - dL/dq",
        "d/dt ∂L/∂q̇ − ∂L/∂q",
        r"\frac{d}{dt} \frac{\partial L}{\partial \dot{q}} - \frac{\partial L}{\partial q}",
    ),
    ("dL/dq", "∂L/∂q", r"\frac{\partial L}{\partial q}"),
    ("T - V", "T − V", "T - V"),
)


def note_parts(note: str) -> list[tuple[str, int | None]]:
    """A step note split into ``(text, None)`` and ``(ascii_formula, k)`` pieces, ``k``
    indexing :data:`NOTE_FORMULAS` (the first, longest formula found wins)."""
    for k, (ascii_form, _, _) in enumerate(NOTE_FORMULAS):
        at = note.find(ascii_form)
        if at >= 0:
            tail = note[at + len(ascii_form) :]
            head = [(note[:at], None)] if at else []
            return head + [(ascii_form, k)] + (note_parts(tail) if tail else [])
    return [(note, None)] if note else []


def note_text(note: str) -> str:
    """The note with its formulas in Unicode: ``inertial force m v̇_C``."""
    return "".join(text if k is None else NOTE_FORMULAS[k][1] for text, k in note_parts(note))
