"""The campaign file (layout: docs/hdf5-layout.md): a `Campaign` written as HDF5, and read back.

The file is built whole in memory and handed back as bytes; the writer puts them on disk with an atomic
replace, so the HDF5 library never writes to disk and a reader never meets a file half-written. Every
dataset carries HDF5's Fletcher-32 checksum, so a flipped bit is an error on reading, not a wrong number.

Reading checks every dataset's presence, type and shape before it reads a byte of it, and reads formats 1
(written in place by accelcal-rig before the journal) and 2 (one acceleration channel, its datasets beside
the DUT's own) as well as format 3 (a group per channel).
"""

from __future__ import annotations

import itertools
from collections.abc import Callable
from typing import Any

import h5py
import numpy as np

from accelcal_rig.config.yaml_lines import parse_yaml_text
from accelcal_rig.errors import ConfigError
from accelcal_rig.store.content import CHANNEL_FIELDS, POSE_FIELDS, Campaign, measurements_sha256
from accelcal_rig.store.records import (
    CampaignHeader,
    ChannelInfo,
    ChannelPoseRecord,
    DutPoseRecord,
    PoseRecord,
    RunStart,
    SoakTrace,
    StoredEvent,
    StoredPlan,
    plain_value,
)

FORMAT_NAME = "accelcal-rig campaign"
FORMAT_VERSION = 3
READABLE_VERSIONS = (1, 2, 3)
TEXT = h5py.string_dtype("utf-8")
#: Text columns are fixed-length UTF-8 (bytes per row; h5py returns bytes, `.decode()` them), longer text
#: cut at a character boundary.
#: A DUT's truth per pose in `simulation_truth/<serial>/` (the rest there describes its model).
_TRUTH_COLUMNS = ("parameters", "gravity_g", "temperature_c", "gyro_wander_dps")
TEXT_BYTES = {"step_key": 64, "wall_time": 32, "level": 8, "kind": 16, "message": 1024}
_UNITS = {"setpoint_c": "degC", "commanded_angles_deg": "deg", "measured_angles_deg": "deg", "gravity_fixture": "g",
          "t_start_s": "s", "t_end_s": "s", "chamber_temperature_c": "degC", "raw_codes": "LSB", "mean_g": "g",
          "stderr_g": "g", "temperature_c": "degC", "gravity_reference_g": "g", "angles_deg": "deg", "t_s": "s",
          "chamber_c": "degC", "dut_c": "degC", "settled_dut_c": "degC", "gravity_g": "g"}
#: Names of the in-memory files images are built in (HDF5 wants one; nothing is written under it).
_image_names = itertools.count()
#: What a dataset may claim beyond twice the bytes stored for it (small datasets, headers).
_SLACK_BYTES = 1 << 20
#: Most runs (1 + resumes) a file may claim before it is taken for damaged.
_MAX_RUNS = 10_000
#: Largest plan and sample count a file may claim before it is taken for damaged.
_MAX_ROWS = 10_000_000


class DamagedFile(ValueError):
    """The HDF5 file is not a readable campaign file; the message says what is wrong."""


# ---------------------------------------------------------------------- writing
def _fixed_text(name: str, rows: list[str]) -> np.ndarray:
    width = TEXT_BYTES[name]
    return np.array([r.encode()[:width].decode(errors="ignore").encode() for r in rows], dtype=f"S{width}")


def _dataset(group: h5py.Group, name: str, data: Any, unit: str | None = None) -> None:
    data = np.asarray(data)
    options: dict[str, Any] = {"fletcher32": True, "chunks": True} if data.ndim and data.size else {}
    if data.dtype.kind == "S":
        data = data.astype(h5py.string_dtype("utf-8", length=data.dtype.itemsize))
    dataset = group.create_dataset(name, data=data, **options)
    unit = unit or _UNITS.get(name)
    if unit:
        dataset.attrs["unit"] = unit


