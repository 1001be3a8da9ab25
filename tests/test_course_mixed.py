"""A mixed class (RP arms and parallel-axis proofs) made into one folder and graded: a
rubric per kind, side by side; each student graded against their own kind; one row per
student; final torques per method; the summary per kind.

Every expected score is counted here by hand from the rubric's rules and the steps each
kind asks (an RP arm: Newton-Euler's 21 steps, each 1 point and each tau 2, 23 points;
Lagrange's 11 steps, 13 points; 36 in all. The parallel-axis proof: its worked proof's 7
links, 1 point each), never read from armdyn's output.
"""

from __future__ import annotations

import json
import re

import pytest

from armdyn.cli import main
from armdyn.course import Gradebook, Rubric, summary_html
from armdyn.course.exercise import make_exercise, rubric_path
from armdyn.errors import ModelError

RP_NE, RP_LAGRANGE, PROOF_LINKS = 23, 13, 7


@pytest.fixture(scope="module")
def mixed(tmp_path_factory):
    """Exercise folder: rp for ana, ben, cy, dan; parallel-axis for eve, fay, gus."""
    root = tmp_path_factory.mktemp("mixed")
    ex = root / "exercise"
    (root / "arms.csv").write_text("id\nana\nben\ncy\ndan\n")
    (root / "proofs.csv").write_text("id\neve\nfay\ngus\n")
    make_exercise("rp", ex, seed=3, roster=root / "arms.csv", convention="craig")
    make_exercise("parallel-axis", ex, seed=3, roster=root / "proofs.csv")
    return root, ex


def _lines(text: str) -> list[str]:
    return text.splitlines()


def _sign_slip_in_tau(text: str, tau: str, which: int) -> str:
    """The ``which``-th (0-based) display line of ``tau`` with its first ``+`` made ``-``."""
    out, seen = [], 0
    for line in _lines(text):
        if line.startswith(f"$$\\tau_{{{tau}}} = "):
            if seen == which:
                head, rest = line.split(" = ", 1)
                line = head + " = " + rest.replace(" + ", " - ", 1)
            seen += 1
        out.append(line)
    return "\n".join(out) + "\n"


@pytest.fixture(scope="module")
def graded(mixed):
    root, ex = mixed
    subs = root / "subs"
    subs.mkdir()
    sol = {s: (ex / s / "solution.md").read_text() for s in ("ana", "ben", "cy", "dan", "eve", "fay")}
    (subs / "ana.md").write_text(sol["ana"])  # every step right
    # ben stops after the outward pass: 3 base + 12 outward steps, all right, 15 points
    ben = _lines(sol["ben"])
    (subs / "ben.md").write_text(
        "\n".join(
            ben[: ben.index("**Inward pass (force and moment on each link by its parent, in the link's frame)**")]
        )
        + "\n"
    )
    # cy forgets the Coriolis factor 2 in v_dot_2: wrong (0), and the right vc_dot_2 after it is
    # no longer what cy's own v_dot_2 gives: unsupported (half)
    cy = sol["cy"].replace(r"- 2 \dot d_2 \dot\theta_1", r"- \dot d_2 \dot\theta_1", 1)
    assert cy != sol["cy"]
    (subs / "cy.md").write_text(cy)
    # dan slips in Newton-Euler's tau_2 (a sign) but has Lagrange's tau_2 right
    (subs / "dan.md").write_text(_sign_slip_in_tau(sol["dan"], "2", 0))
    (subs / "eve.md").write_text(sol["eve"])  # the worked proof
    # fay says the mass-centre fact of the reference point instead of C
    fay = re.sub(
        r"\\int_\{\\mathcal\{B\}\} (\\mathbf\{)?r_C(\})? \\, dm", r"\\int_{\\mathcal{B}} \1r_X\2 \\, dm", sol["fay"]
    )
    point = re.search(r"about a point (\w)", sol["fay"]).group(1)
    fay = fay.replace("r_X", f"r_{point}")
    assert fay != sol["fay"]
    (subs / "fay.md").write_text(fay)
    (subs / "gus.md").write_text("---\nstudent: gus\nvariant: gus\nrobot: model.yaml\n---\n\n")  # nothing after it
    out = root / "out"
    code = main(["grade", str(subs), "--variants", str(ex), "--gradebook", str(out / "grades.csv"), "--jobs", "2"])
    data = json.loads((out / "grades.json").read_text())
    return code, {r["student"]: r for r in data["rows"]}, data, (out / "summary.html").read_text(), out


