"""armdyn.course: exercise variants, their worked solutions, rubric, gradebook, summary.

Second opinions: the grader (an independent re-application of each method to the
solution's own values) must find every generated solution right, and an injected slip
first wrong exactly where it was put; the same arm written in three frame conventions
must have the same joint torques; the assignment's arm must give the hand-derived torques
of exercise 7-4; gradebook points are recomputed here by hand from the rubric's rules.
"""

from __future__ import annotations

import json
import re

import numpy as np
import pytest
import sympy as sp

import armdyn
from armdyn.course import Gradebook, Rubric, summary_html
from armdyn.course.errorkinds import classify
from armdyn.course.exercise import make_exercise, read_roster
from armdyn.course.kinds import KINDS
from armdyn.course.solution import inject_slip, solution_markdown, solution_steps
from armdyn.course.variants import CONVENTIONS, draw_variant
from armdyn.errors import ModelError
from armdyn.io.yaml import load_yaml_string

# the slips' kinds are checked where the grader's explanation reads the terms exactly
# (its tidy form is skipped for expressions over 400 operations: rrr, whose slips are
# still found first wrong but explained as "differs by")
SMALL_KINDS = ("rp", "rr", "pr", "rrp")
KIND_OF_SLIP = {"drop": "missing term", "sign": "wrong sign"}


def _write_variant(tmp_path, kind, convention, masses="point", ident="s1"):
    import yaml

    v = draw_variant(kind, ident, seed=11, convention=convention, masses=masses)
    folder = tmp_path / f"{kind}-{convention}-{masses}"
    folder.mkdir()
    (folder / "model.yaml").write_text(yaml.safe_dump(v.model_dict(), sort_keys=False))
    robot = armdyn.load(str(folder / "model.yaml"))
    return v, folder, robot


@pytest.mark.parametrize("convention", CONVENTIONS)
@pytest.mark.parametrize("kind", list(KINDS))
def test_solution_grades_correct_and_slips_are_found(tmp_path, kind, convention):
    masses = "rod" if kind in ("rp", "rrp") else "point"
    _, folder, robot = _write_variant(tmp_path, kind, convention, masses)
    steps = solution_steps(robot)
    front = {"robot": "model.yaml", "method": "both"}
    (folder / "solution.md").write_text(solution_markdown(robot, steps, front, "solution"))
    report = armdyn.grade(str(folder / "solution.md"))
    assert [s.name for s in report.steps if s.status != "correct"] == []
    assert report.first_wrong is None and all(report.tau_correct)
    assert len(report.steps) == len(steps)

    rng = np.random.default_rng(sum(map(ord, kind + convention)))
    for k in range(2 if kind != "rrr" else 1):
        slipped, slip = inject_slip(steps, rng, robot.q, how=("drop", "sign")[k % 2])
        (folder / "slip.md").write_text(solution_markdown(robot, slipped, front, "with a slip"))
        report = armdyn.grade(str(folder / "slip.md"))
        assert report.first_wrong == slip.name, slip
        wrong = [s for s in report.steps if s.status == "wrong"]
        assert wrong[0].line == report.steps[slip.index].line
        if kind in SMALL_KINDS:
            assert classify(wrong[0].message) == KIND_OF_SLIP[slip.how], (slip, wrong[0].message)


@pytest.mark.parametrize("kind", list(KINDS))
def test_three_frame_conventions_give_the_same_torques(kind):
    """Frames are a choice: the joint torques of one arm do not depend on them."""
    from armdyn.symbolic import derive

    taus = []
    for convention in CONVENTIONS:
        masses = "point" if kind == "rrr" else "rod"  # rrr's rods: a minute of derivation
        v = draw_variant(kind, "x", seed=5, convention=convention, masses=masses, symbolic=True)
        import yaml

        robot = load_yaml_string(yaml.safe_dump(v.model_dict()), "m.yaml")
        taus.append(sp.Matrix(derive(robot, "newton-euler").tau))
    # compared at random points of every symbol (exact simplification of rrr takes a minute)
    symbols = sorted(set().union(*(t.free_symbols for t in taus)), key=str)
    rng = np.random.default_rng(3)
    for _ in range(5):
        point = {s: float(x) for s, x in zip(symbols, rng.uniform(0.3, 1.7, len(symbols)))}
        ref = np.array(taus[0].evalf(subs=point), dtype=float).ravel()
        assert np.all(np.isfinite(ref)) and np.abs(ref).max() > 0.1
        for t in taus[1:]:
            got = np.array(t.evalf(subs=point), dtype=float).ravel()
            assert np.allclose(got, ref, rtol=1e-10, atol=1e-10)


