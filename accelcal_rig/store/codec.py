"""The campaign's records as journal records, and a journal's records replayed into a `Campaign`.

Kinds: `header` (first, once), `run` (each run's start), `instruments` (the drivers a run reached),
`events`, `pose`, `soak`, `state`. Numbers travel as arrays, so they come back bit for bit. A pose holds
each channel's arrays under the channel's name (`accel/raw_codes`, …); a pose written before parts
declared channels holds the acceleration's under its old names (`raw_codes`, `mean_g`, …), read the same.
"""

from __future__ import annotations

import numpy as np

from accelcal_rig.store.content import Campaign
from accelcal_rig.store.journal import Record, Scan, encode_record
from accelcal_rig.store.records import (
    CampaignHeader,
    ChannelInfo,
    ChannelPoseRecord,
    DutPoseRecord,
    PoseRecord,
    RunStart,
    SoakTrace,
    StateChange,
    StoredEvent,
    StoredPlan,
    plain_value,
)


class NotACampaignJournal(ValueError):
    """The journal has no readable header record."""


#: What a record that checksums but holds the wrong things (crafted, or from another program) raises
#: when it is taken apart: the record is noted as unusable and left out.
_UNUSABLE = (KeyError, ValueError, TypeError, IndexError, AttributeError, OverflowError, RecursionError)


# ---------------------------------------------------------------------- encoding
def encode_header(header: CampaignHeader) -> bytes:
    plan = header.plan
    truth_attrs = {s: {k: plain_value(v) for k, v in d.items() if not isinstance(v, np.ndarray)}
                   for s, d in header.truth.items()}
    arrays = {"plan_setpoint_c": plan.setpoint_c, "plan_pose_number": plan.pose_number,
              "plan_angles_deg": plan.angles_deg, "plan_gravity_fixture": plan.gravity_fixture}
    arrays.update({f"truth_coefficients/{s}": np.asarray(d["polynomial_coefficients"], dtype="f8")
                   for s, d in header.truth.items()})
    # Any other array of a DUT's truth (a gyroscope's coefficients, the Earth's rate) under its own name.
    arrays.update({f"truth_array/{s}/{k}": np.asarray(v, dtype="f8") for s, d in header.truth.items()
                   for k, v in d.items() if isinstance(v, np.ndarray) and k != "polynomial_coefficients"})
    meta = {"campaign_id": header.campaign_id, "created": header.created, "software_version": header.software_version,
            "attrs": plain_value(header.attrs), "procedure_yaml": header.procedure_yaml, "rig_yaml": header.rig_yaml,
            "plan": {"step_key": list(plan.step_key), "kind": list(plan.kind), "fingerprint": plan.fingerprint,
                     "axis_names": list(plan.axis_names)},
            "duts": plain_value(header.duts), "instruments": header.instruments,
            "turntable_accuracy_arcsec": float(header.turntable_accuracy_arcsec), "truth": truth_attrs,
            "channels": {serial: {c.name: c.attrs() for c in channels} for serial, channels in header.channels.items()},
            "references": header.references}
    return encode_record("header", meta, arrays)


def encode_run(run: RunStart) -> bytes:
    return encode_record("run", {"run": run.run, "pid": run.pid, "host": run.host, "started": run.started})


def encode_instruments(instruments: dict[str, dict[str, str]]) -> bytes:
    return encode_record("instruments", {"instruments": instruments})


def encode_state(change: StateChange) -> bytes:
    return encode_record("state", {"state": change.state, "reason": change.reason, "wall_time": change.wall_time})


def encode_events(events: list[StoredEvent]) -> bytes:
    rows = [[e.wall_time, e.level, e.kind, e.message] for e in events]
    return encode_record("events", {"rows": rows}, {"t_s": np.array([e.t_s for e in events], dtype="f8")})


