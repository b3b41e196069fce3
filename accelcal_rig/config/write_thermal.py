"""Writing measured thermal constants into a rig config's `thermal:` section, every other byte of the file —
its comments, order, spacing — as the lab wrote it.

The section is a top-level key the fit owns whole, so its lines are replaced as text (or appended where the
file has none); the result must parse to the same config but for `thermal:` and validate as a rig config
before it replaces the file (atomically: durable.write_atomically). A write that would do otherwise is refused
and the file is left as it was.
"""

from __future__ import annotations

import re
from pathlib import Path

from accelcal_rig.config.load import validate_rig_text
from accelcal_rig.config.rig import RigThermal
from accelcal_rig.config.yaml_lines import parse_yaml_text
from accelcal_rig.durable import write_text_atomically
from accelcal_rig.errors import ConfigError

#: The order the section's keys are written in (the model's).
_KEYS = tuple(RigThermal.model_fields)
#: Where a top-level `thermal:` key starts (a block mapping: nothing after the colon but a comment).
_SECTION = re.compile(r"^thermal:[ \t]*(#.*)?$")
_COMMENT = "# The rig's own thermal constants, measured by rig characterise: what duration estimates use."


def section_lines(constants: dict[str, float | None], measured: str) -> list[str]:
    """The `thermal:` block as text (None: the key left out — a floor that was not seen)."""
    lines = ["thermal:"]
    for key in _KEYS:
        value = measured if key == "measured" else constants.get(key)
        if value is None:
            continue
        shown = f"{round(value, 4) + 0.0:g}" if isinstance(value, float) else _quoted(str(value))  # + 0.0: no -0
        lines.append(f"  {key}: {shown}")
    return lines


def _quoted(text: str) -> str:
    return '"' + text.replace("\\", "\\\\").replace('"', '\\"') + '"'


def with_thermal(text: str, constants: dict[str, float | None], measured: str) -> str:
    """`text` (a rig config) with its `thermal:` block replaced by the constants', or the block appended."""
    lines = text.splitlines()
    block = section_lines(constants, measured)
    start = next((i for i, line in enumerate(lines) if _SECTION.match(line)), None)
    if start is None:
        return text + ("" if text.endswith("\n") or not text else "\n") + "\n".join(["", _COMMENT, *block]) + "\n"
    end = start + 1
    while end < len(lines) and (not lines[end].strip() or lines[end][0] in " \t"):
        end += 1
    while end > start + 1 and not lines[end - 1].strip():  # blank lines before the next key stay with it
        end -= 1
    return "\n".join([*lines[:start], *block, *lines[end:]]) + "\n"


def write_thermal(rig_path: Path, constants: dict[str, float | None], measured: str) -> None:
    """Write the constants into the rig config at `rig_path`, checked first; ConfigError naming the file
    when it cannot be (nothing is changed then)."""
    try:
        text = rig_path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise ConfigError(f"{rig_path}: cannot read it: {exc}") from None
    before = parse_yaml_text(text, str(rig_path))
    if isinstance(before, dict) and "thermal" in before and not any(map(_SECTION.match, text.splitlines())):
        raise ConfigError(f"{rig_path}: its thermal: is not a block of its own lines (flow style?): write the "
                          "constants by hand; the file was left as it was")
    new_text = with_thermal(text, constants, measured)
    after = parse_yaml_text(new_text, str(rig_path))
    if not isinstance(before, dict) or not isinstance(after, dict) or \
            {k: v for k, v in before.items() if k != "thermal"} != {k: v for k, v in after.items() if k != "thermal"}:
        raise ConfigError(f"{rig_path}: its thermal: section could not be rewritten without touching the rest (a "
                          "flow-style or anchored thermal: ?): write it by hand; the file was left as it was")
    try:
        validate_rig_text(new_text, rig_path)
    except ConfigError as exc:
        raise ConfigError(f"the measured constants would not make a valid rig config ({exc}); {rig_path} was "
                          "left as it was") from None
    write_text_atomically(rig_path, new_text, "the rig config")
