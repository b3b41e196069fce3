"""Write the campaign file (layout: docs/hdf5-layout.md).

Every dataset that grows is created empty and resizable when the file is created, then appended to and
flushed after each pose, so the file on disk always holds every pose measured so far. Events are
buffered and written with the next pose, soak or state change (the run's log file has them at once).
A process killed in the middle of a pose can leave some pose-aligned datasets one row longer than the
others; reopening the file to resume cuts them back to the poses stored whole.
"""

from __future__ import annotations

import datetime as dt
import os
import socket
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import h5py
import numpy as np

from accelcal_rig import __version__
from accelcal_rig.errors import ConfigError
from accelcal_rig.plan.compile import Plan
from accelcal_rig.store.atomic import signals_deferred
from accelcal_rig.store.records import Event, PoseRecord, SoakTrace

FORMAT_NAME = "accelcal-rig campaign"
_POSE_FIELDS = ("step_key", "setpoint_c", "pose_number", "commanded_angles_deg", "measured_angles_deg",
                "gravity_fixture", "t_start_s", "t_end_s", "chamber_temperature_c")
_DUT_FIELDS = ("raw_codes", "mean_g", "stderr_g", "temperature_c", "gravity_reference_g", "temperature_in_band")
_TRUTH_FIELDS = ("parameters", "gravity_g", "temperature_c")
_EVENT_FIELDS = ("t_s", "wall_time", "level", "kind", "message")
FORMAT_VERSION = 1
TEXT = h5py.string_dtype("utf-8")
#: Text that grows row by row is fixed-length UTF-8 (bytes per row), kept in the dataset's own chunks:
#: variable-length strings live in a file-wide heap, which a process killed while flushing can leave
#: damaged for the next writer. Longer text is cut at a character boundary.
GROWING_TEXT_BYTES = {"step_key": 64, "wall_time": 32, "level": 8, "kind": 16, "message": 1024}


def growing_text(name: str) -> np.dtype:
    return h5py.string_dtype("utf-8", length=GROWING_TEXT_BYTES[name])


def utc_now() -> str:
    return dt.datetime.now(dt.timezone.utc).isoformat(timespec="seconds")


def _growable(group: h5py.Group, name: str, tail: tuple[int, ...], dtype: Any, unit: str | None = None,
              chunk_rows: int = 64) -> h5py.Dataset:
    dataset = group.create_dataset(name, shape=(0,) + tail, maxshape=(None,) + tail, dtype=dtype,
                                   chunks=(chunk_rows,) + tail)
    if unit:
        dataset.attrs["unit"] = unit
    return dataset


@dataclass(frozen=True)
class Reopened:
    """What reopening a campaign file to resume it found."""

    previous_state: str        # the state the last run left: "running" means it never closed the file
    run: int                   # this run's number (1 was the run that created the file)
    poses_stored: int
    rows_cut: int              # rows of a pose killed mid-write, removed
    clock_now_s: float         # where the campaign's clock resumes: its latest time in the file, plus the
                               # wall time since then when the clock is real


def _append_rows(dataset: h5py.Dataset, rows: Any) -> None:
    if dataset.dtype.kind == "S":
        width = dataset.dtype.itemsize
        rows = np.array([str(r).encode()[:width].decode(errors="ignore").encode() for r in rows], dtype=dataset.dtype)
    else:
        rows = np.asarray(rows)
    n = dataset.shape[0]
    dataset.resize(n + len(rows), axis=0)
    dataset[n:] = rows