def encode_pose(pose: PoseRecord) -> bytes:
    """Each channel's arrays stacked over the DUTs that have it (`accel/raw_codes`, …, meta `channels`: which
    DUTs, in order); the DUTs' own temperatures stacked over all of them."""
    duts = pose.duts
    arrays: dict[str, np.ndarray] = {
        "commanded_angles_deg": np.asarray(pose.commanded_angles_deg, dtype="f8"),
        "measured_angles_deg": np.asarray(pose.measured_angles_deg, dtype="f8"),
        "gravity_fixture": np.asarray(pose.gravity_fixture, dtype="f8"),
        "scalars": np.array([pose.setpoint_c, pose.t_start_s, pose.t_end_s, *pose.chamber_temperature_c], dtype="f8"),
        "temperature_c": np.array([d.temperature_c for d in duts], dtype="f8"),
        "temperature_in_band": np.array([d.temperature_in_band for d in duts], dtype="?"),
    }
    having: dict[str, list[str]] = {}
    for dut in duts:
        for name in dut.channels:
            having.setdefault(name, []).append(dut.serial)
    by_serial = {d.serial: d for d in duts}
    for name, serials in having.items():
        channels = [by_serial[serial].channels[name] for serial in serials]
        arrays[f"{name}/raw_codes"] = np.stack([np.asarray(c.raw_codes, dtype="i4") for c in channels])
        for field in ("mean", "stderr", "reference"):
            arrays[f"{name}/{field}"] = np.stack([np.asarray(getattr(c, field), dtype="f8") for c in channels])
        if any(c.range is not None for c in channels):  # a step at a range other than the campaign's (NaN: its own)
            arrays[f"{name}/range"] = np.array([np.nan if c.range is None else c.range for c in channels], dtype="f8")
    if all(d.truth is not None for d in duts) and duts:
        arrays["truth_parameters"] = np.stack([np.asarray(d.truth["parameters"], dtype="f8") for d in duts])  # type: ignore[index]
        arrays["truth_gravity_g"] = np.stack([np.asarray(d.truth["gravity_g"], dtype="f8") for d in duts])  # type: ignore[index]
        arrays["truth_temperature_c"] = np.array([float(d.truth["temperature_c"]) for d in duts], dtype="f8")  # type: ignore[index]
        if any("gyro_wander_dps" in d.truth for d in duts):  # type: ignore[operator]
            arrays["truth_gyro_wander_dps"] = np.stack([np.asarray(d.truth.get("gyro_wander_dps", np.full(3, np.nan)),  # type: ignore[union-attr]
                                                                   dtype="f8") for d in duts])
    meta = {"step_key": pose.step_key, "pose_number": int(pose.pose_number), "serials": [d.serial for d in duts],
            "channels": having}
    return encode_record("pose", meta, arrays)


def encode_soak(soak: SoakTrace, serials: list[str]) -> bytes:
    """`serials`: whose temperatures the columns of `soak.dut_c` are, in order."""
    arrays = {"t_s": np.asarray(soak.t_s, dtype="f8"), "chamber_c": np.asarray(soak.chamber_c, dtype="f8"),
              "dut_c": np.asarray(soak.dut_c, dtype="f8"), "settled_dut_c": np.asarray(soak.settled_dut_c, dtype="f8"),
              "times_s": np.array([soak.setpoint_c, soak.t_reached_s, soak.t_stable_s], dtype="f8"),
              "ramp_t_s": np.asarray(soak.ramp_t_s, dtype="f8"), "ramp_chamber_c": np.asarray(soak.ramp_chamber_c, dtype="f8")}
    return encode_record("soak", {"label": soak.label, "outcome": soak.outcome, "serials": serials}, arrays)


