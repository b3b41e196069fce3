"""What a quantity's channel model is: the one place after the journal that knows the quantity.

Everything that handles a calibrated channel — the campaign fit, verification, the budget, acceptance and the
decision rule, the calibration file, the certificate, the report, `rig fit`'s table, the registry, the
dashboard and the exports — asks the channel's model, looked up by the quantity the part's channel declares
(`Channel.quantity`: "acceleration", "angular rate", …), never by the channel's name. A model answers with
data (figures with their units, limits it understands, parameter groups, certificate sections as tables),
and each output renders that data the same way for every quantity.

Built-in models are registered in `fit/channel_models.py`; a package adds one through the entry-point group
`accelcal_rig.channel_models` (the object a `ChannelModel`).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Protocol, runtime_checkable

import numpy as np

if TYPE_CHECKING:
    from accelcal_rig.fit.calibration import ChannelCalibration
    from accelcal_rig.fit.options import FitOptions
    from accelcal_rig.fit.parameter_uncertainty import ParameterUncertainty
    from accelcal_rig.fit.thermal import ThermalModel
    from accelcal_rig.store.content import Campaign
    from accelcal_rig.store.records import ChannelInfo


@dataclass(frozen=True)
class Figure:
    """One figure of a channel's fit: where it is in the channel's figures (a dotted path: `rmse_after_mg`,
    `verification.rmse_mg`), what it is called and its unit. A figure whose value is a list is per axis."""

    key: str
    label: str
    unit: str
    spec: str = ".4f"
    #: its column's heading in a terminal's table, a word or two
    short: str = ""

    def value(self, figures: Mapping[str, Any]) -> Any:
        """The figure in `figures` (None where it is not there)."""
        found: Any = figures
        for part in self.key.split("."):
            if not isinstance(found, Mapping) or part not in found:
                return None
            found = found[part]
        return found

    def text(self, figures: Mapping[str, Any]) -> str:
        """The figure formatted (the largest of a per-axis one), or "—"."""
        value = self.value(figures)
        if isinstance(value, list):
            value = max((abs(v) for v in value if v is not None), default=None)
        return "—" if value is None else format(float(value), self.spec)


@dataclass(frozen=True)
class FigureLimit:
    """An acceptance limit on a verification figure (`acceptance.<channel>.<key>`): the figure it judges in the
    channel's `verification` figures (per axis where it is a list), with the figure's own expanded uncertainty
    under the same key in `verification.expanded_u`."""

    key: str                 #: e.g. "max_verification_rmse_mg"
    figure: str              #: e.g. "rmse_mg"
    label: str               #: e.g. "verification |g| RMSE"
    unit: str
    upper: float             #: the largest limit a procedure may state
    description: str
    #: verification temperatures the figure needs (a drift: two)
    needs_temperatures: int = 0
    #: why it cannot be judged when the verification has no such figure
    missing: str = "no verification records stored"


@dataclass(frozen=True)
class ParameterGroup:
    """Parameters of one kind (a bias per axis, the scale errors, the cross-axis terms): how the certificate
    states them at its reference temperature, and how a limit on them (`acceptance.<channel>.parameters.<key>`)
    judges them: (value + offset) × factor, in `unit`, signed."""

    key: str                 #: e.g. "bias_mg"
    label: str               #: e.g. "bias"
    names: tuple[str, ...]   #: the model's parameters, one per column
    columns: tuple[str, ...]  #: each one's axis or term, e.g. ("x", "y", "z")
    factor: float
    offset: float
    unit: str
    spec: str                #: format of a value, e.g. "+.4f"
    upper: float             #: the largest limit a procedure may state
    description: str


@dataclass(frozen=True)
class Table:
    """A table as data: a header and rows of text; the first `text_columns` columns are left-aligned."""

    header: tuple[str, ...]
    rows: tuple[tuple[str, ...], ...]
    text_columns: int = 1


@dataclass(frozen=True)
class Section:
    """A part of a certificate or report a model states of its calibration: a title, paragraphs before its
    table, the table, and notes after it (plain text: the renderer escapes it)."""

    title: str
    paragraphs: tuple[str, ...] = ()
    table: Table | None = None
    notes: tuple[str, ...] = ()
    #: key/value rows instead of a table (a verification's figures)
    facts: tuple[tuple[str, str], ...] = ()


@dataclass(frozen=True)
class NoiseFigures:
    """How a still record's Allan figures of the quantity are quoted: the random walk's and the bias
    instability's names in the figures, their units, the factor from the data's unit per √Hz and from the data's
    unit, and their formats."""

    random_walk: str                 #: e.g. "arw_deg_per_rthr"
    random_walk_label: str           #: e.g. "angle random walk"
    random_walk_unit: str            #: e.g. "°/√h"
    random_walk_factor: float
    instability: str                 #: e.g. "bias_instability_dph"
    instability_unit: str            #: e.g. "°/h"
    instability_factor: float
    random_walk_spec: str = ".4f"
    instability_spec: str = ".2f"


@dataclass(frozen=True)
class FlightStackOffsets:
    """What a flight stack's offset-only thermal compensation can hold of a channel: the bias's parameters
    (x, y, z) and the factor from the model's unit to SI (m/s², rad/s); `role` the stacks' word for the
    sensor ("accelerometer", "gyroscope")."""

    role: str
    bias: tuple[str, str, str]
    si_factor: float
    si_unit: str


@dataclass(frozen=True)
class CExport:
    """How the C header carries a model's calibrations: the names its table and C functions use (each
    calibration's row: serial, its unit per code, the polynomials' middle and half-width, the calibrated range,
    whether it clamps, the coefficients in the model's order) and the functions themselves (C99, <math.h>)."""

    type_name: str                     #: e.g. "accelcal_sensor"
    table: str                         #: the array of rows, e.g. "ACCELCAL_SENSORS"
    index: str                         #: a row's index macro before the serial, e.g. "ACCELCAL_SENSOR_"
    count: str                         #: e.g. "ACCELCAL_N_SENSORS"
    n_parameters: str                  #: e.g. "ACCELCAL_N_PARAMETERS"
    degree: str                        #: e.g. "ACCELCAL_DEGREE"
    lsb: str                           #: the row's unit-per-code field, e.g. "lsb_g"
    comment: tuple[str, ...]           #: the section's opening comment, a line each
    functions: str
    defines: tuple[tuple[str, str], ...] = ()
    #: code every section of this kind shares, emitted once (a helper both an accelerometer's and a
    #: magnetometer's functions call), with its guard macro
    shared: tuple[str, str] | None = None


