"""A continuous recording of one accelerometer (and of a gyroscope beside it, if the CSV has its columns), from
a CSV file or from a campaign file's raw samples."""

from __future__ import annotations

import csv
import hashlib
import io
import math
from array import array
from dataclasses import dataclass, field
from pathlib import Path
from typing import Literal

import numpy as np

from accelcal_rig.core.units import STANDARD_GRAVITY_M_S2
from accelcal_rig.durable import read_regular_file
from accelcal_rig.errors import ConfigError
from accelcal_rig.store.read import dut_description, rows_at_setpoint, usable_campaign
from accelcal_rig.store.records import STATIC_KINDS

#: The largest number a recording's CSV may hold, and the largest reading (in g, once scaled) and
#: temperature range taken for a recording of an accelerometer turned by hand.
MAX_VALUE = 1e15
#: The largest CSV recording read (a day at 1 kHz is about 3 GB: split it; an hour at 100 Hz is 20 MB).
MAX_CSV_BYTES = 512 << 20
MAX_ACCEL_G = 1000.0
MIN_TEMPERATURE_C, MAX_TEMPERATURE_C = -100.0, 300.0
#: The largest rate (°/s, once scaled) taken for a gyroscope turned by hand: MEMS gyroscopes end at ±4000 °/s, and
#: a column read in the wrong units (°/s read as rad/s: ×57) goes past it.
MAX_GYRO_DPS = 5000.0
Units = Literal["g", "counts", "m/s2"]
GyroUnits = Literal["dps", "rad/s", "counts"]
TimeUnit = Literal["s", "ms", "samples"]


class RecordingUnusable(ConfigError):
    """Too few static intervals, or too poorly spread, or turns that say too little, for the fit asked for: bad
    input (exit code 2)."""


@dataclass(frozen=True)
class Recording:
    source: str
    t_s: np.ndarray                    # (n,) increasing
    accel_g: np.ndarray                # (n, 3) raw readings in g (counts × lsb_g)
    temperature_c: np.ndarray | None   # (n,) the sensor's own temperature, if recorded
    lsb_g: float                       # g per count (for codes); 1.0 when given in g
    sha256: str                        # of the source data, for the calibration's provenance
    notes: list[str] = field(default_factory=list)
    serial: str | None = None          # the sensor, when the source names it (a campaign file's DUT)
    gravity_m_s2: float | None = None  # the site's gravity, when the source states it (a campaign file)
    gyro_dps: np.ndarray | None = None  # (n, 3) raw gyro readings in °/s (counts × gyro_lsb_dps), if recorded
    gyro_lsb_dps: float | None = None   # °/s per count (for codes); 1.0 in °/s, 180/π in rad/s; None without a gyro
    simulated: bool = False             # a dry run's campaign file: a rehearsal, recorded apart from the lab's


