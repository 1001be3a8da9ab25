"""Errors raised for bad models and bad input.

Every model error names where it happened (file, element) and what is wrong, so the
CLI can print it as one line and exit non-zero without a traceback.
"""

from __future__ import annotations


class ModelError(ValueError):
    """A robot description that is wrong.

    ``str(err)`` is one line: ``"<source>: <element>: <message>"`` (parts that are
    unknown are left out), e.g. ``"arm.yaml: joint 'j2': axis is zero"``.
    """

    def __init__(self, message: str, element: str | None = None, source: str | None = None):
        self.message = message
        self.element = element
        self.source = source
        super().__init__(self._line())

    def _line(self) -> str:
        parts = [p for p in (self.source, self.element) if p]
        return ": ".join(parts + [self.message])

    def __str__(self) -> str:  # recomputed: `source` may be filled in after construction
        return self._line()

    def located(self, source: str | None = None, element: str | None = None) -> "ModelError":
        """Fill in the source file and/or element if not yet known; returns self."""
        if source and not self.source:
            self.source = source
        if element and not self.element:
            self.element = element
        return self


class FloatingBaseError(ModelError, NotImplementedError):
    """A function that handles fixed-base robots only was given one whose base floats
    (``root_joint="free-flyer"``); the message names the function."""


class UnboundParameterError(ValueError):
    """A numeric function was given a robot that still has free symbols."""
