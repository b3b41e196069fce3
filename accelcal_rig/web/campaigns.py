"""The campaigns in the watched folders, read as `rig status` reads them (the journal, never the writer's
lock), each read again only when its files change: the campaign's, its progress snapshot, its calibration."""

from __future__ import annotations

import socket
import threading
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from accelcal_rig.core.formatting import format_duration
from accelcal_rig.errors import RigError
from accelcal_rig.fit.campaign_file import calibration_verdicts
from accelcal_rig.report.warning_groups import warning_groups
from accelcal_rig.store.follow_up_record import recorded_calibration
from accelcal_rig.store.lock import holder
from accelcal_rig.store.paths import journal_path, progress_path
from accelcal_rig.store.read import campaign_status, load_campaign, without_pose_count
from accelcal_rig.web.interruptions import Interruption, interruptions

_JOURNAL_SUFFIX = ".journal"


#: A DUT without a verdict stored (its procedure states no acceptance limits), as every page names it.
NOT_JUDGED = "NOT JUDGED"


@dataclass
class _Cached:
    stamp: tuple[tuple[int, int], ...]
    summary: dict[str, Any]
    series: dict[str, list[float]]
    #: Where the campaign's calibration is (its follow-up says; beside it until read): its changes are watched.
    calibration: Path
    stops: list[Interruption]


class CampaignFolders:
    def __init__(self, folders: list[Path]) -> None:
        self.folders = [folder.resolve() for folder in folders]
        self._cache: dict[Path, _Cached] = {}
        self._lock = threading.Lock()  # requests are answered on several threads

    def paths(self) -> dict[str, Path]:
        """Every campaign file (or journal of one not built yet) in the folders, by its name."""
        found: dict[str, Path] = {}
        for folder in self.folders:
            for candidate in [*folder.glob("*.h5"), *folder.glob(f"*.h5{_JOURNAL_SUFFIX}")]:
                path = candidate.with_name(candidate.name.removesuffix(_JOURNAL_SUFFIX))
                found.setdefault(path.name, path)
        return found

    def summaries(self) -> list[dict[str, Any]]:
        """Newest first; a file that cannot be read is listed with its error, not dropped."""
        paths = self.paths()  # the folders looked through once per request
        rows = [self._read(path, name).summary for name, path in paths.items()]
        return sorted(rows, key=lambda r: r.get("started") or "", reverse=True)

    def summary(self, name: str) -> dict[str, Any]:
        return self._read(self.path(name), name).summary

    def series(self, name: str) -> dict[str, list[float]]:
        return self._read(self.path(name), name).series

    def interruptions(self, name: str) -> list[Interruption]:
        return self._read(self.path(name), name).stops

    def ended(self, host: str, campaign: str) -> dict[str, Any] | None:
        """The summary of a campaign run on this computer, in a watched folder, whose file says it ended (done
        or aborted), else None: what a rig card the registry last heard running is checked against. A path
        the registry names is read only when it is one of the watched campaigns (the registry says where to
        look, never what to open)."""
        if host != socket.gethostname():
            return None
        try:
            wanted = Path(campaign).resolve()
        except (OSError, ValueError):
            return None
        for name, path in self.paths().items():
            if path.resolve() == wanted:
                summary = self._read(path, name).summary
                return summary if summary.get("state") in ("done", "aborted") else None
        return None

    def path(self, name: str) -> Path:
        paths = self.paths()
        if name not in paths:
            raise KeyError(name)
        return paths[name]

    def _read(self, path: Path, name: str) -> _Cached:
        with self._lock:
            cached = self._cache.get(path)
        calibration = cached.calibration if cached is not None else path.with_suffix(".calibration.yaml")
        files = tuple(_stamp(p) for p in (path, journal_path(path), progress_path(path)))
        if cached is not None and cached.stamp == (*files, _stamp(calibration)) \
                and not _writer_gone(path, cached.summary):
            return cached
        stops: list[Interruption] = []
        calibration_stamp = _stamp(calibration)
        try:
            campaign = load_campaign(path)
            status = campaign_status(path, campaign)
            warnings = [e.message for e in campaign.events if e.level in ("warning", "error")]
            groups = [{**g.as_dict(), "first": format_duration(g.first_s), "last": format_duration(g.last_s)}
                      for g in warning_groups(campaign.events)]
            stops = interruptions(campaign)
            summary = {**status, "name": name, "warnings": warnings[-20:], "warning_groups": groups, "error": None,
                       "interruptions": [stop.as_dict() for stop in stops]}
            if summary.get("progress"):
                remaining = summary["progress"].get("remaining_s")
                summary["progress"]["left"] = format_duration(remaining) if remaining is not None else None
                summary["progress"]["now"] = without_pose_count(str(summary["progress"].get("line", "")))
            series = _temperatures(campaign)
            calibration = recorded_calibration(campaign.attrs, path)
            calibration_stamp = _stamp(calibration)  # before it is read: one written meanwhile is read next time
            summary.update(_verdicts(path, calibration, campaign))
        except Exception as exc:  # noqa: BLE001 - a damaged file is shown as such, the others still are
            summary = {"name": name, "file": str(path), "state": "unreadable", "error": str(exc), "verdicts": {},
                       "interruptions": []}
            series, stops = {}, []
        cached = _Cached((*files, calibration_stamp), summary, series, calibration, stops)
        with self._lock:
            self._cache[path] = cached
        return cached


