"""Write output files all at once: stage in a temporary file, then rename.

A reader (or a crash) never sees half a file: each output is first written to a hidden
temporary file in the same directory as its destination (so the final ``os.replace`` is
an atomic rename on the same file system), flushed to disk with ``fsync``, given the
permissions a newly created file gets under the current umask (``mkstemp`` makes 0600
files), and only then renamed over the destination. On any error every temporary file
is removed and no destination is touched.
"""

from __future__ import annotations

import os
import tempfile
from collections.abc import Callable, Iterable
from pathlib import Path

Writer = Callable[[str], object]


def _stage(path: Path) -> str:
    """An empty temporary file next to ``path``; it keeps ``path``'s extension, as writers
    such as matplotlib's ``savefig`` choose the format from it."""
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=f".tmp{path.suffix}", dir=path.parent)
    os.close(fd)
    return tmp


def _fsync(path: str) -> None:
    fd = os.open(path, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


def _umask() -> int:
    mask = os.umask(0)  # the only portable way to read it
    os.umask(mask)
    return mask


def atomic_writes(outputs: Iterable[tuple[str | os.PathLike, Writer]]) -> None:
    """Write several files all or nothing: ``writer(tmp)`` writes each output to its
    temporary path ``tmp`` (a ``str`` with the destination's extension); only when every
    writer has returned are the files renamed into place. If a writer raises, its error
    propagates and no destination is created or changed."""
    staged: list[tuple[str, Path]] = []
    try:
        for path, writer in outputs:
            final = Path(os.path.abspath(path))
            tmp = _stage(final)
            staged.append((tmp, final))
            writer(tmp)
            _fsync(tmp)
        mode = 0o666 & ~_umask()
        for tmp, final in staged:
            os.chmod(tmp, mode)
        for tmp, final in staged:
            os.replace(tmp, final)
        for folder in {final.parent for _, final in staged}:
            _fsync_dir(folder)
    finally:
        for tmp, _ in staged:
            if os.path.exists(tmp):
                os.remove(tmp)


def _fsync_dir(folder: Path) -> None:
    """Make the renames durable (where the platform allows a directory to be opened)."""
    try:
        fd = os.open(folder, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


def atomic_write(path: str | os.PathLike, writer: Writer) -> None:
    """Write one file through ``writer(tmp)`` all at once (see :func:`atomic_writes`)."""
    atomic_writes([(path, writer)])


def atomic_write_text(path: str | os.PathLike, text: str, encoding: str = "utf-8") -> None:
    """Write ``text`` to ``path`` all at once."""
    atomic_write(path, lambda tmp: Path(tmp).write_text(text, encoding=encoding))
