"""The statement of a variant: ``problem.md`` (Markdown + LaTeX) and ``problem.html``
(the same text, math as MathML, and a drawing of the arm and its frames).

Both are rendered from one list of blocks, so they say the same thing:
``("h1" | "h2" | "p", text)`` where text may hold inline ``$...$`` LaTeX, ``("math", latex)``
for display math, ``("table", header, rows)`` with cells as text, ``("list", items)``.
The HTML escapes every piece of text, loads nothing (CSP meta), and embeds the drawing
as an SVG ``data:`` URI drawn with a fixed hash salt and no date (byte-reproducible).
"""

from __future__ import annotations

import base64
import io
import re

import sympy as sp

from ..mathml import escape, latex_to_mathml, math_element
from .page import course_page
from .variants import Variant

_NOMINAL_LENGTHS = {"l1": 1.0, "l2": 0.8, "l3": 0.6}


def _tex(x) -> str:
    return sp.latex(sp.sympify(x))


def _vec(v) -> str:
    return r"\begin{pmatrix}" + r" \\ ".join(_tex(c) for c in v) + r"\end{pmatrix}"


def statement_blocks(variant: Variant, model: dict) -> list[tuple]:
    """The statement's blocks (see the module docstring)."""
    spec = variant.spec
    dof = len(spec.rows)
    rows = variant.rows()
    coords = [f"\\theta_{{{i}}}" if r.kind == "revolute" else f"d_{{{i}}}" for i, r in enumerate(rows, 1)]
    out = [("h1", f"Exercise {variant.ident}: the dynamics of {spec.title.split(':')[0]}")]
    out.append(
        ("p", f"The arm is {spec.title}. Its joint coordinates are " + ", ".join(f"${c}$" for c in coords) + ".")
    )
    g = sp.Matrix(variant.gravity) * sp.Symbol("g")
    out.append(("p", f"Gravity, in the base frame 0, is $\\mathbf{{g}} = {_vec(g)}$ (magnitude $g$)."))
    if variant.masses == "point":
        out.append(("p", "Each link is a point mass $m_i$ at its far end (no rotational inertia)."))
    else:
        out.append(
            (
                "p",
                (
                    "Each link is a uniform thin rod of mass $m_i$: its centre of mass is at its middle and "
                    "its inertia about the centre of mass is $m_i \\ell^2/12$ about every axis across it "
                    "(zero along it)."
                ),
            )
        )
    if variant.lengths:
        out.append(
            ("p", "Lengths: " + ", ".join(f"${_tex(sp.Symbol(k))} = {v:g}$ m" for k, v in variant.lengths) + ".")
        )
    out.append(("h2", "Frames"))
    out.append(
        ("p", (f"Use {variant.describe()}; they are exactly the frames of `model.yaml`, which the grader uses."))
    )
    if variant.convention in ("craig", "spong"):
        head = (
            ["$i$", "$\\alpha_{i-1}$", "$a_{i-1}$", "$d_i$", "$\\theta_i$"]
            if variant.convention == "craig"
            else ["$i$", "$a_i$", "$\\alpha_i$", "$d_i$", "$\\theta_i$"]
        )
        table = []
        for i, row in enumerate(model["dh"], 1):
            d = f"{_tex(row['d'])} + d_{{{i}}}" if row["type"] == "prismatic" else _tex(row["d"])
            th = f"{_tex(row['theta'])} + \\theta_{{{i}}}" if row["type"] == "revolute" else _tex(row["theta"])
            d = d.removeprefix("0 + ")
            th = th.removeprefix("0 + ")
            cells = (
                [str(i), f"${_tex(row['alpha'])}$", f"${_tex(row['a'])}$"]
                if variant.convention == "craig"
                else [str(i), f"${_tex(row['a'])}$", f"${_tex(row['alpha'])}$"]
            )
            table.append(cells + [f"${d}$", f"${th}$"])
        out.append(("table", head, table))
        if variant.convention == "spong":
            out.append(
                (
                    "p",
                    (
                        "Write each link's vectors in frame $i$ placed on joint $i$'s axis with $z_i$ along "
                        "it (DH frame $i-1$ turned by joint $i$), as armdyn's model of this table does."
                    ),
                )
            )
        coms = []
        for i, row in enumerate(model["dh"], 1):
            coms.append(f"$p_{{C_{i}}} = {_vec(row['com'])}$")
        out.append(("p", "Centres of mass, each in its row's DH frame: " + ", ".join(coms) + "."))
    else:
        items = []
        for i, j in enumerate(model["joints"], 1):
            xyz = j.get("xyz", [0, 0, 0])
            text = f"joint {i} (${coords[i - 1]}$, {j['type']}) sits at ${_vec(xyz)}$ in frame {i - 1}"
            if "rotation" in j:
                text += (
                    f", its frame turned by $R = {_tex(sp.Matrix(j['rotation']))}$ (columns: its axes in frame {i - 1})"
                )
            text += "; it moves about/along its own z axis"
            if "frame_xyz" in j:
                text += (
                    f"; frame {i} is then moved by ${_vec(j['frame_xyz'])}$ to link {i}'s centre of mass, off "
                    "the joint's axis"
                )
            else:
                text += f"; frame {i} is the joint's frame after the motion"
            items.append(text + ".")
        out.append(("list", items))
    out.append(("h2", "Tasks"))
    out.append(
        (
            "list",
            [
                (
                    "Write the equations of motion by iterating the Newton-Euler equations: the base's "
                    "$\\omega_0, \\dot\\omega_0, \\dot v_0$ (gravity as an upward acceleration of the base), then for each link "
                    "$\\omega_i, \\dot\\omega_i, \\dot v_i, \\dot v_{C_i}, F_i, N_i$ outwards and $f_i, n_i, \\tau_i$ inwards, "
                    "each vector in link $i$'s own frame."
                ),
                (
                    "Check the result with Lagrange's equations: $T$, $V$, $L$, and for each coordinate "
                    "$\\partial L/\\partial \\dot q_i$, its time derivative, $\\partial L/\\partial q_i$ and $\\tau_i$."
                ),
            ],
        )
    )
    out.append(("h2", "Handing in"))
    out.append(("p", "One Markdown file, every equation as display math `$$ ... $$`, with this front matter:"))
    out.append(
        ("code", (f"---\nstudent: {variant.ident}\nvariant: {variant.ident}\nrobot: model.yaml\nmethod: both\n---"))
    )
    out.append(
        (
            "p",
            (
                f"{dof} joints: name the steps as in the textbook (`\\dot v_{{C_1}}`, `F_2`, `\\tau_1`, `T`); "
                "`armdyn grade` checks each one against the method and your own earlier steps."
            ),
        )
    )
    return out


