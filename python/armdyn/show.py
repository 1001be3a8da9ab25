"""Look at a robot: a text table of its joints and links, and a 3-D picture of the arm.

``show(robot, q=None, out=None)`` returns the table (a string) and, when ``out`` is a
file name, saves a matplotlib picture of the arm at the joint coordinates ``q``
(default all zero) to it (PNG, SVG or PDF, by the name's extension).

The picture, in the base frame (metres, z up as the model has it):

* every link frame's origin is a dot, and a grey segment joins each joint's parent
  frame origin to its child frame origin (so the "links" are drawn between frame
  origins, which for DH models need not follow the physical links);
* each movable joint's axis is an arrow at the child frame origin (orange: revolute,
  purple: prismatic), with the joint's name joined to the arrow's tip by a thin line
  (names are placed away from the arm and from each other, so that they never overlap);
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
#: joints of several coordinates have no axis: a ring at the joint instead
JOINT_MARKS = {"spherical": "tab:green", "planar": "tab:cyan", "floating": "tab:gray"}


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


def joint_values(robot: Robot, q) -> np.ndarray:
    """The joints' configuration (a floating base's left out: drawn in the base frame) as a
    float array of finite values (None: zeros, or the neutral configuration of joints of
    several coordinates), else a ValueError. A floating robot's whole ``q`` is taken too."""
    base = 7 if robot.floating else 0
    if q is None:
        if robot.multi_dof_joints:
            from .configuration import neutral

            return neutral(robot)[base:]
        return np.zeros(robot.dof)
    q = np.asarray(q, dtype=float).reshape(-1)
    if base and q.shape == (robot.nq,):
        q = q[base:]
    if q.shape != (robot.nq - base,):
        each = "one per movable joint" if robot.nq - base == robot.dof else "quaternions x y z w, planar x y cos sin"
        raise ValueError(f"q must have {robot.nq - base} values ({each}), got {q.size}")
    if not np.all(np.isfinite(q)):
        raise ValueError("q contains NaN or inf")
    if robot.multi_dof_joints:  # a quaternion or (cos, sin) pair off unit length: refused, naming the joint
        from .configuration import check_configuration, neutral

        check_configuration(robot, np.concatenate([neutral(robot)[:base], q]))
    return q


def as_floats(m: sp.Matrix) -> np.ndarray:
    """A numeric SymPy matrix as a float array."""
    return np.array(m.evalf(), dtype=float)


def frame_poses(robot: Robot, q=None) -> dict[str, np.ndarray]:
    """Pose of every link frame in the base frame at ``q`` (dof,): dict link name ->
    (4, 4) homogeneous transform, base first, then in joint (tree) order.

    ``robot`` must be numeric (see :func:`numeric_robot`). Each pose is the parent's
    pose times the joint's ``Joint.transform(q_i)``.
    """
    q = joint_values(robot, q)
    poses = {robot.base: np.eye(4)}
    # each joint's place in q: its velocity coordinate's index -> its configuration block
    base = (7, 6) if robot.floating else (0, 0)
    block = {iv - base[1]: (iq - base[0], kind) for _, kind, iq, iv in robot.configuration_layout}
    for joint in robot.joints:
        f = robot.follows(joint)  # (coordinate, multiplier, offset); mimic joints follow a leader
        if f is None:
            R, p = joint.transform(0)
        elif joint.nq > 1:
            iq, _ = block[f[0]]
            R, p = joint.transform(q[iq : iq + joint.nq].tolist())
        else:
            R, p = joint.transform(float(f[1]) * q[block[f[0]][0]] + float(f[2]))
        local = np.eye(4)
        local[:3, :3], local[:3, 3] = as_floats(R), as_floats(p).reshape(3)
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
    r = as_floats(R)
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
        lines.append(
            f"joint dynamics: {', '.join(robot.joint_dynamics)} (in rnea/aba; "
            "robot.without_joint_dynamics() drops them)"
        )
    rows = []
    for j in robot.joints:
        angles = "(" + ", ".join(_num(a) for a in rpy(j.rotation)) + ")" if not j.rotation.free_symbols else "symbolic"
        if j.lower is not None or j.upper is not None:
            bounds = [_num(b) if b is not None else "-" for b in (j.lower, j.upper)]
            limits = f"[{bounds[0]}, {bounds[1]}]"
        else:
            limits = ""
        axis = _vec(j.axis) if j.movable and j.nv == 1 else ""  # a ball or planar joint has none
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
            note = (note + ", " if note else "") + ("base (floating)" if robot.floating else "base (fixed)")
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

    q = joint_values(robot, q)
    poses = frame_poses(robot, q)
    origins = np.array([T[:3, 3] for T in poses.values()])
    fig = plt.figure(figsize=(7, 7))
    ax = fig.add_axes((0, 0, 1, 0.95), projection="3d")
    qtext = ", ".join(f"{v:.3g}" for v in q)
    draw_on(ax, robot, poses, title or f"{robot.name} at q = [{qtext}]", view_of(origins))
    if out is not None:
        from pathlib import Path

        from ._io_atomic import atomic_write

        fmt = Path(out).suffix[1:].lower() or "png"
        try:  # staged in a temporary file: an error (or Ctrl-C) leaves nothing half-written
            atomic_write(out, lambda tmp: fig.savefig(tmp, dpi=110, bbox_inches="tight", format=fmt))
        finally:
            plt.close(fig)
    return fig


