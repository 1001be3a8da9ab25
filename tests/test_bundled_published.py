"""Every bundled model loads by default; the published ones whose inertias are not
physical (PUMA 560 and Stanford arm as their sources give them) with exactly one
warning naming the source and each offending link, refused under strict checking."""

from __future__ import annotations

import re
import warnings

import numpy as np
import pytest

import armdyn
from armdyn.cli import main
from armdyn.errors import ModelError
from armdyn.inertia import physical_violations
from armdyn.io import bundled_robots


def _bad_links(robot) -> list[str]:
    """Links of the bound robot that fail the physical check (evaluated here, with NumPy
    eigenvalues, not by the loader)."""
    out = []
    for link in robot.links.values():
        inertia = np.array(link.inertia.evalf(), dtype=float)
        moments = np.sort(np.linalg.eigvalsh(inertia))
        if moments[0] + moments[1] < moments[2] * (1 - 1e-6) or float(link.mass) < 0:
            out.append(link.name)
    return out


@pytest.mark.parametrize("name", [r["name"] for r in bundled_robots()])
def test_bundled_model_loads_and_binds_with_at_most_one_warning(name):
    with warnings.catch_warnings(record=True) as record:
        warnings.simplefilter("always")
        robot = armdyn.load(name)
        bound = robot.bind()
        bound.bind()
    if bound.free_symbols():  # a symbolic textbook model: nothing to check numerically
        assert not record
        return
    bad = _bad_links(bound)
    assert len(record) == (1 if bad else 0), [str(w.message) for w in record]
    if bad:
        message = str(record[0].message)
        assert re.findall(r"link '(\w+)'", message) == bad
        assert robot.meta["source"].split()[0] in message
        with pytest.raises(ModelError, match="triangle inequality"):
            armdyn.load(name, strict=True).bind()
        # the accepted links are exactly what the library's own check flags
        assert all(physical_violations(bound.links[n].mass, bound.links[n].inertia) for n in bad)


def test_cli_show_and_simulate_puma560(capsys, tmp_path):
    assert main(["show", "puma560"]) == 0
    err = capsys.readouterr().err
    assert err.count("armdyn: warning:") == 1 and "link 'link1'" in err and "link 'link3'" in err
    assert main(["simulate", "puma560", "--duration", "0.05", "--dt", "1e-3", "--quiet"]) == 0
    out, err = capsys.readouterr()
    assert err.count("\n") == 1 and "q_final" in out
    assert main(["show", "puma560", "--strict"]) == 2
    assert "triangle inequality" in capsys.readouterr().err
