"""The test environment's lock (requirements/test.lock) agrees with pyproject.toml.

The README's test command installs with ``-c requirements/test.lock``, so a fresh clone
tests against the versions that passed; these tests check that the lock pins every
requirement of the test extra within pyproject's bounds, that dask and distributed are
pinned to the same release, and (in CI) that the environment really is the locked one.
The drift check without the lock is `.ci/drift` (needs the registry).
"""

from __future__ import annotations

import os
import re
import sys
from importlib import metadata

import pytest
from packaging.markers import Marker
from packaging.requirements import Requirement
from packaging.utils import canonicalize_name
from packaging.version import Version

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
LOCK = os.path.join(ROOT, "requirements", "test.lock")


def _pyproject() -> dict:
    if sys.version_info < (3, 11):
        pytest.skip("reading pyproject.toml needs tomllib (Python 3.11+)")
    import tomllib

    with open(os.path.join(ROOT, "pyproject.toml"), "rb") as fh:
        return tomllib.load(fh)


def _lock() -> dict[str, Version]:
    """name -> version pinned for this interpreter (markers evaluated)."""
    pins: dict[str, Version] = {}
    with open(LOCK, encoding="utf-8") as fh:
        for raw in fh:
            line = raw.split("#", 1)[0].strip()
            if not line:
                continue
            spec, _, marker = line.partition(";")
            m = re.fullmatch(r"([A-Za-z0-9_.\-]+)(?:\[[^\]]*\])?==([^\s]+)", spec.strip())
            assert m, f"{LOCK}: not a pin: {raw.strip()!r}"
            if marker.strip() and not Marker(marker.strip()).evaluate():
                continue
            name = canonicalize_name(m.group(1))
            assert name not in pins, f"{LOCK}: {name} pinned twice for this Python"
            pins[name] = Version(m.group(2))
    return pins


def _requirements(extra: str) -> list[Requirement]:
    project = _pyproject()["project"]
    names = project["dependencies"] + project["optional-dependencies"][extra]
    return [Requirement(r) for r in names]


def test_every_requirement_is_bounded_above():
    project = _pyproject()["project"]
    groups = {"dependencies": project["dependencies"], **project["optional-dependencies"]}
    for group, reqs in groups.items():
        for text in reqs:
            req = Requirement(text)
            assert any(s.operator in ("<", "<=", "==", "~=") for s in req.specifier), (
                f"pyproject.toml [{group}]: {text!r} has no upper bound; next month's release could break it"
            )


def test_lock_pins_every_test_requirement_within_its_bounds():
    pins = _lock()
    for req in _requirements("test"):
        name = canonicalize_name(req.name)
        assert name in pins, f"{LOCK} does not pin {req.name} (refresh it: bash requirements/refresh-lock)"
        assert req.specifier.contains(pins[name], prereleases=True), (
            f"{LOCK} pins {req.name}=={pins[name]}, outside pyproject's {req.specifier}"
        )


def test_dask_and_distributed_move_in_step():
    pins = _lock()
    assert pins["dask"] == pins["distributed"], f"dask {pins['dask']} with distributed {pins['distributed']}"
    extras = _pyproject()["project"]["optional-dependencies"]
    for extra in ("dask", "test"):
        reqs = [Requirement(r) for r in extras[extra]]
        dask = [r for r in reqs if canonicalize_name(r.name) == "dask"]
        assert dask and "distributed" in dask[0].extras, f"[{extra}] must take distributed through dask's extra"
        assert not any(canonicalize_name(r.name) == "distributed" for r in reqs), (
            f"[{extra}] names distributed on its own: pip can pair it with a dask it does not import with"
        )


@pytest.mark.skipif(not (os.environ.get("CI") or os.environ.get("ARMDYN_CHECK_LOCK")), reason="CI only")
def test_the_environment_is_the_locked_one():
    """In CI the test command installed with -c requirements/test.lock: every locked
    package present here has the locked version."""
    pins = _lock()
    wrong = []
    for dist in metadata.distributions():
        name = canonicalize_name(dist.metadata["Name"])
        if name in pins and Version(dist.version) != pins[name]:
            wrong.append(f"{name} {dist.version} (locked {pins[name]})")
    assert not wrong, "installed versions differ from requirements/test.lock: " + ", ".join(sorted(wrong))
