"""Reading robot models: YAML (general frames or DH tables), DH tables from Python, URDF.

``load(source)`` takes a bundled model's name (``armdyn.load("rp-arm")``; the files
live in ``armdyn/robots/``) or a file path (``.yaml``/``.yml``: :mod:`armdyn.io.yaml`;
``.urdf``: :mod:`armdyn.io.urdf`; ``.xml``: MuJoCo's MJCF, :mod:`armdyn.io.mjcf`; ``.xacro``: :mod:`armdyn.io.xacro`, needs the ``xacro``
package and ``trusted=True``: xacro runs Python code from the file). ``bundled_robots()``
lists the bundled models.

Physical validity: a model file is checked strictly by default (a link whose inertia is
not physical is a :class:`ModelError`). A bundled model is a published one, kept as
published: it loads by default even where its published inertias are not physical
(PUMA 560 and Stanford arm values break the triangle inequality), with one warning
naming its source and each such link; ``load(name, strict=True)`` refuses it.
"""

from __future__ import annotations

import os
import warnings
from pathlib import Path

from ..errors import ModelError
from ..model import Robot
from . import urdf  # registers Robot.from_urdf with armdyn.dispatch

#: Directory of the bundled models.
ROBOTS_DIR = Path(__file__).resolve().parent.parent / "robots"

_SUFFIXES = (".yaml", ".yml", ".urdf", ".xml", ".xacro")


def bundled_files() -> dict[str, Path]:
    """name -> file of each bundled model (a .yaml wins over a .urdf of the same name)."""
    out: dict[str, Path] = {}
    if ROBOTS_DIR.is_dir():
        for suffix in reversed(_SUFFIXES):
            for path in sorted(ROBOTS_DIR.glob(f"*{suffix}")):
                out[path.stem] = path
    return dict(sorted(out.items()))


def _load_file(path: Path, strict: bool, source: str, trusted: bool = False, floating: str | None = None) -> Robot:
    suffix = path.suffix.lower()
    if suffix in (".yaml", ".yml"):
        from .yaml import load_yaml

        return load_yaml(path, strict=strict, source=source)
    if suffix == ".urdf":
        return urdf.load_urdf(path, strict=strict)
    if suffix == ".xml":
        from .mjcf import load_mjcf

        return load_mjcf(path, strict=strict, floating=floating)
    if suffix == ".xacro":
        from .xacro import load_xacro

        return load_xacro(path, strict=strict, trusted=trusted)
    raise ModelError(f"unknown model file type '{suffix}' (expected .yaml, .yml, .urdf, .xml or .xacro)", None, source)


def _published(path: Path) -> Robot:
    """A bundled model as published: links whose published (default) values are not
    physical are accepted, with one warning for the whole model (not one per link, nor
    again for every bound copy)."""
    from ..inertia import physical_violations

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        robot = _load_file(path, False, path.name, trusted=True)
        bound = robot.bind() if robot.defaults else robot
    accepted = []
    for link in bound.links.values():
        mass, inertia = link.floats("mass"), link.floats("inertia")
        problems = physical_violations(
            link.mass if mass is None else mass, link.inertia if inertia is None else inertia
        )
        if problems:
            accepted.append((link.name, "; ".join(problems)))
    if not accepted:
        return robot
    source = " ".join(str(robot.meta.get("source", "")).split())
    source = source if len(source) <= 90 else source[:87] + "..."
    what = "; ".join(f"link '{name}': {problem}" for name, problem in accepted)
    warnings.warn(
        f"{path.stem} as published{f' ({source})' if source else ''} is not physical: {what} "
        f"(loaded anyway; strict=True / --strict refuses it)",
        UserWarning,
        stacklevel=3,
    )
    meta = dict(robot.meta, nonphysical_accepted=tuple(accepted))
    return Robot(
        robot.name,
        robot.links.values(),
        robot.joints,
        robot.gravity,
        robot.parameters,
        meta,
        robot.base,
        robot.defaults,
        strict=False,
        root_joint=robot.root_joint,
    )


