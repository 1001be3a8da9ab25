"""The notebooks in examples/notebooks run top to bottom without an error.

Each notebook's last cell asserts what it showed against a second opinion of its own (the
two derivation methods and a closed-form integral; the grading of the student's text before
and after its first slip is fixed; the NumPy reference and the aba(rnea(qdd)) = qdd
identity), so executing it is the test: a failing cell fails it. They are executed by
nbclient in a Jupyter kernel started from this interpreter (a kernel spec written to a
temporary directory), with armdyn importable from where this process imports it.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

import pytest

import armdyn

nbformat = pytest.importorskip("nbformat")
nbclient = pytest.importorskip("nbclient")
kernelspec = pytest.importorskip("ipykernel.kernelspec")

NOTEBOOKS = Path(__file__).resolve().parents[1] / "examples" / "notebooks"
NAMES = ("exercise", "grading", "numeric")
KERNEL = "armdyn-notebook-test"
#: seconds a single cell may take (each notebook runs in well under 30 s on a quiet machine)
CELL_TIMEOUT = 180


@pytest.fixture(scope="module")
def kernel_env(tmp_path_factory):
    """A kernel spec that runs ``sys.executable`` (whatever ``python3`` the user's Jupyter
    would pick), found through JUPYTER_PATH, with armdyn's directory on PYTHONPATH."""
    prefix = tmp_path_factory.mktemp("jupyter")
    package_root = str(Path(armdyn.__file__).resolve().parents[1])
    path = os.pathsep.join(p for p in (package_root, os.environ.get("PYTHONPATH", "")) if p)
    kernelspec.install(kernel_name=KERNEL, prefix=str(prefix), env={"PYTHONPATH": path})
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("JUPYTER_PATH", str(prefix / "share" / "jupyter"))
        yield sys.executable


def test_notebooks_are_stored_without_outputs():
    for name in NAMES:
        book = nbformat.read(NOTEBOOKS / f"{name}.ipynb", as_version=4)
        nbformat.validate(book)
        code = [c for c in book.cells if c.cell_type == "code"]
        assert code, name
        assert all(not c.outputs and c.execution_count is None for c in code), f"{name}.ipynb has outputs"
        assert "assert" in code[-1].source, f"{name}.ipynb: the last cell checks nothing"


@pytest.mark.parametrize("name", NAMES)
def test_notebook_runs(name, kernel_env):
    book = nbformat.read(NOTEBOOKS / f"{name}.ipynb", as_version=4)
    client = nbclient.NotebookClient(
        book, timeout=CELL_TIMEOUT, kernel_name=KERNEL, resources={"metadata": {"path": str(NOTEBOOKS)}}
    )
    client.execute()  # raises CellExecutionError on the first failing cell
    last = [c for c in book.cells if c.cell_type == "code"][-1]
    printed = "".join(o.get("text", "") for o in last.outputs if o.output_type == "stream")
    assert "all checks passed" in printed, last.outputs
