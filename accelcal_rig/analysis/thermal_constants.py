"""The rig's own thermal constants, fitted to a finished campaign's ramps and soaks (`rig characterise`).

The model is the one the duration estimate plays a plan against (core/thermal.py): the controller moves its
reference towards each set point at a heating or a cooling rate — cooling slower towards a floor, at
`rate × (T − floor) / (room − floor)` below the room, at the full rate above it — the air follows the reference with a first-order lag, and after the
ramp arrives the controller drives past the set point by a share of the step (`_bump`, peaking three air time
constants after arrival). Each DUT follows its slot's air with its own first-order lag, with a gain and an
offset (a slot nearer the inlet, the DUT's self-heating).

The chamber's five constants are fitted together, by least squares, to the air polled during every ramp and
soak of the campaign (the ramps from the set point's write on: `SoakTrace.ramp_t_s`); each DUT's lag to its
soak traces, against the air as measured. The room temperature the floor is reckoned from is the air at the
first ramp's start (a campaign starts with the chamber at room temperature).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import least_squares, minimize_scalar
from scipy.signal import lfilter

from accelcal_rig.core.thermal import OVERSHOOT_PEAK_TIME_CONSTANTS
from accelcal_rig.store.records import SoakTrace

#: The grid the chamber model is evaluated on (s): fine against the shortest time constant worth fitting.
_GRID_S = 2.0
#: Bounds of the chamber's time constant (s) and of a DUT's (s) the fit searches.
_CHAMBER_TAU_S = (5.0, 3600.0)
_DUT_TAU_S = (10.0, 6 * 3600.0)
#: A floor this far below the room cannot be told from none; nor one where no cooling went this far below it.
_FLOOR_UNSEEN_C = 150.0
_FLOOR_NEEDS_C = 5.0


@dataclass(frozen=True)
class Segment:
    """One set point's ramp and soak as the fit sees them: the air polled from the set point's write on."""

    setpoint_c: float
    t_s: np.ndarray       # (n,) from the write, increasing
    air_c: np.ndarray     # (n,)

    @property
    def start_c(self) -> float:
        return float(self.air_c[0])

    @property
    def cooling(self) -> bool:
        return self.setpoint_c < self.start_c


@dataclass(frozen=True)
class ChamberFit:
    heating_rate_c_per_min: float | None   # None: no heating ramp in the campaign
    cooling_rate_c_per_min: float | None   # at room temperature; None: no cooling ramp
    cooling_floor_c: float | None          # None: cooling did not slow with temperature
    chamber_time_constant_min: float
    chamber_overshoot_pct: float
    residual_rms_c: float
    n_points: int
    room_c: float


@dataclass(frozen=True)
class DutFit:
    serial: str
    time_constant_min: float
    gain: float
    offset_c: float
    residual_rms_c: float


@dataclass(frozen=True)
class ThermalConstants:
    chamber: ChamberFit
    duts: tuple[DutFit, ...]

    @property
    def fixture_time_constant_min(self) -> float:
        """The slowest DUT's lag: a soak waits for the slowest, so the estimate plays it."""
        return max(d.time_constant_min for d in self.duts)


def segments_of(soaks: list[SoakTrace]) -> list[Segment]:
    """Each soak with the ramp before it, joined into one segment from the set point's write (soaks whose
    ramp was not kept — the first of a resumed run, a software ramp — are left out)."""
    found = []
    for soak in soaks:
        if len(soak.ramp_t_s) < 2 or len(soak.t_s) == 0:
            continue
        t_s = np.concatenate([soak.ramp_t_s, soak.t_s])
        air_c = np.concatenate([soak.ramp_chamber_c, soak.chamber_c])
        keep = np.isfinite(t_s) & np.isfinite(air_c)
        order = np.argsort(t_s[keep], kind="stable")
        found.append(Segment(float(soak.setpoint_c), t_s[keep][order], air_c[keep][order]))
    return found