def statement_markdown(blocks: list[tuple]) -> str:
    out = []
    for b in blocks:
        if b[0] == "h1":
            out.append(f"# {b[1]}")
        elif b[0] == "h2":
            out.append(f"## {b[1]}")
        elif b[0] == "p":
            out.append(b[1])
        elif b[0] == "math":
            out.append(f"$${b[1]}$$")
        elif b[0] == "code":
            out.append(f"```\n{b[1]}\n```")
        elif b[0] == "list":
            out.append("\n".join(f"{k}. {item}" for k, item in enumerate(b[1], 1)))
        elif b[0] == "table":
            out.append("| " + " | ".join(b[1]) + " |")
            out[-1] += "\n|" + "---|" * len(b[1])
            out[-1] += "".join("\n| " + " | ".join(r) + " |" for r in b[2])
        out.append("")
    return "\n".join(out).rstrip() + "\n"


_INLINE = re.compile(r"\$([^$]+)\$|`([^`]+)`")


def inline_html(text: str) -> str:
    """Text with ``$latex$`` as MathML and ```code``` as <code>, the rest escaped."""
    out, at = [], 0
    for m in _INLINE.finditer(text):
        out.append(escape(text[at : m.start()]))
        if m.group(1) is not None:
            mml = latex_to_mathml(m.group(1))
            out.append(math_element(mml) if mml is not None else f"<code>{escape(m.group(1))}</code>")
        else:
            out.append(f"<code>{escape(m.group(2))}</code>")
        at = m.end()
    out.append(escape(text[at:]))
    return "".join(out)


