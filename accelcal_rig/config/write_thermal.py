"""Writing measured thermal constants into a rig config's `thermal:` section, every other byte of the file —
its comments, order, spacing, line endings — as the lab wrote it.

The section is a top-level key the fit owns, so its key lines are replaced as text (or appended where the file
has none); the section's own comments stay (a comment line where it was, at the top of the section; a comment
after a key's value after that key's new value). The result must parse to the same config but for `thermal:`
and validate as a rig config before it replaces the file (atomically: durable.write_atomically) — the file a
symbolic link names, the link left a link. A write that would do otherwise is refused and the file is left as
it was.
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
    """`text` (a rig config) with its `thermal:` block replaced by the constants', or the block appended; in the
    file's own line ending (CRLF stays CRLF)."""
    newline = "\r\n" if "\r\n" in text else "\n"
    lines = text.splitlines()
    block = section_lines(constants, measured)
    start = next((i for i, line in enumerate(lines) if _SECTION.match(line)), None)
    if start is None:
        ending = "" if text.endswith(("\n", "\r")) or not text else newline
        return text + ending + newline.join(["", _COMMENT, *block]) + newline
    end = start + 1
    while end < len(lines) and (not lines[end].strip() or lines[end][0] in " \t"):
        end += 1
    while end > start + 1 and not lines[end - 1].strip():  # blank lines before the next key stay with it
        end -= 1
    kept = _with_comments(lines[start], lines[start + 1:end], block)
    return newline.join([*lines[:start], *kept, *lines[end:]]) + newline


#: A key's line in the section with a comment after its value (` # …` after a space).
_KEY_COMMENT = re.compile(r"^[ \t]+([A-Za-z_][A-Za-z0-9_]*)[ \t]*:.*?([ \t]+#.*)$")


def _with_comments(header: str, old: list[str], block: list[str]) -> list[str]:
    """The new block with the old section's comments: its header line's, its comment lines (at the top), each
    key's comment after its value."""
    standalone = [line for line in old if line.strip().startswith("#")]
    after_value = {m.group(1): m.group(2) for line in old if (m := _KEY_COMMENT.match(line))}
    keyed = []
    for line in block[1:]:
        key = line.strip().partition(":")[0]
        keyed.append(line + after_value.get(key, ""))
    return [header, *standalone, *keyed]


def write_thermal(rig_path: Path, constants: dict[str, float | None], measured: str) -> None:
    """Write the constants into the rig config at `rig_path`, checked first; ConfigError naming the file
    when it cannot be (nothing is changed then)."""
    try:
        target = rig_path.resolve(strict=True)  # a link's file, written in place of the link's own name
        text = target.read_bytes().decode("utf-8")
    except (OSError, UnicodeDecodeError, RuntimeError) as exc:
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
    write_text_atomically(target, new_text, "the rig config")
