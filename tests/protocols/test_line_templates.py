"""What line protocols share: a request's number read as a controller reads one."""

from __future__ import annotations

import pytest

from accelcal_rig.protocols.line_templates import finite_number


@pytest.mark.parametrize(("text", "value"), [("-40.0", -40.0), ("25", 25.0), ("+1.5e2", 150.0), ("1.", 1.0),
                                             ("-0", 0.0), ("1E3", 1000.0)])
def test_numbers_as_controllers_write_them(text: str, value: float) -> None:
    assert finite_number(text) == value


@pytest.mark.parametrize("text", ["nan", "NaN", "inf", "-inf", "Infinity", "1_0", " 1", "1 ", "0x10", ".5", "",
                                  "\u0661", "\uff11"])  # the last two: digits float() takes from other scripts
def test_what_only_python_reads_as_a_number_is_not_one(text: str) -> None:
    with pytest.raises(ValueError, match="not a number"):
        finite_number(text)


@pytest.mark.parametrize("text", ["1e400", "-1e400", "9" * 400])
def test_a_number_beyond_a_float_is_not_finite(text: str) -> None:
    with pytest.raises(ValueError, match="not a finite number"):
        finite_number(text)
