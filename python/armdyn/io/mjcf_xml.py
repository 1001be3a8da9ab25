"""The XML side of the MJCF reader (:mod:`armdyn.io.mjcf`): a document read with expat
and without a DTD (:func:`armdyn.io.urdf.refuse_dtd`), each element's file and line kept
for messages, ``<include>``s put in place (relative to the main file's directory, as in
MuJoCo; each file once, at most ``MAX_INCLUDE_DEPTH`` deep, all files together at most
``MODEL_MAX_BYTES``; iteratively, so nesting costs no recursion), and numbers in
attributes read strictly."""

from __future__ import annotations

import math
import os
import re
import xml.etree.ElementTree as ET
from pathlib import Path
from xml.parsers import expat

import numpy as np

from ..errors import ModelError
from .textfile import MODEL_MAX_BYTES, read_bytes
from .urdf import refuse_dtd

__all__ = ["MjcfDocument", "clip", "MAX_INCLUDE_DEPTH", "ATTRIBUTES"]

MAX_INCLUDE_DEPTH = 16

_ORIENTATION = "quat axisangle xyaxes zaxis euler"
#: the attributes MJCF allows on the elements this reader reads (MuJoCo refuses any
#: other, so a misspelt ``dampng`` is an error here too, not a silently missing damping)
ATTRIBUTES = {
    tag: frozenset(names.split())
    for tag, names in {
        "body": f"name childclass pos {_ORIENTATION} mocap gravcomp sleep simple user",
        "frame": f"name childclass pos {_ORIENTATION}",
        "inertial": f"pos mass diaginertia fullinertia {_ORIENTATION}",
        "joint": "name class type group pos axis springdamper limited actuatorfrclimited solreflimit solimplimit "
        "solreffriction solimpfriction stiffness range actuatorfrcrange actuatorgravcomp margin ref springref "
        "armature damping frictionloss user",
        "freejoint": "name group align",
        "geom": "name class type contype conaffinity condim group priority size material friction mass density "
        f"shellinertia solmix solref solimp margin gap surfacevel adhesion fromto pos {_ORIENTATION} hfield mesh "
        "fitscale rgba fluidshape fluidcoef user",
        "include": "file",
    }.items()
}

# a plain decimal number (no "nan", "inf", hex or "1_000")
_NUMBER = re.compile(r"[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?")


