"""Grade a whole class: ``armdyn grade DIR --gradebook grades.csv``.

    result = grade_class("submissions/", "grades.csv", variants="exercise/", rubric=Rubric.default(),
                         html_dir="reports/", jobs=2)
    result.gradebook.rows; result.not_graded      # lines "file: why", one per submission not graded

Every ``*.md``, ``*.yaml``, ``*.yml`` file directly in the folder is a submission
(symbolic links are skipped, with a note). Its student is the file's stem, never what
the text says (a front matter ``student:`` that differs gets a note); its variant the
roster's (``variants/<student>/``) when there is one, else the front matter's
``variant:``. With ``variants`` (the folder ``armdyn exercise make`` wrote) each
submission is graded against ``variants/<variant>/model.yaml``; a submission whose
variant is not there is not graded (status ``no-variant``); one whose front matter names
no ``robot:`` is graded against the robot its text describes, with a warning in its
report when that differs from the variant's (:mod:`armdyn.grading.robot_text.assigned`;
the variant's when the text's cannot be read); its exercise kind is the variant folder's
``variant.yaml`` (:func:`.exercise.variant_kind`), and without a ``rubric`` it is scored
with that kind's ``rubric-<kind>.yaml``. Without ``variants``, against the
front matter's ``robot:``: a bundled name or a file directly in the folder (never a
``.xacro`` file: models are loaded untrusted). A second file for the same student, or
one whose report would have the same file name (``a b`` and ``a_b``), is not graded
(``duplicate``, naming both files; the student keeps one row, :mod:`.gradebook`). An empty
file, or one with nothing after its front matter, is not graded (``error``, saying so).

Each submission is graded in its own forked child (:mod:`.isolate`) with a time and
memory limit; one that times out, runs out of memory or crashes is reported as such
and loses no one else's result. Results are cached in ``.armdyn-cache/`` beside the
gradebook, keyed by a hash of the submission's bytes, the model's bytes, the rubric,
armdyn's version and the grader's source: a re-run grades only what changed.

Outputs (each written all or nothing): the gradebook CSV, the same as JSON beside it
(``grades.json``), ``summary.html`` beside it, and with ``html_dir`` one report per
student (``<student>.html``).
"""

from __future__ import annotations

import hashlib
import json
import os
import re
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

from ..errors import ModelError
from .exercise import rubric_path, variant_kind
from .gradebook import Gradebook
from .rubric import Rubric

SUFFIXES = (".md", ".yaml", ".yml")
CACHE_DIR = ".armdyn-cache"


@dataclass
class Task:
    """One submission to grade (JSON-able: it crosses to the child and to Dask workers)."""

    path: str
    student: str
    variant: str | None
    robot: str | None
    want_html: bool
    from_text: bool = False  # names no model: graded against its text's, robot the assigned one to compare
    kind: str | None = None  # the exercise kind (variant.yaml of its variant folder), None when not known


@dataclass
class BatchResult:
    """The gradebook, one line per submission not graded (``file: status: why``),
    how many were taken from the cache, the seconds it took, and notes (``file: what``:
    a link skipped, a front matter overruled, a warm-up given up)."""

    gradebook: Gradebook
    not_graded: list[str] = field(default_factory=list)
    cached: int = 0
    seconds: float = 0.0
    notes: list[str] = field(default_factory=list)


# ------------------------------------------------------------------ one submission
def grade_task(task: dict) -> dict:
    """Grade one submission (runs in the child): ``{"report": grade JSON, "html": page}``
    or ``{"error": "error: file:line: what"}`` for a submission the grader refuses. Each
    wrong step whose kind :mod:`.slipkinds` reads from its values gets ``slip_kind``."""
    from ..grading import grade

    try:
        if task.get("from_text"):
            report = _graded_from_text(task)
        else:
            report = grade(task["path"], robot=task["robot"])
    except (ModelError, ValueError, OSError) as exc:
        return {"error": "error: " + " ".join(str(exc).split())}
    out = {"report": json.loads(report.to_json())}
    from .slipkinds import slip_kinds

    for k, kind in slip_kinds(report).items():  # read from the values, where the message is vague
        out["report"]["steps"][k]["slip_kind"] = kind
    if task["want_html"]:
        from ..grading.html import report_html

        out["html"] = report_html(report)
    return out


