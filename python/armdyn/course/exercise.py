"""``armdyn exercise make``: one folder per student (or variant) with the statement, the
model and the worked solution.

    make_exercise("rp", "out/", seed=7, count=30)              # ids v001..v030
    make_exercise("rr", "out/", seed=7, roster="roster.csv")   # ids from the roster

Each ``out/<id>/`` holds ``problem.md``, ``problem.html`` (with a drawing),
``model.yaml`` and ``solution.md`` (front matter ``robot: model.yaml``, ``student``,
``variant``; grading it gives every step correct). The same seed and roster give
byte-identical files. Each folder also holds ``variant.yaml`` (the exercise kind and
what was drawn: what ``armdyn grade DIR --variants`` reads the student's kind from), and
``out/rubric-<kind>.yaml`` is the kind's rubric, every step of its worked solution
required per part: exercises of several kinds made into one folder (a mixed class) each
get their own, side by side. A folder that already holds a variant (or the kind's rubric)
is refused, naming it, unless ``force``: nothing is then written. A roster is a CSV file
with a header naming an ``id`` (or ``student``) column; other columns are ignored. Ids are folder names: letters, digits,
``.``, ``_``, ``-`` (not first), at most 64 characters.
"""

from __future__ import annotations

import csv
import io
import os
import re
from dataclasses import dataclass, field

import yaml

from ..errors import ModelError
from ..io.textfile import read_text
from .kinds import KINDS
from .proofkinds import PROOF_KINDS
from .variants import draw_variant

ID_PATTERN = re.compile(r"[A-Za-z0-9_][A-Za-z0-9._-]{0,63}")
#: the largest roster read (bytes)
MAX_ROSTER_BYTES = 10_000_000


@dataclass
class MakeResult:
    """What ``make_exercise`` wrote (ids, in order) and the roster lines it refused."""

    written: list[str] = field(default_factory=list)
    problems: list[str] = field(default_factory=list)


def read_roster(path) -> tuple[list[str], list[str]]:
    """The ids of a roster CSV and one line per refused row (``file:line: ...``):
    a duplicate id, an empty or unsafe one. A roster without an id column is a
    :class:`ModelError`."""
    path = os.fspath(path)
    text = read_text(path, "roster", MAX_ROSTER_BYTES, encoding="utf-8-sig")
    reader = csv.reader(io.StringIO(text))
    try:
        header = next(reader)
    except StopIteration:
        raise ModelError("empty roster (expected a header line with an 'id' column)", source=f"{path}:1") from None
    except csv.Error as exc:
        raise ModelError(f"CSV error: {exc}", source=f"{path}:1") from None
    names = [h.strip().lower() for h in header]
    col = next((names.index(c) for c in ("id", "student") if c in names), None)
    if col is None:
        raise ModelError(f"no 'id' (or 'student') column in the header {header!r}", source=f"{path}:1")
    ids, problems, seen = [], [], {}
    try:
        for row in reader:
            line = reader.line_num
            if not row or not any(c.strip() for c in row):
                continue
            ident = row[col].strip() if col < len(row) else ""
            if not ID_PATTERN.fullmatch(ident):
                problems.append(
                    f"{path}:{line}: id {ident!r} is not a folder name (letters, digits, . _ -; at most 64)"
                )
            elif ident in seen:
                problems.append(f"{path}:{line}: duplicate id {ident!r} (first on line {seen[ident]}); skipped")
            else:
                seen[ident] = line
                ids.append(ident)
    except csv.Error as exc:
        raise ModelError(f"CSV error: {exc}", source=f"{path}:{reader.line_num}") from None
    return ids, problems