def test_assignment_arm_gives_the_exercise_torques():
    """The rp kind, off-axis frames, point masses, gravity along -y0: exercise 7-4's arm.
    Its torques are the hand-derived ones of the assignment's Lagrangian check."""
    import yaml

    from armdyn.symbolic import derive

    for seed in range(40):  # the variant whose draw is the assignment's gravity
        v = draw_variant("rp", "a", seed=seed, convention="offaxis", masses="point", symbolic=True)
        if v.gravity == (0, -1, 0):
            break
    robot = load_yaml_string(yaml.safe_dump(v.model_dict()), "m.yaml")
    tau = derive(robot, "newton-euler").tau
    th, d = robot.q
    thd, dd = robot.qd
    thdd, ddd = robot.qdd
    m1, m2, l1, g = (sp.Symbol(n) for n in ("m1", "m2", "l1", "g"))
    tau1 = (
        (m1 + m2) * l1**2 * thdd
        + m2 * l1 * ddd
        + 2 * m2 * d * thd * dd
        + m2 * thdd * d**2
        + (m1 + m2) * g * l1 * sp.cos(th)
        - m2 * g * d * sp.sin(th)
    )
    tau2 = m2 * (l1 * thdd - thd**2 * d + ddd + g * sp.cos(th))
    assert sp.simplify(tau[0] - tau1) == 0
    assert sp.simplify(tau[1] - tau2) == 0


def test_same_seed_same_bytes_and_seed_matters(tmp_path):
    a, b, c = tmp_path / "a", tmp_path / "b", tmp_path / "c"
    make_exercise("rp", a, seed=4, count=2)
    make_exercise("rp", b, seed=4, count=2)
    make_exercise("rp", c, seed=5, count=2)
    files = sorted(p.relative_to(a) for p in a.rglob("*") if p.is_file())
    assert len(files) == 13  # 6 files per variant + rubric-rp.yaml
    for f in files:
        assert (a / f).read_bytes() == (b / f).read_bytes(), f
    assert any((a / f).read_bytes() != (c / f).read_bytes() for f in files if f.name == "model.yaml")


def test_variant_folder_contents(tmp_path):
    make_exercise("rr", tmp_path, seed=1, count=1, convention="craig")
    folder = tmp_path / "v001"
    html = (folder / "problem.html").read_text()
    assert 'http-equiv="Content-Security-Policy"' in html and "<script" not in html
    assert re.search(r'<img [^>]*src="data:image/svg\+xml;base64,', html)
    assert "<math" in html
    md = (folder / "problem.md").read_text()
    assert "$\\alpha_{i-1}$" in md  # Craig's table
    sol = (folder / "solution.md").read_text()
    assert sol.startswith("---\n") and "robot: model.yaml" in sol and "student: v001" in sol
    assert "kind: rr" in (folder / "variant.yaml").read_text()
    page = (folder / "solution.html").read_text()
    assert 'http-equiv="Content-Security-Policy"' in page and "<script" not in page
    assert page.count("<math") >= 30 and "<pre>" not in page  # every step as MathML
    report = armdyn.grade(str(folder / "solution.md"))
    assert report.passed and report.first_wrong is None


def test_statement_escapes_a_hostile_id(tmp_path):
    from armdyn.course.statement import statement_blocks, statement_html

    v = draw_variant("rr", "s1", seed=1)
    v = type(v)(**{**v.__dict__, "ident": "<script>x</script>"})
    page = statement_html(statement_blocks(v, v.model_dict()), None)
    assert "<script>" not in page and "&lt;script&gt;" in page


def test_roster_duplicate_and_bad_ids(tmp_path):
    roster = tmp_path / "roster.csv"
    roster.write_text("id,name\ns1,Ann\ns2,Bo\ns1,Again\n../x,Evil\n\ns3,Cy\n")
    ids, problems = read_roster(roster)
    assert ids == ["s1", "s2", "s3"]
    assert problems[0].startswith(f"{roster}:4: duplicate id 's1' (first on line 2)")
    assert problems[1].startswith(f"{roster}:5: id '../x' is not a folder name")
    (tmp_path / "none.csv").write_text("name\nAnn\n")
    with pytest.raises(ModelError, match=r"none.csv:1: no 'id'"):
        read_roster(tmp_path / "none.csv")


def test_cli_make_with_a_duplicate_roster_row(tmp_path, capsys):
    from armdyn.cli import main

    roster = tmp_path / "roster.csv"
    roster.write_text("student\nann\nann\n")
    code = main(["exercise", "make", "pr", "--roster", str(roster), "--seed", "2", "--out", str(tmp_path / "out")])
    err = capsys.readouterr().err
    assert code == 1
    assert f"{roster}:3: duplicate id 'ann'" in err
    assert (tmp_path / "out" / "ann" / "solution.md").is_file()