@dataclass(frozen=True)
class CsvLayout:
    """Which CSV columns hold time, x, y, z (and temperature, and the gyroscope's x, y, z), and in what units."""

    time: str
    x: str
    y: str
    z: str
    temperature: str | None = None
    time_unit: TimeUnit = "s"
    rate_hz: float | None = None       # needed when time_unit is "samples"
    units: Units = "g"
    counts_per_g: float | None = None  # needed for counts
    zero_code: float = 0.0             # code of 0 g: 0 for signed codes, e.g. 32768 for 16-bit offset binary
    gyro: tuple[str, str, str] | None = None  # the gyroscope's x, y, z columns, if it is to be read
    gyro_units: GyroUnits = "dps"
    counts_per_dps: float | None = None       # needed for gyro counts (the fit finds each axis's scale from it)

    @classmethod
    def parse_columns(cls, spec: str, gyro: str | None = None, **options: object) -> CsvLayout:
        """`time,x,y,z[,temperature]` (and `gyro`: `gx,gy,gz`): column names from the file's header, or column
        numbers counted from 1 (as cut and awk count) for a file with or without one."""
        names = [n.strip() for n in spec.split(",")]
        if len(names) not in (4, 5) or not all(names):
            raise ConfigError(f"--columns: {spec!r}: expected time,x,y,z or time,x,y,z,temperature column names "
                              "or numbers")
        numbered = [n.isdigit() for n in names]
        if any(numbered) and not all(numbered):
            raise ConfigError(f"--columns: {spec!r}: all names or all numbers, not both")
        if all(numbered) and min(int(n) for n in names) < 1:
            raise ConfigError(f"--columns: {spec!r}: column numbers count from 1")
        gyro_names: tuple[str, str, str] | None = None
        if gyro is not None:
            split = [n.strip() for n in gyro.split(",")]
            if len(split) != 3 or not all(split):
                raise ConfigError(f"--gyro-columns: {gyro!r}: expected gx,gy,gz column names or numbers")
            if any(n.isdigit() != all(numbered) for n in split):
                raise ConfigError(f"--gyro-columns: {gyro!r}: by {'number' if all(numbered) else 'name'}, as --columns "
                                  f"{spec!r}")
            if all(numbered) and min(int(n) for n in split) < 1:
                raise ConfigError(f"--gyro-columns: {gyro!r}: column numbers count from 1")
            gyro_names = (split[0], split[1], split[2])
        options["gyro"] = gyro_names
        return cls(*names[:4], names[4] if len(names) == 5 else None, **options)  # type: ignore[arg-type, call-arg]

    @property
    def wanted(self) -> list[str]:
        return ([self.time, self.x, self.y, self.z] + ([self.temperature] if self.temperature else [])
                + list(self.gyro or ()))

    @property
    def numbered(self) -> bool:
        return self.time.isdigit()


def _split_rows(text: str) -> tuple[list[list[str]], str]:
    """The rows of a delimited text, and what delimits them: a comma, a semicolon or a tab if the first line
    has one, else runs of white space."""
    lines = text.splitlines()
    first = next((line for line in lines if line.strip()), "")
    delimiter = next((d for d in (",", ";", "\t") if d in first), None)
    if delimiter is None:
        return [line.split() for line in lines], "white space"
    return list(csv.reader(io.StringIO(text, newline=""), delimiter=delimiter)), repr(delimiter)


def _column_index(path: Path, layout: CsvLayout, rows: list[list[str]]) -> tuple[list[int], int]:
    """(each wanted column's index, the row the data starts at): by name from the header, or by number, with
    a header line skipped if there is one."""
    start = next((i for i, row in enumerate(rows) if row), None)
    if start is None:
        raise ConfigError(f"{path}: empty file")
    if layout.numbered:
        index = [int(n) - 1 for n in layout.wanted]
        width = len(rows[start])
        if max(index) >= width:
            raise ConfigError(f"{path}: column {max(index) + 1} asked for, its first line has {width}")
        try:
            [float(rows[start][i]) for i in index]
        except ValueError:
            return index, start + 1  # a header line: skip it
        return index, start
    header = [h.strip() for h in rows[start]]
    missing = [c for c in layout.wanted if c not in header]
    if missing:
        columns = repr(", ".join(header))[1:-1]
        option = ("--gyro-columns gx,gy,gz" if set(missing) <= set(layout.gyro or ())
                  else "--columns time,x,y,z[,temperature]")
        raise ConfigError(f"{path}: no column {', '.join(missing)} (columns: {columns[:120]}"
                          f"{'…' if len(columns) > 120 else ''}); map them with {option} (names, or numbers from 1)")
    return [header.index(c) for c in layout.wanted], start + 1


