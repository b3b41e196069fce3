"""An instrument or transport whose every method call goes through a retry function (see engine/retry.py).

Drivers use it on their transports, where each method is one exchange on the wire and safe to repeat; a
test double without a transport of its own is wrapped whole.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, TypeVar

T = TypeVar("T")
#: `call(operation, reconnect)`: run `operation`, retrying transient failures, reconnecting with `reconnect`.
RetryCall = Callable[[Callable[[], Any], Callable[[], None] | None], Any]


class Retrying:
    """Stands in for `target`: attributes pass through, method calls go through `call`."""

    def __init__(self, target: Any, call: RetryCall) -> None:
        self._target = target
        self._call = call

    def __getattr__(self, name: str) -> Any:
        attribute = getattr(self._target, name)
        if not callable(attribute) or name.startswith("_") or name in ("close", "reconnect"):
            return attribute
        reconnect = getattr(self._target, "reconnect", None)

        def retried(*args: Any, **kwargs: Any) -> Any:
            return self._call(lambda: attribute(*args, **kwargs), reconnect)

        return retried
