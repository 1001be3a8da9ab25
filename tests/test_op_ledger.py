"""The operation-count ledger (benchmarks/op_counts.json): the generated code of every
bundled arm costs no more operations per state than the ledger says.

The ledger is a ratchet, not a proof of correctness (the other codegen tests compare the
generated code with the Rust core and with armdyn.derive): tau, g, M and C of each arm, in
the standard (grouped) and in the base parameters, recounted here; a count above the
ledger's fails (an optimisation lost), and so does one below it, with the command that
writes the new ledger (an optimisation gained: the ledger follows it).
"""

from __future__ import annotations

import json
import os
import warnings

import pytest

import armdyn
import armdyn.printing as printing
from armdyn.io import bundled_robots

LEDGER = os.path.join(os.path.dirname(__file__), "..", "benchmarks", "op_counts.json")
REGENERATE = "PYTHONPATH=python python3 benchmarks/bench_codegen.py --ledger"
QUANTITIES = ("tau", "g", "M", "C")
KINDS = ("mul", "add", "sin_cos", "other", "total")
#: (arm, parameter set) recounted only by the ledger's writer: the 7-dof arms' base
#: parameters take minutes to find (armdyn.identification), not seconds
TOO_SLOW = {("iiwa14", "base"), ("panda", "base")}


def _ledger() -> dict:
    with open(LEDGER) as fh:
        return json.load(fh)["arms"]


def _cases():
    return [
        (entry["name"], key)
        for entry in bundled_robots()
        for key in ("standard", "base")
        if (entry["name"], key) not in TOO_SLOW
    ]


def test_ledger_covers_every_bundled_arm():
    """Every bundled arm has both parameter sets (the slow ones may be missing), every
    quantity and every kind of count in the ledger, each a non-negative integer with
    mul + add = total."""
    ledger = _ledger()
    names = {entry["name"] for entry in bundled_robots()}
    assert names == set(ledger), f"the ledger's arms differ from the bundled ones; run {REGENERATE}"
    for name in names:
        for key in ("standard", "base"):
            if (name, key) in TOO_SLOW and key not in ledger[name]:
                continue
            assert key in ledger[name], f"{name}: no {key} parameters in the ledger; run {REGENERATE}"
            for w in QUANTITIES:
                counts = ledger[name][key][w]
                assert all(isinstance(counts[k], int) and counts[k] >= 0 for k in KINDS), (name, key, w)
                assert counts["mul"] + counts["add"] == counts["total"], (name, key, w)


@pytest.mark.parametrize("name, key", _cases())
def test_operation_counts_do_not_rise(name, key):
    """The counts of tau, g, M and C of one arm and parameter set equal the ledger's: a
    rise fails (naming the quantity and kind), a fall asks for the ledger to be rewritten."""
    want = _ledger()[name][key]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        robot = armdyn.load(name, strict=False)
    got = printing.codegen(robot, what=QUANTITIES, base=(key == "base")).op_counts
    rises, falls = [], []
    for w in QUANTITIES:
        for kind in KINDS:
            was, now = want[w][kind], got[w][kind]
            if now > was:
                rises.append(f"{w} {kind} {was} -> {now}")
            elif now < was:
                falls.append(f"{w} {kind} {was} -> {now}")
    assert not rises, f"{name} ({key} parameters): operation counts rose: {'; '.join(rises)}"
    assert not falls, (
        f"{name} ({key} parameters): operation counts fell ({'; '.join(falls)}): write the new ledger with {REGENERATE}"
    )
