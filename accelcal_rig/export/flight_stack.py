"""What the PX4 and ArduPilot exports share: one sensor's bias as the cubic in (T - T_ref) both stacks hold
(the accelerometer's in m/s², the gyroscope's in rad/s), and the statements of what else the calibration holds
that an offset-only thermal model cannot.

Both stacks subtract a per-axis offset polynomial of the sensor temperature from the raw reading, clipped to a
temperature range, and nothing else that changes with temperature: scale factors and cross-axis terms (Eq. 1's
S, C and M; the gyroscope model's K, asymmetry, nonlinearity and g-sensitivity) have no place, so every export
says how large they are for the sensor it is for.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.polynomial import Polynomial

from accelcal_rig.core.units import STANDARD_GRAVITY_M_S2
from accelcal_rig.errors import ConfigError
from accelcal_rig.fit import gyro_model
from accelcal_rig.fit.calibration import CalibrationFile, ChannelCalibration
from accelcal_rig.fit.channel_models import model_of
from accelcal_rig.fit.sfem import error_matrix

#: Both stacks hold the offset as a cubic in the temperature difference.
STACK_DEGREE = 3
#: Temperatures across the calibrated range at which the sizes stated are taken (and a refit is fitted).
_GRID_POINTS = 401
#: Significant digits written: 9 carry a float32 (what both stacks store) exactly.
_DIGITS = 9
#: Both stacks take angular rates in rad/s.
RAD_PER_DEG = float(np.pi / 180.0)
#: Directions of the true rate over which what a gyroscope's offset-only compensation leaves is searched.
_DIRECTIONS = 2000


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
    """Per axis (rows x, y, z), offset(T) = Σ_k coefficients[axis, k] · (T - t_ref_c)^k in the stack's unit
    (m/s² for an accelerometer, rad/s for a gyroscope), for T within t_min_c…t_max_c. `refit_error`: how far
    it strays from the calibration's own bias over that range, in the same unit: 0 when the calibration's
    polynomial (of `source_degree`) has degree ≤ 3, re-expanded exactly."""

    t_ref_c: float
    t_min_c: float
    t_max_c: float
    coefficients: np.ndarray
    source_degree: int
    refit_error: float


@dataclass(frozen=True)
class ParamsExport:
    """A parameter file's text, the sensor it is for, and its notes: what it cannot carry, in its header too."""

    serial: str
    text: str
    notes: tuple[str, ...]


#: The roles a flight stack's thermal compensation has a place for: its accelerometers' and its gyroscopes'.
ACCELEROMETER, GYROSCOPE = "accelerometer", "gyroscope"


def select_sensor(calibration: CalibrationFile, options: StackOptions) -> ChannelCalibration:
    """The accelerometer calibration of the sensor `--serial` names, or of the file's only one: a flight stack's
    parameters are one sensor's, its accelerometer's at least (the channel whose model a stack holds as one)."""
    serials = list(calibration.duts)
    if options.serial is None:
        if len(serials) != 1:
            raise ConfigError(f"{options.source}: sensors: {len(serials)} sensors ({_listed(serials)}): "
                              "choose one with --serial")
        serial = serials[0]
    elif options.serial not in calibration.duts:
        raise ConfigError(f"{options.source}: sensors: no sensor {options.serial!r} (the file has {_listed(serials)})")
    else:
        serial = options.serial
    found = in_role(calibration, serial, ACCELEROMETER)
    if found is None:
        raise ConfigError(f"{options.source}: sensor {serial}: no accelerometer calibration (its channels: "
                          f"{', '.join(calibration.duts[serial].channels)}): a flight stack's thermal compensation "
                          "holds an accelerometer's, and a gyroscope's beside it")
    return found


def in_role(calibration: CalibrationFile, serial: str, role: str) -> ChannelCalibration | None:
    """The DUT's calibration of the channel whose model a flight stack holds in `role`, where it has one."""
    for channel in calibration.duts[serial].channels.values():
        stack = model_of(channel).flight_stack
        if stack is not None and stack.role == role:
            return channel
    return None


def _listed(serials: Sequence[str], most: int = 8) -> str:
    shown = ", ".join(serials[:most])
    return shown if len(serials) <= most else f"{shown}, … ({len(serials)} in all)"


def instance_index(options: StackOptions, low: int, high: int, default: int, parameters: str) -> int:
    """`--instance` (or the stack's default) within the stack's numbering of its parameter sets."""
    index = default if options.instance is None else options.instance
    if not low <= index <= high:
        raise ConfigError(f"--instance {index}: {parameters} numbers its parameter sets {low} to {high}")
    return index


