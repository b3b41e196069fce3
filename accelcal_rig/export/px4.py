"""One sensor's bias as PX4's accelerometer (and, where the DUT has a calibrated gyroscope, gyro) thermal
compensation, in a .params file QGroundControl loads.

PX4 (its temperature_compensation module) subtracts offset_i = X0_i + X1_i·dT + X2_i·dT² + X3_i·dT³,
dT = clip(T, TMIN, TMAX) - TREF, from the raw reading of the sensor whose device id TC_A<n>_ID (TC_G<n>_ID)
names: in m/s² before the accelerometer's CAL_ACC offsets and scales, in rad/s before the gyroscope's CAL_GYRO
offsets. The bias has a place there, and nothing else of either model does.
The sources read are cited in docs/calibration.md ("Exports to PX4 and ArduPilot").
"""

from __future__ import annotations

from accelcal_rig import __version__
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
    offset_cubic,
    range_held,
    range_note,
    refit_note,
    select_sensor,
    steepest_slope,
    steepest_slope_mg_per_c,
)
from accelcal_rig.fit.calibration import CalibrationFile, ChannelCalibration

#: TC_A0_… to TC_A3_… and TC_G0_… to TC_G3_… (the module's ACCEL_COUNT_MAX and GYRO_COUNT_MAX are 4); which one
#: holds a sensor does not matter, its ID does.
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
    range (TREF, as PX4's own Tools/process_sensor_caldata.py chooses), clipped to that range; where the DUT's
    gyroscope is calibrated, TC_G_ENABLE and the TC_G<n>_ set of its bias in rad/s, made the same way."""
    sensor = select_sensor(calibration, options)
    n = instance_index(options, *INSTANCES, default=INSTANCES[0], parameters="PX4 (TC_A0_ to TC_A3_)")
    low, high = sensor.validity_c
    cubic = offset_cubic(sensor, round(0.5 * (low + high), 2))  # a TREF the file holds exactly
    gyro = gyro_of(calibration, sensor.serial)
    gyro_cubic = None if gyro is None else offset_cubic(gyro, round(0.5 * sum(gyro.validity_c), 2))
    device_id = 0 if options.device_id is None else options.device_id
    notes = _notes(sensor, cubic, n, device_id)
    if gyro is not None and gyro_cubic is not None:
        notes += _gyro_notes(gyro, gyro_cubic, n, device_id)
    sets = f"TC_A{n}_" if gyro is None else f"TC_A{n}_, TC_G{n}_"
    lines = header([
        f"PX4 {'accelerometer' if gyro is None else 'accelerometer and gyro'} thermal compensation "
        f"({sets}) for sensor {sensor.serial}, written by accelcal-rig "
        f"{__version__} from {options.source.name} (calibration created {calibration.created})",
        "PX4 subtracts offset = X0 + X1*dT + X2*dT^2 + X3*dT^3 (m/s^2) from the raw reading, per axis (_0 x, _1 y, "
        "_2 z), dT = clip(T, TMIN, TMAX) - TREF in degC, before CAL_ACC offsets and scales",
        *([] if gyro is None else [
            "the same for the gyro (TC_G): offset in rad/s subtracted from the raw rate before the CAL_GYRO offsets"]),
        f"TC_A_ENABLE{'' if gyro is None else ' and TC_G_ENABLE'} take effect after a reboot; QGroundControl loads "
        f"only a file whose first column is the vehicle's MAVLink system id (here {_VEHICLE_ID})",
        *notes,
    ])
    params = _parameters("A", n, device_id, cubic)
    if gyro_cubic is not None:
        params = sorted(params + _parameters("G", n, device_id, gyro_cubic))
    rows = ["\t".join((str(_VEHICLE_ID), str(_COMPONENT_ID), name, value, str(kind))) for name, value, kind in params]
    return ParamsExport(sensor.serial, "\n".join([*lines, "#", "# Vehicle-Id Component-Id Name Value Type", *rows])
                        + "\n", tuple(notes))


def _parameters(kind: str, n: int, device_id: int, cubic: OffsetCubic) -> list[tuple[str, str, int]]:
    """(name, value, MAV_PARAM_TYPE) of TC_<kind>_ENABLE and the TC_<kind><n>_ set (kind A or G), sorted by
    name as QGroundControl writes them."""
    prefix = f"TC_{kind}{n}_"
    params = [(f"TC_{kind}_ENABLE", "1", _INT32), (f"{prefix}ID", str(device_id), _INT32),
              (f"{prefix}TMIN", number(cubic.t_min_c), _REAL32), (f"{prefix}TMAX", number(cubic.t_max_c), _REAL32),
              (f"{prefix}TREF", number(cubic.t_ref_c), _REAL32)]
    params += [(f"{prefix}X{power}_{axis}", number(cubic.coefficients[axis, power]), _REAL32)
               for power in range(STACK_DEGREE + 1) for axis in range(3)]
    return sorted(params)


def _notes(sensor: ChannelCalibration, cubic: OffsetCubic, n: int, device_id: int) -> list[str]:
    """What the file cannot carry or needs from the user, stated in its header and on stderr."""
    notes = [not_exported(sensor, "PX4"), range_note(sensor, cubic, "PX4", f"TC_A{n}_TMIN/TMAX"),
             *refit_note(cubic, "PX4"),
             f"TC_A{n}_X0_ holds the offset at TREF = {cubic.t_ref_c:.2f} degC ({mg(cubic.coefficients[:, 0])} mg):"
             " the CAL_ACC offsets PX4 subtracts after it must not hold it again",
             f"PX4 renews the offset only after the temperature moved more than {_REPUBLISH_STEP_C:g} degC: up to "
             f"{steepest_slope_mg_per_c(cubic) * _REPUBLISH_STEP_C:.4f} mg at this sensor's steepest bias slope",
             AXES_NOTE]
    if device_id == 0:
        notes.append(f"TC_A{n}_ID is 0, which names no accelerometer: PX4 compensates only the one whose device id "
                     "it holds; pass --device-id (that accelerometer's CAL_ACC<k>_ID) or set it before loading")
    return notes


def _gyro_notes(gyro: ChannelCalibration, cubic: OffsetCubic, n: int, device_id: int) -> list[str]:
    """The gyroscope's statements: what TC_G cannot hold, its range, X0, the republish step and its ID."""
    notes = [gyro_not_exported(gyro, "PX4"), range_note(gyro, cubic, "PX4", f"TC_G{n}_TMIN/TMAX", "gyro temperature"),
             *refit_note(cubic, "PX4", what="gyro bias"),
             f"TC_G{n}_X0_ holds the gyro offset at TREF = {cubic.t_ref_c:.2f} degC ({dps(cubic.coefficients[:, 0])} "
             "deg/s): the CAL_GYRO offsets PX4 subtracts after it must not hold it again (zero them, and do not "
             "recalibrate the gyro with TC_G_ENABLE off)",
             f"PX4 renews the gyro offset only after the temperature moved more than {_REPUBLISH_STEP_C:g} degC: up "
             f"to {steepest_slope(cubic) / RAD_PER_DEG * _REPUBLISH_STEP_C:.5f} deg/s at this gyro's steepest bias "
             "slope", range_held(gyro), GYRO_AXES_NOTE]
    if device_id == 0:
        notes.append(f"TC_G{n}_ID is 0, which names no gyro: pass --device-id or set TC_G{n}_ID to the gyro's "
                     "CAL_GYRO<k>_ID before loading")
    else:
        notes.append(f"TC_G{n}_ID is --device-id as TC_A{n}_ID: right where the driver gives the part's accelerometer "
                     "and gyro one device id (a single-die IMU such as PX4's MPU9250 driver); a part with a gyro die "
                     f"of its own (BMI055) has its own: set TC_G{n}_ID to that gyro's CAL_GYRO<k>_ID")
    return notes
