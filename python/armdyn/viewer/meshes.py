"""Triangle meshes from the files a URDF ``<mesh filename>`` names: STL (binary and
ASCII), Wavefront OBJ and COLLADA (``.dae``).

``read_mesh(path)`` returns ``(vertices (n, 3) float32, triangles (m, 3) uint32)`` in
the file's own units (metres for URDF; ``<mesh scale>`` is applied by the viewer), with a
COLLADA file's ``<unit meter>``, ``<up_axis>`` and node transforms applied (what its
authors see). Every file is read through :func:`armdyn.io.textfile.read_bytes`: a
regular file of at most :data:`MESH_MAX_BYTES`; a mesh of more than
:data:`MAX_TRIANGLES` triangles is refused. Every problem is a :class:`ModelError`
naming the file. COLLADA is parsed as XML with no DTD (the URDF reader's rule), and
only its geometry is read (no materials, textures, animations or skins).
"""

from __future__ import annotations

import struct
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

from ..errors import ModelError
from ..io.textfile import read_bytes

__all__ = ["read_mesh", "MESH_MAX_BYTES", "MAX_TRIANGLES", "MESH_SUFFIXES"]

#: a mesh file larger than this is refused
MESH_MAX_BYTES = 64_000_000
#: a mesh with more triangles than this is refused (a browser draws it, but the page grows to ~30 MB)
MAX_TRIANGLES = 1_500_000
MESH_SUFFIXES = (".stl", ".obj", ".dae")


def read_mesh(path) -> tuple[np.ndarray, np.ndarray]:
    """Vertices (n, 3) and triangles (m, 3) of the mesh file ``path`` (see the module docstring)."""
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in MESH_SUFFIXES:
        raise ModelError(f"mesh format {suffix or '(none)'} is not read (STL, OBJ and DAE are)", source=str(path))
    raw = read_bytes(path, "mesh", MESH_MAX_BYTES)
    try:
        if suffix == ".stl":
            v, t = _stl(raw)
        elif suffix == ".obj":
            v, t = _obj(raw)
        else:
            v, t = _dae(raw)
    except ModelError as err:
        raise err.located(source=str(path)) from None
    except (ValueError, IndexError, struct.error) as err:
        raise ModelError(f"malformed mesh: {err}", source=str(path)) from None
    if len(t) > MAX_TRIANGLES:
        raise ModelError(f"mesh has {len(t)} triangles, more than {MAX_TRIANGLES}", source=str(path))
    if len(t) and (t.max() >= len(v)):
        raise ModelError("a triangle refers to a vertex that does not exist", source=str(path))
    if not np.all(np.isfinite(v)):
        raise ModelError("mesh has NaN or infinite coordinates", source=str(path))
    return v.astype(np.float32), t.astype(np.uint32)


# ------------------------------------------------------------------------ STL


def _stl(raw: bytes) -> tuple[np.ndarray, np.ndarray]:
    # binary: 80-byte header, uint32 count, 50 bytes a triangle (an ASCII file may start with "solid" too)
    if len(raw) >= 84:
        count = struct.unpack_from("<I", raw, 80)[0]
        if len(raw) == 84 + 50 * count:
            if count > MAX_TRIANGLES:
                raise ModelError(f"mesh has {count} triangles, more than {MAX_TRIANGLES}")
            rec = np.frombuffer(raw, dtype=np.dtype([("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")]), offset=84)
            return _soup(rec["v"].reshape(-1, 3))
    text = raw.decode("ascii", errors="strict") if raw[:5].lower() == b"solid" else None
    if text is None:
        raise ModelError("neither binary STL (size does not match its triangle count) nor ASCII STL")
    points = [line.split()[1:4] for line in text.splitlines() if line.strip().lower().startswith("vertex")]
    if len(points) % 3:
        raise ModelError("ASCII STL: the number of vertices is not a multiple of 3")
    return _soup(np.array(points, dtype=float).reshape(-1, 3))


