"""The channel model of any three-axis quantity whose reference at a pose is a vector of known size: the paper's
sensor-frame error model (Eq. 1: bias, scale, non-orthogonality, misalignment), fitted per setpoint by
Levenberg–Marquardt against the reference vectors the rig recorded (or, norm-only, against their size), its
parameters as polynomials over temperature, judged on the poses the fit never saw.

An accelerometer against gravity (fit/acceleration.py) is one; a magnetometer against the site's field is
another: Eq. 1's bias and matrix are its hard-iron offset and soft-iron matrix. What differs between them is
data, a `VectorQuantity`: names, units, where the reference's size comes from, the figures' angle (gravity's
tilt, a field's direction), the simulation's truth, and what the outputs say.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Any

import numpy as np
from scipy.stats import chi2

from accelcal_rig.fit.approach import (
    HYSTERESIS_CANDIDATES,
    approach_directions,
    hysteresis_states,
    temperature_rates_c_per_min,
)
from accelcal_rig.fit.budget import (
    FittedTerms,
    budget,
    calibration_covariance,
    fitted_powers,
    smoothed_temperature_u_c,
    temperature_scatter_c,
    truth_coverage,
)
from accelcal_rig.fit.calibration import ChannelCalibration, PolynomialModel, SetpointFit, plain
from accelcal_rig.fit.channel_model import (
    ChannelFit,
    Figure,
    FigureLimit,
    FlightStackOffsets,
    NoiseFigures,
    ParameterGroup,
    Section,
    StoredFigure,
    Table,
    consistency_notes,
    noise_stored,
)
from accelcal_rig.fit.eq1_c import eq1_c_export
from accelcal_rig.fit.expected import expected_norm_rmse_mg, expected_reference_rmse_mg, thermal_jacobian
from accelcal_rig.fit.joint import fit_joint
from accelcal_rig.fit.lm import SfemFit, fit_sfem, norm_sigma
from accelcal_rig.fit.metrics import drift_mg, noise_floor_mg, norm_rmse_mg
from accelcal_rig.fit.options import FitOptions
from accelcal_rig.fit.parameter_uncertainty import (
    certificate_temperatures,
    expanded_at,
    nearest_setpoint_sigma,
    of_sensor,
    reference_c,
)
from accelcal_rig.fit.sfem import correct, norm_only_gauge
from accelcal_rig.fit.thermal import ThermalModel, fit_thermal
from accelcal_rig.fit.uncertainty import (
    CoefficientCovariance,
    combined,
    consistency,
    magnitude_noise_u,
    output_uncertainty,
)
from accelcal_rig.fit.verification import AngleFigure, ReferenceUncertainty, pose_figures
from accelcal_rig.store.read import VectorPoses, read_vector_poses

if TYPE_CHECKING:
    from accelcal_rig.store.content import Campaign
    from accelcal_rig.store.records import ChannelInfo

#: The paper whose method an Eq. 1 calibration follows (the text in ../shared/reference/paper.txt has its abstract
#: and body; its title and venue are those of the publication the abstract is from).
PAPER = ("“Thermal Calibration of Triaxial Accelerometer for Tilt Measurement”, Sensors 23(4), 2105 (2023), "
         "doi:10.3390/s23042105")
#: Poses each direction of approach needs before the hysteresis term is fitted.
MIN_POSES_EACH_WAY = 6
_NO_POSES = "no verification poses stored"
#: The model's parameters' kinds, in Eq. 1's order (each three wide).
BIAS, SCALE, NONORTH, MISALIGN = slice(0, 3), slice(3, 6), slice(6, 9), slice(9, 12)


# A VectorQuantity's defaults are module-level functions, not lambdas: a large fixture's jobs carry it to fit
# worker processes (fit/fixture_pool.py), and a lambda in a class body cannot be pickled.
def _no_statements(figures: Mapping[str, Any]) -> list[tuple[str, str]]:
    return []


def _direction_always_known(campaign: Campaign) -> bool:
    return True


def _no_site_description(campaign: Campaign) -> dict[str, Any] | None:
    return None


@dataclass(frozen=True)
class VectorQuantity:
    """What one quantity's Eq. 1 channel model says of itself; everything else is the shared model's."""

    quantity: str                      #: "acceleration"
    sensor: str                        #: "accelerometer"
    unit: str                          #: its readings', "g"
    milli: str                         #: its figures' (thousandths of `unit`), "mg"
    magnitude_label: str               #: the reference's size as a figure names it, "|g|"
    reference_label: str               #: what its reference is, "gravity"
    magnitude_figure: tuple[str, float]  #: the reference's size stated in the figures: (key, factor from unit)
    angle: AngleFigure                 #: gravity's Eq. 10 tilt, or any vector's direction
    #: the site's reference size and its standard uncertainty (in `unit`) as the campaign recorded them
    site: Callable[[Campaign], tuple[float, float]]
    #: the simulation's truth of the DUT's channel: (Eq. 1 parameters per pose, true reference per pose or None)
    truth: Callable[[Campaign, str, str, VectorPoses], tuple[np.ndarray | None, np.ndarray | None]]
    method: str                        #: the method a certificate cites
    micro: str                         #: millionths of `unit`, how a certificate states small figures: "µg"
    magnitude_source: str              #: what the reference's size comes from, as a certificate says it
    size_source: str                   #: the budget's source of the reference size's uncertainty, "gravity"
    angle_label: str                   #: the angle figure as a certificate names it
    #: a certificate's format of each parameter kind's results (by its label), where not the group's own
    result_digits: Mapping[str, str] = field(default_factory=dict)
    noise: NoiseFigures | None = None
    flight_stack: FlightStackOffsets | None = None
    #: the C header's names for it: "" the accelerometer's (the header's first), else a token ("mag")
    c_token: str = ""
    #: whether the early check judges it after each setpoint (its reference's direction always known)
    setpoint_check: bool = False
    #: what its references were, from a calibration's figures: (what, statement) rows of a certificate
    statements: Callable[[Mapping[str, Any]], list[tuple[str, str]]] = _no_statements
    #: whether the campaign places the reference's direction (else only its size is known: fitted norm-only)
    direction_known: Callable[[Campaign], bool] = _direction_always_known
    #: how its method departs from the paper's (an accelerometer's paper), said after the paper on a certificate
    paper_departure: str = ""
    #: the site's reference as the campaign recorded it, kept with the figures (`site_<quantity>`; None: none)
    site_description: Callable[[Campaign], dict[str, Any] | None] = _no_site_description

    @property
    def parameter_names(self) -> tuple[str, ...]:
        return (*(f"bias_{a}_{self.unit}" for a in "xyz"), "scale_x", "scale_y", "scale_z", "nonorth_yx_rad",
                "nonorth_zx_rad", "nonorth_zy_rad", "misalign_x_rad", "misalign_y_rad", "misalign_z_rad")


class Eq1Model:
    """The channel model of a `VectorQuantity` (see the module)."""

    model_id = "sfem-eq1"

    def __init__(self, spec: VectorQuantity) -> None:
        self.spec = spec
        self.quantity, self.sensor, self.figure_unit = spec.quantity, spec.sensor, spec.milli
        self.parameter_names = spec.parameter_names
        self.noise, self.flight_stack = spec.noise, spec.flight_stack
        self.c_export = eq1_c_export(spec.c_token, spec.unit, spec.sensor, self.parameter_names)
        self.setpoint_check = spec.setpoint_check
        m, size = spec.milli, spec.magnitude_label
        self.figures = (
            Figure(f"rmse_before_{m}", f"raw {size} RMSE", m, ".3f", f"raw {size}"),
            Figure(f"noise_floor_{m}", "in-sample noise floor", m, short="floor"),
            Figure(f"expected_fit_rmse_{m}", "expected in-sample RMSE", m, short="expected"),
            Figure(f"rmse_after_{m}", f"in-sample {size} RMSE", m, short=f"fit {size}"),
            Figure(f"drift_after_{m}", "in-sample offset drift", m, short="fit drift"),
            Figure(f"verification.rmse_{m}", f"verification {size} RMSE", m, short=f"verif. {size}"),
            Figure(f"verification.max_axis_error_{m}", "verification axis error", m, short="axis"),
            Figure(f"verification.max_{spec.angle}_error_deg", f"verification {spec.angle} error", "°", short=spec.angle),
            Figure(f"verification.drift_{m}", "verification drift", m, short="drift"),
            Figure(f"expanded_uncertainty_{m}", "expanded uncertainty (k = 2)", m, short="U k=2"),
        )
        angle = "tilt" if spec.angle == "tilt" else "direction"
        self.limits = (
            FigureLimit(f"max_verification_rmse_{m}", f"rmse_{m}", f"verification {size} RMSE", m, 1000,
                        f"Eq. 9 {size} RMSE", missing=_NO_POSES),
            FigureLimit(f"max_axis_error_{m}", f"max_axis_error_{m}", "largest verification axis error", m, 1000,
                        f"largest per-axis error of the compensated vector against the reference "
                        f"{spec.reference_label}", missing=_NO_POSES),
            FigureLimit(f"max_{spec.angle}_error_deg", f"max_{spec.angle}_error_deg",
                        f"largest verification {angle} error", "°", 90,
                        "largest Eq. 10 pitch or roll error" if spec.angle == "tilt"
                        else "largest angle between a compensated vector and its reference", missing=_NO_POSES),
            FigureLimit(f"max_drift_{m}", f"drift_{m}", "verification drift", m, 1000,
                        "residual zero offset drift per axis over the verification temperatures (max − min)",
                        needs_temperatures=2, missing=_NO_POSES),
        )
        self.parameter_groups = (
            ParameterGroup(f"bias_{m}", "bias", self.parameter_names[BIAS], ("x", "y", "z"), 1e3, 0.0, m, "+.4f",
                           1000, "|bias| of each axis"),
            ParameterGroup("scale_error_ppm", "scale error", self.parameter_names[SCALE], ("x", "y", "z"), 1e6, -1.0,
                           "ppm", "+.0f", 1e6, "|scale − 1| of each axis"),
            ParameterGroup("nonorthogonality_mrad", "non-orthogonality", self.parameter_names[NONORTH],
                           ("yx", "zx", "zy"), 1e3, 0.0, "mrad", "+.3f", 1000, "|each non-orthogonality|"),
            ParameterGroup("misalignment_mrad", "misalignment", self.parameter_names[MISALIGN], ("x", "y", "z"), 1e3,
                           0.0, "mrad", "+.3f", 1000, "|each misalignment| (reference mode only)"),
        )

    # --- records and the fit ---------------------------------------------------------------------------------

    def records(self, campaign: Campaign, channel: ChannelInfo, serial: str, options: FitOptions) -> VectorRecords:
        poses = read_vector_poses(campaign, serial, channel.name)
        magnitude, magnitude_u = self.spec.site(campaign)
        truth, reference = self.spec.truth(campaign, serial, channel.name, poses)
        poses = replace(poses, magnitude=magnitude, magnitude_u=magnitude_u, truth_parameters=truth,
                        truth_reference=reference)
        poses = with_approach(campaign, poses) if options.hysteresis == "on" else poses
        site = self.spec.site_description(campaign)
        known = self.spec.direction_known(campaign)
        return VectorRecords(poses, None if site is None else {**site, "direction_known": known}, known)

    def fit(self, records: VectorRecords, options: FitOptions, allan: dict[str, Any] | None) -> ChannelFit:
        return fit_vector(records.poses, options, self.spec, records.site, records.direction_known)

    def judged_groups(self, calibration: ChannelCalibration) -> tuple[tuple[ParameterGroup, ...], list[str]]:
        """Every group; misalignment only where a reference fit determines it."""
        if calibration.mode == "reference":
            return self.parameter_groups, []
        return self.parameter_groups[:3], ["misalignment not judged: a norm-only fit determines none"]

    def compensate(self, calibration: ChannelCalibration, reading: np.ndarray, temperature_c: np.ndarray | float,
                   companions: Mapping[str, np.ndarray]) -> np.ndarray:
        return correct(np.asarray(reading, dtype=float), calibration.parameters_at(temperature_c))

    # --- what the outputs say ------------------------------------------------------------------------------

    def stored_figures(self, calibration: ChannelCalibration) -> list[StoredFigure]:
        """Bias, scale error (each with its own expanded uncertainty; a fit from before they were stated: the
        reading's budget and twice the nearest setpoint's 1σ) and the largest non-orthogonality at the reference
        temperature, the verification RMSE, and the noise record's figures."""
        m, names = self.spec.milli, self.parameter_names
        at = reference_c(calibration.validity_c)
        values = dict(zip(names, calibration.polynomial.at(at).tolist()))
        metrics = calibration.metrics
        table = metrics.get("parameter_uncertainty")
        own = isinstance(table, dict) and any(abs(float(t) - at) < 1e-6 for t in table.get("temperatures_c", []))
        if own:
            bias_u: tuple[float, ...] | None = tuple(1e3 * (expanded_at(metrics, n, at) or 0.0) for n in names[BIAS])
            scale_u: tuple[float, ...] | None = tuple(1e6 * (expanded_at(metrics, n, at) or 0.0) for n in names[SCALE])
        else:
            expanded = metrics.get(f"expanded_uncertainty_{m}")
            bias_u = tuple(float(u) for u in expanded) if expanded else None
            sigma = nearest_setpoint_sigma(calibration.setpoints, at)
            scale_sigma = [float(s) for n in names[SCALE] if (s := sigma.get(n)) is not None]
            scale_u = tuple(2e6 * s for s in scale_sigma) if len(scale_sigma) == 3 else None
        found = metrics.get("verification")
        verification: dict[str, Any] = found if isinstance(found, dict) else {}
        rmse = verification.get(f"rmse_{m}")
        figures = [
            StoredFigure("bias", "bias", m, tuple(1e3 * values[n] for n in names[BIAS]), bias_u, trend=True),
            StoredFigure("scale_error", "scale error", "ppm", tuple(1e6 * (values[n] - 1.0) for n in names[SCALE]),
                         scale_u, trend=True),
            StoredFigure("nonorthogonality", "non-orthogonality", "mrad",
                         (1e3 * max(abs(values[n]) for n in names[NONORTH]),)),
        ]
        if rmse is not None:
            figures.append(StoredFigure("verification_rmse", f"verification {self.spec.magnitude_label} RMSE", m,
                                        (float(rmse),), lot=False))
        return figures + noise_stored(self.noise, metrics, lot=False)


    def sections(self, calibration: ChannelCalibration) -> list[Section]:
        return [self._results(calibration), self._verification(calibration), self._budget(calibration)]

    def method(self, calibration: ChannelCalibration) -> str:
        setpoints = len(calibration.setpoints)
        return (f"Eq. 1 sensor frame error model, {calibration.mode} fit of {len(calibration.free_parameters)} "
                f"parameters at each of {setpoints} setpoint{'s' if setpoints != 1 else ''}, polynomials of degree "
                f"{calibration.polynomial.degree} in temperature, after {PAPER}{self.spec.paper_departure}")

    def reference_statements(self, figures: Mapping[str, Any]) -> list[tuple[str, str]]:
        return self.spec.statements(figures)

    def summary(self, figures: Sequence[Mapping[str, Any]]) -> str:
        m, size = self.spec.milli, self.spec.magnitude_label
        before = max(r[f"rmse_before_{m}"] for r in figures)
        verified = all("verification" in r for r in figures)
        floor = max((r["verification"] if verified else r)[f"noise_floor_{m}"] for r in figures)
        if verified:
            after = max(r["verification"][f"rmse_{m}"] for r in figures)
            drift = max(max(r["verification"][f"drift_{m}"]) for r in figures)
            return (f"{size} RMSE {before:.2f} → {after:.4f} {m} on verification poses (noise floor {floor:.4f} {m}), "
                    f"residual drift ≤ {drift:.4f} {m}")
        after = max(r[f"rmse_after_{m}"] for r in figures)
        drift = max(max(r[f"drift_after_{m}"]) for r in figures)
        return (f"{size} RMSE {before:.2f} → {after:.4f} {m} in-sample, no verification poses (noise floor "
                f"{floor:.4f} {m}), offset drift after ≤ {drift:.4f} {m}")

    def _results(self, calibration: ChannelCalibration) -> Section:
        """Eq. 1's parameters at the ends and the middle of the calibrated range, each ± its expanded uncertainty
        there (misalignment only where a reference fit determined it)."""
        low, high = calibration.validity_c
        temperatures = np.array([low, 0.5 * (low + high), high])
        values = calibration.parameters_at(temperatures)
        groups, _ = self.judged_groups(calibration)
        rows = []
        for group in groups:
            digits = self.spec.result_digits.get(group.label, group.spec)
            for name, column in zip(group.names, group.columns):
                index = self.parameter_names.index(name)
                cells = []
                for i, t in enumerate(temperatures):
                    u = expanded_at(calibration.metrics, name, float(t))
                    text = format((values[i, index] + group.offset) * group.factor, digits)
                    cells.append(text if u is None else f"{text} ± {format(u * group.factor, digits.lstrip('+'))}")
                rows.append((f"{group.label} {column} ({group.unit})", *cells))
        return Section(
            "Results", (f"Calibrated range {low:.2f} … {high:.2f} °C (the DUT's own temperature sensor). Parameters of "
                        f"{self.spec.method}, at the ends and the middle of the range, each ± its expanded uncertainty "
                        "(k = 2: the fit's, carried through its polynomial, the thermal model's scatter and, for the "
                        f"scale factors, the {self.spec.magnitude_source}); the full polynomials are in the "
                        "calibration file.",),
            Table(("parameter", *(f"at {t:.2f} °C" for t in temperatures)), tuple(rows)))

    def _verification(self, calibration: ChannelCalibration) -> Section:
        v = calibration.metrics.get("verification")
        m, size, micro = self.spec.milli, self.spec.magnitude_label, self.spec.micro
        title = "Verification (poses the calibration never saw)"
        if not isinstance(v, dict):
            return Section(title, ("No verification poses: the calibration was not checked on poses it was not "
                                   "fitted to.",))
        temperatures = ", ".join(f"{r['setpoint_c']:g}" for r in v["by_setpoint"])
        expanded = v.get("expanded_u", {})

        def u(key: str, spec: str = ".4f") -> str:
            return f" ± {format(expanded[key], spec)}" if key in expanded else ""

        drift_u = expanded.get(f"drift_{m}")
        drift = ", ".join(f"{d * 1e3:.1f}" + (f" ± {drift_u[a] * 1e3:.1f}" if drift_u else "")
                          for a, d in enumerate(v[f"drift_{m}"]))
        angle = f"max_{self.spec.angle}_error_deg"
        return Section(title, facts=(
            ("poses", f"{v['n_poses']} at {temperatures} °C"),
            (f"{size} RMSE (Eq. 9)", f"{v[f'rmse_{m}']:.4f}{u(f'rmse_{m}')} {m} (their noise floor "
                                     f"{v[f'noise_floor_{m}']:.4f} {m})"),
            ("largest axis error", f"{v[f'max_axis_error_{m}']:.4f}{u(f'max_axis_error_{m}')} {m} ({v['frame']})"),
            (self.spec.angle_label, f"{v[angle]:.4f}{u(angle)}°"),
            (f"residual zero-{self.spec.unit} drift x, y, z", drift + f" {micro} over the range"),
        ), notes=("± the figure's expanded uncertainty (k = 2) as a measurement of the calibrated DUT's error: the "
                  f"table's pointing, the {self.spec.magnitude_source} and the reading's noise.",) if expanded else ())

    def _budget(self, calibration: ChannelCalibration) -> Section:
        m, micro = self.spec.milli, self.spec.micro
        budget_ = calibration.metrics["uncertainty_budget"]
        rows = tuple((name.replace("_", " "), *(f"{u * 1e3:.1f}" for u in values))
                     for name, values in budget_[f"sources_{m}"].items())
        rows += (("combined standard uncertainty", *(f"{u * 1e3:.1f}" for u in budget_[f"standard_{m}"])),
                 (f"expanded uncertainty (k = {budget_['coverage_factor']:g}, about 95 %)",
                  *(f"{u * 1e3:.1f}" for u in budget_[f"expanded_{m}"])))
        notes = consistency_notes(calibration.metrics, "poses", "the verification readings' errors (their noise in "
                                  "them as in U)")
        return Section("Uncertainty of a compensated reading",
                       (f"For {budget_['reading']}: each source's largest standard uncertainty over every orientation "
                        "and the calibrated range, per axis (GUM, sources uncorrelated).",),
                       Table(("source", f"x ({micro})", f"y ({micro})", f"z ({micro})"), rows), notes)


