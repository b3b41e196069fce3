"""One sensor's bias as ArduPilot's IMU temperature calibration (INS_TCAL<n>_), in a .param file.

ArduPilot subtracts P(T) - P(T_cal) from the raw reading in m/s², P(t) = (ACC1·u + ACC2·u² + ACC3·u³)·1e-6 with
u = clip(t, TMIN, TMAX) - 35 °C, T_cal the temperature of its own accelerometer calibration (INS_ACC<n>_CALTEMP),
before that calibration's offsets and scales. The cubic has no constant: the offset itself is what the
accelerometer calibration's offsets hold. The sources read are cited in docs/calibration.md.
"""

from __future__ import annotations

from accelcal_rig import __version__
from accelcal_rig.errors import ConfigError
from accelcal_rig.export.flight_stack import (
    AXES_NOTE,
    STACK_DEGREE,
    OffsetCubic,
    ParamsExport,
    StackOptions,
    header,
    instance_index,
    mg,
    not_exported,
    number,
    offset_at,
    offset_cubic,
    range_note,
    refit_note,
    select_sensor,
)
from accelcal_rig.fit.calibration import CalibrationFile, SensorCalibration

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
    notes = _notes(sensor, cubic, n)
    lines = header([
        f"ArduPilot IMU temperature calibration (INS_TCAL{n}_) for sensor {sensor.serial}, written by accelcal-rig "
        f"{__version__} from {options.source.name} (calibration created {calibration.created})",
        "ArduPilot subtracts P(T) - P(T_cal) (m/s^2) from the raw reading, per axis, P(t) = (ACC1*u + ACC2*u^2 + "
        f"ACC3*u^3) * 1e-6, u = clip(t, TMIN, TMAX) - {REFERENCE_C:g} degC, T_cal = INS_ACC{n}_CALTEMP, before "
        "the INS_ACC offsets and scales",
        *notes,
    ])
    rows = [f"{name} {value}" for name, value in _parameters(n, cubic)]
    return ParamsExport(sensor.serial, "\n".join([*lines, *rows]) + "\n", tuple(notes))


def _parameters(n: int, cubic: OffsetCubic) -> list[tuple[str, str]]:
    """(name, value) in the order ArduPilot's Tools/scripts/tempcal_IMU.py writes them."""
    prefix = f"INS_TCAL{n}_"
    params = [(f"{prefix}ENABLE", "1"), (f"{prefix}TMIN", number(cubic.t_min_c)),
              (f"{prefix}TMAX", number(cubic.t_max_c))]
    params += [(f"{prefix}ACC{power}_{axis}", number(cubic.coefficients_m_s2[index, power] * SCALE))
               for power in range(1, STACK_DEGREE + 1) for index, axis in enumerate("XYZ")]
    return params


def _offsets_name(n: int) -> str:
    """IMU 1's accelerometer offsets are INS_ACCOFFS_*, IMU 2's INS_ACC2OFFS_*, IMU 3's INS_ACC3OFFS_*."""
    return f"INS_ACC{'' if n == 1 else n}OFFS_X/Y/Z"


def _notes(sensor: SensorCalibration, cubic: OffsetCubic, n: int) -> list[str]:
    """What the file cannot carry or needs from the user, stated in its header and on stderr."""
    at_c = min(max(REFERENCE_C, cubic.t_min_c), cubic.t_max_c)
    return [not_exported(sensor, "ArduPilot"), range_note(sensor, cubic, "ArduPilot", f"INS_TCAL{n}_TMIN/TMAX"),
            *refit_note(cubic, "ArduPilot", since="T_cal"),
            f"the offset itself is not in the file (at {at_c:.2f} degC it is {mg(offset_at(cubic, at_c))} mg):"
            f" ArduPilot's cubic has no constant and removes only the change since T_cal; its accelerometer "
            f"calibration holds the offset ({_offsets_name(n)}, at the T_cal it records in INS_ACC{n}_CALTEMP): "
            "run it after loading this file", AXES_NOTE]
