"""Reading an instructor's small text files (roster, rubric): bounded in size, errors
naming ``file`` or ``file:line``."""

from __future__ import annotations

import os

from ..errors import ModelError


def read_text(path, what: str, max_bytes: int, encoding: str = "utf-8") -> tuple[str, str]:
    """``(path, text)`` of the file at ``path``; :class:`ModelError` when it cannot be read,
    is larger than ``max_bytes`` or is not text in ``encoding`` (naming the line)."""
    path = os.fspath(path)
    try:
        with open(path, "rb") as fh:
            raw = fh.read(max_bytes + 1)
    except OSError as exc:
        raise ModelError(f"cannot read the {what} ({exc.strerror})", source=path) from None
    if len(raw) > max_bytes:
        raise ModelError(f"{what} larger than {max_bytes} bytes", source=path)
    try:
        return path, raw.decode(encoding)
    except UnicodeDecodeError as exc:
        line = raw[: exc.start].count(b"\n") + 1
        raise ModelError("not UTF-8 text", source=f"{path}:{line}") from None