def _graded_from_text(task: dict):
    """A submission that names no model, in a class with variants: graded against the robot
    its text describes, warned when that differs from the assigned variant's model (which
    it is graded against when the text's cannot be read)."""
    from ..grading import grade
    from ..grading.reader import read
    from ..grading.robot_text.assigned import model_for
    from ..io import load

    sub = read(task["path"])
    assigned = load(task["robot"], strict=False)  # the course's model.yaml: a YAML file, never .xacro
    model, notes = model_for(sub, assigned, f"variant {task['variant']}")
    report = grade(sub, robot=model)
    report.notes[:0] = notes
    return report


def _dask_task(task: dict, timeout: float, memory_mb: int | None) -> dict:
    from .isolate import run_isolated

    return run_isolated(grade_task, task, timeout, memory_mb)


# ------------------------------------------------------------------ finding submissions
def _front_matter(path: str) -> tuple[dict, str | None]:
    """The submission's front matter (Markdown) or top-level mapping (YAML), and why the
    file cannot be graded at all (too large, not UTF-8: ``path:line: what``) or None.
    A front matter that does not parse gives {} (the grader then says why). Read as the
    grader reads it: the one bounded reader, YAML through the alias and depth screen."""
    from ..grading.reader import read_text, safe_yaml

    try:
        text = read_text(path)
    except ModelError as exc:
        return {}, str(exc)
    if not text.strip():
        return {}, f"{path}: the file is empty"
    if path.lower().endswith(".md"):
        from ..grading.display import front_matter

        front = front_matter(text)  # after blank lines or comments too, as the grader reads it
        if front is None or front[1] < 0:
            return {}, None
        if not text[front[1] :].lstrip("-").strip():
            return {}, f"{path}: the file is empty after its front matter (no derivation)"
        text = text[front[0] : front[1]]
    try:
        data = safe_yaml(text, path)
    except (ModelError, RecursionError, ValueError):
        return {}, None
    return (data if isinstance(data, dict) else {}), None


def _name(value) -> str | None:
    if value is None or isinstance(value, (dict, list)):
        return None
    text = " ".join(str(value).split())
    return text[:200] or None


def safe_file_name(student: str) -> str:
    """A file name for a student's report: unsafe characters become ``_``."""
    name = re.sub(r"[^A-Za-z0-9._-]", "_", student)[:100].lstrip(".")
    return name or "_"


@dataclass
class Found:
    """What :func:`discover` found: the tasks, the rows of submissions that cannot be
    graded (``(student, variant, error)``) and notes (``file: what``) on what was
    skipped or overruled."""

    tasks: list[Task]
    refused: list[tuple]
    notes: list[str]


