"""The notation corpus (tests/corpus/): its truth files agree with SymPy, and the grader's
verdicts agree with them.

(a) ``truth.py --check`` re-establishes every equation's truth from first principles with
    plain SymPy and compares it with the sidecar; a sidecar that disagrees fails, and so does
    a spec that calls a right equation wrong (checked on a mutated spec below).
(b) every corpus file is graded; no file may be refused, and every equation the grader
    reads must get a verdict consistent with its truth: no false alarm on a right equation,
    no pass on a wrong one. Equations the grader does not read are counted by
    benchmarks/bench_corpus.py, not failed here.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest
import yaml

ROOT = Path(__file__).resolve().parent.parent
CORPUS = ROOT / "tests" / "corpus"
sys.path.insert(0, str(ROOT / "benchmarks"))

import bench_corpus  # noqa: E402

FILES = sorted(p for p in CORPUS.glob("*.md") if p.name != "README.md")


def test_truth_files_agree_with_sympy():
    run = subprocess.run(
        [sys.executable, str(CORPUS / "truth.py"), "--check"], capture_output=True, text=True, timeout=900
    )
    assert run.returncode == 0, run.stdout + run.stderr
    assert "DIFFERS" not in run.stdout and "NO SPEC" not in run.stdout


def test_truth_check_can_fail(tmp_path):
    # the same file with one slip's truth flipped must be reported as differing
    sys.path.insert(0, str(CORPUS))
    import truth

    name = "planar-2r-energy-slip.md"
    established = truth.establish(name, truth.all_specs()[name])
    on_disk = yaml.safe_load((CORPUS / "planar-2r-energy-slip.truth.yaml").read_text(encoding="utf-8"))
    assert established == on_disk
    flipped = [e for e in established["equations"] if e["truth"] == "wrong"]
    assert flipped, "the file has a deliberate slip"
    flipped[0]["truth"] = "right"
    assert established != on_disk


def test_corpus_is_large_enough():
    assert len(FILES) >= 15
    with_slips = 0
    for md in FILES:
        truth_file = md.with_name(md.name[: -len(".md")] + ".truth.yaml")
        assert truth_file.exists(), f"{md.name} has no truth file"
        eqs = yaml.safe_load(truth_file.read_text(encoding="utf-8"))["equations"]
        with_slips += any(e["truth"] == "wrong" for e in eqs)
    assert with_slips >= len(FILES) // 4


@pytest.mark.parametrize("md", FILES, ids=[p.name for p in FILES])
def test_grader_agrees_with_truth(md):
    truth_file = md.with_name(md.name[: -len(".md")] + ".truth.yaml")
    fs = bench_corpus.score(md, truth_file)
    assert not fs.refused, f"{md.name} refused: {fs.refused}"
    assert not fs.false_alarms, f"{md.name}: false alarms at lines {fs.false_alarms}"
    assert not fs.missed, f"{md.name}: missed slips / carried errors at lines {fs.missed}"


@pytest.mark.parametrize("md", FILES, ids=[p.name for p in FILES])
def test_grader_agrees_with_truth_without_the_robot(md):
    # the robot read from the text (or, failing that, the text's own values): what is read is
    # never called wrong when the truth says right, nor right when it carries a slip
    truth_file = md.with_name(md.name[: -len(".md")] + ".truth.yaml")
    fs = bench_corpus.score(md, truth_file, no_robot=True)
    assert not fs.refused, f"{md.name} refused: {fs.refused}"
    assert not fs.false_alarms, f"{md.name}: false alarms at lines {fs.false_alarms}"
    assert not fs.missed, f"{md.name}: missed slips / carried errors at lines {fs.missed}"


def test_truth_refuses_an_unexplained_wrong_transcription():
    # a right equation transcribed wrong (theta1-ddot for theta1-dot in omega_1) with no
    # 'why' must stop truth.py: a wrong equation is never silently accepted
    sys.path.insert(0, str(CORPUS))
    import dataclasses

    import sympy as sp
    import truth

    name = "planar-2r-craig-align.md"
    spec = dict(truth.all_specs()[name])
    eqs = list(spec["eqs"])
    k = next(i for i, e in enumerate(eqs) if e.quantity == "omega1")
    eqs[k] = dataclasses.replace(eqs[k], rhs=sp.Matrix([0, 0, sp.Symbol("qdd1")]))
    spec["eqs"] = eqs[: k + 1]
    with pytest.raises(SystemExit, match="says nothing"):
        truth.establish(name, spec)
