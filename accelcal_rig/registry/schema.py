"""The registry's tables as the current migration leaves them (accelcal_rig/registry/migrations): one row
per calibration of one channel of one DUT (an IMU's accelerometer and gyroscope are two rows), and its figures
with their units, one row each. What
identifies a calibration is its source file's SHA-256, the DUT's serial and the fit's own digest (each
channel's fit its own): registering the same file again adds nothing; a refit of it with other options is
another calibration."""

from __future__ import annotations

import sqlalchemy as sa

metadata = sa.MetaData()

calibrations = sa.Table(
    "calibrations", metadata,
    sa.Column("id", sa.Integer, primary_key=True, autoincrement=True),
    sa.Column("serial", sa.String(128), nullable=False, index=True),
    sa.Column("part", sa.String(64), nullable=False),
    sa.Column("source_kind", sa.String(16), nullable=False),       # campaign | recording
    sa.Column("source_path", sa.String(4096), nullable=False),
    sa.Column("source_sha256", sa.String(64), nullable=False),
    sa.Column("fit_sha256", sa.String(64), nullable=False),
    sa.Column("procedure", sa.String(128), nullable=False),
    sa.Column("rig", sa.String(128), nullable=False),
    sa.Column("simulated", sa.Boolean, nullable=False),
    sa.Column("software_version", sa.String(64), nullable=False),
    sa.Column("calibrated_at", sa.DateTime, nullable=False, index=True),   # UTC: when the sensor was measured
    sa.Column("registered_at", sa.DateTime, nullable=False),               # UTC
    sa.Column("valid_from_c", sa.Float, nullable=False),
    sa.Column("valid_to_c", sa.Float, nullable=False),
    sa.Column("verdict", sa.String(16), nullable=True),                     # PASS | FAIL | CONDITIONAL | none (NOT JUDGED); 0005 widened it
    sa.Column("verdict_reasons", sa.JSON, nullable=False),
    sa.Column("calibration", sa.JSON, nullable=False),                      # the whole fit, to export again
    # Added by migration 0002: when the fit was made, and where its figures (calibration_figures) are stated.
    sa.Column("fitted_at", sa.DateTime, nullable=True),                     # UTC
    sa.Column("reference_c", sa.Float, nullable=True),
    # Added by migration 0003: which channel of its DUT the calibration is.
    sa.Column("channel", sa.String(16), nullable=False, server_default="accel"),
    # Added by migration 0007: the lab's lot of the DUT (its own word for it, not the part number).
    sa.Column("lot", sa.String(64), nullable=True),
    sa.Index("calibrations_serial_channel", "serial", "channel"),
    sa.UniqueConstraint("source_sha256", "serial", "fit_sha256", name="one_calibration_per_fit"),
)

COLUMNS = tuple(column.name for column in calibrations.columns)

# Added by migration 0008: each calibration's figures with their units (the columns 0002 and 0004 had, `bias_mg`,
# `bias_dps`, …, moved here), as its channel's model states them (fit/channel_model.py StoredFigure).
calibration_figures = sa.Table(
    "calibration_figures", metadata,
    sa.Column("id", sa.Integer, primary_key=True, autoincrement=True),
    sa.Column("calibration_id", sa.Integer, sa.ForeignKey("calibrations.id"), nullable=False, index=True),
    sa.Column("name", sa.String(64), nullable=False),                   # bias, scale_error, …
    sa.Column("label", sa.String(128), nullable=False),                 # as people say it
    sa.Column("unit", sa.String(16), nullable=False),                   # mg, °/s, ppm, …
    sa.Column("axes", sa.String(8), nullable=False),                    # "xyz": a value per axis; "": one value
    sa.Column("value", sa.JSON, nullable=False),                        # [x, y, z] or [value]
    sa.Column("expanded_u", sa.JSON, nullable=True),                    # as value, k = 2, where stated
    sa.Column("trend", sa.Boolean, nullable=False),                     # a sensor's drift per year is stated of it
    sa.Column("lot", sa.Boolean, nullable=False),                       # a lot's statistics show its spread
    sa.UniqueConstraint("calibration_id", "name", name="one_figure_per_name"),
)

# Added by migration 0006: the lab's users, the append-only record of approvals, and every certificate
# revision issued (the database refuses to change or delete the last two).
users = sa.Table(
    "users", metadata,
    sa.Column("id", sa.Integer, primary_key=True, autoincrement=True),
    sa.Column("name", sa.String(64), nullable=False, unique=True),
    sa.Column("full_name", sa.String(128), nullable=False),
    sa.Column("role", sa.String(16), nullable=False),                 # approver | viewer
    sa.Column("password_hash", sa.String(256), nullable=True),        # argon2id; none: a reverse proxy's user
    sa.Column("disabled", sa.Boolean, nullable=False, server_default=sa.false()),
    sa.Column("created_at", sa.DateTime, nullable=False),
    # Added by migration 0009 (registry/sign_ins.py): raised to end every session of the user; consecutive
    # failed logins; locked out until (UTC).
    sa.Column("session_generation", sa.Integer, nullable=False, server_default="0"),
    sa.Column("failed_logins", sa.Integer, nullable=False, server_default="0"),
    sa.Column("locked_until", sa.DateTime, nullable=True),
    # Added by migration 0010: what certificates print under the approver's name ("Head of laboratory").
    sa.Column("function", sa.String(128), nullable=False, server_default=""),
)