def discover(folder, variants=None, want_html: bool = False) -> Found:
    """The submissions of ``folder`` (see the module docstring). A student is the file's
    name: the text cannot speak for someone else (``student:`` in the front matter is
    only compared, with a note when it differs); nor pick another student's variant
    when the roster made one for this student. Symbolic links are not followed."""
    folder = os.fspath(folder)
    if not os.path.isdir(folder):
        raise ModelError("not a folder of submissions", source=folder)
    tasks, refused, notes, owner, reports = [], [], [], {}, {}
    for f in sorted(os.listdir(folder)):
        path = os.path.join(folder, f)
        if not f.lower().endswith(SUFFIXES) or f.startswith("."):
            continue
        if os.path.islink(path):
            notes.append(f"{path}: a symbolic link, not followed (skipped)")
            continue
        if not os.path.isfile(path):
            continue
        meta, unreadable = _front_matter(path)
        student = os.path.splitext(f)[0]
        claimed = _name(meta.get("student"))
        if claimed is not None and claimed != student:
            notes.append(f"{path}: the front matter says student {claimed!r}; graded as {student!r} (the file's name)")
        variant = _name(meta.get("variant"))
        if unreadable:
            refused.append((student, variant, f"error: {unreadable}"))
            continue
        robot, from_text, kind = None, False, None
        if variants is not None:
            own = student if os.path.isdir(os.path.join(variants, student)) else None
            if own is not None and variant not in (None, own):
                notes.append(
                    f"{path}: the front matter says variant {variant!r}; graded against {own!r} (the roster's)"
                )
            variant = own or variant
            model = os.path.join(variants, variant, "model.yaml") if variant else None
            if variant is None or "/" in variant or variant.startswith(".") or not os.path.isfile(model):
                what = (
                    f"no variant {variant!r} in {variants}"
                    if variant
                    else f"no variant for student {student!r} (no variant: in the front matter, no folder {student!r})"
                )
                refused.append((student, variant, f"no-variant: {path}: {what}"))
                continue
            robot = model
            from_text = _name(meta.get("robot")) is None
            kind = variant_kind(os.path.join(variants, variant))
        else:
            robot, why = _class_model(folder, _name(meta.get("robot")))
            if why:
                refused.append((student, variant, f"error: {path}: {why}"))
                continue
        report = safe_file_name(student).casefold()  # one file on a case-blind disk too
        if student in owner:
            why = f"duplicate: {path}: student {student!r} also handed in {owner[student]} (graded that one)"
            refused.append((student, variant, why))
            continue
        if report in reports:
            why = (
                f"duplicate: {path}: its report would be {safe_file_name(student)}.html, as for "
                f"{reports[report]} (graded that one; rename one of the two files)"
            )
            refused.append((student, variant, why))
            continue
        owner[student], reports[report] = path, path
        tasks.append(Task(path, student, variant, robot, want_html, from_text, kind))
    return Found(tasks, refused, notes)


def _class_model(folder: str, name: str | None) -> tuple[str | None, str | None]:
    """(the model a submission of the class names, why it cannot be used): a bundled
    name, or a regular file directly in the class folder (no path, no link: a student's
    text does not choose which of the grader's files are read). None: the grader says
    that no robot is named."""
    from ..io import bundled_files

    if name is None or name in bundled_files():
        return name, None
    path = os.path.join(folder, name)
    if any(c in name for c in "/\\") or name.startswith(".") or os.path.islink(path) or not os.path.isfile(path):
        return None, (
            f"robot {name!r}: in class grading a model is a bundled name or a file directly in the class folder"
        )
    return os.path.abspath(path), None


# ------------------------------------------------------------------ cache
def _grader_fingerprint() -> str:
    """armdyn's version and a hash of the grader's source and of :mod:`.slipkinds` (a
    changed grader re-grades)."""
    from .. import __version__

    h = hashlib.sha256(__version__.encode())
    root = Path(__file__).resolve().parent.parent / "grading"  # the grader's package (robot_text, proofs too)
    for p in sorted(root.rglob("*.py")):
        h.update(p.relative_to(root).as_posix().encode())
        h.update(p.read_bytes())
    h.update((Path(__file__).resolve().parent / "slipkinds.py").read_bytes())  # its kinds are in the result
    return h.hexdigest()


def _file_bytes(path: str | None) -> bytes:
    from ..io.textfile import MODEL_MAX_BYTES, read_bytes

    try:
        return read_bytes(path, "file", MODEL_MAX_BYTES) if path and os.path.exists(path) else b""
    except ModelError:
        return b""


def cache_key(task: Task, rubric: Rubric, grader: str) -> str:
    h = hashlib.sha256()
    for part in (
        _file_bytes(task.path),
        _file_bytes(task.robot),
        (task.robot or "").encode(),
        rubric.fingerprint().encode(),
        grader.encode(),
        b"html" if task.want_html else b"",
        b"from-text" if task.from_text else b"",
    ):
        h.update(hashlib.sha256(part).digest())
    return h.hexdigest()


