"""How a simulation ends when it should not go on: a diverging state (NaN/inf) stops at
its step, naming the joint, and keeps what was computed; Ctrl-C ends a long CLI run
within a second, writing nothing. And what a run reports about energy: the work-energy
balance E(t) - E(0) - W(t) of a controlled run, checked against the test's own
trapezoid integrals of tau.qd and g(q).qd and its own kinetic energy 1/2 qd.M qd."""

from __future__ import annotations

import os
import select
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

import armdyn
from armdyn import numeric as num
from armdyn.cli import main
from armdyn.simulate import PD, simulate
from armdyn.simulate_cli import gif_frames

ROOT = Path(__file__).resolve().parent.parent


@pytest.fixture(scope="module")
def ur5():
    return armdyn.load("ur5")


def _unstable(ur5):
    """Explicit PD with gains far beyond what dt = 1e-2 can integrate: diverges."""
    return PD(kp=1e7, kd=0.0, target=np.full(6, 0.5), gravity_compensation=False)


def test_diverging_run_stops_at_its_step(ur5):
    run = simulate(ur5, np.zeros(6), dt=1e-2, steps=400, controller=_unstable(ur5))
    k = run.nonfinite_step
    assert 0 < k < 400
    # kept: exactly the samples before step k, all finite, energies too
    assert len(run.t) == k and run.q.shape == (k, 6)
    assert np.isfinite(run.q).all() and np.isfinite(run.energy).all()
    # a second opinion: k steps from the same start end non-finite, k - 1 steps do not,
    # and the reported joint is the first non-finite one there
    last = simulate(ur5, np.zeros(6), dt=1e-2, steps=k, controller=_unstable(ur5), energies=False)
    before = simulate(ur5, np.zeros(6), dt=1e-2, steps=k - 1, controller=_unstable(ur5), energies=False)
    assert before.nonfinite_step == -1 and np.isfinite(before.q_final).all()
    bad = ~np.isfinite(last.q_final + last.qd_final)
    assert bad.any() and run.nonfinite_joint == int(np.argmax(bad))
    np.testing.assert_array_equal(run.q[-1], before.q[-1])


def test_diverging_batch_row_is_nan_after_its_step(ur5):
    """Row 0 under a torque so large that qd overflows within a few steps, rows 1 and 2
    passive: only row 0 stops, and the others equal single-state runs bit for bit."""
    steps = 200
    torque = np.zeros((3, steps, 6))
    torque[0, :, 1] = 1e305
    q0 = np.array([[0.0, -0.3, 0.3, 0, 0, 0], [0.1, -0.5, 0.2, 0, 0, 0], [0.0, 0.2, 0.1, 0, 0, 0]])
    run = simulate(ur5, q0, dt=1e-3, steps=steps, torque=torque)
    k = run.nonfinite_step[0]
    assert 0 < k < steps and 0 <= run.nonfinite_joint[0] < 6
    assert (run.nonfinite_step[1:] == -1).all() and (run.nonfinite_joint[1:] == -1).all()
    assert np.isnan(run.q[0, k:]).all() and np.isfinite(run.q[0, :k]).all()
    assert np.isnan(run.energy[0, k:]).all() and np.isfinite(run.energy[0, :k]).all()
    for i in (1, 2):
        one = simulate(ur5, q0[i], dt=1e-3, steps=steps)
        np.testing.assert_array_equal(run.q[i], one.q)


def test_diverging_python_torque_is_not_called_singular(ur5):
    kp = 1e7

    def torque(t, q, qd):
        return kp * (0.5 - q)

    run = simulate(ur5, np.zeros(6), dt=1e-2, steps=300, torque=torque)
    assert run.nonfinite_step > 0 and 0 <= run.nonfinite_joint < 6
    assert np.isfinite(run.q).all() and len(run.t) <= run.nonfinite_step


def test_cli_diverging_run_exit_4_writes_what_it_has(capsys, tmp_path):
    png = tmp_path / "run.png"
    code = main(
        [
            "simulate",
            "ur5",
            "--duration",
            "4",
            "--dt",
            "1e-2",
            "--controller",
            "pd",
            "--target",
            "0.5",
            "--kp",
            "1e7",
            "--kd",
            "0",
            "--plot",
            str(png),
        ]
    )
    out, err = capsys.readouterr()
    assert code == 4, err
    assert "singular" not in err + out
    assert err.count("\n") == 1 and "NaN/inf at step" in err and "in joint '" in err
    assert "energy: E(0)" in out and png.exists()


