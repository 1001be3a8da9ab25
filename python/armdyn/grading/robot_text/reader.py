"""The reading pass: statements -> frames, joints, mass centres -> a model in YAML."""

from __future__ import annotations

import os
import re
from dataclasses import dataclass, field

import sympy as sp

from ...errors import ModelError
from ...model import Robot
from ..reader import Submission
from .dh import dh_statements, dh_tables, table_equations
from .energy import mass_centres
from .geometry import (
    axis_angle,
    frame_of,
    model_name,
    pretty_vector,
    rot_into,
    rotation_ok,
    rz,
    same,
    vector,
    yaml_matrix,
    yaml_vec,
)
from .gravity import read_gravity
from .recursion import positions_from_accelerations
from .statements import MAX_FRAMES, Names, Statement, all_equations, joint_candidates, read_statements


def _plain(e):
    """A frame's offset or axis, tidied: it holds no joint variable here (each was set to 0 or
    differentiated away), so expanding and cancelling is enough (sympy's simplify would cost
    its first caller 0.7 s of imports)."""
    return sp.cancel(sp.expand(e))


def _energies(statements, what: str) -> list:
    """The kinetic energies stated as a function of the rates (``K = K_1 + K_2`` names others: left out)."""
    return [
        st
        for st in statements
        if st.what == what
        and not isinstance(st.value, sp.MatrixBase)
        and any(s.name.endswith("_dot") for s in st.value.free_symbols)
    ]


@dataclass
class TextModel:
    """The model read from a text: its YAML (each item with the line it comes from), the
    Robot, what was assumed and which statements disagree."""

    yaml: str
    robot: Robot
    assumptions: list[str] = field(default_factory=list)
    conflicts: list[str] = field(default_factory=list)
    #: the readings with another of the gravities stated (the grading keeps the one the
    #: text's steps agree with most)
    alternatives: list = field(default_factory=list)

    def note(self) -> str:
        """The grade report's first note: the model was read from the text."""
        text = "model read from the text (no robot named; `armdyn grade --show-model` prints it)"
        if self.assumptions:
            text += "; assumed: " + "; ".join(self.assumptions)
        if self.conflicts:
            text += "; statements that disagree: " + "; ".join(self.conflicts)
        return text


