"""The starting set a lab edits: the shipped procedures, rig configs and the editors' schemas, written by
`rig init DIR` into a folder of the user's own. They ship in the package (accelcal_rig/starter/), laid out as
the folder they are written to, so a procedure's `rig: ../configs/…` and a file's schema line hold in both."""

from __future__ import annotations

import os
import shutil
import tempfile
from importlib.resources import as_file, files
from pathlib import Path

from accelcal_rig.errors import ConfigError

#: The folders of the starting set, in the package and in the folder written.
FOLDERS = ("procedures", "configs", "schemas")


def starter_files() -> list[Path]:
    """Every file of the starting set, relative to the set's root (README.md, then each folder's files)."""
    root = files("accelcal_rig") / "starter"
    found = [Path("README.md")]
    for folder in FOLDERS:
        found += sorted(Path(folder) / entry.name for entry in (root / folder).iterdir()
                        if entry.is_file() and entry.name.endswith((".yaml", ".json")))
    return found


def write_starter(folder: Path) -> list[Path]:
    """Write the starting set into `folder` (a new folder, or an empty one) and return the files written.

    Written beside `folder` first and renamed into place, so an interrupted `rig init` leaves no half set and
    nothing a user had in `folder` is ever overwritten."""
    if folder.exists() and not folder.is_dir():
        raise ConfigError(f"{folder} is a file; the starting set goes into a new or empty folder")
    if folder.is_dir() and any(folder.iterdir()):
        raise ConfigError(f"{folder} is not empty; nothing written (the starting set goes into a new "
                          "or empty folder, so no file of yours is replaced)")
    parent = folder.absolute().parent
    if not parent.is_dir():
        raise ConfigError(f"{parent} does not exist")
    written = starter_files()
    try:
        holder = Path(tempfile.mkdtemp(prefix=f".{folder.name}.init-", dir=parent))
    except OSError as exc:  # a folder we may not write in: one line, not a traceback
        raise ConfigError(f"cannot write {folder}: {exc.strerror or exc}") from None
    staging = holder / folder.name  # made with mkdir, so the umask gives it a normal folder's mode
    try:
        staging.mkdir()
        with as_file(files("accelcal_rig") / "starter") as source:
            for relative in written:
                (staging / relative).parent.mkdir(exist_ok=True)
                shutil.copyfile(source / relative, staging / relative)
        os.rename(staging, folder)  # onto a missing or empty folder: atomic on POSIX
    except OSError as exc:
        raise ConfigError(f"cannot write {folder}: {exc.strerror or exc}") from None
    finally:
        shutil.rmtree(holder, ignore_errors=True)
    return [folder / relative for relative in written]