def root_attrs(campaign: Campaign, journal_bytes: int) -> dict[str, Any]:
    last_run = campaign.runs[-1] if campaign.runs else RunStart(1, 0, "", campaign.header.created)
    return {"format": FORMAT_NAME, "format_version": FORMAT_VERSION, "software_version": campaign.header.software_version,
            "campaign_id": campaign.header.campaign_id, "state": campaign.state, "started": campaign.header.created,
            "finished": campaign.finished, "abort_reason": campaign.abort_reason, "runs": campaign.run_count,
            "writer_pid": last_run.pid, "writer_host": last_run.host, "poses_done": len(campaign.poses),
            "journal_bytes": journal_bytes, "measurements_sha256": measurements_sha256(campaign), **campaign.attrs}


def campaign_image(campaign: Campaign, journal_bytes: int) -> bytes:
    """The whole campaign file as bytes. `journal_bytes`: how much of the journal it holds. DamagedFile
    when what the campaign holds cannot be written as HDF5 (a journal whose records checksum but hold
    values of the wrong kind: crafted, or from another program)."""
    try:
        return _image(campaign, journal_bytes)
    except (ValueError, TypeError, OverflowError, KeyError) as exc:
        raise DamagedFile(f"cannot be written as a campaign file: {str(exc).splitlines()[0] if str(exc) else exc}") \
            from None


def _image(campaign: Campaign, journal_bytes: int) -> bytes:
    with h5py.File(f"campaign-image-{next(_image_names)}", "w", driver="core", backing_store=False) as file:
        file.attrs.update(root_attrs(campaign, journal_bytes))
        header = campaign.header
        config = file.create_group("config")
        config.create_dataset("procedure_yaml", data=header.procedure_yaml, dtype=TEXT)
        config.create_dataset("rig_yaml", data=header.rig_yaml, dtype=TEXT)
        _write_plan(file.create_group("plan"), header.plan)
        poses = file.create_group("poses")
        poses.attrs["turntable_accuracy_arcsec"] = header.turntable_accuracy_arcsec
        for name in POSE_FIELDS:
            column = campaign.pose_column(name)
            _dataset(poses, name, _fixed_text("step_key", list(column)) if name == "step_key" else column)
        duts = file.create_group("duts", track_order=True)
        for dut in header.duts:
            serial = dut["serial"]
            group = duts.create_group(serial, track_order=True)
            group.attrs.update(dut)
            for name in ("temperature_c", "temperature_in_band"):
                _dataset(group, name, campaign.dut_column(serial, name))
            for channel in header.dut_channels(serial):
                channel_group = group.create_group(channel.name)
                channel_group.attrs.update(channel.attrs())
                for name in CHANNEL_FIELDS:
                    _dataset(channel_group, name, campaign.channel_column(serial, channel.name, name),
                             "LSB" if name == "raw_codes" else channel.unit)
                ranges = campaign.channel_ranges(serial, channel.name)
                if np.any(ranges != channel.range):  # some records at a finer range: each record's range
                    _dataset(channel_group, "range", ranges, channel.unit)
        instruments = file.create_group("instruments")
        for name, info in campaign.instruments.items():
            instruments.create_group(name).attrs.update(info)
        references = file.create_group("references")
        for name, info in header.references.items():
            references.create_group(name).attrs.update(info)
        soaks = file.create_group("soaks")
        for name, soak in zip(campaign.soak_names(), campaign.soaks):
            group = soaks.create_group(name)
            group.attrs.update({"setpoint_c": soak.setpoint_c, "outcome": soak.outcome, "t_reached_s": soak.t_reached_s,
                                "t_stable_s": soak.t_stable_s})
            for field in ("t_s", "chamber_c", "dut_c", "settled_dut_c", "ramp_t_s", "ramp_chamber_c"):
                _dataset(group, field, getattr(soak, field))
        events = file.create_group("events")
        _dataset(events, "t_s", np.array([e.t_s for e in campaign.events], dtype="f8"))
        for name in ("wall_time", "level", "kind", "message"):
            _dataset(events, name, _fixed_text(name, [getattr(e, name) for e in campaign.events]))
        if header.truth:
            truth = file.create_group("simulation_truth")
            truth.attrs["note"] = "SIMULATION TRUTH: hidden parameters of simulated DUTs, not measured data"
            for serial, description in header.truth.items():
                group = truth.create_group(serial)
                for name, value in description.items():  # the coefficients, and any other array of the truth
                    if isinstance(value, np.ndarray):
                        _dataset(group, name, value)
                group.attrs.update({k: v for k, v in description.items() if not isinstance(v, np.ndarray)})
                for name in ("parameters", "gravity_g", "temperature_c"):
                    _dataset(group, name, campaign.truth_column(serial, name))
                wander = campaign.truth_column(serial, "gyro_wander_dps")  # a gyroscope's, where it has one
                if wander is not None and np.isfinite(wander).any():
                    _dataset(group, "gyro_wander_dps", wander)
        file.flush()
        return bytes(file.id.get_file_image())


