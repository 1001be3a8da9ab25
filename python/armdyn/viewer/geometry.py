"""The shapes the viewer draws for each link: a URDF's ``<visual>`` geometry.

``urdf_visuals(robot, package_dirs=())`` reads the URDF file the robot came from
(``robot.meta["file"]``) again and returns ``(visuals, meshes)``:

* ``visuals``: link name -> list of dicts, each ``{"shape": "box" | "cylinder" |
  "sphere" | "mesh", "pose": [x, y, z, qx, qy, qz, qw]`` (the ``<visual><origin>`` in
  the link frame) and the shape's sizes (``size``; ``radius``, ``length``; ``mesh``
  (index into ``meshes``), ``scale``), ``"rgba"`` when the visual names a colour;
* ``meshes``: list of ``(vertices (n, 3) float32, triangles (m, 3) uint32)``, each file
  read once (:func:`armdyn.viewer.meshes.read_mesh`).

Mesh paths: ``package://NAME/rest`` is looked up in ``package_dirs`` (folders holding
package ``NAME`` as a sub-folder, or named ``NAME``), then in ``ROS_PACKAGE_PATH``, then
in the folders above the URDF (a folder named ``NAME``, or holding one). ``rest`` must
stay inside the package folder. A plain or ``file://`` path is relative to the URDF's
folder and must stay inside it (an absolute path or ``..`` out of it is refused). A mesh
that cannot be found, is refused or cannot be read becomes the simple shape of its link
(the viewer's capsule) with one :class:`MeshWarning` naming it and why.
"""

from __future__ import annotations

import os
import warnings
from pathlib import Path

import numpy as np

from ..errors import ModelError

__all__ = ["urdf_visuals", "resolve_mesh", "quaternion", "quaternions", "MeshWarning"]


class MeshWarning(UserWarning):
    """A mesh of the model is not drawn (not found, refused or unreadable); its link gets a simple shape."""


def quaternions(R: np.ndarray) -> np.ndarray:
    """Unit quaternions ``[x, y, z, w]`` (..., 4), ``w >= 0``, of the rotation matrices
    ``R`` (..., 3, 3) (Shepperd's method: each from the largest of its four squares, for
    accuracy)."""
    R = np.asarray(R, dtype=float)
    shape = R.shape[:-2]
    R = R.reshape(-1, 3, 3)
    d = np.stack([np.trace(R, axis1=1, axis2=2), R[:, 0, 0], R[:, 1, 1], R[:, 2, 2]], axis=1)
    k = np.argmax(d, axis=1)
    q = np.empty((len(R), 4))
    for case in range(4):
        m = R[k == case]
        if case == 0:
            s = 2 * np.sqrt(np.maximum(1 + d[k == 0, 0], 0))
            q[k == 0] = np.stack(
                [(m[:, 2, 1] - m[:, 1, 2]) / s, (m[:, 0, 2] - m[:, 2, 0]) / s, (m[:, 1, 0] - m[:, 0, 1]) / s, s / 4], 1
            )
            continue
        i, j, n = case - 1, case % 3, (case + 1) % 3
        s = 2 * np.sqrt(np.maximum(1 + m[:, i, i] - m[:, j, j] - m[:, n, n], 0))
        part = np.empty((len(m), 4))
        part[:, i], part[:, j], part[:, n] = s / 4, (m[:, j, i] + m[:, i, j]) / s, (m[:, n, i] + m[:, i, n]) / s
        part[:, 3] = (m[:, n, j] - m[:, j, n]) / s
        q[k == case] = part
    q *= np.where(q[:, 3:] < 0, -1.0, 1.0)
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    return q.reshape(*shape, 4)


def quaternion(R: np.ndarray) -> list[float]:
    """The unit quaternion ``[x, y, z, w]`` of one rotation matrix (see :func:`quaternions`)."""
    return quaternions(R).tolist()


def _package_roots(name: str, urdf_dir: Path, package_dirs) -> list[Path]:
    roots = []
    env = [p for p in os.environ.get("ROS_PACKAGE_PATH", "").split(os.pathsep) if p]
    for folder in [*map(Path, package_dirs), *map(Path, env)]:
        roots += [folder / name, folder] if folder.name == name else [folder / name]
    for up in [urdf_dir, *urdf_dir.parents]:
        roots += [up] if up.name == name else [up / name]
    return [r for r in roots if r.is_dir()]


def resolve_mesh(filename: str, urdf_dir: Path, package_dirs=()) -> Path:
    """The file a ``<mesh filename>`` names (see the module docstring), or a
    ModelError saying why it is not taken."""
    if filename.startswith("package://"):
        name, _, rest = filename[len("package://") :].partition("/")
        if not name or not rest:
            raise ModelError(f"'{filename}' names no package and file")
        roots = _package_roots(name, urdf_dir, package_dirs)
        if not roots:
            raise ModelError(f"package '{name}' not found (give package_dirs= or set ROS_PACKAGE_PATH)")
        for root in roots:
            path = (root / rest).resolve()
            if not path.is_relative_to(root.resolve()):
                raise ModelError(f"'{filename}' leaves its package folder")
            if path.is_file():
                return path
        raise ModelError(f"'{rest}' not found in package '{name}' ({', '.join(str(r) for r in roots[:3])})")
    if "://" in filename and not filename.startswith("file://"):
        raise ModelError(f"'{filename}': only package:// and paths next to the URDF are read")
    plain = filename[len("file://") :] if filename.startswith("file://") else filename
    if os.path.isabs(plain):
        raise ModelError(f"'{filename}' is an absolute path: only paths inside the model's folder are read")
    path = (urdf_dir / plain).resolve()
    if not path.is_relative_to(urdf_dir.resolve()):
        raise ModelError(f"'{filename}' is outside the model's folder")
    if not path.is_file():
        raise ModelError(f"'{filename}' not found next to the model")
    return path


