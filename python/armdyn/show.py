"""Look at a robot: a text table of its joints and links, and a 3-D picture of the arm.

``show(robot, q=None, out=None)`` returns the table (a string) and, when ``out`` is a
file name, saves a matplotlib picture of the arm at the joint coordinates ``q``
(default all zero) to it (PNG, SVG or PDF, by the name's extension).

The picture, in the base frame (metres, z up as the model has it):

* every link frame's origin is a dot, and a grey segment joins each joint's parent
  frame origin to its child frame origin (so the "links" are drawn between frame
  origins, which for DH models need not follow the physical links);
* each movable joint's axis is an arrow at the child frame origin (orange: revolute,
  purple: prismatic), with the joint's name;
* each link frame is a small triad (x red, y green, z blue);
* each centre of mass is a black dot whose area grows with the mass; the base is a
  black square.

Forward kinematics chains :meth:`armdyn.model.Joint.transform` with numbers. A model
with parameters is first bound to its published defaults (``robot.bind()``); a
parameter still free after that is a :class:`ModelError` naming it.
"""

from __future__ import annotations

import math

import numpy as np
import sympy as sp

from .errors import ModelError
from .model import Robot

__all__ = ["show", "table", "frame_poses", "numeric_robot", "draw_on", "animate"]

AXIS_COLOURS = {"revolute": "tab:orange", "prismatic": "tab:purple"}


# ----------------------------------------------------------------- kinematics


def numeric_robot(robot: Robot) -> Robot:
    """``robot`` with every parameter bound to a number (its defaults), or a
    :class:`ModelError` naming the parameters that have no default value."""
    if robot.free_symbols():
        robot = robot.bind()
    free = sorted(s.name for s in robot.free_symbols())
    if free:
        raise ModelError(
            f"parameters {free} have no default value: bind them first (robot.bind({{...}}))",
            f"robot '{robot.name}'",
        )
    return robot


def _coordinates(robot: Robot, q) -> np.ndarray:
    if q is None:
        return np.zeros(robot.dof)
    q = np.asarray(q, dtype=float).reshape(-1)
    if q.shape != (robot.dof,):
        raise ValueError(f"q must have {robot.dof} values (one per movable joint), got {q.size}")
    if not np.all(np.isfinite(q)):
        raise ValueError("q contains NaN or inf")
    return q


def _floats(m: sp.Matrix) -> np.ndarray:
    return np.array(m.evalf(), dtype=float)


def frame_poses(robot: Robot, q=None) -> dict[str, np.ndarray]:
    """Pose of every link frame in the base frame at ``q`` (dof,): dict link name ->
    (4, 4) homogeneous transform, base first, then in joint (tree) order.

    ``robot`` must be numeric (see :func:`numeric_robot`). Each pose is the parent's
    pose times the joint's ``Joint.transform(q_i)``.
    """
    q = _coordinates(robot, q)
    poses = {robot.base: np.eye(4)}
    for joint in robot.joints:
        f = robot.follows(joint)  # (coordinate, multiplier, offset); mimic joints follow a leader
        R, p = joint.transform(0 if f is None else float(f[1]) * q[f[0]] + float(f[2]))
        local = np.eye(4)
        local[:3, :3], local[:3, 3] = _floats(R), _floats(p).reshape(3)
        poses[joint.child] = poses[joint.parent] @ local
    return poses


# ---------------------------------------------------------------------- table


def _num(x) -> str:
    x = sp.sympify(x)
    if x.free_symbols:
        return str(x)
    v = float(x)
    return "0" if abs(v) < 5e-13 else f"{v:.6g}"


def _vec(v) -> str:
    return "(" + ", ".join(_num(c) for c in v) + ")"


def rpy(R: sp.Matrix) -> tuple:
    """URDF roll, pitch, yaw of a numeric rotation (inverse of ``rpy_matrix``)."""
    r = _floats(R)
    pitch = math.atan2(-r[2, 0], math.hypot(r[2, 1], r[2, 2]))
    if math.hypot(r[2, 1], r[2, 2]) < 1e-12:  # gimbal lock: put it all in yaw
        return 0.0, pitch, math.atan2(-r[0, 1], r[1, 1])
    return math.atan2(r[2, 1], r[2, 2]), pitch, math.atan2(r[1, 0], r[0, 0])


def _rows(header: list[str], rows: list[list[str]]) -> list[str]:
    widths = [max(len(r[i]) for r in [header] + rows) for i in range(len(header))]
    line = lambda r: "  ".join(c.ljust(w) for c, w in zip(r, widths)).rstrip()  # noqa: E731
    return [line(header), line(["-" * w for w in widths])] + [line(r) for r in rows]


