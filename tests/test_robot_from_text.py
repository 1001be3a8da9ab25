"""The robot read from a derivation's own statements (no model named): graded alike, the
same dynamics as the model the text was written from, conflicts and assumptions named."""

from __future__ import annotations

import math
import os
import random
import time

import pytest
import sympy as sp
from test_symbolic import exercise_tau

import armdyn
from armdyn.errors import ModelError
from armdyn.grading import grade
from armdyn.grading.reader import read
from armdyn.grading.robot_text import robot_from_text, show_model

HERE = os.path.dirname(__file__)
EXAMPLES = os.path.join(HERE, "..", "examples", "grading")


def _unnamed(name: str, tmp_path, edit=None) -> str:
    """The example with its front matter's ``robot:`` line blanked (line numbers kept)."""
    lines = open(os.path.join(EXAMPLES, name), encoding="utf-8").read().split("\n")
    lines = ["# (robot removed)" if ln.startswith("robot:") else ln for ln in lines]
    text = "\n".join(lines)
    if edit is not None:
        text = edit(text)
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return str(path)


def _verdicts(report):
    return [(v.line, v.name, v.status) for v in report.steps]


@pytest.mark.parametrize(
    "name",
    [
        "rp-arm-exercise.md",
        "rp-arm-dalembert.md",
        "planar-2r-lagrange.md",
        "planar-2r-craig.md",  # its geometry for a generic link i: ${}^{i}P_{C_i}$, diag(0, I_i, I_i)
        "planar-3r-spong.md",  # r_{i,c_i}, r_{i,i+1}, R_i^{i-1} = R_z(theta_i), in the prose
    ],
)
def test_same_verdicts_as_the_named_model(name, tmp_path):
    named = grade(os.path.join(EXAMPLES, name))
    unnamed = grade(_unnamed(name, tmp_path))
    assert _verdicts(unnamed) == _verdicts(named)
    assert unnamed.notes[0].startswith("model read from the text")
    assert not any("read from the text" in n for n in named.notes)


def test_geometry_stated_only_in_words_is_not_read(tmp_path):
    # the SCARA text states its gravity (along -z0), its rotations and the heights only in
    # words; its horizontal p_{ck} leave the quill's slider d_3 moving nothing: it says so
    path = _unnamed("scara-lagrange.md", tmp_path)
    with pytest.raises(ModelError, match="cannot read the robot from the text: joint variable q3 moves nothing"):
        robot_from_text(read(path))
    # graded all the same, against the text's own earlier values, the reason first
    report = grade(path)
    assert report.model_note.startswith("no model: the robot could not be read from the text")
    assert "joint variable q3 moves nothing" in report.model_note
    assert report.notes[0] == report.model_note


def _tau_at(robot, values: dict):
    eom = armdyn.derive(robot, "lagrange")
    return [sp.N(t.subs(values)) for t in eom.tau]


def _state(robot, names: dict[str, sp.Symbol], seed: int) -> dict:
    rng = random.Random(seed)
    values = {}
    for vec in (robot.q, robot.qd, robot.qdd):
        for s in vec:
            values[s] = rng.uniform(-1.5, 1.5)
    for p in names.values():
        values[p] = rng.uniform(0.2, 2.0)
    return values


def test_rp_arm_read_has_the_exercises_dynamics(tmp_path):
    robot = robot_from_text(read(_unnamed("rp-arm-exercise.md", tmp_path))).robot
    m1, m2, l1, g = (robot.parameters[n] for n in ("m1", "m2", "l1", "g"))
    tau1, tau2 = exercise_tau(robot)  # by hand, from the arm's Lagrangian (tests/test_symbolic.py)
    bundled = armdyn.load("rp-arm")
    for seed in range(3):
        at = _state(robot, {"m1": m1, "m2": m2, "l1": l1, "g": g}, seed)
        got = _tau_at(robot, at)
        assert abs(got[0] - sp.N(tau1.subs(at))) < 1e-9 and abs(got[1] - sp.N(tau2.subs(at))) < 1e-9
        renamed = {bundled.q[k]: at[robot.q[k]] for k in range(2)}
        renamed |= {bundled.qd[k]: at[robot.qd[k]] for k in range(2)}
        renamed |= {bundled.qdd[k]: at[robot.qdd[k]] for k in range(2)}
        renamed |= {p: at[p] for p in (m1, m2, l1, g)}
        assert max(abs(a - b) for a, b in zip(got, _tau_at(bundled, renamed), strict=True)) < 1e-9


