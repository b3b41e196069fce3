"""The calibration file: per DUT, one calibration per channel (its channel model's parameters as polynomials of
the sensor's temperature, and how they were made), and the channels it measured that no channel model
calibrates, each with why.

A versioned YAML artefact, checked on load. Version 3 holds `duts: {serial: {channels: {accel: …, gyro: …},
not_calibrated: {…: why}}}`, every channel's calibration the one shape `ChannelCalibration` (its `quantity`
names its model). Version 2 (each quantity's entry its own shape: `range_g`, `range_dps`) and version 1
(`sensors: {serial: …}`, every DUT an accelerometer, read as its `accel` channel) are read as version 3.
`apply` compensates raw readings with it, as the channel's model does.
"""

from __future__ import annotations

import warnings
from collections.abc import Mapping
from pathlib import Path
from typing import Annotated, Any, Literal

import numpy as np
import yaml
from pydantic import Field, field_validator, model_validator

from accelcal_rig.config.bounds import StrictModel, TemperatureC
from accelcal_rig.config.load import load_validated
from accelcal_rig.config.yaml_lines import CALIBRATION_LIMITS
from accelcal_rig.core.identifiers import is_serial
from accelcal_rig.durable import clear_dead_temporaries, write_text_atomically

FORMAT_NAME = "accelcal-rig calibration"
FORMAT_VERSION = 3
READABLE_VERSIONS = (1, 2, 3)
#: The quantity every version-1 calibration is (an accelerometer's), and its channel's name then.
VERSION_1_QUANTITY = "acceleration"
VERSION_1_CHANNEL = "accel"


class CalibrationRangeWarning(UserWarning):
    """Samples outside the calibrated temperature range were clamped or extrapolated."""


def _ordered(value: tuple[float, float]) -> tuple[float, float]:
    if not value[0] < value[1]:
        raise ValueError(f"a temperature range from low to high, not {value[0]:g}…{value[1]:g}")
    return value


class PolynomialModel(StrictModel):
    """Each parameter's coefficients in x = (T − mid(domain)) / half-width(domain), increasing powers, in the
    order of its channel model's parameters (checked by the calibration that holds it)."""

    domain_c: tuple[TemperatureC, TemperatureC]
    degree: int = Field(ge=0, le=6)
    coefficients: dict[Annotated[str, Field(max_length=64)],
                       Annotated[list[Annotated[float, Field(ge=-1e6, le=1e6)]], Field(min_length=1, max_length=7)]] = \
        Field(max_length=64)

    _domain = field_validator("domain_c")(_ordered)

    def matrix(self) -> np.ndarray:
        width = max(len(c) for c in self.coefficients.values())
        return np.array([c + [0.0] * (width - len(c)) for c in self.coefficients.values()])

    def at(self, temperature_c: np.ndarray | float) -> np.ndarray:
        """Every parameter (..., P) at each temperature, as the polynomials give it (no clamping here)."""
        d_low, d_high = self.domain_c
        x = (np.asarray(temperature_c, dtype=float) - 0.5 * (d_low + d_high)) / (0.5 * (d_high - d_low))
        return np.moveaxis(np.polynomial.polynomial.polyval(x, self.matrix().T), 0, -1)

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(self.coefficients)


class SetpointFit(StrictModel):
    setpoint_c: float
    temperature_c: float
    n_poses: int
    chi2_reduced: float | None
    parameters: dict[str, float]
    sigma: dict[str, float | None]


#: A sensor's verdict: CONDITIONAL where guarded acceptance leaves a figure inside its guard band.
VerdictName = Literal["PASS", "FAIL", "CONDITIONAL", "NOT JUDGED"]

#: How calibrations written before version 3 named a channel's range and code size, by the quantity they
#: were of: an accelerometer's `range_g`/`lsb_g`, a gyroscope's `range_dps`/`lsb_dps` (its model's
#: statements `earth_rate` and `gauge` at the top of its entry).
_BEFORE_VERSION_3 = {"range_g": ("acceleration", "g", "lsb_g", "sfem-eq1"),
                     "range_dps": ("angular rate", "dps", "lsb_dps", "gyro-rate-table")}


