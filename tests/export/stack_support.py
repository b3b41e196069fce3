"""What the PX4 and ArduPilot export tests share: the bias part of a calibration, and `rig export` run."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from accelcal_rig.cli import main
from accelcal_rig.fit.calibration import ChannelCalibration, PolynomialModel, apply
from accelcal_rig.fit.sfem import PARAMETER_NAMES

G0 = 9.80665  # m/s² per standard g: the unit both stacks work in


def bias_only(sensor: ChannelCalibration) -> ChannelCalibration:
    """The sensor's Eq. 1 with its bias polynomials and nothing else: scale 1, no cross-axis terms."""
    neutral = {name: [1.0] if name.startswith("scale_") else [0.0] for name in PARAMETER_NAMES[3:]}
    bias = {name: sensor.polynomial.coefficients[name] for name in PARAMETER_NAMES[:3]}
    polynomial = PolynomialModel(domain_c=sensor.polynomial.domain_c, degree=sensor.polynomial.degree,
                                 coefficients=bias | neutral)
    return sensor.model_copy(update={"polynomial": polynomial})


def bias_removed_m_s2(sensor: ChannelCalibration, raw_m_s2: np.ndarray, temperature_c: np.ndarray) -> np.ndarray:
    """What `apply` makes of raw readings (m/s²) with the bias part of the calibration only."""
    return apply(bias_only(sensor), raw_m_s2 / G0, temperature_c) * G0


def export(capsys, argv: list[str]) -> tuple[int, str, list[str]]:
    """`rig export …`: exit code, standard output, and the warnings it printed (without their prefix)."""
    code = main(["export", *argv])
    captured = capsys.readouterr()
    notes = [line.removeprefix("rig: warning: ") for line in captured.err.splitlines()]
    assert all(line.startswith("rig: warning: ") for line in captured.err.splitlines()), captured.err
    return code, captured.out, notes


def stated(pattern: str, notes: list[str]) -> list[float]:
    """The numbers the first note matching `pattern` (a regex with groups) states."""
    for note in notes:
        found = re.search(pattern, note)
        if found:
            return [float(v) for v in found.groups()]
    raise AssertionError(f"no note matches {pattern!r}: {notes}")


def written_comments(path: Path) -> set[str]:
    """The file's comment lines without their '# '."""
    return {line[2:] for line in path.read_text().splitlines() if line.startswith("# ")}