def markdown_blocks(text: str) -> list[tuple]:
    """The blocks of a Markdown file as ``exercise make`` writes it (a statement or a
    solution: headings, paragraphs, display math, code, numbered lists, tables, ``**stage**``
    lines), the front matter skipped; :func:`statement_blocks` makes the same blocks."""
    blocks: list[tuple] = []
    lines = text.splitlines()
    if lines and lines[0] == "---" and "---" in lines[1:]:
        lines = lines[lines.index("---", 1) + 1 :]
    i = 0
    while i < len(lines):
        line = lines[i]
        if not line.strip():
            i += 1
        elif line.startswith("```"):
            j = i + 1
            while j < len(lines) and not lines[j].startswith("```"):
                j += 1
            blocks.append(("code", "\n".join(lines[i + 1 : j])))
            i = j + 1
        elif line.startswith("## "):
            blocks.append(("h2", line[3:].strip()))
            i += 1
        elif line.startswith("# "):
            blocks.append(("h1", line[2:].strip()))
            i += 1
        elif line.startswith("|"):
            rows = []
            while i < len(lines) and lines[i].startswith("|"):
                cells = [c.strip() for c in lines[i].strip().strip("|").split("|")]
                if not all(re.fullmatch(r"-+", c) for c in cells):
                    rows.append(cells)
                i += 1
            blocks.append(("table", rows[0], rows[1:]))
        elif re.match(r"\d+\. ", line):
            items = []
            while i < len(lines) and re.match(r"\d+\. ", lines[i]):
                items.append(lines[i].split(". ", 1)[1])
                i += 1
            blocks.append(("list", items))
        elif line.startswith("**") and line.rstrip().endswith("**") and len(line.strip()) > 4:
            blocks.append(("p", line.strip().strip("*")))
            i += 1
        elif line.startswith("$$") and line.rstrip().endswith("$$") and len(line.strip()) > 4:
            blocks.append(("math", line.strip()[2:-2]))
            i += 1
        else:
            para = []
            while i < len(lines) and lines[i].strip() and not lines[i].startswith(("#", "|", "```", "$$")):
                para.append(lines[i].strip())
                i += 1
            if not para:  # a line no rule above takes: shown as text
                para.append(lines[i].strip())
                i += 1
            blocks.append(("p", " ".join(para)))
    return blocks


def statement_body(blocks: list[tuple], drawing_uri: str | None, level: int = 1) -> tuple[str, str]:
    """(title, HTML) of the blocks, headings from ``<h{level}>`` down (a page: 1; a
    statement inside another page, as ``armdyn serve``'s, deeper)."""
    body = []
    title = "Exercise"
    for b in blocks:
        if b[0] == "h1":
            title = b[1]
            body.append(f"<h{level}>{inline_html(b[1])}</h{level}>")
            if drawing_uri:
                body.append(
                    f'<img class="chart" alt="the arm at a sample pose: its joints, angles, slides, lengths and frames '
                    f'(x red, y green, z blue)" '
                    f'src="{escape(drawing_uri)}">'
                )
        elif b[0] == "h2":
            body.append(f"<h{level + 1}>{inline_html(b[1])}</h{level + 1}>")
        elif b[0] == "p":
            body.append(f"<p>{inline_html(b[1])}</p>")
        elif b[0] == "math":
            mml = latex_to_mathml(b[1])
            body.append(math_element(mml, display=True) if mml else f"<pre>{escape(b[1])}</pre>")
        elif b[0] == "code":
            body.append(f"<pre>{escape(b[1])}</pre>")
        elif b[0] == "list":
            body.append("<ol>" + "".join(f"<li>{inline_html(x)}</li>" for x in b[1]) + "</ol>")
        elif b[0] == "table":
            head = "".join(f"<th>{inline_html(h)}</th>" for h in b[1])
            rows = "".join("<tr>" + "".join(f"<td>{inline_html(c)}</td>" for c in r) + "</tr>" for r in b[2])
            body.append(f'<table class="grid"><tr>{head}</tr>{rows}</table>')
    return title, "\n".join(body)


def statement_html(blocks: list[tuple], drawing_uri: str | None) -> str:
    return course_page(*statement_body(blocks, drawing_uri))


def drawing_uri(variant: Variant, robot) -> str:
    """The arm at a sample pose, its frames and joint axes in 3-D (armdyn.show's picture),
    as an SVG ``data:`` URI: the spatial arm's drawing (:mod:`.drawing` draws the planar
    ones). Symbolic lengths are drawn at nominal values."""
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt
    import numpy as np

    from ..show import draw_on, frame_poses, view_of

    bound = robot.bind({s.name: _NOMINAL_LENGTHS.get(s.name, 1.0) for s in robot.free_symbols()})
    q = np.array([0.5 if j.type == "revolute" else 0.4 for j in robot.movable_joints])
    poses = frame_poses(bound, q)
    origins = np.array([T[:3, 3] for T in poses.values()])
    with matplotlib.rc_context({"svg.hashsalt": "armdyn-course", "svg.fonttype": "path"}):
        fig = plt.figure(figsize=(5.5, 5.5))
        try:
            ax = fig.add_subplot(projection="3d")
            draw_on(ax, bound, poses, f"{variant.ident}: frames at a sample pose", view_of(origins))
            if variant.spec.planar and variant.gravity != (0, 0, -1):
                ax.view_init(elev=90, azim=-90)  # the arm's plane is x0-y0: seen from above
                ax.set_zticks([])
                ax.set_zlabel("")
            buf = io.BytesIO()
            fig.savefig(buf, format="svg", bbox_inches="tight", metadata={"Date": None, "Creator": None})
        finally:
            plt.close(fig)
    return "data:image/svg+xml;base64," + base64.b64encode(buf.getvalue()).decode("ascii")
