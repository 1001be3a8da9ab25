"""The drawing of a variant for its statement: the arm in its plane at a sample pose, with
every label on its object, as a teacher draws it on the board.

    uri = drawing_uri(variant, robot)          # SVG data: URI for problem.html
    drawing_png(variant, robot, "arm.png")     # the same picture as a PNG (to look at it)

What is drawn (a planar arm in the plane its joints move it in: ``x0``-``y0``, or
``x0``-``z0`` for the ``pr`` arm):

* the base (hatched) and each link as a thick line, each joint as a circle (revolute) or
  a sleeve along its axis (prismatic);
* each revolute joint's angle ``θi`` as an arc at that joint, from the line it is measured
  from (``x0``, or the previous link's line) to its link, labelled at the arc's middle;
* each prismatic joint's ``di`` as a dimension arrow along its slide, labelled at its middle;
* each length parameter (``l1``, ``l2``) as a dimension line beside the segment it measures;
* each frame of ``model.yaml`` (the variant's convention) as its in-plane axes, labelled
  ``x0``, ``y0``, ``x1``... at their tips (an axis out of the plane as ⊙ / ⊗ beside the
  origin), each mass ``mi`` at its centre, and gravity ``g``.

The spatial ``rrp`` arm keeps the 3-D picture of :mod:`armdyn.show`. Symbolic lengths are
drawn at nominal values. Deterministic: the SVG has a fixed hash salt and no date.
"""

from __future__ import annotations

import base64
import io
import math

import numpy as np
import sympy as sp

from .variants import Variant

#: lengths drawn for symbolic length parameters (m)
NOMINAL = {"l1": 1.0, "l2": 0.8, "l3": 0.6}
#: the sample pose: revolute angles (rad) and slides (m)
ANGLE, SLIDE = 0.6, 0.45
_PLANE = {"pr": (0, 2)}  # base axes the drawing's (horizontal, vertical) are; default x0, y0
_AXIS_NAMES = "xyz"
_COLOURS = ("#c0392b", "#1e8449", "#1f4e9c")
#: a label stays readable where it crosses a line
_BOX = dict(boxstyle="round,pad=0.1", facecolor="white", edgecolor="none", alpha=0.85)


def _craig(row, q: float, f) -> np.ndarray:
    """Craig's link transform of one row (alpha, a, d, theta + its joint value); ``f``
    makes a row's value a number."""
    alpha, a = f(row.alpha), f(row.a)
    d = f(row.d) + (q if row.kind == "prismatic" else 0.0)
    th = f(row.theta) + (q if row.kind == "revolute" else 0.0)
    ca, sa, ct, st = math.cos(alpha), math.sin(alpha), math.cos(th), math.sin(th)
    return np.array(
        [
            [ct, -st, 0, a],
            [st * ca, ct * ca, -sa, -sa * d],
            [st * sa, ct * sa, ca, ca * d],
            [0, 0, 0, 1],
        ]
    )


def _numeric_rows(variant: Variant):
    subs = {sp.Symbol(k): v for k, v in NOMINAL.items()}
    subs.update({sp.Symbol(k): v for k, v in variant.lengths})
    rows = []
    for r in variant.rows():

        def f(x):
            return float(sp.sympify(x).xreplace(subs))

        rows.append((r, f, tuple(map(f, r.rod[0])), tuple(map(f, r.rod[1]))))
    return rows, subs


def _sample(rows) -> list[float]:
    return [ANGLE if r.kind == "revolute" else SLIDE for r, *_ in rows]


