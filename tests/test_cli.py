"""The command line as a user meets it: the main job, formats, checks, and bad input."""

from __future__ import annotations

import os
import re
import subprocess
import sys
import unicodedata
from pathlib import Path

import pytest

from armdyn.cli import main

HERE = Path(__file__).resolve().parent
BAD = sorted((HERE / "models" / "bad").glob("*.yaml"))


def run(capsys, *argv):
    code = main(list(argv))
    out = capsys.readouterr()
    return code, out.out, out.err


def test_main_job_prints_both_methods_and_agreement(capsys):
    code, out, err = run(capsys, "derive", "rp-arm")
    assert code == 0 and err == ""
    assert "Newton-Euler:" in out and "Lagrange:" in out
    assert out.count("τ₁ =") == 2 and out.count("τ₂ =") == 2
    assert "[OK  ] tau: newton-euler == lagrange (exact)" in out


def test_steps_show_every_quantity_per_link(capsys):
    code, out, _ = run(capsys, "derive", "rp-arm", "--steps", "--method", "newton-euler")
    assert code == 0
    for label in ("ω₁", "ω̇₁", "v̇₁", "v̇_C₁", "F₁", "N₁", "ω₂", "v̇_C₂", "f₂", "n₂", "f₁", "n₁", "τ₁", "τ₂"):
        assert f"  {label} = " in out, label
    # the centripetal term the exercise drops from link 2's acceleration is there
    line = next(s for s in out.splitlines() if s.startswith("  v̇_C₂ = "))
    assert "l₁ θ̇₁²" in line


def test_text_report_writes_symbols_as_the_field_does(capsys):
    """Before: ω̇₁ = [0, 0, 1*theta1_ddot] and 1*d2_ddot, Unicode labels beside ASCII
    symbols."""
    code, out, _ = run(capsys, "derive", "rp-arm", "--steps", "--method", "newton-euler")
    assert code == 0
    out, nfc = unicodedata.normalize("NFC", out), lambda t: unicodedata.normalize("NFC", t)
    assert nfc("  ω̇₁ = [0, 0, θ̈₁]") in out and "  ω₂ = [0, -θ̇₁, 0]" in out
    assert not re.search(r"(?<![\w.])1\*", out) and "_dot" not in out and "_ddot" not in out
    # factors side by side, as written by hand: no "*" anywhere in the Unicode report
    assert nfc("m₂ d̈₂") in out and nfc("2 d₂ m₂ ḋ₂ θ̇₁") in out and "*" not in out
    code, ascii_out, _ = run(capsys, "derive", "rp-arm", "--steps", "--method", "newton-euler", "--ascii")
    assert code == 0 and ascii_out.isascii()
    assert "  omega_dot1 = [0, 0, theta1_ddot]" in ascii_out and "  tau1 = " in ascii_out
    assert not re.search(r"(?<![\w.])1\*", ascii_out)


def test_lagrange_steps_show_energies(capsys):
    code, out, _ = run(capsys, "derive", "rp-arm", "--steps", "--method", "lagrange")
    assert code == 0
    for label in ("T_trans₁", "T_rot₁", "V₁", "T_trans₂", "T =", "V =", "L ="):
        assert label in out, label


@pytest.mark.parametrize("fmt,marker", [("latex", r"\ddot{\theta}_{1}"), ("markdown", "$$\\tau_{1} =")])
def test_formats(capsys, fmt, marker):
    code, out, _ = run(capsys, "derive", "rp-arm", "--format", fmt, "--steps")
    assert code == 0 and marker in out


def test_check_command(capsys):
    code, out, _ = run(capsys, "check", "planar-2r")
    assert code == 0
    assert "M qdd + C qd + g" in out and "skew" not in out and "FAIL" not in out


def test_check_refuses_zero_samples_and_says_how_many_were_used(capsys):
    code, out, err = run(capsys, "check", "planar-2r", "--numeric", "--samples", "0")
    assert code == 2 and out == "" and err.startswith("armdyn: error: ") and "samples" in err
    assert err.count("\n") == 1
    code, out, _ = run(capsys, "check", "planar-2r", "--numeric", "--samples", "3")
    assert code == 0 and "numeric, 3 points" in out and "3 random points" in out


def test_robots_lists_bundled_models(capsys):
    code, out, _ = run(capsys, "robots")
    assert code == 0
    for name in ("rp-arm", "planar-2r", "puma560", "puma560-craig"):
        assert f"\n{name} " in out


def test_unknown_robot_is_one_clear_line(capsys):
    code, out, err = run(capsys, "derive", "no-such-arm")
    assert code == 2 and out == ""
    assert err.startswith("armdyn: error:") and "no-such-arm" in err and err.count("\n") == 1


@pytest.mark.parametrize("path", BAD, ids=[p.name for p in BAD])
def test_bad_model_file_one_line_nonzero(capsys, path):
    code, out, err = run(capsys, "derive", str(path))
    assert code == 2, err
    assert err.count("\n") == 1 and path.name in err and "Traceback" not in err