def _write_plan(group: h5py.Group, plan: StoredPlan) -> None:
    group.attrs["fingerprint"] = plan.fingerprint
    group.attrs["axis_names"] = list(plan.axis_names)
    _dataset(group, "step_key", _fixed_text("step_key", list(plan.step_key)))
    _dataset(group, "kind", _fixed_text("kind", list(plan.kind)))
    _dataset(group, "setpoint_c", plan.setpoint_c)
    _dataset(group, "pose_number", plan.pose_number)
    _dataset(group, "angles_deg", plan.angles_deg)
    _dataset(group, "gravity_fixture", plan.gravity_fixture)


# ---------------------------------------------------------------------- reading
def _text(value: Any) -> str:
    return value.decode(errors="replace") if isinstance(value, bytes) else str(value)


class _Reader:
    """Reads datasets only after checking they are what the layout says."""

    def __init__(self, file: h5py.File) -> None:
        self.file = file

    def node(self, path: str, kind: type) -> Any:
        node = self.file.get(path)
        if not isinstance(node, kind):
            raise DamagedFile(f"{path}: missing or not a {'group' if kind is h5py.Group else 'dataset'}")
        return node

    def _stored(self, path: str, dataset: h5py.Dataset) -> None:
        """Refuse a dataset that claims far more data than the file holds for it (unwritten chunks, or
        a damaged shape): reading it would conjure gigabytes of fill values."""
        claimed = int(np.prod(dataset.shape, dtype=np.float64) * dataset.dtype.itemsize) if dataset.shape else 0
        held = dataset.id.get_storage_size()
        if claimed > 2 * held + _SLACK_BYTES:
            raise DamagedFile(f"{path}: claims {claimed} bytes, the file holds {held} for it")

    def array(self, path: str, tail: tuple[int, ...], kinds: str, rows: int | None = None) -> np.ndarray:
        dataset = self.node(path, h5py.Dataset)
        shape, dtype = dataset.shape, dataset.dtype
        if shape is None or len(shape) != 1 + len(tail) or tuple(shape[1:]) != tail or dtype.kind not in kinds:
            raise DamagedFile(f"{path}: shape {shape} of {dtype}, expected (rows, {', '.join(map(str, tail))}) of "
                              f"kind {kinds}")
        if shape[0] > _MAX_ROWS or (rows is not None and shape[0] < rows):
            raise DamagedFile(f"{path}: {shape[0]} rows{f' for {rows} poses' if rows is not None else ''}")
        self._stored(path, dataset)
        return dataset[: shape[0] if rows is None else rows]

    def matrix(self, path: str) -> np.ndarray:
        dataset = self.node(path, h5py.Dataset)
        if dataset.ndim != 2 or dataset.dtype.kind != "f" or dataset.size > _MAX_ROWS:
            raise DamagedFile(f"{path}: shape {dataset.shape} of {dataset.dtype}, expected a matrix of numbers")
        self._stored(path, dataset)
        return dataset[()]

    def text(self, path: str) -> str:
        dataset = self.node(path, h5py.Dataset)
        if dataset.shape != () or dataset.dtype.kind not in "OS":
            raise DamagedFile(f"{path}: not a text")
        return _text(dataset[()])

    def attr(self, node: Any, name: str, convert: Callable[[Any], Any]) -> Any:
        try:
            return convert(node.attrs[name])
        except (KeyError, TypeError, ValueError, OSError) as exc:
            raise DamagedFile(f"{node.name}: attribute {name} missing or unreadable ({exc})") from None


