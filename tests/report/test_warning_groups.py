"""A campaign's warnings grouped by kind and instrument, with count, first and last time and whether they
recovered — as a lab reads them, not one raw line per retry attempt."""

from __future__ import annotations

from accelcal_rig.report.warning_groups import warning_groups
from accelcal_rig.store.records import StoredEvent

CHAMBER = "chamber (modbus-tcp 10.0.0.7:502)"
BRIDGE = "sensor bridge (serial /dev/ttyACM1)"


def event(t_s: float, level: str, kind: str, message: str) -> StoredEvent:
    return StoredEvent(t_s, "2026-12-02T00:00:00Z", level, kind, message)


def test_retries_of_one_instrument_are_one_row_and_recover_unless_the_fault_names_it() -> None:
    events = [
        event(10.0, "warning", "retry", f"{CHAMBER}: no reply reading register 2820: Modbus Error: [Input/Output] "
                                        "No response received after 0 retries; attempt 2 of 5 in 0.5 s"),
        event(11.0, "info", "ramp", "ramp 23.0 → -40 °C"),
        event(40.0, "warning", "retry", f"{CHAMBER}: no reply reading register 2821: Modbus Error: [Input/Output] "
                                        "No response received after 0 retries; attempt 3 of 5 in 1 s"),
        event(50.0, "warning", "retry", f"{BRIDGE}: 'R 28 1': no reply within the timeout; attempt 2 of 5 in 0.5 s"),
        event(70.0, "warning", "retry", f"{BRIDGE}: 'R 06 2': no reply within the timeout; attempt 5 of 5 in 8 s"),
        event(90.0, "error", "fault", f"campaign aborted: {BRIDGE}: 'R 06 2': no reply within the timeout"),
        event(95.0, "warning", "fit", "sensor ADX355-A001: 2 temperatures for degree 2: fitted with degree 1"),
    ]
    groups = {(g.kind, g.source): g for g in warning_groups(events)}
    assert list(groups) == [("retry", CHAMBER), ("retry", BRIDGE), ("fit", "sensor ADX355-A001")]  # no fault row
    chamber = groups["retry", CHAMBER]
    assert (chamber.what, chamber.count, chamber.first_s, chamber.last_s, chamber.recovered) == (
        "no reply reading register N", 2, 10.0, 40.0, True)
    bridge = groups["retry", BRIDGE]
    assert (bridge.what, bridge.count, bridge.recovered) == ("no reply within the timeout", 2, False)
    assert bridge.last_message.endswith("attempt 5 of 5 in 8 s")
    fit = groups["fit", "sensor ADX355-A001"]
    assert (fit.what, fit.recovered) == ("N temperatures for degree N", None)


def test_a_message_naming_nothing_is_its_own_what() -> None:
    (group,) = warning_groups([event(1.0, "warning", "soak", "the DUTs drifted 0.4 °C during the poses")])
    assert (group.source, group.what) == ("", "the DUTs drifted N °C during the poses")