@dataclass(frozen=True)
class VectorRecords:
    """A channel's poses as its Eq. 1 model fits them, the site's reference as the campaign recorded it, and
    whether the reference's direction is known (else only its size)."""

    poses: VectorPoses
    site: dict[str, Any] | None = None
    direction_known: bool = True


@dataclass(frozen=True)
class VectorFitDetail:
    """What an Eq. 1 fit's report draws: each setpoint and its DUT temperature, its fit, the calibration poses
    compensated with the thermal model, and the figures (the simulation truth's errors among them)."""

    setpoints_c: np.ndarray           # (K,)
    temperatures_c: np.ndarray        # (K,) mean DUT temperature at each setpoint
    fits: list[SfemFit]
    compensated: np.ndarray           # (N, 3)
    metrics: dict[str, Any]


def smoothed_temperatures(poses: VectorPoses, groups: list[np.ndarray]) -> np.ndarray:
    """Each pose's DUT temperature from a straight line in time through its setpoint's readings.

    The ADXL355 reads temperature in 0.11 °C steps, so one pose's reading is ~0.04 °C off — at 0.2 mg/°C
    of bias drift, as much error as the noise floor. During a setpoint's poses the sensor's temperature
    moves smoothly (a few hundredths of a degree), which a line in time follows and the steps do not.
    """
    smoothed = poses.temperature_c.astype(float).copy()
    for group in groups:
        if len(group) >= 3 and np.ptp(poses.t_s[group]) > 0:
            line = np.polynomial.Polynomial.fit(poses.t_s[group], poses.temperature_c[group], 1)
            smoothed[group] = line(poses.t_s[group])
    return smoothed