def offset_cubic(calibration: ChannelCalibration, t_ref_c: float) -> OffsetCubic:
    """The channel's bias (the parameters its model's `flight_stack` names, over x = (T - mid) / half-width) as a
    cubic in (T - t_ref_c) in SI units (an accelerometer's m/s², a gyroscope's rad/s). Up to degree 3 this is the
    same polynomial written about another point (exact but for rounding); above, the least-squares cubic over
    the calibrated range, and how far it strays is part of the result."""
    stack = model_of(calibration).flight_stack
    assert stack is not None
    rows = [list(calibration.polynomial.names).index(name) for name in stack.bias]
    return _bias_cubic(calibration.polynomial.matrix()[rows] * stack.si_factor, calibration.polynomial.domain_c,
                       calibration.validity_c, t_ref_c)


def _bias_cubic(bias: np.ndarray, domain_c: tuple[float, float], validity_c: tuple[float, float],
                t_ref_c: float) -> OffsetCubic:
    """Rows of coefficients over the scaled temperature (already in the stack's unit) as cubics about t_ref_c."""
    low, high = validity_c
    grid = np.linspace(low, high, _GRID_POINTS)
    degree = bias.shape[1] - 1
    rows, worst = [], 0.0
    for row in bias:
        own = Polynomial(row, domain=list(domain_c), window=[-1.0, 1.0])
        if degree > STACK_DEGREE:
            cubic = _about(Polynomial.fit(grid, own(grid), STACK_DEGREE), t_ref_c)
            worst = max(worst, float(np.max(np.abs(cubic(grid) - own(grid)))))
        else:
            cubic = _about(own, t_ref_c)
        rows.append(np.pad(cubic.coef, (0, STACK_DEGREE + 1 - len(cubic.coef))))
    return OffsetCubic(t_ref_c, low, high, np.array(rows), degree, worst)


def _about(polynomial: Polynomial, t_ref_c: float) -> Polynomial:
    """The same polynomial with coefficients in powers of u = T - t_ref_c (its domain mapped onto u)."""
    return polynomial.convert(domain=[t_ref_c, t_ref_c + 1.0], window=[0.0, 1.0])


def offset_at(cubic: OffsetCubic, temperature_c: float) -> np.ndarray:
    """The cubic's offset per axis (m/s²) at one temperature, clipped to its range as the stacks clip it."""
    u = float(np.clip(temperature_c, cubic.t_min_c, cubic.t_max_c)) - cubic.t_ref_c
    return np.asarray(cubic.coefficients @ u ** np.arange(STACK_DEGREE + 1), dtype=float)


def steepest_slope(cubic: OffsetCubic) -> float:
    """The largest |d offset / dT| of any axis over the range, in the stack's unit per °C: what a stale
    temperature costs."""
    u = np.linspace(cubic.t_min_c, cubic.t_max_c, _GRID_POINTS) - cubic.t_ref_c
    slopes = [Polynomial(row).deriv()(u) for row in cubic.coefficients]
    return float(np.max(np.abs(slopes)))


def steepest_slope_mg_per_c(cubic: OffsetCubic) -> float:
    """`steepest_slope` of an accelerometer's cubic (m/s²), in mg/°C."""
    return steepest_slope(cubic) / STANDARD_GRAVITY_M_S2 * 1e3


def not_exported(sensor: ChannelCalibration, stack: str) -> str:
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


def range_held(gyro: ChannelCalibration) -> str:
    """Which range the exported gyro offsets are the gyroscope's at (a bias in deg/s is the same at every range
    to the calibration's range-to-range scales, stated)."""
    others = "".join(f"; at +/-{o.range:g} deg/s it reads {max(abs(v - 1.0) for v in o.scale) * 1e6:.0f} ppm off that "
                     "at most (the calibration file holds each axis's scale)" for o in gyro.range_scales)
    return f"gyro offsets as the gyroscope reads at +/-{gyro.range:g} deg/s, the range the calibration holds{others}"


