"""A stored campaign as plain data: what its journal (or its HDF5 file) holds, with the views readers use.

The journal and the HDF5 file are two ways of writing the same `Campaign`; every command reads one of
them into this, so what a reader sees does not depend on which file it came from.
"""

from __future__ import annotations

import datetime as dt
import hashlib
from collections import Counter
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from accelcal_rig.core.units import STANDARD_GRAVITY_M_S2, site_gravity_g
from accelcal_rig.store.records import CampaignHeader, ChannelInfo, PoseRecord, RunStart, SoakTrace, StoredEvent

#: The acceleration channel's fields under their names in formats 1 and 2.
#: A channel's fields, per pose.
CHANNEL_FIELDS = ("raw_codes", "mean", "stderr", "reference")
POSE_FIELDS = ("step_key", "setpoint_c", "pose_number", "commanded_angles_deg", "measured_angles_deg",
               "gravity_fixture", "t_start_s", "t_end_s", "chamber_temperature_c")


@dataclass
class Campaign:
    header: CampaignHeader
    runs: list[RunStart] = field(default_factory=list)
    instruments: dict[str, dict[str, str]] = field(default_factory=dict)
    poses: list[PoseRecord] = field(default_factory=list)
    soaks: list[SoakTrace] = field(default_factory=list)
    events: list[StoredEvent] = field(default_factory=list)
    state: str = "created"
    abort_reason: str = ""
    finished: str = ""
    #: What reading it found wrong that leaves the measurements usable (a pose stored twice, damaged
    #: journal records skipped, …), one line each.
    notes: list[str] = field(default_factory=list)
    #: What makes the stored measurements untrustworthy until repaired (a damaged column), one line each.
    damage: list[str] = field(default_factory=list)
    #: Where it was read from: "journal" or "file" (the HDF5 file alone); and how many bytes of the
    #: journal it holds.
    source: str = "journal"
    journal_bytes: int = 0
    _columns: dict[str, np.ndarray] = field(default_factory=dict, repr=False)
    _stored: set[str] = field(default_factory=set, repr=False)

    def __post_init__(self) -> None:
        self._stored = {p.step_key for p in self.poses}
        if not self.instruments:  # later runs may reach them another way: `instruments` records update these
            self.instruments = {name: dict(info) for name, info in self.header.instruments.items()}

    # ------------------------------------------------------------------ building it
    def add_pose(self, pose: PoseRecord, where: str) -> bool:
        """Keep `pose` unless its step is stored already (then say so, naming `where` it came from). Its
        DUTs are matched to the campaign's by serial, whatever order they came in; ValueError when they
        are not the campaign's."""
        if [d.serial for d in pose.duts] != self.serials:
            by_serial = {d.serial: d for d in pose.duts}
            if sorted(by_serial) != sorted(self.serials) or len(by_serial) != len(pose.duts):
                raise ValueError(f"its sensors {sorted(by_serial)} are not the campaign's {self.serials}")
            pose = replace(pose, duts=[by_serial[serial] for serial in self.serials])
        if pose.step_key in self.stored_keys:
            self.notes.append(f"pose {pose.step_key} stored more than once ({where}): the first is kept")
            return False
        self.poses.append(pose)
        self._stored.add(pose.step_key)
        self._columns.clear()
        return True

    def add_soak(self, soak: SoakTrace) -> None:
        """Keep a soak trace, its DUT columns put in the campaign's order."""
        if soak.serials and list(soak.serials) != self.serials:
            if sorted(soak.serials) != sorted(self.serials):
                raise ValueError(f"its sensors {list(soak.serials)} are not the campaign's {self.serials}")
            order = [soak.serials.index(serial) for serial in self.serials]
            dut_c = soak.dut_c[:, order] if soak.dut_c.size else soak.dut_c
            soak = replace(soak, dut_c=dut_c, settled_dut_c=soak.settled_dut_c[order], serials=tuple(self.serials))
        self.soaks.append(soak)

    @property
    def stored_keys(self) -> set[str]:
        return self._stored

    # ------------------------------------------------------------------ views
    @property
    def serials(self) -> list[str]:
        return self.header.serials

    @property
    def attrs(self) -> dict[str, Any]:
        return self.header.attrs

    @property
    def poses_planned(self) -> int:
        return len(self.header.plan.pose_keys)

    @property
    def run_count(self) -> int:
        return max(len(self.runs), 1)

    def pose_column(self, name: str) -> np.ndarray:
        """One field of every stored pose, stacked: (N, …)."""
        key = f"poses/{name}"
        if key not in self._columns:
            values = [getattr(p, name) for p in self.poses]
            if name == "step_key":
                self._columns[key] = np.array(values, dtype=object)
            else:
                self._columns[key] = _stack(values, _POSE_TAILS[name](self), _POSE_DTYPES.get(name, "f8"))
        return self._columns[key]

    def dut_column(self, serial: str, name: str) -> np.ndarray:
        """One of a DUT's own fields over the stored poses: `temperature_c`, `temperature_in_band` (its channels'
        are `channel_column`'s)."""
        key = f"duts/{serial}/{name}"
        if key not in self._columns:
            index = self.serials.index(serial)
            values = [getattr(p.duts[index], name) for p in self.poses]
            tail, dtype = {"temperature_c": ((2,), "f8"), "temperature_in_band": ((), "?")}[name]
            self._columns[key] = _stack(values, tail, dtype)
        return self._columns[key]

    def channel_column(self, serial: str, channel: str, name: str) -> np.ndarray:
        """One field of one of a DUT's channels over the stored poses: `raw_codes` (N, n, axes), `mean`,
        `stderr`, `reference` (N, axes)."""
        key = f"duts/{serial}/{channel}/{name}"
        if key not in self._columns:
            index = self.serials.index(serial)
            info = self.channel_info(serial, channel)
            values = [getattr(p.duts[index].channels[channel], name) for p in self.poses]
            axes = len(info.axes)
            tail = (self.samples_per_pose, axes) if name == "raw_codes" else (axes,)
            self._columns[key] = _stack(values, tail, "i4" if name == "raw_codes" else "f8")
        return self._columns[key]

    def channel_ranges(self, serial: str, channel: str) -> np.ndarray:
        """(N,) the ± full scale each stored record of the channel was taken at: the channel's own range where the
        record states none (every record of a campaign at one range)."""
        key = f"duts/{serial}/{channel}/range"
        if key not in self._columns:
            index = self.serials.index(serial)
            default = self.channel_info(serial, channel).range
            values = [p.duts[index].channels[channel].range for p in self.poses]
            self._columns[key] = np.array([default if v is None else v for v in values], dtype="f8")
        return self._columns[key]

    def channel_values(self, serial: str, channel: str) -> np.ndarray:
        """(N, n, axes) each record's samples in the channel's unit: its codes times its own code size (the
        channel's, scaled by the record's range: a part's codes are one width at every range)."""
        lsb = self.channel_info(serial, channel).lsb_at(self.channel_ranges(serial, channel))
        return self.channel_column(serial, channel, "raw_codes") * lsb[:, None, None]

    def channel_info(self, serial: str, channel: str) -> ChannelInfo:
        for info in self.header.dut_channels(serial):
            if info.name == channel:
                return info
        raise KeyError(f"sensor {serial} has no {channel!r} channel")

    def channel_of(self, serial: str, quantity: str) -> ChannelInfo | None:
        """The DUT's first channel that measures `quantity` (a reader of one quantity: a tilt check's
        accelerometer), None where it has none."""
        return next((info for info in self.header.dut_channels(serial) if info.quantity == quantity), None)

    def truth_column(self, serial: str, name: str) -> np.ndarray | None:
        """Simulation truth of one field over the poses (dry runs), None when the campaign has none."""
        if serial not in self.header.truth:
            return None
        key = f"truth/{serial}/{name}"
        if key not in self._columns:
            index = self.serials.index(serial)
            truths = [p.duts[index].truth for p in self.poses]
            tail = {"parameters": (12,), "gravity_g": (3,), "gyro_wander_dps": (3,)}.get(name, ())
            values = [truth[name] if truth is not None and name in truth else np.full(tail, np.nan) for truth in truths]
            self._columns[key] = _stack(values, tail, "f8")
        return self._columns[key]

    @property
    def samples_per_pose(self) -> int:
        return int(self.attrs.get("samples_per_pose", 0))

    def soak_names(self) -> list[str]:
        """Each soak's name in the file: its label, then `T-40#2`, `T-40#3`, … for later soaks there."""
        names, seen = [], Counter[str]()
        for soak in self.soaks:
            seen[soak.label] += 1
            names.append(soak.label if seen[soak.label] == 1 else f"{soak.label}#{seen[soak.label]}")
        return names

    def last_clock_s(self) -> float:
        """The latest campaign-clock time anything in the campaign carries."""
        times = [e.t_s for e in self.events[-1:]] + [p.t_end_s for p in self.poses[-1:]]
        times += [float(s.t_s[-1]) for s in self.soaks if len(s.t_s)]
        return float(max(times, default=0.0))

    def clock_now_s(self) -> float:
        """Where a resumed run's clock starts: the latest time in the campaign, plus the wall time since
        its last event when the clock is real."""
        last = self.last_clock_s()
        if self.attrs.get("clock") != "real" or not self.events:
            return last
        try:
            wall = dt.datetime.fromisoformat(self.events[-1].wall_time)
        except ValueError:
            return last
        return last + max(0.0, (dt.datetime.now(dt.UTC) - wall).total_seconds())

    def unusable_reasons(self) -> list[str]:
        """Why the measurements cannot be fitted or analysed as they are (empty when they can)."""
        return list(self.damage) + [
            f"duts/{serial}: implausible values (zeros or non-finite) in {len(rows)} poses, first "
            f"{self.poses[rows[0]].step_key}" for serial in self.serials if (rows := _implausible_rows(self, serial))]

    def integrity_problems(self) -> list[str]:
        """What is wrong with the stored poses, one line each (empty for a sound campaign)."""
        problems = self.unusable_reasons() + list(self.notes)
        foreign = sorted(self.stored_keys - set(self.header.plan.pose_keys))
        if foreign:
            problems.append(f"poses not in the plan: {', '.join(foreign[:5])}{' …' if len(foreign) > 5 else ''}")
        return problems


