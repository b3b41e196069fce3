"""The calibration file: per DUT, one calibration per channel (the thermal polynomials of Eq. 1's parameters
and how they were made), and the channels it measured that no channel model calibrates yet, each with why.

A versioned YAML artefact, checked on load. Version 2 holds `duts: {serial: {channels: {accel: …},
not_calibrated: {gyro: why}}}`; version 1 (`sensors: {serial: …}`, every DUT an accelerometer) is read as
version 2 with each calibration its DUT's `accel` channel. `apply` compensates raw readings with it.
"""

from __future__ import annotations

import warnings
from pathlib import Path
from typing import Annotated, Any, ClassVar, Literal

import numpy as np
import yaml
from pydantic import Discriminator, Field, Tag, field_validator, model_validator

from accelcal_rig.config.bounds import StrictModel, TemperatureC
from accelcal_rig.config.load import load_validated
from accelcal_rig.config.yaml_lines import CALIBRATION_LIMITS
from accelcal_rig.durable import clear_dead_temporaries, write_text_atomically
from accelcal_rig.fit import gyro_model
from accelcal_rig.fit.sfem import PARAMETER_NAMES, correct

FORMAT_NAME = "accelcal-rig calibration"
FORMAT_VERSION = 2
READABLE_VERSIONS = (1, 2)
#: The channel every version-1 calibration is, and the one readers that handle a single channel take.
ACCELERATION = "accel"
#: A six-axis part's gyroscope channel.
ANGULAR_RATE = "gyro"


class CalibrationRangeWarning(UserWarning):
    """Samples outside the calibrated temperature range were clamped or extrapolated."""



def _ordered(value: tuple[float, float]) -> tuple[float, float]:
    if not value[0] < value[1]:
        raise ValueError(f"a temperature range from low to high, not {value[0]:g}…{value[1]:g}")
    return value


class PolynomialModel(StrictModel):
    """Each parameter's coefficients in x = (T − mid(domain)) / half-width(domain), increasing powers."""

    #: The model's parameters, in its order: Eq. 1's.
    NAMES: ClassVar[tuple[str, ...]] = PARAMETER_NAMES

    domain_c: tuple[TemperatureC, TemperatureC]
    degree: int = Field(ge=0, le=6)
    coefficients: dict[str, Annotated[list[Annotated[float, Field(ge=-1e6, le=1e6)]], Field(min_length=1, max_length=7)]]

    @field_validator("coefficients")
    @classmethod
    def _all_parameters(cls, value: dict[str, list[float]]) -> dict[str, list[float]]:
        if set(value) != set(cls.NAMES):
            raise ValueError(f"coefficients needed for exactly {', '.join(cls.NAMES)}")
        return value

    _domain = field_validator("domain_c")(_ordered)

    def matrix(self) -> np.ndarray:
        width = max(len(c) for c in self.coefficients.values())
        return np.array([self.coefficients[n] + [0.0] * (width - len(self.coefficients[n])) for n in self.NAMES])

    def at(self, temperature_c: np.ndarray | float) -> np.ndarray:
        """Every parameter (..., P) at each temperature, as the polynomials give it (no clamping here)."""
        d_low, d_high = self.domain_c
        x = (np.asarray(temperature_c, dtype=float) - 0.5 * (d_low + d_high)) / (0.5 * (d_high - d_low))
        return np.moveaxis(np.polynomial.polynomial.polyval(x, self.matrix().T), 0, -1)


class GyroPolynomialModel(PolynomialModel):
    """The rate-table gyroscope model's 27 parameters (fit/gyro_model.py), each a polynomial."""

    NAMES: ClassVar[tuple[str, ...]] = gyro_model.PARAMETER_NAMES


class SetpointFit(StrictModel):
    setpoint_c: float
    temperature_c: float
    n_poses: int
    chi2_reduced: float | None
    parameters: dict[str, float]
    sigma: dict[str, float | None]


def _within_validity(polynomial: PolynomialModel, validity_c: tuple[float, float], out_of_range: str, who: str,
                     temperature_c: np.ndarray | float) -> np.ndarray:
    """Every channel model's parameters at each temperature, as its file's `out_of_range` says outside its
    validity (clamped or extrapolated, warned either way)."""
    temperature_c = np.asarray(temperature_c, dtype=float)
    low, high = validity_c
    outside = (temperature_c < low) | (temperature_c > high)
    if np.any(outside):
        action = "clamped to" if out_of_range == "clamp" else "extrapolated beyond"
        warnings.warn(CalibrationRangeWarning(
            f"{who}: {int(outside.sum())} of {outside.size} temperatures {action} the calibrated {low:g}…{high:g} °C"),
            stacklevel=4)
    if out_of_range == "clamp":
        temperature_c = np.clip(temperature_c, low, high)
    return polynomial.at(temperature_c)


#: A sensor's verdict: CONDITIONAL where guarded acceptance leaves a figure inside its guard band.
VerdictName = Literal["PASS", "FAIL", "CONDITIONAL", "NOT JUDGED"]


