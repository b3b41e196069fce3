"""One sensor's bias as ArduPilot's IMU temperature calibration (INS_TCAL<n>_), in a .param file.

ArduPilot subtracts P(T) - P(T_cal) from the raw reading in m/s², P(t) = (ACC1·u + ACC2·u² + ACC3·u³)·1e-6 with
u = clip(t, TMIN, TMAX) - 35 °C, T_cal the temperature of its own accelerometer calibration (INS_ACC<n>_CALTEMP),
before that calibration's offsets and scales. The cubic has no constant: the offset itself is what the
accelerometer calibration's offsets hold. Where the DUT's gyroscope is calibrated, GYR1…GYR3 hold its bias the
same way in rad/s, T_cal then the temperature of the boot-time gyro calibration (INS_GYR<n>_CALTEMP) whose
INS_GYROFFS hold the offset. The sources read are cited in docs/calibration.md.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from accelcal_rig import __version__
from accelcal_rig.errors import ConfigError
from accelcal_rig.export.flight_stack import (
    AXES_NOTE,
    GYRO_AXES_NOTE,
    RAD_PER_DEG,
    STACK_DEGREE,
    OffsetCubic,
    ParamsExport,
    StackOptions,
    dps,
    gyro_not_exported,
    gyro_of,
    header,
    instance_index,
    mg,
    not_exported,
    number,
    offset_at,
    offset_cubic,
    range_held,
    range_note,
    refit_note,
    select_sensor,
)
from accelcal_rig.fit.calibration import CalibrationFile, ChannelCalibration

#: INS_TCAL1_ to INS_TCAL3_, one per IMU.
INSTANCES = (1, 3)
#: ArduPilot expands every temperature calibration about this fixed temperature (°C).
REFERENCE_C = 35.0
#: ArduPilot stores the coefficients times this, so parameter editors show them without exponents.
SCALE = 1e6


def to_ardupilot_params(calibration: CalibrationFile, options: StackOptions) -> ParamsExport:
    """INS_TCAL<n>_ENABLE, TMIN, TMAX and ACC1…ACC3 of one sensor: its bias about 35 °C without the constant."""
    if options.device_id is not None:
        raise ConfigError("--device-id is PX4's TC_A<n>_ID: ArduPilot's INS_TCAL<n>_ is for IMU n, chosen by --instance")
    sensor = select_sensor(calibration, options)
    n = instance_index(options, *INSTANCES, default=INSTANCES[0], parameters="ArduPilot (INS_TCAL1_ to INS_TCAL3_)")
    cubic = offset_cubic(sensor, REFERENCE_C)
    gyro = gyro_of(calibration, sensor.serial)
    gyro_cubic = None if gyro is None else offset_cubic(gyro, REFERENCE_C)
    notes = _notes(sensor, cubic, n)
    if gyro is not None and gyro_cubic is not None:
        notes += _gyro_notes(gyro, gyro_cubic, cubic, n)
    lines = header([
        f"ArduPilot IMU temperature calibration (INS_TCAL{n}_) for sensor {sensor.serial}, written by accelcal-rig "
        f"{__version__} from {options.source.name} (calibration created {calibration.created})",
        "ArduPilot subtracts P(T) - P(T_cal) (m/s^2) from the raw reading, per axis, P(t) = (ACC1*u + ACC2*u^2 + "
        f"ACC3*u^3) * 1e-6, u = clip(t, TMIN, TMAX) - {REFERENCE_C:g} degC, T_cal = INS_ACC{n}_CALTEMP, before "
        "the INS_ACC offsets and scales",
        *([] if gyro is None else [
            "the gyro the same with GYR1..GYR3 in rad/s, T_cal = INS_GYR{n}_CALTEMP, before the INS_GYROFFS offsets"
            .replace("{n}", str(n))]),
        *notes,
    ])
    rows = [f"{name} {value}" for name, value in _parameters(n, cubic, gyro_cubic)]
    return ParamsExport(sensor.serial, "\n".join([*lines, *rows]) + "\n", tuple(notes))


def _parameters(n: int, cubic: OffsetCubic, gyro_cubic: OffsetCubic | None) -> list[tuple[str, str]]:
    """(name, value): ENABLE, TMIN, TMAX, ACC1…ACC3 in the order ArduPilot's Tools/scripts/tempcal_IMU.py writes
    them, then the gyro's GYR1…GYR3 where there is one. One TMIN/TMAX serves both: the accelerometer's range (the
    gyroscope's own is stated where it differs)."""
    prefix = f"INS_TCAL{n}_"
    params = [(f"{prefix}ENABLE", "1"), (f"{prefix}TMIN", number(cubic.t_min_c)),
              (f"{prefix}TMAX", number(cubic.t_max_c))]
    params += [(f"{prefix}ACC{power}_{axis}", number(cubic.coefficients[index, power] * SCALE))
               for power in range(1, STACK_DEGREE + 1) for index, axis in enumerate("XYZ")]
    if gyro_cubic is not None:
        params += [(f"{prefix}GYR{power}_{axis}", number(gyro_cubic.coefficients[index, power] * SCALE))
                   for power in range(1, STACK_DEGREE + 1) for index, axis in enumerate("XYZ")]
    return params


def _offsets_name(n: int) -> str:
    """IMU 1's accelerometer offsets are INS_ACCOFFS_*, IMU 2's INS_ACC2OFFS_*, IMU 3's INS_ACC3OFFS_*."""
    return f"INS_ACC{'' if n == 1 else n}OFFS_X/Y/Z"


def _notes(sensor: ChannelCalibration, cubic: OffsetCubic, n: int) -> list[str]:
    """What the file cannot carry or needs from the user, stated in its header and on stderr."""
    at_c = min(max(REFERENCE_C, cubic.t_min_c), cubic.t_max_c)
    return [not_exported(sensor, "ArduPilot"), range_note(sensor, cubic, "ArduPilot", f"INS_TCAL{n}_TMIN/TMAX"),
            *refit_note(cubic, "ArduPilot", since="T_cal"),
            f"the offset itself is not in the file (at {at_c:.2f} degC it is {mg(offset_at(cubic, at_c))} mg):"
            f" ArduPilot's cubic has no constant and removes only the change since T_cal; its accelerometer "
            f"calibration holds the offset ({_offsets_name(n)}, at the T_cal it records in INS_ACC{n}_CALTEMP): "
            "run it after loading this file", AXES_NOTE]


def _gyro_offsets_name(n: int) -> str:
    """IMU 1's gyro offsets are INS_GYROFFS_*, IMU 2's INS_GYR2OFFS_*, IMU 3's INS_GYR3OFFS_*."""
    return f"INS_GYR{'' if n == 1 else n}OFFS_X/Y/Z"


def _gyro_notes(gyro: ChannelCalibration, cubic: OffsetCubic, accel: OffsetCubic, n: int) -> list[str]:
    """The gyroscope's statements: what GYR1…GYR3 cannot hold, the range it shares with the accelerometer, and
    the offset left to ArduPilot's boot-time gyro calibration."""
    at_c = min(max(REFERENCE_C, accel.t_min_c), accel.t_max_c)
    low, high = gyro.validity_c
    grid = np.linspace(low, high, 401)
    shared = np.array([offset_at(cubic, t) - offset_at(replace(cubic, t_min_c=accel.t_min_c, t_max_c=accel.t_max_c), t)
                       for t in grid])
    notes = [gyro_not_exported(gyro, "ArduPilot"),
             f"gyro temperature: calibrated {low:.2f} to {high:.2f} degC; ArduPilot clips it to the accelerometer's "
             f"INS_TCAL{n}_TMIN/TMAX ({accel.t_min_c:.2f} to {accel.t_max_c:.2f} degC), which it shares: up to "
             f"{np.max(np.abs(shared)) / RAD_PER_DEG:.6f} deg/s from the gyro's bias within its own range",
             *refit_note(cubic, "ArduPilot", since="T_cal", what="gyro bias"),
             f"the gyro offset itself is not in the file (at {at_c:.2f} degC it is {dps(offset_at(cubic, at_c))} deg/s): "
             "ArduPilot removes only its change since T_cal; the gyro calibration it runs at every boot "
             f"(INS_GYR_CAL 1) measures the offset into {_gyro_offsets_name(n)} with the temperature correction off "
             f"and records T_cal in INS_GYR{n}_CALTEMP: keep the vehicle still at boot (what it measures also holds "
             "the Earth's rate and the g-sensitivity at that attitude)", range_held(gyro), GYRO_AXES_NOTE]
    return notes
