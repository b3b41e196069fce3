"""The safe state: chamber to its safe setpoint, turntable stopped, sensors in standby.

Each device's action runs in its own guard, so one failing device never keeps the others unsafe.
"""

from __future__ import annotations

from collections.abc import Callable

from accelcal_rig.engine.events import EventLog
from accelcal_rig.instruments.interfaces import Accelerometer, Chamber, Turntable


def apply_safe_state(chamber: Chamber, turntable: Turntable, sensors: list[Accelerometer],
                     safe_setpoint_c: float, events: EventLog) -> bool:
    """Run every safe action; return True when all succeeded (failures are logged, never raised)."""
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
        except Exception as exc:  # noqa: BLE001 - one device's failure must not stop the next device
            all_ok = False
            events.error("safe", f"safe state FAILED: {description}: {exc}")
    return all_ok
