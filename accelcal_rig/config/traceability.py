"""Whether a rig's references are in calibration: a reference past its due date makes every campaign run with
it untraceable through it, so `rig plan` and `rig run` say so before anything moves (or refuse, when the rig
config's `references_overdue` says so). "Today" is the caller's: the command line passes the calendar's."""

from __future__ import annotations

import datetime as dt
from dataclasses import dataclass

from accelcal_rig.config.lab import REFERENCE_LABELS, ReferenceConfig
from accelcal_rig.config.load import LoadedConfig
from accelcal_rig.config.rig import RigConfig
from accelcal_rig.errors import ConfigError


def expected_references(rig: RigConfig) -> list[str]:
    """The references the rig's campaigns rely on: the table's rate only where an axis has a rate mode, the
    site's magnetic field only where the rig states one (its magnetometers' reference)."""
    rate_mode = any(axis.has_rate_mode for axis in rig.turntable.axes)
    relied_on = {"turntable_rate": rate_mode, "site_magnetic_field": rig.magnetic_field is not None}
    return [key for key in REFERENCE_LABELS if relied_on.get(key, True) or getattr(rig.references, key) is not None]


@dataclass(frozen=True)
class Overdue:
    key: str                          # "turntable_angle", …
    reference: ReferenceConfig

    def sentence(self) -> str:
        return (f"overdue since {self.reference.due_date.isoformat()} (certificate {self.reference.certificate} by "
                f"{self.reference.issuer}): a campaign with it is not traceable through its "
                f"{REFERENCE_LABELS[self.key].split(' (')[0]}")


def overdue_references(rig: RigConfig, today: dt.date) -> list[Overdue]:
    """The stated references whose due date is before `today` (due today is still in calibration)."""
    stated = {key: getattr(rig.references, key) for key in REFERENCE_LABELS}
    return [Overdue(key, reference) for key, reference in stated.items()
            if reference is not None and reference.due_date < today]


def reference_warnings(rig: LoadedConfig[RigConfig], today: dt.date) -> list[str]:
    """One line per overdue reference, naming the file, the line and the key; ConfigError on the first instead
    when the rig config says `references_overdue: refuse`."""
    lines = []
    for overdue in overdue_references(rig.model, today):
        error = rig.error(("references", overdue.key, "due_date"), overdue.sentence())
        if rig.model.references_overdue == "refuse":
            raise ConfigError(f"{error}; refused (references_overdue: refuse): recalibrate it, or state its new "
                              "certificate")
        lines.append(str(error))
    return lines
