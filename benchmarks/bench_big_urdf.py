"""Time to load a valid URDF with many joints (a chain with a side branch every tenth
link, every link with an inertial, every fifth joint fixed), to show the reader and
the Robot's tree ordering scale linearly.

    PYTHONPATH=python python3 benchmarks/bench_big_urdf.py [N ...]   (default 1000 10000)
"""

from __future__ import annotations

import sys
import time
import warnings


def big_urdf(n: int) -> str:
    links = ['<link name="l0"/>']
    joints = []
    for k in range(1, n + 1):
        links.append(
            f'<link name="l{k}"><inertial><mass value="1"/><origin xyz="0.1 0 0"/>'
            '<inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>'
        )
        parent = k - 1 if k % 10 else max(0, k - 5)  # a side branch every tenth link
        kind = "fixed" if k % 5 == 0 else "revolute"
        joints.append(
            f'<joint name="j{k}" type="{kind}"><parent link="l{parent}"/><child link="l{k}"/>'
            f'<origin xyz="0.1 0 0" rpy="0 0 0.1"/><axis xyz="0 0 1"/>'
            '<limit lower="-3" upper="3" effort="1" velocity="1"/></joint>'
        )
    # joints listed in reverse, so the reader must reorder them into a tree order
    return '<?xml version="1.0"?>\n<robot name="big">' + "".join(links) + "".join(reversed(joints)) + "</robot>"


def main(sizes: list[int]) -> None:
    from armdyn.io.urdf import load_urdf

    for n in sizes:
        text = big_urdf(n)
        t0 = time.perf_counter()
        with warnings.catch_warnings():
            warnings.simplefilter("error")  # every link has mass: no warning expected
            robot = load_urdf(text)
        seconds = time.perf_counter() - t0
        assert len(robot.joints) == n
        print(f"{n:>6} joints ({robot.dof} movable, joints given child-first): loaded in {seconds:.2f} s")


if __name__ == "__main__":
    main([int(a) for a in sys.argv[1:]] or [1000, 10000])
