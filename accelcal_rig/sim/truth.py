"""Each simulated DUT's hidden truth: Eq. 1 parameters that vary with temperature as smooth cubics.

Seeded by the serial number, so a DUT is the same sensor in every run. Magnitudes follow the paper's
ADXL355: bias within ±25 mg at 25 °C with 10–20 mg of drift over −40…60 °C, scale within ±1 %,
non-orthogonality and misalignment of a few tenths of a degree.
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass

import numpy as np
from numpy.polynomial import polynomial

T_REF_C = 25.0
HALF_RANGE_C = 50.0
#: The drift spans below are set over this range (the paper's campaign).
DRIFT_RANGE_C = (-40.0, 60.0)

_DEG = np.pi / 180.0
# (value at 25 °C: ± half-width, drift over DRIFT_RANGE_C: low…high) per parameter group.
_NOMINAL_HALF_WIDTH = np.repeat([25e-3, 0.01, 0.4 * _DEG, 0.5 * _DEG], 3)
_NOMINAL_CENTRE = np.repeat([0.0, 1.0, 0.0, 0.0], 3)
_DRIFT_LOW = np.repeat([10e-3, 100e-6, 0.005 * _DEG, 0.005 * _DEG], 3)
_DRIFT_HIGH = np.repeat([20e-3, 800e-6, 0.02 * _DEG, 0.02 * _DEG], 3)


@dataclass(frozen=True)
class DutTruth:
    """`coefficients[k]` are parameter k's cubic in x = (T − 25 °C) / 50 °C, increasing powers."""

    serial: str
    coefficients: np.ndarray

    def parameters_at(self, temperature_c: np.ndarray | float) -> np.ndarray:
        """The model's parameters at each temperature, shape (..., P): Eq. 1's (fit.sfem.PARAMETER_NAMES) for an
        accelerometer, the rate-table model's (fit.gyro_model.PARAMETER_NAMES) for a gyroscope."""
        x = (np.asarray(temperature_c, dtype=float) - T_REF_C) / HALF_RANGE_C
        return np.moveaxis(polynomial.polyval(x, self.coefficients.T), 0, -1)


def fixture_parameters_at(coefficients: np.ndarray, temperature_c: np.ndarray) -> np.ndarray:
    """Eq. 1 parameters (n, 12) of n DUTs whose cubics are `coefficients` (n, 12, powers), each at its own
    temperature (n,): the whole fixture in one evaluation."""
    x = (np.asarray(temperature_c, dtype=float) - T_REF_C) / HALF_RANGE_C
    return polynomial.polyval(x[:, None], np.moveaxis(coefficients, -1, 0), tensor=False)


def truth_for_serial(serial: str) -> DutTruth:
    """The deterministic hidden truth of the DUT with this serial number."""
    return _cubic_truth(serial, serial, _NOMINAL_CENTRE, _NOMINAL_HALF_WIDTH, _DRIFT_LOW, _DRIFT_HIGH)


def _cubic_truth(serial: str, seed_text: str, centre: np.ndarray, half_width: np.ndarray, drift_low: np.ndarray,
                 drift_high: np.ndarray) -> DutTruth:
    """Each parameter a cubic over temperature: its value at 25 °C within centre ± half_width, its drift over
    DRIFT_RANGE_C between drift_low and drift_high (either sign), its shape drawn; seeded by `seed_text`."""
    seed = int.from_bytes(hashlib.sha256(seed_text.encode()).digest()[:8], "little")
    rng = np.random.default_rng(seed)
    count = len(centre)
    nominal = centre + rng.uniform(-1, 1, count) * half_width
    drift = rng.uniform(drift_low, drift_high) * rng.choice([-1.0, 1.0], count)
    shape = np.column_stack([np.ones(count), rng.uniform(-0.4, 0.4, (count, 2))])  # x + a2 x² + a3 x³
    x = (np.linspace(*DRIFT_RANGE_C, 201) - T_REF_C) / HALF_RANGE_C
    curves = polynomial.polyval(x, np.column_stack([np.zeros(count), shape]).T)
    span = curves.max(axis=1) - curves.min(axis=1)
    return DutTruth(serial, np.column_stack([nominal, shape * (drift / span)[:, None]]))


