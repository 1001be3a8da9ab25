"""``armdyn grade DIR``: a class graded in parallel, the gradebook and summary against
the known truth of injected slips, bad files reported alone, limits, the cache, Dask.

The truth is computed here from the injection list (which step, drop or sign) and the
rubric's rules, never from armdyn's output: every step right except the slipped one,
which is wrong and first wrong; its kind is a missing term (drop) or a wrong sign.
"""

from __future__ import annotations

import collections
import json
import os
import re
import time

import numpy as np
import pytest
import yaml

import armdyn
from armdyn.cli import main
from armdyn.course.isolate import ChildPool
from armdyn.course.solution import inject_slip, solution_markdown, solution_steps
from armdyn.course.variants import draw_variant

RUBRIC = "points:\n  tau: 3\n  T: 2\ndefault: 1\ncredit:\n  wrong: 0\n"
POINTS = {"tau": 3, "T": 2}
KIND_OF_SLIP = {"drop": "missing term", "sign": "wrong sign"}
VARIANTS = [("rp", "offaxis"), ("rp", "craig"), ("rr", "spong"), ("pr", "craig"), ("rr", "offaxis"), ("pr", "spong")]


def _points(name: str) -> float:
    key = name if name in ("T", "V", "L") else name.rpartition("_")[0]
    return POINTS.get(key, 1)


def _consumers(name: str, dof: int) -> set[str]:
    """The steps that take ``name`` as a direct input (Newton-Euler of a serial arm, links
    1..dof, and Lagrange), written out from the recursions by hand. Written right after a
    slip in ``name``, such a step does not follow from the student's own value: it is
    right but unsupported (half credit) when the slipped term reaches it."""
    key, _, i = name.rpartition("_") if name not in ("T", "V", "L") else (name, "", "")
    i = int(i) if i else 0
    up, same, down = f"_{i + 1}", f"_{i}", f"_{i - 1}"
    table = {
        "omega": {"omega" + up, "omega_dot" + up, "v_dot" + up, "vc_dot" + same, "N" + same},
        "omega_dot": {"omega_dot" + up, "v_dot" + up, "vc_dot" + same, "N" + same},
        "v_dot": {"v_dot" + up, "vc_dot" + same},
        "vc_dot": {"F" + same},
        "F": {"f" + same, "n" + same},
        "N": {"n" + same},
        "f": {"f" + down, "n" + down, "tau" + same},
        "n": {"n" + down, "tau" + same},
        "T": {"L"},
        "V": {"L"},
        "L": {f"dL_dq{d}_{k}" for d in ("", "d") for k in range(1, dof + 1)},
        "dL_dqd": {"ddt_dL_dqd" + same},
        "ddt_dL_dqd": {"tau" + same},
        "dL_dq": {"tau" + same},
    }
    return {c for c in table.get(key, set()) if not c.endswith(("_0", f"_{dof + 1}"))}


@pytest.fixture(scope="module")
def course(tmp_path_factory):
    """Six variants (model.yaml each) and their solution steps."""
    root = tmp_path_factory.mktemp("course")
    variants = root / "variants"
    out = {}
    for k, (kind, convention) in enumerate(VARIANTS):
        vid = f"w{k}"
        v = draw_variant(kind, vid, seed=9, convention=convention, masses="point")
        (variants / vid).mkdir(parents=True)
        (variants / vid / "model.yaml").write_text(yaml.safe_dump(v.model_dict(), sort_keys=False))
        robot = armdyn.load(str(variants / vid / "model.yaml"))
        out[vid] = (robot, solution_steps(robot))
    (root / "rubric.yaml").write_text(RUBRIC)
    return root, out


def _submission(robot, steps, student, vid, slip_rng=None, how=None):
    slip = None
    if slip_rng is not None:
        steps, slip = inject_slip(steps, slip_rng, robot.q, how=how)
    front = {"student": student, "variant": vid, "robot": "model.yaml", "method": "both"}
    return solution_markdown(robot, steps, front, f"{student}'s derivation"), slip


