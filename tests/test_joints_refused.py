"""What handles revolute and prismatic joints only refuses a joint of several coordinates
(spherical, planar, floating) with one ModelError that names what refused and the joint,
before any work: never a wrong answer, never a traceback from deep inside."""

from __future__ import annotations

import argparse
import types

import numpy as np
import pytest
import sympy as sp

import armdyn
from armdyn.errors import ModelError
from armdyn.model import Joint, Link, Robot


def arm(kind: str = "spherical", root_joint=None) -> Robot:
    """A joint of several coordinates ``kind`` named 'hip', then a revolute joint 'knee'."""
    inertia = np.diag([0.02, 0.03, 0.04]).tolist()
    links = [Link("base", 1.0, [0, 0, 0], inertia), Link("thigh", 2.0, [0.1, 0, -0.3], inertia)]
    links.append(Link("shin", 1.5, [0, 0.05, -0.2], inertia))
    joints = [
        Joint("hip", kind, "base", "thigh", [0, 0, 0.8]),
        Joint("knee", "revolute", "thigh", "shin", [0, 0, -0.5], axis=[0, 1, 0]),
    ]
    return Robot("leg", links, joints, root_joint=root_joint)


def refused(call, what: str, joint: str = "hip"):
    with pytest.raises(ModelError) as err:
        call()
    text = str(err.value)
    assert what in text and f"'{joint}'" in text, text
    return text


@pytest.mark.parametrize("kind", ["spherical", "planar", "floating"])
def test_lagrange_and_check_refuse(kind):
    robot = arm(kind)
    refused(lambda: armdyn.derive(robot, "lagrange"), "Lagrange's method")
    refused(lambda: armdyn.prove_agreement(robot), "armdyn.prove_agreement")


@pytest.mark.parametrize("root_joint", [None, "free-flyer"])
@pytest.mark.parametrize("kind, own", [("spherical", "hip.r23"), ("planar", "hip.cos"), ("floating", "hip.z")])
def test_newton_euler_refuses_a_name_of_the_joints_own_symbols(kind, own, root_joint):
    """The derivation keeps a joint's pose as symbols named after it: a parameter of that
    name would be confused with them."""
    from dataclasses import replace

    robot = arm(kind, root_joint)
    mass = sp.Symbol(own)
    links = [replace(link, mass=mass) if link.name == "shin" else link for link in robot.links.values()]
    robot = Robot(robot.name, links, robot.joints, parameters=[mass], root_joint=root_joint)
    text = refused(lambda: armdyn.derive(robot), own)
    assert "rename" in text


@pytest.mark.parametrize("kind", ["spherical", "planar"])
def test_codegen_and_identification_refuse(kind):
    robot = arm(kind)
    # codegen takes these joints (test_codegen_floating.py), not their C (a quasi-velocity)
    refused(lambda: armdyn.codegen(robot, what="C"), "armdyn.codegen")
    refused(lambda: armdyn.regressor(robot), "armdyn.identification.regressor")
    refused(lambda: armdyn.base_parameters(robot), "armdyn.identification.base_parameters")


def test_grade_refuses_the_model(tmp_path):
    path = tmp_path / "derivation.md"
    path.write_text("# Newton-Euler\n\n$$\\tau_1 = 0$$\n", encoding="utf-8")
    refused(lambda: armdyn.grade(str(path), robot=arm()), "armdyn.grade")


def test_course_solution_refuses():
    from armdyn.course.solution import solution_steps

    refused(lambda: solution_steps(arm()), "course")


def test_simulate_command_runs_and_checks_its_start(tmp_path, capsys):
    """``armdyn simulate`` on a ball joint: from the neutral configuration with a given
    velocity the passive run keeps its energy (E = T + V, the robot's own energies); a
    typed quaternion off unit length is refused, naming the joint (controllers:
    tests/test_simulate_control_joints.py)."""
    from armdyn.simulate_cli import run

    def args(**given):
        base = dict(q0=None, qd0=None, controller=None, target=None, kp=None, kd=None, dt=1e-3, duration=0.5)
        base.update(stride=None, method="rk4", plot=None, animate=None, three_d=None, quiet=True, fps=25.0)
        return argparse.Namespace(**{**base, **given})

    assert run(args(qd0="1,0,0.5,0.3"), arm()) == 0
    drift = float(capsys.readouterr().out.split("relative drift")[1].split()[0])
    assert drift < 1e-9
    with pytest.raises(ValueError, match=r"joint 'hip' \(spherical\) does not have unit length"):
        run(args(q0="0,0,0,2,0"), arm())
    with pytest.raises(ValueError, match="--q0 needs 5 joint values"):
        run(args(q0="0,0,1"), arm())


def test_reference_oracle_refuses():
    from armdyn import reference

    robot = arm()
    refused(
        lambda: reference.rnea(robot, np.zeros(robot.nq), np.zeros(robot.nv), np.zeros(robot.nv)), "armdyn.reference"
    )


def test_compiled_model_refused_by_its_widths():
    from armdyn.numeric.checks import require_one_dof_joints

    model = types.SimpleNamespace(nq=5, nv=4, floating=False, name="leg")  # one joint of several coordinates
    with pytest.raises(ModelError, match="nq 5, nv 4"):
        require_one_dof_joints(model, "armdyn.dask.rnea")
    require_one_dof_joints(types.SimpleNamespace(nq=9, nv=8, floating=True, name="f"), "x")  # a free-flyer alone


BALL_MJCF = """<mujoco model="ballpend">
  <worldbody>
    <body name="bob" pos="0 0 1">
      <joint name="ball" type="ball"/>
      <inertial pos="0.1 0 -0.5" mass="2" diaginertia="0.1 0.2 0.3"/>
    </body>
  </worldbody>
</mujoco>
"""


def test_commands_on_a_ball_joint_model(tmp_path, capsys):
    """armdyn derive prints a ball joint's steps (Newton-Euler only); what takes 1-dof
    joints only says so on one line, naming the file and the joint, status 2 (a passive
    simulation runs: test_simulate_command_runs_and_checks_its_start)."""
    from armdyn.cli import main

    model = tmp_path / "ball.xml"
    model.write_text(BALL_MJCF, encoding="utf-8")
    assert main(["derive", str(model), "--steps", "--method", "both"]) == 0
    out, err = capsys.readouterr()
    assert "spherical joint is derived by Newton-Euler only" in err
    assert "outward pass" in out and "τ₁..₃ = [" in out and "τ₃ = " in out and "Lagrange" not in out
    for argv, what in (
        (["derive", str(model), "--method", "lagrange"], "Lagrange's method"),
        (["check", str(model)], "armdyn.prove_agreement"),
        (["codegen", str(model), "--what", "tau,C"], "armdyn.codegen"),
    ):
        assert main(argv) == 2, argv
        err = capsys.readouterr().err.strip()
        assert err.count("\n") == 0 and str(model) in err and what in err and "'ball'" in err, err