def gyro_not_exported(gyro: ChannelCalibration, stack: str) -> str:
    """The gyroscope model's terms an offset-only thermal model cannot hold, over the calibrated range, and what
    leaving them out costs at full scale.

    With the bias alone removed the stack outputs u + a|u| + n u (u/1000)² + G·f for u = K·ω: the error left is
    that minus ω. "Together" bounds it at |ω| = the range and |f| = 1 g: the largest error of the rate terms
    over directions of ω and temperatures, plus the largest ‖G‖₂."""
    low, high = gyro.validity_c
    parameters = gyro.parameters_at(np.linspace(low, high, _GRID_POINTS))
    scale_ppm = (parameters[:, gyro_model.SCALE] - 1.0) * 1e6
    cross_mrad = parameters[:, gyro_model.CROSS] * 1e3
    asymmetry_ppm = parameters[:, gyro_model.ASYMMETRY] * 1e6
    nonlinearity_ppm = parameters[:, gyro_model.NONLINEARITY] * 1e6
    gsens = gyro_model.gsensitivity_matrix(parameters)
    gsens_norm = np.linalg.norm(gsens, ord=2, axis=(1, 2))
    rate_dps = gyro.range * _sphere(_DIRECTIONS)
    left = [np.linalg.norm(_rate_terms_left(p, rate_dps), axis=1).max() for p in parameters[:: _GRID_POINTS // 40]]
    together = float(max(left)) + float(gsens_norm.max())
    return (f"not exported ({stack} holds gyro offsets only): scale error up to {np.max(np.abs(scale_ppm)):.0f} ppm, "
            f"changing by up to {_spread(scale_ppm):.0f} ppm over {low:.2f} to {high:.2f} degC; cross-axis "
            f"sensitivity (misalignment and non-orthogonality) up to {np.max(np.abs(cross_mrad)):.3f} mrad, changing "
            f"by up to {_spread(cross_mrad):.3f} mrad; +/- asymmetry up to {np.max(np.abs(asymmetry_ppm)):.0f} ppm; "
            f"cubic nonlinearity up to {np.max(np.abs(nonlinearity_ppm)):.0f} ppm at 1000 deg/s; g-sensitivity up "
            f"to {gsens_norm.max():.4f} deg/s per g, changing by up to {_spread(gsens.reshape(len(gsens), 9)):.4f} "
            f"deg/s per g; together up to {together:.3f} deg/s at full scale ({gyro.range:g} deg/s) and 1 g "
            "left uncorrected")


def _rate_terms_left(params: np.ndarray, rate_dps: np.ndarray) -> np.ndarray:
    """What a gyroscope with `params` reads for each true rate, bias and g-sensitivity taken off, minus the rate."""
    no_bias_no_g = np.array(params, dtype=float)
    no_bias_no_g[gyro_model.BIAS] = 0.0
    no_bias_no_g[gyro_model.GSENS] = 0.0
    return gyro_model.distort_rate(rate_dps, np.zeros(3), no_bias_no_g) - rate_dps


def _sphere(n: int) -> np.ndarray:
    """n directions spread evenly over the unit sphere (a Fibonacci lattice), and the six axes both ways."""
    k = np.arange(n) + 0.5
    z = 1.0 - 2.0 * k / n
    phi = np.pi * (1.0 + 5.0**0.5) * k
    r = np.sqrt(1.0 - z * z)
    return np.concatenate([np.stack([r * np.cos(phi), r * np.sin(phi), z], axis=1), np.eye(3), -np.eye(3)])


def _spread(values: np.ndarray) -> float:
    """The largest change of any one column over the rows (temperatures)."""
    return float(np.max(values.max(axis=0) - values.min(axis=0)))


def range_note(sensor: ChannelCalibration, cubic: OffsetCubic, stack: str, names: str, label: str = "temperature") -> str:
    """The calibrated range against the clipping range written (the same), and what each does beyond it."""
    low, high = sensor.validity_c
    beyond = "clamps" if sensor.out_of_range == "clamp" else "extrapolates"
    return (f"{label}: calibrated {low:.2f} to {high:.2f} degC (beyond it the calibration {beyond}); {names} "
            f"written {cubic.t_min_c:.2f} to {cubic.t_max_c:.2f} degC: {stack} clips the temperature to them, so "
            "beyond them it holds the offset of the nearer end")


def refit_note(cubic: OffsetCubic, stack: str, since: str = "", what: str = "bias") -> list[str]:
    """A statement only when the calibration's polynomial is above the stack's degree and was refitted; `since`:
    the temperature a stack takes the cubic's change from, which doubles what the change may stray. `what`:
    "bias" (an accelerometer's cubic, m/s², stated in mg) or "gyro bias" (rad/s, stated in deg/s)."""
    if cubic.source_degree <= STACK_DEGREE:
        return []
    change = f" (its change since {since}, which {stack} subtracts, up to twice that)" if since else ""
    size = (f"{cubic.refit_error / STANDARD_GRAVITY_M_S2 * 1e3:.4f} mg" if what == "bias"
            else f"{cubic.refit_error / RAD_PER_DEG:.5f} deg/s")
    return [f"the calibration's degree-{cubic.source_degree} {what} polynomial refitted as {stack}'s cubic: "
            f"up to {size} from it over the calibrated range{change}"]


def mg(values_m_s2: np.ndarray) -> str:
    """x, y, z in mg for a note."""
    return ", ".join(f"{v:.3f}" for v in np.asarray(values_m_s2) / STANDARD_GRAVITY_M_S2 * 1e3)


def dps(values_rad_s: np.ndarray) -> str:
    """x, y, z in deg/s for a note."""
    return ", ".join(f"{v:.5f}" for v in np.asarray(values_rad_s) / RAD_PER_DEG)


def gyro_of(calibration: CalibrationFile, serial: str) -> ChannelCalibration | None:
    """The DUT's gyroscope calibration, where it has one: a flight stack's file then carries it too."""
    return in_role(calibration, serial, GYROSCOPE)


GYRO_AXES_NOTE = ("the gyro coefficients are in the gyroscope's own x, y, z as calibrated (its sensitivity matrix "
                  "is relative to the fixture frame): permute and re-sign them as the accelerometer's where the "
                  "driver publishes the gyroscope rotated")


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