def take_what_the_file_kept(campaign: Campaign, from_file: Campaign, journal_name: str, file_name: str) -> int:
    """Add to a journal's `campaign` the poses its campaign file `from_file` (the same campaign, read
    whole) still holds and the journal has lost, in measurement order; how many. Only measurements are
    taken back: the journal's own records (state, soaks, events) stay what they are, a lost one is what
    a resume treats as a run that died."""
    poses = [p for p in from_file.poses if p.step_key not in campaign.stored_keys]
    if not poses:
        return 0
    for pose in poses:
        campaign.add_pose(pose, file_name)
    campaign.poses.sort(key=lambda p: p.t_start_s)
    campaign._columns.clear()
    campaign.notes.append(f"{journal_name} had lost {len(poses)} poses {file_name} still holds: taken from "
                          f"{file_name} (rig repair gives them back to the journal)")
    return len(poses)


def measurements_sha256(campaign: Campaign) -> str:
    """Digest of the measured data (pose keys, raw codes, temperatures, references), not of a file: the
    same campaign read from its journal or its HDF5 file has the same digest. Each DUT's first channel with
    its temperatures between its codes and its references, then its other channels: the order formats 1 and 2
    digested an accelerometer's campaign in (its acceleration channel first), so such a campaign keeps its
    digest in every format."""
    digest = hashlib.sha256()
    digest.update(b"".join(p.step_key.encode() for p in campaign.poses))
    for serial in sorted(campaign.serials):
        for index, info in enumerate(campaign.header.dut_channels(serial)):
            digest.update(np.ascontiguousarray(campaign.channel_column(serial, info.name, "raw_codes")).tobytes())
            if index == 0:
                digest.update(np.ascontiguousarray(campaign.dut_column(serial, "temperature_c")).tobytes())
            digest.update(np.ascontiguousarray(campaign.channel_column(serial, info.name, "reference")).tobytes())
            ranges = campaign.channel_ranges(serial, info.name)
            if np.any(ranges != info.range):  # the codes' meaning; a campaign at one range keeps its digest
                digest.update(np.ascontiguousarray(ranges).tobytes())
    return digest.hexdigest()