#: The figures that need the reference's direction: not stated where only its size is known.
_DIRECTED = ("max_axis_error", "rms_axis_error", "drift", "offset")


def fit_vector(stored: VectorPoses, options: FitOptions, spec: VectorQuantity, site: dict[str, Any] | None = None,
               direction_known: bool = True) -> ChannelFit:
    """Fit the calibration poses; judge the result on them (in-sample) and on the verification poses. Where the
    reference's direction is not known (`direction_known` False), norm-only against its size, and the figures
    that need its direction left out."""
    if not direction_known and options.mode != "norm-only":
        options = replace(options, mode="norm-only")
    fitted = _fit_vector(stored, options, spec)
    if site is not None:
        fitted.figures[f"site_{spec.quantity.replace(' ', '_')}"] = site
    if direction_known:
        return fitted
    note = (f"the {spec.reference_label}'s direction at each pose is not known (the rig config states no table "
            f"heading): fitted norm-only against its size; the figures that need its direction are not stated")
    fitted.thermal.warnings.append(note)
    figures = _undirected(fitted.figures, spec)
    calibration = fitted.calibration.model_copy(update={"metrics": _undirected(fitted.calibration.metrics, spec),
                                                        "warnings": fitted.thermal.warnings})
    return replace(fitted, figures=figures, calibration=calibration)


