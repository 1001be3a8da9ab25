"""Reading robot models: YAML (general frames or DH tables), DH tables from Python, URDF.

``load(source)`` takes a bundled model's name (``armdyn.load("rp-arm")``; the files
live in ``armdyn/robots/``) or a file path (``.yaml``/``.yml``: :mod:`armdyn.io.yaml`;
``.urdf``: :mod:`armdyn.io.urdf`). ``bundled_robots()`` lists the bundled models.
"""

from __future__ import annotations

import os
from pathlib import Path

from ..errors import ModelError
from ..model import Robot

#: Directory of the bundled models.
ROBOTS_DIR = Path(__file__).resolve().parent.parent / "robots"

_SUFFIXES = (".yaml", ".yml", ".urdf")


def _bundled_files() -> dict[str, Path]:
    """name -> file of each bundled model (a .yaml wins over a .urdf of the same name)."""
    out: dict[str, Path] = {}
    if ROBOTS_DIR.is_dir():
        for suffix in reversed(_SUFFIXES):
            for path in sorted(ROBOTS_DIR.glob(f"*{suffix}")):
                out[path.stem] = path
    return dict(sorted(out.items()))


def _load_file(path: Path, strict: bool, source: str) -> Robot:
    suffix = path.suffix.lower()
    if suffix in (".yaml", ".yml"):
        from .yaml import load_yaml

        return load_yaml(path, strict=strict, source=source)
    if suffix == ".urdf":
        try:
            from .urdf import load_urdf
        except ImportError:
            raise ModelError("URDF support not available", None, source) from None
        return load_urdf(path, strict=strict)
    raise ModelError(f"unknown model file type '{suffix}' (expected .yaml, .yml or .urdf)", None, source)


def load(source: str | os.PathLike[str], strict: bool = True) -> Robot:
    """A :class:`~armdyn.Robot` from a bundled model's name or a model file.

    source: a bundled name (see :func:`bundled_robots`, e.g. ``"rp-arm"``, ``"puma560"``)
            or a path (str or PathLike) to a ``.yaml``/``.yml``/``.urdf`` file. A string
            with a path separator or one of those suffixes is always taken as a path; a
            bare bundled name wins over a file of that name in the working directory.
    strict: check each link's physical validity (mass >= 0, inertia PSD, triangle
            inequality); see :class:`armdyn.Robot`.

    Raises ModelError (one line naming the file) for an unknown name, a missing file
    or a bad model.
    """
    text = os.fspath(source)
    path = Path(text)
    looks_like_path = path.suffix.lower() in _SUFFIXES or os.sep in text or "/" in text
    bundled = _bundled_files()
    if not looks_like_path and text in bundled:
        return _load_file(bundled[text], strict, bundled[text].name)
    if looks_like_path or path.is_file():
        if not path.is_file():
            raise ModelError("no such file", None, text)
        return _load_file(path, strict, text)
    names = ", ".join(bundled) or "none"
    raise ModelError(f"unknown robot '{text}': not a file, and not a bundled model ({names})")


def bundled_robots() -> list[dict]:
    """The bundled models, sorted by name: one dict each with ``name``, ``dof``,
    ``convention``, ``description``, ``source`` and ``path`` (plus ``error`` if the
    file does not load, with ``dof`` None)."""
    out = []
    for name, path in _bundled_files().items():
        entry: dict[str, object] = {"name": name, "path": os.fspath(path)}
        try:
            robot = _load_file(path, strict=False, source=path.name)
        except ModelError as err:
            entry.update(dof=None, convention=None, description="", source="", error=str(err))
        else:
            entry.update(
                dof=robot.dof,
                convention=robot.meta.get("convention", "urdf" if path.suffix == ".urdf" else None),
                description=robot.meta.get("description") or f"{robot.name} ({path.suffix[1:].upper()} file)",
                source=robot.meta.get("source", ""),
            )
        out.append(entry)
    return out


__all__ = ["load", "bundled_robots", "ROBOTS_DIR"]