def _dimension(ax, a, b, text: str, offset: float, colour="0.25", where: float = 0.5):
    """A dimension line from ``a`` to ``b`` (2-D), shifted ``offset`` to its left, with
    ``text`` on its outer side, ``where`` of the way along it (the middle by default)."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    t = b - a
    n = np.linalg.norm(t)
    if n < 1e-9:
        return
    left = np.array([-t[1], t[0]]) / n
    p, q = a + offset * left, b + offset * left
    for end in (a, b):  # extension lines from the object to the dimension line
        ax.plot(*zip(end + 0.15 * offset * left, end + 1.15 * offset * left), color=colour, lw=0.6)
    ax.annotate("", xy=q, xytext=p, arrowprops=dict(arrowstyle="<->", color=colour, lw=0.9, shrinkA=0, shrinkB=0))
    mid = p + where * (q - p) + 0.06 * np.sign(offset) * left * max(1.0, abs(offset) / 0.12)
    ax.text(*mid, text, color=colour, fontsize=11, ha="center", va="center", bbox=_BOX, zorder=8)


def _arc(ax, centre, start: float, sweep: float, radius: float, text: str, colour="#7d3c98"):
    """An angle: an arc at ``centre`` from direction ``start`` (rad) through ``sweep``,
    an arrow at its end, ``text`` at its middle just outside it."""
    from matplotlib.patches import FancyArrowPatch

    c = np.asarray(centre, float)
    angles = np.linspace(start, start + sweep, 30)
    pts = c + radius * np.c_[np.cos(angles), np.sin(angles)]
    ax.plot(pts[:-3, 0], pts[:-3, 1], color=colour, lw=1.2)
    ax.add_patch(FancyArrowPatch(pts[-4], pts[-1], arrowstyle="-|>", mutation_scale=10, color=colour, lw=1.2))
    mid = start + sweep / 2
    ax.text(
        *(c + 1.35 * radius * np.array([math.cos(mid), math.sin(mid)])),
        text,
        color=colour,
        fontsize=12,
        ha="center",
        va="center",
        bbox=_BOX,
        zorder=8,
    )


def _frame(ax, origin, axes3, index: int, size: float, plane):
    """The in-plane axes of frame ``index`` at ``origin`` (2-D), labelled at their tips;
    an axis out of the plane as ⊙ (towards the viewer) or ⊗ beside the origin."""
    h, v = plane
    normal = np.cross(np.eye(3)[h], np.eye(3)[v])
    spots = []
    for k in range(3):
        axis = axes3[:, k]
        flat = np.array([axis[h], axis[v]])
        if np.linalg.norm(flat) > 0.5:
            tip = origin + size * flat
            style = dict(arrowstyle="-|>", color=_COLOURS[k], lw=1.3, shrinkA=0, shrinkB=0)
            ax.annotate("", xy=tip, xytext=origin, arrowprops=style)
            ax.text(
                *(origin + 1.22 * size * flat),
                f"${_AXIS_NAMES[k]}_{{{index}}}$",
                color=_COLOURS[k],
                fontsize=11,
                ha="center",
                va="center",
                bbox=_BOX,
                zorder=8,
            )
        else:  # out of the plane: ⊙ / ⊗ beside the origin, away from the in-plane axes
            out = float(axis @ normal) > 0
            spots.append((k, out))
    flats = [np.array([axes3[h, k], axes3[v, k]]) for k in range(3)]
    flats = [math.atan2(f[1], f[0]) for f in flats if np.linalg.norm(f) > 0.5]
    for n, (k, out) in enumerate(spots):

        def gap(a):
            return min((abs((a - b + math.pi) % (2 * math.pi) - math.pi) for b in flats), default=math.pi)

        ups = [math.radians(d) for d in range(0, 181, 45)]  # above the origin: the base is below
        best = max(ups, key=lambda a: (round(gap(a), 3), -abs(a - 2.4)))
        # frames at one origin (frames 0 and 1 of Craig's table): one line apart, odd above even
        spot = origin + size * 0.75 * np.array([math.cos(best), math.sin(best)])
        spot = spot + np.array([0.0, 0.13 * (index % 2) + 0.13 * n])
        ax.text(
            *spot,
            f"${_AXIS_NAMES[k]}_{{{index}}}$" + (" ⊙" if out else " ⊗"),
            color=_COLOURS[k],
            fontsize=9,
            ha="center",
            va="center",
            bbox=_BOX,
            zorder=8,
        )


def _figure(variant: Variant, robot):
    """The matplotlib figure of a planar variant (see the module docstring)."""
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    from ..show import frame_poses

    h, v = _PLANE.get(variant.kind, (0, 1))
    rows, subs = _numeric_rows(variant)
    q = _sample(rows)
    T = np.eye(4)
    joints, rods, axes = [], [], []
    for (r, f, start, end), qi in zip(rows, q):
        T_fixed = T @ _craig(r, 0.0, f)  # the joint's frame before its motion
        T = T @ _craig(r, qi, f)
        joints.append((r, T_fixed, T.copy(), qi))
        rods.append(((T @ np.r_[start, 1.0])[:3], (T @ np.r_[end, 1.0])[:3]))
        axes.append(T[:3, 2])

    def p2(p3):
        return np.array([p3[h], p3[v]])

    fig, ax = plt.subplots(figsize=(6.4, 5.6))
    size = 0.22
    # base
    ax.add_patch(plt.Rectangle((-0.18, -0.1), 0.36, 0.1, hatch="////", fill=False, color="0.3", lw=0.8))
    ax.plot([-0.22, 0.22], [0, 0], color="0.2", lw=1.2)
    # links: from each joint to the next joint, and each rod
    prev = np.zeros(2)
    for i, ((r, T_fixed, T_moved, qi), (a3, b3)) in enumerate(zip(joints, rods), 1):
        at = p2(T_moved[:3, 3])
        if r.kind == "prismatic":
            base = p2(T_fixed[:3, 3])
            ax.plot(*zip(prev, base), color="0.55", lw=5, solid_capstyle="round", zorder=1)
            along = p2(T_moved[:3, 2])
            sleeve = [base - 0.12 * along, base + 0.12 * along]
            ax.plot(*zip(*sleeve), color="0.2", lw=9, solid_capstyle="butt", zorder=2)
            ax.plot(*zip(p2(a3), p2(b3)), color="0.45", lw=4, solid_capstyle="round", zorder=3)
            _dimension(ax, base, at, f"$d_{{{i}}}$", -0.22, colour="#b9770e")  # right: lengths go left
        else:
            ax.plot(*zip(prev, at), color="0.55", lw=5, solid_capstyle="round", zorder=1)
            ax.add_patch(plt.Circle(at, 0.045, facecolor="white", edgecolor="0.1", lw=1.5, zorder=5))
            ax.plot(*zip(p2(a3), p2(b3)), color="0.45", lw=4, solid_capstyle="round", zorder=3)
            ref = p2(T_fixed[:3, 0])  # the line the angle is measured from: x of the joint's frame at rest
            start = math.atan2(ref[1], ref[0])
            sweep = qi if float(T_moved[:3, 2] @ np.cross(np.eye(3)[h], np.eye(3)[v])) > 0 else -qi
            # the line the angle starts from (x0, or the previous link's continued), past its axis label
            ax.plot(*zip(at + (0.33 if i == 1 else 0) * ref, at + 0.5 * ref), color="#7d3c98", lw=0.8, ls="--")
            radius = min(0.4, 0.4 * np.linalg.norm(p2(b3) - p2(a3)) or 0.4)  # inside a short link
            _arc(ax, at, start, sweep, radius, f"$\\theta_{{{i}}}$")
        prev = p2(b3) if r.kind == "revolute" else at
    # frames of the model: the variant's own convention
    poses = frame_poses(robot.bind({s.name: NOMINAL.get(s.name, 1.0) for s in robot.free_symbols()}), np.array(q))
    for index, (name, P) in enumerate(poses.items()):
        _frame(ax, p2(P[:3, 3]), P[:3, :3], index, size, (h, v))
    # masses and gravity
    # lengths: each named length beside the segment it is, its label at the middle or, when
    # a frame's origin is there (at a centre of mass), a third of the way: a turning link's
    # on its left (its angle sweeps on its right), a sliding link's beyond its slide's d
    for i, ((r, *_), (a3, b3)) in enumerate(zip(joints, rods), 1):
        name = r.length
        if sp.Symbol(name) not in subs and name not in dict(variant.lengths):
            continue
        a, b = p2(a3), p2(b3)
        if np.linalg.norm(b - a) > 1e-6:
            value = dict(variant.lengths).get(name)
            text = f"${name[0]}_{{{name[1:]}}}$" + (f" = {value:g} m" if value is not None else "")
            offset = 0.16 if r.kind == "revolute" else -0.5
            origins = [p2(P[:3, 3]) for P in poses.values()]
            where = next(
                (w for w in (0.5, 0.3, 0.7) if min(np.linalg.norm(a + w * (b - a) - o) for o in origins) > 0.3), 0.5
            )
            _dimension(ax, a, b, text, offset, where=where)
    for link, P in poses.items():  # each mass, named by its link (link1 -> m1)
        body = robot.links.get(link)
        if body is None or link == robot.base or sp.sympify(body.mass) == 0 or not link[-1:].isdigit():
            continue
        com = np.array([float(sp.sympify(c).xreplace(subs)) for c in body.com])
        c = p2(P[:3, :3] @ com + P[:3, 3])
        ax.scatter(*c, s=70, color="black", zorder=6)
        ax.text(*(c + np.array([0.08, -0.1])), f"$m_{{{link.lstrip('link')}}}$", fontsize=11, zorder=8, bbox=_BOX)
    ax.set_aspect("equal")
    ax.autoscale()
    x0, x1 = ax.get_xlim()
    y0, y1 = ax.get_ylim()
    x0, x1, y0, y1 = x0 - 0.3, x1 + 0.2, y0 - 0.15, y1 + 0.2
    g = np.array(variant.gravity, float)
    gp = np.array([g[h], g[v]])
    corner = np.array([x0 + 0.25, y1 - 0.25])  # gravity in the top left corner, clear of the arm
    if np.linalg.norm(gp) > 0.5:
        tail = corner - 0.15 * gp
        ax.annotate("", xy=tail + 0.3 * gp, xytext=tail, arrowprops=dict(arrowstyle="-|>", color="black", lw=1.6))
        ax.text(*(corner + np.array([0.08, 0.08])), "$g$", fontsize=12, va="center")
    else:
        ax.text(*corner, "$g$ ⊗ (into the page)", fontsize=10, va="center")
    ax.set_xlim(x0, x1)
    ax.set_ylim(y0, y1)
    ax.axis("off")
    ax.set_title(f"{variant.ident}: the arm at a sample pose, its frames ({variant.convention})", fontsize=10)
    return fig


def _save(variant: Variant, robot, fmt: str, out) -> None:
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    with matplotlib.rc_context({"svg.hashsalt": "armdyn-course", "svg.fonttype": "path", "font.family": "DejaVu Sans"}):
        fig = _figure(variant, robot)
        try:
            meta = {"Date": None, "Creator": None} if fmt == "svg" else None
            fig.savefig(out, format=fmt, bbox_inches="tight", dpi=110, metadata=meta)
        finally:
            plt.close(fig)


def drawing_png(variant: Variant, robot, path) -> None:
    """The drawing as a PNG file (to look at it)."""
    _save(variant, robot, "png", path)


def drawing_uri(variant: Variant, robot) -> str:
    """The drawing as an SVG ``data:`` URI; the spatial arm: :func:`armdyn.course.statement.drawing_uri`."""
    if not variant.spec.planar:
        from .statement import drawing_uri as spatial

        return spatial(variant, robot)
    buf = io.BytesIO()
    _save(variant, robot, "svg", buf)
    return "data:image/svg+xml;base64," + base64.b64encode(buf.getvalue()).decode("ascii")