def read_csv_recording(path: Path, layout: CsvLayout) -> Recording:
    """A delimited text recording: comma, semicolon, tab or white space; with a header (columns by name or
    number) or without (by number)."""
    if layout.time_unit == "samples" and not layout.rate_hz:
        raise ConfigError("--rate-hz is needed when the time column counts samples")
    if layout.gyro and layout.gyro_units == "counts" and not layout.counts_per_dps:
        raise ConfigError("--counts-per-dps is needed with --gyro-units counts (ICM-42688-P at ±2000 °/s: 16.4)")
    raw = read_regular_file(path, MAX_CSV_BYTES, "a recording")
    try:
        rows, delimiter = _split_rows(raw.decode("utf-8-sig", errors="replace"))
    except csv.Error as exc:
        raise ConfigError(f"{path}: not a delimited text: {exc}") from None
    index, start = _column_index(path, layout, rows)
    wanted = layout.wanted
    values = array("d")
    for line, row in enumerate(rows[start:], start=start + 1):
        if not row:
            continue
        try:
            numbers = [float(row[i]) for i in index]
        except (ValueError, IndexError):
            _refuse_cell(path, line, layout, row, index, delimiter)
        if not all(math.isfinite(v) and abs(v) <= MAX_VALUE for v in numbers):
            raise ConfigError(f"{path}:{line}: not a finite number of at most {MAX_VALUE:g} in "
                              f"columns {', '.join(wanted)}")
        values.extend(numbers)
    data = np.array(values, dtype=float).reshape(-1, len(wanted))
    if len(data) < 10:
        raise ConfigError(f"{path}: {len(data)} rows: too short to be a calibration recording")
    notes = []
    order = np.argsort(data[:, 0], kind="stable")
    if np.any(order != np.arange(len(order))):
        data = data[order]
        notes.append("rows were not in time order: sorted by the time column")
    t = data[:, 0] * {"s": 1.0, "ms": 1e-3, "samples": 1.0 / (layout.rate_hz or 1.0)}[layout.time_unit]
    if np.any(np.diff(t) <= 0):
        raise ConfigError(f"{path}: column {layout.time} repeats a time: one row per sample expected")
    codes = data[:, 1:4] - (layout.zero_code if layout.units == "counts" else 0.0)
    counts_per_g = layout.counts_per_g
    if layout.units == "counts" and not counts_per_g:
        # A norm-only fit finds each axis's scale itself: a provisional one that puts the median reading at
        # 1 g is enough (the fitted scale absorbs the rest, and the calibration keeps the LSB it used).
        counts_per_g = float(np.median(np.linalg.norm(codes, axis=1)))
        if not counts_per_g > 0:
            raise ConfigError(f"{path}: every reading is zero once --zero-code is taken off: give --counts-per-g")
        notes.append(f"--counts-per-g not given: {counts_per_g:.6g} taken from the median |reading|; the fitted "
                     "scale absorbs the difference")
    lsb_g = {"g": 1.0, "m/s2": 1.0 / STANDARD_GRAVITY_M_S2, "counts": 1.0 / (counts_per_g or 1.0)}[layout.units]
    accel_g = codes * lsb_g
    largest = float(np.abs(accel_g).max())
    if largest > MAX_ACCEL_G:
        raise ConfigError(f"{path}: readings up to {largest:.3g} g once scaled: not an accelerometer at rest and "
                          "turned by hand; check --units, --counts-per-g and --zero-code")
    temperature = data[:, 4] if layout.temperature else None
    if temperature is not None and not np.all((MIN_TEMPERATURE_C <= temperature) & (temperature <= MAX_TEMPERATURE_C)):
        raise ConfigError(f"{path}: column {layout.temperature}: temperatures outside {MIN_TEMPERATURE_C:g} … "
                          f"{MAX_TEMPERATURE_C:g} °C")
    gyro_dps, gyro_lsb_dps = _gyro_columns(path, layout, data)
    return Recording(str(path), t, accel_g, temperature, lsb_g, hashlib.sha256(raw).hexdigest(), notes,
                     gyro_dps=gyro_dps, gyro_lsb_dps=gyro_lsb_dps)


