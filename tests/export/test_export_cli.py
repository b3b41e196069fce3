"""`rig export`'s refusals: a campaign file where a calibration file belongs, and flight-stack options given
to the formats that write every sensor."""

from __future__ import annotations

from pathlib import Path

from accelcal_rig.cli import main


def one_line(capsys, argv: list[str]) -> str:
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err, err
    return err


def test_a_campaign_file_is_refused_naming_the_fit_that_makes_its_calibration(fitted_paper_campaign, capsys) -> None:
    campaign = fitted_paper_campaign[0]
    for fmt in ("json", "px4-params"):
        err = one_line(capsys, ["export", str(campaign), "--format", fmt])
        assert err.startswith(f"rig: error: {campaign}: an HDF5 campaign file, not a calibration file")
        assert f"rig fit {campaign} -o " in err


def test_flight_stack_options_are_refused_for_the_other_formats(fitted_paper_campaign, capsys) -> None:
    calibration = fitted_paper_campaign[1]
    for option in (["--serial", "ADX355-A001"], ["--instance", "1"], ["--device-id", "5"]):
        err = one_line(capsys, ["export", str(calibration), "--format", "csv", *option])
        assert "are for px4-params and ardupilot-params, not csv" in err


def test_a_missing_calibration_file_is_still_one_line(tmp_path: Path, capsys) -> None:
    missing = tmp_path / "none.calibration.yaml"
    assert f"{missing}: file not found" in one_line(capsys, ["export", str(missing), "--format", "px4-params"])


def test_a_missing_output_folder_is_one_line_before_any_note(fitted_paper_campaign, tmp_path: Path, capsys) -> None:
    out = tmp_path / "no-such-folder" / "px4.params"
    err = one_line(capsys, ["export", str(fitted_paper_campaign[1]), "--format", "px4-params", "--serial",
                            "ADX355-A001", "-o", str(out)])
    assert err.startswith(f"rig: error: {out}: folder {out.parent} does not exist")
