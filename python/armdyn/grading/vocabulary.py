"""The textbooks' names for the energy-method quantities, read from a normalised
left-hand side (:func:`armdyn.grading.notation.normalise`).

Craig, Spong-Hutchinson-Vidyasagar, Siciliano et al. and Lynch-Park name the same
quantities differently; each name below maps to one key of
:class:`~armdyn.grading.notation.StepRef`:

=============  ==================================================================
key            names
=============  ==================================================================
T (total)      ``K``, ``T``, ``KE``, ``k``, ``E_k``, ``\\mathcal{E}_K``, ``\\mathcal{K}``, ``\\mathcal{T}``
V (total)      ``U``, ``V``, ``P``, ``PE``, ``u``, ``E_p``, ``\\mathcal{U}``, ``\\mathcal{V}``, ``\\mathcal{P}``
Tl, Vl         the same with a link index: ``K_1``, ``T_2``, ``KE_1``, ``PE_1``, ``u_2``, ``P_1``,
               ``\\mathcal{E}_{K_1}`` (Lynch & Park)
pc             ``p_{c1}``, ``r_{c_2}``, ``x_{c1}`` / ``y_{c1}`` / ``z_{c1}`` (one component);
               ``x_1``, ``y_2``, ``P_{1,x}`` without the c when the value moves with the joints
vc             ``v_{c1}``, ``\\dot p_{c1}``, ``\\dot x_{c1}``, ``\\dot x_1``; squared: ``v_{c1}^2``,
               ``|v_{c1}|^2``, ``v_{c1}^T v_{c1}``, ``v_{c1} \\cdot v_{c1}``, a scalar ``v_2^2``; a
               scalar ``v_2``: the speed (a point mass's, by shape)
Jv, Jw         ``J_{v_1}``, ``J_{v_{c1}}``, ``J_{\\omega_1}``
M              ``M``, ``D``, ``H``, ``B``, ``M(q)``, ``D(q)``, ``M(\\theta)``, ``H(q)``, ``B(q)``;
               entries ``d_{11}``, ``m_{12}``, ``M_{11}``, ``D_{21}``, ``b_{12}``
christoffel    ``c_{ijk}``, ``\\Gamma_{ijk}``, ``h_{ijk}`` (three indices)
C              ``C``, ``C(q,\\dot q)`` (the Coriolis matrix)
h              ``V(\\theta,\\dot\\theta)`` (Craig), ``c(\\theta,\\dot\\theta)`` (Lynch & Park), ``h``,
               ``b(q,\\dot q)``, ``C(q,\\dot q)\\dot q``; entries ``h_i``
G              ``g(q)``, ``G(\\theta)``, ``G``, ``N(\\theta,\\dot\\theta)`` (Murray, Li & Sastry); entries ``g_k``, ``G_k``, ``\\phi_k``
               (``g`` alone is the gravity constant, not a step)
=============  ==================================================================

A name whose meaning depends on what it is given (``P_1``: an energy or Craig's
position; ``V``: the potential energy or Craig's centrifugal/Coriolis vector; ``L``: the
Lagrangian or an angular momentum; ``f_k``: a joint force or Newton-Euler's force; a
scalar ``\\omega_1``) is marked ``by_shape``: the grader decides from the value's shape and
says which reading it took (:func:`by_shape`).
"""

from __future__ import annotations

import re

from .text import NOT_A_STEP

_KINETIC = r"K|T|KE|k|E_\{?[kK]\}?|E_\{?kin\}?|KE"
_POTENTIAL = r"U|V|P|PE|u|E_\{?[pP]\}?|E_\{?pot\}?"
#: a function's arguments as students write them after a name: (q), (q,\dot{q}), (\theta,\dot\theta),
#: (\theta_2) (an entry M_{12}(\theta_2) written as a function of the joint it depends on)
_ARGS = re.compile(r"\(([\\A-Za-z0-9_{},]+)\)$")  # one character class: linear, no nested repetition
_ARG = re.compile(r"(?:\\?[A-Za-z]+|\\d?dot\{\\?[A-Za-z]+\})(?:_\{?\d\}?)?")
#: a left-hand side longer than this names no quantity (bounds the regular expressions below)
MAX_LHS = 120
_MC = r"(?:[CcG]|cm|CM|com)"
#: the alias of a position or speed written without the mass centre's c (``x_1``, ``v_2^2``)
POINT = "point"


