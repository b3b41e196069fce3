"""One class per combination of capabilities: a driver or wrapper instance is of a class that has a
capability's methods exactly when its profile (or the instrument it wraps) has the feature, so
`isinstance(x, Capability)` tells the truth and nothing answers for a feature that is not there."""

from __future__ import annotations

from collections.abc import Iterable
from functools import cache
from typing import TypeVar, cast

T = TypeVar("T")


def composed(base: type[T], mixins: Iterable[type]) -> type[T]:
    """`base` with the members of `mixins` (subclasses of `base`, each adding one capability), named as `base`:
    a campaign records a driver by its class's name, which the capabilities do not change."""
    chosen: tuple[type, ...] = tuple(mixins)
    return cast(type[T], _combined(cast(type, base), chosen)) if chosen else base


def instance_of(cls: type[T]) -> T:
    """A new, not yet initialised instance of `cls`: what a `__new__` that chooses the class returns."""
    return object.__new__(cls)


@cache
def _combined(base: type, mixins: tuple[type, ...]) -> type:
    return type(base.__name__, (*mixins, base), {"__module__": base.__module__, "__qualname__": base.__qualname__})