# ------------------------------------------------------------------ rubric
def test_rubric_default_and_file(tmp_path):
    r = Rubric.default()
    assert r.step_points("tau_1", "tau") == 2 and r.step_points("F_1", "F") == 1
    assert r.credit["follows-from-earlier-error"] == 0.5 and r.credit["wrong"] == 0
    p = tmp_path / "r.yaml"
    p.write_text("points:\n  tau_2: 5\n  F: 3\ndefault: 0.5\nparts:\n  lagrange: 4\ncredit:\n  wrong: 0.25\n")
    r = Rubric.load(p)
    assert r.step_points("tau_2", "tau") == 5 and r.step_points("F_1", "F") == 3
    assert r.step_points("tau_1", "tau") == 0.5 and r.parts == {"lagrange": 4.0} and r.credit["wrong"] == 0.25


@pytest.mark.parametrize(
    "text, line, what",
    [
        ("points:\n  tau: [1\n", 3, "YAML syntax error"),
        ("points:\n  tau: 2\ncredits:\n  wrong: 0\n", 3, "unknown key 'credits'"),
        ("credit:\n  wrong: 2\n", 2, "credit.wrong must be a fraction"),
        ("credit:\n  wronng: 0\n", 2, "unknown status 'wronng'"),
        ("points:\n  tau: two\n", 2, "points.tau must be a number"),
        ("default: .nan\n", 1, "default must be a number in"),
        ("points:\n  tau: 1\npoints:\n  F: 2\n", 3, "duplicate key"),
    ],
)
def test_rubric_errors_name_file_and_line(tmp_path, text, line, what):
    p = tmp_path / "rubric.yaml"
    p.write_text(text)
    with pytest.raises(ModelError) as err:
        Rubric.load(p)
    assert str(err.value).startswith(f"{p}:{line}: ") and what in str(err.value), str(err.value)
    assert "\n" not in str(err.value)


# ------------------------------------------------------------------ gradebook
def _step(name, status, message=""):
    return {"name": name, "status": status, "message": message}


def test_gradebook_points_by_hand():
    report = {
        "method": "newton-euler+lagrange",
        "first_wrong": "v_dot_1",
        "tau_correct": [True, False],
        "steps": [
            _step("", "unrecognised"),
            _step("omega_1", "correct"),
            _step("v_dot_1", "wrong", "missing term −l1·θ̇1² in the x component"),
            _step("F_1", "follows-from-earlier-error"),
            _step("F_2", "correct-by-convention"),
            _step("tau_1", "correct-but-unsupported"),
            _step("tau_2", "wrong", "θ̇1 written where θ̈1 belongs"),
            _step("T", "correct"),
            _step("tau_1", "correct"),
        ],
    }
    rubric = Rubric.from_text("points:\n  tau: 4\n  F_2: 3\ndefault: 1\nrequired: [n_1, V]\n")
    gb = Gradebook.from_results(
        [("bob", "v1", report, None), ("amy", None, None, "timeout: more than 60 s")], rubric=rubric
    )
    amy, bob = gb.rows
    assert bob["kind"] == "arm-2"  # no exercise kind given: an arm of as many joints as torques
    # Newton-Euler: omega 1 + v_dot 0 + F_1 0.5 + F_2 3 + tau_1 4*0.5 + tau_2 0, of 1+1+1+3+4+4 (+ n_1 required: 1)
    assert bob["points_newton-euler"] == 6.5
    # Lagrange: T 1 + tau_1 4, of 1 + 4 (+ V required: 1)
    assert bob["points_lagrange"] == 5
    assert bob["total"] == 11.5 and bob["max"] == 15 + 6
    assert bob["first_wrong"] == "v_dot_1" and bob["first_wrong_kind"] == "missing term"
    # the final torques per method: NE tau_1 unsupported (right), tau_2 wrong; Lagrange tau_1 right
    assert bob["tau_newton-euler"] == "1/2" and bob["tau_lagrange"] == "1/2"
    assert bob["n_wrong"] == 2 and bob["n_unrecognised"] == 1
    assert amy["status"] == "timeout" and amy["total"] == 0 and amy["error"].startswith("timeout")
    assert gb.kind_counts() == {"missing term": 1, "derivative mixed up": 1}
    assert gb.first_wrong_counts() == {"v_dot_1": 1}
    lines = gb.to_csv().splitlines()
    assert lines[0].startswith(
        "student,variant,kind,status,error,submissions,policy,points_newton-euler,points_lagrange,total,max"
    )
    assert lines[2].startswith("bob,v1,arm-2,graded,,1,latest,6.5,5,11.5,21,v_dot_1,missing term,1/2,1/2")
    data = json.loads(gb.to_json())
    assert data["rows"][1]["total"] == 11.5 and data["columns"] == gb.columns


