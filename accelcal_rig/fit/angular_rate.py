"""The gyroscope's channel model: the rate-table model (fit/gyro_model.py) fitted per setpoint to the campaign's
rate steps and static poses against the table's rate and the Earth's (fit/gyro_fit.py), its budget at rest and
at the largest calibrated rate (fit/gyro_budget.py), and what the outputs say of it."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from accelcal_rig.core.geometry import fixture_to_dut
from accelcal_rig.fit import gyro_model
from accelcal_rig.fit.calibration import ChannelCalibration
from accelcal_rig.fit.channel_model import (
    ChannelFit,
    Figure,
    FigureLimit,
    FlightStackOffsets,
    NoiseFigures,
    NotCalibrated,
    ParameterGroup,
    Section,
    StoredFigure,
    Table,
    consistency_notes,
    noise_stored,
)
from accelcal_rig.fit.gyro_c import gyro_c_export
from accelcal_rig.fit.gyro_fit import MODEL_ID, GyroDesignError, GyroRecords, fit_gyro, read_gyro_records, site_of
from accelcal_rig.fit.options import FitOptions
from accelcal_rig.fit.parameter_uncertainty import expanded_at, nearest_setpoint_sigma, reference_c
from accelcal_rig.store.content import Campaign
from accelcal_rig.store.read import dut_description, site_gravity
from accelcal_rig.store.records import ChannelInfo

AXES = gyro_model.AXES
_CROSSES = tuple(f"{AXES[i]}{AXES[j]}" for i, j in gyro_model.CROSS_TERMS)
_PER_AXIS = ("x", "y", "z")
#: The quantity whose compensated reading is the specific force the g-sensitivity is fitted against.
SPECIFIC_FORCE = "acceleration"


def specific_force_g(campaign: Campaign, serial: str) -> np.ndarray:
    """The specific force (N, 3, standard g) the DUT felt at each stored record: its accelerometer's reference
    where it has one, else the site's gravity at the commanded pose through the DUT's nominal mount."""
    for info in campaign.header.dut_channels(serial):
        if info.quantity == SPECIFIC_FORCE:
            return campaign.channel_column(serial, info.name, "reference")
    mount = fixture_to_dut(tuple(dut_description(campaign, serial).get("mount_euler_deg", (0.0, 0.0, 0.0))))
    return site_gravity(campaign)[0] * campaign.pose_column("gravity_fixture") @ mount.T


class AngularRateModel:
    quantity = "angular rate"
    model_id = MODEL_ID
    sensor = "gyroscope"
    figure_unit = "°/s"
    parameter_names = gyro_model.PARAMETER_NAMES
    figures = (
        Figure("rmse_before_dps", "raw rate RMS error", "°/s", ".3f", "raw rms"),
        Figure("rmse_after_dps", "in-sample rate RMS error", "°/s", short="fit rms"),
        Figure("verification.rmse_dps", "verification rate RMS error", "°/s", short="verif. rms"),
        Figure("verification.max_axis_error_dps", "verification axis error", "°/s", short="axis"),
        Figure("verification.scale_error_ppm", "verification scale error", "ppm", ".0f", "scale"),
        Figure("verification.rest_error_dps", "verification error at rest", "°/s", short="rest"),
        Figure("expanded_uncertainty_dps", "expanded uncertainty (k = 2)", "°/s", short="U k=2"),
    )
    limits = (
        FigureLimit("max_verification_rmse_dps", "rmse_dps", "verification rate RMS error", "°/s", 10_000,
                    "RMS axis error of the compensated verification rate steps against their references"),
        FigureLimit("max_axis_error_dps", "max_axis_error_dps", "largest verification rate axis error", "°/s", 10_000,
                    "largest axis error of a compensated verification rate step"),
        FigureLimit("max_scale_error_ppm", "scale_error_ppm", "largest verification scale error", "ppm", 1e6,
                    "largest relative error along the turning axis at the verification rates"),
        FigureLimit("max_rest_error_dps", "rest_error_dps", "verification error at rest", "°/s", 10_000,
                    "RMS axis error of the compensated verification poses (at rest: the bias left)"),
    )
    parameter_groups = (
        ParameterGroup("bias_dps", "bias", gyro_model.PARAMETER_NAMES[gyro_model.BIAS], _PER_AXIS, 1.0, 0.0, "°/s",
                       "+.4f", 1000, "|bias| of each axis, the Earth's rate taken out as the calibration states"),
        ParameterGroup("scale_error_ppm", "scale error", gyro_model.PARAMETER_NAMES[gyro_model.SCALE], _PER_AXIS, 1e6,
                       -1.0, "ppm", "+.0f", 1e6, "|scale − 1| of each axis"),
        ParameterGroup("asymmetry_ppm", "asymmetry", gyro_model.PARAMETER_NAMES[gyro_model.ASYMMETRY], _PER_AXIS, 1e6,
                       0.0, "ppm", "+.0f", 1e6, "|± asymmetry of scale| of each axis"),
        ParameterGroup("nonlinearity_ppm", "nonlinearity", gyro_model.PARAMETER_NAMES[gyro_model.NONLINEARITY],
                       _PER_AXIS, 1e6, 0.0, "ppm", "+.0f", 1e6, "|cubic change of scale at 1000 °/s| of each axis"),
        ParameterGroup("cross_axis_mrad", "cross-axis", gyro_model.PARAMETER_NAMES[gyro_model.CROSS], _CROSSES, 1e3,
                       0.0, "mrad", "+.3f", 1000, "|each cross-axis term| of K"),
        ParameterGroup("gsens_dps_per_g", "g-sensitivity", gyro_model.PARAMETER_NAMES[gyro_model.GSENS],
                       tuple(f"{a}{b}" for a in AXES for b in AXES), 1.0, 0.0, "°/s/g", "+.4f", 1000,
                       "|each g-sensitivity term|"),
    )
    noise = NoiseFigures("arw_deg_per_rthr", "angle random walk", "°/√h", 60.0, "bias_instability_dph", "°/h", 3600.0,
                         ".4f", ".2f")
    flight_stack = FlightStackOffsets("gyroscope", ("bias_x_dps", "bias_y_dps", "bias_z_dps"), np.pi / 180.0, "rad/s")
    c_export = gyro_c_export()
    setpoint_check = False

    def records(self, campaign: Campaign, channel: ChannelInfo, serial: str,
                options: FitOptions) -> tuple[GyroRecords, dict[str, Any]] | str:
        """Its records, or why the campaign cannot calibrate it: no rate steps stored."""
        if not campaign.header.plan.keys_of("rate") & campaign.stored_keys:
            return "the campaign has no rate steps to calibrate it (a rate table and a procedure with rates:)"
        return read_gyro_records(campaign, serial, channel.name, specific_force_g(campaign, serial)), site_of(campaign)

    def fit(self, records: Any, options: FitOptions, allan: dict[str, Any] | None) -> ChannelFit:
        gyro_records, site = records
        try:
            return fit_gyro(gyro_records, options.degree, options.out_of_range, site, allan,
                            joint=options.temperature_model == "joint")
        except GyroDesignError as exc:
            raise NotCalibrated(f"not calibrated: {exc}") from None

    def judged_groups(self, calibration: ChannelCalibration) -> tuple[tuple[ParameterGroup, ...], list[str]]:
        return self.parameter_groups, []

    def compensate(self, calibration: ChannelCalibration, reading: np.ndarray, temperature_c: np.ndarray | float,
                   companions: Mapping[str, np.ndarray]) -> np.ndarray:
        """The rate in the DUT frame from a reading and the specific force it was taken at (the DUT's compensated
        accelerometer: its g-sensitivity is the model's)."""
        if SPECIFIC_FORCE not in companions:
            raise ValueError(f"gyroscope {calibration.serial}: its compensation needs the specific force each reading "
                             "was taken at (the DUT's compensated accelerometer)")
        return gyro_model.correct_rate(reading, np.asarray(companions[SPECIFIC_FORCE], dtype=float),
                                       calibration.parameters_at(temperature_c))

    def sections(self, calibration: ChannelCalibration) -> list[Section]:
        return [self._results(calibration), self._verification(calibration), self._budget(calibration)]

    def method(self, calibration: ChannelCalibration) -> str:
        setpoints = len(calibration.setpoints)
        how = ("rate steps about each fixture axis on a rate table" if calibration.mode == "rate-table"
               else "the turns between a hand-held recording's still intervals")
        return (f"the gyroscope's rate-table model (this laboratory's addition, not in the paper), {how}, fitted at "
                f"each of {setpoints} setpoint{'s' if setpoints != 1 else ''}, polynomials of degree "
                f"{calibration.polynomial.degree} in temperature")

    def reference_statements(self, figures: Mapping[str, Any]) -> list[tuple[str, str]]:
        return []

    def stored_figures(self, calibration: ChannelCalibration) -> list[StoredFigure]:
        """Bias and scale error at the reference temperature, each with its own expanded uncertainty (a fit from
        before they were stated: the bias's of a compensated rate at rest, the scale's twice the nearest
        setpoint's 1σ), the expanded uncertainty of a compensated rate at the largest calibrated rate, the
        verification rate steps' RMS error, and the noise record's figures."""
        at = reference_c(calibration.validity_c)
        values = dict(zip(self.parameter_names, calibration.polynomial.at(at).tolist()))
        metrics = calibration.metrics
        bias_names = self.parameter_names[gyro_model.BIAS]
        scale_names = self.parameter_names[gyro_model.SCALE]
        table = metrics.get("parameter_uncertainty")
        own = isinstance(table, dict) and any(abs(float(t) - at) < 1e-6 for t in table.get("temperatures_c", []))
        at_rest = (metrics.get("uncertainty_budget") or {}).get("at_rest") or {}
        sigma = nearest_setpoint_sigma(calibration.setpoints, at)
        scale_sigma = [float(s) for n in scale_names if (s := sigma.get(n)) is not None]
        bias_u = (tuple(expanded_at(metrics, n, at) or 0.0 for n in bias_names) if own
                  else tuple(float(u) for u in at_rest["expanded_dps"]) if at_rest.get("expanded_dps") else None)
        scale_u = (tuple(1e6 * (expanded_at(metrics, n, at) or 0.0) for n in scale_names) if own
                   else tuple(2e6 * s for s in scale_sigma) if len(scale_sigma) == 3 else None)
        figures = [StoredFigure("bias", "bias", "°/s", tuple(values[n] for n in bias_names), bias_u, trend=True),
                   StoredFigure("scale_error", "scale error", "ppm",
                                tuple(1e6 * (values[n] - 1.0) for n in scale_names), scale_u, trend=True)]
        expanded = metrics.get("expanded_uncertainty_dps")
        if expanded:
            figures.append(StoredFigure("expanded_uncertainty", "expanded uncertainty at the largest rate", "°/s",
                                        tuple(float(u) for u in expanded), lot=False))
        found = metrics.get("verification")
        verification: dict[str, Any] = found if isinstance(found, dict) else {}
        if verification.get("rmse_dps") is not None:
            figures.append(StoredFigure("verification_rmse", "verification rate RMS error", "°/s",
                                        (float(verification["rmse_dps"]),)))
        return figures + noise_stored(self.noise, metrics)

    def summary(self, figures: Sequence[Mapping[str, Any]]) -> str:
        checked = all("verification" in g and g["verification"]["rmse_dps"] is not None for g in figures)
        before = max((g["verification"] if checked else g)["rmse_before_dps"] for g in figures)
        after = max(g["verification"]["rmse_dps"] if checked else g["rmse_after_dps"] for g in figures)
        return (f"gyro rate RMS {before:.3f} → {after:.4f} °/s "
                f"{'at verification rates' if checked else 'in-sample, no verification rates'}, expanded "
                f"uncertainty ≤ {max(max(g['expanded_uncertainty_dps']) for g in figures):.4f} °/s at "
                f"{figures[0]['uncertainty_budget']['largest_rate_dps']:g} °/s")

    def _results(self, calibration: ChannelCalibration) -> Section:
        """The parameters at the reference temperature, a row per kind and a column per axis, each ± its expanded
        uncertainty there."""
        at = reference_c(calibration.validity_c)
        values = dict(zip(self.parameter_names, calibration.parameters_at(at).tolist()))

        def cell(name: str, factor: float, offset: float, spec: str) -> str:
            text = format((values[name] + offset) * factor, spec)
            expanded = expanded_at(calibration.metrics, name, at)
            return text if expanded is None else f"{text} ± {format(abs(expanded) * factor, spec.lstrip('+'))}"

        def row(label: str, names: list[str], factor: float, offset: float, spec: str) -> tuple[str, ...]:
            return (label, *(cell(n, factor, offset, spec) for n in names))

        others = [[b for b in AXES if b != a] for a in AXES]
        rows = (row("bias (°/s)", [f"bias_{a}_dps" for a in AXES], 1.0, 0.0, "+.4f"),
                row("scale error (ppm)", [f"scale_{a}" for a in AXES], 1e6, -1.0, "+.0f"),
                row("asymmetry (ppm)", [f"asymmetry_{a}" for a in AXES], 1e6, 0.0, "+.0f"),
                row("nonlinearity (ppm at 1000 °/s)", [f"nonlinearity_{a}" for a in AXES], 1e6, 0.0, "+.0f"),
                *(row(f"cross-axis K {', '.join(a + o[k] for a, o in zip(AXES, others))} (mrad)",
                      [f"cross_{a}{o[k]}_rad" for a, o in zip(AXES, others)], 1e3, 0.0, "+.3f") for k in range(2)),
                *(row(f"g-sensitivity G {', '.join(a + b for a in AXES)} (°/s/g)",
                      [f"gsens_{a}{b}_dps_per_g" for a in AXES], 1.0, 0.0, "+.4f") for b in AXES))
        low, high = calibration.validity_c
        statements = calibration.statements
        return Section(
            "Results", (f"Calibrated range {low:.2f} … {high:.2f} °C (the DUT's own temperature sensor), "
                        f"±{calibration.range:g} °/s. Parameters of the rate-table model ω_raw = b + u + a⊙|u| + "
                        f"n⊙u⊙(u/1000 °/s)² + G·f, u = K·ω, at {at:.2f} °C, each ± its expanded uncertainty (k = 2: "
                        "the fit's through the polynomials, the table's rate and pointing accuracy, the Earth's rate "
                        "where unplaced, the bias's wander); the full polynomials are in the calibration file.",),
            Table(("parameter", "gyro x", "gyro y", "gyro z"), rows),
            (f"Earth's rate: {statements.get('earth_rate', 'not stated')}. Gauge (the frame of K): "
             f"{statements.get('gauge', 'not stated')}." + (f" Ranges: {statements['ranges']}." if "ranges" in statements
                                                            else ""),))

    def _verification(self, calibration: ChannelCalibration) -> Section:
        title = "Verification (rate steps the calibration never saw)"
        v = calibration.metrics.get("verification")
        if not isinstance(v, dict):
            return Section(title, ("No verification rate steps: the gyroscope's calibration was not checked on rates "
                                   "it was not fitted to.",))
        temperatures = ", ".join(f"{t:g}" for t in v.get("temperatures_c", []))
        expanded = v.get("expanded_u", {})

        def dps(key: str) -> str:
            u = f" ± {expanded[key]:.4f}" if key in expanded else ""
            return "—" if v.get(key) is None else f"{v[key]:.4f}{u} °/s"

        rms = dps("rmse_dps") + (f" (before calibration {v['rmse_before_dps']:.4f} °/s; their noise floor "
                                 f"{v['noise_floor_dps']:.4f} °/s)" if v.get("rmse_before_dps") is not None
                                 and v.get("noise_floor_dps") is not None else "")
        scale_u = f" ± {expanded['scale_error_ppm']:.0f}" if "scale_error_ppm" in expanded else ""
        scale = "—" if v.get("scale_error_ppm") is None else f"{v['scale_error_ppm']:.0f}{scale_u} ppm"
        return Section(title, facts=(
            ("rate steps", f"{v.get('rate_steps', 0)} at {temperatures} °C"),
            ("RMS axis error", rms),
            ("largest axis error", dps("max_axis_error_dps")),
            ("largest scale error along the turning axis", scale),
            ("error at rest (RMS, verification poses)", dps("rest_error_dps")),
        ))

    def _budget(self, calibration: ChannelCalibration) -> Section:
        budget = calibration.metrics["uncertainty_budget"]
        rest, turning = budget["at_rest"], budget["at_largest_rate"]
        rate = f"{float(budget['largest_rate_dps']):g}"

        def cells(values: list[float]) -> tuple[str, ...]:
            return tuple(f"{u:.5f}" for u in values)

        rows = tuple((name, *cells(rest["sources_dps"][name]), *cells(turning["sources_dps"][name]))
                     for name in turning["sources_dps"])
        rows += (("combined standard uncertainty", *cells(rest["standard_dps"]), *cells(turning["standard_dps"])),
                 (f"expanded uncertainty (k = {budget['coverage_factor']:g}, about 95 %)",
                  *cells(rest["expanded_dps"]), *cells(turning["expanded_dps"])))
        notes = consistency_notes(calibration.metrics, "records", "the calibration's errors (the readings' noise "
                                  "taken out)")
        return Section("Uncertainty of a compensated rate",
                       (f"For {budget['reading']}: each source's largest standard uncertainty over the calibrated range "
                        f"and gravity along ±x, ±y, ±z, at rest and at ±{rate} °/s (the largest calibrated rate) about "
                        "each axis; °/s per axis (GUM, sources uncorrelated).",),
                       Table(("source", "rest x", "rest y", "rest z", f"{rate} °/s x", "y", "z"), rows), notes)


MODEL = AngularRateModel()