STANDARD_DH = r"""# Planar 2R, frames from a standard DH table

| i | $a_i$ | $\alpha_i$ | $d_i$ | $\theta_i$ |
|---|---|---|---|---|
| 1 | $l_1$ | 0 | 0 | $q_1$ |
| 2 | $l_2$ | 0 | 0 | $q_2$ |

Mass centres in each DH frame (at the link's far end): $r_{1,c_1} = (l_{c1} - l_1, 0, 0)^T$,
$r_{2,c_2} = (l_{c2} - l_2, 0, 0)^T$. Gravity: $\dot v_0^0 = (0, g, 0)^T$.
Inertias: $I_1 = \mathrm{diag}(0, I_1, I_1)$, $I_2 = \mathrm{diag}(0, I_2, I_2)$; masses: $F_1 = m_1 a_1$, $F_2 = m_2 a_2$.
"""

MODIFIED_DH = r"""# Planar 2R, frames from Craig's DH table

| $i$ | $\alpha_{i-1}$ | $a_{i-1}$ | $d_i$ | $\theta_i$ |
|:-:|:-:|:-:|:-:|:-:|
| 1 | 0 | 0 | 0 | $\theta_1$ |
| 2 | 0 | $l_1$ | 0 | $\theta_2$ |

${}^{1}P_{C_1} = (l_{c1}, 0, 0)^T$, ${}^{2}P_{C_2} = (l_{c2}, 0, 0)^T$, ${}^{0}\dot v_0 = (0, g, 0)^T$,
${}^{C_1}I_1 = \mathrm{diag}(0, I_1, I_1)$, ${}^{C_2}I_2 = \mathrm{diag}(0, I_2, I_2)$,
and the masses $m_1$, $m_2$: $F_1 = m_1 a_1$, $F_2 = m_2 a_2$.

$$\tau_1 = m_1 g$$
$$\tau_2 = m_2 g$$
"""


def _as_array(text: str, env: str) -> str:
    """The text's Markdown DH table written as a LaTeX ``env`` (array or tabular), on as many lines."""
    lines = text.split("\n")
    k = next(i for i, ln in enumerate(lines) if ln.startswith("|"))
    cells = [[c.strip().strip("$") for c in ln.strip().strip("|").split("|")] for ln in lines[k : k + 4]]
    spec = "{c|cccc}"
    body = [
        f"$$\\begin{{{env}}}{spec} " + " & ".join(cells[0]) + r" \\ \hline",
        " & ".join(cells[2]) + r" \\",
        " & ".join(cells[3]),
        f"\\end{{{env}}}$$",
    ]
    return "\n".join(lines[:k] + body + lines[k + 4 :])


DH_TEXTS = {
    "standard-dh": STANDARD_DH,
    "modified-dh": MODIFIED_DH,
    "standard-dh-array": _as_array(STANDARD_DH, "array"),
    "modified-dh-tabular": _as_array(MODIFIED_DH, "tabular"),
}


