"""What an exercise kind asks a student to write: its parts and its steps.

    exp = expected_for("rp")                 # an exercise kind of armdyn exercise make
    exp.parts, exp.steps                     # ("newton-euler", "lagrange"), (("newton-euler", "omega_0"), ...)
    exp = expected_from_report(report_json)  # a class with no variant folder: read from the report

An arm of ``n`` joints asks, in Newton-Euler, the base's ``omega_0, omega_dot_0, v_dot_0``,
then per link outwards ``omega_i, omega_dot_i, v_dot_i, vc_dot_i, F_i, N_i`` and inwards
``f_i, n_i, tau_i``; in Lagrange ``T, V, L`` and per coordinate ``dL_dqd_i, ddt_dL_dqd_i,
dL_dq_i, tau_i`` (the names ``armdyn grade`` gives the steps, the worked solution's
steps). A proof asks as many links (each ``=`` of each equation) as its worked proof has;
its links are named by line, so they are counted, not named.
"""

from __future__ import annotations

from dataclasses import dataclass

from ..grading.notation import LAGRANGE_KEYS  # a tau after one of them belongs to the Lagrange part

NE = "newton-euler"
LAGRANGE = "lagrange"
PROOF = "proof"
#: the parts of a gradebook, in column order
PARTS = (NE, LAGRANGE, PROOF)


@dataclass(frozen=True)
class Expected:
    """What one exercise kind asks.

    kind:    the exercise kind (``rp``, ``parallel-axis``), or for a kind read from a report
             ``arm-<n>`` / ``proof``
    parts:   the parts it has (of :data:`PARTS`)
    steps:   ``(part, step name)`` of every step it asks (arms)
    links:   how many links its worked proof has (proofs), else 0
    dof:     joints of the arm (0 for a proof)
    """

    kind: str
    parts: tuple
    steps: tuple = ()
    links: int = 0
    dof: int = 0


def arm_steps(dof: int, parts=(NE, LAGRANGE)) -> tuple:
    """``(part, name)`` of every step of an arm of ``dof`` joints, in the worked solution's order."""
    out = []
    if NE in parts:
        out += [(NE, n) for n in ("omega_0", "omega_dot_0", "v_dot_0")]
        for i in range(1, dof + 1):
            out += [(NE, f"{k}_{i}") for k in ("omega", "omega_dot", "v_dot", "vc_dot", "F", "N")]
        for i in range(dof, 0, -1):
            out += [(NE, f"{k}_{i}") for k in ("f", "n", "tau")]
    if LAGRANGE in parts:
        out += [(LAGRANGE, n) for n in ("T", "V", "L")]
        for i in range(1, dof + 1):
            out += [(LAGRANGE, f"{k}_{i}") for k in ("dL_dqd", "ddt_dL_dqd", "dL_dq", "tau")]
    return tuple(out)


def proof_links(kind: str) -> int:
    """The number of links (``=`` signs) of the worked proof of a proof kind."""
    import numpy as np

    from .proofkinds import ProofLine, proof_blocks

    _, blocks = proof_blocks(kind, np.random.default_rng(0))  # every notation has the same links
    return sum(b.latex.count("=") for b in blocks if isinstance(b, ProofLine))


def expected_for(kind: str) -> Expected:
    """What the exercise kind ``kind`` (of :mod:`.kinds` or :mod:`.proofkinds`) asks: both
    methods for an arm (the statement asks both), the links of the worked proof for a proof."""
    from .kinds import KINDS
    from .proofkinds import PROOF_KINDS

    if kind in PROOF_KINDS:
        return Expected(kind, (PROOF,), links=proof_links(kind))
    dof = len(KINDS[kind].rows)
    return Expected(kind, (NE, LAGRANGE), arm_steps(dof), dof=dof)


def expected_from_report(report: dict) -> Expected | None:
    """A kind read from a grade report when no exercise kind is known: a proof when its
    steps are links of a proof, else an arm of ``len(tau_correct)`` joints with the methods
    the report names (``newton-euler``, ``lagrange`` or both). None when nothing says how
    many joints (then only the steps written are counted)."""
    steps = [s for s in report.get("steps") or [] if isinstance(s, dict)]
    if any(str(s.get("name") or "").startswith("proof_") for s in steps):
        return Expected(PROOF, (PROOF,))
    dof = len(report.get("tau_correct") or [])
    if not dof:
        return None
    method = str(report.get("method") or "")
    parts = tuple(p for p in (NE, LAGRANGE) if p in method) or (NE,)
    return Expected(f"arm-{dof}", parts, arm_steps(dof, parts), dof=dof)


def key_of(name: str) -> str:
    """A step's key from its name: ``v_dot_1`` -> ``v_dot``, ``T`` -> ``T``, ``R_0^1`` -> ``R``."""
    if name in ("T", "V", "L") or not name:
        return name
    if name.startswith("R_"):
        return "R"
    if name.startswith("proof_"):
        return "proof"
    head, _, tail = name.rpartition("_")
    return head if tail.isdigit() else name


def parts_of_name(name: str) -> tuple:
    """The parts a step name given without its part belongs to: a tau to both methods."""
    key = key_of(name)
    if key == "tau":
        return (NE, LAGRANGE)
    if key == "proof":
        return (PROOF,)
    return (LAGRANGE,) if key in LAGRANGE_KEYS else (NE,)