def _undirected(metrics: dict[str, Any], spec: VectorQuantity) -> dict[str, Any]:
    """The figures without those that need the reference's direction (each verification and in-sample set's, and
    their expanded uncertainties)."""
    directed = {f"{name}_{spec.milli}" for name in _DIRECTED} | {f"max_{spec.angle}_error_deg"}

    def without(figures: Any) -> Any:
        if not isinstance(figures, dict):
            return figures
        return {k: (without(v) if k in ("expanded_u",) else [without(r) for r in v] if k == "by_setpoint" else v)
                for k, v in figures.items() if k not in directed}

    return {k: without(v) if k in ("verification", "in_sample") else v for k, v in metrics.items()}


def _fit_vector(stored: VectorPoses, options: FitOptions, spec: VectorQuantity) -> ChannelFit:
    m = spec.milli
    poses = stored.subset(~stored.verification)
    if not len(poses.setpoint_c):
        raise ValueError(f"sensor {stored.serial}: no calibration poses stored, nothing to fit")
    setpoints = np.array(list(dict.fromkeys(poses.setpoint_c.tolist())))
    groups = [np.flatnonzero(poses.setpoint_c == s) for s in setpoints]
    pose_temperatures = smoothed_temperatures(poses, groups)
    temperatures = np.array([pose_temperatures[g].mean() for g in groups])
    reference = poses.reference if options.mode == "reference" else None
    accuracy_rad = np.radians(poses.reference_accuracy_arcsec / 3600)
    fits = []
    for setpoint, group in zip(setpoints, groups):
        try:
            fits.append(fit_sfem(poses.mean[group], poses.stderr[group], None if reference is None else reference[group],
                                 options.mode, options.free, accuracy_rad, poses.magnitude))
        except ValueError as exc:
            raise type(exc)(f"sensor {poses.serial} at {setpoint:g} °C: {exc}") from None
    estimates = np.array([f.parameters for f in fits])
    sigmas = np.array([f.sigma for f in fits])
    free = fits[0].free
    thermal = fit_thermal(temperatures, estimates, sigmas, free, options.degree)
    approach = _both_ways(poses) if options.hysteresis == "on" and options.temperature_model == "joint" else None
    rate = poses.rate_c_per_min if approach is not None else None
    hysteresis, rate_term = np.zeros(3), np.zeros(3)
    chosen: int | None = None  # which of HYSTERESIS_CANDIDATES; None: the sign of the last change
    if options.temperature_model == "joint":
        # The hysteresis state: the sign of the last change, or a swing over a span relaxing at rest (each of
        # HYSTERESIS_CANDIDATES); the one the calibration poses fit best (least χ², the same parameters) is kept.
        candidates: list[tuple[int | None, np.ndarray | None]] = [(None, approach)]
        if approach is not None and poses.hysteresis_states is not None:
            candidates += list(enumerate(poses.hysteresis_states))
        # A state the campaign's travel does not swing through at least half-way (a span wider than it, or one
        # relaxing faster than it travels) is no hysteresis these poses can measure: h times a small swing is a
        # trend the polynomials and a large ±h can mimic. A relaxation is one more thing the poses must
        # determine: kept only where it fits better than the best state that holds by more than χ²(1) at 99 %.
        start, best = thermal, np.inf
        results = []
        for index, state in candidates:
            if index is not None and state is not None and np.ptp(state) < MIN_STATE_SWING:
                continue
            found = fit_joint(start, free, pose_temperatures, poses.mean, poses.stderr, reference, options.mode,
                               accuracy_rad, poses.magnitude, state, rate)
            relaxing = index is not None and HYSTERESIS_CANDIDATES[index][1] is not None
            results.append((found[3] + (RELAXATION_CHI2 if relaxing else 0.0), found, state, index))
        _, (thermal, hysteresis, rate_term, best), approach, chosen = min(results, key=lambda r: r[0])
    span_c, relax_h = HYSTERESIS_CANDIDATES[chosen] if chosen is not None else (0.0, None)
    # In-sample: the fit as fitted (its hysteresis and rate terms removed); the calibration delivered, and
    # so the verification, knows neither: it is the sensor at rest, the mean of both directions.
    unhysteretic = poses.mean
    if approach is not None and rate is not None:
        unhysteretic = poses.mean - approach[:, None] * hysteresis - rate[:, None] * rate_term
    compensated = correct(unhysteretic, thermal.parameters_at(pose_temperatures, "extrapolate"))
    metrics = _metrics(poses, setpoints, groups, temperatures, fits, thermal, compensated, options, spec)
    metrics[f"expected_fit_rmse_{m}"] = _expected_rmse(poses, groups, fits, thermal, pose_temperatures, options)
    if approach is not None:  # warming minus cooling, per axis: what the calibration (their mean) leaves ± half of
        metrics[f"hysteresis_{m}"] = (2e3 * hysteresis).tolist()
        metrics[f"rate_bias_{m}_per_c_per_min"] = (1e3 * rate_term).tolist()
        metrics["hysteresis_span_c"] = span_c
        metrics["hysteresis_relaxation_h"] = relax_h
    elif options.hysteresis == "on":
        thermal.warnings.append("fit.hysteresis not fitted: " + (
            "the temperature model is not joint" if options.temperature_model != "joint" else
            f"fewer than {MIN_POSES_EACH_WAY} poses approached warming and cooling over a common range of "
            "temperature (a campaign stopped before its way back?)"))
    for row, group, fit in zip(metrics["rmse_by_setpoint"], groups, fits):
        row[f"expected_{m}"] = _expected_rmse(poses, [group], [fit], None, pose_temperatures, options)
    align = options.mode == "norm-only"
    metrics["in_sample"] = pose_figures(compensated, poses.reference, poses.stderr, poses.setpoint_c,
                                        pose_temperatures, align, poses.magnitude, milli=m, angle=spec.angle)
    joint = options.temperature_model == "joint"
    terms = FittedTerms(approach, hysteresis, rate, rate_term) if approach is not None and rate is not None else None
    covariance = calibration_covariance(poses, groups, fits, thermal, temperatures, pose_temperatures, options.mode,
                                        joint, terms)
    scatter_c = temperature_scatter_c(poses, pose_temperatures, len(groups))
    metrics["uncertainty_budget"] = budget(poses, covariance, thermal, temperatures, scatter_c, m, spec.size_source)
    metrics[f"expanded_uncertainty_{m}"] = metrics["uncertainty_budget"][f"expanded_{m}"]
    parameter_u = of_sensor(thermal, covariance, poses.magnitude_u / poses.magnitude)
    metrics["parameter_uncertainty"] = parameter_u.expanded_table(certificate_temperatures(thermal.domain_c),
                                                                  list(spec.parameter_names))
    if stored.verification.any():
        checks = stored.subset(stored.verification)
        shift = None
        if terms is not None and checks.rate_c_per_min is not None:
            # The sensor's own state at each check, read off its temperature history as at every calibration
            # pose: the fitted model judged on poses it never saw. The calibration alone (as `apply` uses it,
            # the middle of both branches) beside it: on one branch it is off by up to ±h, the budget's
            # hysteresis.
            state = checks.hysteresis_states[chosen] \
                if chosen is not None and checks.hysteresis_states is not None else checks.approach
            assert state is not None  # a hysteresis fit has each pose's approach
            shift = state[:, None] * hysteresis + checks.rate_c_per_min[:, None] * rate_term
            metrics["verification_as_applied"], _ = _verification(checks, thermal, options, covariance, scatter_c,
                                                                  spec)
        metrics["verification"], coverage = _verification(checks, thermal, options, covariance, scatter_c, spec,
                                                          shift)
        if coverage is not None:
            metrics["truth_coverage_k2"] = coverage
    names = spec.parameter_names
    calibration = ChannelCalibration(
        model=Eq1Model.model_id, quantity=spec.quantity, unit=spec.unit,
        serial=poses.serial, mode=options.mode, free_parameters=[n for n, f in zip(names, free) if f],
        range=poses.range, lsb=poses.lsb, validity_c=thermal.domain_c, out_of_range=options.out_of_range,
        polynomial=PolynomialModel(domain_c=thermal.domain_c, degree=options.degree,
                                   coefficients={n: plain(c) for n, c in zip(names, thermal.coefficients)}),
        setpoints=[
            SetpointFit(setpoint_c=float(s), temperature_c=float(t), n_poses=f.n_poses,
                        chi2_reduced=plain(f.chi2_reduced),
                        parameters=dict(zip(names, plain(f.parameters))), sigma=dict(zip(names, plain(f.sigma))))
            for s, t, f in zip(setpoints, temperatures, fits)
        ],
        metrics=_file_metrics(plain(metrics), m),
        warnings=thermal.warnings,
    )
    return ChannelFit(poses.serial, calibration, plain(metrics), thermal, parameter_u,
                      VectorFitDetail(setpoints, temperatures, fits, compensated, metrics))