def read_campaign_file(file: h5py.File) -> Campaign:
    """The campaign in an open HDF5 campaign file; DamagedFile naming what is wrong. Pose-aligned
    datasets of different lengths (format 1, a process killed mid-pose) are read to the poses stored
    whole; a dataset short of more than that pose is damage the file cannot repair by itself."""
    if _text(file.attrs.get("format", "")) != FORMAT_NAME:
        raise DamagedFile("not an accelcal-rig campaign file")
    version = int(file.attrs.get("format_version", 0))
    if version not in READABLE_VERSIONS:
        raise DamagedFile(f"campaign file format version {version}: this accelcal-rig reads versions "
                          f"{', '.join(map(str, READABLE_VERSIONS))}")
    reader = _Reader(file)
    header = _read_header(reader)
    n_axes, n = len(header.plan.axis_names), int(header.attrs["samples_per_pose"])
    tails = {"step_key": ((), "SO"), "setpoint_c": ((), "f"), "pose_number": ((), "iu"),
             "commanded_angles_deg": ((n_axes,), "f"), "measured_angles_deg": ((n_axes,), "f"),
             "gravity_fixture": ((3,), "f"), "t_start_s": ((), "f"), "t_end_s": ((), "f"),
             "chamber_temperature_c": ((2,), "f")}
    truth_tails = {"parameters": ((12,), "f"), "gravity_g": ((3,), "f"), "temperature_c": ((), "f")}
    optional_truth = {"gyro_wander_dps": ((3,), "f")}  # a gyroscope's; files before issue 39 have none
    tails_of = {s: {**truth_tails, **{name: tail for name, tail in optional_truth.items()
                                      if f"simulation_truth/{s}/{name}" in file}} for s in header.truth}
    dut_columns = {s: _dut_columns(header, s, version, n) for s in header.serials}
    for serial in header.serials:  # a channel some of whose records are at a range of their own
        for info in header.dut_channels(serial) if version >= 3 else ():
            path = f"duts/{serial}/{info.name}/range"
            if path in file:
                dut_columns[serial][(info.name, "range")] = (path, (), "f")
    lengths = {f"poses/{name}": reader.node(f"poses/{name}", h5py.Dataset).shape for name in tails}
    for serial in header.serials:
        lengths.update({path: reader.node(path, h5py.Dataset).shape for path, _, _ in dut_columns[serial].values()})
        if serial in header.truth:
            lengths.update({f"simulation_truth/{serial}/{name}": reader.node(f"simulation_truth/{serial}/{name}",
                                                                             h5py.Dataset).shape
                            for name in tails_of[serial]})
    rows = {path: (shape[0] if shape else 0) for path, shape in lengths.items()}
    whole, longest = min(rows.values()), max(rows.values())
    campaign = Campaign(header)
    if longest - whole > 1:
        short = [f"{path} has {count} rows" for path, count in rows.items() if count < longest - 1]
        campaign.damage.append(f"{'; '.join(short[:3])} for {longest} poses")
    elif longest > whole:
        campaign.notes.append(f"a pose written in part by a run that died (rows beyond pose {whole}) is not used")
    columns = {name: reader.array(f"poses/{name}", tail, kinds, whole) for name, (tail, kinds) in tails.items()}
    duts = {s: {key: reader.array(path, tail, kinds, whole) for key, (path, tail, kinds) in dut_columns[s].items()}
            for s in header.serials}
    truth = {s: {name: reader.array(f"simulation_truth/{s}/{name}", tail, kinds, whole)
                 for name, (tail, kinds) in tails_of[s].items()} for s in header.serials if s in header.truth}
    keys = [_text(k) for k in columns["step_key"]]
    for i, key in enumerate(keys):
        pose_duts = [DutPoseRecord(
            serial=s,
            channels={c.name: ChannelPoseRecord(**{name: duts[s][(c.name, name)][i] for name in CHANNEL_FIELDS},
                                                range=_record_range(duts[s].get((c.name, "range")), i, c.range,
                                                                    f"duts/{s}/{c.name}/range"))
                      for c in header.dut_channels(s)},
            temperature_c=(float(duts[s][("", "temperature_c")][i, 0]), float(duts[s][("", "temperature_c")][i, 1])),
            temperature_in_band=bool(duts[s][("", "temperature_in_band")][i]),
            truth={name: truth[s][name][i] for name in tails_of[s] if np.all(np.isfinite(truth[s][name][i]))
                   or name in truth_tails} if s in truth else None) for s in header.serials]
        campaign.add_pose(PoseRecord(
            key, float(columns["setpoint_c"][i]), int(columns["pose_number"][i]), columns["commanded_angles_deg"][i],
            columns["measured_angles_deg"][i], columns["gravity_fixture"][i], float(columns["t_start_s"][i]),
            float(columns["t_end_s"][i]),
            (float(columns["chamber_temperature_c"][i, 0]), float(columns["chamber_temperature_c"][i, 1])), pose_duts),
            f"row {i + 1} of poses/")
    campaign.soaks = _read_soaks(reader, len(header.serials), campaign.notes)
    try:
        campaign.events = _read_events(reader)
    except (DamagedFile, OSError, ValueError) as exc:  # the log, not a measurement: say so and go on
        campaign.notes.append(f"events unreadable ({exc}): not shown")
    for name, group in reader.node("instruments", h5py.Group).items() if "instruments" in file else ():
        campaign.instruments[name] = {k: _text(v) for k, v in group.attrs.items()}
    attrs = file.attrs
    campaign.state = reader.attr(file, "state", _text)
    campaign.abort_reason = _text(attrs.get("abort_reason", ""))
    campaign.finished = _text(attrs.get("finished", ""))
    runs = int(attrs.get("runs", 1))
    if not 1 <= runs <= _MAX_RUNS:
        raise DamagedFile(f"attribute runs is {runs}")
    recorded = _text(attrs.get("measurements_sha256", ""))
    if recorded and longest == whole and recorded != measurements_sha256(campaign):
        campaign.damage.append("its measurements do not match the digest written with them (changed or damaged "
                               "since accelcal-rig wrote the file)")
    campaign.journal_bytes = int(attrs.get("journal_bytes", 0))
    campaign.runs = [RunStart(k, 0, "", "") for k in range(1, runs)] + [
        RunStart(runs, int(attrs.get("writer_pid", 0)), _text(attrs.get("writer_host", "")), "")]
    return campaign


