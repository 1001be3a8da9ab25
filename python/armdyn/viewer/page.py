"""The page: the view's JSON, the vendored three.js and armdyn's viewer script in one
self-contained HTML document (what is drawn and how: the package docstring)."""

from __future__ import annotations

import base64
import json
import re
from functools import lru_cache
from importlib import resources

import numpy as np

from ..mathml import escape
from ..model import Robot
from .geometry import quaternions, urdf_visuals

#: most frames an animation keeps
MAX_FRAMES = 500
#: the page may run its own inline script and style, and load or send nothing
CSP = (
    "default-src 'none'; script-src 'unsafe-inline'; style-src 'unsafe-inline'; img-src data:; "
    "base-uri 'none'; form-action 'none'"
)

_STYLE = """
html, body { margin:0; height:100%; font:14px/1.4 "Segoe UI","Helvetica Neue","Liberation Sans",Arial,sans-serif;
  color:#1f2328; background:#fff; }
body { display:flex; flex-direction:column; }
header { display:flex; gap:14px; align-items:center; padding:6px 12px; border-bottom:1px solid #d1d9e0; }
header h1 { font-size:15px; font-weight:600; margin:0; }
header input[type=range] { flex:1; }
#armdyn-time { font-variant-numeric:tabular-nums; min-width:9em; }
#armdyn-view { flex:1; min-height:300px; touch-action:none; cursor:grab; }
"""


class View:
    """A 3-D view: ``html()`` the page, ``save(path)`` writes it, Jupyter shows it."""

    def __init__(self, scene: dict, height: int = 520):
        self.scene = scene
        self.height = height

    @property
    def frames(self) -> int:
        """Number of frames (1 for :func:`view`)."""
        return len(self.scene["times"])

    def html(self) -> str:
        """The self-contained HTML page."""
        s = self.scene
        controls = ""
        if len(s["times"]) > 1:
            last = len(s["times"]) - 1
            controls = (
                '<button id="armdyn-play" type="button">Play</button>'
                f'<input id="armdyn-slider" type="range" min="0" max="{last}" step="1" value="0" aria-label="frame">'
                '<label><input id="armdyn-loop" type="checkbox" checked> loop</label>'
                '<span id="armdyn-time"></span>'
            )
        return (
            '<!DOCTYPE html>\n<html lang="en">\n<head>\n<meta charset="utf-8">\n'
            f'<meta http-equiv="Content-Security-Policy" content="{CSP}">\n'
            '<meta name="viewport" content="width=device-width, initial-scale=1">\n'
            f"<title>{escape(s['name'])} (3-D)</title>\n<style>{_STYLE}</style>\n</head>\n<body>\n"
            f"<header><h1>{escape(s['name'])}</h1>{controls}</header>\n"
            '<main id="armdyn-view"></main>\n'
            f'<script type="application/json" id="armdyn-scene">{script_json(s)}</script>\n'
            f'<script type="module">\n{_code()}\n</script>\n'
            "</body>\n</html>\n"
        )

    def save(self, path) -> None:
        """Write the page to ``path`` (all at once: an error leaves no half-written file)."""
        from .._io_atomic import atomic_write_text

        atomic_write_text(path, self.html())

    def _repr_html_(self) -> str:
        # a sandboxed frame (scripts, no same-origin): the page runs apart from the notebook
        return (
            f'<iframe srcdoc="{escape(self.html())}" sandbox="allow-scripts" '
            f'style="width:100%;height:{int(self.height)}px;border:1px solid #d1d9e0" '
            f'title="{escape(self.scene["name"])} (3-D)"></iframe>'
        )


def script_json(data) -> str:
    """``data`` as JSON that is inert inside ``<script>``: no ``</script>``, no ``<!--``
    (``<``, ``>``, ``&`` escaped) and no raw U+2028/U+2029."""
    text = json.dumps(data, ensure_ascii=False, separators=(",", ":"), allow_nan=False)
    for raw, escaped in (
        ("<", "\\u003c"),
        (">", "\\u003e"),
        ("&", "\\u0026"),
        ("\u2028", "\\u2028"),
        ("\u2029", "\\u2029"),
    ):
        text = text.replace(raw, escaped)
    return text