#: What a relaxing hysteresis state must gain in χ² over the best held one to be kept: χ²(1) at 99 %.
RELAXATION_CHI2 = float(chi2.ppf(0.99, 1))
#: The least swing (of −1…+1) a candidate hysteresis state must make over the calibration poses to be tried.
MIN_STATE_SWING = 1.0


def _file_metrics(metrics: dict[str, Any], milli: str) -> dict[str, Any]:
    """What the calibration file keeps of the figures: all but the simulation truth's errors, and of the
    budget at each temperature the totals (each source's share there is in `rig fit --json`)."""
    kept = {k: v for k, v in metrics.items() if k != "truth_error"}
    budget_ = dict(kept["uncertainty_budget"])
    budget_["by_temperature"] = [{k: v for k, v in row.items() if k != f"sources_{milli}"}
                                 for row in budget_["by_temperature"]]
    return {**kept, "uncertainty_budget": budget_}


def _expected_rmse(poses: VectorPoses, groups: list[np.ndarray], fits: list[SfemFit], thermal: ThermalModel | None,
                   pose_temperatures: np.ndarray, options: FitOptions) -> float:
    """The in-sample magnitude RMSE the fit is expected to reach (thousandths of the unit): of the thermal
    model's coefficients over every pose, or (`thermal` None) of one setpoint's parameters."""
    rows = np.concatenate(groups)
    if thermal is None:
        jacobian = fits[0].jacobian
    else:
        n_powers = fitted_powers(thermal, len(groups), options.temperature_model == "joint")
        powers = [np.vander(thermal.scaled(pose_temperatures[g]), n_powers, increasing=True) for g in groups]
        jacobian = thermal_jacobian([f.jacobian for f in fits], powers, 3 if options.mode == "reference" else 1)
    if options.mode == "reference":
        return expected_reference_rmse_mg(jacobian, poses.reference[rows], poses.stderr[rows],
                                          np.radians(poses.reference_accuracy_arcsec / 3600))
    return expected_norm_rmse_mg(jacobian, norm_sigma(poses.mean[rows], poses.stderr[rows]))


