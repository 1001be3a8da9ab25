"""With ARMDYN_REQUIRE_OPTIONAL=1 (set in CI, where the test extra is installed) a
skipped test is reported as a failure: nothing may skip silently there."""

from __future__ import annotations

import os

import pytest


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_makereport(item, call):
    outcome = yield
    report = outcome.get_result()
    if report.skipped and os.environ.get("ARMDYN_REQUIRE_OPTIONAL") == "1":
        reason = report.longrepr[2] if isinstance(report.longrepr, tuple) else str(report.longrepr)
        report.outcome = "failed"
        report.longrepr = f"skipped, but ARMDYN_REQUIRE_OPTIONAL=1 forbids skips: {reason}"