class CampaignWriter:
    """Owns the open campaign file for the length of a run."""

    def __init__(self, file: h5py.File) -> None:
        self._file = file
        self._datasets: dict[str, h5py.Dataset] = {}
        self._pending_events: list[tuple[float, str, str, str, str]] = []

    @property
    def file(self) -> h5py.File:
        """The open file, for stages that read what was stored (the fit) and add their own groups."""
        return self._file

    def _dataset(self, path: str) -> h5py.Dataset:
        """The dataset at `path`, its handle cached: lookups cost more than the writes themselves."""
        dataset = self._datasets.get(path)
        if dataset is None:
            dataset = self._datasets[path] = self._file[path]
        return dataset

    @classmethod
    def create(cls, path: Path, *, overwrite: bool, attrs: dict[str, Any], procedure_yaml: str,
               rig_yaml: str, plan: Plan, duts: list[dict[str, Any]], instruments: dict[str, dict[str, str]],
               samples_per_pose: int, turntable_accuracy_arcsec: float) -> CampaignWriter:
        if path.exists() and not overwrite:
            raise ConfigError(f"{path}: campaign file exists; choose another -o or pass --overwrite")
        try:
            file = h5py.File(path, "w")
        except OSError as exc:
            raise ConfigError(f"{path}: cannot create campaign file: {exc}") from None
        file.attrs.update({"format": FORMAT_NAME, "format_version": FORMAT_VERSION,
                           "software_version": __version__, "state": "created", "started": utc_now(),
                           "finished": "", "abort_reason": "", "runs": 1, **_writer_attrs(), **attrs})
        config = file.create_group("config")
        config.create_dataset("procedure_yaml", data=procedure_yaml, dtype=TEXT)
        config.create_dataset("rig_yaml", data=rig_yaml, dtype=TEXT)
        cls._write_plan(file.create_group("plan"), plan)
        poses = file.create_group("poses")
        poses.attrs["turntable_accuracy_arcsec"] = turntable_accuracy_arcsec
        cls._create_poses(poses, len(plan.axis_names))
        duts_group = file.create_group("duts")
        for dut in duts:
            cls._create_dut(duts_group.create_group(dut["serial"]), dut, samples_per_pose)
        group = file.create_group("instruments")
        for name, info in instruments.items():
            group.create_group(name).attrs.update(info)
        file.create_group("soaks")
        events = file.create_group("events")
        _growable(events, "t_s", (), "f8", "s", chunk_rows=256)
        for name in _EVENT_FIELDS[1:]:
            _growable(events, name, (), growing_text(name), chunk_rows=256)
        file.flush()
        return cls(file)

    @classmethod
    def reopen(cls, path: Path) -> tuple[CampaignWriter, Reopened]:
        """Open an existing campaign to continue it: cut any pose written only in part, count this run."""
        if not path.exists():
            raise ConfigError(f"{path}: no such campaign file to resume")
        try:
            file = h5py.File(path, "a")
        except OSError as exc:
            raise ConfigError(f"{path}: cannot open to resume (is a campaign still running on it?): {exc}") from None
        if file.attrs.get("format") != FORMAT_NAME:
            file.close()
            raise ConfigError(f"{path}: not an accelcal-rig campaign file")
        writer = cls(file)
        previous = str(file.attrs["state"])
        stored, cut = writer._cut_to_whole_poses()
        run = int(file.attrs.get("runs", 1)) + 1
        file.attrs.update({"runs": run, **_writer_attrs()})  # the last abort reason stays until this run starts
        file.flush()
        return writer, Reopened(previous, run, stored, cut, writer._clock_now_s())

    def _pose_aligned(self) -> list[h5py.Dataset]:
        datasets = [d for d in self._file["poses"].values()]
        for group in ("duts", "simulation_truth"):
            for serial in self._file.get(group, {}):
                datasets += [d for d in self._file[group][serial].values() if isinstance(d, h5py.Dataset)
                             and d.maxshape[0] is None]
        return datasets

    def _cut_to_whole_poses(self) -> tuple[int, int]:
        """(poses stored whole, rows removed): every pose-aligned dataset and event column cut to the
        shortest, the length every one of them reached."""
        cut = 0
        for datasets in (self._pose_aligned(), list(self._file["events"].values())):
            whole = min(d.shape[0] for d in datasets)
            for dataset in datasets:
                cut += dataset.shape[0] - whole
                dataset.resize(whole, axis=0)
        stored = self._file["poses/step_key"].shape[0]
        self._file.attrs["poses_done"] = stored
        return stored, cut

    def _clock_now_s(self) -> float:
        times = [self._file["events/t_s"][-1:], self._file["poses/t_end_s"][-1:]]
        times += [soak["t_s"][-1:] for soak in self._file["soaks"].values() if "t_s" in soak]
        last_t_s = float(max((float(t[0]) for t in times if len(t)), default=0.0))
        wall_times = self._file["events/wall_time"]
        if self._file.attrs.get("clock") != "real" or not wall_times.shape[0]:
            return last_t_s
        last_wall = dt.datetime.fromisoformat(_text(wall_times[-1]))
        return last_t_s + max(0.0, (dt.datetime.now(dt.timezone.utc) - last_wall).total_seconds())

    def record_instruments(self, instruments: dict[str, dict[str, str]]) -> None:
        """The drivers and endpoints of this run (a resumed run may reach an instrument another way)."""
        with signals_deferred():
            for name, info in instruments.items():
                self._file.require_group(f"instruments/{name}").attrs.update(info)

    def stored_step_keys(self) -> set[str]:
        return {_text(k) for k in self._file["poses/step_key"][:]}

    @staticmethod
    def _write_plan(group: h5py.Group, plan: Plan) -> None:
        n_axes = len(plan.axis_names)
        steps = plan.steps
        group.attrs["fingerprint"] = plan.fingerprint
        group.attrs["axis_names"] = list(plan.axis_names)
        group.create_dataset("step_key", data=[s.key for s in steps], dtype=TEXT)
        group.create_dataset("kind", data=[s.kind for s in steps], dtype=TEXT)
        group.create_dataset("setpoint_c", data=[s.setpoint_c for s in steps]).attrs["unit"] = "degC"
        group.create_dataset("pose_number", data=[s.pose.number if s.pose else 0 for s in steps])
        nan_angles = (np.nan,) * n_axes
        angles = [s.pose.angles_deg if s.pose else nan_angles for s in steps]
        group.create_dataset("angles_deg", data=np.array(angles).reshape(len(steps), n_axes)).attrs["unit"] = "deg"
        gravity = [s.pose.gravity_fixture if s.pose else (np.nan,) * 3 for s in steps]
        group.create_dataset("gravity_fixture", data=np.array(gravity)).attrs["unit"] = "g"

    @staticmethod
    def _create_poses(group: h5py.Group, n_axes: int) -> None:
        _growable(group, "step_key", (), growing_text("step_key"))
        _growable(group, "setpoint_c", (), "f8", "degC")
        _growable(group, "pose_number", (), "i4")
        _growable(group, "commanded_angles_deg", (n_axes,), "f8", "deg")
        _growable(group, "measured_angles_deg", (n_axes,), "f8", "deg")
        _growable(group, "gravity_fixture", (3,), "f8", "g")
        _growable(group, "t_start_s", (), "f8", "s")
        _growable(group, "t_end_s", (), "f8", "s")
        _growable(group, "chamber_temperature_c", (2,), "f8", "degC")

    @staticmethod
    def _create_dut(group: h5py.Group, dut: dict[str, Any], samples_per_pose: int) -> None:
        group.attrs.update(dut)
        _growable(group, "raw_codes", (samples_per_pose, 3), "i4", "LSB", chunk_rows=1)
        _growable(group, "mean_g", (3,), "f8", "g")
        _growable(group, "stderr_g", (3,), "f8", "g")
        _growable(group, "temperature_c", (2,), "f8", "degC")
        _growable(group, "gravity_reference_g", (3,), "f8", "g")
        _growable(group, "temperature_in_band", (), "?")

    def write_truth_header(self, serial: str, description: dict[str, Any]) -> None:
        """Open `simulation_truth/<serial>`: the hidden model of a simulated DUT, never a measurement."""
        with signals_deferred():
            self._write_truth_header(serial, description)

    def _write_truth_header(self, serial: str, description: dict[str, Any]) -> None:
        root = self._file.require_group("simulation_truth")
        root.attrs["note"] = "SIMULATION TRUTH: hidden parameters of simulated DUTs, not measured data"
        group = root.create_group(serial)
        group.create_dataset("polynomial_coefficients", data=description.pop("polynomial_coefficients"))
        group.attrs.update(description)
        _growable(group, "parameters", (12,), "f8")
        _growable(group, "gravity_g", (3,), "f8", "g")
        _growable(group, "temperature_c", (), "f8", "degC")

    def append_pose(self, pose: PoseRecord) -> None:
        """Store one pose for every DUT, then flush: after this returns, the pose is on disk.

        All or nothing: signals wait until the pose is written, and a write that fails midway is rolled
        back, so every pose-aligned dataset always has the same number of rows.
        """
        rows = {f"poses/{name}": getattr(pose, name) for name in _POSE_FIELDS}
        for dut in pose.duts:
            rows.update({f"duts/{dut.serial}/{name}": getattr(dut, name) for name in _DUT_FIELDS})
            if dut.truth is not None:
                rows.update({f"simulation_truth/{dut.serial}/{name}": dut.truth[name] for name in _TRUTH_FIELDS})
        with signals_deferred():
            before = self._dataset("poses/step_key").shape[0]
            try:
                for path, row in rows.items():
                    _append_rows(self._dataset(path), [row])
                self._file.attrs["poses_done"] = before + 1
                self.flush()
            except BaseException:
                for path in rows:
                    self._dataset(path).resize(before, axis=0)
                raise

    def flush(self) -> None:
        """Write buffered events (all columns or none) and push everything to disk."""
        with signals_deferred():
            if self._pending_events:
                columns = dict(zip(_EVENT_FIELDS, zip(*self._pending_events)))
                before = self._dataset("events/t_s").shape[0]
                try:
                    for name, column in columns.items():
                        _append_rows(self._dataset(f"events/{name}"), list(column))
                except BaseException:
                    for name in columns:
                        self._dataset(f"events/{name}").resize(before, axis=0)
                    raise
                self._pending_events.clear()
            self._file.flush()

    def write_soak(self, soak: SoakTrace) -> None:
        with signals_deferred():
            self._write_soak(soak)

    def _write_soak(self, soak: SoakTrace) -> None:
        soaks = self._file["soaks"]
        name, again = soak.label, 1
        while name in soaks:  # soaked again after a resume: T-40#2, T-40#3, …
            again += 1
            name = f"{soak.label}#{again}"
        group = soaks.create_group(name)
        group.attrs.update({"setpoint_c": soak.setpoint_c, "outcome": soak.outcome,
                            "t_reached_s": soak.t_reached_s, "t_stable_s": soak.t_stable_s})
        group.create_dataset("t_s", data=soak.t_s).attrs["unit"] = "s"
        group.create_dataset("chamber_c", data=soak.chamber_c).attrs["unit"] = "degC"
        group.create_dataset("dut_c", data=soak.dut_c).attrs["unit"] = "degC"
        group.create_dataset("settled_dut_c", data=soak.settled_dut_c).attrs["unit"] = "degC"
        self.flush()

    def log_event(self, event: Event) -> None:
        """Buffer an event; it reaches the file with the next pose, soak or state change."""
        self._pending_events.append((event.t_s, utc_now(), event.level, event.kind, event.message))

    def set_state(self, state: str, *, reason: str = "", finished: bool = False) -> None:
        with signals_deferred():
            self._file.attrs["state"] = state
            if state == "running":  # a resumed run starts afresh: the last run's ending no longer applies
                self._file.attrs.update({"abort_reason": "", "finished": ""})
            if reason:
                self._file.attrs["abort_reason"] = reason
            if finished:
                self._file.attrs["finished"] = utc_now()
            self.flush()

    def close(self) -> None:
        if self._file.id.valid:
            self.flush()
            self._file.close()


def _text(value: Any) -> str:
    return value.decode() if isinstance(value, bytes) else str(value)


def _writer_attrs() -> dict[str, Any]:
    """Who writes the file now, so `rig status` can tell a running campaign from one whose process died."""
    return {"writer_pid": os.getpid(), "writer_host": socket.gethostname()}