def view_of(origins: np.ndarray) -> tuple[np.ndarray, float]:
    """Centre (3,) and size (m) of a view holding the points ``origins`` (k, 3)."""
    return (origins.max(axis=0) + origins.min(axis=0)) / 2, _reach(origins)


def _view_box(origins: np.ndarray, size: float) -> np.ndarray:
    """Half extents (3,) of the box shown around the points ``origins`` (k, 3): each
    axis as long as the points' span there plus a margin for the arrows and frames, at
    least a third of ``size`` (a flat arm keeps some depth). The three axes share one
    scale (``set_box_aspect``), so the box is not a cube: the arm fills the picture."""
    span = np.ptp(origins, axis=0) if len(origins) > 1 else np.zeros(3)
    return np.maximum(0.5 * span + 0.15 * size, size / 3)


def _place_labels(ax, labels: list[tuple[str, np.ndarray, str]], avoid: np.ndarray, fontsize: float = 7):
    """Write each ``(text, point (3,), colour)`` of ``labels`` near its point, joined to it
    by a thin line, where it overlaps no other label and covers none of the points
    ``avoid`` (k, 3) (the arm): greedy, in projected screen coordinates, trying
    directions away from the arm's middle first, at growing distances."""
    from mpl_toolkits.mplot3d import proj3d

    if not labels:
        return
    M = ax.get_proj()
    to_screen = ax.transData.transform
    px_per_pt = ax.figure.dpi / 72

    def screen(p):
        x, y, _ = proj3d.proj_transform(p[0], p[1], p[2], M)
        return np.array([x, y]), to_screen((x, y))

    arm = np.array([screen(p)[1] for p in avoid]) if len(avoid) else np.zeros((0, 2))
    middle = arm.mean(axis=0) if len(arm) else np.zeros(2)
    taken: list[tuple[float, float, float, float]] = []  # screen boxes (x0, y0, x1, y1)
    w_char, h_text = 0.62 * fontsize * px_per_pt, 1.3 * fontsize * px_per_pt

    width, height = ax.figure.bbox.width, ax.figure.bbox.height

    def clash(box):
        x0, y0, x1, y1 = box
        if x0 < 2 or y0 < 2 or x1 > width - 2 or y1 > height - 2:  # inside the picture
            return True
        if any(x0 < b[2] and b[0] < x1 and y0 < b[3] and b[1] < y1 for b in taken):
            return True
        return bool(len(arm)) and bool(
            np.any((arm[:, 0] > x0 - 4) & (arm[:, 0] < x1 + 4) & (arm[:, 1] > y0 - 4) & (arm[:, 1] < y1 + 4))
        )

    for text, point, colour in labels:
        xy, at = screen(point)
        away = at - middle
        base = math.atan2(away[1], away[0]) if np.hypot(*away) > 1e-6 else math.pi / 2
        w, h = w_char * len(text), h_text
        best = None
        for dist in (14, 26, 40, 56, 75, 100):
            for turn in (0, 30, -30, 60, -60, 90, -90, 120, -120, 150, -150, 180):
                a = base + math.radians(turn)
                dx, dy = dist * px_per_pt * math.cos(a), dist * px_per_pt * math.sin(a)
                # anchor the text's near side at the offset point
                x0 = at[0] + dx - (w if math.cos(a) < -0.3 else (w / 2 if abs(math.cos(a)) <= 0.3 else 0))
                y0 = at[1] + dy - (h if math.sin(a) < -0.3 else (h / 2 if abs(math.sin(a)) <= 0.3 else 0))
                box = (x0, y0, x0 + w, y0 + h)
                if not clash(box):
                    best = (box, dx, dy)
                    break
            if best:
                break
        if best is None:  # crowded: the farthest candidate straight out
            dx, dy = 100 * px_per_pt * math.cos(base), 100 * px_per_pt * math.sin(base)
            best = ((at[0] + dx, at[1] + dy, at[0] + dx + w, at[1] + dy + h), dx, dy)
        box, dx, dy = best
        taken.append(box)
        ax.annotate(
            text,
            xy=xy,
            xytext=(box[0] - at[0], box[1] - at[1]),
            textcoords="offset pixels",
            fontsize=fontsize,
            color=colour,
            ha="left",
            va="bottom",
            arrowprops=dict(arrowstyle="-", color=colour, linewidth=0.6, shrinkA=0, shrinkB=1),
        )