def table(robot: Robot) -> str:
    """A text table of the joints (name, type, parent, child, placement xyz and rpy,
    axis, limits) and the links (mass, centre of mass, inertia diagonal)."""
    lines = [f"{robot.name}: {robot.dof} dof, base '{robot.base}', gravity {_vec(robot.gravity)}"]
    if robot.meta.get("source"):
        lines.append(f"source: {robot.meta['source']}")
    if robot.joint_dynamics:  # a rigid-body library (Pinocchio) leaves these out
        lines.append(f"joint dynamics: {', '.join(robot.joint_dynamics)} (in rnea/aba; "
                     "robot.without_joint_dynamics() drops them)")
    rows = []
    for j in robot.joints:
        angles = "(" + ", ".join(_num(a) for a in rpy(j.rotation)) + ")" if not j.rotation.free_symbols else "symbolic"
        if j.lower is not None or j.upper is not None:
            bounds = [_num(b) if b is not None else "-" for b in (j.lower, j.upper)]
            limits = f"[{bounds[0]}, {bounds[1]}]"
        else:
            limits = ""
        axis = _vec(j.axis) if j.movable else ""
        rows.append([j.name, j.type, j.parent, j.child, _vec(j.xyz), angles, axis, limits])
    lines += ["", "joints"] + _rows(["name", "type", "parent", "child", "xyz", "rpy", "axis", "limits"], rows)
    for j in robot.mimic_joints:  # no coordinate of their own: say whom they follow
        m, o = j.mimic.multiplier, j.mimic.offset
        lines.append(f"mimic: {j.name} = {_num(m)} * {j.mimic.joint}" + (f" + {_num(o)}" if o != 0 else ""))
    massless = set(robot.meta.get("massless_links", ()))
    rows = []
    for link in robot.links.values():
        note = "no <inertial>" if link.name in massless else ""
        if link.name == robot.base:
            note = (note + ", " if note else "") + "base (fixed)"
        diag = _vec([link.inertia[0, 0], link.inertia[1, 1], link.inertia[2, 2]])
        rows.append([link.name, _num(link.mass), _vec(link.com), diag, note])
    lines += ["", "links"] + _rows(["name", "mass", "com", "inertia (ixx, iyy, izz)", ""], rows)
    return "\n".join(lines)


# -------------------------------------------------------------------- picture


def _reach(points: np.ndarray) -> float:
    span = np.ptp(points, axis=0).max() if len(points) > 1 else 0.0
    return span if span > 1e-9 else 1.0