# ------------------------------------------------------------------ the class
def grade_class(
    folder,
    gradebook,
    rubric: Rubric | None = None,
    html_dir=None,
    jobs: int | None = None,
    variants=None,
    timeout: float = 60.0,
    memory_mb: int | None = 1024,
    use_cache: bool = True,
    dask: str | None = None,
    progress: bool | None = None,
    policy: str = "latest",
) -> BatchResult:
    """Grade every submission in ``folder`` and write the gradebook (see the module docstring).
    ``rubric``: one rubric for every student; None: with ``variants`` each student's
    kind's ``rubric-<kind>.yaml`` there (:func:`.exercise.rubric_path`), else the default.
    ``policy``: which submission a student who handed in twice is graded on
    (:data:`.gradebook.POLICIES`)."""
    from .._io_atomic import atomic_writes
    from .summary import summary_html

    t0 = time.perf_counter()
    gradebook = os.fspath(gradebook)
    if variants is not None and not os.path.isdir(variants):
        raise ModelError("not a folder of variants (the output of armdyn exercise make)", source=os.fspath(variants))
    found = discover(folder, variants, want_html=html_dir is not None)
    tasks, refused, notes = found.tasks, found.refused, list(found.notes)
    rubrics = {}
    if rubric is None and variants is not None:  # each kind its own rubric, when exercise make wrote it
        for kind in sorted({t.kind for t in tasks if t.kind}):
            if os.path.isfile(rubric_path(variants, kind)):
                rubrics[kind] = Rubric.load(rubric_path(variants, kind))
    rubric = rubric or Rubric.default()
    out_dir = os.path.dirname(os.path.abspath(gradebook))
    cache_dir = os.path.join(out_dir, CACHE_DIR)
    grader = _grader_fingerprint()
    keys = {t.path: cache_key(t, rubrics.get(t.kind, rubric), grader) for t in tasks}
    results: dict[str, dict] = {}
    todo = []
    for t in tasks:
        hit = _cache_get(cache_dir, keys[t.path]) if use_cache else None
        if hit is not None:
            results[t.path] = hit
        else:
            todo.append(t)
    cached = len(results)
    jobs = jobs or os.cpu_count() or 1
    bar = _bar(len(todo), progress)
    try:
        for path, result in _run(todo, jobs, timeout, memory_mb, dask, notes):
            results[path] = result
            deterministic = "report" in result or str(result.get("error", "")).startswith("error:")
            if use_cache and deterministic:
                _cache_put(cache_dir, keys[path], result)
            if bar is not None:
                bar.update(1)
    finally:
        if bar is not None:
            bar.close()

    items, not_graded = [], []
    for t in tasks:
        r = results[t.path]
        items.append((t.student, t.variant, r.get("report"), r.get("error"), t.kind))
        if "report" not in r:
            not_graded.append(_why(t.path, r.get("error") or "crashed: no result"))
    for student, variant, error in refused:
        ok = variants and variant and "/" not in variant and not variant.startswith(".")
        kind = variant_kind(os.path.join(variants, variant)) if ok else None
        items.append((student, variant, None, error, kind))
        not_graded.append(_why(None, error))
    book = Gradebook.from_results(items, rubric=rubric, policy=policy, rubrics=rubrics)

    outputs = [
        (gradebook, book.to_csv()),
        (os.path.splitext(gradebook)[0] + ".json", book.to_json()),
        (os.path.join(out_dir, "summary.html"), summary_html(book)),
    ]
    if html_dir is not None:
        os.makedirs(html_dir, exist_ok=True)
        for t in tasks:
            r = results[t.path]
            page = r.get("html") or _not_graded_page(t.student, r.get("error") or "not graded")
            outputs.append((os.path.join(html_dir, safe_file_name(t.student) + ".html"), page))
    atomic_writes([(p, _text_writer(text)) for p, text in outputs])
    return BatchResult(
        gradebook=book, not_graded=not_graded, cached=cached, seconds=time.perf_counter() - t0, notes=notes
    )


def _why(path: str | None, error: str) -> str:
    """``status: what`` as one line for stderr: ``file[:line]: what (status)``."""
    status, _, rest = error.partition(": ")
    if path and path not in rest:
        rest = f"{path}: {rest}"
    return f"{rest} ({status})"


def _text_writer(text: str):
    def write(tmp):
        with open(tmp, "w", encoding="utf-8", newline="\n") as fh:
            fh.write(text)

    return write


def _not_graded_page(student: str, error: str) -> str:
    from ..mathml import escape
    from .page import course_page

    return course_page(f"{student}: not graded", f"<h1>{escape(student)}: not graded</h1>\n<p>{escape(error)}</p>")


