"""The repository speaks for itself: no file cites an issue tracker or a design document.

Code, tests, benchmarks and docs say what a number or a check means (the target, the
feature), not which tracker entry asked for it: a reader of the repository has no tracker.
The scan runs over every tracked text file (``git ls-files``) and lists each hit as
``file:line: text``. Paths to optional data beside the repository (``shared/data/``) are
code, not citations, and are not matched.
"""

from __future__ import annotations

import re
import shutil
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]

#: the word issue(s) or ticket(s) followed by a number (with a space, an underscore, a "#" or
#: nothing between them, as in a test named after one) or a design document kept outside the
#: repository
TRACKER_REF = re.compile(r"(?<![A-Za-z])(?:[Ii]ssues?|[Tt]ickets?)[ _]?#?[0-9]+|DESIGN\.md")


def tracker_refs(text: str) -> list[tuple[int, str]]:
    """(1-based line number, stripped line) of every line of ``text`` that cites a tracker."""
    return [(n, line.strip()) for n, line in enumerate(text.splitlines(), 1) if TRACKER_REF.search(line)]


def scan(root: Path) -> list[str]:
    """``path:line: text`` of every tracker reference in the files git tracks under ``root``.

    Binary files (a NUL byte, or not UTF-8) are skipped: they hold no prose."""
    if shutil.which("git") is None:
        pytest.skip("git is not installed: cannot list the tracked files")
    listed = subprocess.run(["git", "ls-files", "-z"], cwd=root, capture_output=True, check=True)
    hits = []
    for name in sorted(p for p in listed.stdout.decode().split("\0") if p):
        path = root / name
        if not path.is_file():  # deleted in the work tree, not yet committed
            continue
        data = path.read_bytes()
        if b"\0" in data:
            continue
        try:
            text = data.decode("utf-8")
        except UnicodeDecodeError:
            continue
        hits += [f"{name}:{n}: {line}" for n, line in tracker_refs(text)]
    return hits


def test_no_tracked_file_cites_an_issue_tracker():
    if not (ROOT / ".git").exists():
        pytest.skip("not a git checkout: no list of tracked files")
    hits = scan(ROOT)
    assert not hits, "references to an issue tracker (say what was meant instead):\n" + "\n".join(hits)


# The synthetic references are built from pieces so that this file does not cite one itself.
CITES = [
    "see " + "issue" + " 8 for the target",
    "(" + "issue" + " 11)",
    "Issues" + " #12 and 13",
    "as the " + "issue" + " 9, fifth part, asks",
    "def test_" + "issue" + "8_op_count():",
    "ticket" + " #7",
    "the design is in " + "DESIGN" + ".md",
]
DOES_NOT_CITE = [
    "an issue with the solver",
    "tissue" + " 3 of the sample",
    "joint #1: name: expected a name",
    "&#10; is a line break",
    "shared/data/iiwa14_dynamics_only.urdf beside the repository",
    "issues of style, not of numbers",
]


@pytest.mark.parametrize("line", CITES)
def test_a_tracker_reference_is_found(line):
    text = "first line\n" + line + "\nlast line\n"
    assert tracker_refs(text) == [(2, line.strip())]


@pytest.mark.parametrize("line", DOES_NOT_CITE)
def test_prose_without_a_number_is_not_a_tracker_reference(line):
    assert tracker_refs(line + "\n") == []


def test_the_scan_fails_on_a_committed_reference(tmp_path):
    """A throwaway repository with one file citing a tracker: the scan names file and line,
    and an untracked file with the same text is not scanned."""
    if shutil.which("git") is None:
        pytest.skip("git is not installed")
    (tmp_path / "notes.md").write_text("# Notes\n\nThe target comes from " + "issue" + " 8.\n")
    (tmp_path / "clean.py").write_text('"""Nothing to see."""\n')
    (tmp_path / "image.bin").write_bytes(b"\0" + ("issue" + " 3").encode())
    subprocess.run(["git", "init", "-q"], cwd=tmp_path, check=True)
    subprocess.run(["git", "add", "notes.md", "clean.py", "image.bin"], cwd=tmp_path, check=True)
    (tmp_path / "untracked.md").write_text("issue" + " 9\n")
    assert scan(tmp_path) == ["notes.md:3: The target comes from " + "issue" + " 8."]
