"""What a person probably meant: an unknown key's nearest known one, and for a missing key the unknown
key beside it that looks like a misspelling of it."""

from __future__ import annotations

import typing
from difflib import get_close_matches
from typing import Any

from pydantic import BaseModel
from pydantic_core import ErrorDetails


def explained(model: type[BaseModel], data: Any, error: ErrorDetails) -> str | None:
    """A better message for an unknown or missing key; None for other errors (pydantic's is fine)."""
    location = tuple(error["loc"])
    if not location or error["type"] not in ("extra_forbidden", "missing"):
        return None
    parent = model_at(model, location[:-1])
    if parent is None:
        return None
    name, known = str(location[-1]), list(parent.model_fields)
    if error["type"] == "extra_forbidden":
        close = get_close_matches(name, known, n=1, cutoff=0.6)
        return f"unknown key; did you mean {close[0]}?" if close else f"unknown key (known here: {', '.join(known)})"
    given = _data_at(data, location[:-1])
    strangers = [str(k) for k in given if str(k) not in known] if isinstance(given, dict) else []
    close = get_close_matches(name, strangers, n=1, cutoff=0.6)
    return f"required, and missing: is {close[0]!r} a misspelling of it?" if close else "required, and missing"


def model_at(model: type[BaseModel], location: tuple[Any, ...]) -> type[BaseModel] | None:
    """The model that holds the keys at `location` (list indices skipped), if the path leads to one."""
    current: type[BaseModel] | None = model
    for step in location:
        if isinstance(step, int) or current is None:
            continue
        field = current.model_fields.get(str(step))
        if field is None:
            return None
        current = _submodel(field.annotation)
    return current


def _submodel(annotation: Any) -> type[BaseModel] | None:
    candidates = [annotation, *typing.get_args(annotation)]
    for candidate in candidates:
        inner = [candidate, *typing.get_args(candidate)]
        for kind in inner:
            if isinstance(kind, type) and issubclass(kind, BaseModel):
                return kind
    return None


def _data_at(data: Any, location: tuple[Any, ...]) -> Any:
    for step in location:
        try:
            data = data[step]
        except (KeyError, IndexError, TypeError):
            return None
    return data