class SensorCalibration(StrictModel):
    serial: str = Field(min_length=1, max_length=128)
    mode: Literal["reference", "norm-only"]
    free_parameters: list[str] = Field(max_length=12)
    range_g: float = Field(gt=0, le=1000, description="measuring range, ± g (2, 4 or 8 for an ADXL355)")
    lsb_g: float = Field(gt=0, le=1, description="g per code, for compensating raw codes")
    validity_c: tuple[TemperatureC, TemperatureC]
    out_of_range: Literal["clamp", "extrapolate"] = "clamp"
    polynomial: PolynomialModel
    setpoints: list[SetpointFit]
    metrics: dict[str, Any] = {}
    warnings: list[str] = []
    verdict: VerdictName | None = Field(None, description="against the procedure's acceptance limits under its "
                                                          "decision rule (NOT JUDGED: it states none)")
    verdict_reasons: list[str] = []
    decision: dict[str, Any] = Field({}, description="the decision rule as stated and every figure judged: its "
                                                     "value, expanded uncertainty, limit and outcome")

    def parameters_at(self, temperature_c: np.ndarray | float) -> np.ndarray:
        """Eq. 1 parameters (..., 12) at each temperature, as the file's `out_of_range` says outside it."""
        return _within_validity(self.polynomial, self.validity_c, self.out_of_range, f"sensor {self.serial}",
                                temperature_c)


class GyroCalibration(StrictModel):
    """A gyroscope's calibration on a rate table (fit/gyro_model.py): its 27 parameters as polynomials of its
    own temperature, how the Earth's rate was taken out, and the gauge its misalignment is in."""

    model: Literal["gyro-rate-table"] = "gyro-rate-table"
    serial: str = Field(min_length=1, max_length=128)
    mode: Literal["rate-table", "hand-held"] = Field("rate-table", description="rate steps on a rate table, or "
                                                     "the turns between a hand-held recording's still intervals")
    free_parameters: list[str] = Field(list(gyro_model.PARAMETER_NAMES), max_length=27, description="the "
                                       "parameters the data determined; the others hold their nominal values")
    range_dps: float = Field(gt=0, le=100_000, description="measuring range, ± °/s")
    lsb_dps: float = Field(gt=0, le=100, description="°/s per code, for compensating raw codes")
    validity_c: tuple[TemperatureC, TemperatureC]
    out_of_range: Literal["clamp", "extrapolate"] = "clamp"
    polynomial: GyroPolynomialModel
    setpoints: list[SetpointFit]
    earth_rate: str = Field(max_length=500, description="how the Earth's rate entered the references")
    gauge: str = Field(max_length=500, description="the frame the sensitivity matrix is relative to")
    metrics: dict[str, Any] = {}
    warnings: list[str] = []
    verdict: VerdictName | None = None
    verdict_reasons: list[str] = []
    decision: dict[str, Any] = {}

    def parameters_at(self, temperature_c: np.ndarray | float) -> np.ndarray:
        """The model's 27 parameters (..., 27) at each temperature, as the file's `out_of_range` says outside it."""
        return _within_validity(self.polynomial, self.validity_c, self.out_of_range, f"gyroscope {self.serial}",
                                temperature_c)


def _channel_model(value: Any) -> str:
    """Which model a channel's calibration is: its `model`, Eq. 1 for one that names none (every file before
    gyroscopes)."""
    model = value.get("model", "sfem-eq1") if isinstance(value, dict) else getattr(value, "model", "sfem-eq1")
    return str(model)


ChannelCalibration = Annotated[
    Annotated[SensorCalibration, Tag("sfem-eq1")] | Annotated[GyroCalibration, Tag("gyro-rate-table")],
    Discriminator(_channel_model)]


class DutCalibration(StrictModel):
    """One DUT: a calibration per channel a channel model handles, and why each other channel has none."""

    channels: dict[str, ChannelCalibration] = Field(min_length=1, max_length=16)
    not_calibrated: dict[str, Annotated[str, Field(max_length=500)]] = Field({}, max_length=16)


