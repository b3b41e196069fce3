"""One sensor's bias as PX4's accelerometer thermal compensation, in a .params file QGroundControl loads.

PX4 (its temperature_compensation module) subtracts offset_i = X0_i + X1_i·dT + X2_i·dT² + X3_i·dT³ in m/s²,
dT = clip(T, TMIN, TMAX) - TREF, from the raw reading of the accelerometer whose device id TC_A<n>_ID names,
before its CAL_ACC offsets and scales: the sensor's bias has a place there, and nothing else of Eq. 1 does.
The sources read are cited in docs/calibration.md ("Exports to PX4 and ArduPilot").
"""

from __future__ import annotations

from accelcal_rig import __version__
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
    offset_cubic,
    range_note,
    refit_note,
    select_sensor,
    steepest_slope_mg_per_c,
)
from accelcal_rig.fit.calibration import CalibrationFile, SensorCalibration

#: TC_A0_… to TC_A3_… (the module's ACCEL_COUNT_MAX is 4); which one holds a sensor does not matter, its ID does.
INSTANCES = (0, 3)
#: MAVLink MAV_PARAM_TYPE of a parameter, which QGroundControl checks against the vehicle's on load.
_INT32, _REAL32 = 6, 9
#: The first two columns: the vehicle's MAVLink system id (QGroundControl refuses a file of another) and the
#: autopilot's component id.
_VEHICLE_ID, _COMPONENT_ID = 1, 1
#: PX4 publishes a new offset only once the temperature has moved more than this (°C) since the last one.
_REPUBLISH_STEP_C = 1.0


def to_px4_params(calibration: CalibrationFile, options: StackOptions) -> ParamsExport:
    """TC_A_ENABLE and the TC_A<n>_ set of one sensor: its bias re-expanded about the middle of its calibrated
    range (TREF, as PX4's own Tools/process_sensor_caldata.py chooses), clipped to that range."""
    sensor = select_sensor(calibration, options)
    n = instance_index(options, *INSTANCES, default=INSTANCES[0], parameters="PX4 (TC_A0_ to TC_A3_)")
    low, high = sensor.validity_c
    cubic = offset_cubic(sensor, round(0.5 * (low + high), 2))  # a TREF the file holds exactly
    device_id = 0 if options.device_id is None else options.device_id
    notes = _notes(sensor, cubic, n, device_id)
    lines = header([
        f"PX4 accelerometer thermal compensation (TC_A{n}_) for sensor {sensor.serial}, written by accelcal-rig "
        f"{__version__} from {options.source.name} (calibration created {calibration.created})",
        "PX4 subtracts offset = X0 + X1*dT + X2*dT^2 + X3*dT^3 (m/s^2) from the raw reading, per axis (_0 x, _1 y, "
        "_2 z), dT = clip(T, TMIN, TMAX) - TREF in degC, before CAL_ACC offsets and scales",
        "TC_A_ENABLE takes effect after a reboot; QGroundControl loads only a file whose first column is the "
        f"vehicle's MAVLink system id (here {_VEHICLE_ID})",
        *notes,
    ])
    rows = ["\t".join((str(_VEHICLE_ID), str(_COMPONENT_ID), name, value, str(kind)))
            for name, value, kind in _parameters(n, device_id, cubic)]
    return ParamsExport(sensor.serial, "\n".join([*lines, "#", "# Vehicle-Id Component-Id Name Value Type", *rows])
                        + "\n", tuple(notes))


def _parameters(n: int, device_id: int, cubic: OffsetCubic) -> list[tuple[str, str, int]]:
    """(name, value, MAV_PARAM_TYPE), sorted by name as QGroundControl writes them."""
    prefix = f"TC_A{n}_"
    params = [("TC_A_ENABLE", "1", _INT32), (f"{prefix}ID", str(device_id), _INT32),
              (f"{prefix}TMIN", number(cubic.t_min_c), _REAL32), (f"{prefix}TMAX", number(cubic.t_max_c), _REAL32),
              (f"{prefix}TREF", number(cubic.t_ref_c), _REAL32)]
    params += [(f"{prefix}X{power}_{axis}", number(cubic.coefficients_m_s2[axis, power]), _REAL32)
               for power in range(STACK_DEGREE + 1) for axis in range(3)]
    return sorted(params)


def _notes(sensor: SensorCalibration, cubic: OffsetCubic, n: int, device_id: int) -> list[str]:
    """What the file cannot carry or needs from the user, stated in its header and on stderr."""
    notes = [not_exported(sensor, "PX4"), range_note(sensor, cubic, "PX4", f"TC_A{n}_TMIN/TMAX"),
             *refit_note(cubic, "PX4"),
             f"TC_A{n}_X0_ holds the offset at TREF = {cubic.t_ref_c:.2f} degC ({mg(cubic.coefficients_m_s2[:, 0])} mg):"
             " the CAL_ACC offsets PX4 subtracts after it must not hold it again",
             f"PX4 renews the offset only after the temperature moved more than {_REPUBLISH_STEP_C:g} degC: up to "
             f"{steepest_slope_mg_per_c(cubic) * _REPUBLISH_STEP_C:.4f} mg at this sensor's steepest bias slope",
             AXES_NOTE]
    if device_id == 0:
        notes.append(f"TC_A{n}_ID is 0, which names no accelerometer: PX4 compensates only the one whose device id "
                     "it holds; pass --device-id (that accelerometer's CAL_ACC<k>_ID) or set it before loading")
    return notes
