"""Joints of several coordinates: armdyn.numeric vs Pinocchio per call from Python, side by
side in one process, on three models built here in both libraries from the same numbers.

    python benchmarks/bench_joints.py            # full run
    python benchmarks/bench_joints.py --quick    # smoke run: fewer repeats

(with armdyn importable: ``PYTHONPATH=python`` after a release build).

* ``rope``: eight links on spherical joints (``JointModelSpherical``), nv 24;
* ``ball-hip quadruped``: a free-flyer base, four legs of a spherical hip and a revolute
  knee, nv 22;
* ``planar base arm``: a planar joint (``JointModelPlanar``) carrying six revolute joints,
  nv 9.

rnea, crba and aba (the same timing as ``bench_floating.py``: medians of ``--repeat``
alternating ``timeit`` runs of ``--number`` calls), and the derivatives of rnea and aba
(``computeRNEADerivatives``, ``computeABADerivatives``; armdyn's from
``algo/multi_derivatives.rs``). Each model is first checked: armdyn == Pinocchio to 1e-10.
Ratios are armdyn time / Pinocchio time: below 1 means armdyn is faster.

Not a test: timings depend on the machine and its load.
"""

from __future__ import annotations

import argparse
import os
import platform
import sys

import numpy as np
import pinocchio as pin

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from bench_numeric import paired_medians, per_call_run  # noqa: E402  (the same timing as the arms')

from armdyn import numeric as num  # noqa: E402
from armdyn.model import Joint, Link, Robot  # noqa: E402

PIN_JOINTS = {
    "spherical": pin.JointModelSpherical,
    "planar": pin.JointModelPlanar,
    "floating": pin.JointModelFreeFlyer,
    "revolute": pin.JointModelRY,
}


def build(name: str, spec: list[tuple], root: bool):
    """(armdyn robot, Pinocchio model) from ``spec``: (joint, type, parent, child, xyz) rows,
    revolute joints about y, every link a 1 kg rod 0.3 m long along -z."""

    def link(n: str) -> Link:
        return Link(n, 1.0, (0.0, 0.0, -0.15), [[0.008, 0, 0], [0, 0.008, 0], [0, 0, 0.001]])

    links = [Link("base", 5.0, (0, 0, 0), [[0.05, 0, 0], [0, 0.08, 0], [0, 0, 0.1]])]
    links += [link(c) for _, _, _, c, _ in spec]
    joints = [Joint(j, t, p, c, xyz=xyz, axis=(0, 1, 0)) for j, t, p, c, xyz in spec]
    robot = Robot(name, links, joints, root_joint="free-flyer" if root else None)
    model = pin.Model()
    model.gravity = pin.Motion(np.array([0, 0, -9.81, 0, 0, 0]))
    ids = {"base": 0}
    inertia = {ln.name: pin.Inertia(float(ln.mass), np.array(ln.floats("com")), ln.floats("inertia")) for ln in links}
    if root:
        ids["base"] = model.addJoint(0, pin.JointModelFreeFlyer(), pin.SE3.Identity(), "root")
        model.appendBodyToJoint(ids["base"], inertia["base"], pin.SE3.Identity())
    for j, t, p, c, xyz in spec:
        ids[c] = model.addJoint(ids[p], PIN_JOINTS[t](), pin.SE3(np.eye(3), np.array(xyz, dtype=float)), j)
        model.appendBodyToJoint(ids[c], inertia[c], pin.SE3.Identity())
    return robot, model


def models() -> dict:
    rope = [
        (f"s{k}", "spherical", "base" if k == 0 else f"l{k - 1}", f"l{k}", (0, 0, 0 if k == 0 else -0.3))
        for k in range(8)
    ]
    legs = []
    for k, (x, y) in enumerate(((0.2, 0.1), (0.2, -0.1), (-0.2, 0.1), (-0.2, -0.1))):
        legs += [
            (f"hip{k}", "spherical", "base", f"thigh{k}", (x, y, 0)),
            (f"knee{k}", "revolute", f"thigh{k}", f"shin{k}", (0, 0, -0.3)),
        ]
    arm = [("slide", "planar", "base", "cart", (0, 0, 0))]
    arm += [
        (f"j{k}", "revolute", "cart" if k == 0 else f"a{k - 1}", f"a{k}", (0, 0, -0.3 if k else 0.1)) for k in range(6)
    ]
    return {
        "rope": build("rope", rope, False),
        "ball-hip quadruped": build("quadruped", legs, True),
        "planar base arm": build("planar-arm", arm, False),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--repeat", type=int, default=15)
    parser.add_argument("--number", type=int, default=2000)
    args = parser.parse_args()
    repeat, number = (5, 300) if args.quick else (args.repeat, args.number)
    print(f"{platform.processor() or platform.machine()}, Python {platform.python_version()}, pin {pin.__version__}")
    print(f"median of {repeat} runs x {number} calls; ratio = armdyn / Pinocchio\n")
    print("| model | nq | nv | algorithm | armdyn (us) | Pinocchio (us) | ratio |")
    print("| --- | --- | --- | --- | --- | --- | --- |")
    rng = np.random.default_rng(0)
    for name, (robot, model) in models().items():
        data = model.createData()
        assert (robot.nq, robot.nv) == (model.nq, model.nv)
        q = pin.randomConfiguration(model, -np.ones(model.nq), np.ones(model.nq))
        v, a = rng.uniform(-1, 1, (2, robot.nv))
        tau = num.rnea(robot, q, v, a)
        assert np.max(np.abs(tau - pin.rnea(model, data, q, v, a))) < 1e-10 * max(1, np.max(np.abs(tau)))
        M = pin.crba(model, data, q)
        assert np.max(np.abs(num.crba(robot, q) - (np.triu(M) + np.triu(M, 1).T))) < 1e-10
        assert np.max(np.abs(num.aba(robot, q, v, tau) - a)) < 1e-8
        pin.computeRNEADerivatives(model, data, q, v, a)
        dq, dv, _ = num.rnea_derivatives(robot, q, v, a)
        assert max(np.max(np.abs(dq - data.dtau_dq)), np.max(np.abs(dv - data.dtau_dv))) < 1e-9 * max(
            1, np.max(np.abs(dq))
        )
        cases = {
            "rnea": ((num.rnea, (robot, q, v, a)), (pin.rnea, (model, data, q, v, a))),
            "crba": ((num.crba, (robot, q)), (pin.crba, (model, data, q))),
            "aba": ((num.aba, (robot, q, v, tau)), (pin.aba, (model, data, q, v, tau))),
            "rnea derivatives": (
                (num.rnea_derivatives, (robot, q, v, a)),
                (pin.computeRNEADerivatives, (model, data, q, v, a)),
            ),
            "aba derivatives": (
                (num.aba_derivatives, (robot, q, v, tau)),
                (pin.computeABADerivatives, (model, data, q, v, tau)),
            ),
        }
        for algo, ((f, fa), (g, ga)) in cases.items():
            n = max(number // 10, 30) if algo.endswith("derivatives") else number
            mine, theirs = paired_medians(per_call_run(f, fa, n), per_call_run(g, ga, n), repeat)
            print(
                f"| {name} | {robot.nq} | {robot.nv} | {algo} | {mine * 1e6:.2f} | {theirs * 1e6:.2f} | {mine / theirs:.2f} |"
            )


if __name__ == "__main__":
    main()