@dataclass(frozen=True)
class StoredFigure:
    """A figure the registry keeps of a calibration, queried across calibrations (trend, lot statistics): its
    name and unit, its value per axis (or one value), and each one's expanded uncertainty (k = 2) where stated.
    `trend`: a sensor's drift per year is stated of it; `lot`: a lot's statistics show its spread."""

    name: str                          #: e.g. "bias"
    label: str                         #: e.g. "bias"
    unit: str                          #: e.g. "mg"
    values: tuple[float, ...]
    expanded: tuple[float, ...] | None = None
    trend: bool = False
    lot: bool = True


@dataclass(frozen=True)
class ChannelFit:
    """One channel of one DUT fitted: its calibration (as the file keeps it), the figures `rig fit --json`
    prints, and what acceptance judges with (the thermal model and each parameter's uncertainty)."""

    serial: str
    calibration: ChannelCalibration
    figures: dict[str, Any]
    thermal: ThermalModel
    parameter_u: ParameterUncertainty | None
    #: what the model's own report figures draw (an Eq. 1 fit's setpoints, their fits, the poses compensated)
    detail: Any = None


class NotCalibrated(Exception):  # noqa: N818 - what happened, not an error
    """A channel's records cannot calibrate it (a line saying why): it is measured and stored, and the calibration
    file says why it has no calibration."""


