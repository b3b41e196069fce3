"""The TDK InvenSense ICM-42688-P: a six-axis IMU, two channels (acceleration, angular rate) on one register
map, 16-bit data registers, a signed 16-bit temperature.

Sources (docs/instruments.md, "TDK ICM-42688-P", cites each): the data sheet DS-000347 (noise densities,
sensitivities per range, temperature formula); the Linux IIO driver drivers/iio/imu/inv_icm42600/ (WHO_AM_I
0x47 since TDK's "add support of ICM-42688-P" patch; FS_SEL and ODR codes; temperature scale and offset).
"""

from __future__ import annotations

from accelcal_rig.parts.part import Channel, Part, SpiFraming, TemperatureFormat

#: Output data rates in low-noise mode (both sensors), in Hz, and their ACCEL_CONFIG0/GYRO_CONFIG0 ODR codes
#: (bits 3:0). 6.25, 3.125 and 1.5625 Hz (codes 12–14) are the accelerometer's low-power mode only: not listed.
OUTPUT_DATA_RATES_HZ: tuple[float, ...] = (
    32000.0, 16000.0, 8000.0, 4000.0, 2000.0, 1000.0, 200.0, 100.0, 50.0, 25.0, 12.5, 500.0,
)
ODR_CODES: tuple[int, ...] = (1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 15)

#: ACCEL_CONFIG0 ACCEL_FS_SEL (bits 7:5): ±16 g is 0 … ±2 g is 3; 32768 LSB over the full scale.
_ACCEL_LSB_PER_G = {2: 16384.0, 4: 8192.0, 8: 4096.0, 16: 2048.0}
_ACCEL_FS_SEL = {16: 0, 8: 1, 4: 2, 2: 3}

#: GYRO_CONFIG0 GYRO_FS_SEL (bits 7:5): ±2000 °/s is 0 … ±15.625 °/s is 7. Sensitivities as the data sheet
#: rounds them (16.4 LSB/(°/s) at ±2000; the Linux driver's scale is 32768/2000 = 16.384).
_GYRO_LSB_PER_DPS = {2000: 16.4, 1000: 32.8, 500: 65.5, 250: 131.0, 125: 262.0, 62.5: 524.3, 31.25: 1048.6,
                     15.625: 2097.2}
_GYRO_FS_SEL = {2000: 0, 1000: 1, 500: 2, 250: 3, 125: 4, 62.5: 5, 31.25: 6, 15.625: 7}

ICM42688P = Part(
    name="icm42688p", label="ICM-42688-P", identity=(0x47,), identity_names=("WHO_AM_I",),
    channels=(
        Channel(name="accel", quantity="acceleration", unit="g", lsb_per_unit=_ACCEL_LSB_PER_G,
                range_codes=_ACCEL_FS_SEL, code_bits=16, noise_density_micro_per_rthz=70.0),
        Channel(name="gyro", quantity="angular rate", unit="dps", lsb_per_unit=_GYRO_LSB_PER_DPS,
                range_codes=_GYRO_FS_SEL, code_bits=16, noise_density_micro_per_rthz=2800.0),
    ),
    output_data_rates_hz=OUTPUT_DATA_RATES_HZ,
    odr_codes=ODR_CODES,
    # TEMP_DATA1/TEMP_DATA0, signed: °C = TEMP_DATA / 132.48 + 25.
    temperature=TemperatureFormat(bits=16, intercept_lsb=0.0, slope_lsb_per_c=132.48, signed=True),
    source="ICM-42688-P data sheet DS-000347; Linux IIO inv_icm42600 driver",
    device="accelcal_rig.instruments.icm42688_driver:Icm42688",
    simulator="accelcal_rig.sim.icm42688_bridge_server:serve_bridge",
    spi=SpiFraming(address_shift=0, read_bit=0x80),  # bit 7 set reads (docs/instruments.md, TDK ICM-42688-P)
    fifo_sample_bytes=16,  # packet 3: header, accelerometer, gyroscope, temperature, timestamp
)