def _record_range(ranges: np.ndarray | None, row: int, channel_range: float, path: str) -> float | None:
    """A record's range as the pose record holds it: None where it is the channel's own; one that is no ± full
    scale (not positive, not finite) is damage."""
    if ranges is None or float(ranges[row]) == channel_range:
        return None
    if not 0.0 < float(ranges[row]) < np.inf:
        raise DamagedFile(f"{path} row {row + 1}: {float(ranges[row])}, not a ± full scale")
    return float(ranges[row])


#: Where formats 1 and 2 kept the acceleration channel's fields: beside the DUT's own.
_ACCELERATION_DATASETS = {"raw_codes": "raw_codes", "mean": "mean_g", "stderr": "stderr_g",
                          "reference": "gravity_reference_g"}


def _dut_columns(header: CampaignHeader, serial: str, version: int,
                 n: int) -> dict[tuple[str, str], tuple[str, tuple[int, ...], str]]:
    """A DUT's pose-aligned datasets: (channel, field) → (path, shape after the pose, kinds); the DUT's own
    fields under channel ""."""
    base = f"duts/{serial}"
    found: dict[tuple[str, str], tuple[str, tuple[int, ...], str]] = {
        ("", "temperature_c"): (f"{base}/temperature_c", (2,), "f"),
        ("", "temperature_in_band"): (f"{base}/temperature_in_band", (), "b")}
    for info in header.dut_channels(serial):
        axes = len(info.axes)
        for name in CHANNEL_FIELDS:
            path = f"{base}/{info.name}/{name}" if version >= 3 else f"{base}/{_ACCELERATION_DATASETS[name]}"
            found[(info.name, name)] = (path, (n, axes) if name == "raw_codes" else (axes,),
                                        "i" if name == "raw_codes" else "f")
    return found


