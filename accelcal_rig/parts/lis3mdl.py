"""The ST LIS3MDL: a three-axis magnetometer, one channel (magnetic field, gauss), 16-bit little-endian data
registers, a 16-bit temperature sensor.

Sources (docs/instruments.md, "ST LIS3MDL", cites each): the data sheet DS9463 Rev 7 (WHO_AM_I 0x3D; the ±4, ±8,
±12 and ±16 gauss scales and their sensitivities 6842, 3421, 2281 and 1711 LSB/gauss, Table 2; the output data
rates and their CTRL_REG1 codes, Tables 19 and 21; RMS noise 3.2 mgauss at ±12 gauss in ultra-high-performance
mode; the zero-gauss level ±1 gauss; the temperature sensor's 8 LSB/°C); ST's own driver lis3mdl-pid (the
temperature's zero, 0 LSB at 25 °C; the packed CTRL_REG1 rate codes).
"""

from __future__ import annotations

from accelcal_rig.parts.part import Channel, Part, SpiFraming, TemperatureFormat

#: Output data rates, in Hz, and their codes: CTRL_REG1 bits 6:1 as ST's driver packs them (OM 6:5, DO 4:2,
#: FAST_ODR 1). Up to 80 Hz in ultra-high-performance mode (OM 11); 155, 300, 560 and 1000 Hz are FAST_ODR in
#: the mode that gives each (ultra-high, high, medium performance, low power).
OUTPUT_DATA_RATES_HZ: tuple[float, ...] = (0.625, 1.25, 2.5, 5.0, 10.0, 20.0, 40.0, 80.0, 155.0, 300.0, 560.0, 1000.0)
ODR_CODES: tuple[int, ...] = (0x30, 0x32, 0x34, 0x36, 0x38, 0x3A, 0x3C, 0x3E, 0x31, 0x21, 0x11, 0x01)

#: CTRL_REG2 FS (bits 6:5): ±4 gauss is 0 … ±16 gauss is 3.
_LSB_PER_GAUSS = {4: 6842.0, 8: 3421.0, 12: 2281.0, 16: 1711.0}
_FS = {4: 0, 8: 1, 12: 2, 16: 3}

LIS3MDL = Part(
    name="lis3mdl", label="LIS3MDL", identity=(0x3D,), identity_names=("WHO_AM_I",),
    # Noise density: the data sheet gives 3.2 mgauss RMS (x, y) in ultra-high-performance mode and no density;
    # this one makes the simulation's white noise that RMS at 155 Hz (density × √(π/2 × ODR/4)).
    channels=(Channel(name="mag", quantity="magnetic field", unit="gauss", lsb_per_unit=_LSB_PER_GAUSS,
                      range_codes=_FS, code_bits=16, noise_density_micro_per_rthz=410.0, zero_offset=1.0,
                      default_range=4.0),),  # CTRL_REG2's reset value 0x00: ±4 gauss (the Earth's is below 0.7)
    output_data_rates_hz=OUTPUT_DATA_RATES_HZ,
    odr_codes=ODR_CODES,
    # TEMP_OUT_H/L, signed: °C = TEMP_OUT / 8 + 25 (8 LSB/°C; the zero at 25 °C is ST's driver's).
    temperature=TemperatureFormat(bits=16, intercept_lsb=0.0, slope_lsb_per_c=8.0, signed=True),
    source="LIS3MDL data sheet DS9463 Rev 7; ST lis3mdl-pid driver",
    device="accelcal_rig.instruments.lis3mdl_driver:Lis3mdl",
    simulator="accelcal_rig.sim.lis3mdl_bridge_server:serve_bridge",
    # RW bit 7, MS (auto-increment) bit 6; the clock idles high and data are captured on its rising edge: mode 3
    # (DS9463 §5.2, Figure 4).
    spi=SpiFraming(address_shift=0, read_bit=0x80, burst_bit=0x40, mode=3),
)