def _version_3_entry(data: dict[str, Any]) -> dict[str, Any]:
    """A channel's entry as version 3 writes it, from one of any version."""
    if "range" in data:
        return data
    for old, (quantity, unit, lsb, model) in _BEFORE_VERSION_3.items():
        if old in data:
            entry = {k: v for k, v in data.items() if k not in (old, lsb, "earth_rate", "gauge")}
            statements = {k: data[k] for k in ("earth_rate", "gauge") if k in data}
            return {**entry, "range": data[old], **({"lsb": data[lsb]} if lsb in data else {}), "quantity": quantity,
                    "unit": unit, "model": data.get("model", model), **({"statements": statements} if statements else {})}
    return data


class ChannelRangeScale(StrictModel):
    """Another range the channel was measured at: its readings are `scale` × (per axis) what the channel's own
    range reads, so they are divided by it before the model."""

    range: float = Field(gt=0, le=1e6, description="± full scale in the channel's unit")
    scale: list[float] = Field(min_length=1, max_length=3)
    sigma: list[float] = Field(min_length=1, max_length=3, description="1σ of each scale")


class ChannelCalibration(StrictModel):
    """One channel of one DUT calibrated: its model's parameters as polynomials of the sensor's own
    temperature, the setpoint fits they came from, the figures, the verdict and the decision, and what its
    model states of how it was made (`statements`). The same shape for every quantity: the channel model
    (fit/channel_models.py, by `quantity`) knows what its parameters and figures mean."""

    model: str = Field(min_length=1, max_length=64, description="the channel model's parameterisation, e.g. "
                                                                 "sfem-eq1 (Eq. 1), gyro-rate-table")
    quantity: str = Field(min_length=1, max_length=64, description="what the channel measures: acceleration, "
                                                                    "angular rate, …")
    unit: str = Field(min_length=1, max_length=16, description="the unit of its readings: g, dps, …")
    serial: str = Field(min_length=1, max_length=128)
    mode: str = Field(min_length=1, max_length=32, description="how it was fitted: reference, norm-only, rate-table, "
                                                                "hand-held")
    free_parameters: list[Annotated[str, Field(max_length=64)]] = Field(max_length=64, description="the parameters "
                                                                         "the data determined; the others hold "
                                                                         "their nominal values")
    range: float = Field(gt=0, le=1e6, description="measuring range, ± in `unit`")
    lsb: float = Field(gt=0, le=100, description="`unit` per code, for compensating raw codes")
    range_scales: list[ChannelRangeScale] = Field([], max_length=8, description="the other ranges it was measured "
                                                  "at, each one's sensitivity relative to `range`")
    validity_c: tuple[TemperatureC, TemperatureC]
    out_of_range: Literal["clamp", "extrapolate"] = "clamp"
    polynomial: PolynomialModel
    setpoints: list[SetpointFit]
    statements: dict[Annotated[str, Field(max_length=64)], Annotated[str, Field(max_length=1000)]] = Field(
        {}, max_length=16, description="what the model states of how it was made (a gyroscope's Earth rate and gauge)")
    metrics: dict[str, Any] = {}
    warnings: list[str] = []
    verdict: VerdictName | None = Field(None, description="against the procedure's acceptance limits under its "
                                                          "decision rule (NOT JUDGED: it states none)")
    verdict_reasons: list[str] = []
    decision: dict[str, Any] = Field({}, description="the decision rule as stated and every figure judged: its "
                                                     "value, expanded uncertainty, limit and outcome")

    @model_validator(mode="before")
    @classmethod
    def _of_its_model(cls, data: Any) -> Any:
        """An entry written before version 3 read as one of version 3 (its range and code size named in its
        quantity's unit, an accelerometer's without a `model`, a gyroscope's statements beside its figures);
        then its quantity's model found, and its polynomials put in the model's order of parameters."""
        if not isinstance(data, dict):
            return data
        data = _version_3_entry(data)
        from accelcal_rig.fit.channel_models import model_for_quantity  # the models build calibrations

        quantity = data.get("quantity")
        model = model_for_quantity(quantity) if isinstance(quantity, str) else None
        if model is None:
            return data  # the field's own check says what is wrong
        if data.get("model") != model.model_id:
            raise ValueError(f"a {quantity} calibration of model {data.get('model')!r}: this accelcal-rig's "
                             f"{model.sensor} model is {model.model_id!r}")
        polynomial = data.get("polynomial")
        coefficients = polynomial.get("coefficients") if isinstance(polynomial, dict) else None
        if isinstance(coefficients, dict):
            names = model.parameter_names
            if set(coefficients) != set(names):
                raise ValueError(f"polynomial coefficients needed for exactly {', '.join(names)}")
            data = {**data, "polynomial": {**polynomial, "coefficients": {n: coefficients[n] for n in names}}}
        return data

    @field_validator("quantity")
    @classmethod
    def _a_model_calibrates_it(cls, value: str) -> str:
        from accelcal_rig.fit.channel_models import known_quantities, model_for_quantity

        if model_for_quantity(value) is None:
            raise ValueError(f"no channel model calibrates {value!r} here (known: {', '.join(known_quantities())})")
        return value

    @property
    def parameter_names(self) -> tuple[str, ...]:
        return self.polynomial.names

    def parameters_at(self, temperature_c: np.ndarray | float) -> np.ndarray:
        """The model's parameters (..., P) at each temperature, as the file's `out_of_range` says outside its
        validity (clamped or extrapolated, warned either way)."""
        temperature_c = np.asarray(temperature_c, dtype=float)
        low, high = self.validity_c
        outside = (temperature_c < low) | (temperature_c > high)
        if np.any(outside):
            action = "clamped to" if self.out_of_range == "clamp" else "extrapolated beyond"
            warnings.warn(CalibrationRangeWarning(
                f"{self.quantity} of sensor {self.serial}: {int(outside.sum())} of {outside.size} temperatures "
                f"{action} the calibrated {low:g}…{high:g} °C"), stacklevel=3)
        if self.out_of_range == "clamp":
            temperature_c = np.clip(temperature_c, low, high)
        return self.polynomial.at(temperature_c)