def load(
    source: str | os.PathLike[str],
    strict: bool | None = None,
    trusted: bool = False,
    floating: str | None = None,
    root_joint: str | None = None,
) -> Robot:
    """A :class:`~armdyn.Robot` from a bundled model's name or a model file.

    source: a bundled name (see :func:`bundled_robots`, e.g. ``"rp-arm"``, ``"puma560"``)
            or a path (str or PathLike) to a ``.yaml``/``.yml``/``.urdf``/``.xml`` (MJCF) file. A string
            with a path separator or one of those suffixes is always taken as a path; a
            bare bundled name wins over a file of that name in the working directory.
    strict: check each link's physical validity (mass >= 0, inertia PSD, triangle
            inequality); see :class:`armdyn.Robot`. None (default): strict for files;
            a bundled model loads as published with one warning if it is not physical.
            False: warn (per link) instead of raising; True: raise, bundled models too.
    trusted: allow a ``.xacro`` file, which the ``xacro`` package expands by running
            the Python expressions in its ``${...}`` (they can run any command). Off by
            default: a ``.xacro`` file is then a ModelError naming it and this option.
            Pass True only for a file you would run as a program; class grading and
            ``armdyn serve`` never do.
    floating: MJCF only: ``"weld"`` reads a ``free`` joint of a body of the world body as
            a fixed base (see :func:`armdyn.io.mjcf.load_mjcf`); without it that body
            is a floating base, whatever ``root_joint`` says.
    root_joint: None (the model's root link is fixed in the world) or ``"free-flyer"``:
            the root link floats, as Pinocchio's ``buildModelFromUrdf(path,
            JointModelFreeFlyer())`` (any model format; see :class:`armdyn.Robot`'s
            ``floating``, ``nq``, ``nv``, and :mod:`armdyn.numeric` for the arrays).

    Raises ModelError (one line naming the file) for an unknown name, a missing file
    or a bad model.
    """
    robot = _load(source, strict, trusted, floating)
    if root_joint == robot.root_joint or root_joint is None and robot.meta.get("base_pose"):
        return robot  # an MJCF free body floats as written (floating="weld" fixes it)
    return with_root_joint(robot, root_joint)


def with_root_joint(robot: Robot, root_joint: str | None) -> Robot:
    """``robot`` with its root link fixed (``root_joint=None``) or floating
    (``"free-flyer"``); links, joints and parameters unchanged."""
    import warnings

    with warnings.catch_warnings():  # its links were warned about when it was built
        warnings.simplefilter("ignore")
        return Robot(
            robot.name,
            robot.links.values(),
            robot.joints,
            robot.gravity,
            robot.parameters,
            robot.meta,
            robot.base,
            robot.defaults,
            strict=robot.strict,
            root_joint=root_joint,
        )


def _load(source, strict: bool | None, trusted: bool, floating: str | None) -> Robot:
    text = os.fspath(source)
    path = Path(text)
    if floating is not None and path.suffix.lower() != ".xml":
        raise ModelError("floating= applies to MJCF (.xml) files only", None, text)
    looks_like_path = path.suffix.lower() in _SUFFIXES or os.sep in text or "/" in text
    bundled = bundled_files()
    if not looks_like_path and text in bundled:
        if strict is None:
            return _published(bundled[text])
        return _load_file(bundled[text], strict, bundled[text].name, trusted=True)
    strict = True if strict is None else strict
    if looks_like_path or path.is_file():
        if not path.is_file():
            what = "cannot read the model (not a regular file)" if path.exists() else "no such file"
            raise ModelError(what, None, text)
        return _load_file(path, strict, text, trusted, floating)
    names = ", ".join(bundled) or "none"
    raise ModelError(f"unknown robot '{text}': not a file, and not a bundled model ({names})")


def bundled_robots() -> list[dict]:
    """The bundled models, sorted by name: one dict each with ``name``, ``dof``,
    ``convention``, ``description``, ``source`` and ``path`` (plus ``error`` if the
    file does not load, with ``dof`` None)."""
    out = []
    for name, path in bundled_files().items():
        entry: dict[str, object] = {"name": name, "path": os.fspath(path)}
        try:
            robot = _load_file(path, strict=False, source=path.name, trusted=True)
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
