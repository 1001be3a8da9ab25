"""`armdyn simulate` as a user meets it: the run, its plot and GIF, the progress bar, and bad
input (one line, non-zero exit, nothing written)."""

from __future__ import annotations

import sys

import numpy as np
import pytest
from PIL import Image

from armdyn.cli import main


def run(capsys, *argv):
    code = main(list(argv))
    out = capsys.readouterr()
    return code, out.out, out.err


def test_simulate_writes_plot_and_gif(capsys, tmp_path):
    png, gif = tmp_path / "run.png", tmp_path / "run.gif"
    code, out, err = run(
        capsys,
        "simulate",
        "ur5",
        "--duration",
        "1",
        "--dt",
        "1e-3",
        "--q0",
        "0,-0.3,0.3,0,0,0",
        "--plot",
        str(png),
        "--animate",
        str(gif),
        "--fps",
        "10",
    )
    assert code == 0, err
    assert "1000 steps" in out and "relative drift" in out
    drift = float(out.split("relative drift ")[1].split()[0])
    assert 0 <= drift < 1e-6
    with Image.open(png) as im:
        assert im.size[0] > 400 and im.size[1] > 400
    with Image.open(gif) as im:
        assert im.n_frames == 11  # 1 s at 10 frames per second, both ends
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run.gif", "run.png"]  # no temporary left


def test_simulate_pd_controller_reaches_target(capsys):
    target = [0.4, -1.0, 1.0, 0.2, 0.3, 0.1]
    for controller in ("pd-gravity", "computed-torque"):
        code, out, err = run(
            capsys,
            "simulate",
            "ur5",
            "--duration",
            "4",
            "--dt",
            "1e-3",
            "--controller",
            controller,
            "--target",
            ",".join(map(str, target)),
        )
        assert code == 0, err
        final = [float(x) for x in out.split("q_final  = [")[1].split("]")[0].split(",")]
        np.testing.assert_allclose(final, target, atol=1e-3)


def test_progress_bar_only_on_a_terminal(capsys, monkeypatch):
    argv = ("simulate", "ur5", "--duration", "20", "--dt", "1e-4", "--stride", "1000")
    code, out, err = run(capsys, *argv)
    assert code == 0 and err == ""  # redirected stderr: no bar frames in a log
    monkeypatch.setattr(sys.stderr, "isatty", lambda: True)  # stderr as a terminal: a tqdm bar
    code, out, err = run(capsys, *argv)
    assert code == 0
    assert "simulating:" in err and "step" in err


@pytest.mark.parametrize(
    "argv, message",
    [
        (["--duration", "1", "--dt", "0"], "--dt must be a positive"),
        (["--duration", "1", "--dt", "nan"], "--dt must be a positive"),
        (["--duration", "0", "--dt", "1e-3"], "--duration must be"),
        (["--duration", "1e7", "--dt", "1e-3", "--stride", "1"], "GiB"),
        (["--duration", "1", "--dt", "1e-3", "--q0", "1,2,x"], "--q0 must be comma-separated numbers"),
        (["--duration", "1", "--dt", "1e-3", "--q0", "1,2,3"], "--q0 needs 1 or 6 values"),
        (["--duration", "1", "--dt", "1e-3", "--controller", "pd"], "needs --target"),
        (["--duration", "1", "--dt", "1e-3", "--target", "1"], "--target needs --controller"),
        (["--duration", "1", "--dt", "1e-3", "--animate", "run.mp4"], "ending in .gif"),
        (["--duration", "1", "--dt", "1e-3", "--plot", "nowhere/run.png"], "does not exist"),
    ],
)
def test_bad_input_one_line_nothing_written(capsys, tmp_path, monkeypatch, argv, message):
    monkeypatch.chdir(tmp_path)
    extra = [] if "--plot" in argv else ["--plot", "ok.png"]
    code, out, err = run(capsys, "simulate", "ur5", *argv, *extra)
    assert code == 2
    assert err.startswith("armdyn: error: ") and message in err and err.count("\n") == 1, err
    assert list(tmp_path.iterdir()) == []
