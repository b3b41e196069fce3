import pytest

from accelcal_rig.parts.registry import DEFAULT_PART, known_parts, part


def test_built_in_parts_by_name() -> None:
    assert {"adxl355", "adxl357", "adxl359"} <= set(known_parts())
    assert part(DEFAULT_PART).label == "ADXL355"
    assert part("adxl357").channel("accel").ranges == (10, 20, 40)


def test_an_unknown_part_names_the_known_ones() -> None:
    with pytest.raises(KeyError, match=r"unknown part 'adxl999' \(known: adxl355, adxl357, adxl359"):
        part("adxl999")