class TextReader:
    def __init__(self, sub: Submission):
        self.sub = sub
        self.assumptions: list[str] = []
        self.conflicts: list[str] = []
        self.unplaced: dict[int, str] = {}  # frame -> why its only rotation stated was not used
        self.gravity_choice = 0  # which of the gravities stated (most supported first) is read
        self.gravity_options = 1
        self.pair_choices: dict[int, bool] = {}  # link -> the other of its x_k, y_k readings (energy.py)

    def where(self, st: Statement) -> str:
        return f"line {st.line}"

    def fail(self, message: str):
        raise ModelError(f"cannot read the robot from the text: {message}", source=self.sub.path)

    # -- the pass
    def read(self) -> TextModel:
        equations, text = all_equations(self.sub)
        tables = dh_tables(text)
        equations += table_equations(tables)
        self.equations = equations
        joints, written = joint_candidates(equations, self.sub.symbols)
        if not joints:
            if self._proofs_only(text):
                return self._no_arm()
            self.fail("no joint variable (\\theta_k, q_k, d_k) is written; name the model with --robot")
        n = max(joints)
        if n > MAX_FRAMES:
            self.fail(
                f"joint variables numbered up to {n}: more frames than a derivation by hand has (at most {MAX_FRAMES})"
            )
        names = Names(joints, self.sub.symbols)
        self.text, self.names = text, names
        statements = read_statements(equations, names, n)
        if tables:
            from_table, assumed, problems = dh_statements(tables, names)
            statements = from_table + statements  # the table first: it is the frames' definition
            self.assumptions += assumed
            self.conflicts += problems
        q = {k: sp.Symbol(v) for k, v in joints.items()}
        missing = [k for k in range(1, n + 1) if k not in q]
        if missing:
            self.fail(f"no variable of joint {missing[0]} is written (joints 1..{n} are used)")
        qs = [q[k] for k in range(1, n + 1)]
        self.n, self.q = n, qs
        free = set().union(*(self._symbols(st.value) for st in statements)) | set(qs)
        self.free = free
        rot = self._rotations(statements)
        revolute = {
            qs[k - 1] for k in range(1, n + 1) if rot.get(k) is not None and qs[k - 1] in rot[k][0].free_symbols
        }
        gravity, g_line = self._gravity(statements)
        stated = {
            ("Pc" if st.what == "C" else st.what, st.index) for st in statements if st.what in ("P", "Pc", "C", "I")
        }
        solved, notes = positions_from_accelerations(equations, names, qs, rot, stated)
        statements = statements + solved  # Craig's P used only in products: from the accelerations they give
        self.assumptions += notes
        coms = self._coms(statements, gravity, rot, revolute)
        revolute |= {x for p in coms.values() for x in self._in_trig(p[0])}
        lengths = {x for p in coms.values() for x in self._outside_trig(p[0])} - revolute
        for k in range(1, n + 1):  # an angle's name, turned by no rotation stated: read as revolute, named
            if rot.get(k) is None and qs[k - 1] in lengths and written[k] == "theta":
                self.assumptions.append(
                    f"joint {k} is prismatic: \\theta_{k} is a length in the positions read (in no sine or cosine)"
                )
                continue
            if rot.get(k) is None and qs[k - 1] not in revolute and written[k] == "theta":
                revolute.add(qs[k - 1])
                self.assumptions.append(f"joint {k} is revolute: \\theta_{k} names an angle")
        for k in range(1, n + 1):
            if rot.get(k) is None and k in self.unplaced:
                self.fail(f"{self.unplaced[k]}, and no other statement turns frame {k - 1} into frame {k}")
            if rot.get(k) is None:
                if qs[k - 1] in revolute:
                    rot[k] = (rz(qs[k - 1]), None)
                    self.assumptions.append(
                        f"joint {k} turns about z{k - 1} (no rotation between frames {k - 1} and {k} is stated)"
                    )
                else:
                    rot[k] = (sp.eye(3), None)
                    if any(rot.get(j, (None, None))[1] is not None for j in range(1, n + 1)):
                        self.assumptions.append(
                            f"frame {k} not turned from frame {k - 1}: no rotation between them is stated, "
                            "while other frames' are"
                        )
        return self._build(statements, rot, revolute, gravity, g_line, coms)

    def _proofs_only(self, text: str) -> bool:
        """A text with proofs and no joint variable: a rigid-body proof needs no arm."""
        from ..proofs import check_text

        return bool(text) and bool(check_text(text, self.sub.path or "<string>", set()))

    def _no_arm(self) -> TextModel:
        """The model of a proof: no joints, no links (its links are checked on their own)."""
        from ...io.yaml import load_yaml_string

        text = (
            f"# the robot read from {os.path.basename(self.sub.path)}: none (a proof, no joint variable)\n"
            f"name: {model_name(self.sub.path)}\n"
            "description: no arm; the text proves rigid-body identities\n"
            "parameters: []\ngravity: [0, 0, 0]\njoints: []\nlinks: []\n"
        )
        robot = load_yaml_string(text, source=f"{self.sub.path} (the model read from it)", strict=False)
        self.assumptions.append("no arm: no joint variable is written, and the text's proofs need none")
        return TextModel(text, robot, self.assumptions, self.conflicts)

    @staticmethod
    def _symbols(value) -> set:
        return set(value.free_symbols) if hasattr(value, "free_symbols") else set()

    @staticmethod
    def _in_trig(expr) -> set:
        return {s for f in sp.sympify(expr).atoms(sp.sin, sp.cos) for s in f.free_symbols}

    def _outside_trig(self, p) -> set:
        """The joint variables a position holds as lengths (a factor outside every sine and cosine)."""
        bare = sp.Matrix(p).applyfunc(lambda e: e.replace(lambda f: isinstance(f, (sp.sin, sp.cos)), lambda f: 1))
        return bare.free_symbols & set(self.q)

    def _rotations(self, statements) -> dict:
        """Frame k's axes in frame k-1 (a function of joint k's variable) -> (matrix, statement)."""
        out: dict[int, tuple] = {}
        for st in statements:
            if st.what != "R":
                continue
            a, b = st.index, st.frame
            if a is not None and b is not None and abs(a - b) == 1 and max(a, b) > self.n and "(i = " in st.source:
                continue  # a generic link i's rotation, instanced past the last joint: nothing stated
            if a is None or b is None or abs(a - b) != 1 or max(a, b) > self.n:
                self.conflicts.append(
                    f"line {st.line}: {st.source[:60]} relates frames {a} and {b}, not successive frames "
                    f"of joints 1..{self.n} (not used)"
                )
                continue
            m = st.value
            if not isinstance(m, sp.MatrixBase) or m.shape != (3, 3):
                continue  # R_2^1 = (R_1^2)^T: a name for another statement, not a matrix
            if not rotation_ok(m, self.free):
                self.conflicts.append(f"line {st.line}: R_{a}^{b} is not a rotation (its columns are not orthonormal)")
                self.unplaced.setdefault(max(a, b), self.conflicts[-1])
                continue
            k = max(a, b)
            axes = m if a == k else m.T  # R_a^b maps a -> b: frame a's axes in frame b
            if k in out:
                if not same(out[k][0], axes, self.free):
                    self.conflicts.append(
                        f"lines {out[k][1].line} and {st.line} state different rotations between frames "
                        f"{k - 1} and {k} (line {out[k][1].line} used)"
                    )
                continue
            others = (axes.free_symbols & set(self.q)) - {self.q[k - 1]}
            if others:
                self.conflicts.append(
                    f"line {st.line}: the rotation between frames {k - 1} and {k} moves with "
                    f"{', '.join(sorted(map(str, others)))}, not only joint {k}'s variable (not used)"
                )
                continue
            out[k] = (axes, st)
        return out

    def _gravity(self, statements):
        return read_gravity(self, statements)

    def _coms(self, statements, gravity, rot, revolute) -> dict:
        """Link k's mass centre in the base frame -> (position, mass or None, statement)."""
        return mass_centres(statements, gravity, self.q, revolute, self.free, self.conflicts, self.pair_choices)

    # -- the model
    def _build(self, statements, rot, revolute, gravity, g_line, coms) -> TextModel:
        n = self.n
        # orientation and origin of each frame in the base frame
        R0 = [sp.eye(3)]
        for k in range(1, n + 1):
            R0.append(R0[k - 1] * rot[k][0])
        pstat = self._vote(statements, "P", "frame {k}'s origin", R0, -1)
        pc = self._vote(statements, "Pc", "link {k}'s mass centre", R0, 0)
        o = [sp.zeros(3, 1)]
        com_local: dict[int, sp.Matrix] = {}
        for k in range(1, n + 1):
            Rk = R0[k]
            if k in pstat:
                st = pstat[k]
                f = st.frame if st.frame is not None else k - 1
                if f > k:
                    self.conflicts.append(f"line {st.line}: P_{k} is written in frame {f}, not yet placed (not used)")
                    del pstat[k]
                else:
                    o.append(o[k - 1] + R0[f] * vector(st.value))
                    continue
            if k in pc and k in coms:
                c = (
                    vector(pc[k].value)
                    if pc[k].frame in (None, k)
                    else rot_into(R0, pc[k].frame, k) * vector(pc[k].value)
                )
                o.append(coms[k][0] - Rk * c)
            elif k in coms:
                o.append(coms[k][0])
                com_local[k] = sp.zeros(3, 1)
            elif k in pc:
                o.append(o[k - 1])
                self.assumptions.append(
                    f"frame {k}'s origin at frame {k - 1}'s (on joint {k}'s axis): no P_{k} is stated"
                )
            elif k == 1:  # where the whole arm sits changes no torque: the base's origin
                o.append(o[0])
                self.assumptions.append("frame 1's origin at the base frame's (no P_1^0 is stated)")
            else:
                self.fail(
                    f"frame {k}'s origin is not stated (P_{k}^{k - 1}) and link {k}'s mass centre cannot be "
                    "placed (no V, no P_{C_" + str(k) + "})"
                )
        for k in range(1, n + 1):
            if k in com_local:
                continue
            if k in pc:
                st = pc[k]
                c = vector(st.value)
                if st.frame not in (None, k):
                    c = rot_into(R0, st.frame, k) * c
                com_local[k] = c
                if k in coms and not same(o[k] + R0[k] * c, coms[k][0], self.free):
                    self.conflicts.append(
                        f"line {st.line} and line {coms[k][2].line} (V) place link {k}'s mass centre differently "
                        f"(line {st.line} used)"
                    )
            elif k in coms:
                com_local[k] = R0[k].T * (coms[k][0] - o[k])
            else:
                com_local[k] = sp.zeros(3, 1)
                self.assumptions.append(f"link {k}'s mass centre at frame {k}'s origin (no position of it is stated)")
        if not pstat and any(k not in pc for k in coms):
            self.assumptions.append(
                "each frame's origin at its link's mass centre (no frame origin P_i is stated; "
                "the dynamics do not depend on where frames sit)"
            )
        return self._emit(statements, rot, revolute, gravity, g_line, coms, R0, o, com_local, pstat, pc)

    def _vote(self, statements, what: str, label: str, R0, shift: int) -> dict[int, Statement]:
        """Link/frame k -> the statement of one vector that most statements agree with (compared
        in the base frame; a tie: the first written); each disagreement named with its lines."""
        groups: dict[int, list[list]] = {}
        for st in statements:
            k = st.index
            if st.what != what or vector(st.value) is None or k is None or not 1 <= k <= self.n:
                continue
            f = frame_of(st, k + shift)
            if not 0 <= f <= self.n:
                self.conflicts.append(
                    f"line {st.line}: {label.format(k=k)} is written in frame {f}, which no statement places (not used)"
                )
                continue
            in_base = R0[f] * vector(st.value)
            for group in groups.setdefault(k, []):
                if same(group[0][1], in_base, self.free):
                    group.append((st, in_base))
                    break
            else:
                groups[k].append([(st, in_base)])
        chosen: dict[int, Statement] = {}
        for k, gs in groups.items():
            best = max(gs, key=lambda g: (len(g), -g[0][0].line))
            chosen[k] = best[0][0]
            if len(gs) > 1:
                used = ", ".join(str(x) for x in dict.fromkeys(st.line for st, _ in best))
                others = ", ".join(str(x) for x in dict.fromkeys(st.line for g in gs if g is not best for st, _ in g))
                why = "most statements" if len(best) > max(len(g) for g in gs if g is not best) else "the first written"
                self.conflicts.append(
                    f"line{'s' if len(best) > 1 else ''} {used} and line{'s' if ',' in others else ''} {others} "
                    f"state {label.format(k=k)} differently (line{'s' if len(best) > 1 else ''} {used} used: {why})"
                )
        return chosen

    def _emit(self, statements, rot, revolute, gravity, g_line, coms, R0, o, com_local, pstat, pc) -> TextModel:
        n, qs = self.n, self.q
        zero = {x: 0 for x in qs}
        lines = [
            f"# the robot read from {os.path.basename(self.sub.path)} (no model named)",
            f"name: {model_name(self.sub.path)}",
            "description: read from the derivation's own statements",
        ]
        joints_yaml, links_yaml = [], []
        params: set = set()
        masses = self._masses(statements, coms)
        inertias = self._inertias(statements, R0, coms, masses, com_local)
        for k in range(1, n + 1):
            x = qs[k - 1]
            axes, st = rot[k]
            rel = (R0[k - 1].T * (o[k] - o[k - 1])).applyfunc(sp.expand)
            rel_k = rel.subs({y: 0 for y in qs if y != x})
            if not same(rel, rel_k, self.free):
                self.fail(
                    f"frame {k}'s origin, seen from frame {k - 1}, moves with other joints than joint {k}: "
                    "the positions read are not those of a serial arm"
                )
            item = [f"  - name: {x}", f"    parent: {'base' if k == 1 else f'link{k - 1}'}", f"    child: link{k}"]
            src = f"line {st.line}: {st.source[:70]}" if st is not None else "assumed"
            if x in revolute:
                A0 = axes.subs(x, 0)
                S = (A0.T * axes.diff(x)).subs(x, 0)
                axis = sp.Matrix([S[2, 1], S[0, 2], S[1, 0]]).applyfunc(sp.nsimplify)
                if not same(axes, A0 * axis_angle(axis, x), self.free):
                    self.fail(f"the rotation of frame {k} ({src}) is not a turn about one axis by {x}")
                centre = ((rel_k.subs(x, 0) + rel_k.subs(x, sp.pi)) / 2).applyfunc(_plain)
                fx = (A0.T * (rel_k.subs(x, 0) - centre)).applyfunc(_plain)
                if not same(rel_k, centre + A0 * axis_angle(axis, x) * fx, self.free):
                    self.conflicts.append(f"frame {k}'s origin does not turn about joint {k}'s axis")
                item.insert(1, "    type: revolute")
                if A0 != sp.eye(3):
                    item.append(f"    rotation: {yaml_matrix(A0)}    # {src}")
                item.append(f"    axis: {yaml_vec(axis)}    # {x} turns frame {k} ({src})")
                if centre != sp.zeros(3, 1):
                    item.append(f"    xyz: {yaml_vec(centre)}")
                if fx != sp.zeros(3, 1):
                    item.append(f"    frame_xyz: {yaml_vec(fx)}    # frame {k}'s origin off the axis")
                params |= axis.free_symbols | centre.free_symbols | fx.free_symbols
            else:
                slide = rel_k.diff(x).applyfunc(_plain)
                if x not in rel_k.free_symbols:
                    self.fail(
                        f"joint variable {x} moves nothing: it is in no rotation and in no position read "
                        f"(state frame {k}'s origin, P_{k}^{k - 1}, or the heights in V)"
                    )
                axis = (axes.T * slide).applyfunc(_plain)
                if slide.free_symbols or axis.norm() != 1:
                    self.fail(f"joint {k} ({x}) slides along {pretty_vector(slide)}, not a unit direction")
                at = rel_k.subs(x, 0).applyfunc(_plain)
                item.insert(1, "    type: prismatic")
                if axes != sp.eye(3):
                    item.append(f"    rotation: {yaml_matrix(axes)}    # {src}")
                item.append(f"    axis: {yaml_vec(axis)}    # {x} slides frame {k}")
                if at != sp.zeros(3, 1):
                    item.append(f"    xyz: {yaml_vec(at)}")
                params |= at.free_symbols
            joints_yaml += item
            mass, mline = masses.get(k, (None, None))
            if mass is None:
                self.fail(f"no mass of link {k} (m_{k}) is stated in V or T")
            c = com_local[k].subs(zero).applyfunc(_plain)
            inertia, iline = inertias[k][:2]
            links_yaml += [
                f"  - name: link{k}",
                f"    mass: {mass}    # {mline}",
                f"    com: {yaml_vec(c)}    # {self._com_source(k, coms, pc)}",
                f"    inertia: {inertia}    # {iline}",
            ]
            params |= c.free_symbols | {mass}
        params |= gravity.free_symbols
        params |= set().union(*(sp.sympify(v).free_symbols for v in inertias.get("symbols", [])))
        # the front matter's symbols name the model's parameters: each one the model has
        params |= {sp.Symbol(str(t)) for t in self.sub.symbols.values() if re.fullmatch(r"[A-Za-z]\w{0,40}", str(t))}
        params -= set(qs) | {sp.Symbol(f"{x}_{d}") for x in qs for d in ("dot", "ddot")}
        g_src = self.gravity_source if g_line else "assumed: none stated"
        lines += [
            f"parameters: [{', '.join(sorted(str(p) for p in params))}]",
            f"gravity: {yaml_vec(gravity)}    # {g_src}",
            "joints:",
            *joints_yaml,
            "links:",
            *links_yaml,
        ]
        text = "\n".join(lines) + "\n"
        from ...io.yaml import load_yaml_string

        robot = load_yaml_string(text, source=f"{self.sub.path} (the model read from it)", strict=False)
        self._check_T(statements, robot, g_line is None and any(c[2].what in ("V", "Vl") for c in coms.values()))
        return TextModel(text, robot, self.assumptions, self.conflicts)

    def _com_source(self, k, coms, pc) -> str:
        if k in pc:
            return f"line {pc[k].line}: {pc[k].source[:70]}"
        if k in coms:
            how = f"from the height of m{k} in V" if coms[k][2].what in ("V", "Vl") else coms[k][2].source[:70]
            return f"line {coms[k][2].line}: {how}"
        return "assumed"

    def _masses(self, statements, coms) -> dict:
        out = {k: (v[1], f"line {v[2].line}: m{k} in V") for k, v in coms.items() if v[1] is not None}
        for st in statements:
            if st.what in ("T", "V", "Tl", "Vl") and not isinstance(st.value, sp.MatrixBase):
                for s in st.value.free_symbols:
                    m = re.fullmatch(r"m(\d+)", s.name)
                    if m and int(m.group(1)) not in out:
                        out[int(m.group(1))] = (s, f"line {st.line}: m{m.group(1)} in {st.what}")
        for k in range(1, self.n + 1):  # Newton-Euler texts: m_k in F_k = m_k \dot v_{C_k}
            if k in out:
                continue
            pattern = re.compile(r"(?<![A-Za-z\\])m_\{?\s*" + str(k) + r"(?!\d)")
            for eq in self.equations:
                if eq.lhs and pattern.search(str(eq.value)):
                    out[k] = (sp.Symbol(f"m{k}"), f"line {eq.line}: m_{k} written there")
                    self.assumptions.append(f"link {k}'s mass is m{k}, by its name (first used on line {eq.line})")
                    break
        return out

    def _inertias(self, statements, R0, coms, masses, com_local) -> dict:
        """Link k's inertia about its mass centre: a stated tensor, ``I_k`` in T (about z), or a point mass."""
        out: dict = {"symbols": []}
        for st in statements:
            if st.what == "I" and isinstance(st.value, sp.MatrixBase) and st.value.shape == (3, 3):
                k = st.index
                if k in out:
                    if not same(out[k][2], st.value, self.free):
                        self.conflicts.append(f"lines {out[k][1]} and {st.line} state link {k}'s inertia differently")
                    continue
                out[k] = (yaml_matrix(st.value), f"line {st.line}: {st.source[:70]}", st.value)
                out["symbols"] += list(st.value)
        Ts, Tl = _energies(statements, "T"), _energies(statements, "Tl")
        for st in Ts[:1] + Tl:  # the whole T, and each link's own T_k / K_k
            for s in st.value.free_symbols:
                m = re.fullmatch(r"I(?:zz)?(\d+)", s.name)
                if m and int(m.group(1)) <= self.n and int(m.group(1)) not in out:
                    k = int(m.group(1))
                    out[k] = (
                        f"{{ixx: 0, iyy: {s}, izz: {s}}}",
                        f"line {st.line}: {s} in T, about z (a thin rod)",
                        None,
                    )
                    out["symbols"].append(s)
        for k in range(1, self.n + 1):  # principal moments used by name: I_{xx1}, I_{zz1}
            if k in out:
                continue
            pattern = re.compile(r"I_\{?\s*(xx|yy|zz)\s*[,_]?\s*\{?\s*" + str(k) + r"(?!\d)")
            used: dict[str, int] = {}
            for eq in self.equations:
                for m in pattern.finditer(str(eq.value)):
                    used.setdefault(m.group(1), eq.line)
            if used:
                entries = ", ".join(f"i{a}: {f'I{a}{k}' if a in used else 0}" for a in ("xx", "yy", "zz"))
                lines = sorted(set(used.values()))
                out[k] = (f"{{{entries}}}", f"line {lines[0]}: I_{{..{k}}} used there", None)
                out["symbols"] += [sp.Symbol(f"I{a}{k}") for a in used]
                self.assumptions.append(
                    f"link {k}'s inertia diagonal in frame {k}, from the moments named on line"
                    f"{'s' if len(lines) > 1 else ''} {', '.join(map(str, lines))} (others 0)"
                )
        point = [k for k in range(1, self.n + 1) if k not in out]
        for k in point:
            out[k] = ("0", "point mass", None)
        if point:
            self.assumptions.append(
                f"point masses for link{'s' if len(point) > 1 else ''} {', '.join(map(str, point))}: "
                "no inertia tensor is stated"
            )
        return out

    def _check_T(self, statements, robot: Robot, gravity_assumed: bool):
        """A stated T must be the kinetic energy of the model read (else the positions or inertias disagree)."""
        Ts = _energies(statements, "T")
        if not Ts:
            return
        from ...symbolic.lagrange import link_energies

        T_trans, T_rot, _, _ = link_energies(robot)
        T = sum(T_trans.values(), sp.Integer(0)) + sum(T_rot.values(), sp.Integer(0))
        ren = {sp.Symbol(f"{q}_dot"): qd for q, qd in zip(robot.q, robot.qd, strict=True)}
        ren.update({sp.Symbol(str(q)): q for q in robot.q})
        mine = Ts[0].value.xreplace(ren)
        parts = {st.index: st for st in reversed(_energies(statements, "Tl")) if st.index is not None}
        if len(parts) == self.n:  # each link's T_k stated: a slip in the whole T is not the reading's fault
            whole = sum((st.value for st in parts.values()), sp.Integer(0)).xreplace(ren)
            if not same(mine, T, mine.free_symbols | T.free_symbols) and same(
                whole, T, whole.free_symbols | T.free_symbols
            ):
                self.conflicts.append(
                    f"line {Ts[0].line}: T is not the sum of the links' T_k (lines "
                    f"{', '.join(str(parts[k].line) for k in sorted(parts))}), which the arm read gives"
                )
                return
        if not same(mine, T, mine.free_symbols | T.free_symbols):
            if gravity_assumed:  # the positions rest on an assumed gravity: the reading is not to be trusted
                self.fail(
                    f"T (line {Ts[0].line}) is not the kinetic energy of the arm read from V with gravity "
                    "assumed along -y0: state the base acceleration or the mass centres' positions"
                )
            self.conflicts.append(
                f"line {Ts[0].line}: T is not the kinetic energy of the arm the other statements describe"
            )