def _asset(name: str) -> str:
    """A vendored asset's text, through the one bounded reader (the largest is 692 kB)."""
    from ..io.textfile import read_text

    return read_text(resources.files("armdyn").joinpath("viewer_assets", name), "viewer asset", 2_000_000)


@lru_cache(maxsize=1)
def _code() -> str:
    """The page's script: three.js, then armdyn's viewer. Neither may hold what would end
    or bend the ``<script>`` element around it (they are checked, not rewritten: the
    files are vendored as they are)."""
    code = _three() + "\n" + _asset("viewer.js")
    if re.search(r"<!--|</?script", code, re.I):
        raise RuntimeError("viewer_assets: the script holds '<!--' or '<script': it cannot be inlined")
    return code


def _three() -> str:
    """three.js as a plain script defining ``THREE``: the module's final
    ``export{a as B, ...}`` becomes ``const THREE = {B: a, ...}`` (one inline script, no
    import, no URL)."""
    code = _asset("three.module.min.js")
    m = re.search(r"export\s*\{([^}]*)\}\s*;?\s*$", code)
    if m is None:
        raise RuntimeError("viewer_assets/three.module.min.js: no final export clause (not the vendored build?)")
    pairs = []
    for item in m.group(1).split(","):
        local, _, exported = (p.strip() for p in item.partition(" as "))
        pairs.append(f"{exported or local}:{local}")
    return code[: m.start()] + "const THREE={" + ",".join(pairs) + "};"


# --------------------------------------------------------------------- scene


def _coerce(robot) -> Robot:
    from ..show import numeric_robot

    if not isinstance(robot, Robot):
        from ..io import load

        robot = load(robot)
    return numeric_robot(robot)


def _link_poses(robot: Robot, Q: np.ndarray) -> np.ndarray:
    """(N, links, 4, 4) world poses of ``list(robot.links)`` at the rows of ``Q``. A
    floating robot's rows are its ``q`` (base position, quaternion ``x, y, z, w``,
    joints): the same tree with its base fixed gives the poses in the base frame, which
    the base pose carries into the world."""
    from ..numeric import forward_kinematics

    if not robot.floating:
        return np.asarray(forward_kinematics(robot, np.ascontiguousarray(Q))).reshape(len(Q), -1, 4, 4)
    from ..io import with_root_joint

    fixed = with_root_joint(robot, None)  # its joints in tree order: their blocks of q, moved
    place = {name: iq for name, _, iq, _ in robot.configuration_layout}
    width = {j.name: j.nq for j in robot.movable_joints}
    columns = [place[name] + k for name, _, _, _ in fixed.configuration_layout for k in range(width[name])]
    joints = np.ascontiguousarray(Q[:, columns])
    local = np.asarray(forward_kinematics(fixed, joints)).reshape(len(Q), -1, 4, 4)
    at = {n: i for i, n in enumerate(fixed.links)}
    local = local[:, [at[n] for n in robot.links]]
    base = np.tile(np.eye(4), (len(Q), 1, 1))
    x, y, z, w = Q[:, 3:7].T
    base[:, :3, :3] = np.stack(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    ).transpose(2, 0, 1)
    base[:, :3, 3] = Q[:, :3]
    return base[:, None] @ local


def _configurations(robot: Robot, Q) -> np.ndarray:
    """``Q`` (N, nq) as finite floats; a floating base's quaternions checked unit."""
    Q = np.asarray(Q, dtype=float)
    if Q.ndim != 2 or Q.shape[1] != robot.nq or len(Q) == 0:
        raise ValueError(f"Q: shape {Q.shape}, expected (frames, {robot.nq}) with at least one frame")
    if not np.all(np.isfinite(Q)):
        raise ValueError("times or Q contain NaN or inf")
    if robot.floating or robot.multi_dof_joints:
        from ..configuration import difference

        difference(robot, Q, Q)  # refuses a quaternion off unit length, naming it
    return Q


def _poses(robot: Robot, Q: np.ndarray) -> tuple[list[float], np.ndarray]:
    """Flat ``x, y, z, qx, qy, qz, qw`` per frame and link, and every link origin (k, 3)."""
    T = _link_poses(robot, Q)
    flat = np.concatenate([T[:, :, :3, 3], quaternions(T[:, :, :3, :3])], axis=2).round(7)
    return flat.reshape(-1).tolist(), T[:, :, :3, 3].reshape(-1, 3)


