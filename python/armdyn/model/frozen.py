"""Containers that refuse in-place changes, and the metaclass that freezes a Robot once built."""

from __future__ import annotations


class FrozenList(list):
    """A list that refuses in-place changes (``+`` still gives a new plain list)."""

    def _refuse(self, *args, **kwargs):
        raise TypeError("this list belongs to a Robot, which is immutable: build a new Robot instead")

    append = extend = insert = pop = remove = clear = sort = reverse = _refuse
    __setitem__ = __delitem__ = __iadd__ = __imul__ = _refuse

    def __copy__(self):
        return list(self)

    def __reduce__(self):
        # pickle's default for a list subclass refills it with extend(), which is refused
        return (FrozenList, (list(self),))


class FrozenDict(dict):
    """A dict that refuses in-place changes (``dict(d)``, ``{**d}`` give plain copies)."""

    def _refuse(self, *args, **kwargs):
        raise TypeError("this mapping belongs to a Robot, which is immutable: build a new Robot instead")

    __setitem__ = __delitem__ = __ior__ = pop = popitem = clear = update = setdefault = _refuse

    def __copy__(self):
        return dict(self)

    def __reduce__(self):
        # pickle's default for a dict subclass refills it item by item, which is refused
        return (FrozenDict, (dict(self),))


class FreezeAfterInit(type):
    """Robot's metaclass: once ``__init__`` (whatever fields it sets) has returned, the
    instance is frozen (see :meth:`Robot.__setattr__`). No field is listed here."""

    def __call__(cls, *args, **kwargs):
        obj = super().__call__(*args, **kwargs)
        object.__setattr__(obj, "_frozen", True)
        return obj