def _run(tasks: list[Task], jobs: int, timeout: float, memory_mb, dask: str | None, notes: list[str]):
    """Yield ``(path, result)`` per task, locally (forked children) or on a Dask cluster;
    a warm-up given up is added to ``notes``."""
    if not tasks:
        return
    if dask:
        try:
            from distributed import Client, as_completed
        except ImportError:
            raise ModelError("--dask needs the 'distributed' package (pip install armdyn[dask])") from None
        with Client(dask) as client:
            futures = {client.submit(_dask_task, t.__dict__, timeout, memory_mb, pure=False): t.path for t in tasks}
            for fut in as_completed(futures):
                try:
                    result = fut.result()
                except Exception as exc:  # noqa: BLE001 - a lost worker loses one result, not the batch
                    result = {"error": f"crashed: {type(exc).__name__}: {exc}"}
                yield futures[fut], result
        return
    # import the grader once here: every forked child starts with it loaded
    import armdyn.grading
    import armdyn.grading.html  # noqa: F401

    from .isolate import ChildPool

    notes.extend(_warm_up(tasks, jobs, timeout, memory_mb))
    pool = ChildPool(grade_task, jobs, timeout, memory_mb)
    yield from pool.run((t.path, t.__dict__) for t in tasks)


#: a model shared by at least this many submissions is warmed up in the parent first
WARM_SHARED = 3
#: at most this many models are warmed up
WARM_MODELS = 4


def _warm_one(model: str) -> dict:
    """Grade armdyn's own solution of ``model`` (derive it, grade it, typeset the
    report): what fills the derivation's and the report's caches. ``{"ok": True}``, or
    ``{"error": why}``."""
    import tempfile

    from ..grading import grade, text  # noqa: F401 - text: to_json's module, loaded here once
    from ..grading.html import report_html
    from ..io import load
    from .solution import solution_markdown, solution_steps

    try:
        robot = load(model, strict=False)
        markdown = solution_markdown(robot, solution_steps(robot), {"method": "both"}, "warm-up")
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "solution.md")
            with open(path, "w", encoding="utf-8") as fh:
                fh.write(markdown)
            report = grade(path, robot=robot)
            report.to_json()
            report_html(report)
    except Exception as exc:  # noqa: BLE001 - a warm-up that fails only costs time
        return {"error": f"error: {' '.join(str(exc).split())[:200]}"}
    return {"ok": True}


def _warm_up(tasks: list[Task], jobs: int, timeout: float, memory_mb) -> list[str]:
    """Warm up, in the parent, each model that many submissions share, so that the
    children fork with the derivation's and the report's caches warm (the expected
    values they show are the same for the whole class). A model (a student's file too)
    can be large: each is first warmed up in a child under a submission's time and
    memory limits (:class:`.isolate.ChildPool`), and only one that finished there is
    warmed up here; the others are left to each submission's own child. Returns a note
    per model given up."""
    import collections

    from .isolate import ChildPool

    counts = collections.Counter(t.robot for t in tasks if t.robot)
    shared = [m for m, n in counts.most_common(WARM_MODELS) if n >= WARM_SHARED]
    notes = []
    for model, result in ChildPool(_warm_one, jobs, timeout, memory_mb).run((m, m) for m in shared):
        if result.get("ok"):
            _warm_one(model)
        else:
            why = result.get("error", "no result")
            notes.append(f"{model}: not warmed up ({why}); each submission derives it in its own child")
    return notes


def _bar(total: int, progress: bool | None):
    if progress is False or total == 0 or (progress is None and not sys.stderr.isatty()):
        return None
    try:
        from tqdm import tqdm
    except ImportError:
        return None
    return tqdm(total=total, unit="submission", file=sys.stderr)


def _cache_get(folder: str, key: str) -> dict | None:
    try:
        with open(os.path.join(folder, key + ".json"), encoding="utf-8") as fh:
            data = json.load(fh)
    except (OSError, ValueError):
        return None
    return data if isinstance(data, dict) and ("report" in data or "error" in data) else None


def _cache_put(folder: str, key: str, result: dict) -> None:
    from .._io_atomic import atomic_write_text

    try:
        os.makedirs(folder, exist_ok=True)
        atomic_write_text(os.path.join(folder, key + ".json"), json.dumps(result, sort_keys=True))
    except OSError:
        pass  # a cache that cannot be written only costs time
