"""The range every numeric key of the procedure and rig config accepts, read from the models (for the
docs' range table and the test that keeps it true)."""

from __future__ import annotations

import types
import typing
from collections.abc import Iterator

import annotated_types
from pydantic import BaseModel
from pydantic.fields import FieldInfo


def _limits(metadata: list[object]) -> tuple[float | None, bool, float | None, bool]:
    """(low, low is open, high, high is open) from pydantic/annotated-types metadata."""
    low = high = None
    low_open = high_open = False
    for item in metadata:
        if isinstance(item, FieldInfo):
            found = _limits(list(item.metadata))
            low, low_open = (found[0], found[1]) if found[0] is not None else (low, low_open)
            high, high_open = (found[2], found[3]) if found[2] is not None else (high, high_open)
        elif isinstance(item, annotated_types.Ge):
            low, low_open = item.ge, False
        elif isinstance(item, annotated_types.Gt):
            low, low_open = item.gt, True
        elif isinstance(item, annotated_types.Le):
            high, high_open = item.le, False
        elif isinstance(item, annotated_types.Lt):
            high, high_open = item.lt, True
    return low, low_open, high, high_open


def numeric_keys(model: type[BaseModel], prefix: str = "") -> Iterator[tuple[str, type, tuple]]:
    """(dotted key, int or float, limits) of every numeric leaf, `[]` marking list items."""
    for name, field in model.model_fields.items():
        yield from _leaf(prefix + name, field.annotation, list(field.metadata))


def _leaf(key: str, annotation: object, metadata: list[object]) -> Iterator[tuple[str, type, tuple]]:
    origin, args = typing.get_origin(annotation), typing.get_args(annotation)
    if origin is typing.Annotated:
        yield from _leaf(key, args[0], metadata + list(args[1:]))
    elif isinstance(annotation, type) and issubclass(annotation, BaseModel):
        yield from numeric_keys(annotation, key + ".")
    elif annotation in (int, float):
        yield key, annotation, _limits(metadata)
    elif origin in (typing.Union, types.UnionType):
        for member in args:
            if member is not type(None):
                yield from _leaf(key, member, metadata)
    elif origin in (list, tuple):
        for member in dict.fromkeys(a for a in args if a is not Ellipsis):
            yield from _leaf(key + "[]", member, [])


def _number(value: float) -> str:
    return f"{int(value)}" if float(value).is_integer() and abs(value) < 1e12 else f"{value:g}"


def shown(limits: tuple) -> str | None:
    """`0.1 … 50`, `> 0 … 240`; None when the model checks the key another way (a list of rates, say)."""
    low, low_open, high, high_open = limits
    if low is None and high is None:
        return None
    left = "" if low is None else (f"> {_number(low)}" if low_open else _number(low))
    right = "" if high is None else (f"< {_number(high)}" if high_open else _number(high))
    return f"{left} … {right}".strip()