def test_gradebook_part_totals_scale_and_csv_formulas_are_quoted():
    report = {
        "method": "newton-euler",
        "first_wrong": None,
        "tau_correct": [True],
        "steps": [_step("omega_1", "correct"), _step("tau_1", "follows-from-earlier-error")],
    }
    gb = Gradebook.from_results(
        [("=HYPERLINK(1)", None, report, None)], rubric=Rubric.from_text("parts:\n  newton-euler: 10\n  lagrange: 5\n")
    )
    row = gb.rows[0]
    # a one-joint arm graded by Newton-Euler only asks 12 steps (base 3, outward 6, inward 3):
    # 11 points + tau's 2; written: omega_1 1 + tau_1 2*0.5, scaled to the part's 10
    assert row["kind"] == "arm-1"
    assert row["points_newton-euler"] == pytest.approx(10 * (1 + 1) / 13, abs=0.01)
    assert "points_lagrange" not in row and row["max"] == 10  # no Lagrange part: not counted
    assert "\n'=HYPERLINK(1)," in gb.to_csv()


@pytest.mark.parametrize(
    "message, kind",
    [
        ("missing term −l1·θ̇1² in the x component", "missing term"),
        ("extra terms a + b in the y component", "extra term"),
        ("sign flipped", "wrong sign"),
        ("wrong sign on the term m2·θ̈1 in the z component", "wrong sign"),
        ("θ̇1 written where θ̈1 belongs in the x component", "derivative mixed up"),
        ("a factor l1 missing on m2·d2 in the z component", "factor missing"),
        ("an extra factor m2 on l1", "extra factor"),
        ("differs by −l1", "other"),
    ],
)
def test_error_kinds(message, kind):
    assert classify(message) == kind


def test_summary_page_is_self_contained_and_escaped():
    report = {
        "method": "newton-euler",
        "first_wrong": "F_2",
        "tau_correct": [False],
        "steps": [_step("F_2", "wrong", "missing term <script>alert(1)</script>")],
    }
    gb = Gradebook.from_results([("mallory <b>", "v", report, None), ("x", "v", None, "error: a.md:3: bad")])
    page = summary_html(gb)
    assert 'http-equiv="Content-Security-Policy"' in page and "default-src 'none'" in page
    assert "<script" not in page and "&lt;script&gt;" in page
    assert "mallory" not in page  # anonymised
    assert re.search(r'<img class="chart" [^>]*src="data:image/svg\+xml;base64,', page)
    assert summary_html(gb) == page  # byte-reproducible


# ------------------------------------------------------------------ proofs
@pytest.mark.parametrize("kind", ["parallel-axis", "rotational-energy"])
def test_proof_solutions_grade_correct_and_slips_are_found(tmp_path, kind):
    from armdyn.course.proofkinds import PROOF_MODEL, proof_blocks, proof_markdown, slippable_lines

    (tmp_path / "model.yaml").write_text(PROOF_MODEL)
    for seed in range(3):  # three notations
        title, blocks = proof_blocks(kind, np.random.default_rng(seed))
        text, where = proof_markdown(blocks, {"robot": "model.yaml"}, title)
        (tmp_path / "proof.md").write_text(text)
        report = armdyn.grade(str(tmp_path / "proof.md"))
        links = [s for s in report.steps if s.name.startswith("proof_")]
        assert len(links) >= len(where) and all(s.status == "correct" for s in links), [
            (s.name, s.status, s.message) for s in links
        ]
        for k in slippable_lines(blocks):
            for j in range(len(blocks[k].slips)):
                text, where = proof_markdown(blocks, {"robot": "model.yaml"}, title, slip=(k, j))
                (tmp_path / "slip.md").write_text(text)
                report = armdyn.grade(str(tmp_path / "slip.md"))
                assert report.first_wrong is not None
                assert report.first_wrong.split(".")[0] == f"proof_{where[k]}", (k, j, report.first_wrong)


def test_make_a_proof_exercise(tmp_path):
    make_exercise("rotational-energy", tmp_path, seed=3, count=2)
    for v in ("v001", "v002"):
        report = armdyn.grade(str(tmp_path / v / "solution.md"))
        assert report.first_wrong is None and report.passed
        assert sum(1 for s in report.steps if s.name.startswith("proof_")) >= 7
