"""Every bad procedure or rig file is refused with `file:line: key: message` before anything moves."""

from pathlib import Path

import pytest

from accelcal_rig.config.load import load_procedure, load_rig
from accelcal_rig.engine.preparation import prepare
from accelcal_rig.errors import ConfigError
from tests.conftest import REPO, TINY_PROCEDURE


@pytest.mark.parametrize("path", sorted((REPO / "procedures").glob("*.yaml")))
def test_shipped_procedures_prepare(path: Path) -> None:
    prepared = prepare(path)
    assert prepared.plan.pose_steps


def test_setpoint_range_shorthand_expands() -> None:
    procedure = load_procedure(REPO / "procedures" / "paper-24pos-thermal.yaml").model
    assert procedure.setpoints_c == [-40, -30, -20, -10, 0, 10, 20, 30, 40, 50, 60]


@pytest.mark.parametrize(
    ("replace", "by", "expected"),
    [
        ("samples_per_pose: 20", "samples_per_pose: 1", r"tiny.yaml:6: acquisition.samples_per_pose: .*greater than or equal to 2"),
        ("odr_hz: 125", "odr_hz: 5000", r"tiny.yaml:6: acquisition.odr_hz: 5000 Hz is faster than every ADXL355 output "
                                        r"data rate"),
        ("range_g: 2", "range_g: 3", r"tiny.yaml:6: acquisition.range_g: "),
        ("kind: six-position", "kind: seven-position", r"tiny.yaml:5: schedule: "),
        ("kind: six-position", "kind: sphere", r"tiny.yaml:5: schedule.count: Field required"),
        ("band_c: 0.3", "band_c: wide", r"tiny.yaml:4: soak.band_c: expected a number, got the text 'wide'$"),
        ("band_c: 0.3", "bnad_c: 0.3", r"tiny.yaml:4: soak.bnad_c: unknown key; did you mean band_c?"),
        ("timeout_min: 120", "timeout_min: 1", r"tiny.yaml:4: soak: timeout_min must be at least"),
        ("setpoints_c: [30]", "setpoints_c: [30, 30]", r"tiny.yaml:3: setpoints_c: setpoints must be distinct"),
        ("setpoints_c: [30]", "setpoints_c: {from_c: 0, to_c: 10}", r"tiny.yaml:3: setpoints_c: a setpoint range needs"),
    ],
)
def test_procedure_errors_name_file_line_and_key(write, replace: str, by: str, expected: str) -> None:
    path = write("tiny.yaml", TINY_PROCEDURE.replace(replace, by))
    with pytest.raises(ConfigError, match=expected):
        prepare(path)


def test_setpoint_outside_chamber_limits_points_at_the_setpoint(write) -> None:
    path = write("tiny.yaml", TINY_PROCEDURE.replace("setpoints_c: [30]", "setpoints_c:\n  - 30\n  - 120\n"))
    with pytest.raises(ConfigError, match=r"tiny.yaml:5: setpoints_c\[1\]: 120 °C is outside the chamber limits"):
        prepare(path)


def test_explicit_angles_checked_against_axis_count(write) -> None:
    text = TINY_PROCEDURE.replace("schedule: {kind: six-position}",
                                  "schedule:\n  kind: explicit\n  angles_deg:\n    - [0, 0, 0]\n    - [0, 90]\n")
    with pytest.raises(ConfigError, match=r"tiny.yaml:9: schedule.angles_deg\[1\]: 2 angles given"):
        prepare(write("tiny.yaml", text))


def test_unreachable_schedule_is_a_config_error(write, workdir: Path) -> None:
    rig = (workdir / "sim.yaml").read_text().replace(
        "{name: middle, axis: [1, 0, 0], min_deg: -180, max_deg: 180, continuous: true, speed_deg_s: 20}",
        "{name: middle, axis: [1, 0, 0], min_deg: -90, max_deg: 90, speed_deg_s: 20}",
    )
    (workdir / "sim.yaml").write_text(rig)
    with pytest.raises(ConfigError, match=r"tiny.yaml:5: schedule: gravity direction .* out of reach"):
        prepare(write("tiny.yaml", TINY_PROCEDURE))


def test_missing_rig_file_is_named(write) -> None:
    path = write("tiny.yaml", TINY_PROCEDURE.replace("rig: sim.yaml", "rig: nowhere.yaml"))
    with pytest.raises(ConfigError, match=r"tiny.yaml:2: rig: .*nowhere.yaml: no such rig config"):
        prepare(path)


@pytest.mark.parametrize(
    ("replace", "by", "expected"),
    [
        ("safe_setpoint_c: 23", "safe_setpoint_c: 150", r"sim.yaml:\d+: chamber: safe_setpoint_c must lie within"),
        ("serial: ADX355-A002", "serial: ADX355-A001", r"sim.yaml:\d+: fixture.sensors: sensor serial numbers must be distinct"),
        ("axis: [1, 0, 0]", "axis: [0, 0, 0]", r"sim.yaml:\d+: turntable.axes\[1\].axis: axis direction must not be zero"),
        ("ramp_rate_c_per_min: 3", "ramp_rate_c_per_min: -3", r"sim.yaml:\d+: chamber.ramp_rate_c_per_min: "),
        ("driver: modbus-tcp\n", "driver: modbus\n", r"sim.yaml:\d+: chamber.driver: "),
        ("profile: watlow-f4t", "profile: watlow-f4t\n  registers: {process_value: -1}",
         r"sim.yaml:\d+: chamber: registers.process_value: Input should be greater than or equal to 0"),
        ("profile: watlow-f4t", "profile: watlow-f4t\n  registers: {setpiont: 300}",
         r"sim.yaml:\d+: chamber: registers.setpiont: Extra inputs are not permitted"),
        ("profile: watlow-f4t", "profile: watlow-f4t\n  endpoint: chamber.local",
         r"sim.yaml:\d+: chamber: modbus-tcp endpoint 'chamber.local' is not host:port"),
        ("protocol: accelcal-line", "protocol: accelcal-line\n  protocol_overrides: {busy: {send: B, reply: '(', answer: '0'}}",
         r"sim.yaml:\d+: turntable: protocol_overrides.busy.reply: Value error, not a regular expression"),
    ],
)
def test_rig_errors_name_file_line_and_key(workdir: Path, replace: str, by: str, expected: str) -> None:
    path = workdir / "sim.yaml"
    text = path.read_text()
    assert replace in text
    path.write_text(text.replace(replace, by, 1))
    with pytest.raises(ConfigError, match=expected):
        load_rig(path)