def test_class_of_60_against_the_injected_truth(course, tmp_path, capsys):
    root, variants = course
    subs = tmp_path / "subs"
    subs.mkdir()
    rng = np.random.default_rng(60)
    truth = {}
    vids = sorted(variants)
    for i in range(60):
        vid = vids[i % len(vids)]
        robot, steps = variants[vid]
        student = f"s{i:02d}"
        slipped = i % 4 != 0  # one in four hands in a right derivation
        how = ("drop", "sign")[int(rng.integers(2))] if slipped else None
        text, slip = _submission(robot, steps, student, vid, rng if slipped else None, how)
        (subs / f"{student}.md").write_text(text)
        total = sum(_points(s.name) for s in steps)
        earned = total - (_points(slip.name) if slip else 0)
        unsupported = sum(_points(c) for c in _consumers(slip.name, robot.dof)) / 2 if slip else 0
        truth[student] = (vid, slip, (earned - unsupported, earned), total)

    book = tmp_path / "out" / "grades.csv"
    book.parent.mkdir()
    t0 = time.perf_counter()
    code = main(
        [
            "grade",
            str(subs),
            "--variants",
            str(root / "variants"),
            "--gradebook",
            str(book),
            "--rubric",
            str(root / "rubric.yaml"),
            "--html-dir",
            str(tmp_path / "reports"),
            "--jobs",
            "2",
        ]
    )
    seconds = time.perf_counter() - t0
    assert code == 0, capsys.readouterr().err
    data = json.loads((tmp_path / "out" / "grades.json").read_text())
    rows = {r["student"]: r for r in data["rows"]}
    assert sorted(rows) == sorted(truth)
    for student, (vid, slip, earned, total) in truth.items():
        r = rows[student]
        assert r["status"] == "graded" and r["variant"] == vid
        assert r["first_wrong"] == (slip.name if slip else None), (student, slip)
        assert r["first_wrong_kind"] == (KIND_OF_SLIP[slip.how] if slip else None), (student, slip)
        low, high = earned  # a right step after the slip that uses it directly may be unsupported
        assert low - 1e-9 <= r["total"] <= high + 1e-9 and r["max"] == pytest.approx(total), (student, slip)
        assert r["n_wrong"] == (1 if slip else 0)
    # the CSV says the same as the JSON
    lines = book.read_text().splitlines()
    assert len(lines) == 61 and lines[0].split(",")[:5] == ["student", "variant", "kind", "status", "error"]
    # the summary's counts: first wrong steps and kinds, from the injection list
    firsts = collections.Counter(s.name for _, s, _, _ in truth.values() if s)
    kinds = collections.Counter(KIND_OF_SLIP[s.how] for _, s, _, _ in truth.values() if s)
    page = (tmp_path / "out" / "summary.html").read_text()
    shown, shown_kinds = collections.Counter(), collections.Counter()  # summed over the kinds' sections
    for k, n in re.findall(r'<tr><td><code>([^<]+)</code></td><td class="num">(\d+)</td>', page):
        shown[k] += int(n)
    for k, n in re.findall(r'<tr><td>([a-z ]+)</td><td class="num">(\d+)</td>', page):
        shown_kinds[k] += int(n)
    assert shown == firsts and shown_kinds == kinds
    # each kind its own section: read from model.yaml's description (no variant.yaml here)
    assert {r["kind"] for r in rows.values()} == {k for k, _ in VARIANTS}
    assert all(f"<h2>{k}</h2>" in page for k, _ in VARIANTS)
    assert f"<b>{len(truth)}</b> students, <b>{len(truth)}</b> submissions" in page
    assert len(list((tmp_path / "reports").glob("*.html"))) == 60
    print(f"60 submissions graded in {seconds:.1f} s with --jobs 2")


@pytest.fixture()
def small_class(course, tmp_path):
    root, variants = course
    subs = tmp_path / "subs"
    subs.mkdir()
    for k, vid in enumerate(sorted(variants)[:3]):
        robot, steps = variants[vid]
        text, _ = _submission(robot, steps, f"s{k}", vid)
        (subs / f"s{k}.md").write_text(text)
    return root, subs