def draw(robot: Robot, q=None, out=None, title: str | None = None):
    """The picture of the (numeric) ``robot`` at ``q``; saved to ``out`` if given.
    Returns the matplotlib figure."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    q = _coordinates(robot, q)
    poses = frame_poses(robot, q)
    origins = np.array([T[:3, 3] for T in poses.values()])
    fig = plt.figure(figsize=(7, 7))
    ax = fig.add_subplot(projection="3d")
    qtext = ", ".join(f"{v:.3g}" for v in q)
    draw_on(ax, robot, poses, title or f"{robot.name} at q = [{qtext}]", _view(origins))
    if out is not None:
        fig.savefig(out, dpi=110, bbox_inches="tight")
        plt.close(fig)
    return fig


def _view(origins: np.ndarray) -> tuple[np.ndarray, float]:
    """Centre (3,) and size (m) of a view holding the points ``origins`` (k, 3)."""
    return (origins.max(axis=0) + origins.min(axis=0)) / 2, _reach(origins)


def draw_on(ax, robot: Robot, poses: dict[str, np.ndarray], title: str, view: tuple[np.ndarray, float]):
    """Draw the arm with link frame ``poses`` (link name -> (4, 4), base frame) on the 3-D
    axes ``ax``; ``view`` = (centre (3,), size in m) of the box shown (see the module
    docstring for what is drawn). Used by :func:`draw` and for animation frames."""
    origins = np.array([T[:3, 3] for T in poses.values()])
    centre, size = view
    triad, arrow = 0.08 * size, 0.12 * size
    for j in robot.joints:
        a, b = poses[j.parent][:3, 3], poses[j.child][:3, 3]
        ax.plot(*zip(a, b), color="0.45", linewidth=3, solid_capstyle="round")
    ax.scatter(*origins.T, color="0.2", s=12, depthshade=False)
    ax.scatter(*poses[robot.base][:3, 3], marker="s", color="black", s=60, depthshade=False)

    for T in poses.values():
        for k, colour in enumerate(("red", "green", "blue")):
            ax.quiver(*T[:3, 3], *(triad * T[:3, k]), color=colour, linewidth=1)

    for j in robot.movable_joints:
        T = poses[j.child]
        axis = T[:3, :3] @ _floats(j.axis).reshape(3)
        ax.quiver(*T[:3, 3], *(arrow * axis), color=AXIS_COLOURS[j.type], linewidth=2.5, arrow_length_ratio=0.3)
        ax.text(*(T[:3, 3] + 1.15 * arrow * axis), j.name, fontsize=7, color=AXIS_COLOURS[j.type])

    masses = {n: float(ln.mass) for n, ln in robot.links.items() if n != robot.base}
    heaviest = max(masses.values(), default=0.0)
    for name, m in masses.items():
        if m > 0:
            c = poses[name][:3, :3] @ _floats(robot.links[name].com).reshape(3) + poses[name][:3, 3]
            ax.scatter(*c, color="black", s=10 + 80 * m / heaviest, alpha=0.6, depthshade=False)

    # equal scales on the three axes, so the arm is not distorted
    half = 0.6 * size
    ax.set_xlim(centre[0] - half, centre[0] + half)
    ax.set_ylim(centre[1] - half, centre[1] + half)
    ax.set_zlim(centre[2] - half, centre[2] + half)
    ax.set_box_aspect((1, 1, 1))
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_zlabel("z (m)")
    ax.set_title(title, fontsize=10)


def show(robot, q=None, out=None) -> str:
    """The joint/link table of ``robot`` (a :class:`Robot`, or a model file or bundled
    robot name for :func:`armdyn.io.load`); with ``out``, also save the picture of
    the arm at ``q`` (dof,) there. Returns the table."""
    if not isinstance(robot, Robot):
        from .io import load

        robot = load(robot)
    robot = numeric_robot(robot)
    text = table(robot)
    if out is not None:
        draw(robot, q, out)
    return text


# ------------------------------------------------------------------ animation


def animate(robot, q, out, *, t=None, fps: float = 25.0, title: str | None = None, dpi: int = 80) -> int:
    """Write a GIF of the arm moving through the joint coordinates ``q`` (frames, dof), one
    frame per row, drawn as :func:`draw` draws it (same view box for every frame). ``t``
    (frames,): times shown in the title (s). GIFs are written by Pillow (no video tools
    needed), first to a temporary file next to ``out`` and then renamed, so an error never
    leaves half a file. Returns the number of frames.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from PIL import Image

    from .io import load
    from .numeric import forward_kinematics

    if not isinstance(robot, Robot):
        robot = load(robot)
    robot = numeric_robot(robot)
    q = np.asarray(q, dtype=float)
    if q.ndim != 2 or q.shape[1] != robot.dof or len(q) == 0:
        raise ValueError(f"q: shape {q.shape}, expected (frames, {robot.dof}) with at least one frame")
    if not np.all(np.isfinite(q)):
        raise ValueError("q contains NaN or inf")
    if not (np.isfinite(fps) and fps > 0):
        raise ValueError(f"fps must be positive, got {fps}")
    if not str(out).lower().endswith(".gif"):
        raise ValueError(f"{out}: animations are written as GIF (give a .gif name)")
    poses = np.asarray(forward_kinematics(robot, np.ascontiguousarray(q)))  # (frames, nlinks, 4, 4)
    names = list(robot.links)
    view = _view(poses[:, :, :3, 3].reshape(-1, 3))
    fig = plt.figure(figsize=(6, 6), dpi=dpi)
    ax = fig.add_subplot(projection="3d")
    images = []
    for k in range(len(q)):
        ax.cla()
        when = f"t = {t[k]:.2f} s" if t is not None else f"frame {k}"
        draw_on(ax, robot, dict(zip(names, poses[k])), f"{title or robot.name}: {when}", view)
        fig.canvas.draw()
        rgba = np.asarray(fig.canvas.buffer_rgba())
        images.append(Image.fromarray(rgba[..., :3].copy()).quantize(colors=64, method=Image.Quantize.MEDIANCUT))
    plt.close(fig)
    from ._io_atomic import atomic_write

    atomic_write(out, lambda tmp: images[0].save(tmp, format="GIF", save_all=True, append_images=images[1:],
                                                 duration=max(20, round(1000 / fps)), loop=0))
    return len(images)