_HEADER_ATTRS = ("procedure_name", "procedure_version", "procedure_path", "rig_name", "rig_path", "dry_run", "seed",
                 "clock", "lab_name", "lab_address", "place_of_calibration",
                 "samples_per_pose", "fit_mode", "polynomial_degree", "fit_parameters", "fit_out_of_range",
                 "fit_temperature_model")


def _read_header(reader: _Reader) -> CampaignHeader:
    file = reader.file
    plan_group = reader.node("plan", h5py.Group)
    step_key = [_text(k) for k in reader.array("plan/step_key", (), "OS")]
    steps = len(step_key)
    axis_names = tuple(_text(a) for a in reader.attr(plan_group, "axis_names", list))
    plan = StoredPlan(
        tuple(step_key), tuple(_text(k) for k in reader.array("plan/kind", (), "OS", steps)),
        reader.array("plan/setpoint_c", (), "f", steps), reader.array("plan/pose_number", (), "iu", steps),
        reader.array("plan/angles_deg", (len(axis_names),), "f", steps), reader.array("plan/gravity_fixture", (3,), "f", steps),
        reader.attr(plan_group, "fingerprint", _text), axis_names)
    attrs = {name: plain_value(file.attrs[name]) for name in _HEADER_ATTRS if name in file.attrs}
    samples = attrs.get("samples_per_pose")
    if not isinstance(samples, int) or not 0 < samples <= _MAX_ROWS:
        raise DamagedFile(f"attribute samples_per_pose is {samples!r}")
    rig_yaml = reader.text("config/rig_yaml")
    duts = []
    groups = reader.node("duts", h5py.Group)
    channels: dict[str, tuple[ChannelInfo, ...]] = {}
    for serial in _campaign_order(rig_yaml, list(groups)):
        group = groups[serial]
        if not isinstance(group, h5py.Group):
            raise DamagedFile(f"duts/{serial}: not a group")
        duts.append({"serial": serial, **{k: plain_value(v) for k, v in group.attrs.items() if k != "serial"}})
        if int(file.attrs.get("format_version", 0)) >= 3:  # each channel's range and code size with the channel
            channels[serial] = _read_channels(group)
        for name in ("odr_hz",) if serial in channels else ("range_g", "lsb_g", "odr_hz"):
            reader.attr(group, name, float)
    truth = {}
    if "simulation_truth" in file:
        for serial, group in reader.node("simulation_truth", h5py.Group).items():
            if serial in {d["serial"] for d in duts} and isinstance(group, h5py.Group):
                truth[serial] = {**{k: plain_value(v) for k, v in group.attrs.items()},
                                 "polynomial_coefficients": reader.matrix(f"simulation_truth/{serial}/polynomial_coefficients"),
                                 **{name: np.asarray(node[()], dtype=float) for name, node in group.items()
                                    if name not in _TRUTH_COLUMNS and name != "polynomial_coefficients"
                                    and isinstance(node, h5py.Dataset) and node.dtype.kind == "f" and node.size <= 4096}}
    references = {name: {k: _text(v) for k, v in group.attrs.items()}
                  for name, group in (reader.node("references", h5py.Group).items() if "references" in file else ())
                  if isinstance(group, h5py.Group)}  # absent before campaigns recorded them
    poses_group = reader.node("poses", h5py.Group)
    return CampaignHeader(
        campaign_id=_text(file.attrs.get("campaign_id", "")), created=_text(file.attrs.get("started", "")),
        software_version=_text(file.attrs.get("software_version", "")), attrs=attrs,
        procedure_yaml=reader.text("config/procedure_yaml"), rig_yaml=rig_yaml, plan=plan,
        duts=duts, instruments={}, turntable_accuracy_arcsec=float(poses_group.attrs.get("turntable_accuracy_arcsec", 0.0)),
        truth=truth, channels=channels, references=references)