def _run(root, subs, tmp_path, *extra):
    book = tmp_path / "out" / "grades.csv"
    book.parent.mkdir(exist_ok=True)
    code = main(
        ["grade", str(subs), "--variants", str(root / "variants"), "--gradebook", str(book), "--jobs", "2", *extra]
    )
    return code, book


def test_bad_files_are_reported_alone(small_class, tmp_path, capsys):
    root, subs = small_class
    (subs / "corrupt.md").write_bytes(b"---\nstudent: c\nvariant: w0\n---\n$$\\tau_1 = \xff\xfe$$\n")
    (subs / "lost.md").write_text("---\nstudent: lost\nvariant: w99\n---\n$$T = 0$$\n")
    (subs / "twice.md").write_text((subs / "s1.md").read_text())  # says student: s1, but is 'twice'
    (subs / "s1.yaml").write_text("student: s1\nvariant: w1\nsteps: {}\n")  # s1 a second time
    (subs / "nameless.md").write_text("$$T = 0$$\n")  # no front matter, no variant folder 'nameless'
    code, book = _run(root, subs, tmp_path)
    err = capsys.readouterr().err
    assert code == 1
    data = json.loads(book.with_suffix(".json").read_text())
    rows = {r["student"]: r for r in data["rows"]}
    assert len(rows) == len(data["rows"])  # one row per student
    assert [rows[f"s{k}"]["status"] for k in range(3)] == ["graded"] * 3
    assert all(rows[f"s{k}"]["first_wrong"] is None for k in range(3))
    # a file that is not UTF-8 cannot say who handed it in: the file's stem stands for the student
    assert rows["corrupt"]["status"] == "error"
    assert f"{subs / 'corrupt.md'}:5: not UTF-8" in rows["corrupt"]["error"]
    assert rows["lost"]["status"] == "no-variant" and "w99" in rows["lost"]["error"]
    assert rows["nameless"]["status"] == "no-variant"
    # s1 handed in twice: one row (the graded file), the other set aside with its reason
    assert rows["s1"]["submissions"] == 2 and rows["s1"]["policy"] == "latest"
    dup = data["set_aside"]
    assert len(dup) == 1 and dup[0]["student"] == "s1" and dup[0]["status"] == "duplicate"
    assert "s1.yaml" in dup[0]["error"] and "s1.md" in dup[0]["error"]
    assert rows["twice"]["status"] == "graded" and rows["twice"]["variant"] == "w1"
    assert f"armdyn: note: {subs / 'twice.md'}: the front matter says student 's1'" in err
    not_graded = [line for line in err.splitlines() if line.startswith("armdyn: not graded: ")]
    assert len(not_graded) == 4
    assert any(str(subs / "corrupt.md") in line and "UTF-8" in line for line in not_graded), err


def test_a_rubric_that_does_not_parse_stops_before_grading(small_class, tmp_path, capsys):
    root, subs = small_class
    bad = tmp_path / "rubric.yaml"
    bad.write_text("points:\n  tau: 3\n credit: x\n")
    code, book = _run(root, subs, tmp_path, "--rubric", str(bad))
    err = capsys.readouterr().err.strip()
    assert code == 2 and err.startswith(f"armdyn: error: {bad}:3: ") and "\n" not in err
    assert not book.exists()


def test_cache_regrades_only_what_changed(small_class, tmp_path, capsys):
    root, subs = small_class
    code, book = _run(root, subs, tmp_path)
    first = capsys.readouterr().out
    assert code == 0 and "(0 unchanged" in first
    outputs = {p: p.read_bytes() for p in book.parent.glob("*.*") if p.is_file()}
    code, _ = _run(root, subs, tmp_path)
    assert code == 0 and "(3 unchanged" in capsys.readouterr().out
    assert {p: p.read_bytes() for p in book.parent.glob("*.*") if p.is_file()} == outputs  # same bytes
    text = (subs / "s2.md").read_text()
    (subs / "s2.md").write_text(
        re.sub(r"^(\$\$\\tau_\{1\} = .*)\$\$$", r"\1 + 2 m_{1}$$", text, count=1, flags=re.MULTILINE)
    )
    code, _ = _run(root, subs, tmp_path)
    assert code == 0 and "(2 unchanged" in capsys.readouterr().out
    rows = {r["student"]: r for r in json.loads(book.with_suffix(".json").read_text())["rows"]}
    assert rows["s2"]["n_wrong"] >= 1 and rows["s0"]["n_wrong"] == 0