@pytest.mark.parametrize("name", ["planar-2r-lagrange.md", "planar-2r-craig.md", *DH_TEXTS])
def test_planar_2r_read_has_spongs_dynamics(name, tmp_path):
    if name in DH_TEXTS:
        path = tmp_path / f"{name}.md"
        path.write_text(DH_TEXTS[name], encoding="utf-8")
        model = robot_from_text(read(str(path)))
        assert any(a.startswith(f"the DH table of line 3 is {name.split('-')[0]} DH") for a in model.assumptions)
        robot = model.robot
    else:
        robot = robot_from_text(read(_unnamed(name, tmp_path))).robot
    q1, q2 = robot.q
    qd1, qd2 = robot.qd
    qdd1, qdd2 = robot.qdd
    m1, m2, l1, lc1, lc2, I1, I2, g = sp.symbols("m1 m2 l1 lc1 lc2 I1 I2 g")
    # Spong, Hutchinson, Vidyasagar, section 7.4.2, written out by hand
    d11 = m1 * lc1**2 + m2 * (l1**2 + lc2**2 + 2 * l1 * lc2 * sp.cos(q2)) + I1 + I2
    d12 = m2 * (lc2**2 + l1 * lc2 * sp.cos(q2)) + I2
    d22 = m2 * lc2**2 + I2
    h = -m2 * l1 * lc2 * sp.sin(q2)
    phi1 = (m1 * lc1 + m2 * l1) * g * sp.cos(q1) + m2 * lc2 * g * sp.cos(q1 + q2)
    phi2 = m2 * lc2 * g * sp.cos(q1 + q2)
    tau = [d11 * qdd1 + d12 * qdd2 + 2 * h * qd1 * qd2 + h * qd2**2 + phi1, d12 * qdd1 + d22 * qdd2 - h * qd1**2 + phi2]
    names = {str(p): p for p in (m1, m2, l1, lc1, lc2, I1, I2, g, sp.Symbol("l2"))}  # l2: the DH frames' own
    for seed in range(3):
        at = _state(robot, names, seed)
        got = _tau_at(robot, at)
        assert max(abs(a - sp.N(t.subs(at))) for a, t in zip(got, tau, strict=True)) < 1e-9


def test_show_model_prints_a_loadable_model_with_its_sources(tmp_path, capsys):
    from armdyn.cli import main

    path = _unnamed("rp-arm-exercise.md", tmp_path)
    assert main(["grade", path, "--show-model"]) == 0
    text = capsys.readouterr().out
    assert "# line 91" in text and "gravity (0, -g, 0), from line 95" in text
    assert "point masses for links 1, 2: no inertia tensor is stated" in text
    model = tmp_path / "model.yaml"
    model.write_text(text)
    robot = armdyn.load(str(model))
    assert [j.name for j in robot.joints] == ["theta1", "d2"]
    named = show_model(read(os.path.join(EXAMPLES, "rp-arm-exercise.md")))
    assert "the model named (rp-arm) is used" in named


def _model(path):
    return robot_from_text(read(path))


def test_a_rotation_with_a_slip_is_named_with_its_line(tmp_path):
    slip = r"\mathbf{R}_1^2 = \begin{pmatrix} 1 & 0 & 0 \\ 0 & 0 & -1 \\ 0 & 2 & 0 \end{pmatrix}"
    path = _unnamed(
        "rp-arm-exercise.md",
        tmp_path,
        lambda t: t.replace(
            r"\mathbf{R}_1^2 = \begin{pmatrix} 1 & 0 & 0 \\ 0 & 0 & -1 \\ 0 & 1 & 0 \end{pmatrix}", slip
        ),
    )
    with pytest.raises(ModelError) as err:
        _model(path)
    # frame 2 cannot be placed without it: the message names the line of the slip
    assert "line 91: R_1^2 is not a rotation" in str(err.value)


def test_a_mass_centre_stated_twice_is_named_and_the_first_used(tmp_path):
    extra = "\n$P_{C_2}^2 = (0, 0, 0)^T$\n\nand later $P_{C_2}^2 = (0, l_1, 0)^T$.\n"
    path = _unnamed("rp-arm-exercise.md", tmp_path, lambda t: t + extra)
    model = _model(path)
    n = open(path).read().count("\n")  # the last line's number
    expected = (
        f"line {n - 2} and line {n} state link 2's mass centre differently (line {n - 2} used: the first written)"
    )
    assert expected in model.conflicts
    assert "model read from the text" in model.note() and "disagree" in model.note()
    assert list(model.robot.links["link2"].com) == [0, 0, 0]


def test_the_position_most_statements_give_is_used(tmp_path):
    # a slip first, then the same vector twice, once in frame 2 and once in frame 1 (x2 = x1, y2 = -z1, z2 = y1)
    extra = "\n$P_{C_2}^2 = (0, l_1, 0)^T$\n\n$P_{C_2}^2 = (l_1, 0, 0)^T$\n\n$P_{C_2}^1 = (l_1, 0, 0)^T$\n"
    path = _unnamed("rp-arm-exercise.md", tmp_path, lambda t: t + extra)
    model = _model(path)
    n = open(path).read().count("\n")
    expected = (
        f"lines {n - 2}, {n} and line {n - 4} state link 2's mass centre differently "
        f"(lines {n - 2}, {n} used: most statements)"
    )
    assert expected in model.conflicts
    assert list(model.robot.links["link2"].com) == [sp.Symbol("l1"), 0, 0]