@runtime_checkable
class ChannelModel(Protocol):
    """A quantity's model after the journal: how its records are read and fitted, how a reading is
    compensated, its figures and units, what limits it understands, and what the outputs state of it."""

    @property
    def quantity(self) -> str:
        """The quantity a part's channel declares, e.g. "acceleration"."""
        ...

    @property
    def model_id(self) -> str:
        """The calibration file's `model` of a channel it calibrates, e.g. "sfem-eq1"."""
        ...

    @property
    def sensor(self) -> str:
        """The sensor it calibrates, as people say it: "accelerometer"."""
        ...

    @property
    def figure_unit(self) -> str:
        """The unit its figures are stated in, e.g. "mg"."""
        ...

    @property
    def parameter_names(self) -> tuple[str, ...]:
        """The model's parameters, in its order."""
        ...

    @property
    def figures(self) -> tuple[Figure, ...]:
        """The figures `rig fit`'s table, the report and the registry show, in-sample first."""
        ...

    @property
    def limits(self) -> tuple[FigureLimit, ...]:
        """The verification limits it understands (acceptance.<channel>.<key>)."""
        ...

    @property
    def parameter_groups(self) -> tuple[ParameterGroup, ...]:
        """Its parameters by kind, as certificates state them and limits judge them."""
        ...

    @property
    def noise(self) -> NoiseFigures | None:
        """How its noise record's Allan figures are quoted (None: it has none)."""
        ...

    @property
    def flight_stack(self) -> FlightStackOffsets | None:
        """What a flight stack's offset-only thermal compensation can hold of it (None: no stack has a place for it)."""
        ...

    @property
    def setpoint_check(self) -> bool:
        """Whether its channel is checked after each setpoint's poses (the early check: a DUT loose, turned or with
        a dead axis; fit/setpoint_check.py): a model whose every pose has a vector reference it knows well."""
        ...

    @property
    def c_export(self) -> CExport | None:
        """How the C header carries its calibrations (None: it has no C code)."""
        ...

    def records(self, campaign: Campaign, channel: ChannelInfo, serial: str, options: FitOptions) -> Any:
        """The DUT's records of this channel as the fit needs them (picklable: a large fixture is fitted in
        worker processes), or a line saying why the campaign cannot calibrate it."""
        ...

    def fit(self, records: Any, options: FitOptions, allan: dict[str, Any] | None) -> ChannelFit:
        """The channel fitted from its records (`allan`: its noise record's figures, where the campaign has
        one). NotCalibrated where the records cannot determine the model; ValueError where the fit fails."""
        ...

    def judged_groups(self, calibration: ChannelCalibration) -> tuple[tuple[ParameterGroup, ...], list[str]]:
        """The parameter groups a limit may judge in this calibration, and notes on those it may not (a
        norm-only fit determines no misalignment)."""
        ...

    def compensate(self, calibration: ChannelCalibration, reading: np.ndarray, temperature_c: np.ndarray | float,
                   companions: Mapping[str, np.ndarray]) -> np.ndarray:
        """Readings (..., axes) in the channel's unit at the sensor's own temperatures → the quantity in the DUT
        frame. `companions`: the DUT's other channels' compensated readings by quantity, for a model whose
        error depends on them (a gyroscope's g-sensitivity on the specific force)."""
        ...

    def method(self, calibration: ChannelCalibration) -> str:
        """How it was calibrated, as a certificate states the method (and the source it follows)."""
        ...

    def reference_statements(self, figures: Mapping[str, Any]) -> list[tuple[str, str]]:
        """What its references were, from a calibration's figures, as a certificate and `rig fit` state them:
        (what, statement)."""
        ...

    def sections(self, calibration: ChannelCalibration) -> list[Section]:
        """What a certificate states of the calibration beyond the shared parts: its results, verification,
        uncertainty budget and the model's own statements."""
        ...

    def stored_figures(self, calibration: ChannelCalibration) -> list[StoredFigure]:
        """What the registry keeps of the calibration beside it whole: its figures at the reference temperature
        (25 °C, or the calibrated range's nearest end) and its noise."""
        ...

    def summary(self, figures: Sequence[Mapping[str, Any]]) -> str:
        """One phrase for `rig fit`'s summary line over every DUT's figures of this channel (the worst of each)."""
        ...



def noise_stored(noise: NoiseFigures | None, metrics: Mapping[str, Any], lot: bool = True) -> list[StoredFigure]:
    """A calibration's noise record's figures (the record nearest 25 °C) as the registry keeps them, where it has
    them: the random walk and the bias instability per axis."""
    allan = metrics.get("allan") or {}
    if noise is None or not isinstance(allan, Mapping):
        return []
    kept = []
    for key, label, unit in ((noise.random_walk, noise.random_walk_label, noise.random_walk_unit),
                             (noise.instability, "bias instability", noise.instability_unit)):
        if isinstance(allan.get(key), list):
            kept.append(StoredFigure(label.replace(" ", "_"), label, unit, tuple(float(e["value"]) for e in allan[key]),
                                     lot=lot))
    return kept


def consistency_notes(metrics: Mapping[str, Any], records: str, truth_errors: str) -> tuple[str, ...]:
    """A budget section's notes on how its expanded uncertainty held on the verification `records` ("poses",
    "records"): the E_n check a lab can repeat (`verification.consistency_k2`: each axis error against the
    calibration's U with the verification measurement's), and in a dry run the check against the simulation's
    truth, saying which errors it counts (`truth_errors`) so that it compares what the budget covers."""
    notes = []
    check = (metrics.get("verification") or {}).get("consistency_k2")
    if check:
        notes.append(f"Verification: {check['within_share'] * 100:.1f} % of the {check['axis_errors']} axis errors of "
                     f"the verification {records} lie within this U combined with their measurement's (noise, "
                     "reference): E_n ≤ 1 (ISO 13528), about 95 % expected.")
    coverage = metrics.get("truth_coverage_k2")
    if coverage is not None:
        notes.append(f"Dry run: {coverage * 100:.1f} % of {truth_errors} against the simulation truth lie within U.")
    return tuple(notes)
