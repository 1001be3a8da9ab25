"""A first pass over untrusted YAML that refuses what would make loading it blow up.

Model files and graded submissions come from people armdyn may not trust. Before any
Python object is built, :func:`screen` reads the YAML *event stream* (the parser's output:
no node is composed, no alias expanded, no object constructed; the parser keeps its own
stack, so depth costs it no recursion) and refuses, with one line naming the file and line:

* any alias (``*name``): a few lines of nested aliases ("billion laughs") expand into
  billions of nodes when constructed, or when an error message walks them;
* nesting deeper than :data:`MAX_DEPTH` mappings and sequences: composing and
  constructing recurse once per level (a 10^4-deep ``[[[...]]]`` is a RecursionError);
* a plain integer of more than :data:`MAX_INT_DIGITS` digits: Python refuses to convert
  one of more than 4300 digits with a message that names no file, and no model value
  or submission needs a number of that size.

Both loaders of armdyn (:mod:`armdyn.io.yaml` for models, :mod:`armdyn.grading.reader`
for submissions) call it first.
"""

from __future__ import annotations

import re

import yaml

from ..errors import ModelError
from .expressions import MAX_INT_DIGITS  # the same bound for a YAML integer and one in an expression

#: Deepest nesting of mappings and sequences accepted (a model needs about 5).
MAX_DEPTH = 64

_PARSER = getattr(yaml, "CSafeLoader", yaml.SafeLoader)  # libyaml's parser when present
_INTEGER_LIKE = re.compile(r"[-+]?[0-9][0-9a-fA-F_:xXoO]*")


def screen(text: str, source: str, what: str = "the file") -> None:
    """Raise :class:`~armdyn.errors.ModelError` ("``source:line``: ...") if ``text``
    holds an alias, nesting deeper than :data:`MAX_DEPTH` or an integer longer than
    :data:`MAX_INT_DIGITS` digits. YAML syntax errors are left to the loader that follows
    (it reports them with its own wording); the pass stops at the first one."""
    depth = 0
    try:
        for event in yaml.parse(text, Loader=_PARSER):
            if isinstance(event, (yaml.SequenceStartEvent, yaml.MappingStartEvent)):
                depth += 1
                if depth > MAX_DEPTH:
                    raise _refused(event, source, f"nesting deeper than {MAX_DEPTH} levels in {what}")
            elif isinstance(event, (yaml.SequenceEndEvent, yaml.MappingEndEvent)):
                depth -= 1
            elif isinstance(event, yaml.AliasEvent):
                raise _refused(
                    event,
                    source,
                    f"YAML aliases (*{event.anchor}) are not allowed in {what}"
                    if len(str(event.anchor)) <= 40
                    else f"YAML aliases are not allowed in {what}",
                )
            elif isinstance(event, yaml.ScalarEvent) and not event.style and len(event.value) > MAX_INT_DIGITS:
                digits = sum(c.isdigit() for c in event.value)
                if digits > MAX_INT_DIGITS and _INTEGER_LIKE.fullmatch(event.value):
                    raise _refused(
                        event,
                        source,
                        f"a number of {digits} digits is beyond the float64 range (at most {MAX_INT_DIGITS} digits)",
                    )
    except yaml.YAMLError as exc:
        # libyaml (PyYAML >= 6.0.4) stops deep flow collections in its scanner, before
        # their start events reach us: the same refusal, at the line it names
        mark = getattr(exc, "problem_mark", None)
        if "nesting depth" in str(getattr(exc, "problem", "")) and mark is not None:
            message = f"nesting deeper than {MAX_DEPTH} levels in {what}"
            raise ModelError(message, None, f"{source}:{mark.line + 1}") from None
        return  # a syntax error: the loader reports it, with its line


def _refused(event, source: str, message: str) -> ModelError:
    mark = event.start_mark
    where = f"{source}:{mark.line + 1}" if mark is not None else source
    return ModelError(message, None, where)


__all__ = ["screen", "MAX_DEPTH", "MAX_INT_DIGITS"]