def proof_files(kind: str, ident: str, seed: int) -> dict[str, str]:
    """The four files of one variant of a proof exercise: name -> text."""
    from .proofkinds import PROOF_MODEL, proof_blocks, proof_markdown
    from .statement import markdown_blocks, statement_html, statement_markdown
    from .variants import rng_for

    title, blocks = proof_blocks(kind, rng_for(seed, ident))
    statement = [
        ("h1", f"Exercise {ident}: prove {title}"),
        ("p", blocks[0]),
        ("h2", "Handing in"),
        (
            "p",
            (
                "One Markdown file: your proof in prose with every equation as display math `$$ ... $$`; "
                "armdyn checks every `=` of every equation. Start with this front matter:"
            ),
        ),
        ("code", f"---\nstudent: {ident}\nvariant: {ident}\nrobot: model.yaml\n---"),
    ]
    front = {"robot": "model.yaml", "student": ident, "variant": ident}
    text, _ = proof_markdown(blocks, front, f"Solution of exercise {ident}: {title}")
    return {
        "solution.html": statement_html(markdown_blocks(text), None),
        "model.yaml": PROOF_MODEL,
        "problem.md": statement_markdown(statement),
        "problem.html": statement_html(statement, None),
        "solution.md": text,
    }


def variant_files(kind: str, ident: str, seed: int, convention: str | None = None) -> dict[str, str]:
    """The four files of one variant: name -> text."""
    if kind in PROOF_KINDS:
        return proof_files(kind, ident, seed)
    from ..io.yaml import load_yaml_string
    from .drawing import drawing_uri
    from .solution import solution_markdown, solution_steps
    from .statement import (
        markdown_blocks,
        statement_blocks,
        statement_html,
        statement_markdown,
    )

    v = draw_variant(kind, ident, seed=seed, convention=convention)
    model = v.model_dict()
    model_text = (
        "# generated by armdyn exercise make: the frames of this variant (armdyn's model format)\n"
        + yaml.safe_dump(model, sort_keys=False, default_flow_style=None, width=100, allow_unicode=True)
    )
    robot = load_yaml_string(model_text, f"{ident}/model.yaml")
    blocks = statement_blocks(v, model)
    steps = solution_steps(robot)
    front = {"robot": "model.yaml", "method": "both", "student": ident, "variant": ident}
    intro = (
        f"The worked solution of exercise {ident}, derived by armdyn (Newton's sign: $F_i = m_i \\dot v_{{C_i}}$, "
        "$N_i = I_i \\dot\\omega_i + \\omega_i \\times I_i \\omega_i$; gravity as an upward acceleration of "
        "the base). `armdyn grade solution.md` grades every step correct."
    )
    solution = solution_markdown(robot, steps, front, f"Solution of exercise {ident}", intro)
    return {
        "model.yaml": model_text,
        "problem.md": statement_markdown(blocks),
        "problem.html": statement_html(blocks, drawing_uri(v, robot)),
        "solution.md": solution,
        "solution.html": statement_html(markdown_blocks(solution), None),
    }


def rubric_text(kind: str) -> str:
    """The rubric of an exercise kind: the default points and credit, and every step its
    worked solution has, required per part (a proof: its links are counted, see
    :mod:`.expected`)."""
    from .expected import expected_for

    exp = expected_for(kind)
    lines = [
        f"# armdyn exercise make {kind}: the rubric of this kind, every step of the worked solution",
        "# required (a step not handed in scores 0 of its points). See docs/course.md.",
        "points:\n  tau: 2\ndefault: 1\ncredit:\n  correct: 1\n  correct-by-convention: 1",
        "  follows-from-earlier-error: 0.5\n  correct-but-unsupported: 0.5\n  consistent: 0.5\n  wrong: 0",
    ]
    if exp.steps:
        lines.append("required:")
        for part in exp.parts:
            lines.append(f"  {part}:")
            lines += [f"    - {n}" for p, n in exp.steps if p == part]
    else:
        lines.append(f"# a proof: its {exp.links} links (each = of the worked proof) are required")
    return "\n".join(lines) + "\n"


def rubric_path(out, kind: str) -> str:
    """Where ``exercise make`` writes the rubric of ``kind``: ``out/rubric-<kind>.yaml``."""
    return os.path.join(os.fspath(out), f"rubric-{kind}.yaml")


