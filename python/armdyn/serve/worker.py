"""A grading process: the only place the server evaluates a student's text.

Started by :class:`armdyn.serve.pool.Pool` as ``python -m armdyn.serve.worker``. It
limits its own address space (``RLIMIT_AS``; the time limit is the pool's: it kills a
worker that overruns), imports armdyn once, says ``{"ready": ...}``,
then answers one JSON line on stdout for each JSON line on stdin:

    {"kind": "grade", "exercise": "rp-arm" | null, "markdown": "..."}
      -> {"ok": true, "graded_as", "passed", "first_wrong", "error", "report_json",
          "report_html", "report_fragment"}       (error: the student's input error)
      -> {"ok": false, "reason": "..."}           (grading itself failed: no verdict)

A submission that names no model (no exercise in the request, no ``robot:``) is graded
against the robot its text describes, with a warning when that differs from the served
variant its front matter's ``variant:`` names (see :mod:`armdyn.grading.robot_text.assigned`).
    {"kind": "preview", "exercise": ..., "markdown": "..."}
      -> {"ok": true, "html": "<ol>...</ol>"}     (each equation as read: sanitized MathML)

The exercises it may load come from ``ARMDYN_SERVE_EXERCISES`` (JSON id -> bundled name
or model path, the server's whitelist): an exercise named in the request or in the
front matter that is not there is the student's error, never a path to open.
"""

from __future__ import annotations

import json
import os
import resource
import signal
import sys

SUBMISSION = "submission.md"  # the name reports show; nothing is read from or written to it
#: graded once before saying ready, so that the first student does not wait for the
#: lazy imports and caches of the grader, the LaTeX reader and the HTML report
WARM_UP = "$$\\omega_1^1 = \\begin{pmatrix} 0 \\\\ 0 \\\\ \\dot{\\theta}_1 \\end{pmatrix}$$\n$$\\tau_1 = 0$$\n"
MAX_PREVIEW_EQUATIONS = 200
#: ``graded_as`` of a submission graded against the robot its own text describes
FROM_TEXT = "(read from the text)"


def limit_memory(memory_mb: int) -> None:
    """Cap this process's address space: a runaway grading ends in MemoryError (reported
    as a failed grading) instead of starving the machine."""
    if memory_mb > 0:
        cap = memory_mb * 1024 * 1024
        resource.setrlimit(resource.RLIMIT_AS, (cap, cap))