def _soup(points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Separate triangles (every 3 points one) as shared vertices and indices."""
    v, inverse = np.unique(np.asarray(points, dtype=np.float32), axis=0, return_inverse=True)
    return v, inverse.reshape(-1, 3)


# ------------------------------------------------------------------------ OBJ


def _obj(raw: bytes) -> tuple[np.ndarray, np.ndarray]:
    vertices: list[list[float]] = []
    faces: list[list[int]] = []
    for number, line in enumerate(raw.decode("utf-8", errors="replace").splitlines(), 1):
        parts = line.split()
        if not parts:
            continue
        if parts[0] == "v":
            vertices.append([float(x) for x in parts[1:4]])
        elif parts[0] == "f":
            try:  # "f 1/2/3 4//6 -1": the vertex index is before the first slash; negative counts back
                idx = [int(p.split("/")[0]) for p in parts[1:]]
            except ValueError:
                raise ModelError(f"line {number}: bad face") from None
            idx = [i - 1 if i > 0 else len(vertices) + i for i in idx]
            faces += [[idx[0], idx[k], idx[k + 1]] for k in range(1, len(idx) - 1)]  # a polygon as a fan
            if len(faces) > MAX_TRIANGLES:
                raise ModelError(f"mesh has more than {MAX_TRIANGLES} triangles")
    t = np.array(faces, dtype=np.int64).reshape(-1, 3)
    if len(t) and t.min() < 0:
        raise ModelError("a face refers to a vertex that does not exist")
    return np.array(vertices, dtype=float).reshape(-1, 3), t


# ---------------------------------------------------------------------- COLLADA


def _local(tag: str) -> str:
    return tag.rsplit("}", 1)[-1]


def _dae(raw: bytes) -> tuple[np.ndarray, np.ndarray]:
    from ..io.urdf import refuse_dtd

    refuse_dtd(raw, "COLLADA")
    try:
        root = ET.fromstring(raw)
    except ET.ParseError as err:
        raise ModelError(f"malformed XML: {str(err).split(':')[0]}", f"line {err.position[0]}") from None
    for e in root.iter():  # namespaces off: COLLADA 1.4 and 1.5 name the same elements
        e.tag = _local(e.tag)
    ids = {e.get("id"): e for e in root.iter() if e.get("id")}
    geometries = {g.get("id"): _dae_geometry(g, ids) for g in root.iter("geometry")}
    placed: list[tuple[np.ndarray, np.ndarray]] = []
    scene = root.find("library_visual_scenes/visual_scene")
    if scene is None:  # no scene: every geometry where it is
        placed = [(v, t) for v, t in geometries.values()]
    else:
        for node in scene.findall("node"):
            _dae_node(node, np.eye(4), geometries, ids, placed, depth=0)
    unit = root.find("asset/unit")
    scale = float(unit.get("meter", "1")) if unit is not None else 1.0
    up = (root.findtext("asset/up_axis") or "Z_UP").strip().upper()
    turn = {"Y_UP": np.array([[1, 0, 0], [0, 0, -1], [0, 1, 0]]), "X_UP": np.array([[0, -1, 0], [1, 0, 0], [0, 0, 1]])}
    R = turn.get(up, np.eye(3)) * scale
    vertices, triangles, offset = [], [], 0
    for v, t in placed:
        vertices.append(v @ R.T)
        triangles.append(t + offset)
        offset += len(v)
    if not vertices:
        return np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64)
    return np.vstack(vertices), np.vstack(triangles)


def _dae_node(node, parent: np.ndarray, geometries: dict, ids: dict, placed: list, depth: int) -> None:
    if depth > 64:
        raise ModelError("COLLADA nodes nested more than 64 deep")
    T = parent @ _dae_transform(node)
    for inst in node.findall("instance_geometry"):
        g = geometries.get(inst.get("url", "").lstrip("#"))
        if g is not None:
            v, t = g
            placed.append((v @ T[:3, :3].T + T[:3, 3], t))
    for inst in node.findall("instance_node"):  # a node of library_nodes placed here
        target = ids.get(inst.get("url", "").lstrip("#"))
        if target is not None and target.tag == "node":
            _dae_node(target, T, geometries, ids, placed, depth + 1)
    for child in node.findall("node"):
        _dae_node(child, T, geometries, ids, placed, depth + 1)


def _dae_transform(node) -> np.ndarray:
    T = np.eye(4)
    for e in node:
        values = [float(x) for x in (e.text or "").split()]
        M = np.eye(4)
        if e.tag == "matrix" and len(values) == 16:
            M = np.array(values).reshape(4, 4)
        elif e.tag == "translate" and len(values) == 3:
            M[:3, 3] = values
        elif e.tag == "scale" and len(values) == 3:
            M[:3, :3] = np.diag(values)
        elif e.tag == "rotate" and len(values) == 4:
            M[:3, :3] = _axis_angle(np.array(values[:3]), np.radians(values[3]))
        else:
            continue
        T = T @ M
    return T


def _axis_angle(axis: np.ndarray, angle: float) -> np.ndarray:
    n = np.linalg.norm(axis)
    if n == 0:
        return np.eye(3)
    x, y, z = axis / n
    K = np.array([[0, -z, y], [z, 0, -x], [-y, x, 0]])
    return np.eye(3) + np.sin(angle) * K + (1 - np.cos(angle)) * K @ K


def _dae_floats(source) -> np.ndarray:
    arr = source.find("float_array")
    if arr is None:
        raise ModelError(f"source '{source.get('id')}' has no <float_array>")
    accessor = source.find("technique_common/accessor")
    stride = int((accessor if accessor is not None else source).get("stride", "3"))
    values = np.array((arr.text or "").split(), dtype=float)
    return values[: len(values) // stride * stride].reshape(-1, stride)[:, :3]


def _dae_geometry(geometry, ids: dict) -> tuple[np.ndarray, np.ndarray]:
    mesh = geometry.find("mesh")
    if mesh is None:
        return np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64)
    positions = None
    vertices = mesh.find("vertices")
    if vertices is not None:
        for inp in vertices.findall("input"):
            if inp.get("semantic") == "POSITION":
                positions = _dae_floats(ids[inp.get("source", "").lstrip("#")])
    if positions is None:
        raise ModelError(f"geometry '{geometry.get('id')}' has no vertex positions")
    tris = []
    for prim in list(mesh):
        if prim.tag not in ("triangles", "polylist", "polygons"):
            continue  # lines, linestrips: nothing to draw as a surface
        inputs = prim.findall("input")
        stride = max(int(i.get("offset", "0")) for i in inputs) + 1
        at = next(int(i.get("offset", "0")) for i in inputs if i.get("semantic") == "VERTEX")
        blocks = [p.text or "" for p in prim.findall("p")]
        if prim.tag == "polygons":  # one <p> a polygon
            counts = None
            index = [np.array(b.split(), dtype=np.int64)[at::stride] for b in blocks]
        else:
            flat = np.array(" ".join(blocks).split(), dtype=np.int64)[at::stride]
            counts = (
                np.array((prim.findtext("vcount") or "").split(), dtype=np.int64) if prim.tag == "polylist" else None
            )
            if counts is None:
                tris.append(flat[: len(flat) // 3 * 3].reshape(-1, 3))
                continue
            if len(counts) and np.all(counts == 3):
                tris.append(flat[: 3 * len(counts)].reshape(-1, 3))
                continue
            index = np.split(flat, np.cumsum(counts)[:-1])
        for poly in index:  # a polygon as a fan
            tris += [np.array([[poly[0], poly[k], poly[k + 1]]]) for k in range(1, len(poly) - 1)]
    t = np.vstack(tris) if tris else np.zeros((0, 3), dtype=np.int64)
    return positions, t
