"""Shared by the benchmarks: a simulated rig with a fixture of any size, and a procedure run on it."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import yaml


def write_rig(base: Path, duts: int, prefix: str, folder: Path) -> Path:
    """`base`'s rig config with `duts` sensors (serials `prefix000`…, mounted at the four yaw angles in turn),
    as `folder/rig.yaml`."""
    rig = yaml.safe_load(base.read_text())
    rig["fixture"]["sensors"] = [{"serial": f"{prefix}{k:03d}", "mount_euler_deg": [0, 0, 90 * (k % 4)]}
                                 for k in range(duts)]
    path = folder / "rig.yaml"
    path.write_text(yaml.safe_dump(rig))
    return path


def write_procedure(base: Path, folder: Path, name: str, **changes: Any) -> Path:
    """`base`'s procedure naming `folder/rig.yaml`, its top-level keys changed as given, as `folder/name`."""
    procedure = yaml.safe_load(base.read_text())
    procedure.update(rig="rig.yaml", **changes)
    path = folder / name
    path.write_text(yaml.safe_dump(procedure))
    return path