def _refuse_cell(path: Path, line: int, layout: CsvLayout, row: list[str], index: list[int], delimiter: str) -> None:
    """One line for a row with a cell that is not a number: a gyro column by its name (its option is a new one
    to get wrong), the accelerometer's as the columns it was read with."""
    for name, i in zip(layout.wanted, index):
        try:
            float(row[i])
        except (ValueError, IndexError):
            if name in (layout.gyro or ()):
                cell = repr(row[i]) if i < len(row) else "missing"
                raise ConfigError(f"{path}:{line}: column {name} (--gyro-columns): not a number ({cell}; delimited "
                                  f"by {delimiter})") from None
            break
    raise ConfigError(f"{path}:{line}: not a number in columns {', '.join(layout.wanted)} (delimited by "
                      f"{delimiter})")


def _gyro_columns(path: Path, layout: CsvLayout, data: np.ndarray) -> tuple[np.ndarray | None, float | None]:
    """The gyro columns in °/s (the last three read), and °/s per count; refused when a column reads faster
    than any MEMS gyroscope turns, which is what a wrong --gyro-units or --counts-per-dps looks like."""
    if not layout.gyro:
        return None, None
    lsb_dps = {"dps": 1.0, "rad/s": 180.0 / math.pi, "counts": 1.0 / (layout.counts_per_dps or 1.0)}[layout.gyro_units]
    gyro_dps = data[:, -3:] * lsb_dps
    largest = np.abs(gyro_dps).max(axis=0)
    if largest.max() > MAX_GYRO_DPS:
        name = layout.gyro[int(np.argmax(largest))]
        raise ConfigError(f"{path}: column {name}: rates up to {largest.max():.3g} °/s once scaled ({layout.gyro_units}"
                          f"): not a gyroscope turned by hand; check --gyro-units and --counts-per-dps")
    return gyro_dps, lsb_dps


def read_campaign_recording(path: Path, serial: str | None, setpoint_c: float | None) -> Recording:
    """One DUT's raw samples at one setpoint of a campaign file, pose after pose, as one recording (the
    gaps between poses are where the turntable moved)."""
    campaign = usable_campaign(path)
    serials = campaign.serials
    if serial is None:
        serial = serials[0]
    if serial not in serials:
        raise ConfigError(f"{path}: no sensor {serial} (the file has {', '.join(serials)})")
    setpoint_c, mask = rows_at_setpoint(path, campaign, setpoint_c)
    # The poses at rest: a rate step's turning table adds a centripetal acceleration no static interval has.
    rows = np.flatnonzero(mask & np.isin(campaign.pose_column("step_key"),
                                         list(campaign.header.plan.keys_of(*STATIC_KINDS))))
    dut = dut_description(campaign, serial)
    accelerometer = campaign.channel_of(serial, "acceleration")
    if accelerometer is None:
        raise ConfigError(f"{path}: sensor {serial} has no accelerometer (its channels: "
                          f"{', '.join(c.name for c in campaign.header.dut_channels(serial))})")
    lsb_g, odr_hz = accelerometer.lsb, float(dut["odr_hz"])
    codes = campaign.channel_column(serial, accelerometer.name, "raw_codes")[rows]
    pose_temperature = campaign.dut_column(serial, "temperature_c")[rows].mean(axis=1)
    t_start = campaign.pose_column("t_start_s")[rows]
    n = codes.shape[1]
    t = (t_start[:, None] + np.arange(n)[None, :] / odr_hz).ravel()
    accel_g = codes.reshape(-1, 3).astype(float) * lsb_g
    digest = hashlib.sha256(np.ascontiguousarray(codes).tobytes()).hexdigest()
    gravity = campaign.attrs.get("gravity_m_s2")
    return Recording(f"{path} sensor {serial} at {setpoint_c:g} °C", t, accel_g, np.repeat(pose_temperature, n), lsb_g,
                     digest, serial=serial, gravity_m_s2=float(gravity) if gravity is not None else None,
                     simulated=bool(campaign.attrs.get("dry_run", False)))