def test_positions_and_V_that_disagree_are_named(tmp_path):
    # the 2R text's p_{c2} with a slip (l_2 for l_{c2}): V (line 40) disagrees, p_{c2} is used
    path = _unnamed(
        "planar-2r-lagrange.md",
        tmp_path,
        lambda t: t.replace(r"l_1(\cos q_1, \sin q_1) + l_{c2}(", r"l_1(\cos q_1, \sin q_1) + l_2("),
    )
    model = _model(path)
    assert "line 40 (V) and line 31 place link 2's mass centre at different heights (line 31 used)" in model.conflicts


def test_no_gravity_stated_is_an_assumption_named(tmp_path):
    path = _unnamed(
        "rp-arm-exercise.md",
        tmp_path,
        lambda t: t.replace(r"\dot{\boldsymbol{v}}_0^0 = \begin{pmatrix} 0 \\ g \\ 0 \end{pmatrix}", r"\mathbf{x} = 0"),
    )
    model = _model(path)
    assert any("no base acceleration or gravity vector is stated" in a for a in model.assumptions)
    assert list(model.robot.gravity) == [0, -sp.Symbol("g"), 0]


def test_a_joint_that_moves_nothing_is_refused(tmp_path):
    path = tmp_path / "idle.md"
    path.write_text("$$V = m_1 g l_1 \\sin\\theta_1 + m_2 g l_1 \\sin\\theta_1$$\n\n$$\\tau_2 = m_2 g d_2$$\n")
    with pytest.raises(ModelError, match="d2 moves nothing"):
        _model(str(path))


def test_hostile_texts_end_in_one_line_in_bounded_time(tmp_path):
    many = tmp_path / "many.md"
    many.write_text("".join(f"$R_{{{k}}}^{{{k + 1}}} = R_z(\\theta_{{{k + 1}}})$\n" for k in range(10_000)))
    huge = tmp_path / "huge.md"
    huge.write_text(
        "$$R_0^1 = \\begin{pmatrix} 1" + "0" * 5000 + " & 0 & 0 \\\\ 0 & 1 & 0 \\\\ 0 & 0 & 1 \\end{pmatrix}$$\n"
    )
    circular = tmp_path / "circular.md"
    circular.write_text(
        "$$R_0^1 = \\begin{pmatrix} \\cos\\theta_1 & \\sin\\theta_1 & 0 \\\\ -\\sin\\theta_1 & \\cos\\theta_1 & 0"
        " \\\\ 0 & 0 & 1 \\end{pmatrix}$$\n\n$$R_1^0 = R_0^1$$\n\n$$R_1^0 = \\begin{pmatrix} 1 & 0 & 0 \\\\ 0 & 1 & 0"
        " \\\\ 0 & 0 & 1 \\end{pmatrix}$$\n\n$$V = m_1 g l_1 \\sin\\theta_1$$\n"
    )
    for path in (many, huge, circular):
        start = time.perf_counter()
        try:
            model = _model(str(path))
            message = "; ".join(model.conflicts)
        except ModelError as err:
            message = str(err)
        assert time.perf_counter() - start < 10
        assert message and "\n" not in message
    assert "lines 1 and 5 state different rotations between frames 0 and 1" in message


def test_reading_the_model_is_fast(tmp_path):
    sub = read(_unnamed("rp-arm-exercise.md", tmp_path))
    start = time.perf_counter()
    robot_from_text(sub)
    assert time.perf_counter() - start < 0.5


