"""The safe state: chamber to its safe setpoint, turntable stopped, sensors in standby.

Each device's action runs in its own guard, so one failing device never keeps the others unsafe.
"""

from __future__ import annotations

from collections.abc import Callable

from accelcal_rig.config.procedure import Procedure
from accelcal_rig.config.rig import RigConfig
from accelcal_rig.engine.events import EventLog
from accelcal_rig.instruments.interfaces import Chamber, Sensor, Turntable


def apply_safe_state(chamber: Chamber, turntable: Turntable, sensors: list[Sensor],
                     safe_setpoint_c: float, events: EventLog) -> bool:
    """Run every safe action; return True when all succeeded.

    Failures are logged, never raised, and that includes interrupts: an operator pressing Ctrl-C again
    while the rig is being made safe must not leave the remaining devices as they were.
    """
    actions: list[tuple[str, Callable[[], None]]] = [
        (f"chamber ({chamber.endpoint}) to {safe_setpoint_c:g} °C", lambda: chamber.write_setpoint_c(safe_setpoint_c)),
        (f"turntable ({turntable.endpoint}) stop", turntable.stop),
    ]
    actions += [(f"sensor {s.serial} ({s.endpoint}) standby", s.standby) for s in sensors]
    all_ok = True
    for description, action in actions:
        try:
            action()
            events.info("safe", f"safe state: {description}")
        except BaseException as exc:  # noqa: BLE001 - neither a fault nor a second Ctrl-C may skip a device
            all_ok = False
            events.error("safe", f"safe state FAILED: {description}: {type(exc).__name__}: {exc}")
    return all_ok


def safe_setpoint_c(procedure: Procedure, rig: RigConfig) -> float:
    """Where the chamber goes when the campaign ends or stops: the procedure's choice, else the rig's."""
    return rig.chamber.safe_setpoint_c if procedure.safe_setpoint_c is None else procedure.safe_setpoint_c
