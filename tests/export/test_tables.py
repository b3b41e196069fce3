"""JSON and CSV exports carry the calibration exactly: read back, they give the same parameters."""

from __future__ import annotations

import csv
import io
import json
from pathlib import Path

import numpy as np

from accelcal_rig.export.tables import to_csv, to_json
from accelcal_rig.fit.calibration import CalibrationFile, load_calibration
from accelcal_rig.fit.sfem import PARAMETER_NAMES


def test_json_is_the_calibration_file_itself(fitted_paper_campaign: tuple[Path, Path]) -> None:
    calibration = load_calibration(fitted_paper_campaign[1])
    assert CalibrationFile.model_validate(json.loads(to_json(calibration))) == calibration


def test_csv_rows_evaluate_to_the_calibrations_parameters(fitted_paper_campaign: tuple[Path, Path]) -> None:
    calibration = load_calibration(fitted_paper_campaign[1])
    rows = list(csv.DictReader(io.StringIO(to_csv(calibration))))
    assert len(rows) == 12 * len(calibration.of_quantity("acceleration"))
    temperatures = np.array([-35.0, 0.0, 22.5, 55.0])  # inside the calibrated range
    for serial, sensor in calibration.of_quantity("acceleration").items():
        mine = [r for r in rows if r["serial"] == serial]
        assert [r["parameter"] for r in mine] == list(PARAMETER_NAMES)
        from_csv = np.empty((len(temperatures), 12))
        for k, row in enumerate(mine):
            x = (temperatures - float(row["t_mid_c"])) / float(row["t_half_range_c"])
            coefficients = [float(row[f"c{j}"]) for j in range(4)]
            from_csv[:, k] = np.polynomial.polynomial.polyval(x, coefficients)
            assert row["out_of_range"] == sensor.out_of_range and float(row["lsb"]) == sensor.lsb
        np.testing.assert_allclose(from_csv, sensor.parameters_at(temperatures), rtol=0, atol=1e-15)
