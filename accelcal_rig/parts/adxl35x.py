"""The ADXL355, ADXL357 and ADXL359: one register map, one data format, three tables of facts.

Sources: Analog Devices data sheets ADXL354/ADXL355 Rev. D, ADXL356/ADXL357 Rev. 0 and ADXL359 Rev. 0
(identification registers, RANGE and FILTER codes, sensitivity, temperature sensor, noise density); the
Linux IIO adxl355 driver and Analog Devices' no-OS adxl355 driver agree on PARTID, scale and temperature
offset per part (see docs/instruments.md).
"""

from __future__ import annotations

from accelcal_rig.parts.part import AccelerometerPart, TemperatureFormat

#: ODR_LPF codes 0..10 of the FILTER register, in Hz; the low-pass corner is ODR/4. The same on all three.
OUTPUT_DATA_RATES_HZ: tuple[float, ...] = (
    4000.0, 2000.0, 1000.0, 500.0, 250.0, 125.0, 62.5, 31.25, 15.625, 7.813, 3.906,
)
_RANGE_CODES = (0b01, 0b10, 0b11)  # RANGE bits 1:0, lowest range first

ADXL355 = AccelerometerPart(
    name="adxl355", label="ADXL355", identity=(0xAD, 0x1D, 0xED),
    lsb_per_g={2: 256_000.0, 4: 128_000.0, 8: 64_000.0},
    range_codes=dict(zip((2, 4, 8), _RANGE_CODES)),
    output_data_rates_hz=OUTPUT_DATA_RATES_HZ, code_bits=20,
    temperature=TemperatureFormat(bits=12, intercept_lsb=1885.0, slope_lsb_per_c=-9.05),
    noise_density_ug_per_rthz=25.0, source="ADXL354/ADXL355 data sheet Rev. D",
    zero_g_offset_mg=25.0,  # as the verified-calibration issue cites the data sheet; see docs/instruments.md
)

#: The ADXL355's sibling for ±10/20/40 g: the same identity registers (PARTID 0xED), 1/5 of the sensitivity.
ADXL357 = AccelerometerPart(
    name="adxl357", label="ADXL357", identity=(0xAD, 0x1D, 0xED),
    lsb_per_g={10: 51_200.0, 20: 25_600.0, 40: 12_800.0},
    range_codes=dict(zip((10, 20, 40), _RANGE_CODES)),
    output_data_rates_hz=OUTPUT_DATA_RATES_HZ, code_bits=20,
    temperature=TemperatureFormat(bits=12, intercept_lsb=1885.0, slope_lsb_per_c=-9.05),
    noise_density_ug_per_rthz=80.0, source="ADXL356/ADXL357 data sheet Rev. 0",
)

#: Ranges and sensitivity of the ADXL357, its own PARTID (0xE9) and temperature intercept (1852 LSB).
ADXL359 = AccelerometerPart(
    name="adxl359", label="ADXL359", identity=(0xAD, 0x1D, 0xE9),
    lsb_per_g={10: 51_200.0, 20: 25_600.0, 40: 12_800.0},
    range_codes=dict(zip((10, 20, 40), _RANGE_CODES)),
    output_data_rates_hz=OUTPUT_DATA_RATES_HZ, code_bits=20,
    temperature=TemperatureFormat(bits=12, intercept_lsb=1852.0, slope_lsb_per_c=-9.05),
    # Noise density: the ADXL357's figure, not yet checked against the ADXL359 data sheet (docs/instruments.md).
    noise_density_ug_per_rthz=80.0, source="ADXL359 data sheet Rev. 0 (identity, ranges); no-OS driver (scale)",
)
