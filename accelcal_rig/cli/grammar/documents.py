"""The grammar of the commands that write documents from a campaign or its calibration: `rig report |
certificate | export`."""

from __future__ import annotations

from pathlib import Path

from accelcal_rig.cli.grammar.common import Commands, certificate_options, command, number


def add_document_commands(commands: Commands) -> None:
    """`rig report | certificate | export`, in this order."""
    for add in (_add_report, _add_certificate, _add_export):
        add(commands)


def _add_report(commands: Commands) -> None:
    """The HTML report."""
    report = command(commands, "report", "write an HTML report with figures of a campaign",
                     "Write REPORT/index.html and REPORT/figures/*.png: the campaign's summary, |g| per pose "
                     "before and after calibration, the raw ellipsoid and calibrated sphere, every parameter "
                     "over temperature with its polynomial, offset drift before and after compensation, RMSE "
                     "per setpoint, the soak traces and the event log. Opens in a browser with no network. "
                     "Needs matplotlib (pip install 'accelcal-rig[report]'). The fit is redone in memory with "
                     "the campaign's options; the file is only read, so a running or aborted campaign works.",
                     "rig report campaign.h5 -o report/")
    report.add_argument("campaign", type=Path, help="campaign file (HDF5)")
    report.add_argument("-o", "--output", type=Path, required=True, help="folder to write (created if needed)")


def _add_certificate(commands: Commands) -> None:
    """Certificates per DUT."""
    certificate = command(commands, "certificate", "write a calibration certificate per DUT (HTML and PDF)",
                          "Write OUT/<serial>.html and OUT/<serial>.pdf for every DUT of the calibration: the item "
                          "and its identity, the campaign and its instruments, the results, the verification, the "
                          "uncertainty budget, the verdict and fields for signatures. PDFs need WeasyPrint (pip "
                          "install 'accelcal-rig[pdf]'). `rig run` writes them at its end too.",
                          "rig certificate campaign.h5 -o certs/ --operator 'A. Smith'")
    certificate.add_argument("campaign", type=Path, help="campaign file (HDF5)")
    certificate.add_argument("-o", "--output", type=Path, required=True, help="folder to write (created if needed)")
    certificate.add_argument("--calibration", type=Path,
                             help="its calibration file (default: beside the campaign, .calibration.yaml)")
    certificate_options(certificate)


def _add_export(commands: Commands) -> None:
    """A calibration for other tools."""
    export = command(commands, "export", "write a calibration file as JSON, CSV, a C header or flight-stack parameters",
                     "Write the coefficients of a calibration file for other tools (json: the same structure; "
                     "csv: one row per sensor and parameter) or for firmware (c-header: every sensor's "
                     "polynomials and C99 functions that apply them, accelcal_apply and accelcal_apply_codes), "
                     "or one sensor's bias as a flight stack's thermal compensation (px4-params: TC_A<n>_ for "
                     "QGroundControl; ardupilot-params: INS_TCAL<n>_). Those hold offsets only: what they cannot "
                     "hold is stated on standard error and in the file.",
                     "rig export campaign.calibration.yaml --format c-header -o accel_calibration.h")
    export.add_argument("calibration", type=Path, help="calibration file (YAML, from rig run or rig fit)")
    export.add_argument("--format", required=True, choices=["json", "csv", "c-header", "px4-params", "ardupilot-params"],
                        help="what to write (px4-params, ardupilot-params: one sensor's thermal offsets)")
    export.add_argument("--serial", help="px4-params, ardupilot-params: the sensor (needed when the file has several)")
    export.add_argument("--instance", type=number(0, 3, integer=True),
                        help="px4-params: n of TC_A<n>_ (0-3, default 0); ardupilot-params: the IMU, n of INS_TCAL<n>_ "
                             "(1-3, default 1)")
    export.add_argument("--device-id", type=number(1, 2**31 - 1, integer=True),
                        help="px4-params: TC_A<n>_ID, the device id of the accelerometer (its CAL_ACC<k>_ID; "
                             "default 0, which PX4 matches to none)")
    export.add_argument("-o", "--output", type=Path, help="file to write (default: standard output)")