def _verification(checks: VectorPoses, thermal: ThermalModel, options: FitOptions, covariance: CoefficientCovariance,
                  scatter_c: float, spec: VectorQuantity,
                  shift: np.ndarray | None = None) -> tuple[dict[str, Any], float | None]:
    """The figures on poses the fit never saw, compensated as `apply` would (the calibration's out-of-range
    rule), each at its own smoothed temperature, after taking off `shift` (N, 3) where given (a hysteresis
    fit's terms at each check: then the uncertainty they are checked against has no hysteresis source, as they
    have none left); and in a dry run the share of their axis errors against the truth inside the expanded
    uncertainty."""
    groups = [np.flatnonzero(checks.setpoint_c == s) for s in dict.fromkeys(checks.setpoint_c.tolist())]
    temperatures = smoothed_temperatures(checks, groups)
    reading = checks.mean if shift is None else checks.mean - shift
    compensated = correct(reading, thermal.parameters_at(temperatures, options.out_of_range))
    references = ReferenceUncertainty(np.radians(checks.reference_accuracy_arcsec / 3600),
                                      checks.magnitude_u / checks.magnitude)
    figures = pose_figures(compensated, checks.reference, checks.stderr, checks.setpoint_c, temperatures,
                           options.mode == "norm-only", checks.magnitude, references, spec.milli, spec.angle)
    temperature_u_c = smoothed_temperature_u_c(checks.t_s, groups, scatter_c)
    # What the checks' Eq. 9 RMSE would be if the model were right: each check's own noise, and the noise of the
    # calibration carried to it (largest at the range's ends, where a ramp's checks are): the yardstick of an
    # out-of-sample RMSE, which the in-sample expected_fit_rmse (a fit takes up some of its poses' noise) is not.
    direction = compensated / np.linalg.norm(compensated, axis=1, keepdims=True)
    own = np.sum((direction * checks.stderr) ** 2, axis=1)
    carried = magnitude_noise_u(reading, temperatures, thermal, covariance, temperature_u_c, options.out_of_range)
    figures[f"expected_rmse_{spec.milli}"] = float(np.sqrt(np.mean(own + carried**2)) * 1e3)
    if shift is not None:  # each check's own state taken off: what is left of the hysteresis is not a source
        covariance = replace(covariance, hysteresis=None)
    if options.mode == "reference":
        figures["consistency_k2"] = _consistency(checks, compensated, temperatures, temperature_u_c, thermal,
                                                 covariance, options)
    coverage = truth_coverage(checks, covariance, thermal, compensated, temperatures, temperature_u_c, options.mode,
                              options.out_of_range)
    return figures, coverage