def _verdicts(path: Path, calibration: Path, campaign: Any) -> dict[str, Any]:
    """Each DUT's verdict and reasons from the campaign's calibration (`verdicts` empty until there is one, or
    when it cannot be read: `calibration` says why), and whether it was fitted to the measurements stored now."""
    try:
        found = calibration_verdicts(path, calibration, campaign)
    except (RigError, OSError, ValueError, KeyError, TypeError) as exc:  # the campaign is still shown
        return {"calibration": f"{calibration}: cannot be judged: {(str(exc).splitlines() or [type(exc).__name__])[0]}",
                "verdicts": {}}
    verdicts = {serial: {"verdict": judged["verdict"] or NOT_JUDGED, "reasons": list(judged["reasons"]),
                         "sensors": dict(judged.get("sensors") or {})}
                for serial, judged in (found["verdicts"] or {}).items()}
    return {"calibration": found["calibration"], "verdicts": verdicts, "sensor_verdicts": by_sensor(verdicts)}


def by_sensor(verdicts: dict[str, Any]) -> str:
    """A campaign of several sensors per DUT (IMUs) in one line, each sensor's verdicts counted, worst first:
    "accelerometer 4 PASS · gyroscope 3 PASS, 1 FAIL"; "" when each DUT has one sensor (its verdict says it)."""
    sensors = list(dict.fromkeys(name for judged in verdicts.values() for name in judged.get("sensors", {})))
    if len(sensors) < 2:
        return ""
    order = ["FAIL", "CONDITIONAL", "PASS", NOT_JUDGED]
    parts = []
    for sensor in sensors:
        said = [judged["sensors"][sensor] for judged in verdicts.values() if sensor in judged.get("sensors", {})]
        counts = ", ".join(f"{said.count(v)} {v}" for v in order if v in said)
        parts.append(f"{sensor} {counts}")
    return " · ".join(parts)


def _writer_gone(path: Path, summary: dict[str, Any]) -> bool:
    """A campaign shown as run by a live process whose process has ended since (a kill changes no file): what
    was shown of it is stale. Asked only of a campaign shown as running (asking takes the lock a moment)."""
    return str(summary.get("writer") or "").startswith("alive") and holder(path) is None


def _stamp(path: Path) -> tuple[int, int]:
    """(modification time, size): a file that changed differs in one or the other."""
    try:
        status = path.stat()
    except OSError:
        return (-1, -1)
    return (status.st_mtime_ns, status.st_size)


def _temperatures(campaign: Any) -> dict[str, list[float]]:
    """Chamber air and the DUTs' mean temperature at every stored pose, ramp and soak poll, on the campaign
    clock (a ramp polls the air only: its DUT value is missing, NaN)."""
    points: list[tuple[float, float, float]] = []
    for soak in campaign.soaks:
        for t, chamber in zip(soak.ramp_t_s, soak.ramp_chamber_c):
            points.append((float(t), float(chamber), float("nan")))
        for t, chamber, duts in zip(soak.t_s, soak.chamber_c, soak.dut_c):
            points.append((float(t), float(chamber), float(np.mean(duts))))
    for pose in campaign.poses:
        points.append((float(pose.t_start_s), float(np.mean(pose.chamber_temperature_c)),
                       float(np.mean([np.mean(d.temperature_c) for d in pose.duts]))))
    points.sort()
    return {"t_h": [p[0] / 3600.0 for p in points], "chamber_c": [p[1] for p in points],
            "dut_c": [p[2] for p in points]}