def test_make_writes_a_rubric_per_kind_and_refuses_to_overwrite(mixed, capsys):
    root, ex = mixed
    assert rubric_path(ex, "rp").endswith("rubric-rp.yaml")
    rp = Rubric.load(rubric_path(ex, "rp"))
    proof = Rubric.load(rubric_path(ex, "parallel-axis"))
    assert len(rp.required_by_part["newton-euler"]) == 21 and len(rp.required_by_part["lagrange"]) == 11
    assert "tau_2" in rp.required_by_part["lagrange"] and "omega_3" not in rp.required_by_part["newton-euler"]
    assert not proof.required and not proof.required_by_part
    assert "kind: parallel-axis" in (ex / "eve" / "variant.yaml").read_text()
    before = (ex / "ana" / "model.yaml").read_bytes()
    with pytest.raises(ModelError, match=r"already there: ana, ben, cy, dan, rubric-rp.yaml"):
        make_exercise("rp", ex, seed=99, roster=root / "arms.csv")
    assert (ex / "ana" / "model.yaml").read_bytes() == before  # nothing written
    code = main(["exercise", "make", "rr", "--roster", str(root / "arms.csv"), "--out", str(ex)])
    assert code == 2 and "already there: ana" in capsys.readouterr().err
    assert (ex / "ana" / "model.yaml").read_bytes() == before


def test_force_overwrites(tmp_path):
    make_exercise("rr", tmp_path, seed=1, count=1)
    with pytest.raises(ModelError, match="--force"):
        make_exercise("rr", tmp_path, seed=2, count=1)
    make_exercise("rr", tmp_path, seed=2, count=1, force=True)
    assert "seed: 2" in (tmp_path / "v001" / "variant.yaml").read_text()


def test_each_student_against_their_own_kind(graded):
    code, rows, data, _, _ = graded
    assert code == 1  # gus is not graded
    ana, ben, cy, dan, eve, fay, gus = (rows[s] for s in ("ana", "ben", "cy", "dan", "eve", "fay", "gus"))
    assert ana["kind"] == "rp" and eve["kind"] == "parallel-axis"
    assert (ana["total"], ana["max"]) == (36, 36)
    assert (ana["points_newton-euler"], ana["points_lagrange"], ana["points_proof"]) == (RP_NE, RP_LAGRANGE, None)
    assert ana["tau_newton-euler"] == "2/2" and ana["tau_lagrange"] == "2/2"
    assert (ben["total"], ben["max"]) == (15, 36)  # only what is written
    assert ben["tau_newton-euler"] == "0/2" and ben["tau_lagrange"] == "0/2"
    assert (cy["total"], cy["max"]) == (36 - 1 - 0.5, 36)
    assert cy["first_wrong"] == "v_dot_2" and cy["first_wrong_kind"] == "factor missing"
    assert (dan["total"], dan["max"]) == (36 - 2, 36)
    assert dan["tau_newton-euler"] == "1/2" and dan["tau_lagrange"] == "2/2"  # the NE slip is not masked
    assert dan["first_wrong"] == "tau_2" and dan["first_wrong_kind"] == "wrong sign"
    assert (eve["total"], eve["max"]) == (PROOF_LINKS, PROOF_LINKS)
    assert (eve["points_proof"], eve["points_newton-euler"], eve["tau_newton-euler"]) == (PROOF_LINKS, None, None)
    assert (fay["total"], fay["max"]) == (PROOF_LINKS - 1, PROOF_LINKS)
    assert fay["first_wrong_kind"] == "proof: mass-centre fact about the wrong point"
    assert not fay["first_wrong"].startswith("proof_") and "dm" in fay["first_wrong"]  # named by its equation
    assert gus["status"] == "error" and "the file is empty" in gus["error"]
    assert all(r["submissions"] == 1 and r["policy"] == "latest" for r in rows.values())


def test_csv_columns_are_the_same_for_every_kind(graded):
    *_, out = graded
    lines = (out / "grades.csv").read_text().splitlines()
    head = lines[0].split(",")
    assert head[:7] == ["student", "variant", "kind", "status", "error", "submissions", "policy"]
    assert [c for c in head if c.startswith("points_")] == ["points_newton-euler", "points_lagrange", "points_proof"]
    assert "tau_newton-euler" in head and "tau_lagrange" in head and not any("7-4" in c for c in head)
    assert all(len(line.split(",")) == len(head) for line in lines[1:] if '"' not in line)


def test_summary_per_kind(graded):
    *_, page, _ = graded
    sections = re.split(r"<h2>", page)
    rp = next(s for s in sections if s.startswith("rp</h2>"))
    proof = next(s for s in sections if s.startswith("parallel-axis</h2>"))
    assert "<b>4</b> students" in rp and "mean points <b>29.88</b> of <b>36</b>" in rp  # (36+15+34.5+34)/4
    firsts = dict(re.findall(r'<tr><td><code>([^<]+)</code></td><td class="num">(\d+)</td>', rp))
    assert firsts == {"v_dot_2": "1", "tau_2": "1"}
    kinds = dict(re.findall(r'<tr><td>([^<]+)</td><td class="num">(\d+)</td><td class="num">\d+</td><td>', rp))
    assert kinds == {"factor missing": "1", "wrong sign": "1"}
    assert re.search(r"right but unsupported.*?<td class=\"num\">1</td>", rp)  # cy's vc_dot_2
    assert "proof_" not in proof and "proof: mass-centre fact about the wrong point" in proof
    assert "mean points <b>6.50</b> of <b>7</b>" in proof
    assert "the file is empty after its front matter" in page and "gus" not in page
    assert "one row per student: the latest graded submission" in page