def _consistency(checks: VectorPoses, compensated: np.ndarray, temperatures: np.ndarray, temperature_u_c: np.ndarray,
                 thermal: ThermalModel, covariance: CoefficientCovariance, options: FitOptions) -> dict[str, Any]:
    """The verification poses' axis errors against the reference, each against its combined expanded uncertainty:
    the calibration's at the pose (the budget's sources) with the verification measurement's (the reading's noise,
    the table's pointing across the reference, its size's uncertainty along it): the share with E_n ≤ 1 (the
    gyroscope's likewise)."""
    sources = output_uncertainty(checks.mean, temperatures, thermal, covariance, checks.stderr, temperature_u_c,
                                 0.0, options.out_of_range)
    pointing = np.radians(checks.reference_accuracy_arcsec / 3600)
    size = np.linalg.norm(checks.reference, axis=1, keepdims=True)
    reference_u = np.sqrt((pointing * np.sqrt(np.maximum(size**2 - checks.reference**2, 0.0))) ** 2
                          + (checks.reference * checks.magnitude_u / checks.magnitude) ** 2)
    return consistency(compensated - checks.reference, combined(sources), reference_u)


def _metrics(poses: VectorPoses, setpoints: np.ndarray, groups: list[np.ndarray], temperatures: np.ndarray,
             fits: list[SfemFit], thermal: ThermalModel, compensated: np.ndarray, options: FitOptions,
             spec: VectorQuantity) -> dict[str, Any]:
    m = spec.milli
    by_setpoint = []
    for setpoint, temperature, group, fit in zip(setpoints, temperatures, groups, fits):
        by_setpoint.append({
            "setpoint_c": setpoint, "temperature_c": temperature,
            f"before_{m}": norm_rmse_mg(poses.mean[group], poses.magnitude),
            f"polynomial_{m}": norm_rmse_mg(compensated[group], poses.magnitude),
            f"measurement_{m}": norm_rmse_mg(correct(poses.mean[group], fit.parameters), poses.magnitude),
        })
    # Zero offset at each temperature: before, the fitted raw bias; after, what the polynomial model makes of
    # that same raw zero reading.
    bias = np.array([f.parameters[BIAS] for f in fits])
    offset_after = correct(bias, thermal.parameters_at(temperatures, "extrapolate"))
    magnitude_key, magnitude_factor = spec.magnitude_figure
    metrics: dict[str, Any] = {
        f"rmse_before_{m}": norm_rmse_mg(poses.mean, poses.magnitude),
        f"rmse_after_{m}": norm_rmse_mg(compensated, poses.magnitude),
        magnitude_key: poses.magnitude * magnitude_factor,
        "rmse_by_setpoint": by_setpoint,
        f"drift_before_{m}": drift_mg(bias),
        f"drift_after_{m}": drift_mg(offset_after),
        f"noise_floor_{m}": noise_floor_mg(poses.mean, poses.stderr),
        "chi2_reduced": [f.chi2_reduced for f in fits],
        "temperature_range_c": [float(temperatures.min()), float(temperatures.max())],
    }
    if poses.truth_parameters is not None:
        metrics["truth_error"] = _truth_error(poses.truth_parameters, setpoints, groups, fits, options.mode,
                                              spec.parameter_names)
    return metrics