def test_mangled_texts_end_in_a_model_or_one_clear_error(tmp_path):
    # characters dropped, repeated, digits and signs changed: a model or one ModelError line
    sources = [_unnamed(n, tmp_path) for n in ("rp-arm-exercise.md", "planar-2r-lagrange.md", "planar-3r-spong.md")]
    rng = random.Random(7)
    for trial in range(30):
        text = open(rng.choice(sources), encoding="utf-8").read()
        for _ in range(rng.randint(1, 4)):
            i = rng.randrange(len(text))
            text = rng.choice(
                [
                    text[:i] + text[i + rng.randint(1, 30) :],
                    text[:i] + text[i : i + rng.randint(1, 40)] + text[i:],
                    text[:i] + str(rng.randint(0, 9)) + text[i + 1 :],
                    text[:i] + "-" + text[i:],
                ]
            )
        path = tmp_path / f"mangled{trial}.md"
        path.write_text(text, encoding="utf-8")
        try:
            robot_from_text(read(str(path)))
        except ModelError as err:
            assert "\n" not in str(err) and str(path) in str(err)


def test_principal_moments_used_by_name_are_the_links_inertia(tmp_path):
    path = tmp_path / "pendulum.md"
    path.write_text(
        "$$R_0^1 = \\begin{pmatrix} \\cos\\theta_1 & \\sin\\theta_1 & 0 \\\\ -\\sin\\theta_1 & \\cos\\theta_1 & 0"
        " \\\\ 0 & 0 & 1 \\end{pmatrix}$$\n\n$$P_{C_1}^1 = (l_{c1}, 0, 0)^T, \\dot v_0^0 = (0, g, 0)^T$$\n\n"
        "$$N_1^1 = \\begin{pmatrix} 0 \\\\ 0 \\\\ I_{zz1} \\ddot\\theta_1 \\end{pmatrix}$$\n\n"
        "$$F_1^1 = m_1 \\dot v_{C_1}^1$$\n",
        encoding="utf-8",
    )
    model = _model(str(path))
    assert "link 1's inertia diagonal in frame 1, from the moments named on line 5 (others 0)" in model.assumptions
    assert any("frame 1's origin at frame 0's" in a for a in model.assumptions)
    th, thdd = model.robot.q[0], model.robot.qdd[0]
    izz, m1, lc1, g = sp.symbols("Izz1 m1 lc1 g")
    pendulum = (izz + m1 * lc1**2) * thdd + m1 * g * lc1 * sp.cos(th)  # a physical pendulum, by hand
    for seed in range(3):
        at = _state(model.robot, {"Izz1": izz, "m1": m1, "lc1": lc1, "g": g}, seed)
        assert abs(_tau_at(model.robot, at)[0] - sp.N(pendulum.subs(at))) < 1e-9


def test_gravity_stated_in_words_is_read_with_its_line(tmp_path):
    # "gravity $g$ acts along $-y_0$" (line 27): the base frame's -y, the line named
    text = show_model(read(_unnamed("planar-2r-lagrange.md", tmp_path)))
    assert "gravity: [0, -g, 0]    # line 27: in words" in text
    # turned to -x0 in the words: gravity along -x0, so V = g (m1 x_{c1} + m2 x_{c2}) and by hand
    # dV/dq1 = -g (m1 lc1 + m2 (l1 + lc2)) at q = (pi/2, 0), zero at q = 0
    sideways = _unnamed("planar-2r-lagrange.md", tmp_path, lambda t: t.replace("along $-y_0$", "along $-x_0$"))
    model = robot_from_text(read(sideways))
    assert "gravity: [-g, 0, 0]    # line 27: in words" in model.yaml
    from armdyn.numeric import gravity

    values = {"g": 9.81, "m1": 1.3, "m2": 0.7, "l1": 0.9, "lc1": 0.4, "lc2": 0.35, "I1": 0.1, "I2": 0.05}
    arm = model.robot.bind({k: v for k, v in values.items() if k in model.robot.parameters})
    hand = -9.81 * (1.3 * 0.4 + 0.7 * (0.9 + 0.35))
    assert gravity(arm, [math.pi / 2, 0]) == pytest.approx([hand, -9.81 * 0.7 * 0.35], abs=1e-9)
    assert gravity(arm, [0, 0]) == pytest.approx([0, 0], abs=1e-9)
    # without the words: assumed along -y0, and said so
    quiet = _unnamed("planar-2r-lagrange.md", tmp_path, lambda t: t.replace("gravity $g$ acts along $-y_0$", "g"))
    assert any(
        "no base acceleration or gravity vector is stated" in a for a in robot_from_text(read(quiet)).assumptions
    )
