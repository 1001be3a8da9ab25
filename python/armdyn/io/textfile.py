"""The one bounded reader of text files armdyn is given: submissions, rosters, rubrics,
YAML and URDF models.

A file is opened without blocking (a FIFO named as a submission cannot hang the
reader), must be a regular file (``/dev/zero`` or a FIFO is refused, not read forever),
is read up to ``max_bytes + 1`` bytes whatever its size claims (a file growing while
it is read cannot exceed the limit) and decoded strictly. Every failure is one
:class:`~armdyn.errors.ModelError` naming the file (and the line of a bad byte).
"""

from __future__ import annotations

import os
import stat

from ..errors import ModelError

__all__ = ["read_bytes", "read_text", "MODEL_MAX_BYTES"]

#: a model file larger than this is refused (a 10^4-joint URDF is about 6 MB)
MODEL_MAX_BYTES = 64_000_000


def read_bytes(path, what: str, max_bytes: int, name: str | None = None) -> bytes:
    """The bytes of the regular file ``path``, at most ``max_bytes``; else a ModelError
    naming ``what`` (``"submission"``, ``"roster"``, ...) and the file (as ``name``,
    default ``path``)."""
    path = os.fspath(path)
    name = name or path
    try:
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_CLOEXEC", 0))
    except FileNotFoundError:
        raise ModelError("no such file", source=name) from None
    except OSError as exc:
        raise ModelError(f"cannot read the {what} ({exc.strerror})", source=name) from None
    with os.fdopen(fd, "rb") as fh:
        if not stat.S_ISREG(os.fstat(fd).st_mode):
            raise ModelError(f"cannot read the {what} (not a regular file)", source=name)
        try:
            raw = fh.read(max_bytes + 1)
        except OSError as exc:
            raise ModelError(f"cannot read the {what} ({exc.strerror})", source=name) from None
    if len(raw) > max_bytes:
        raise ModelError(f"{what} larger than {max_bytes} bytes", source=name)
    return raw


def read_text(path, what: str, max_bytes: int, encoding: str = "utf-8", name: str | None = None) -> str:
    """The text of the regular file ``path`` (:func:`read_bytes`) decoded as ``encoding``;
    a byte that is not is a ModelError naming ``name:line`` (``name``: default ``path``)."""
    name = name or os.fspath(path)
    raw = read_bytes(path, what, max_bytes, name)
    try:
        return raw.decode(encoding)
    except UnicodeDecodeError as exc:
        line = raw[: exc.start].count(b"\n") + 1
        raise ModelError(f"not UTF-8 text (byte {exc.start + 1})", source=f"{name}:{line}") from None
