"""Allan deviation of a sensor held still, and the noise figures read off it (IEEE Std 952 / 1554 practice):
the random walk (angle random walk of a gyroscope, velocity random walk of an accelerometer) and the bias
instability, each with a confidence interval from the equivalent degrees of freedom.

The deviations come from allantools (overlapping Allan deviation of rate data); the equivalent degrees of
freedom from Greenhall's algorithm in allantools, taken for the noise that dominates where each figure is
read: white rate noise on the −1/2 slope, flicker at the flat minimum (NIST SP 1065, §5.3).
"""

from __future__ import annotations

from dataclasses import dataclass

import allantools
import numpy as np
from scipy.optimize import nnls

#: σ(τ) of flicker rate noise of bias instability B is √(2 ln 2 / π) · B on its flat part.
FLICKER_FLOOR = float(np.sqrt(2.0 * np.log(2.0) / np.pi))
#: One standard deviation's share of a normal distribution: the intervals' default confidence.
ONE_SIGMA = 0.6826894921370859
#: Allantools' α of each noise type in rate ("frequency") data: white 0, flicker −1.
_WHITE, _FLICKER = 0, -1


@dataclass(frozen=True)
class AllanCurve:
    """One axis's overlapping Allan deviation: at each averaging time, the deviation in the data's unit, and
    how many terms it averages."""

    tau_s: np.ndarray
    deviation: np.ndarray
    terms: np.ndarray
    n_samples: int
    rate_hz: float


@dataclass(frozen=True)
class Estimate:
    """A figure with its confidence interval (`confidence`, e.g. 0.683) and the averaging time it was read at."""

    value: float
    low: float
    high: float
    tau_s: float
    confidence: float


def allan_deviation(samples: np.ndarray, rate_hz: float, taus: str | np.ndarray = "octave") -> list[AllanCurve]:
    """The overlapping Allan deviation of each column of `samples` (n, axes), rate data at `rate_hz`."""
    samples = np.atleast_2d(np.asarray(samples, dtype=float).T).T
    if samples.shape[0] < 16:
        raise ValueError(f"{samples.shape[0]} samples: an Allan deviation needs at least 16")
    curves = []
    for column in samples.T:
        tau, deviation, _, terms = allantools.oadev(column, rate=rate_hz, data_type="freq", taus=taus)
        curves.append(AllanCurve(np.asarray(tau), np.asarray(deviation), np.asarray(terms), len(column), rate_hz))
    return curves


#: A figure is read only at averaging times up to this share of the record (beyond, too few averages).
LONGEST_SHARE = 0.1


def _readable(curve: AllanCurve) -> np.ndarray:
    """The indices of the averaging times a figure may be read at: up to a tenth of the record."""
    duration_s = curve.n_samples / curve.rate_hz
    return np.flatnonzero(curve.tau_s <= LONGEST_SHARE * duration_s)


def _edf(curve: AllanCurve, index: int, alpha: int) -> float:
    """The deviation's equivalent degrees of freedom at one τ (Greenhall, overlapping, for noise `alpha`)."""
    m = int(round(curve.tau_s[index] * curve.rate_hz))
    return float(allantools.edf_greenhall(alpha=alpha, d=2, m=m, N=curve.n_samples + 1, overlapping=True))


def _interval(value: float, edf: float, confidence: float) -> tuple[float, float]:
    low, high = allantools.confidence_interval(value, edf, ci=confidence)
    return float(low), float(high)


@dataclass(frozen=True)
class NoiseModel:
    """The Allan variance as the sum of its three terms over the readable averaging times, fitted by
    non-negative weighted least squares: σ²(τ) = N²/τ + (0.664·B)² + K²·τ/3 (white, flicker, random walk of
    the rate), each point weighted by its degrees of freedom over its variance (var σ̂² ≈ 2σ⁴/edf)."""

    white: float      #: N², the data's unit² per Hz
    flicker: float    #: (0.664·B)²
    walk: float       #: K²/3, the data's unit² per Hz per s


def noise_model(curve: AllanCurve) -> NoiseModel:
    readable = _readable(curve)
    if len(readable) < 3:
        raise ValueError("fewer than 3 averaging times short enough against the record to fit the noise terms")
    tau, avar = curve.tau_s[readable], curve.deviation[readable] ** 2
    weight = np.sqrt([_edf(curve, k, _WHITE) for k in readable]) / avar
    terms = np.column_stack([1.0 / tau, np.ones_like(tau), tau])
    coefficients, _ = nnls(terms * weight[:, None], avar * weight)
    return NoiseModel(*(float(c) for c in coefficients))


def _relative_interval(curve: AllanCurve, index: int, alpha: int, confidence: float) -> tuple[float, float]:
    """The interval of the deviation at one τ, as factors of the deviation."""
    low, high = _interval(float(curve.deviation[index]), _edf(curve, index, alpha), confidence)
    return low / float(curve.deviation[index]), high / float(curve.deviation[index])


def random_walk(curve: AllanCurve, confidence: float = ONE_SIGMA) -> Estimate:
    """The white noise's density N (the data's unit per √Hz): √ of the noise model's white term. Its interval:
    the relative interval of the deviation at the shortest averaging time, where white noise dominates and
    the degrees of freedom are most (the points overlap: fitting them all adds little)."""
    model, index = noise_model(curve), int(_readable(curve)[0])
    value = float(np.sqrt(model.white))
    low, high = _relative_interval(curve, index, _WHITE, confidence)
    return Estimate(value, value * low, value * high, float(curve.tau_s[index]), confidence)


def bias_instability(curve: AllanCurve, confidence: float = ONE_SIGMA) -> Estimate:
    """The bias instability B (the data's unit): √ of the noise model's flicker term over the flicker floor's
    factor √(2 ln 2 / π) ≈ 0.664. Its interval: the relative interval, for flicker noise, of the deviation at
    the curve's least readable point, where flicker dominates. Where the fit finds no flicker term (a record
    too short for it to rise above the white noise), or a flicker term smaller than the least deviation's own
    uncertainty (its variance's interval there: the fit's split of that point between white and flicker is
    then noise), the value is 0 and the interval reaches up to what that least deviation allows, its own upper
    end over 0.664: an upper bound, not a measurement."""
    model, readable = noise_model(curve), _readable(curve)
    index = int(readable[np.argmin(curve.deviation[readable])])
    value = float(np.sqrt(model.flicker)) / FLICKER_FLOOR
    low, high = _relative_interval(curve, index, _FLICKER, confidence)
    least_variance = float(curve.deviation[index]) ** 2
    if model.flicker < least_variance * (high**2 - 1.0):
        value = 0.0
    if value == 0.0:  # not resolved (white noise hides it): no flicker floor can lie above the least deviation
        return Estimate(0.0, 0.0, float(curve.deviation[index]) * high / FLICKER_FLOOR, float(curve.tau_s[index]),
                        confidence)
    return Estimate(value, value * low, value * high, float(curve.tau_s[index]), confidence)


def per_root_hour(density_per_rthz: float) -> float:
    """A random walk's density per √Hz (unit·s / √s) as per √h: ×√3600 (°/s/√Hz → °/√h)."""
    return density_per_rthz * 60.0