def test_work_energy_balance_of_a_pd_run(ur5):
    """W(t) = integral tau.qd dt and E(t) - E(0) = W(t), against the test's own trapezoid
    integrals on a run ten times finer (dt = 1e-4): tau re-evaluated from the PD law,
    T = 1/2 qd.M qd (crba), V(t) - V(0) = integral g(q).qd dt (g = dV/dq)."""
    target = np.array([0.4, -1, 1, 0.2, 0.3, 0.1])
    m_ii = np.diag(num.crba(ur5, target))  # gains scaled by the joint inertias (light wrist)
    kp, kd = 100.0 * m_ii, 20.0 * m_ii
    pd = PD(kp, kd, target, gravity_compensation=True)
    run = simulate(ur5, np.zeros(6), dt=1e-3, duration=1.0, controller=pd)
    fine = simulate(ur5, np.zeros(6), dt=1e-4, duration=1.0, controller=pd, energies=False)
    q, qd, t = fine.q, fine.qd, fine.t
    g = num.gravity(ur5, q)
    tau = kp * (target - q) - kd * qd + g
    kinetic = 0.5 * np.einsum("si,sij,sj->s", qd, num.crba(ur5, q), qd)

    def integral(power):
        out = np.zeros(len(t))
        for s in range(1, len(t)):
            out[s] = out[s - 1] + 0.5 * (power[s] + power[s - 1]) * (t[s] - t[s - 1])
        return out

    work = integral(np.einsum("si,si->s", tau, qd))
    potential_change = integral(np.einsum("si,si->s", g, qd))
    scale = max(abs(run.energy[0]), kinetic.max(), np.abs(work).max())
    # the physics holds in the test's own numbers (trapezoid error at 1e-4 s)
    assert np.abs(kinetic - kinetic[0] + potential_change - work).max() / scale < 1e-5
    # the run's work (integrated with its state) is that integral, at its own samples
    np.testing.assert_allclose(run.work, work[::10], rtol=0, atol=1e-5 * scale)
    assert np.abs(run.work).max() > 1.0
    # and its balance is small, while the drift is the torques' work
    assert run.energy_balance() < 1e-5 < 1e-2 < run.energy_drift()  # RK4 error at dt = 1e-3: ~3e-6
    assert not run.passive


def test_cli_reports_balance_for_controlled_and_drift_for_passive(capsys):
    main(
        [
            "simulate",
            "ur5",
            "--duration",
            "1",
            "--dt",
            "1e-3",
            "--controller",
            "pd-gravity",
            "--target",
            "0.4,-1,1,0,0,0",
        ]
    )
    out = capsys.readouterr().out
    assert "balance max |E - E(0) - W| / scale" in out and "drift" not in out
    assert float(out.split("/ scale ")[1].split()[0]) < 1e-5
    main(["simulate", "ur5", "--duration", "0.5", "--dt", "1e-3"])
    out = capsys.readouterr().out
    assert "relative drift" in out and "balance" not in out


def test_gif_plays_in_real_time(capsys, tmp_path):
    gif = tmp_path / "run.gif"
    assert (
        main(["simulate", "ur5", "--duration", "2", "--dt", "1e-3", "--q0", "0,-0.3,0.3,0,0,0", "--animate", str(gif)])
        == 0
    )
    out = capsys.readouterr().out
    with Image.open(gif) as im:
        durations = []
        for k in range(im.n_frames):
            im.seek(k)
            durations.append(im.info["duration"])
    # each frame lasts the simulated time between frames: 41 frames 50 ms apart span 2 s
    assert durations == [50] * 41
    assert "GIF: 41 frames of 50 ms, real time" in out
    # long runs: capped frame count, still real time where the sample spacing allows it
    t = np.arange(2001) * 0.01  # 20 s kept every 10 ms
    frames, ms, slowdown = gif_frames(t, 20.0)
    assert len(frames) <= 300 and slowdown == 1.0
    assert ms * (len(frames) - 1) == pytest.approx(1000 * (t[frames[-1]] - t[0]))


def test_ctrl_c_stops_a_long_run_within_a_second(tmp_path):
    """SIGINT during a 1e11-step run: the one line comes within a second (the integration
    polls its stop flag every 256 steps, Python's signal handlers every 50 ms); the exit
    follows after the interpreter's teardown (slow on a loaded machine, so bounded
    loosely); nothing is written."""
    # the armdyn this test imports (a source tree with its built _core, or the installed one)
    env = dict(os.environ, PYTHONPATH=str(Path(armdyn.__file__).resolve().parent.parent))
    proc = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "armdyn",
            "simulate",
            "ur5",
            "--duration",
            "1e5",
            "--dt",
            "1e-6",
            "--plot",
            "run.png",
            "--quiet",
        ],
        cwd=tmp_path,
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        # a child inherits an ignored SIGINT (as under pytest-xdist's workers), and Python
        # then installs no handler for it: give the child the default a terminal gives
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
    )
    try:
        time.sleep(8.0)  # imports, model, and well into the integration (a loaded machine imports slowly)
        assert proc.poll() is None, proc.communicate()
        sent = time.monotonic()
        proc.send_signal(signal.SIGINT)
        assert select.select([proc.stderr], [], [], 20.0)[0], "no line on stderr within 20 s of SIGINT"
        line = proc.stderr.readline()
        took = time.monotonic() - sent
        out, err = proc.communicate(timeout=30)
    finally:
        proc.kill()
    assert line == "armdyn: interrupted\n" and err == "" and out == ""
    assert took < 1.0, took
    assert proc.returncode == 130
    assert list(tmp_path.iterdir()) == []