# ---------------------------------------------------------------------- decoding
def _header(record: Record) -> CampaignHeader:
    meta, arrays = record.meta, record.arrays
    plan_meta = meta["plan"]
    plan = StoredPlan(tuple(plan_meta["step_key"]), tuple(plan_meta["kind"]), arrays["plan_setpoint_c"],
                      arrays["plan_pose_number"], arrays["plan_angles_deg"], arrays["plan_gravity_fixture"],
                      str(plan_meta["fingerprint"]), tuple(plan_meta["axis_names"]))
    steps = len(plan.step_key)
    if not (len(plan.kind) == plan.setpoint_c.shape[0] == plan.pose_number.shape[0] == steps
            and plan.angles_deg.shape == (steps, len(plan.axis_names)) and plan.gravity_fixture.shape == (steps, 3)):
        raise ValueError("plan columns of different lengths")
    truth = {s: {**_attributes(attrs), "polynomial_coefficients": arrays[f"truth_coefficients/{s}"],
                 **{name.split("/", 2)[2]: value for name, value in arrays.items()
                    if name.startswith(f"truth_array/{s}/")}}
             for s, attrs in meta.get("truth", {}).items()}
    duts = [_attributes(d) for d in meta["duts"]]
    if not all(isinstance(d.get("serial"), str) for d in duts) or len({d["serial"] for d in duts}) != len(duts):
        raise ValueError("DUT serials missing or repeated")
    if not set(truth) <= {d["serial"] for d in duts} or not all(isinstance(n, str) for n in plan.axis_names):
        raise ValueError("truth of sensors not in the campaign, or axis names that are not text")
    channels = {str(serial): tuple(ChannelInfo.from_attrs(name, attrs) for name, attrs in by_name.items())
                for serial, by_name in meta.get("channels", {}).items()}  # absent before parts declared channels
    if not set(channels) <= {d["serial"] for d in duts} or not all(channels.values()):
        raise ValueError("channels of sensors not in the campaign, or a sensor without channels")
    stated = meta.get("references", {})  # absent before campaigns recorded them
    if not isinstance(stated, dict):
        raise ValueError("references that are not a mapping")
    references = {str(key): {str(k): str(v) for k, v in _attributes(info).items()} for key, info in stated.items()}
    return CampaignHeader(str(meta["campaign_id"]), str(meta["created"]), str(meta["software_version"]),
                          dict(meta["attrs"]), str(meta["procedure_yaml"]), str(meta["rig_yaml"]), plan, duts,
                          dict(meta["instruments"]), float(meta["turntable_accuracy_arcsec"]), truth, channels,
                          references)


def _attributes(value: object) -> dict[str, object]:
    """A dict of attributes as the campaign file can hold them: text, numbers, flags, lists of numbers."""
    if not isinstance(value, dict):
        raise ValueError("attributes that are not a mapping")
    for key, item in value.items():
        plain = isinstance(item, (str, bool, int, float)) or (
            isinstance(item, list) and all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in item))
        if not plain or (isinstance(item, int) and not -2**63 <= item < 2**63):
            raise ValueError(f"attribute {key!r} of another kind")
    return dict(value)


def _pose(record: Record, header: CampaignHeader) -> PoseRecord:
    meta, arrays = record.meta, record.arrays
    serials = [str(s) for s in meta["serials"]]  # the order they were measured in; the campaign matches by serial
    if sorted(serials) != sorted(header.serials) or len(set(serials)) != len(serials):
        raise ValueError(f"its sensors {serials} are not the campaign's {header.serials}")
    n_duts, n_axes, n = len(serials), len(header.plan.axis_names), int(header.attrs.get("samples_per_pose", 0))
    shapes = {"commanded_angles_deg": (n_axes,), "measured_angles_deg": (n_axes,), "gravity_fixture": (3,),
              "scalars": (5,), "temperature_c": (n_duts, 2), "temperature_in_band": (n_duts,)}
    if "truth_gyro_wander_dps" in arrays:
        shapes["truth_gyro_wander_dps"] = (n_duts, 3)
    for name, shape in shapes.items():
        if arrays[name].shape != shape:
            raise ValueError(f"{name} has shape {arrays[name].shape}, expected {shape}")
    channels = _pose_channels(meta, arrays, serials, header, n)
    truth = "truth_parameters" in arrays
    setpoint, t_start, t_end, before, after = arrays["scalars"].tolist()
    duts = [
        DutPoseRecord(
            serial=serial, channels=channels[serial],
            temperature_c=(float(arrays["temperature_c"][i, 0]), float(arrays["temperature_c"][i, 1])),
            temperature_in_band=bool(arrays["temperature_in_band"][i]),
            truth=_pose_truth(arrays, i) if truth else None)
        for i, serial in enumerate(serials)
    ]
    if not isinstance(meta["pose_number"], int) or not 0 <= meta["pose_number"] < 2**31:
        raise ValueError(f"pose number {meta['pose_number']!r}")
    return PoseRecord(str(meta["step_key"]), setpoint, int(meta["pose_number"]), arrays["commanded_angles_deg"],
                      arrays["measured_angles_deg"], arrays["gravity_fixture"], t_start, t_end, (before, after), duts)


