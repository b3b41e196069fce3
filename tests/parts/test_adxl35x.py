"""Each part's table against its data sheet's figures, and what the rig derives from a table."""

import numpy as np
import pytest

from accelcal_rig.parts.adxl35x import ADXL355, ADXL357, ADXL359


def test_temperature_conversion_matches_the_datasheets() -> None:
    assert ADXL355.temperature.celsius(1885) == 25.0
    assert ADXL355.temperature.celsius(1885 - 905) == pytest.approx(125.0)  # −9.05 LSB/°C
    np.testing.assert_array_equal(ADXL355.temperature.raw(np.array([25.0, 125.0])), [1885, 980])
    assert ADXL357.temperature == ADXL355.temperature
    assert ADXL359.temperature.celsius(1852) == 25.0                        # its own intercept
    assert ADXL355.temperature.celsius(1852) == pytest.approx(25.0 + 33 / 9.05)  # the hobby-driver bug: 3.6 °C


def test_quantisation_rounds_and_saturates_at_20_bits() -> None:
    codes = ADXL355.channel("accel").quantise(np.array([1.0, -1.0, 3.0, -3.0, 0.5 / 256000]), 2)
    np.testing.assert_array_equal(codes, [256000, -256000, 2**19 - 1, -(2**19), 0])
    assert ADXL355.channel("accel").quantise(np.array([1.0]), 8)[0] == 64000
    np.testing.assert_array_equal(ADXL357.channel("accel").quantise(np.array([1.0, 12.0, -50.0]), 10), [51200, 2**19 - 1, -(2**19)])
    assert ADXL359.channel("accel").quantise(np.array([39.0]), 40)[0] == 39 * 12800


@pytest.mark.parametrize(("part", "ranges", "lsb_per_g_lowest"), [
    (ADXL355, (2, 4, 8), 256_000), (ADXL357, (10, 20, 40), 51_200), (ADXL359, (10, 20, 40), 51_200),
])
def test_ranges_halve_the_sensitivity_each_step(part, ranges, lsb_per_g_lowest) -> None:
    assert part.channel("accel").ranges == ranges
    assert [part.channel("accel").lsb(r) for r in ranges] == [1 / lsb_per_g_lowest, 2 / lsb_per_g_lowest, 4 / lsb_per_g_lowest]
    assert [part.channel("accel").range_codes[r] for r in ranges] == [0b01, 0b10, 0b11]
    assert (part.channel("accel").code_min, part.channel("accel").code_max) == (-(2**19), 2**19 - 1)


def test_identity_tells_the_adxl359_from_the_others_but_not_the_adxl357_from_the_adxl355() -> None:
    assert ADXL355.wrong_identity((0xAD, 0x1D, 0xED)) is None
    assert ADXL357.wrong_identity((0xAD, 0x1D, 0xED)) is None   # the data sheets give both PARTID 0xED
    assert ADXL355.wrong_identity((0xAD, 0x1D, 0xE9)) == "identity AD/1D/E9 is not an ADXL355 (AD/1D/ED)"
    assert ADXL359.wrong_identity((0xAD, 0x1D, 0xED)) == "identity AD/1D/ED is not an ADXL359 (AD/1D/E9)"


def test_range_and_rate_problems_name_the_part_and_what_it_offers() -> None:
    assert ADXL357.range_problem("accel", 20) is None and ADXL357.rate_problem(125) is None
    assert ADXL357.range_problem("accel", 2) == "±2 g is not a range of the ADXL357 (±10/20/40 g)"
    assert ADXL355.rate_problem(100) is None and ADXL355.rate_for(100) == 125   # its next faster rate
    assert ADXL355.rate_problem(5000).startswith("5000 Hz is faster than every ADXL355 output data rate (4000, 2000, ")
    assert ADXL355.odr_code(125.0) == 5 and ADXL355.odr_code(3.906) == 10