approvals = sa.Table(
    "approvals", metadata,
    sa.Column("id", sa.Integer, primary_key=True, autoincrement=True),
    sa.Column("calibration_id", sa.Integer, sa.ForeignKey("calibrations.id"), nullable=False, index=True),
    sa.Column("action", sa.String(16), nullable=False),               # approve | reject | reissue
    sa.Column("user_name", sa.String(64), nullable=False),
    sa.Column("full_name", sa.String(128), nullable=False),
    sa.Column("authority", sa.String(128), nullable=False),
    sa.Column("reason", sa.Text, nullable=False, server_default=""),
    sa.Column("revision", sa.Integer, nullable=True),
    sa.Column("at", sa.DateTime, nullable=False),
)

certificate_revisions = sa.Table(
    "certificate_revisions", metadata,
    sa.Column("id", sa.Integer, primary_key=True, autoincrement=True),
    sa.Column("calibration_id", sa.Integer, sa.ForeignKey("calibrations.id"), nullable=False),
    sa.Column("revision", sa.Integer, nullable=False),
    sa.Column("number", sa.String(128), nullable=False),
    sa.Column("approver", sa.String(128), nullable=False),
    sa.Column("issued_at", sa.DateTime, nullable=False),
    sa.Column("reason", sa.Text, nullable=False, server_default=""),
    sa.Column("html", sa.Text, nullable=False),
    sa.Column("pdf", sa.LargeBinary, nullable=True),
    sa.Column("sha256", sa.String(64), nullable=False),
    # Added by migration 0010: the item facts this revision states in place of the campaign's (JSON: customer,
    # contact, received_date, condition, remarks), carried over by the next revision.
    sa.Column("amendments", sa.Text, nullable=False, server_default="{}"),
    sa.UniqueConstraint("calibration_id", "revision", name="one_certificate_per_revision"),
)

# Added by migration 0007: what running campaigns publish while they run (registry/live.py): one row per
# campaign file on its host with its latest snapshot, its events, and its temperatures thinned in time.
live_campaigns = sa.Table(
    "live_campaigns", metadata,
    sa.Column("key", sa.String(64), primary_key=True),             # the campaign file on its host (live.campaign_key)
    sa.Column("rig", sa.String(128), nullable=False),
    sa.Column("host", sa.String(255), nullable=False),
    sa.Column("campaign", sa.String(4096), nullable=False),        # the file's path on its host
    sa.Column("procedure", sa.String(128), nullable=False),
    sa.Column("dry_run", sa.Boolean, nullable=False),
    sa.Column("pid", sa.Integer, nullable=False),
    sa.Column("state", sa.String(16), nullable=False),             # running | done | aborted | stopped
    sa.Column("phase", sa.String(32), nullable=False),
    sa.Column("setpoint_c", sa.Float, nullable=True),
    sa.Column("setpoint_number", sa.Integer, nullable=False),
    sa.Column("setpoints_total", sa.Integer, nullable=False),
    sa.Column("poses_done", sa.Integer, nullable=False),
    sa.Column("poses_total", sa.Integer, nullable=False),
    sa.Column("chamber_c", sa.Float, nullable=True),
    sa.Column("dut_c", sa.JSON, nullable=False),                   # [each DUT's last reading]
    sa.Column("remaining_s", sa.Float, nullable=True),
    sa.Column("clock_s", sa.Float, nullable=False),
    sa.Column("line", sa.Text, nullable=False),                    # the progress line rig status prints
    sa.Column("warnings", sa.Integer, nullable=False),
    sa.Column("errors", sa.Integer, nullable=False),
    sa.Column("verdicts", sa.JSON, nullable=False),                # {serial: {verdict, reasons}} once judged
    sa.Column("findings", sa.JSON, nullable=False),                # [early findings on DUTs]
    sa.Column("abort_reason", sa.Text, nullable=False),
    sa.Column("started_at", sa.DateTime, nullable=False),          # UTC, the campaign's
    sa.Column("updated_at", sa.DateTime, nullable=False, index=True),  # UTC, the database's clock
)

live_events = sa.Table(
    "live_events", metadata,
    sa.Column("id", sa.Integer, primary_key=True, autoincrement=True),
    sa.Column("key", sa.String(64), nullable=False, index=True),
    sa.Column("clock_s", sa.Float, nullable=False),                # campaign clock
    sa.Column("at", sa.DateTime, nullable=False),                  # UTC, the publisher's
    sa.Column("level", sa.String(16), nullable=False),
    sa.Column("kind", sa.String(32), nullable=False),
    sa.Column("message", sa.Text, nullable=False),
)

live_temperatures = sa.Table(
    "live_temperatures", metadata,
    sa.Column("id", sa.Integer, primary_key=True, autoincrement=True),
    sa.Column("key", sa.String(64), nullable=False, index=True),
    sa.Column("clock_s", sa.Float, nullable=False),
    sa.Column("chamber_c", sa.Float, nullable=True),
    sa.Column("dut_c", sa.Float, nullable=True),                   # the DUTs' mean
)


# Added by migration 0009: the record of sign-ins (registry/sign_ins.py), oldest first.
sign_ins = sa.Table(
    "sign_ins", metadata,
    sa.Column("id", sa.Integer, primary_key=True, autoincrement=True),
    sa.Column("at", sa.DateTime, nullable=False),                   # UTC
    sa.Column("user_name", sa.String(64), nullable=False, index=True),  # as given (a failed login's may be no user)
    sa.Column("client", sa.String(64), nullable=False),             # the dashboard's client address, or "command line"
    sa.Column("event", sa.String(32), nullable=False),              # login | login failed | locked | unlocked | logout | sessions ended
    sa.Column("detail", sa.Text, nullable=False, server_default=""),
)


def registry_tables() -> list[sa.Table]:
    """Every table of the current schema (what opening a registry checks is there)."""
    return list(metadata.sorted_tables)
