"""Which registry: `--registry URL`, else the rig config's `registry:`, else the ACCELCAL_REGISTRY
environment variable, else an SQLite file in the user's data folder (created on first use). A dry run's
calibrations are rehearsals: they go to a registry of their own (`--registry URL`, else the
ACCELCAL_DRY_RUN_REGISTRY environment variable, else `dry-runs.sqlite` beside the default), never to the
lab's."""

from __future__ import annotations

import os
import re
from pathlib import Path

from accelcal_rig.errors import ConfigError

ENVIRONMENT_VARIABLE = "ACCELCAL_REGISTRY"
DRY_RUN_ENVIRONMENT_VARIABLE = "ACCELCAL_DRY_RUN_REGISTRY"


def default_path() -> Path:
    """`$XDG_DATA_HOME/accelcal-rig/registry.sqlite`, `~/.local/share/…` without it."""
    data = os.environ.get("XDG_DATA_HOME") or str(Path.home() / ".local" / "share")
    return Path(data) / "accelcal-rig" / "registry.sqlite"


def default_dry_run_path() -> Path:
    """`dry-runs.sqlite` beside the default registry: where dry runs are recorded unless told otherwise."""
    return default_path().with_name("dry-runs.sqlite")


def registry_url(flag: str | None = None, configured: str | None = None) -> str:
    """The first given of the flag, the rig config's value and the environment, else the default file; as a
    SQLAlchemy URL (a bare path is an SQLite file, `postgresql://` is spoken with psycopg)."""
    chosen = flag or configured or os.environ.get(ENVIRONMENT_VARIABLE) or str(default_path())
    return normalised(chosen)


def recording_url(flag: str | None, configured: str | None, simulated: bool) -> str:
    """Where a fit is recorded: a real calibration as `registry_url` chooses; a dry run's in the dry runs'
    registry (the flag, else ACCELCAL_DRY_RUN_REGISTRY, else the default beside the lab's), never in the
    rig config's or the environment's registry, which are the lab's."""
    if not simulated:
        return registry_url(flag, configured)
    return normalised(flag or os.environ.get(DRY_RUN_ENVIRONMENT_VARIABLE) or str(default_dry_run_path()))


def configured(value: str | None, config_path: Path) -> str | None:
    """A rig config's `registry:`: a URL as it is, a file path relative to the config's folder."""
    if value is None or "://" in value or value.startswith("sqlite:"):
        return value
    return str((config_path.parent / Path(value).expanduser()).resolve())


def normalised(url: str) -> str:
    if url.startswith(("postgresql://", "postgres://")):
        return "postgresql+psycopg://" + url.split("://", 1)[1]
    if url.startswith(("postgresql+", "sqlite:")):
        return url
    if "://" in url:
        raise ConfigError(f"registry {url!r}: not an SQLite path or file, nor a postgresql:// URL")
    return f"sqlite:///{Path(url).expanduser().resolve()}"


def described(url: str) -> str:
    """The URL as messages show it: without a password (in its user part or its query)."""
    url = re.sub(r"([?&]password=)[^&]*", r"\1***", url)
    scheme, _, rest = url.partition("://")
    if "@" in rest:
        credentials, _, where = rest.rpartition("@")
        user = credentials.split(":", 1)[0]
        rest = f"{user}@{where}" if user else where
    return f"{scheme}://{rest}"


def campaign_rig_registry(campaign: Path) -> str | None:
    """The `registry:` of the rig config a campaign was run with (as the campaign stored it)."""
    import yaml

    from accelcal_rig.store.read import load_campaign

    stored = load_campaign(campaign)
    value = (yaml.safe_load(stored.header.rig_yaml) or {}).get("registry")
    return configured(value, Path(str(stored.attrs.get("rig_path", campaign)))) if value else None
