"""Write output files all at once: stage in a temporary file, then rename.

A reader (or a crash) never sees half a file: each output is first written to a hidden
temporary file in the same directory as its destination (so the final ``os.replace`` is
an atomic rename on the same file system), flushed to disk with ``fsync``, given the
permissions a newly created file gets under the current umask (``mkstemp`` makes 0600
files), and only then renamed over the destination. On any error every temporary file
is removed and no destination is touched.

What a destination may be (checked before anything is written, by :func:`destination`):

* a path that does not exist yet, in an existing directory: a new file with the umask's
  permissions;
* an existing regular file that the user may write and that has a write permission bit:
  replaced, keeping its permission bits; a file marked read-only is refused, also for
  root, who could otherwise replace it;
* a symbolic link: followed, the rules above apply to its final target, which is then
  replaced (the link stays a link); a link to nothing is refused;
* anything else (directory, device node, FIFO, socket) and an empty path: refused with
  :class:`OutputPathError`, one line naming the path.

The check and the rename are two steps: a destination swapped in between by someone
who can write the directory is not defended against.
"""

from __future__ import annotations

import os
import stat
import tempfile
from collections.abc import Callable, Iterable
from pathlib import Path

Writer = Callable[[str], object]


class OutputPathError(ValueError):
    """An output path armdyn will not write: one line naming the path and why."""


_KINDS = (
    (stat.S_ISDIR, "a directory"),
    (stat.S_ISCHR, "a character device"),
    (stat.S_ISBLK, "a block device"),
    (stat.S_ISFIFO, "a FIFO"),
    (stat.S_ISSOCK, "a socket"),
)


def destination(path: str | os.PathLike) -> tuple[Path, int | None]:
    """``(file to replace or create, its permission bits or None for a new file)`` for the
    output ``path``, following a symbolic link to its target; raises
    :class:`OutputPathError` for a path armdyn refuses (see the module's docstring)."""
    shown = os.fspath(path)
    if isinstance(shown, bytes):
        shown = os.fsdecode(shown)
    if not shown:
        raise OutputPathError("output path is empty")
    final = Path(os.path.abspath(shown))
    try:
        st = os.lstat(final)
    except FileNotFoundError:
        st = None
    except OSError as exc:
        raise OutputPathError(f"{shown}: cannot inspect the output path ({exc.strerror})") from None
    if st is not None and stat.S_ISLNK(st.st_mode):
        final = Path(os.path.realpath(final))
        try:
            st = os.stat(final)
        except OSError as exc:
            raise OutputPathError(
                f"{shown}: a symbolic link whose target {final} cannot be written ({exc.strerror}); not followed"
            ) from None
    if st is not None:
        kind = next((name for test, name in _KINDS if test(st.st_mode)), None)
        if kind or not stat.S_ISREG(st.st_mode):
            raise OutputPathError(f"{shown}: is {kind or 'not a regular file'}; armdyn writes only regular files")
        if not st.st_mode & 0o222 or not os.access(final, os.W_OK):
            raise OutputPathError(f"{shown}: the file is read-only; not replaced")
    if not final.parent.is_dir():
        raise OutputPathError(f"{shown}: directory {final.parent} does not exist")
    return final, (stat.S_IMODE(st.st_mode) if st is not None else None)


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
    propagates and no destination is created or changed. A destination armdyn refuses
    (:func:`destination`) raises :class:`OutputPathError` before any writer runs."""
    outputs = list(outputs)
    checked = [destination(path) for path, _ in outputs]  # every one before any is written
    staged: list[tuple[str, Path]] = []
    try:
        new_mode = 0o666 & ~_umask()
        modes = []
        for (final, mode), (_, writer) in zip(checked, outputs):
            tmp = _stage(final)
            staged.append((tmp, final))
            modes.append(new_mode if mode is None else mode)
            writer(tmp)
            _fsync(tmp)
        for (tmp, final), mode in zip(staged, modes):
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