def _read_channels(group: h5py.Group) -> tuple[ChannelInfo, ...]:
    """A format-3 DUT's channels: its subgroups, in the order they were written."""
    found = []
    for name, channel in group.items():
        if not isinstance(channel, h5py.Group):
            continue
        try:
            attrs = {k: channel.attrs[k] for k in ("quantity", "unit", "range", "lsb")}
            attrs["axes"] = [_text(a) for a in channel.attrs["axes"]]
            found.append(ChannelInfo.from_attrs(name, {k: _text(v) if isinstance(v, bytes) else v
                                                       for k, v in attrs.items()}))
        except (KeyError, TypeError, ValueError, OSError) as exc:
            raise DamagedFile(f"{channel.name}: channel attributes missing or unreadable ({exc})") from None
    if not found:
        raise DamagedFile(f"{group.name}: no channel groups")
    return tuple(found)


def _campaign_order(rig_yaml: str, serials: list[str]) -> list[str]:
    """The DUTs in the campaign's order: the rig config's fixture order, in which every run measured them
    and the soak traces' columns are (the file's groups may list them in another)."""
    try:
        sensors = parse_yaml_text(rig_yaml, "the stored rig config")["fixture"]["sensors"]
        order = [str(sensor["serial"]) for sensor in sensors]
    except (ConfigError, KeyError, TypeError, IndexError):
        return sorted(serials)
    return order if sorted(order) == sorted(serials) else sorted(serials)


def _read_soaks(reader: _Reader, n_duts: int, notes: list[str]) -> list[SoakTrace]:
    """Every readable soak trace (traces, not measurements: one that is damaged is noted and left out)."""
    soaks = []
    for name in list(reader.node("soaks", h5py.Group)):
        try:
            group = reader.node(f"soaks/{name}", h5py.Group)
            t_s = reader.array(f"soaks/{name}/t_s", (), "f")
            m = len(t_s)
            dut_c = reader.array(f"soaks/{name}/dut_c", (n_duts,), "f", m) if m else np.zeros((0, n_duts))
            ramp_t_s, ramp_c = np.zeros(0), np.zeros(0)
            if "ramp_t_s" in group:  # files from before ramps were kept have none
                ramp_t_s = reader.array(f"soaks/{name}/ramp_t_s", (), "f")
                ramp_c = reader.array(f"soaks/{name}/ramp_chamber_c", (), "f", len(ramp_t_s))
            soaks.append(SoakTrace(
                name.split("#")[0], reader.attr(group, "setpoint_c", float), reader.attr(group, "outcome", _text), t_s,
                reader.array(f"soaks/{name}/chamber_c", (), "f", m), dut_c, reader.attr(group, "t_reached_s", float),
                reader.attr(group, "t_stable_s", float), reader.array(f"soaks/{name}/settled_dut_c", (), "f"),
                ramp_t_s=ramp_t_s, ramp_chamber_c=ramp_c))
        except (DamagedFile, OSError, ValueError, KeyError) as exc:
            notes.append(f"soaks/{name} unreadable ({exc}): left out")
    soaks.sort(key=lambda s: s.t_reached_s)
    return soaks


def _read_events(reader: _Reader) -> list[StoredEvent]:
    t_s = reader.array("events/t_s", (), "f")
    rows = min([len(t_s)] + [reader.node(f"events/{n}", h5py.Dataset).shape[0] for n in ("wall_time", "level", "kind", "message")])
    columns = [reader.array(f"events/{n}", (), "SO", rows) for n in ("wall_time", "level", "kind", "message")]
    return [StoredEvent(float(t), *(_text(c[i]) for c in columns)) for i, t in enumerate(t_s[:rows])]