def fit_thermal_constants(soaks: list[SoakTrace], serials: list[str]) -> ThermalConstants:
    """The chamber's constants from every ramp and soak, each DUT's lag from its soak traces. ValueError when
    the campaign kept no ramp (nothing to fit the rates to)."""
    segments = segments_of(soaks)
    if not segments:
        raise ValueError("no ramp kept with any soak (a campaign from before ramps were kept, or only software "
                         "ramps): nothing to fit the chamber's rates to")
    chamber = fit_chamber(segments, room_c=segments[0].start_c)
    duts = tuple(fit_dut(serial, [(s.t_s, s.chamber_c, s.dut_c[:, column]) for s in soaks if len(s.t_s) > 2])
                 for column, serial in enumerate(serials))
    return ThermalConstants(chamber, duts)


# ----------------------------------------------------------------------------------------------- chamber
def chamber_air_c(segment: Segment, heating_c_per_s: float, cooling_c_per_s: float, floor_share_per_c: float,
                  tau_s: float, overshoot: float, room_c: float) -> np.ndarray:
    """The model's air at the segment's poll times. `floor_share_per_c` is 1 / (room − floor) (0: no floor)."""
    start_c, target_c = segment.start_c, segment.setpoint_c
    grid_s = np.arange(0.0, segment.t_s[-1] - segment.t_s[0] + _GRID_S, _GRID_S)
    step_c = target_c - start_c
    if step_c >= 0:
        reference_c = np.minimum(start_c + heating_c_per_s * grid_s, target_c)
        arrival_s = step_c / heating_c_per_s
    elif floor_share_per_c > 0:  # above the room at the full rate, then exponentially towards the floor
        floor_c = room_c - 1.0 / floor_share_per_c
        decay = cooling_c_per_s * floor_share_per_c
        knee_c = min(start_c, room_c)
        knee_s = (start_c - knee_c) / cooling_c_per_s
        below_s = np.clip(grid_s - knee_s, 0.0, None)
        reference_c = np.where(grid_s < knee_s, start_c - cooling_c_per_s * grid_s,
                               floor_c + (knee_c - floor_c) * np.exp(-decay * below_s))
        reference_c = np.maximum(reference_c, target_c)
        if target_c >= knee_c:
            arrival_s = (start_c - target_c) / cooling_c_per_s
        else:
            arrival_s = knee_s + (math.log((knee_c - floor_c) / (target_c - floor_c)) / decay if target_c > floor_c
                                  else math.inf)
    else:
        reference_c = np.maximum(start_c - cooling_c_per_s * grid_s, target_c)
        arrival_s = -step_c / cooling_c_per_s
    peak_s = OVERSHOOT_PEAK_TIME_CONSTANTS * tau_s
    after_s = np.clip(grid_s - arrival_s, 0.0, None)
    driven_c = reference_c + overshoot * step_c * (after_s / peak_s) * np.exp(1.0 - after_s / peak_s)
    air_c = _lag(driven_c, start_c, start_c, tau_s)
    return np.interp(segment.t_s - segment.t_s[0], grid_s, air_c)


def _lag(inputs: np.ndarray, input_before: float, output_before: float, tau_s: float) -> np.ndarray:
    """A first-order lag on the uniform grid, exact for an input linear between grid points."""
    decay = math.exp(-_GRID_S / tau_s)
    a = tau_s / _GRID_S * (1.0 - decay)
    b = np.array([1.0 - a, a - decay])
    state = np.array([b[1] * input_before + decay * output_before])
    output, _ = lfilter(b, np.array([1.0, -decay]), inputs, zi=state)
    return np.asarray(output)