# A gyroscope's hidden truth: the rate-table model's 27 parameters (fit/gyro_model.py), the same smooth cubics
# over temperature. Magnitudes of a consumer IMU's gyroscope (an ICM-42688-P: zero-rate offset ±0.5 °/s, a few
# mdps/K; sensitivity ±0.5 %, nonlinearity ±0.1 %, cross-axis ±2 %): bias within ±0.5 °/s at 25 °C drifting
# 0.1–0.5 °/s over −40…60 °C, scale within ±0.5 %, cross-axis terms within a few tenths of a degree, ±
# asymmetry and nonlinearity within 0.05 % and 0.1 %, g-sensitivity within ±0.05 °/s per g.
_GYRO_GROUPS = (3, 3, 6, 3, 3, 9)
_GYRO_CENTRE = np.repeat([0.0, 1.0, 0.0, 0.0, 0.0, 0.0], _GYRO_GROUPS)
_GYRO_HALF_WIDTH = np.repeat([0.5, 0.005, 0.3 * _DEG, 5e-4, 1e-3, 0.05], _GYRO_GROUPS)
_GYRO_DRIFT_LOW = np.repeat([0.1, 100e-6, 0.005 * _DEG, 20e-6, 20e-6, 0.002], _GYRO_GROUPS)
_GYRO_DRIFT_HIGH = np.repeat([0.5, 2000e-6, 0.02 * _DEG, 100e-6, 200e-6, 0.01], _GYRO_GROUPS)


def gyro_truth_for_serial(serial: str) -> DutTruth:
    """The deterministic hidden truth of the gyroscope of the DUT with this serial number (fit.gyro_model's
    parameters): its own seed, so an accelerometer's truth (`truth_for_serial`) is the same with or without a
    gyroscope beside it."""
    return _cubic_truth(serial, f"gyro:{serial}", _GYRO_CENTRE, _GYRO_HALF_WIDTH, _GYRO_DRIFT_LOW, _GYRO_DRIFT_HIGH)


#: The spread of a gyroscope's sensitivity from one of its ranges to another (relative, per axis, 1σ): the data
#: sheet states ±0.5 % for each range (ICM-42688-P, "sensitivity scale factor tolerance"); one analog chain
#: behind every range keeps their differences smaller, an assumption of 0.1 %.
GYRO_RANGE_SCALE_SIGMA = 1e-3


def gyro_range_scale(serial: str, ranges: tuple[float, ...]) -> dict[float, np.ndarray]:
    """Each range's sensitivity relative to the widest one's (whose K the truth's parameters are), per axis: the
    gyroscope of `serial` reads (1 + δ) × what its truth says at a range with δ ≠ 0. Deterministic per serial."""
    widest = max(ranges)
    rng = np.random.default_rng(int.from_bytes(hashlib.sha256(f"gyro-ranges:{serial}".encode()).digest()[:8], "big"))
    draws = rng.normal(0.0, GYRO_RANGE_SCALE_SIGMA, (len(ranges), 3))
    return {float(r): (np.zeros(3) if r == widest else d) for r, d in zip(sorted(ranges), draws)}


# A magnetometer's hidden truth: Eq. 1's 12 parameters (its hard-iron offset is the bias, its soft-iron matrix
# M·C·S), the same smooth cubics. Magnitudes of an LIS3MDL on a fixture: zero-gauss level and hard iron within
# ±0.3 gauss at 25 °C drifting 2–10 mgauss over −40…60 °C (the data sheet states no temperature coefficient: an
# assumption), scale within ±3 % drifting 0.05–0.3 %, non-orthogonality and misalignment within ±1°.
_MAG_NOMINAL_HALF_WIDTH = np.repeat([0.3, 0.03, 1.0 * _DEG, 1.0 * _DEG], 3)
_MAG_DRIFT_LOW = np.repeat([2e-3, 500e-6, 0.005 * _DEG, 0.005 * _DEG], 3)
_MAG_DRIFT_HIGH = np.repeat([10e-3, 3000e-6, 0.05 * _DEG, 0.05 * _DEG], 3)


def mag_truth_for_serial(serial: str) -> DutTruth:
    """The deterministic hidden truth of the magnetometer of the DUT with this serial number (Eq. 1's
    parameters, the bias in gauss): its own seed, as a gyroscope's."""
    return _cubic_truth(serial, f"mag:{serial}", _NOMINAL_CENTRE, _MAG_NOMINAL_HALF_WIDTH, _MAG_DRIFT_LOW,
                        _MAG_DRIFT_HIGH)
