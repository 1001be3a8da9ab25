"""Bar charts for course pages, as ``data:`` URIs of SVG (byte-reproducible).

Matplotlib's SVG writer is made deterministic with a fixed ``svg.hashsalt`` (the ids of
clip paths) and no ``Date`` metadata; the text is drawn as paths (``svg.fonttype: path``)
so that the page needs no font.
"""

from __future__ import annotations

import base64
import io


def bar_chart_uri(
    labels: list[str], values: list[int], title: str, xlabel: str, ylabel: str, color: str = "#b42318"
) -> str:
    """A horizontal bar chart (one bar per label, top to bottom in the given order) as a
    ``data:image/svg+xml;base64,...`` URI."""
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    with matplotlib.rc_context(
        {"svg.hashsalt": "armdyn-course", "svg.fonttype": "path", "font.family": "DejaVu Sans", "font.size": 10}
    ):
        n = max(len(labels), 1)
        fig, ax = plt.subplots(figsize=(7.0, 0.9 + 0.34 * n))
        try:
            ys = list(range(len(labels)))[::-1]
            ax.barh(ys, values, color=color, height=0.62)
            ax.set_yticks(ys, labels)
            ax.set_xlabel(xlabel)
            ax.set_ylabel(ylabel)
            ax.set_title(title, loc="left", fontsize=11)
            top = max(values, default=0)
            ax.set_xlim(0, max(1, top) * 1.12)
            ax.xaxis.get_major_locator().set_params(integer=True)
            for y, v in zip(ys, values):
                ax.text(v + max(1, top) * 0.01, y, str(v), va="center", fontsize=9)
            for side in ("top", "right"):
                ax.spines[side].set_visible(False)
            fig.tight_layout()
            buf = io.BytesIO()
            fig.savefig(buf, format="svg", metadata={"Date": None, "Creator": None})
        finally:
            plt.close(fig)
    return "data:image/svg+xml;base64," + base64.b64encode(buf.getvalue()).decode("ascii")
