"""Proof exercises: the parallel axis theorem and the rotational kinetic energy, one
variant per student in its own notation, with the worked proof (graded by
``armdyn.grading.proofs``) and the slips a test injects.

A proof is a list of blocks: prose (str) or a display equation (:class:`ProofLine`) with
the wrong versions a slip may put in its place. What is drawn per variant: the reference
point's letter and the displacement vector's name (parallel axis), bold or plain vectors,
the identity written ``\\mathbf{1}`` or ``\\mathbf{I}``, integrals over the body ``dm`` or
over the link's volume ``\\rho dV`` (rotational energy).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

PROOF_KINDS = ("parallel-axis", "rotational-energy")

#: the model a proof submission names (the grader needs one; a proof uses none of its symbols)
PROOF_MODEL = """# armdyn exercise make: the model a proof submission names (armdyn grade needs one;
# the proof uses none of its symbols)
name: proof
parameters: [m1, l1, g]
gravity: [0, -g, 0]
joints:
  - {name: theta1, type: revolute, parent: base, child: link1}
links:
  - {name: link1, mass: m1, com: [l1, 0, 0], inertia: 0}
"""


@dataclass(frozen=True)
class ProofLine:
    """A display equation and wrong versions of it (each a slip a student makes)."""

    latex: str
    slips: tuple = ()
    slip_names: tuple = ()


def _parallel_axis(rng) -> tuple[str, list]:
    point = ("A", "P", "Q", "B")[int(rng.integers(4))]
    vec = ("d", "p")[int(rng.integers(2))]
    bold = bool(rng.integers(2))
    one = (r"\mathbf{1}", r"\mathbf{I}")[int(rng.integers(2))]

    def v(name):
        return rf"\mathbf{{{name}}}" if bold else name

    rA, rC, d = v(f"r_{point}"), v("r_C"), v(vec)
    IA, IC = rf"\mathbf{{I}}_{point}", r"\mathbf{I}_C"
    integral = r"\int_{\mathcal{B}}"
    blocks = [
        (
            f"Prove that the inertia tensor of a rigid body about a point {point} is the one about its mass center "
            f"C plus that of the whole mass M placed at C."
        ),
        "## Proof",
        f"By definition, with ${rA}$ the position of the mass element $dm$ relative to {point},",
        ProofLine(
            rf"{IA} = {integral} \left( {rA}^T {rA} {one} - {rA} {rA}^T \right) dm",
            (rf"{IA} = {integral} \left( {rA}^T {rA} {one} + {rA} {rA}^T \right) dm",),
            ("wrong sign",),
        ),
        "Every element's position relative to the point is its position relative to C plus a constant:",
        ProofLine(rf"{rA} = {rC} + {d}"),
        "and C is the mass center:",
        ProofLine(rf"{integral} {rC} \, dm = \mathbf{{0}}"),
        "The square of the sum is",
        ProofLine(
            rf"({rC} + {d})^T ({rC} + {d}) = {rC}^T {rC} + 2 {d}^T {rC} + {d}^T {d}",
            (
                rf"({rC} + {d})^T ({rC} + {d}) = {rC}^T {rC} + {d}^T {rC} + {d}^T {d}",
                rf"({rC} + {d})^T ({rC} + {d}) = {rC}^T {rC} + 2 {d}^T {rC}",
            ),
            ("factor missing", "missing term"),
        ),
        "Substituting and splitting the integral,",
        ProofLine(
            rf"{IA} = {integral} \left( ({rC} + {d})^T ({rC} + {d}) {one} - ({rC} + {d})({rC} + {d})^T \right) dm"
            rf" = {IC} + {integral} \left( 2 {d}^T {rC} {one} - {rC} {d}^T - {d} {rC}^T \right) dm"
            rf" + M \left( {d}^T {d} {one} - {d} {d}^T \right)",
            (
                (
                    rf"{IA} = {integral} \left( ({rC} + {d})^T ({rC} + {d}) {one} - ({rC} + {d})({rC} + {d})^T \right)"
                    rf" dm = {IC} + {integral} \left( 2 {d}^T {rC} {one} - {rC} {d}^T - {d} {rC}^T \right) dm"
                    rf" + M \left( {d}^T {d} {one} + {d} {d}^T \right)"
                ),
            ),
            ("wrong sign",),
        ),
        "The middle integral is linear in the position relative to C, so it vanishes:",
        ProofLine(
            rf"{IA} = {IC} + M \left( {d}^T {d} {one} - {d} {d}^T \right)",
            (rf"{IA} = {IC} + \left( {d}^T {d} {one} - {d} {d}^T \right)",),
            ("factor missing",),
        ),
    ]
    return "the parallel axis theorem", blocks


def _rotational_energy(rng) -> tuple[str, list]:
    volume = bool(rng.integers(2))
    R = (r"\mathbf{R}", "R")[int(rng.integers(2))]
    tT = (r"\mathrm{T}", "T")[int(rng.integers(2))]
    one = (r"\mathbf{1}", r"\mathbf{I}")[int(rng.integers(2))]
    if volume:
        integral, measure = r"\int_{V_{l_i}}", r"\rho dV"
    else:
        integral, measure = r"\int_{\mathcal{B}}", "dm"
    blocks = [
        (
            r"Prove that the kinetic energy of rotation of link i is $E_{rot} = \frac{1}{2}\omega^{cT} I^c \omega^c$ "
            "in any frame c."
        ),
        "## Proof",
        r"Each mass element moves with the velocity $\omega_i \times r_i$, so",
        ProofLine(
            rf"E_{{rot}} = \frac{{1}}{{2}} {integral} (\omega_i \times r_i)^T (\omega_i \times r_i) {measure}"
            rf" = \frac{{1}}{{2}} {integral} r_i^T S^T(\omega_i) S(\omega_i) r_i {measure}",
            (
                (
                    rf"E_{{rot}} = {integral} (\omega_i \times r_i)^T (\omega_i \times r_i) {measure}"
                    rf" = {integral} r_i^T S^T(\omega_i) S(\omega_i) r_i {measure}"
                ),
            ),
            ("factor missing",),
        ),
        "The skew matrix swaps its argument with the vector it multiplies, changing sign:",
        ProofLine(r"S(\omega_i) r_i = -S(r_i) \omega_i", (r"S(\omega_i) r_i = S(r_i) \omega_i",), ("wrong sign",)),
        "so that",
        ProofLine(
            rf"\frac{{1}}{{2}} {integral} r_i^T S^T(\omega_i) S(\omega_i) r_i {measure}"
            rf" = \frac{{1}}{{2}} \omega_i^T \left( {integral} S^T(r_i) S(r_i) {measure} \right) \omega_i"
            rf" = \frac{{1}}{{2}} \omega_i^T I_{{l_i}} \omega_i"
        ),
        "In frame c the tensor and the angular velocity are",
        ProofLine(
            rf"I^c_{{l_i}} = {R}^c I_{{l_i}} {R}^{{c{tT}}}",
            (rf"I^c_{{l_i}} = {R}^{{c{tT}}} I_{{l_i}} {R}^c",),
            ("transposed",),
        ),
        ProofLine(rf"\omega^c = {R}^c \omega_i"),
        rf"hence, with ${R}^{{c{tT}}} {R}^c = {one}$,",
        ProofLine(
            rf"\frac{{1}}{{2}}\omega^{{c{tT}}} I^c_{{l_i}} \omega^c"
            rf" = \frac{{1}}{{2}}\omega_i^T {R}^{{c{tT}}} {R}^c I_{{l_i}} {R}^{{c{tT}}} {R}^c \omega_i"
            rf" = \frac{{1}}{{2}} \omega_i^T I_{{l_i}} \omega_i = E_{{rot}}"
        ),
    ]
    return "the kinetic energy of rotation", blocks


def proof_blocks(kind: str, rng: np.random.Generator) -> tuple[str, list]:
    """``(title, blocks)`` of the worked proof of ``kind`` in a notation drawn from ``rng``."""
    return {"parallel-axis": _parallel_axis, "rotational-energy": _rotational_energy}[kind](rng)


def proof_markdown(blocks: list, front: dict, title: str, slip: tuple[int, int] | None = None):
    """The proof as Markdown (front matter first) and the line of each equation:
    ``(text, {block index: line})``. ``slip = (block index, k)`` writes that equation's
    k-th wrong version instead."""
    import yaml

    head = ["---", yaml.safe_dump(front, sort_keys=True, default_flow_style=False).rstrip(), "---", f"# {title}", ""]
    lines = list(head)
    where = {}
    for k, b in enumerate(blocks):
        if isinstance(b, ProofLine):
            latex = b.slips[slip[1]] if slip is not None and slip[0] == k else b.latex
            where[k] = len(lines) + 1
            lines += [f"$${latex}$$", ""]
        else:
            lines += [b, ""]
    return "\n".join(lines).rstrip() + "\n", where


def slippable_lines(blocks: list) -> list[int]:
    """Indices of the equations that have wrong versions."""
    return [k for k, b in enumerate(blocks) if isinstance(b, ProofLine) and b.slips]