def _truth_error(truth: np.ndarray, setpoints: np.ndarray, groups: list[np.ndarray], fits: list[SfemFit],
                 mode: str, names: tuple[str, ...]) -> list[dict[str, Any]]:
    """Estimate minus truth for every fitted parameter, in the fit's own gauge, with its 1σ and z."""
    records = []
    for setpoint, group, fit in zip(setpoints, groups, fits):
        true = truth[group].mean(axis=0)
        if mode == "norm-only":
            true = norm_only_gauge(true)
        for k in np.flatnonzero(fit.free):
            error = fit.parameters[k] - true[k]
            records.append({"parameter": names[k], "setpoint_c": float(setpoint), "error": float(error),
                            "sigma": float(fit.sigma[k]), "z": float(error / fit.sigma[k])})
    return records


def _both_ways(poses: VectorPoses) -> np.ndarray | None:
    """The poses' directions of approach if both occur often enough over a common range of temperature
    (else ±h and the constant bias could not be told apart: no term, and no figure)."""
    if poses.approach is None:
        return None
    warming, cooling = poses.temperature_c[poses.approach > 0], poses.temperature_c[poses.approach < 0]
    if min(len(warming), len(cooling)) < MIN_POSES_EACH_WAY:
        return None
    if max(warming.min(), cooling.min()) >= min(warming.max(), cooling.max()):
        return None
    return poses.approach


def with_approach(campaign: Campaign, poses: VectorPoses) -> VectorPoses:
    """The DUT's poses with the direction each was approached from, read off its soaks and poses."""
    history_t, history_c = [], []
    for soak in campaign.soaks:
        serials = list(soak.serials) or campaign.serials
        if poses.serial in serials and len(soak.t_s):
            history_t.append(np.asarray(soak.t_s, dtype=float))
            history_c.append(np.asarray(soak.dut_c, dtype=float)[:, serials.index(poses.serial)])
    history = (poses.t_s, poses.temperature_c, np.concatenate(history_t or [np.zeros(0)]),
               np.concatenate(history_c or [np.zeros(0)]))
    return replace(poses, approach=approach_directions(*history), rate_c_per_min=temperature_rates_c_per_min(*history),
                   hysteresis_states=hysteresis_states(*history))