def mass_centre(sub: str | None) -> int | None:
    """i of a subscript naming link i's mass centre (``C_1``, ``{c1}``, ``G_1``, ``cm,1``)."""
    if sub is None:
        return None
    m = re.fullmatch(_MC + r"(\d+)", re.sub(r"[{}\s,_]|\\mathrm|\\text", "", sub))
    return int(m.group(1)) if m else None


def _digits(sub: str | None, count: int) -> tuple | None:
    """The ``count`` one-digit indices of ``{12}``, ``{1,2}``, ``{1 2}``, or None."""
    if sub is None:
        return None
    t = re.sub(r"[{}\s,_]", "", sub)
    return tuple(int(c) for c in t) if len(t) == count and t.isdigit() else None


def _index(sub: str | None) -> int | None:
    if sub is None:
        return None
    t = re.sub(r"[{}\s]", "", sub)
    return int(t) if t.isdigit() else None


def energy_lhs(s: str, ref_type):
    """The StepRef (built by ``ref_type``) of an energy-method name in the normalised
    left-hand side ``s``, or None."""
    if s in ("\\tau", "\\boldsymbol{\\tau}") or re.fullmatch(
        r"\((?:\\tau_\{?\d\}?,?)+\)\^(?:\{?T\}?|\\top|\{\\top\}|\{\\mathrm\{T\}\})", s
    ):
        return ref_type("tau_vec")  # the joint torques as one column: (\tau_1, \tau_2)^T = ...
    if len(s) > MAX_LHS:
        return None
    had_args = False
    m = _ARGS.search(s)
    if m and m.start() > 0 and all(_ARG.fullmatch(a) for a in m.group(1).split(",")):
        s, had_args = s[: m.start()], True
    # totals
    if re.fullmatch(_KINETIC, s):
        return ref_type("T", alias=s)
    if re.fullmatch(_POTENTIAL, s):
        if s == "V" and had_args and m and "dot" in m.group(0):
            return ref_type("h", alias="V")  # Craig's V(θ, θ̇): the centrifugal/Coriolis vector
        return ref_type("V", alias=s, by_shape=s in ("V", "P"))
    if s in ("L", "H") and not had_args:
        return ref_type("L", alias=s, by_shape=True) if s == "L" else ref_type("M", alias="H", by_shape=True)
    # a bare letter is a matrix or vector of the method only when its value is one
    # (M = m_1 + m_2 in a proof is a total mass): by_shape
    if s in ("M", "D", "H", "B"):  # B(q): Siciliano et al.
        return ref_type("M", alias=s, by_shape=not had_args)
    if s == "C":
        return ref_type("C", alias=s, by_shape=not had_args)
    if s in ("h", "b") or (s in ("V", "c") and had_args):  # c(θ, θ̇): Lynch & Park
        return ref_type("h", alias=s, by_shape=not had_args)
    if re.fullmatch(r"C(?:\([^()]*\))?\\dot\{(?:q|\\theta|\\boldsymbol\{q\})\}", s):  # C(q, q̇) q̇
        return ref_type("h", alias="C q̇")
    if s in ("G",) or (s in ("g", "N") and had_args):  # N(θ, θ̇): Murray, Li & Sastry (N alone: a moment)
        return ref_type("G", alias=s, by_shape=not had_args)
    # |v|^2, v^T v, v . v
    sq = re.fullmatch(r"(?:\||\\\||\\lVert|\\vert|\\Vert)(.+?)(?:\||\\\||\\rVert|\\vert|\\Vert)\^\{?2\}?", s)
    if sq:
        inner = energy_lhs(sq.group(1), ref_type)
        return ref_type("vc", inner.index, part="sq") if inner is not None and inner.key == "vc" else None
    dot = re.fullmatch(r"(.+?)(?:\^\{?(?:T|\\top|\\mathrm\{T\})\}?|\\cdot)(.+)", s)
    if dot and dot.group(1) == re.sub(r"\^\{?(?:T|\\top)\}?$", "", dot.group(2)):
        inner = energy_lhs(dot.group(1), ref_type)
        return ref_type("vc", inner.index, part="sq") if inner is not None and inner.key == "vc" else None
    return _indexed(s, ref_type)