def _encode(mesh) -> dict:
    v, t = mesh
    return {
        "v": base64.b64encode(np.ascontiguousarray(v, dtype="<f4").tobytes()).decode("ascii"),
        "t": base64.b64encode(np.ascontiguousarray(t, dtype="<u4").tobytes()).decode("ascii"),
    }


def _scene(robot: Robot, times, Q, frames: bool, markers: bool | None, package_dirs) -> dict:
    from ..show import as_floats, view_of

    names = list(robot.links)
    at = {n: i for i, n in enumerate(names)}
    poses, origins = _poses(robot, Q)
    centre, size = view_of(origins)
    visuals, meshes = urdf_visuals(robot, package_dirs)
    drawn = []
    for name, items in visuals.items():
        drawn += [{**item, "link": at[name]} for item in items]
    if markers is None:
        markers = not drawn
    segments = [[at[j.parent], at[j.child]] for j in robot.joints if j.child not in visuals]
    joints, coms = [], []
    if markers:
        for j in robot.movable_joints:
            if j.nv > 1:  # a ball or planar joint has no axis to draw
                continue
            joints.append({"link": at[j.child], "type": j.type, "axis": as_floats(j.axis).reshape(3).tolist()})
        masses = {n: float(ln.mass) for n, ln in robot.links.items()}
        heaviest = max(masses.values(), default=0.0)
        for n, m in masses.items():
            if m > 0:
                com = as_floats(robot.links[n].com).reshape(3).tolist()
                coms.append({"link": at[n], "com": com, "r": float(0.05 * size * (m / heaviest) ** (1 / 3))})
    return {
        "name": robot.name,
        "links": names,
        "times": [round(float(t), 9) for t in times],
        "poses": poses,
        "centre": [float(c) for c in centre],
        "size": float(size),
        "segments": segments,
        "visuals": drawn,
        "meshes": [_encode(m) for m in meshes],
        "joints": joints,
        "coms": coms,
        "axes": bool(frames),
    }


def view(robot, q=None, *, frames: bool = False, markers: bool | None = None, package_dirs=()) -> View:
    """The arm ``robot`` (a :class:`Robot`, model file or bundled name) at ``q`` (dof,)
    (default zeros; a floating robot's ``q`` is (nq,), default its neutral
    configuration). ``frames``: draw each link frame's axes; ``markers``: joint
    cylinders and mass spheres (default: only when the model has no visual geometry);
    ``package_dirs``: folders where ``package://`` meshes are looked up."""
    from ..show import joint_values

    robot = _coerce(robot)
    if robot.floating or robot.multi_dof_joints:
        from ..configuration import neutral

        q = _configurations(robot, [neutral(robot) if q is None else np.asarray(q, dtype=float).reshape(-1)])[0]
    else:
        q = joint_values(robot, q)
    return View(_scene(robot, [0.0], q[None, :], frames, markers, package_dirs))


def sample(times, count: int, max_frames: int = MAX_FRAMES) -> np.ndarray:
    """Indices of at most ``max_frames`` evenly spread rows of ``count`` (first and last kept)."""
    if count <= max_frames:
        return np.arange(count)
    return np.unique(np.linspace(0, count - 1, max_frames).round().astype(int))


def animate(
    robot, times, Q, *, max_frames: int = MAX_FRAMES, frames: bool = False, markers: bool | None = None, package_dirs=()
) -> View:
    """The arm moving through the joint coordinates ``Q`` (N, dof), or a floating robot's
    configurations (N, nq), at the increasing ``times`` (N,) in seconds, played in real
    time; at most ``max_frames`` of the rows are kept (evenly spread, first and last
    included). Other options as :func:`view`."""
    robot = _coerce(robot)
    times = np.asarray(times, dtype=float).reshape(-1)
    Q = _configurations(robot, Q)
    if times.shape != (len(Q),):
        raise ValueError(f"times: {times.size} values for {len(Q)} rows of Q")
    if not np.all(np.isfinite(times)):
        raise ValueError("times or Q contain NaN or inf")
    if np.any(np.diff(times) < 0):
        raise ValueError("times must not decrease")
    if max_frames < 1:
        raise ValueError(f"max_frames must be at least 1, got {max_frames}")
    keep = sample(times, len(Q), max_frames)
    return View(_scene(robot, times[keep], Q[keep], frames, markers, package_dirs))