#: Records taken while the table turns: gravity in the fixture frame may turn through them.
TURNING_KINDS = frozenset({"rate", "verify-rate"})


def _implausible_rows(campaign: Campaign, serial: str) -> list[int]:
    """Rows no real measurement produces: a reference gravity not as long as the site's (through a rate step,
    gravity averaged over a turn: longer than the site's), a block of codes all zero in any channel, or a
    non-finite mean or temperature."""
    if not campaign.poses:
        return []
    temperature = campaign.dut_column(serial, "temperature_c")
    bad = ~np.all(np.isfinite(temperature), axis=1)
    site = site_gravity_g(float(campaign.attrs.get("gravity_m_s2", STANDARD_GRAVITY_M_S2)))
    for info in campaign.header.dut_channels(serial):
        codes = campaign.channel_column(serial, info.name, "raw_codes")
        mean = campaign.channel_column(serial, info.name, "mean")
        bad |= ~np.any(codes != 0, axis=(1, 2)) | ~np.all(np.isfinite(mean), axis=1)
        if info.quantity == "acceleration":  # gravity in standard g: the site's gravity's length
            reference = campaign.channel_column(serial, info.name, "reference")
            kinds = dict(zip(campaign.header.plan.step_key, campaign.header.plan.kind))
            turning = np.array([kinds.get(p.step_key) in TURNING_KINDS for p in campaign.poses])
            with np.errstate(invalid="ignore"):
                off = np.linalg.norm(reference, axis=1) - site
                bad |= np.where(turning, off > 1e-6, np.abs(off) > 1e-6)
    return np.flatnonzero(bad).tolist()


def _stack(values: list[Any], tail: tuple[int, ...], dtype: str) -> np.ndarray:
    if not values:
        return np.zeros((0, *tail), dtype=dtype)
    return np.asarray(np.stack([np.asarray(v, dtype=dtype) for v in values]), dtype=dtype)


def _axes(campaign: Campaign) -> tuple[int, ...]:
    return (len(campaign.header.plan.axis_names),)


_POSE_TAILS = {
    "setpoint_c": lambda c: (), "pose_number": lambda c: (), "t_start_s": lambda c: (), "t_end_s": lambda c: (),
    "commanded_angles_deg": _axes, "measured_angles_deg": _axes, "gravity_fixture": lambda c: (3,),
    "chamber_temperature_c": lambda c: (2,),
}
_POSE_DTYPES = {"pose_number": "i4"}
