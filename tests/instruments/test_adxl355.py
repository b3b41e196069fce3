import numpy as np
import pytest

from accelcal_rig.instruments import adxl355


def test_temperature_conversion_matches_the_datasheet() -> None:
    assert adxl355.temperature_c_from_raw(1885) == 25.0
    assert adxl355.temperature_c_from_raw(1885 - 905) == pytest.approx(125.0)  # −9.05 LSB/°C
    np.testing.assert_array_equal(adxl355.raw_from_temperature_c(np.array([25.0, 125.0])), [1885, 980])


def test_quantisation_rounds_and_saturates_at_20_bits() -> None:
    codes = adxl355.quantise_g(np.array([1.0, -1.0, 3.0, -3.0, 0.5 / 256000]), 2)
    np.testing.assert_array_equal(codes, [256000, -256000, 2**19 - 1, -(2**19), 0])
    assert adxl355.quantise_g(np.array([1.0]), 8)[0] == 64000


def test_lsb_per_range() -> None:
    assert adxl355.lsb_g(2) == 1 / 256000 and adxl355.lsb_g(4) == 2 / 256000 and adxl355.lsb_g(8) == 4 / 256000
