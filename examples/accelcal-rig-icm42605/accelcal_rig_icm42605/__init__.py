"""The TDK InvenSense ICM-42605 as an accelcal-rig part: a six-axis IMU of the ICM-42688-P's family, added from
outside the core through the `accelcal_rig.parts` entry point (this package's pyproject.toml).

It is the built-in ICM-42688-P's table with what differs stated: its own WHO_AM_I (0x42), no 32 kHz and 16 kHz
output data rates, and a noisier gyroscope. What the built-in driver and simulated part use of the ICM-42688-P —
the bank 0 registers (DEVICE_CONFIG, FIFO_CONFIG, TEMP_DATA, INT_STATUS, FIFO_COUNT, FIFO_DATA, SIGNAL_PATH_RESET,
INTF_CONFIG0, PWR_MGMT0, GYRO_CONFIG0, ACCEL_CONFIG0, FIFO_CONFIG1, WHO_AM_I, REG_BANK_SEL), the FS_SEL codes and
sensitivities, the 16-byte FIFO packet and the temperature format (TEMP_DATA / 132.48 + 25 °C) — the ICM-42605
shares, so the part keeps them: its device and the dry run's simulated part are the built-in ones, which read
every part fact from this table.

Sources (see README.md): TDK InvenSense, ICM-42605 data sheet DS-000292 Rev. 1.5 (the full-scale ranges; the
noise densities, 70 µg/√Hz and 3.8 m°/s/√Hz); the Linux IIO inv_icm42600 driver, which drives the ICM-42600
family with one register map (WHO_AM_I 0x42 for the ICM-42605; the ODR codes, 8 kHz = 3 … 12.5 Hz = 11, 500 Hz =
15; the temperature scale and offset).
"""

from __future__ import annotations

from dataclasses import replace

from accelcal_rig.parts.icm42688 import ICM42688P
from accelcal_rig.parts.part import Part

__all__ = ["ICM42605", "ODR_CODES", "OUTPUT_DATA_RATES_HZ"]

#: Output data rates in low-noise mode, in Hz, and their GYRO_CONFIG0/ACCEL_CONFIG0 ODR codes (bits 3:0). The
#: ICM-42688-P's without its 32 kHz and 16 kHz (codes 1 and 2); the accelerometer's low-power-only rates
#: (codes 12…14) are not listed, as for the ICM-42688-P.
OUTPUT_DATA_RATES_HZ: tuple[float, ...] = (8000.0, 4000.0, 2000.0, 1000.0, 200.0, 100.0, 50.0, 25.0, 12.5, 500.0)
ODR_CODES: tuple[int, ...] = (3, 4, 5, 6, 7, 8, 9, 10, 11, 15)

_ACCEL_NOISE_UG_PER_RTHZ = 70.0      # DS-000292: accelerometer noise 70 µg/√Hz (the ICM-42688-P's too)
_GYRO_NOISE_UDPS_PER_RTHZ = 3800.0   # DS-000292: gyroscope noise 3.8 m°/s/√Hz (the ICM-42688-P's: 2.8)


def _icm42605() -> Part:
    """The ICM-42688-P's table with the ICM-42605's identity, rates and noise."""
    accel, gyro = ICM42688P.channel("accel"), ICM42688P.channel("gyro")
    return replace(
        ICM42688P,
        name="icm42605",
        label="ICM-42605",
        identity=(0x42,),
        channels=(replace(accel, noise_density_micro_per_rthz=_ACCEL_NOISE_UG_PER_RTHZ),
                  replace(gyro, noise_density_micro_per_rthz=_GYRO_NOISE_UDPS_PER_RTHZ)),
        output_data_rates_hz=OUTPUT_DATA_RATES_HZ,
        odr_codes=ODR_CODES,
        source="ICM-42605 data sheet DS-000292 Rev. 1.5; Linux IIO inv_icm42600 driver",
    )


#: The part a rig config names as `part: icm42605`.
ICM42605: Part = _icm42605()
