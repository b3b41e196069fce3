"""The ADXL355, ADXL357 and ADXL359: one register map, one data format, three tables of facts, each a
one-channel part (acceleration).

Sources: Analog Devices data sheets ADXL354/ADXL355 Rev. D, ADXL356/ADXL357 Rev. 0 and ADXL359 Rev. 0
(identification registers, RANGE and FILTER codes, sensitivity, temperature sensor, noise density); the
Linux IIO adxl355 driver and Analog Devices' no-OS adxl355 driver agree on PARTID, scale and temperature
offset per part (see docs/instruments.md).
"""

from __future__ import annotations

from accelcal_rig.parts.part import Channel, Part, TemperatureFormat

#: ODR_LPF codes 0..10 of the FILTER register, in Hz; the low-pass corner is ODR/4. The same on all three.
OUTPUT_DATA_RATES_HZ: tuple[float, ...] = (
    4000.0, 2000.0, 1000.0, 500.0, 250.0, 125.0, 62.5, 31.25, 15.625, 7.813, 3.906,
)
_RANGE_CODES = (0b01, 0b10, 0b11)  # RANGE bits 1:0, lowest range first
_IDENTITY_NAMES = ("DEVID_AD", "DEVID_MST", "PARTID")  # registers 0x00..0x02; REVID (0x03) is the revision


def _acceleration(lsb_per_g: dict[int, float], noise_density_ug_per_rthz: float,
                  zero_g_offset_g: float | None = None) -> Channel:
    return Channel(name="accel", quantity="acceleration", unit="g", lsb_per_unit=lsb_per_g,
                   range_codes=dict(zip(sorted(lsb_per_g), _RANGE_CODES)), code_bits=20,
                   noise_density_micro_per_rthz=noise_density_ug_per_rthz, zero_offset=zero_g_offset_g)


ADXL355 = Part(
    name="adxl355", label="ADXL355", identity=(0xAD, 0x1D, 0xED), identity_names=_IDENTITY_NAMES,
    # the zero-g offset: ±25 mg, as the verified-calibration issue cites the data sheet; see docs/instruments.md
    channels=(_acceleration({2: 256_000.0, 4: 128_000.0, 8: 64_000.0}, 25.0, zero_g_offset_g=0.025),),
    output_data_rates_hz=OUTPUT_DATA_RATES_HZ,
    temperature=TemperatureFormat(bits=12, intercept_lsb=1885.0, slope_lsb_per_c=-9.05),
    source="ADXL354/ADXL355 data sheet Rev. D",
)

#: The ADXL355's sibling for ±10/20/40 g: the same identity registers (PARTID 0xED), 1/5 of the sensitivity.
ADXL357 = Part(
    name="adxl357", label="ADXL357", identity=(0xAD, 0x1D, 0xED), identity_names=_IDENTITY_NAMES,
    channels=(_acceleration({10: 51_200.0, 20: 25_600.0, 40: 12_800.0}, 80.0),),
    output_data_rates_hz=OUTPUT_DATA_RATES_HZ,
    temperature=TemperatureFormat(bits=12, intercept_lsb=1885.0, slope_lsb_per_c=-9.05),
    source="ADXL356/ADXL357 data sheet Rev. 0",
)

#: Ranges and sensitivity of the ADXL357, its own PARTID (0xE9) and temperature intercept (1852 LSB).
ADXL359 = Part(
    name="adxl359", label="ADXL359", identity=(0xAD, 0x1D, 0xE9), identity_names=_IDENTITY_NAMES,
    # Noise density: the ADXL357's figure, not yet checked against the ADXL359 data sheet (docs/instruments.md).
    channels=(_acceleration({10: 51_200.0, 20: 25_600.0, 40: 12_800.0}, 80.0),),
    output_data_rates_hz=OUTPUT_DATA_RATES_HZ,
    temperature=TemperatureFormat(bits=12, intercept_lsb=1852.0, slope_lsb_per_c=-9.05),
    source="ADXL359 data sheet Rev. 0 (identity, ranges); no-OS driver (scale)",
)
