"""What the PX4 and ArduPilot exports share: one sensor's bias as the cubic in (T - T_ref) both stacks hold,
in m/s², and the statements of what else the calibration holds that an offset-only thermal model cannot.

Both stacks subtract a per-axis offset polynomial of the sensor temperature from the raw reading, clipped to a
temperature range, and nothing else that changes with temperature: scale factors and cross-axis terms (Eq. 1's
S, C and M) have no place, so every export says how large they are for the sensor it is for.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.polynomial import Polynomial

from accelcal_rig.core.units import STANDARD_GRAVITY_M_S2
from accelcal_rig.errors import ConfigError
from accelcal_rig.fit.calibration import CalibrationFile, SensorCalibration
from accelcal_rig.fit.sfem import error_matrix

#: Both stacks hold the offset as a cubic in the temperature difference.
STACK_DEGREE = 3
#: Temperatures across the calibrated range at which the sizes stated are taken (and a refit is fitted).
_GRID_POINTS = 401
#: Significant digits written: 9 carry a float32 (what both stacks store) exactly.
_DIGITS = 9


#: The exported axes are the sensor's own; a stack applies its terms in the axes its driver publishes.
AXES_NOTE = ("the coefficients are in the sensor chip's own x, y, z: where the flight controller's driver "
             "publishes the accelerometer rotated (board orientation, a rotated mounting), permute and re-sign "
             "the _0/_1/_2 (PX4) or _X/_Y/_Z (ArduPilot) terms to those axes before loading")


@dataclass(frozen=True)
class StackOptions:
    """`rig export`'s choices for a flight-stack export; None where the user left the default."""

    source: Path
    serial: str | None = None
    instance: int | None = None
    device_id: int | None = None


@dataclass(frozen=True)
class OffsetCubic:
    """Per axis (rows x, y, z), offset(T) = Σ_k coefficients_m_s2[axis, k] · (T - t_ref_c)^k in m/s², for T
    within t_min_c…t_max_c. `refit_error_mg`: how far it strays from the calibration's own bias over that
    range: 0 when the calibration's polynomial (of `source_degree`) has degree ≤ 3, re-expanded exactly."""

    t_ref_c: float
    t_min_c: float
    t_max_c: float
    coefficients_m_s2: np.ndarray
    source_degree: int
    refit_error_mg: float


@dataclass(frozen=True)
class ParamsExport:
    """A parameter file's text, the sensor it is for, and its notes: what it cannot carry, in its header too."""

    serial: str
    text: str
    notes: tuple[str, ...]


def select_sensor(calibration: CalibrationFile, options: StackOptions) -> SensorCalibration:
    """The sensor `--serial` names, or the file's only one: a flight stack's parameters are one sensor's."""
    serials = list(calibration.sensors)
    if options.serial is None:
        if len(serials) == 1:
            return calibration.sensors[serials[0]]
        raise ConfigError(f"{options.source}: sensors: {len(serials)} sensors ({_listed(serials)}): "
                          "choose one with --serial")
    if options.serial not in calibration.sensors:
        raise ConfigError(f"{options.source}: sensors: no sensor {options.serial!r} (the file has {_listed(serials)})")
    return calibration.sensors[options.serial]


def _listed(serials: Sequence[str], most: int = 8) -> str:
    shown = ", ".join(serials[:most])
    return shown if len(serials) <= most else f"{shown}, … ({len(serials)} in all)"


def instance_index(options: StackOptions, low: int, high: int, default: int, parameters: str) -> int:
    """`--instance` (or the stack's default) within the stack's numbering of its parameter sets."""
    index = default if options.instance is None else options.instance
    if not low <= index <= high:
        raise ConfigError(f"--instance {index}: {parameters} numbers its parameter sets {low} to {high}")
    return index


def offset_cubic(sensor: SensorCalibration, t_ref_c: float) -> OffsetCubic:
    """The sensor's bias (Eq. 1's b, in g over x = (T - mid) / half-width) as a cubic in (T - t_ref_c) in m/s².

    Up to degree 3 this is the same polynomial written about another point (exact but for rounding); above,
    the least-squares cubic over the calibrated range, and how far it strays is part of the result."""
    low, high = sensor.validity_c
    grid = np.linspace(low, high, _GRID_POINTS)
    bias = sensor.polynomial.matrix()[:3]
    degree = bias.shape[1] - 1
    rows, worst = [], 0.0
    for bias_g in bias:
        own = Polynomial(bias_g * STANDARD_GRAVITY_M_S2, domain=list(sensor.polynomial.domain_c), window=[-1.0, 1.0])
        if degree > STACK_DEGREE:
            cubic = _about(Polynomial.fit(grid, own(grid), STACK_DEGREE), t_ref_c)
            worst = max(worst, float(np.max(np.abs(cubic(grid) - own(grid)))))
        else:
            cubic = _about(own, t_ref_c)
        rows.append(np.pad(cubic.coef, (0, STACK_DEGREE + 1 - len(cubic.coef))))
    return OffsetCubic(t_ref_c, low, high, np.array(rows), degree, worst / STANDARD_GRAVITY_M_S2 * 1e3)