class MjcfDocument:
    """An MJCF document being read: ``source`` (its file, or ``"<mjcf>"`` for text) and
    ``directory`` (where includes are found; None for text, which may not include)."""

    def __init__(self, source: str, directory: Path | None):
        self.source, self.directory = source, directory
        self.origin: dict[ET.Element, tuple[str, int]] = {}  # element -> (file, line)
        self.bytes = 0

    def error(self, elem: ET.Element | None, message: str) -> ModelError:
        if elem is None:
            return ModelError(message, None, self.source)
        name = elem.get("name")
        if name and not name.isprintable():  # a line break in a name must not split the message
            name = repr(name)[1:-1]
        what = f"<{elem.tag} name='{clip(name)}'>" if name else f"<{elem.tag}>"
        file, line = self.origin.get(elem, (self.source, 0))
        return ModelError(message, what, f"{file}:{line}" if line else file)

    def check_attributes(self, elem: ET.Element) -> None:
        """ModelError for an attribute MJCF does not define on ``elem``."""
        unknown = sorted(set(elem.attrib) - ATTRIBUTES[elem.tag])
        if unknown:
            raise self.error(elem, f"unknown attribute '{clip(unknown[0])}' (MuJoCo refuses it too)")

    def parse(self, text: bytes, name: str) -> ET.Element:
        """The ``<mujoco>`` root of ``text``, each element's line kept in ``origin``."""
        self.bytes += len(text)
        if self.bytes > MODEL_MAX_BYTES:
            raise ModelError(f"the model and its includes are larger than {MODEL_MAX_BYTES} bytes", None, name)
        try:
            refuse_dtd(text, "MJCF")
        except ModelError as err:
            raise err.located(source=name)
        parser = expat.ParserCreate()
        stack: list[ET.Element] = []
        roots: list[ET.Element] = []

        def start(tag, attrs):
            elem = ET.Element(tag, attrs)
            self.origin[elem] = (name, parser.CurrentLineNumber)
            (stack[-1] if stack else roots).append(elem)
            stack.append(elem)

        parser.StartElementHandler = start
        parser.EndElementHandler = lambda tag: stack.pop()
        try:
            parser.Parse(text, True)
        except expat.ExpatError as err:
            where = f"column {err.offset + 1}"
            raise ModelError(f"malformed XML: {expat.ErrorString(err.code)}", where, f"{name}:{err.lineno}") from None
        root = roots[0]
        if root.tag != "mujoco":
            raise self.error(root, f"the root element is <{root.tag}>, expected <mujoco>")
        return root

    def expand_includes(self, root: ET.Element) -> None:
        """Put each ``<include file>``'s children in its place (iteratively, bounded)."""
        top = () if self.directory is None else (os.path.realpath(self.source),)
        seen = set(top)
        stack = [(root, top)]
        while stack:
            elem, chain = stack.pop()
            pending = [(child, chain) for child in reversed(elem)]
            children, changed = [], False
            while pending:  # an included file's own includes are expanded in place too
                child, sub = pending.pop()
                if child.tag == "include":
                    changed = True
                    pending += reversed(self.include(child, sub, seen))
                else:
                    children.append(child)
                    stack.append((child, sub))
            if changed:
                elem[:] = children

    def include(self, elem: ET.Element, chain: tuple, seen: set) -> list:
        self.check_attributes(elem)
        file = elem.get("file")
        if not file or not file.strip():
            raise self.error(elem, "<include> has no 'file' attribute")
        if self.directory is None:
            raise self.error(elem, "an <include> needs the model read from its file (its path is relative to it)")
        if len(chain) >= MAX_INCLUDE_DEPTH:
            raise self.error(elem, f"includes nested deeper than {MAX_INCLUDE_DEPTH}")
        path = self.directory / file.strip()
        real = os.path.realpath(path)
        if real in chain:
            loop = " -> ".join(os.path.basename(p) for p in chain + (real,))
            raise self.error(elem, f"include loop: {loop}")
        if real in seen:
            raise self.error(elem, f"'{clip(file)}' is included twice (MuJoCo includes a file once)")
        seen.add(real)
        try:
            text = read_bytes(path, "included file", MODEL_MAX_BYTES)
        except ModelError as err:
            raise self.error(elem, f"cannot include '{clip(file)}': {err.message}") from None
        root = self.parse(text, os.fspath(path))
        return [(child, chain + (real,)) for child in root]

    # ------------------------------------------------------------- numbers

    def numbers(self, elem, attrs, key, count, default=None, at_least=None) -> np.ndarray | None:
        """``attrs[key]`` as ``count`` numbers (``at_least``..``count`` when given)."""
        text = attrs.get(key)
        if text is None:
            return None if default is None else np.array(default, dtype=float)
        parts = text.split()
        low = count if at_least is None else at_least
        if not low <= len(parts) <= count:
            expected = count if at_least is None else f"{at_least} to {count}"
            raise self.error(elem, f"'{key}' is {clip(text)!r}: expected {expected} numbers")
        for part in parts:
            if not _NUMBER.fullmatch(part) or not math.isfinite(float(part)):
                raise self.error(elem, f"'{key}' is {clip(text)!r}: {clip(part)!r} is not a finite number")
        return np.array([float(p) for p in parts])

    def number(self, elem, attrs, key, default: float) -> float:
        return float(self.numbers(elem, attrs, key, 1, [default])[0])


def clip(text: str | None, limit: int = 40) -> str:
    """``text`` shortened for an error message (a bad file may hold megabytes)."""
    text = text or ""
    return text if len(text) <= limit else f"{text[:limit]}... ({len(text)} characters)"