class DutCalibration(StrictModel):
    """One DUT: a calibration per channel a channel model handles, and why each other channel has none."""

    channels: dict[str, ChannelCalibration] = Field(min_length=1, max_length=16)
    not_calibrated: dict[str, Annotated[str, Field(max_length=500)]] = Field({}, max_length=16)


class CalibrationFile(StrictModel):
    format: str
    format_version: int
    created: str
    software_version: str
    source: dict[str, str]
    duts: dict[str, DutCalibration] = Field(min_length=1, max_length=1024)
    dropped: dict[str, Annotated[str, Field(max_length=1000)]] = Field(
        {}, max_length=1024, description="the campaign's DUTs left out of the fit, each with why (the early check "
                                         "dropped it: procedure early_check.action drop); written only when any")

    @field_validator("duts", "dropped")
    @classmethod
    def _serials(cls, value: dict[str, Any]) -> dict[str, Any]:
        bad = [serial for serial in value if not is_serial(serial)]
        if bad:
            raise ValueError(f"serial {bad[0][:80]!r} is not an identifier (letters, digits, _ . -, beginning with a "
                             "letter or a digit)")
        return value

    @model_validator(mode="before")
    @classmethod
    def _earlier_versions(cls, data: Any) -> Any:
        """A version-1 file's `sensors` are its DUTs' acceleration channels; the file-wide `model` of versions
        1 and 2 (every channel's is its own now) is left."""
        if not isinstance(data, dict):
            return data
        if data.get("format_version") == 1 and "sensors" in data and "duts" not in data:
            sensors = data["sensors"]
            duts = ({serial: {"channels": {VERSION_1_CHANNEL: calibration}} for serial, calibration in sensors.items()}
                    if isinstance(sensors, dict) else sensors)
            data = {**{k: v for k, v in data.items() if k != "sensors"}, "duts": duts}
        if data.get("format_version") in (1, 2) and data.get("model", "sfem-eq1") == "sfem-eq1":
            data = {k: v for k, v in data.items() if k != "model"}
        return data

    @field_validator("format")
    @classmethod
    def _format(cls, value: str) -> str:
        if value != FORMAT_NAME:
            raise ValueError(f"not an accelcal-rig calibration file (format {value!r})")
        return value

    @field_validator("format_version")
    @classmethod
    def _version(cls, value: int) -> int:
        if value not in READABLE_VERSIONS:
            raise ValueError(f"calibration format version {value} is not supported (this software reads "
                             f"{', '.join(map(str, READABLE_VERSIONS))})")
        return value

    def calibrated(self) -> list[tuple[str, str, ChannelCalibration]]:
        """Every calibrated channel: (serial, channel, calibration), DUT by DUT in the file's order."""
        return [(serial, name, calibration) for serial, dut in self.duts.items()
                for name, calibration in dut.channels.items()]

    def of_quantity(self, quantity: str) -> dict[str, ChannelCalibration]:
        """Each DUT's calibration of its channel that measures `quantity`, by serial, where it has one (the
        readers that need one quantity: a tilt check's accelerometers)."""
        found: dict[str, ChannelCalibration] = {}
        for serial, _, calibration in self.calibrated():
            if calibration.quantity == quantity and serial not in found:
                found[serial] = calibration
        return found

    def channel(self, serial: str, channel: str) -> ChannelCalibration:
        """One DUT's calibration of one channel; KeyError saying what the file has."""
        if serial not in self.duts:
            raise KeyError(f"no calibration for sensor {serial} (file has {', '.join(self.duts)})")
        dut = self.duts[serial]
        if channel not in dut.channels:
            why = dut.not_calibrated.get(channel, f"the file has {', '.join(dut.channels)}")
            raise KeyError(f"sensor {serial}: no calibration of its {channel} channel ({why})")
        return dut.channels[channel]

    def with_channels(self, serial: str, channels: dict[str, ChannelCalibration]) -> CalibrationFile:
        """A copy with these channels of `serial` (what it held beside them kept; a DUT it lacked added)."""
        dut = self.duts.get(serial)
        updated = (dut.model_copy(update={"channels": {**dut.channels, **channels}}) if dut is not None
                   else DutCalibration(channels=channels))
        return self.model_copy(update={"duts": {**self.duts, serial: updated}})

    def not_calibrated(self) -> dict[str, dict[str, str]]:
        """Each DUT's channels that no channel model calibrated yet, and why (empty: every channel is)."""
        return {serial: dict(dut.not_calibrated) for serial, dut in self.duts.items() if dut.not_calibrated}