def _indexed(s: str, ref_type):
    dots = 0
    acc = re.match(r"\\(d?dot)\{([^{}]*)\}", s)
    if acc:
        dots = 2 if acc.group(1) == "ddot" else 1
        s = acc.group(2) + s[acc.end() :]
    m = re.match(r"(\\[A-Za-z]+|[A-Za-z]+?)(?=[_^]|$)", s)
    if not m:
        return None
    base, rest = m.group(1), s[m.end() :]
    sub, sup = _split_scripts(rest)
    if sub is False:
        return None
    if base in ("x", "y", "z") and mass_centre(sub) is not None and sup is None and dots < 2:
        return ref_type("vc" if dots else "pc", mass_centre(sub), part=base)
    if base in ("p", "r", "v") and mass_centre(sub) is not None and dots + (base == "v") == 1 and (sup in (None, "2")):
        return ref_type("vc", mass_centre(sub), part="sq" if sup == "2" else "")
    if base in ("p", "r") and mass_centre(sub) is not None and dots == 0 and sup is None:
        return ref_type("pc", mass_centre(sub))
    # a point mass's (a link's) position or speed without the c: x_1, \dot x_1, v_2^2; read as
    # link i's mass centre only when the value moves with the joints (decided in the grader)
    if base in ("x", "y", "z") and _index(sub) is not None and sup is None and dots < 2:
        return ref_type("vc" if dots else "pc", _index(sub), part=base, alias=POINT, by_shape=True)
    comp = re.fullmatch(r"\{?(\d+)\s*,\s*([xyz])\}?", sub or "")
    if base in ("P", "p", "r") and comp and sup is None and dots < 2:  # P_{1,x}: one component of a point
        return ref_type("vc" if dots else "pc", int(comp.group(1)), part=comp.group(2), alias=POINT, by_shape=True)
    if base == "v" and _index(sub) is not None and sup == "2" and not dots:
        return ref_type("vc", _index(sub), part="sq", alias=POINT, by_shape=True)
    if base == "v" and _index(sub) is not None and sup is None and not dots:  # a point mass's speed
        return ref_type("vc", _index(sub), part="speed", alias=POINT, by_shape=True)
    if dots:
        return None
    if base == "J" and sub is not None and sup is None:
        j = re.fullmatch(r"(v|\\omega|w)" + _MC + r"?(\d+)", re.sub(r"[{}\s,_]|\\mathrm", "", sub))
        return ref_type("Jv" if j.group(1) == "v" else "Jw", int(j.group(2))) if j else None
    if base == "g" and _index(sub) is not None and sup is not None and _index(sup) is not None:
        return ref_type("G", entry=(_index(sub),), alias="g", frame=_index(sup), by_shape=True)  # g_2^2: a vector
    if sup is not None:
        return None
    if base in ("c", "s", "C", "S") and (_digits(sub, 1) or _digits(sub, 2) or (base != "c" and _digits(sub, 3))):
        digits = _digits(sub, 1) or _digits(sub, 2) or _digits(sub, 3)
        return ref_type("shorthand", entry=digits, alias=base, by_shape=True)  # c_1 = \cos\theta_1: by the value
    if base in ("c", "\\Gamma", "h") and _digits(sub, 3):
        return ref_type("christoffel", entry=_digits(sub, 3), alias=base)
    if base in ("d", "m", "M", "D", "b", "B", "H") and _digits(sub, 2):  # H_{12}: Asada & Slotine
        return ref_type("M", entry=_digits(sub, 2), alias=base)
    if base in ("h", "b") and _index(sub) is not None:
        return ref_type("h", entry=(_index(sub),), alias=base)
    if base in ("g", "G", "\\phi") and _index(sub) is not None:  # g_k: an entry, or gravity in frame k (by shape)
        return ref_type("G", entry=(_index(sub),), alias=base, by_shape=base == "g")
    i = _index(sub)
    if i is None:
        e = re.fullmatch(r"\{?([kpKP])[,_]?\{?(\d+)\}?\}?", sub or "")  # E_{k,1}, E_{p1}, E_{K_1} (Lynch & Park)
        if base == "E" and e:
            return ref_type("Tl" if e.group(1) in "kK" else "Vl", int(e.group(2)), alias="E_" + e.group(1))
        return None
    if re.fullmatch(_KINETIC, base):
        return ref_type("Tl", i, alias=base)
    if re.fullmatch(_POTENTIAL, base):
        return ref_type("Vl", i, alias=base, by_shape=base in ("P", "u"))  # u_1: an energy, or De Luca's torque
    if base in ("L", "H"):
        return ref_type("Lang", i, alias=base)
    return None