def draw_on(ax, robot: Robot, poses: dict[str, np.ndarray], title: str, view: tuple[np.ndarray, float]):
    """Draw the arm with link frame ``poses`` (link name -> (4, 4), base frame) on the 3-D
    axes ``ax``; ``view`` = (centre (3,), size in m[, half extents (3,)]) of the box shown (see the module
    docstring for what is drawn). Used by :func:`draw` and for animation frames."""
    origins = np.array([T[:3, 3] for T in poses.values()])
    centre, size = view[0], view[1]
    half = view[2] if len(view) > 2 else _view_box(origins, size)
    triad, arrow = 0.08 * size, 0.12 * size
    drawn = [origins]  # points the joint names must not cover
    for j in robot.joints:
        a, b = poses[j.parent][:3, 3], poses[j.child][:3, 3]
        ax.plot(*zip(a, b), color="0.45", linewidth=3, solid_capstyle="round")
        drawn.append(a + np.linspace(0, 1, 12)[:, None] * (b - a))
    ax.scatter(*origins.T, color="0.2", s=12, depthshade=False)
    ax.scatter(*poses[robot.base][:3, 3], marker="s", color="black", s=60, depthshade=False)

    for T in poses.values():
        for k, colour in enumerate(("red", "green", "blue")):
            ax.quiver(*T[:3, 3], *(triad * T[:3, k]), color=colour, linewidth=1)
            drawn.append(T[:3, 3] + np.linspace(0.5, 1, 2)[:, None] * triad * T[:3, k])

    labels = []
    for j in robot.movable_joints:
        T = poses[j.child]
        if j.type in JOINT_MARKS:
            ax.scatter(*T[:3, 3], s=140, facecolors="none", edgecolors=JOINT_MARKS[j.type], linewidths=2.5)
            labels.append((f"{j.name} ({j.type})", T[:3, 3] + 0.5 * arrow * T[:3, 2], JOINT_MARKS[j.type]))
            continue
        axis = T[:3, :3] @ as_floats(j.axis).reshape(3)
        ax.quiver(*T[:3, 3], *(arrow * axis), color=AXIS_COLOURS[j.type], linewidth=2.5, arrow_length_ratio=0.3)
        labels.append((j.name, T[:3, 3] + arrow * axis, AXIS_COLOURS[j.type]))
        drawn.append(T[:3, 3] + np.linspace(0.3, 1, 3)[:, None] * arrow * axis)

    masses = {n: float(ln.mass) for n, ln in robot.links.items() if n != robot.base}
    heaviest = max(masses.values(), default=0.0)
    for name, m in masses.items():
        if m > 0:
            c = poses[name][:3, :3] @ as_floats(robot.links[name].com).reshape(3) + poses[name][:3, 3]
            ax.scatter(*c, color="black", s=10 + 80 * m / heaviest, alpha=0.6, depthshade=False)

    # equal scales on the three axes (box sides proportional to the ranges): not distorted
    ax.set_xlim(centre[0] - half[0], centre[0] + half[0])
    ax.set_ylim(centre[1] - half[1], centre[1] + half[1])
    ax.set_zlim(centre[2] - half[2], centre[2] + half[2])
    ax.set_box_aspect(tuple(half), zoom=1.15)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_zlabel("z (m)")
    ax.set_title(title, fontsize=10)
    _place_labels(ax, labels, np.vstack(drawn))


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