def apply(calibration: ChannelCalibration, reading: np.ndarray, temperature_c: np.ndarray | float,
          companions: Mapping[str, np.ndarray] | None = None, range_: float | None = None) -> np.ndarray:
    """Compensate raw readings (..., axes) in the channel's unit taken at the sensor's own temperatures (...) →
    the quantity in the DUT frame, as the channel's model does it. `companions`: the DUT's other channels'
    compensated readings by quantity where the model needs them (a gyroscope's specific force). `range_`: the
    range they were read at, when not the calibration's own: one of its `range_scales`, else refused."""
    from accelcal_rig.fit.channel_models import model_of

    reading = np.asarray(reading, dtype=float)
    if range_ is not None and range_ != calibration.range:
        scale = next((s for s in calibration.range_scales if s.range == range_), None)
        if scale is None:
            measured = "/".join(f"{r:g}" for r in [calibration.range, *(s.range for s in calibration.range_scales)])
            raise ValueError(f"{calibration.quantity} of sensor {calibration.serial}: calibrated at ±{measured} "
                             f"{calibration.unit}, not ±{range_:g}")
        reading = reading / np.asarray(scale.scale)
    return model_of(calibration).compensate(calibration, reading, temperature_c, companions or {})


def apply_codes(calibration: ChannelCalibration, codes: np.ndarray, temperature_c: np.ndarray | float,
                companions: Mapping[str, np.ndarray] | None = None) -> np.ndarray:
    """As `apply`, from the part's signed codes at the calibration's range."""
    return apply(calibration, np.asarray(codes, dtype=float) * calibration.lsb, temperature_c, companions)