def scripts(s: str, i: int):
    """Read ``_X`` / ``^X`` pairs from ``s[i:]``; returns (sub, sup, end)."""
    sub = sup = None
    while i < len(s) and s[i] in "_^":
        mark = s[i]
        i += 1
        if i < len(s) and s[i] == "{":
            depth, j = 1, i + 1
            while j < len(s) and depth:
                depth += {"{": 1, "}": -1}.get(s[j], 0)
                j += 1
            text, i = s[i + 1 : j - 1], j
        elif i < len(s) and s[i] == "\\":
            m = re.match(r"\\[A-Za-z]+", s[i:])
            text = m.group(0) if m else s[i : i + 2]
            i += len(text)
        else:
            text, i = s[i : i + 1], i + 1
        if mark == "_":
            sub = text if sub is None else sub + "," + text
        else:
            sup = text if sup is None else sup + "," + text
    return sub, sup, i


def _split_scripts(rest: str):
    """(sub, sup) of ``_X^Y`` / ``^Y_X`` (braced or one character), or (False, None)."""
    sub, sup, end = scripts(rest, 0)
    return (sub, sup) if end == len(rest) else (False, None)


#: steps checked directly against the model's energy-method quantities (no carry-forward)
MODEL_KEYS = ("Tl", "Vl", "pc", "vc", "w", "Jv", "Jw", "M", "christoffel", "C", "h", "G")


def model_name(ref) -> str:
    """The step name armdyn reports for an energy-method quantity."""
    entry = "".join(str(k) for k in ref.entry)
    if ref.key in ("Tl", "Vl"):
        return f"{ref.key[0]}_{ref.index}"
    if ref.key == "pc":
        return f"{ref.part or 'p'}_c{ref.index}"
    if ref.key == "vc":
        names = {"sq": f"v_c{ref.index}^2", "": f"v_c{ref.index}", "speed": f"|v_c{ref.index}|"}
        return names.get(ref.part, f"{ref.part}dot_c{ref.index}")
    if ref.key == "w":
        return f"omega_{ref.index}"
    if ref.key in ("Jv", "Jw"):
        return f"J_{ref.key[1]}{ref.index}"
    if ref.key == "Lang":
        return f"H_{ref.index}"
    if ref.key == "christoffel":
        return f"c_{entry}"
    if ref.key == "shorthand":
        return f"{ref.alias}_{entry}"
    return f"{ref.key}_{entry}" if entry else ref.key


#: bare letters that are the method's matrices or vectors only when their value is one
SOFT = ("M", "C", "G", "h")


def by_shape(ref, value, step_ref, is_prismatic=None, dof=0, moves=True):
    """The reading of a ``by_shape`` left-hand side given its value, and what was assumed
    (None when the shape fits no reading). ``value``: SymPy scalar or matrix;
    ``step_ref(key, index, **kw)`` builds the new reference; ``moves``: the value depends
    on the joint coordinates or their rates."""
    import sympy as sp

    shape = value.shape if isinstance(value, sp.MatrixBase) else (1, 1)
    scalar = shape == (1, 1)
    if ref.alias == POINT:
        return _point(ref, scalar, moves)
    spong = _spong(ref, shape, step_ref)
    if spong is not None:
        return spong
    # a 0 stands for a zero vector as well (\omega_0 = 0); a frame written makes it a vector
    vector_reading = ref.frame is not None or (scalar and not isinstance(value, sp.MatrixBase) and value == 0)
    column = shape[1] == 1 and not scalar
    name = ref.alias or ref.key
    if ref.key == "V" and ref.index is None:
        if scalar:
            return ref, ""
        if column and ref.alias != "V":
            return None, f"a vector {name} names no step: a position is written with its frame, as P_1^0"
        if column:
            return step_ref("h", alias="V"), (
                f"{name} read as Craig's centrifugal and Coriolis vector V(θ, θ̇) (a column; the potential energy is a scalar)"
            )
    if ref.key == "Vl":
        if scalar:
            return ref, f"{name}_{ref.index} read as link {ref.index}'s potential energy (a scalar)"
        if column:
            return step_ref("P", ref.index), f"{name}_{ref.index} read as Craig's position vector (a vector)"
    if ref.key == "L":
        if scalar:
            return step_ref("L", alias=ref.alias), ""
        return None, (
            f"a {shape[0]}x{shape[1]} {name} is an angular momentum, not the Lagrangian: name its link "
            f"({name}_1) to have it checked"
        )
    if ref.key == "M" and ref.alias == "H" and column and shape[0] == 3:
        return None, "a 3-vector H is an angular momentum: name its link (H_1) to have it checked"
    if ref.key in SOFT and (scalar and not isinstance(value, sp.MatrixBase)) and dof != 1:
        return None, NOT_A_STEP  # a scalar M, C, G, h: a total mass, a constant, a height...
    if ref.key == "omega":
        if scalar and not vector_reading:
            return step_ref("w", ref.index), (
                f"a scalar ω_{ref.index} read as link {ref.index}'s angular velocity about the (planar) axis"
            )
        return ref, ""
    if ref.key == "f":
        if scalar and is_prismatic is not None and not vector_reading:
            return step_ref("tau", ref.index), (
                f"a scalar f_{ref.index} read as joint {ref.index}'s generalised force τ_{ref.index}"
                + ("" if is_prismatic else f" (joint {ref.index} is revolute: a torque)")
            )
        return ref, ""
    return ref, ""