#: A pose record's acceleration arrays before parts declared channels (stacked over every DUT).
_ACCELERATION_ARRAYS = {"raw_codes": "raw_codes", "mean": "mean_g", "stderr": "stderr_g", "reference": "gravity_reference_g"}


def _pose_truth(arrays: dict[str, np.ndarray], i: int) -> dict[str, np.ndarray]:
    """DUT `i`'s simulation truth of a pose record; its gyroscope's wander where the record has it (a DUT with
    none: NaN)."""
    truth = {"parameters": arrays["truth_parameters"][i], "gravity_g": arrays["truth_gravity_g"][i],
             "temperature_c": np.asarray(arrays["truth_temperature_c"][i])}
    wander = arrays.get("truth_gyro_wander_dps")
    if wander is not None and np.all(np.isfinite(wander[i])):
        truth["gyro_wander_dps"] = wander[i]
    return truth


def _pose_channels(meta: dict, arrays: dict[str, np.ndarray], serials: list[str], header: CampaignHeader,
                   n: int) -> dict[str, dict[str, ChannelPoseRecord]]:
    """Each DUT's channels at the pose, checked against the channels the header says it has."""
    if "channels" in meta:
        having = {str(name): [str(s) for s in owners] for name, owners in meta["channels"].items()}
        names = {name: {field: f"{name}/{field}" for field in _ACCELERATION_ARRAYS} for name in having}
    else:  # a record written before channels: acceleration, every DUT
        having, names = {"accel": serials}, {"accel": _ACCELERATION_ARRAYS}
    channels: dict[str, dict[str, ChannelPoseRecord]] = {serial: {} for serial in serials}
    for name, owners in having.items():
        if len(set(owners)) != len(owners) or not set(owners) <= set(serials):
            raise ValueError(f"channel {name}: sensors {owners} are not the pose's")
        for i, serial in enumerate(owners):
            known = {c.name: c for c in header.dut_channels(serial)}
            if name not in known:
                raise ValueError(f"sensor {serial} has no channel {name!r}")
            axes = len(known[name].axes)
            fields = {field: arrays[path] for field, path in names[name].items()}
            expected = {"raw_codes": (len(owners), n, axes), "mean": (len(owners), axes),
                        "stderr": (len(owners), axes), "reference": (len(owners), axes)}
            for field, shape in expected.items():
                if fields[field].shape != shape:
                    raise ValueError(f"{names[name][field]} has shape {fields[field].shape}, expected {shape}")
            ranges = arrays.get(f"{name}/range")
            if ranges is not None and ranges.shape != (len(owners),):
                raise ValueError(f"{name}/range has shape {ranges.shape}, expected {(len(owners),)}")
            range_ = None if ranges is None or np.isnan(ranges[i]) else float(ranges[i])
            if range_ is not None and not 0.0 < range_ < np.inf:
                raise ValueError(f"{name}/range of sensor {serial} is {range_}, not a ± full scale")
            channels[serial][name] = ChannelPoseRecord(fields["raw_codes"][i], fields["mean"][i],
                                                       fields["stderr"][i], fields["reference"][i], range_)
    for serial in serials:
        if set(channels[serial]) != {c.name for c in header.dut_channels(serial)}:
            raise ValueError(f"sensor {serial}: channels {sorted(channels[serial])}, the campaign says "
                             f"{[c.name for c in header.dut_channels(serial)]}")
    return channels


