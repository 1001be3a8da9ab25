"""armdyn._io_atomic: outputs appear whole or not at all, with the permissions a new file
gets under the umask, and no temporary file is left behind."""

from __future__ import annotations

import os
import stat

import pytest

from armdyn._io_atomic import OutputPathError, atomic_write, atomic_write_text, atomic_writes


def _mode(path):
    return stat.S_IMODE(os.stat(path).st_mode)


def test_writes_whole_file_with_umask_permissions(tmp_path):
    old = os.umask(0o027)
    try:
        atomic_write_text(tmp_path / "a.html", "<p>\u0394</p>")
        plain = tmp_path / "plain.txt"
        with open(plain, "w"):  # what open() gives under the same umask: the reference
            pass
    finally:
        os.umask(old)
    assert (tmp_path / "a.html").read_text(encoding="utf-8") == "<p>\u0394</p>"
    assert _mode(tmp_path / "a.html") == _mode(plain) == 0o640
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.html", "plain.txt"]


def test_temporary_keeps_extension_and_folder(tmp_path):
    seen = []

    def writer(tmp):
        seen.append(tmp)
        with open(tmp, "wb") as f:
            f.write(b"GIF89a")

    atomic_write(tmp_path / "run.gif", writer)
    assert len(seen) == 1
    assert os.path.dirname(seen[0]) == str(tmp_path) and seen[0].endswith(".gif")
    assert (tmp_path / "run.gif").read_bytes() == b"GIF89a"
    assert [p.name for p in tmp_path.iterdir()] == ["run.gif"]


def test_error_leaves_old_file_and_no_temporary(tmp_path):
    target = tmp_path / "report.html"
    target.write_text("old")

    def failing(tmp):
        with open(tmp, "w") as f:
            f.write("half a pa")
        raise RuntimeError("writer broke")

    with pytest.raises(RuntimeError, match="writer broke"):
        atomic_write(target, failing)
    assert target.read_text() == "old"
    assert [p.name for p in tmp_path.iterdir()] == ["report.html"]


def test_several_outputs_all_or_nothing(tmp_path):
    def ok(tmp):
        with open(tmp, "w") as f:
            f.write("plot")

    def bad(tmp):
        raise ValueError("animation failed")

    with pytest.raises(ValueError, match="animation failed"):
        atomic_writes([(tmp_path / "run.png", ok), (tmp_path / "run.gif", bad)])
    assert list(tmp_path.iterdir()) == []  # the first, finished, output was not put in place either
    atomic_writes([(tmp_path / "run.png", ok), (tmp_path / "run.gif", ok)])
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run.gif", "run.png"]


def test_missing_folder_is_refused_naming_it(tmp_path):
    with pytest.raises(OutputPathError, match="nope.* does not exist"):
        atomic_write_text(tmp_path / "nope" / "r.html", "x")
    assert list(tmp_path.iterdir()) == []
