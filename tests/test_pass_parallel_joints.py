"""Runs of parallel joints by their compound angle (armdyn.programs.parallel_joints): the
customized Newton-Euler with and without them against armdyn.derive (exactly) and the
Rust core's rnea (a different algorithm), and what they save."""

from __future__ import annotations

import numpy as np
import pytest
from test_codegen import WRIST_3R, _close, _customized_tau_equals_derive, _load

import armdyn
from armdyn.programs.customized_ne import Forms, customized_newton_euler, standard_parameters
from armdyn.programs.grouping import grouped_parameters

# a shoulder, then two parallel joints (alpha 0) with both offsets of the PUMA 560's
# (a2 along x, d3 along the common axis), every inertial parameter symbolic
RUN_3R = (
    WRIST_3R.replace("name: wrist-3r", "name: run-3r")
    .replace("a: 0, alpha: pi/2, d: 0", "a: L2, alpha: 0, d: D3")
    .replace("L1: 0.3,", "L1: 0.3, L2: null, D3: null,")
)


@pytest.mark.parametrize("grouped", [False, True])
def test_parallel_run_by_its_compound_angle_equals_derive_exactly(tmp_path, grouped):
    """Joints 2 and 3 parallel: link 3's angular velocity and U column come from link 1
    by the angle q2 + q3, and link 1's torque takes link 3's moment by that rotation
    (link 2's moment is never formed in full); tau equals armdyn.derive's exactly, with
    the standard and with the grouped parameters, and the runs save operations (the
    program with Forms(parallel_runs=False) is longer)."""
    path = tmp_path / "run-3r.yaml"
    path.write_text(RUN_3R)
    robot = _load(str(path))
    tau_prog = _customized_tau_equals_derive(robot, grouped)
    params = None
    if grouped:
        params, _ = grouped_parameters(robot, *standard_parameters(robot))
    plain, _ = customized_newton_euler(robot, parameters=params, forms=Forms(parallel_runs=False))
    assert tau_prog.operation_counts()["total"] < plain.operation_counts()["total"]


def test_runs_of_parallel_joints_on_a_tree_agree_with_the_rust_core():
    """A tree made to exercise the runs: joint 1 about the base's z, two branches from
    link 1 (one turned by alpha -90 then three parallel joints, its last one followed by a
    prismatic joint and a leaf; one parallel to joint 1 with a fixed joint and a second
    child of the run's middle link), random physical inertias. The customized
    Newton-Euler with its compound angles evaluated at random states equals the Rust
    core's rnea (a different algorithm: spatial vectors, no runs)."""
    from random_models import random_link

    from armdyn.model import Joint, Robot

    rng = np.random.default_rng(21)
    rx = [[1, 0, 0], [0, 0, 1], [0, -1, 0]]  # alpha = -90 deg
    eye = np.eye(3).tolist()
    spec = [  # name, type, parent, child, xyz, rotation, axis
        ("j1", "revolute", "base", "l1", [0, 0, 0.3], eye, [0, 0, 1]),
        ("j2", "revolute", "l1", "l2", [0.1, 0, 0], rx, [0, 0, 1]),
        ("j3", "revolute", "l2", "l3", [0.4, 0, 0.15], eye, [0, 0, 1]),
        ("j4", "revolute", "l3", "l4", [0.35, 0.05, -0.1], eye, [0, 0, 1]),
        ("j5", "prismatic", "l4", "l5", [0.1, 0, 0], rx, [0, 0, 1]),
        ("j6", "revolute", "l1", "l6", [0, 0.2, 0.1], eye, [0, 0, 1]),
        ("j7", "fixed", "l6", "l7", [0.1, 0, 0], rx, [0, 0, 1]),
        ("j8", "revolute", "l3", "l8", [0, 0.1, 0.2], eye, [0, 0, 1]),
    ]
    links = [random_link(rng, "base")] + [random_link(rng, f"l{k}") for k in range(1, 9)]
    joints = [Joint(n, t, p, c, xyz=x, rotation=r, axis=a) for n, t, p, c, x, r, a in spec]
    robot = Robot("runs-tree", links, joints, gravity=(0.0, -3.0, -9.0))
    prog, defs = customized_newton_euler(robot)
    plain, plain_defs = customized_newton_euler(robot, forms=Forms(parallel_runs=False))
    assert prog.operation_counts()["total"] < plain.operation_counts()["total"]  # j3, j4 continue j2's run
    values = {s: float(e) for s, e in defs}
    plain_values = {s: float(e) for s, e in plain_defs}
    for _ in range(4):
        q, qd, qdd = (rng.uniform(-1.5, 1.5, robot.dof) for _ in range(3))
        state = {}
        for group, v in ((robot.q, q), (robot.qd, qd), (robot.qdd, qdd)):
            state.update({s: float(x) for s, x in zip(group, v)})
        want = armdyn.rnea(robot, q, qd, qdd)
        _close(np.array(prog.evaluate({**values, **state}), dtype=float), want)
        _close(np.array(plain.evaluate({**plain_values, **state}), dtype=float), want)