def test_one_rubric_for_a_mixed_class_counts_each_kinds_parts():
    """parts: newton-euler 10, lagrange 5, proof 10; required: tau_1, tau_2 and an RRR arm's
    omega_3. A perfect RP arm scores 15 of 15 (not charged for a third link it does not
    have) and a perfect proof 10 of 10 (not charged for torques)."""
    rubric = Rubric.from_text(
        "parts:\n  newton-euler: 10\n  lagrange: 5\n  proof: 10\nrequired: [tau_1, tau_2, omega_3]\n"
    )
    arm = {
        "method": "newton-euler+lagrange",
        "tau_correct": [True, True],
        "steps": [{"name": n, "status": "correct"} for n in ("F_1", "tau_2", "tau_1", "T", "tau_1", "tau_2")],
    }
    proof = {
        "method": "newton-euler",
        "tau_correct": [],
        "steps": [{"name": f"proof_{k}", "status": "correct"} for k in range(7)],
    }
    gb = Gradebook.from_results([("a", "a", arm, None, "rp"), ("p", "p", proof, None, "parallel-axis")], rubric=rubric)
    a, p = gb.rows
    assert (a["total"], a["max"]) == (15, 15) and (p["total"], p["max"]) == (10, 10)
    # the same arm without its Lagrange torques: tau_1, tau_2 required in both methods (4 of 6 points there)
    arm["steps"] = arm["steps"][:4]
    a = Gradebook.from_results([("a", "a", arm, None, "rp")], rubric=rubric).rows[0]
    assert a["points_lagrange"] == pytest.approx(5 * 1 / 5) and a["points_newton-euler"] == 10


def _report(total_right: int, wrong: int) -> dict:
    steps = [{"name": f"F_{k}", "status": "correct"} for k in range(1, total_right + 1)]
    steps += [{"name": f"N_{k}", "status": "wrong", "message": "sign flipped"} for k in range(1, wrong + 1)]
    return {"method": "newton-euler", "tau_correct": [], "steps": steps}


@pytest.mark.parametrize("policy, total", [("latest", 2), ("best", 3)])
def test_one_row_per_student_by_policy(policy, total):
    items = [
        ("ann", "v", _report(3, 0), None),  # first: 3 points
        ("bob", "v", None, "timeout: more than 60 s"),
        ("ann", "v", _report(2, 1), None),  # then: 2 points
        ("ann", "v", None, "crashed: no result"),  # then not graded: not chosen while one is graded
    ]
    gb = Gradebook.from_results(items, policy=policy)
    rows = {r["student"]: r for r in gb.rows}
    assert len(gb.rows) == 2 and rows["ann"]["submissions"] == 3 and rows["ann"]["total"] == total
    assert rows["ann"]["policy"] == policy and len(gb.set_aside) == 2
    assert f"one row per student: {'the latest' if policy == 'latest' else 'the graded submission with the most'}" in (
        summary_html(gb)
    )
    with pytest.raises(ValueError, match="policy"):
        Gradebook.from_results(items, policy="first")


def test_cli_policy_and_a_shared_rubric(graded, mixed):
    """--policy best is stated in every row; --rubric replaces the kinds' rubrics for all,
    each student still scored on their own kind's parts (from the cache: nothing re-graded)."""
    root, ex = mixed
    *_, out = graded
    shared = root / "shared.yaml"
    shared.write_text("parts:\n  newton-euler: 10\n  lagrange: 5\n  proof: 10\n")
    book = out / "best.csv"
    code = main(
        ["grade", str(root / "subs"), "--variants", str(ex), "--gradebook", str(book), "--policy", "best"]
        + ["--rubric", str(shared)]
    )
    assert code == 1
    rows = {r["student"]: r for r in json.loads(book.with_suffix(".json").read_text())["rows"]}
    assert {r["policy"] for r in rows.values()} == {"best"}
    assert (rows["ana"]["total"], rows["ana"]["max"]) == (15, 15)  # 10 + 5: no proof part
    assert (rows["eve"]["total"], rows["eve"]["max"]) == (10, 10)  # the proof part only
    assert rows["ben"]["points_newton-euler"] == pytest.approx(10 * 15 / RP_NE, abs=0.01)  # 15 of 23 points