def fit_chamber(segments: list[Segment], room_c: float) -> ChamberFit:
    """Least squares over every segment's polls; the rates start from each ramp's average."""
    heating = [s for s in segments if not s.cooling]
    cooling = [s for s in segments if s.cooling]
    coldest_c = min(float(s.air_c.min()) for s in segments)

    def initial_rate(found: list[Segment]) -> float:
        rates = [abs(s.setpoint_c - s.start_c) / max(float(s.t_s[-1] - s.t_s[0]), 1.0) for s in found]
        return float(np.median(rates)) * 3.0 if rates else 0.05

    def residuals(p: np.ndarray) -> np.ndarray:
        heat, cool, share, tau, over = p
        return np.concatenate([chamber_air_c(s, heat, cool, share, tau, over, room_c) - s.air_c for s in segments])

    floor_share_max = 1.0 / max(room_c - coldest_c + 1.0, 1.0)  # the floor below the coldest air reached
    x0 = np.array([initial_rate(heating), initial_rate(cooling), 0.0, 180.0, 0.0])
    lower = np.array([1e-4, 1e-4, 0.0, _CHAMBER_TAU_S[0], 0.0])
    upper = np.array([1.0, 1.0, floor_share_max, _CHAMBER_TAU_S[1], 0.5])
    result = least_squares(residuals, x0, bounds=(lower, upper), x_scale=np.array([0.01, 0.01, 0.005, 60.0, 0.01]))
    heat, cool, share, tau, over = (float(v) for v in result.x)
    cooled_below_room = any(float(s.air_c.min()) < room_c - _FLOOR_NEEDS_C for s in cooling)
    floor_c = room_c - 1.0 / share if share > 1.0 / _FLOOR_UNSEEN_C and cooled_below_room else None
    n = sum(len(s.t_s) for s in segments)
    return ChamberFit(heat * 60.0 if heating else None, cool * 60.0 if cooling else None, floor_c, tau / 60.0,
                      over * 100.0, float(np.sqrt(np.mean(result.fun ** 2))), n, room_c)


# ----------------------------------------------------------------------------------------------- DUTs
def fit_dut(serial: str, traces: list[tuple[np.ndarray, np.ndarray, np.ndarray]]) -> DutFit:
    """A DUT's lag behind the measured air over its soak traces (time, air, DUT): for each time constant the
    gain and offset are linear (least squares), the time constant itself is searched."""
    traces = [(t, air, dut) for t, air, dut in traces if np.all(np.isfinite(dut))]
    if not traces:
        raise ValueError(f"DUT {serial}: no soak trace with its temperatures")

    def design(tau_s: float) -> tuple[np.ndarray, np.ndarray]:
        """Columns (lagged air, lagged one) and the free response of each trace's first value; the data."""
        columns, targets = [], []
        for t_s, air_c, dut_c in traces:
            decay = np.exp(-(t_s - t_s[0]) / tau_s)
            lagged_air = _lag_samples(t_s, air_c, tau_s)
            columns.append(np.column_stack([lagged_air, 1.0 - decay]))
            targets.append(dut_c - dut_c[0] * decay)
        return np.vstack(columns), np.concatenate(targets)

    def misfit(log_tau: float) -> float:
        a, y = design(math.exp(log_tau))
        coefficients, *_ = np.linalg.lstsq(a, y, rcond=None)
        return float(np.sum((a @ coefficients - y) ** 2))

    found = minimize_scalar(misfit, bounds=tuple(math.log(b) for b in _DUT_TAU_S), method="bounded",
                            options={"xatol": 1e-4})
    tau_s = math.exp(found.x)
    a, y = design(tau_s)
    (gain, offset), *_ = np.linalg.lstsq(a, y, rcond=None)
    residual = a @ np.array([gain, offset]) - y
    return DutFit(serial, tau_s / 60.0, float(gain), float(offset), float(np.sqrt(np.mean(residual ** 2))))


def _lag_samples(t_s: np.ndarray, inputs: np.ndarray, tau_s: float) -> np.ndarray:
    """The lagged input from rest at zero, at the samples' own times (the input linear between them): the
    part of the response the input drives (the first value's free response is added by the caller)."""
    output = np.zeros(len(t_s))
    for n in range(1, len(t_s)):
        step_s = t_s[n] - t_s[n - 1]
        decay = math.exp(-step_s / tau_s)
        a = tau_s / step_s * (1.0 - decay) if step_s > 0 else 1.0
        output[n] = decay * output[n - 1] + (1.0 - a) * inputs[n] + (a - decay) * inputs[n - 1]
    return output
