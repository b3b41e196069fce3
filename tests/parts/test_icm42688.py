"""The ICM-42688-P table: the data sheet's facts as the rest of the rig reads them."""

from __future__ import annotations

import numpy as np
import pytest

from accelcal_rig.parts.icm42688 import ICM42688P
from accelcal_rig.parts.registry import part


def test_it_is_a_built_in_part_with_accel_then_gyro() -> None:
    assert part("icm42688p") is ICM42688P
    assert ICM42688P.channel_names == ("accel", "gyro")
    assert ICM42688P.identity == (0x47,)
    assert ICM42688P.describe_identity((0x47,)) == "WHO_AM_I 0x47"
    assert ICM42688P.wrong_identity((0x47,)) is None
    assert "is not an ICM-42688-P (47)" in ICM42688P.wrong_identity((0x40,))


def test_ranges_sensitivities_and_register_codes() -> None:
    accel, gyro = ICM42688P.channels
    assert accel.ranges == (2, 4, 8, 16)
    assert [accel.lsb_per_unit[r] for r in accel.ranges] == [16384, 8192, 4096, 2048]
    assert [accel.range_codes[r] for r in accel.ranges] == [3, 2, 1, 0]
    assert gyro.ranges == (15.625, 31.25, 62.5, 125, 250, 500, 1000, 2000)
    assert gyro.lsb_per_unit[2000] == 16.4 and gyro.lsb_per_unit[15.625] == 2097.2
    assert [gyro.range_codes[r] for r in gyro.ranges] == [7, 6, 5, 4, 3, 2, 1, 0]
    assert gyro.range_codes[2000.0] == 0                      # a procedure's float finds the whole range
    assert (accel.code_bits, gyro.code_bits) == (16, 16)
    assert (accel.code_min, accel.code_max) == (-32768, 32767)
    assert (accel.noise_density_micro_per_rthz, gyro.noise_density_micro_per_rthz) == (70.0, 2800.0)
    assert gyro.quantise(np.array([1.0, -1.0, 3000.0]), 2000).tolist() == [16, -16, 32767]


def test_a_fractional_range_is_named_as_written() -> None:
    assert ICM42688P.range_problem("gyro", 15.625) is None
    problem = ICM42688P.range_problem("gyro", 3000)
    assert problem == ("±3000 dps is not a range of the ICM-42688-P "
                       "(±15.625/31.25/62.5/125/250/500/1000/2000 dps)")
    assert ICM42688P.describe_ranges({"accel": 2, "gyro": 15.625}) == "±2 g, ±15.625 dps"


def test_odr_codes_are_the_registers_not_the_index() -> None:
    assert ICM42688P.odr_code(1000) == 6
    assert ICM42688P.odr_code(100) == 8
    assert ICM42688P.odr_code(500) == 15
    assert ICM42688P.odr_for_code(15) == 500 and ICM42688P.odr_for_code(8) == 100
    assert ICM42688P.odr_for_code(0) is None and ICM42688P.odr_for_code(12) is None
    assert ICM42688P.has_rate(200) and not ICM42688P.has_rate(125)
    assert ICM42688P.rate_for(125) == 200 and ICM42688P.rate_problem(125) is None   # its next faster rate
    assert "64000 Hz is faster than every ICM-42688-P output data rate" in ICM42688P.rate_problem(64000)


def test_temperature_is_signed_132_48_lsb_per_degree_from_25() -> None:
    fmt = ICM42688P.temperature
    assert fmt.celsius(0) == 25.0
    assert fmt.celsius(-2649.6) == pytest.approx(5.0)
    assert fmt.raw(-40.0) == int(round(-65 * 132.48))          # negative codes are not clipped to 0
    assert fmt.raw(25.0 + 1000.0) == 32767 and fmt.raw(-400.0) == -32768
    assert fmt.celsius(fmt.raw(60.0)) == pytest.approx(60.0, abs=0.01)
