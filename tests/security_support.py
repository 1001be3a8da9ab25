"""What the security and hardening tests share: a two-link arm as YAML text whose names
are the caller's, and a wall-clock deadline that turns a hang into a failure."""

from __future__ import annotations

import contextlib
import json
import signal


def two_link_yaml(robot: str, j1: str = "q1", j2: str = "q2", link: str = "link1") -> str:
    """A 2R arm with numeric inertia whose robot, first joint and first link carry the
    given names (JSON strings are valid YAML scalars, whatever they hold)."""
    n, a, b, lk = (json.dumps(x) for x in (robot, j1, j2, link))
    return f"""
name: {n}
gravity: [0, -9.81, 0]
joints:
  - {{name: {a}, type: revolute, parent: base, child: {lk}, axis: [0, 0, 1]}}
  - {{name: {b}, type: revolute, parent: {lk}, child: link2, xyz: [0.7, 0, 0.1], axis: [0, 1, 0]}}
links:
  - {{name: {lk}, mass: 1.3, com: [0.3, 0.05, 0], inertia: {{ixx: 0.02, iyy: 0.05, izz: 0.06}}}}
  - {{name: link2, mass: 0.8, com: [0.25, 0, 0.02], inertia: {{ixx: 0.01, iyy: 0.03, izz: 0.035}}}}
"""


@contextlib.contextmanager
def deadline(seconds: int):
    """A hang becomes a failure (SIGALRM interrupts the Python-level loader)."""

    def expired(*_):
        raise TimeoutError(f"still running after {seconds} s")

    old = signal.signal(signal.SIGALRM, expired)
    signal.alarm(seconds)
    try:
        yield
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, old)