def test_bad_input_in_a_real_process_has_no_traceback():
    env = dict(os.environ)
    proc = subprocess.run(
        [sys.executable, "-m", "armdyn", "derive", str(HERE / "models" / "bad" / "zero-axis.yaml")],
        capture_output=True,
        text=True,
        timeout=120,
        env=env,
    )
    assert proc.returncode == 2
    assert proc.stderr.strip().splitlines() == [proc.stderr.strip()]
    assert "zero-axis.yaml" in proc.stderr and "joint 'j2'" in proc.stderr and "axis is zero" in proc.stderr


def test_exercise_example_runs():
    """examples/rp_arm_exercise.py asserts the exercise's identities itself."""
    script = HERE.parent / "examples" / "rp_arm_exercise.py"
    proc = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    assert "checks for 'rp-arm': all passed" in proc.stdout


@pytest.mark.parametrize("ascii_only", [True, False], ids=["ascii", "unicode"])
def test_printed_tau_is_the_exercise_result(capsys, ascii_only):
    """What the user reads, parsed back, is exactly the exercise's final tau1, tau2.
    The Unicode report is read back by spelling its symbols in ASCII here (a table
    written out by hand, not the report's own)."""
    import sympy as sp
    from sympy.parsing.sympy_parser import implicit_multiplication, parse_expr, standard_transformations

    implicit = standard_transformations + (implicit_multiplication,)
    _, out, _ = run(capsys, "derive", "rp-arm", "--method", "lagrange", *(["--ascii"] if ascii_only else []))
    spelled = {
        "θ̈₁": "theta1_ddot",
        "θ̇₁": "theta1_dot",
        "θ₁": "theta1",
        "d̈₂": "d2_ddot",
        "ḋ₂": "d2_dot",
        "d₂": "d2",
        "m₁": "m1",
        "m₂": "m2",
        "l₁": "l1",
        "τ₁": "tau1",
        "τ₂": "tau2",
        "²": "**2",
    }
    printed = {}
    for line in unicodedata.normalize("NFC", out).splitlines():
        for uni, asc in spelled.items():
            line = line.replace(unicodedata.normalize("NFC", uni), asc)
        if line.startswith("  tau"):
            assert line.isascii(), line
            lhs, rhs = line.split(" = ", 1)
            # the Unicode report writes factors side by side: read juxtaposition as a product
            printed[lhs.strip()] = parse_expr(rhs.rsplit("    (", 1)[0], transformations=implicit)
    m1, m2, l1, g, th, d, thd, dd, thdd, ddd = sp.symbols("m1 m2 l1 g theta1 d2 theta1_dot d2_dot theta1_ddot d2_ddot")
    tau1 = (
        (m1 + m2) * l1**2 * thdd
        + m2 * l1 * ddd
        + 2 * m2 * d * thd * dd
        + m2 * thdd * d**2
        + (m1 + m2) * g * l1 * sp.cos(th)
        - m2 * g * d * sp.sin(th)
    )
    tau2 = m2 * (l1 * thdd - thd**2 * d + ddd + g * sp.cos(th))
    assert sp.expand(printed["tau1"] - tau1) == 0
    assert sp.expand(printed["tau2"] - tau2) == 0


def test_allow_nonphysical_loads_with_one_warning_line(capsys):
    path = HERE / "models" / "bad" / "triangle-inequality.yaml"
    code, out, err = run(capsys, "derive", str(path), "--allow-nonphysical", "--method", "newton-euler")
    assert code == 0 and "τ₁ =" in out
    assert err.startswith("armdyn: warning: ") and err.count("\n") == 1
    assert "triangle-inequality.yaml" in err and "link 'l2'" in err and "triangle inequality" in err


@pytest.mark.parametrize("later", [0.0, 0.1, 0.3])
def test_ctrl_c_while_the_command_imports_is_one_line_and_130(later):
    """Ctrl-C during the second `python -m armdyn` spends importing SymPy used to print a
    traceback from inside the import. The child reports each import as it ends
    (-X importtime); SIGINT goes `later` seconds after the first import that ends once
    armdyn's handler is in place (the one after armdyn._interrupt), so it lands in
    numpy's, SymPy's or armdyn's own import. Before armdyn's first line runs, Ctrl-C is
    the interpreter's own business."""
    import signal
    import time

    env = dict(os.environ, PYTHONPATH=str(Path(__file__).resolve().parents[1] / "python"))
    cmd = [sys.executable, "-X", "importtime", "-m", "armdyn", "check", "rp-arm"]
    # SIGINT at its default in the child even when this process ignores it (pytest-xdist's
    # workers do, and Python then installs no handler in the child)
    proc = subprocess.Popen(
        cmd,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=env,
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
    )
    seen = False
    for line in proc.stderr:
        module = line.split("|")[-1].strip()
        if seen:
            break
        seen = module == "armdyn._interrupt"
    assert seen, "armdyn._interrupt was never imported"
    time.sleep(later)
    proc.send_signal(signal.SIGINT)
    out, err = proc.communicate(timeout=60)
    rest = [t for t in err.split("\n") if t and not t.startswith("import time:")]
    assert proc.returncode == 130 and rest == ["armdyn: interrupted"] and out == "", (proc.returncode, rest[-5:])