def _about(polynomial: Polynomial, t_ref_c: float) -> Polynomial:
    """The same polynomial with coefficients in powers of u = T - t_ref_c (its domain mapped onto u)."""
    return polynomial.convert(domain=[t_ref_c, t_ref_c + 1.0], window=[0.0, 1.0])


def offset_at(cubic: OffsetCubic, temperature_c: float) -> np.ndarray:
    """The cubic's offset per axis (m/s²) at one temperature, clipped to its range as the stacks clip it."""
    u = float(np.clip(temperature_c, cubic.t_min_c, cubic.t_max_c)) - cubic.t_ref_c
    return np.asarray(cubic.coefficients_m_s2 @ u ** np.arange(STACK_DEGREE + 1), dtype=float)


def steepest_slope_mg_per_c(cubic: OffsetCubic) -> float:
    """The largest |d offset / dT| of any axis over the range, mg/°C: what a stale temperature costs."""
    u = np.linspace(cubic.t_min_c, cubic.t_max_c, _GRID_POINTS) - cubic.t_ref_c
    slopes = [Polynomial(row).deriv()(u) for row in cubic.coefficients_m_s2]
    return float(np.max(np.abs(slopes))) / STANDARD_GRAVITY_M_S2 * 1e3


def not_exported(sensor: SensorCalibration, stack: str) -> str:
    """Eq. 1's S, C and M over the calibrated range, and what leaving them out costs at 1 g.

    With the bias alone the stack outputs U - b = A⁻¹·f for the true specific force f (A = M·C·S), so the
    error left is (A⁻¹ - I)·f: at most ‖A⁻¹ - I‖₂ for |f| = 1 g."""
    low, high = sensor.validity_c
    parameters = sensor.parameters_at(np.linspace(low, high, _GRID_POINTS))
    scale_ppm = (parameters[:, 3:6] - 1.0) * 1e6
    nonorth_mrad, misalign_mrad = parameters[:, 6:9] * 1e3, parameters[:, 9:12] * 1e3
    cross_mrad = np.concatenate([nonorth_mrad, misalign_mrad], axis=1)
    left = np.linalg.inv(error_matrix(parameters)) - np.eye(3)
    left_mg = float(np.max(np.linalg.norm(left, ord=2, axis=(1, 2)))) * 1e3
    scale = float(np.max(np.abs(scale_ppm)))
    return (f"not exported ({stack} holds offsets only): scale error up to {scale:.0f} ppm ({scale * 1e-3:.3f} mg "
            f"at 1 g), changing by up to {_spread(scale_ppm):.0f} ppm over {low:.2f} to {high:.2f} degC; "
            f"non-orthogonality up to {np.max(np.abs(nonorth_mrad)):.3f} mrad and misalignment up to "
            f"{np.max(np.abs(misalign_mrad)):.3f} mrad (1 mrad is 1 mg at 1 g), changing by up to "
            f"{_spread(cross_mrad):.3f} mrad; together up to {left_mg:.3f} mg at 1 g left uncorrected")


def _spread(values: np.ndarray) -> float:
    """The largest change of any one column over the rows (temperatures)."""
    return float(np.max(values.max(axis=0) - values.min(axis=0)))


def range_note(sensor: SensorCalibration, cubic: OffsetCubic, stack: str, names: str) -> str:
    """The calibrated range against the clipping range written (the same), and what each does beyond it."""
    low, high = sensor.validity_c
    beyond = "clamps" if sensor.out_of_range == "clamp" else "extrapolates"
    return (f"temperature: calibrated {low:.2f} to {high:.2f} degC (beyond it the calibration {beyond}); {names} "
            f"written {cubic.t_min_c:.2f} to {cubic.t_max_c:.2f} degC: {stack} clips the temperature to them, so "
            "beyond them it holds the offset of the nearer end")


def refit_note(cubic: OffsetCubic, stack: str, since: str = "") -> list[str]:
    """A statement only when the calibration's polynomial is above the stack's degree and was refitted; `since`:
    the temperature a stack takes the cubic's change from, which doubles what the change may stray."""
    if cubic.source_degree <= STACK_DEGREE:
        return []
    change = f" (its change since {since}, which {stack} subtracts, up to twice that)" if since else ""
    return [f"the calibration's degree-{cubic.source_degree} bias polynomial refitted as {stack}'s cubic: "
            f"up to {cubic.refit_error_mg:.4f} mg from it over the calibrated range{change}"]


def mg(values_m_s2: np.ndarray) -> str:
    """x, y, z in mg for a note."""
    return ", ".join(f"{v:.3f}" for v in np.asarray(values_m_s2) / STANDARD_GRAVITY_M_S2 * 1e3)


def number(value: float) -> str:
    """`value` with 9 significant digits and no exponent: parameter editors need not read 1e-07."""
    value = float(value)
    if value == 0.0:
        return "0"
    decimals = max(0, _DIGITS - 1 - int(np.floor(np.log10(abs(value)))))
    return f"{value:.{decimals}f}"


def header(lines: Sequence[str]) -> list[str]:
    """Comment lines ("# …"), one per statement."""
    return [f"# {line}" for line in lines]
