"""The LIS3MDL table: the data sheet's facts (DS9463 Rev 7) and ST's driver's codes as the rest of the rig reads
them."""

from __future__ import annotations

import numpy as np
import pytest

from accelcal_rig.parts.lis3mdl import LIS3MDL
from accelcal_rig.parts.part import odr_hz_of
from accelcal_rig.parts.registry import part


def test_it_is_a_built_in_part_with_one_magnetic_field_channel() -> None:
    assert part("lis3mdl") is LIS3MDL
    (mag,) = LIS3MDL.channels
    assert (mag.name, mag.quantity, mag.unit, mag.axes) == ("mag", "magnetic field", "gauss", ("x", "y", "z"))
    assert LIS3MDL.identity == (0x3D,) and LIS3MDL.describe_identity((0x3D,)) == "WHO_AM_I 0x3D"
    assert "is not an LIS3MDL (3D)" in LIS3MDL.wrong_identity((0x33,))


def test_full_scales_sensitivities_and_fs_codes_are_table_2s() -> None:
    (mag,) = LIS3MDL.channels
    assert mag.ranges == (4, 8, 12, 16)
    assert [mag.lsb_per_unit[r] for r in mag.ranges] == [6842, 3421, 2281, 1711]
    assert [mag.range_codes[r] for r in mag.ranges] == [0, 1, 2, 3]
    assert (mag.code_bits, mag.code_min, mag.code_max) == (16, -32768, 32767)
    assert mag.default_range == 4                            # CTRL_REG2's reset value: FS 00
    assert mag.quantise(np.array([0.5, -0.5, 9.0]), 4).tolist() == [3421, -3421, 32767]
    assert LIS3MDL.range_problem("mag", 6) == "±6 gauss is not a range of the LIS3MDL (±4/8/12/16 gauss)"


def test_rates_and_their_packed_ctrl_reg1_codes_are_st_drivers() -> None:
    assert LIS3MDL.odr_code(80) == 0x3E and LIS3MDL.odr_code(155) == 0x31     # LIS3MDL_UHP_80Hz, _UHP_155Hz
    assert LIS3MDL.odr_code(1000) == 0x01 and LIS3MDL.odr_code(0.625) == 0x30  # LIS3MDL_LP_1kHz, _UHP_0Hz625
    assert LIS3MDL.odr_for_code(0x21) == 300 and LIS3MDL.odr_for_code(0x11) == 560
    assert LIS3MDL.odr_for_code(0x00) is None                                  # low power at 0.625 Hz: not used


def test_a_rate_the_part_lacks_runs_at_its_next_faster_one() -> None:
    assert LIS3MDL.rate_for(80) == 80 and LIS3MDL.rate_for(125) == 155 and LIS3MDL.rate_for(100) == 155
    assert LIS3MDL.rate_for(2000) is None
    assert LIS3MDL.rate_problem(125) is None
    assert "2000 Hz is faster than every LIS3MDL output data rate" in LIS3MDL.rate_problem(2000)
    assert odr_hz_of(LIS3MDL, 125) == 155
    with pytest.raises(ValueError, match="faster than every"):
        odr_hz_of(LIS3MDL, 2000)


def test_temperature_is_8_lsb_per_degree_from_25() -> None:
    fmt = LIS3MDL.temperature
    assert fmt.celsius(0) == 25.0 and fmt.celsius(8) == 26.0 and fmt.celsius(-520) == -40.0
    assert fmt.raw(60.0) == 280