def _spong(ref, shape, step_ref):
    """Spong's Newton-Euler names read by shape: ``\\alpha_i`` (a vector: ω̇_i; a scalar: a DH
    twist), ``g_i`` (a 3-vector: gravity in frame i; a scalar: the gravity vector's entry),
    ``\\tau_i`` (a 3-vector: the moment on link i at joint i, n_i); None for other names."""
    scalar, vector = shape == (1, 1), shape == (3, 1)
    if ref.key == "omega_dot" and ref.alias == "alpha":
        if not vector:
            return None, NOT_A_STEP  # \alpha_1 = 0: a DH twist
        return step_ref("omega_dot", ref.index, frame=ref.frame), (
            f"α_{ref.index} read as link {ref.index}'s angular acceleration ω̇_{ref.index} (Spong)"
        )
    if ref.key == "G" and ref.alias == "g":
        k = ref.entry[0]
        if vector:
            return step_ref("gvec", k, frame=ref.frame), (
                f"g_{k} read as gravity expressed in frame {k} (a 3-vector; a scalar g_{k} is the gravity vector's entry)"
            )
        if scalar and ref.frame is None:
            return step_ref("G", entry=ref.entry, alias="g"), ""
        return None, f"g_{k}: a {shape[0]}x{shape[1]} value is neither gravity in frame {k} nor an entry of g(q)"
    if ref.key == "tau" and vector:
        return step_ref("n", ref.index, frame=ref.frame), (
            f"a 3-vector τ_{ref.index} read as Spong's moment on link {ref.index} at joint {ref.index}, "
            f"n_{ref.index} (a scalar τ_{ref.index} is the joint torque)"
        )
    if ref.key == "tau":
        return ref, ""
    return None


def _point(ref, scalar: bool, moves: bool):
    """``x_1``, ``\\dot x_1``, ``v_2^2``: link i's mass centre when the value is a scalar that moves."""
    i = ref.index
    if not scalar and ref.part == "sq":
        return None, f"a vector v_{i}^2 is Craig's velocity of frame {i}'s origin in frame {i}, not graded"
    if not scalar or not moves:
        return None, NOT_A_STEP  # a constant, a length, a vector: the student's own name
    if ref.part == "sq":
        return ref, f"v_{i}^2 read as the squared speed of link {i}'s mass centre (a scalar)"
    if ref.part == "speed":
        return ref, f"v_{i} read as the speed of link {i}'s mass centre (a scalar, |v_c{i}|)"
    what = "position" if ref.key == "pc" else "velocity"
    name = {"x": "ẋ", "y": "ẏ", "z": "ż"}[ref.part] if ref.key == "vc" else ref.part
    return ref, f"{name}_{i} read as link {i}'s mass centre ({ref.part} of its {what} in the base frame)"


def student_names(ref) -> list[str]:
    """The plain names (as :class:`~armdyn.grading.notation.SymbolMap` looks them up) under
    which the student's value of an energy is kept for later right-hand sides:
    ``L = K - P`` with their ``K`` and ``P``, ``K = K_1 + K_2``."""
    names = [ref.key] if ref.key in ("T", "V", "L") else []
    alias = re.sub(r"[{}_\\]|mathcal|mathrm", "", ref.alias or "")
    index = "" if ref.index is None else str(ref.index)
    if alias:
        names.append(alias + index)
    elif ref.key in ("Tl", "Vl"):
        names.append(ref.key[0] + index)
    return names