def _soak(record: Record, header: CampaignHeader) -> SoakTrace:
    arrays = record.arrays
    m, d = arrays["t_s"].shape[0], len(header.duts)
    if arrays["chamber_c"].shape != (m,) or arrays["dut_c"].size != m * d or arrays["times_s"].shape != (3,):
        raise ValueError("soak columns of different lengths")
    setpoint, reached, stable = arrays["times_s"].tolist()
    columns = [str(s) for s in record.meta.get("serials", header.serials)]
    if sorted(columns) != sorted(header.serials) or arrays["settled_dut_c"].shape != (d,):
        raise ValueError(f"its sensors {columns} are not the campaign's {header.serials}")
    order = [columns.index(serial) for serial in header.serials]  # the campaign's order
    ramp_t_s, ramp_c = arrays.get("ramp_t_s", np.zeros(0)), arrays.get("ramp_chamber_c", np.zeros(0))
    if ramp_t_s.ndim != 1 or ramp_c.shape != ramp_t_s.shape:
        raise ValueError("ramp columns of different lengths")
    return SoakTrace(str(record.meta["label"]), setpoint, str(record.meta["outcome"]), arrays["t_s"],
                     arrays["chamber_c"], arrays["dut_c"].reshape(m, d)[:, order], reached, stable,
                     arrays["settled_dut_c"][order], ramp_t_s=ramp_t_s, ramp_chamber_c=ramp_c)


def replay(found: Scan, source: str) -> Campaign:
    """The campaign a journal's records make; what could not be used is said in `notes`.

    `source` names the journal in those notes. NotACampaignJournal when there is no header to start from.
    """
    records = found.records
    first = next((r for r in records if r.kind == "header"), None)
    if first is None:
        raise NotACampaignJournal(f"{source}: no campaign header record")
    try:
        campaign = Campaign(_header(first))
    except _UNUSABLE as exc:
        raise NotACampaignJournal(f"{source}: its header record is not readable ({exc})") from None
    if found.damaged:
        skipped = sum(length for _, length in found.damaged)
        campaign.notes.append(f"{source}: {len(found.damaged)} damaged stretches ({skipped} bytes, first at byte "
                              f"{found.damaged[0][0]}) skipped; what they held is measured again on resume")
    if first is not records[0]:
        campaign.notes.append(f"{source}: {records.index(first)} records before the header ignored")
    for record in records[records.index(first) + 1:]:
        try:
            _apply(campaign, record, source)
        except _UNUSABLE as exc:
            campaign.notes.append(f"{source}: {record.kind} record at byte {record.offset} not usable ({exc})")
    return campaign


def _apply(campaign: Campaign, record: Record, source: str) -> None:
    meta = record.meta
    if record.kind == "pose":
        campaign.add_pose(_pose(record, campaign.header), f"{source} byte {record.offset}")
    elif record.kind == "events":
        times = record.arrays["t_s"]
        rows = meta["rows"]
        if len(rows) != times.shape[0]:
            raise ValueError("event columns of different lengths")
        campaign.events.extend(StoredEvent(float(t), str(w), str(lv), str(k), str(m))
                               for t, (w, lv, k, m) in zip(times.tolist(), rows))
    elif record.kind == "soak":
        campaign.add_soak(_soak(record, campaign.header))
    elif record.kind == "state":
        state = str(meta["state"])
        if state not in ("running", "done", "aborted", "created"):
            raise ValueError(f"unknown state {state!r}")
        campaign.state = state
        if state == "running":  # a run starts afresh: the last run's ending no longer applies
            campaign.abort_reason, campaign.finished = "", ""
        if meta.get("wall_time"):
            campaign.finished = str(meta["wall_time"])
        if meta.get("reason"):
            campaign.abort_reason = str(meta["reason"])
    elif record.kind == "run":
        if not all(isinstance(meta[k], int) and 0 <= meta[k] < 2**31 for k in ("run", "pid")):
            raise ValueError("run or pid not a small whole number")
        campaign.runs.append(RunStart(meta["run"], meta["pid"], str(meta["host"]), str(meta["started"])))
    elif record.kind == "instruments":
        campaign.instruments.update({str(k): {str(a): str(b) for a, b in _attributes(v).items()}
                                     for k, v in meta["instruments"].items()})
    elif record.kind == "header":
        raise ValueError("a second header")
    else:
        raise ValueError(f"unknown kind {record.kind!r}")
