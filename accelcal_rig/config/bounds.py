"""Number types with units and the ranges a real rig can have: a value outside is a config error naming
its key, never a campaign that runs for a century or an estimate that never ends.

A number in a file is a YAML number (as YAML 1.2 reads one: config/yaml_lines.py), never text: pydantic on
its own reads `"2_0"` as 20, `"1e3"` as 1000 and `true` as 1, and a whole number from `200.0`. `Real` and
`Whole` refuse text and booleans, and `Whole` any float, naming the key (docs/procedures.md, "Numbers");
text from the command line (`--faults rate=0.05`) is read as numbers only where its caller says so
(`NUMBERS_FROM_TEXT` in the validation context).
"""

from __future__ import annotations

from typing import Annotated

from pydantic import BaseModel, BeforeValidator, ConfigDict, Field, ValidationInfo

#: Every config model: unknown keys and non-finite numbers (.inf, .nan) are refused.
STRICT = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)
#: Validation context key: the values are command-line text, whose numbers are written as text.
NUMBERS_FROM_TEXT = "numbers_from_text"
#: Said of text that Python would read as a number (`"20"`, `"1e3"`, `2_0`): how a file writes one.
_HOW_YAML_WRITES_NUMBERS = ": write it as a YAML number, without quotes or underscores (e.g. 20, -40.5, 1e3)"


class StrictModel(BaseModel):
    """The base of every model read from a file: see STRICT."""

    model_config = STRICT


def _from_text(info: ValidationInfo) -> bool:
    return bool(info.context and info.context.get(NUMBERS_FROM_TEXT))


def _not_text(value: object, expected: str) -> None:
    """Text or a boolean where a number belongs is the file's mistake, said in its own terms; text that spells a
    number to Python (`"20"`, `"1e3"`, `2_0`) is told how YAML writes one."""
    if isinstance(value, bool):
        raise ValueError(f"expected {expected}, got {str(value).lower()}")
    if isinstance(value, str):
        hint = _HOW_YAML_WRITES_NUMBERS if _spells_a_number(value) else ""
        raise ValueError(f"expected {expected}, got the text {value!r}{hint}")


def _spells_a_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def real_number(value: object, info: ValidationInfo) -> object:
    """A number in a file is a YAML number (an int or a float), never text that spells one."""
    if not _from_text(info):
        _not_text(value, "a number")
    return value


def whole_number(value: object, info: ValidationInfo) -> object:
    """A count or an address is a whole number: a float is not one, whatever its fraction (200.5, or 200.0
    where 200 was meant)."""
    if _from_text(info):
        return value
    _not_text(value, "a whole number")
    if isinstance(value, float):
        shown = f" (write {int(value)})" if value.is_integer() else ""
        raise ValueError(f"expected a whole number, got {value!r}{shown}")
    return value


#: A number from a file: an int or a float, never text or a boolean.
Real = Annotated[float, BeforeValidator(real_number)]
#: A whole number from a file: never a float, text or a boolean.
Whole = Annotated[int, BeforeValidator(whole_number)]

#: A temperature a calibration chamber can hold, °C.
TemperatureC = Annotated[Real, Field(ge=-100.0, le=300.0)]
#: A temperature difference, °C.
TemperatureSpanC = Annotated[Real, Field(gt=0.0, le=50.0)]
#: A turntable or mount angle, degrees.
AngleDeg = Annotated[Real, Field(ge=-3600.0, le=3600.0)]
#: A wire timeout, s.
TimeoutS = Annotated[Real, Field(ge=0.001, le=60.0)]
#: A serial line's speed, baud.
Baudrate = Annotated[Whole, Field(ge=50, le=20_000_000)]