def _floats(text: str | None, count: int, default: list[float], where: str) -> list[float]:
    from ..io.urdf import parse_numbers

    return default if text is None else parse_numbers(text, count, where.split(":")[0], where)


def _pose(visual, where: str) -> list[float]:
    from ..io.urdf import rpy_floats

    origin = visual.find("origin")
    xyz = _floats(None if origin is None else origin.get("xyz"), 3, [0.0] * 3, f"<origin> xyz: {where}")
    rpy = _floats(None if origin is None else origin.get("rpy"), 3, [0.0] * 3, f"<origin> rpy: {where}")
    return [*xyz, *quaternion(rpy_floats(*rpy))]


def _colours(root) -> dict[str, list[float]]:
    """The robot-level ``<material name><color rgba>`` definitions."""
    out = {}
    for m in root.findall("material"):
        c = m.find("color")
        if m.get("name") and c is not None and c.get("rgba"):
            try:
                out[m.get("name")] = _floats(c.get("rgba"), 4, [], f"<color> rgba: material '{m.get('name')}'")
            except ModelError:
                continue  # a colour is decoration: a bad one is left out, not an error
    return out


def urdf_visuals(robot, package_dirs=()) -> tuple[dict[str, list[dict]], list[tuple[np.ndarray, np.ndarray]]]:
    """``(visuals, meshes)`` of the URDF ``robot`` came from (see the module docstring);
    empty for a model that is not a URDF file."""
    file = robot.meta.get("file")
    if robot.meta.get("convention") != "urdf" or not file:
        return {}, []
    from ..io.textfile import MODEL_MAX_BYTES, read_bytes
    from ..io.urdf import parse_xml
    from .meshes import read_mesh

    if str(file).lower().endswith(".xacro"):  # its visuals hold macros only xacro expands (and runs)
        warnings.warn(MeshWarning(f"{file}: visual geometry of a .xacro model is not drawn (expand it first)"), 2)
        return {}, []
    urdf_dir = Path(file).resolve().parent
    try:  # read again: moved or changed since loading is one warning, the arm still drawn
        root = parse_xml(read_bytes(file, "model", MODEL_MAX_BYTES))
    except ModelError as err:
        warnings.warn(MeshWarning(f"{file}: visual geometry not read: {err}"), stacklevel=2)
        return {}, []
    colours = _colours(root)
    visuals: dict[str, list[dict]] = {}
    meshes: list = []
    index: dict[Path, int] = {}
    for link in root.findall("link"):
        name = link.get("name", "").strip()
        if name not in robot.links:
            continue
        for visual in link.findall("visual"):
            where = f"link '{name}' <visual>"
            geometry = visual.find("geometry")
            shape = None if geometry is None or len(geometry) == 0 else geometry[0]
            if shape is None:
                continue
            try:
                item = {"pose": _pose(visual, where)}
                if shape.tag == "box":
                    item.update(shape="box", size=_floats(shape.get("size"), 3, [0.0] * 3, f"<box> size: {where}"))
                elif shape.tag in ("cylinder", "sphere"):
                    item.update(shape=shape.tag, radius=_floats(shape.get("radius"), 1, [0.0], f"radius: {where}")[0])
                    if shape.tag == "cylinder":
                        item["length"] = _floats(shape.get("length"), 1, [0.0], f"length: {where}")[0]
                elif shape.tag == "mesh":
                    path = resolve_mesh(shape.get("filename", ""), urdf_dir, package_dirs)
                    if path not in index:
                        index[path] = len(meshes)
                        meshes.append(read_mesh(path))
                    scale = _floats(shape.get("scale"), 3, [1.0] * 3, f"<mesh> scale: {where}")
                    item.update(shape="mesh", mesh=index[path], scale=scale)
                else:
                    continue  # <capsule> and others URDF 1.0 lacks: the link keeps its simple shape
            except ModelError as err:
                what = shape.get("filename", shape.tag)
                warnings.warn(MeshWarning(f"{file}: {where}: {what} not drawn: {err}"), stacklevel=2)
                continue
            material = visual.find("material")
            if material is not None:
                colour = material.find("color")
                rgba = colours.get(material.get("name", ""))
                if colour is not None and colour.get("rgba"):
                    try:
                        rgba = _floats(colour.get("rgba"), 4, [], f"<color> rgba: {where}")
                    except ModelError:
                        pass  # decoration: the default colour
                if rgba is not None:
                    item["rgba"] = [min(max(c, 0.0), 1.0) for c in rgba]
            visuals.setdefault(name, []).append(item)
    return visuals, meshes