class CalibrationFile(StrictModel):
    format: str
    format_version: int
    model: Literal["sfem-eq1"] = "sfem-eq1"
    created: str
    software_version: str
    source: dict[str, str]
    duts: dict[str, DutCalibration] = Field(min_length=1, max_length=1024)
    dropped: dict[str, Annotated[str, Field(max_length=1000)]] = Field(
        {}, max_length=1024, description="the campaign's DUTs left out of the fit, each with why (the early check "
                                         "dropped it: procedure early_check.action drop); written only when any")

    @model_validator(mode="before")
    @classmethod
    def _version_1(cls, data: Any) -> Any:
        """A version-1 file's `sensors` are its DUTs' acceleration channels."""
        if isinstance(data, dict) and data.get("format_version") == 1 and "sensors" in data and "duts" not in data:
            sensors = data["sensors"]
            duts = ({serial: {"channels": {ACCELERATION: calibration}} for serial, calibration in sensors.items()}
                    if isinstance(sensors, dict) else sensors)
            data = {**{k: v for k, v in data.items() if k != "sensors"}, "duts": duts, "format_version": 2}
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

    @property
    def sensors(self) -> dict[str, SensorCalibration]:
        """Each DUT's acceleration calibration by serial, for the readers that handle only that channel."""
        return {serial: calibration for serial, dut in self.duts.items()
                if isinstance(calibration := dut.channels.get(ACCELERATION), SensorCalibration)}

    @property
    def gyroscopes(self) -> dict[str, GyroCalibration]:
        """Each DUT's gyroscope calibration by serial, where it has one."""
        return {serial: calibration for serial, dut in self.duts.items()
                if isinstance(calibration := dut.channels.get(ANGULAR_RATE), GyroCalibration)}

    def sensor(self, serial: str) -> SensorCalibration:
        """The accelerometer calibration of one DUT; KeyError saying what the file has."""
        calibration = self._channel(serial, ACCELERATION)
        assert isinstance(calibration, SensorCalibration)
        return calibration

    def gyroscope(self, serial: str) -> GyroCalibration:
        """The gyroscope calibration of one DUT; KeyError saying what the file has."""
        calibration = self._channel(serial, ANGULAR_RATE)
        if not isinstance(calibration, GyroCalibration):
            raise KeyError(f"sensor {serial}: its {ANGULAR_RATE} channel is not a rate-table calibration")
        return calibration

    def _channel(self, serial: str, channel: str) -> SensorCalibration | GyroCalibration:
        if serial not in self.duts:
            raise KeyError(f"no calibration for sensor {serial} (file has {', '.join(self.duts)})")
        dut = self.duts[serial]
        if channel not in dut.channels:
            why = dut.not_calibrated.get(channel, "the file has none")
            raise KeyError(f"sensor {serial}: no calibration of its {channel} channel ({why})")
        return dut.channels[channel]

    def with_sensors(self, sensors: dict[str, SensorCalibration]) -> CalibrationFile:
        """A copy whose DUTs are `sensors`, each its DUT's acceleration calibration (what the others held
        beside it kept)."""
        duts = {serial: (self.duts[serial].model_copy(update={"channels": {**self.duts[serial].channels,
                                                                           ACCELERATION: calibration}})
                         if serial in self.duts else DutCalibration(channels={ACCELERATION: calibration}))
                for serial, calibration in sensors.items()}
        return self.model_copy(update={"duts": duts})

    def not_calibrated(self) -> dict[str, dict[str, str]]:
        """Each DUT's channels that no channel model calibrated yet, and why (empty: every channel is)."""
        return {serial: dict(dut.not_calibrated) for serial, dut in self.duts.items() if dut.not_calibrated}


def apply(calibration: SensorCalibration, accel_g: np.ndarray, temperature_c: np.ndarray | float) -> np.ndarray:
    """Compensate raw readings (..., 3) in g taken at the sensor's own temperatures (...) → specific force in g."""
    return correct(np.asarray(accel_g, dtype=float), calibration.parameters_at(temperature_c))


def apply_codes(calibration: SensorCalibration, codes: np.ndarray, temperature_c: np.ndarray | float) -> np.ndarray:
    """As `apply`, from signed 20-bit ADXL355 codes at the calibration's range."""
    return apply(calibration, np.asarray(codes, dtype=float) * calibration.lsb_g, temperature_c)


def apply_gyro(calibration: GyroCalibration, rate_dps: np.ndarray, force_g: np.ndarray,
               temperature_c: np.ndarray | float) -> np.ndarray:
    """Compensate raw gyroscope readings (..., 3) in °/s, taken at the sensor's own temperatures (...) while
    it felt the specific force `force_g` (..., 3, in g: the compensated accelerometer's reading) → the angular
    rate in the DUT frame, °/s."""
    return gyro_model.correct_rate(np.asarray(rate_dps, dtype=float), np.asarray(force_g, dtype=float),
                                   calibration.parameters_at(temperature_c))


def save_calibration(calibration: CalibrationFile, path: Path) -> None:
    """Write the calibration file, replacing any file at `path` whole (never a half-written one), and what
    writers of it that were killed left half-built beside it."""
    clear_dead_temporaries(path)
    dumper = getattr(yaml, "CSafeDumper", yaml.SafeDumper)  # libyaml: a 64-DUT calibration is 2 MB of YAML
    data = calibration.model_dump(mode="json")
    if not data["dropped"]:
        del data["dropped"]  # a file with every DUT fitted reads as it did before DUTs could be dropped
    text = yaml.dump(data, Dumper=dumper, sort_keys=False, width=120, allow_unicode=True)
    write_text_atomically(path, "# accelcal-rig calibration: Eq. 1 parameters as polynomials of the sensor "
                                "temperature\n" + text, "the calibration")
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
    """Where a key of a DUT's accel calibration stands in a version-1 file (`sensors.<serial>.…`), so that a
    problem in one is reported at its own line."""
    if len(key) >= 4 and key[0] == "duts" and key[2:4] == ("channels", ACCELERATION) and ("sensors", key[1]) in lines:
        return ("sensors", key[1], *key[4:])
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