def test_a_schedule_that_cannot_determine_the_fit_is_refused_before_the_campaign(write) -> None:
    text = TINY_PROCEDURE + "fit: {mode: norm-only}\n"  # six positions cannot fix nine parameters from |g|
    with pytest.raises(ConfigError, match=r"tiny.yaml:7: fit.mode: too few poses: 6 poses give 6 equations"):
        prepare(write("tiny.yaml", text))
    prepare(write("tiny.yaml", TINY_PROCEDURE + "fit: {mode: norm-only, parameters: bias-scale}\n"))


SETPOINTS = TINY_PROCEDURE.replace("setpoints_c: [30]", "setpoints_c: [20, 40]")


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        (SETPOINTS + "verify: {schedule: {kind: sphere, count: 8}, setpoints_c: [50]}\n",
         r"verify.setpoints_c: 50 °C is outside the calibrated range 20 … 40 °C"),
        (SETPOINTS + "verify: {schedule: {kind: sphere, count: 8}, setpoints_c: [40]}\n",
         r"verify.setpoints_c: 40 °C is a calibration setpoint"),
        (SETPOINTS + "verify: {schedule: {kind: sphere, count: 8}, at_setpoints: false}\n",
         r"verify: .*verification needs at_setpoints: true or setpoints_c"),
        (SETPOINTS + "acceptance: {max_verification_rmse_mg: 0.05}\n",
         r"acceptance.max_verification_rmse_mg is judged on verification records: add a verify: section"),
        (SETPOINTS + "acceptance: {parameters: {at_c: 0, bias_mg: 25}}\n",
         r"acceptance.parameters.at_c: 0 °C is outside the calibrated range 20 … 40 °C"),
        (SETPOINTS + "acceptance: {max_tilt_error_deg: 0}\n", r"tiny.yaml:\d+: acceptance.max_tilt_error_deg: .*greater than 0"),
        (SETPOINTS + "cooldown: {pose: 1}\nverify: {schedule: {kind: sphere, count: 8}}\n",
         r"a cool-down procedure"),
        (TINY_PROCEDURE + "verify: {schedule: {kind: sphere, count: 8}}\nacceptance: {max_drift_mg: 0.1}\n",
         r"acceptance.max_drift_mg is judged across verification temperatures: verify at two or more"),
    ],
)
def test_verification_and_acceptance_errors_name_the_key(write, text: str, expected: str) -> None:
    with pytest.raises(ConfigError, match=expected):
        prepare(write("tiny.yaml", text))


def test_verification_setpoints_run_where_the_sequence_passes_them(write) -> None:
    text = TINY_PROCEDURE.replace("setpoints_c: [30]", "setpoints_c: [40, 0, 20]") + (
        "verify: {schedule: {kind: sphere, count: 8}, at_setpoints: false, setpoints_c: [10, 30, 5]}\n")
    plan = prepare(write("tiny.yaml", text)).plan
    # 40 → 0 passes 30, 10 and 5 on the way down; nothing is left for 0 → 20.
    assert plan.setpoints_c == (40, 30, 10, 5, 0, 20)
    verify_keys = [s.key for s in plan.pose_steps if s.stored_kind == "verify"]
    assert verify_keys[0] == "T30/verify01" and len(verify_keys) == 3 * 8


def test_explicit_verification_angles_are_checked_against_the_turntable(write) -> None:
    base = TINY_PROCEDURE + "verify: {schedule: {kind: explicit, angles_deg: ANGLES}}\n"
    with pytest.raises(ConfigError, match=r"tiny.yaml:7: verify.schedule.angles_deg\[0\]: 2 angles given, the turntable .* has 3 axes"):
        prepare(write("tiny.yaml", base.replace("ANGLES", "[[10, 20]]")))


@pytest.mark.parametrize(("replace", "by", "expected"), [
    ("band_c: 0.3", "bnd_c: 0.3", r"tiny.yaml:4: soak.bnd_c: unknown key; did you mean band_c\?$"),
    ("setpoints_c: [30]", "setpoint_c: [30]",
     r"tiny.yaml:1: setpoints_c: required, and missing: is 'setpoint_c' a misspelling of it\? \(and 1 more problem\)"),
    ("samples_per_pose: 20", "samples_per_pose: 20, frobnicate: 1",
     r"acquisition.frobnicate: unknown key \(known here: samples_per_pose, .*\)$"),
])
def test_a_misspelt_key_is_named_with_what_was_meant(write, replace: str, by: str, expected: str) -> None:
    with pytest.raises(ConfigError, match=expected):
        load_procedure(write("tiny.yaml", TINY_PROCEDURE.replace(replace, by)))