def test_time_limit_per_submission(small_class, tmp_path, capsys):
    root, subs = small_class
    code, book = _run(root, subs, tmp_path, "--timeout", "0.05", "--no-cache")
    assert code == 1
    rows = json.loads(book.with_suffix(".json").read_text())["rows"]
    assert {r["status"] for r in rows} == {"timeout"}
    assert "s0.md: more than 0.05 s (timeout)" in capsys.readouterr().err


# ------------------------------------------------------------------ the isolation itself
def _task(arg):
    if arg == "hang":
        time.sleep(60)
    if arg == "abort":
        os.abort()
    if arg == "memory":
        return {"n": len(bytearray(2 << 30))}  # 2 GB under a 300 MB limit
    if arg == "raise":
        raise KeyError("boom")
    return {"ok": arg}


def test_a_hanging_or_crashing_child_loses_no_other_result():
    items = [(k, a) for k, a in enumerate(["a", "hang", "b", "abort", "memory", "raise", "c"])]
    t0 = time.monotonic()
    got = dict(ChildPool(_task, jobs=2, timeout=1.5, memory_mb=300).run(items))
    assert time.monotonic() - t0 < 20
    assert got[0] == {"ok": "a"} and got[2] == {"ok": "b"} and got[6] == {"ok": "c"}
    assert got[1]["error"].startswith("timeout: more than 1.5 s")
    assert got[3]["error"] == "crashed: killed by SIGABRT"
    assert got[4]["error"].startswith("memory: more than 300 MB")
    assert got[5]["error"].startswith("crashed: KeyError")


def _allocate_100_mb(_arg):
    return {"n": len(bytearray(100 << 20))}


def test_the_memory_budget_is_on_top_of_the_parents_address_space():
    """A parent that has mapped a lot (Jupyter, a test runner) forks children that share
    its mappings: each child still gets its whole budget. 1.5 GB of address space is
    reserved here (never touched, so it costs no memory), then a child allocating 100 MB
    under a 300 MB budget must succeed, and one allocating 2 GB must not."""
    import mmap

    reserve = mmap.mmap(-1, 3 << 29)  # 1.5 GB of address space in the parent
    try:
        got = dict(ChildPool(_allocate_100_mb, jobs=1, timeout=20, memory_mb=300).run([(0, None)]))
        assert got[0] == {"n": 100 << 20}
        got = dict(ChildPool(_task, jobs=1, timeout=20, memory_mb=300).run([(0, "memory")]))
        assert got[0]["error"].startswith("memory: more than 300 MB")
    finally:
        reserve.close()


def test_same_batch_on_a_dask_cluster(small_class, tmp_path, capsys):
    distributed = pytest.importorskip("distributed")
    root, subs = small_class
    code, book = _run(root, subs, tmp_path, "--no-cache")
    assert code == 0
    local = book.read_text()
    book.unlink()
    cluster = distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None)
    try:
        code, book = _run(root, subs, tmp_path, "--no-cache", "--dask", cluster.scheduler_address)
    finally:
        cluster.close()
    assert code == 0
    assert book.read_text() == local


def test_hostile_student_names_stay_inside_the_report_folder(tmp_path):
    from armdyn.course.batch import discover, safe_file_name

    assert safe_file_name("../../etc/passwd") == "_.._etc_passwd"
    assert safe_file_name("..") == "_" and safe_file_name("") == "_"
    subs = tmp_path / "subs"
    subs.mkdir()
    (subs / "a.md").write_text("---\nstudent: ../../x\nvariant: {a: 1}\n---\n$$T = 0$$\n")
    found = discover(subs)
    # the file names the student; the text's claim is only noted
    assert [t.student for t in found.tasks] == ["a"] and found.tasks[0].variant is None and found.refused == []
    assert found.notes == [f"{subs / 'a.md'}: the front matter says student '../../x'; graded as 'a' (the file's name)"]
