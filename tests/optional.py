"""Optional test dependencies (the ``test`` extra: pin, example-robot-data, mujoco).

A test that needs one of them is marked ``@needs_pinocchio``, ``@needs_mujoco`` (or calls
:func:`example_robot_data_dir`) and skips alone; its neighbours still run. With the
environment variable ``ARMDYN_REQUIRE_OPTIONAL=1`` (CI, where the test extra is
installed) every skip is a failure instead (see conftest.py).
"""

from __future__ import annotations

import importlib.metadata
from pathlib import Path

import pytest

try:
    import pinocchio as pin
except ImportError:  # the comparisons with Pinocchio skip, nothing else
    pin = None

needs_pinocchio = pytest.mark.skipif(pin is None, reason="pinocchio is not installed (pip install pin)")

try:
    import mujoco
except ImportError:  # the comparisons with MuJoCo skip, nothing else
    mujoco = None

needs_mujoco = pytest.mark.skipif(mujoco is None, reason="mujoco is not installed (pip install mujoco)")

#: where the example-robot-data wheel puts its robots, relative to the distribution
ERD_ROBOTS = "cmeel.prefix/share/example-robot-data/robots"


def example_robot_data_dir() -> Path:
    """``robots/`` of the example-robot-data wheel. Skips the calling test if the
    package is not installed; fails if it is installed but not laid out as expected
    (a silent skip would hide the whole sweep)."""
    try:
        dist = importlib.metadata.distribution("example-robot-data")
    except importlib.metadata.PackageNotFoundError:
        pytest.skip("example-robot-data is not installed (pip install example-robot-data)")
    path = Path(dist.locate_file(ERD_ROBOTS))
    if not path.is_dir():
        pytest.fail(f"example-robot-data {dist.version} is installed but has no {ERD_ROBOTS} (layout changed?)")
    return path