class Grader:
    """Grades and previews against the whitelisted exercises (models loaded once each)."""

    def __init__(self, exercises: dict[str, str]):
        self.exercises = exercises
        self._robots: dict = {}

    def robot(self, name: str | None):
        from ..errors import ModelError
        from ..io import load

        if not name:
            raise ModelError(
                "no exercise chosen: choose one on the page, add ?robot=ID, or write "
                "'robot: rp-arm' in the front matter",
                source=SUBMISSION,
            )
        if name not in self.exercises:
            known = ", ".join(sorted(self.exercises)[:12])
            raise ModelError(f"unknown exercise '{name[:64]}' (this server grades: {known})", source=SUBMISSION)
        if name not in self._robots:
            source = self.exercises[name]
            if os.path.splitext(source)[1].lower() not in ("", ".yaml", ".yml"):
                # a bundled name or a variant's model.yaml; never a .xacro (it runs code) or other file
                raise ModelError(f"exercise '{name}' is not a YAML model; this server grades YAML models only")
            self._robots[name] = load(source, strict=False)
        return self._robots[name]

    def named(self, markdown: str, robot: str | None) -> str | None:
        """The exercise a submission's front matter names: its ``variant:`` when that is
        a served variant (``armdyn exercise make`` writes ``robot: model.yaml`` beside
        it), else its ``robot:``."""
        from ..grading.reader import safe_yaml

        if markdown.startswith("---"):
            end = markdown.find("\n---", 3)
            meta = safe_yaml(markdown[3:end], SUBMISSION) if end > 0 else None
            variant = meta.get("variant") if isinstance(meta, dict) else None
            if isinstance(variant, str) and variant in self.exercises:
                return variant
        return robot

    def from_text(self, sub, variant: str | None):
        """A submission that names no model (no exercise chosen, no ``robot:``): graded
        against the robot its text describes, warned when that differs from the served
        variant its front matter names (graded against that one when the text's cannot be
        read). ``(graded_as, report)``; graded_as ``FROM_TEXT`` for the text's robot."""
        from ..grading import grade
        from ..grading.robot_text.assigned import model_for

        assigned = self.robot(variant) if variant else None  # only a whitelisted exercise
        model, notes = model_for(sub, assigned, f"exercise {variant}" if variant else None)
        report = grade(sub, robot=model)
        report.notes[:0] = notes
        return (variant if model is not None and model is assigned else FROM_TEXT), report

    def grade(self, markdown: str, exercise: str | None) -> dict:
        from ..errors import ModelError
        from ..grading import grade
        from ..grading.html import report_body  # built once, wrapped twice (saves ~0.4 s CPU)
        from ..grading.reader import read_markdown
        from ..htmlpage import fragment, page

        try:
            sub = read_markdown(SUBMISSION, markdown)
            name = exercise or self.named(markdown, sub.robot)
            if exercise is None and sub.robot is None:
                name, report = self.from_text(sub, name)
            else:
                report = grade(sub, robot=self.robot(name))
        except (ModelError, ValueError, RecursionError) as err:
            return {
                "ok": True,
                "graded_as": exercise,
                "passed": False,
                "first_wrong": None,
                "error": " ".join(str(err).split())[:2000],
                "report_json": None,
                "report_html": None,
                "report_fragment": None,
            }
        body = report_body(report)
        return {
            "ok": True,
            "graded_as": name,
            "passed": bool(report.passed),
            "first_wrong": report.first_wrong,
            "error": None,
            "report_json": report.to_json(),
            "report_html": page(f"armdyn grade: {report.submission}", body),  # = grade.html.report_html
            "report_fragment": fragment(body),
        }  # = grade.html.repr_html

    def preview(self, markdown: str, exercise: str | None) -> dict:
        from ..errors import ModelError
        from ..grading.notation import SymbolMap, parse_lhs
        from ..grading.reader import read_markdown
        from ..mathml import escape, latex_to_mathml, math_element

        try:
            sub = read_markdown(SUBMISSION, markdown)
        except (ModelError, ValueError) as err:
            return {"ok": True, "html": f'<p class="error">{escape(str(err))}</p>'}
        try:
            coordinate_of = SymbolMap(
                self.robot(exercise or self.named(markdown, sub.robot)), sub.symbols
            ).coordinate_of
        except Exception:  # noqa: BLE001 - no model: show the equations without step names
            coordinate_of = None
        items = []
        for eq in sub.equations[:MAX_PREVIEW_EQUATIONS]:
            value = eq.value
            if isinstance(value, list):
                value = "\\begin{pmatrix}" + " \\\\ ".join(str(v) for v in value) + "\\end{pmatrix}"
            latex = f"{eq.lhs} = {value}"
            inner = latex_to_mathml(latex) if eq.latex else None
            shown = math_element(inner, display=True) if inner is not None else f"<code>{escape(latex)}</code>"
            step = None
            if coordinate_of is not None:
                try:
                    ref = parse_lhs(eq.lhs, coordinate_of)
                    step = ref.name if ref is not None else None
                except Exception:  # noqa: BLE001 - an unreadable left side is simply not a step
                    step = None
            tag = f'<span class="step">{escape(step)}</span>' if step else '<span class="step none">not a step</span>'
            items.append(f'<li><span class="line">line {eq.line}</span>{tag}{shown}</li>')
        more = len(sub.equations) - MAX_PREVIEW_EQUATIONS
        tail = f"<p>… and {more} more equations</p>" if more > 0 else ""
        if not items:
            return {"ok": True, "html": '<p class="empty">No equation yet: write display math, $$ ... $$</p>'}
        return {"ok": True, "html": f'<ol class="preview">{"".join(items)}</ol>{tail}'}


def serve(stdin, out) -> None:
    """Answer requests from ``stdin`` on ``out`` until stdin closes."""
    grader = Grader(json.loads(os.environ.get("ARMDYN_SERVE_EXERCISES", "{}")))
    if "rp-arm" in grader.exercises:
        grader.grade(WARM_UP, "rp-arm")
        grader.preview(WARM_UP, "rp-arm")

    print(json.dumps({"ready": True, "pid": os.getpid()}), file=out, flush=True)
    for line in stdin:
        try:
            req = json.loads(line)
            kind = req.get("kind")
            if kind == "grade":
                reply = grader.grade(req["markdown"], req.get("exercise"))
            elif kind == "preview":
                reply = grader.preview(req["markdown"], req.get("exercise"))
            else:
                reply = {"ok": False, "reason": f"unknown request {kind!r}"}
        except MemoryError:
            reply = {"ok": False, "reason": "memory limit reached while grading"}
        except Exception as err:  # noqa: BLE001 - a bug of the grader: no verdict, say so
            reply = {"ok": False, "reason": f"internal error: {type(err).__name__}: {err}"[:500]}
        print(json.dumps(reply), file=out, flush=True)


def main() -> None:
    # a Ctrl-C in the terminal reaches the whole process group: the server stops its
    # workers (closing their pipes), a worker does not die of it with a traceback
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    # the protocol owns the real stdout; anything a library prints goes to stderr
    out = os.fdopen(os.dup(1), "w", encoding="utf-8")
    os.dup2(2, 1)
    limit_memory(int(os.environ.get("ARMDYN_SERVE_MEMORY_MB", "2048")))
    serve(sys.stdin, out)


if __name__ == "__main__":
    main()
