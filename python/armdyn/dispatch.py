"""Methods of armdyn's data classes whose work lives in a higher layer.

``Robot._repr_html_``, ``EquationsOfMotion._repr_latex_``, ``GradeReport.text`` and the
like are the classes' public face, but the code behind them (HTML with MathML, the text
report, the URDF reader) sits in layers that import the data classes, not the other way
round. Those layers register a function here; the method asks for it by kind:

    # in a renderer module (it imports the data class, the data class never imports it)
    @register("html", Robot)
    def robot_html(robot) -> str: ...

    # in the data class
    def _repr_html_(self) -> str:
        return call("html", self)

This module imports nothing of armdyn, so the data modules can import it without an
import cycle. ``armdyn/__init__.py`` (and ``grade/__init__.py`` for the grade report)
imports the registering modules, so everything is registered whenever a data class can
exist. Where each kind is registered: see "Where display lives" in docs/architecture.md.
"""

from __future__ import annotations

from typing import Any, Callable, TypeVar

F = TypeVar("F", bound=Callable[..., Any])

#: (kind, class) -> function(obj, *args, **kwargs)
_TABLE: dict[tuple[str, type], Callable[..., Any]] = {}


def register(kind: str, cls: type) -> Callable[[F], F]:
    """Decorator: ``func(obj, ...)`` does ``kind`` for instances of ``cls`` (and its
    subclasses). A later registration of the same pair replaces the earlier one (a
    reloaded module registers again)."""

    def decorate(func: F) -> F:
        _TABLE[(kind, cls)] = func
        return func

    return decorate


def call(kind: str, obj: object, *args: Any, **kwargs: Any) -> Any:
    """``func(obj, *args, **kwargs)`` for the function registered for ``kind`` on the
    nearest class of ``obj`` (``obj``'s own MRO when ``obj`` is a class, for
    classmethods). LookupError if none is registered."""
    cls = obj if isinstance(obj, type) else type(obj)
    for klass in cls.__mro__:
        func = _TABLE.get((kind, klass))
        if func is not None:
            return func(obj, *args, **kwargs)
    raise LookupError(f"no {kind!r} registered for {cls.__name__} (the module providing it was not imported)")


def registered() -> list[tuple[str, str]]:
    """``(kind, class name)`` of every registration, sorted: what tests and docs list."""
    return sorted((kind, f"{cls.__module__}.{cls.__qualname__}") for kind, cls in _TABLE)
