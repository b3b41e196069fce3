"""What to install for an optional capability, said the same way everywhere: the extra by name, and the packages
it stands for (read from the installed package's own metadata, so the hint never falls behind pyproject.toml and
works where accelcal-rig came from a wheel rather than an index)."""

from __future__ import annotations

import re
import shlex
from importlib.metadata import PackageNotFoundError, requires

DISTRIBUTION = "accelcal-rig"


def extra_packages(extra: str) -> list[str]:
    """The requirements the extra `extra` adds (e.g. "starlette>=0.37"); empty when the package's metadata is
    not installed (run from a bare source tree)."""
    try:
        declared = requires(DISTRIBUTION) or []
    except PackageNotFoundError:
        return []
    marker = re.compile(rf"""extra\s*==\s*["']{re.escape(extra)}["']""")
    return [requirement.split(";", 1)[0].strip() for requirement in declared
            if ";" in requirement and marker.search(requirement.split(";", 1)[1])]


def install_hint(extra: str) -> str:
    """The command that installs the extra: `pip install 'accelcal-rig[EXTRA]'` (which pip satisfies from the
    installed accelcal-rig, wheel or clone, fetching only the extra's packages), and those packages by name."""
    packages = extra_packages(extra)
    named = f" (its packages: pip install {' '.join(shlex.quote(p) for p in packages)})" if packages else ""
    return f"pip install '{DISTRIBUTION}[{extra}]'{named}"