def variant_kind(folder) -> str | None:
    """The exercise kind of a variant folder: its ``variant.yaml``, else (a folder made
    before it was written) the arm its ``model.yaml`` description names
    (``exercise variant ada: rp, ...``); None when neither says."""
    folder = os.fspath(folder)
    path = os.path.join(folder, "variant.yaml")
    if os.path.isfile(path) and not os.path.islink(path):
        try:
            data = yaml.safe_load(read_text(path, "variant", 1 << 16))
        except (ModelError, yaml.YAMLError):
            data = None
        kind = data.get("kind") if isinstance(data, dict) else None
        return kind if kind in KINDS or kind in PROOF_KINDS else None
    model = os.path.join(folder, "model.yaml")
    if not os.path.isfile(model) or os.path.islink(model):
        return None
    try:
        head = read_text(model, "model", MAX_ROSTER_BYTES)[:4000]
    except ModelError:
        return None
    m = re.search(r"^description: ['\"]?exercise variant \S+: ([a-z]+), ", head, re.MULTILINE)
    return m.group(1) if m and m.group(1) in KINDS else None


def _writer(text: str):
    def write(tmp):
        with open(tmp, "w", encoding="utf-8", newline="\n") as fh:
            fh.write(text)

    return write


def make_exercise(
    kind: str,
    out,
    seed: int = 0,
    count: int | None = None,
    roster=None,
    convention: str | None = None,
    progress=None,
    force: bool = False,
) -> MakeResult:
    """Write one folder per id into ``out`` (see the module docstring). Each folder is
    written all or nothing. ``progress(ident)`` is called after each one. A variant
    folder that is not empty, or the kind's rubric, already there: :class:`ModelError`
    naming them (nothing written) unless ``force``."""
    from .._io_atomic import atomic_writes

    if kind not in KINDS and kind not in PROOF_KINDS:
        raise ModelError(f"unknown exercise kind {kind!r} (known: {', '.join([*KINDS, *PROOF_KINDS])})")
    if (count is None) == (roster is None):
        raise ModelError("give either a count of variants or a roster")
    result = MakeResult()
    if roster is not None:
        ids, result.problems = read_roster(roster)
    else:
        if not 1 <= count <= 100_000:
            raise ModelError(f"--count must be in 1..100000, got {count}")
        ids = [f"v{k:03d}" for k in range(1, count + 1)]
    out = os.fspath(out)
    if not force:
        taken = [i for i in ids if os.path.isdir(os.path.join(out, i)) and os.listdir(os.path.join(out, i))]
        if os.path.exists(rubric_path(out, kind)):
            taken.append(os.path.basename(rubric_path(out, kind)))
        if taken:
            shown = ", ".join(taken[:5]) + (f" and {len(taken) - 5} more" if len(taken) > 5 else "")
            raise ModelError(
                f"already there: {shown}; nothing written (--force to overwrite, or another --out)", source=out
            )
    for ident in ids:
        files = variant_files(kind, ident, seed, convention)
        files["variant.yaml"] = _variant_yaml(kind, ident, seed, convention)
        folder = os.path.join(out, ident)
        os.makedirs(folder, exist_ok=True)
        atomic_writes([(os.path.join(folder, name), _writer(text)) for name, text in sorted(files.items())])
        result.written.append(ident)
        if progress is not None:
            progress(ident)
    if ids:
        atomic_writes([(rubric_path(out, kind), _writer(rubric_text(kind)))])
    return result


def _variant_yaml(kind: str, ident: str, seed: int, convention: str | None) -> str:
    """``variant.yaml``: the exercise kind of the folder and what it was drawn from."""
    data = {"kind": kind, "id": ident, "seed": int(seed)}
    if kind not in PROOF_KINDS:
        v = draw_variant(kind, ident, seed=seed, convention=convention)
        data.update(convention=v.convention, masses=v.masses, lengths=dict(v.lengths) or "symbolic")
    return "# armdyn exercise make: the exercise kind of this folder\n" + yaml.safe_dump(data, sort_keys=False)