def animate(
    robot,
    q,
    out,
    *,
    t=None,
    fps: float = 25.0,
    title: str | None = None,
    dpi: int = 80,
    frame_ms: int | None = None,
    progress=None,
) -> int:
    """Write a GIF of the arm moving through the joint coordinates ``q`` (frames, dof), one
    frame per row, drawn as :func:`draw` draws it (same view box for every frame). ``t``
    (frames,): times shown in the title (s). GIFs are written by Pillow (no video tools
    needed), first to a temporary file next to ``out`` and then renamed, so an error never
    leaves half a file. Each frame lasts ``frame_ms`` ms (default ``1000 / fps``; GIF
    delays are whole centiseconds, at least 20 ms); for real-time playback give the
    simulated time between frames (see :func:`armdyn.simulate_cli.gif_frames`).
    ``progress(done, frames)`` is called after each frame drawn. Returns the number of
    frames.
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
    width = robot.dof if robot.floating else robot.nq  # a joint of several coordinates: its block of q
    q = np.asarray(q, dtype=float)
    if q.ndim != 2 or q.shape[1] != width or len(q) == 0:
        raise ValueError(f"q: shape {q.shape}, expected (frames, {width}) with at least one frame")
    if not np.all(np.isfinite(q)):
        raise ValueError("q contains NaN or inf")
    if not (np.isfinite(fps) and fps > 0):
        raise ValueError(f"fps must be positive, got {fps}")
    if not str(out).lower().endswith(".gif"):
        raise ValueError(f"{out}: animations are written as GIF (give a .gif name)")
    poses = np.asarray(forward_kinematics(robot, np.ascontiguousarray(q)))  # (frames, nlinks, 4, 4)
    names = list(robot.links)
    points = poses[:, :, :3, 3].reshape(-1, 3)
    centre, size = view_of(points)
    view = (centre, size, _view_box(points, size))  # one box for every frame: the arm moves in it
    fig = plt.figure(figsize=(6, 6), dpi=dpi)
    ax = fig.add_axes((0.0, 0.03, 0.94, 0.91), projection="3d")  # room for the tick labels
    images = []
    for k in range(len(q)):
        ax.cla()
        when = f"t = {t[k]:.2f} s" if t is not None else f"frame {k}"
        draw_on(ax, robot, dict(zip(names, poses[k])), f"{title or robot.name}: {when}", view)
        fig.canvas.draw()
        rgba = np.asarray(fig.canvas.buffer_rgba())
        images.append(Image.fromarray(rgba[..., :3].copy()).quantize(colors=64, method=Image.Quantize.MEDIANCUT))
        if progress is not None:
            progress(k + 1, len(q))
    plt.close(fig)
    duration = max(20, round(1000 / fps)) if frame_ms is None else max(20, int(frame_ms))
    from ._io_atomic import atomic_write

    atomic_write(
        out,
        lambda tmp: images[0].save(
            tmp, format="GIF", save_all=True, append_images=images[1:], duration=duration, loop=0
        ),
    )
    return len(images)
