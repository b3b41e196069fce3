"""The serial bridge's register requests, as every simulated bridge answers them: `R <addr> <count>` reads
(`=<hex>`), `W <addr> <value>` writes (`=`), both hexadecimal but the count, in front of whichever simulated
part sits behind the bridge."""

from __future__ import annotations

from typing import Protocol


class RegisterDevice(Protocol):
    def read(self, address: int, count: int) -> bytes: ...
    def write(self, address: int, value: int) -> None: ...


def register_request(device: RegisterDevice, words: list[str]) -> str | None:
    """The reply to a register request; None when `words` is not one. ValueError for a malformed number."""
    if len(words) == 3 and words[0] == "R":
        return "=" + device.read(int(words[1], 16), int(words[2])).hex().upper()
    if len(words) == 3 and words[0] == "W":
        device.write(int(words[1], 16), int(words[2], 16))
        return "="
    return None


def overlong_request(head: str) -> str:
    """The answer to a line longer than any request, whatever it began with: the reference firmware's
    (firmware/src/bridge.c, `answer_line`), which drops such a line and reads the next."""
    return "!request too long"