def save_calibration(calibration: CalibrationFile, path: Path) -> None:
    """Write the calibration file, replacing any file at `path` whole (never a half-written one), and what
    writers of it that were killed left half-built beside it."""
    clear_dead_temporaries(path)
    dumper = getattr(yaml, "CSafeDumper", yaml.SafeDumper)  # libyaml: a 64-DUT calibration is 2 MB of YAML
    data = calibration.model_dump(mode="json")
    if not data["dropped"]:
        del data["dropped"]  # a file with every DUT fitted reads as it did before DUTs could be dropped
    text = yaml.dump(data, Dumper=dumper, sort_keys=False, width=120, allow_unicode=True)
    write_text_atomically(path, "# accelcal-rig calibration: each channel model's parameters as polynomials of the "
                                "sensor's temperature\n" + text, "the calibration")
    _remember(path, CalibrationFile.model_validate(data))  # what reading it back gives, without the parse


def load_calibration(path: Path) -> CalibrationFile:
    """The calibration file at `path`, validated; read again only once the file has changed (a run's
    certificates and its registry entries read the same file one after the other)."""
    key = _file_key(path)
    if key is None:  # missing or unreadable: the loader says so in its own words
        return load_validated(path, CalibrationFile, CALIBRATION_LIMITS, _in_version_1).model
    if key not in _LOADED:
        _remember(path, load_validated(path, CalibrationFile, CALIBRATION_LIMITS, _in_version_1).model)
    return _LOADED[key].model_copy(deep=True)


def _in_version_1(key: tuple[str | int, ...], lines: dict[tuple[str | int, ...], int]) -> tuple[str | int, ...]:
    """Where a key of a DUT's calibration stands in a file of an earlier version, so that a problem in one is
    reported at its own key and line: a version-1 file's `sensors.<serial>.…`; a channel's range and code size by
    the names of its quantity's unit (`range_g`, `lsb_dps`) before version 3."""
    if (len(key) >= 4 and key[0] == "duts" and key[2:4] == ("channels", VERSION_1_CHANNEL)
            and ("sensors", key[1]) in lines):
        key = ("sensors", key[1], *key[4:])
    if key and key[-1] in ("range", "lsb"):
        for old, (_, unit, _, _) in _BEFORE_VERSION_3.items():
            if (*key[:-1], old) in lines:
                return (*key[:-1], f"{key[-1]}_{unit}")
    return key


#: Calibrations read or written lately, by (path, inode, size, modification time): a changed file is read again.
_LOADED: dict[tuple[Path, int, int, int], CalibrationFile] = {}
_LOADED_AT_MOST = 4


def _file_key(path: Path) -> tuple[Path, int, int, int] | None:
    try:
        stat = path.stat()
    except OSError:
        return None
    return path.resolve(), stat.st_ino, stat.st_size, stat.st_mtime_ns


def _remember(path: Path, calibration: CalibrationFile) -> None:
    key = _file_key(path)
    if key is None:
        return
    _LOADED[key] = calibration
    while len(_LOADED) > _LOADED_AT_MOST:
        _LOADED.pop(next(iter(_LOADED)))


def plain(value: Any) -> Any:
    """numpy scalars and arrays → Python floats and lists, NaN → None, for YAML and JSON."""
    if isinstance(value, dict):
        return {k: plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple, np.ndarray)):
        return [plain(v) for v in value]
    if isinstance(value, (np.integer,)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        return None if not np.isfinite(value) else float(value)
    if isinstance(value, np.bool_):
        return bool(value)
    return value
