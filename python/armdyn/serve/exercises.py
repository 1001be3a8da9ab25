"""The exercises a server grades against, addressed by id from a whitelist.

An exercise id is either a bundled model's name (``rp-arm``: the assignment's arm;
the other bundled arms too) or the id of a variant made by ``armdyn exercise make``
in the directory given with ``--exercises DIR`` (``DIR/<id>/model.yaml``). The
catalogue is built once, at start-up, from the directory listing: a request names an
id, never a path, and an id not in the catalogue is refused, so no request reaches
the file system by a path of its choosing.
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass

from ..errors import ModelError

#: an id as it may appear in a URL or front matter
ID = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_.-]{0,63}$")
DEFAULT = "rp-arm"


@dataclass(frozen=True)
class Exercise:
    id: str
    source: str  # what armdyn.io.load takes: a bundled name or the variant's model.yaml
    title: str
    variant: bool


def catalogue(variants_dir: str | None = None) -> dict[str, Exercise]:
    """id -> :class:`Exercise`: the bundled models, then the variants in ``variants_dir``
    (subdirectories holding a ``model.yaml``; ids that are not plain names are skipped,
    an id equal to a bundled name is refused)."""
    from ..io import bundled_robots

    out = {}
    for entry in bundled_robots():
        if entry.get("dof"):
            title = "the exercise (rp-arm)" if entry["name"] == DEFAULT else entry["name"]
            out[entry["name"]] = Exercise(entry["name"], entry["name"], title, False)
    if variants_dir:
        if not os.path.isdir(variants_dir):
            raise ModelError("not a directory (expected the output of `armdyn exercise make`)", source=variants_dir)
        for name in sorted(os.listdir(variants_dir)):
            model = os.path.join(variants_dir, name, "model.yaml")
            if not ID.match(name) or not os.path.isfile(model):
                continue
            if name in out:
                raise ModelError(f"variant '{name}' has the name of a bundled model; rename it", source=variants_dir)
            out[name] = Exercise(name, os.path.abspath(model), f"variant {name}", True)
    return out


def ordered(exercises: dict[str, Exercise]) -> list[Exercise]:
    """For the student's menu: the exercise first, then the variants, then the other arms."""
    return sorted(exercises.values(), key=lambda e: (e.id != DEFAULT, not e.variant, e.id))
