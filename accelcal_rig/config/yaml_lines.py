"""YAML loading that remembers the line of every key, so validation errors can say `file:line: key`."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import yaml

from accelcal_rig.errors import ConfigError

KeyPath = tuple[str | int, ...]


def load_yaml_with_lines(path: Path) -> tuple[Any, dict[KeyPath, int], str]:
    """Parse `path`; return (data, {key path: 1-based line}, raw text).

    Syntax errors and duplicate keys (which PyYAML would silently overwrite) become ConfigError.
    """
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise ConfigError(f"{path}: file not found") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise ConfigError(f"{path}: cannot read: {exc}") from None
    try:
        root = yaml.compose(text, Loader=yaml.SafeLoader)
        data = yaml.safe_load(text)
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark or exc.context_mark
        line = mark.line + 1 if mark is not None else 1
        problem = (exc.problem or exc.context or "invalid YAML").strip()
        raise ConfigError(f"{path}:{line}: syntax: {problem}") from None
    except yaml.YAMLError as exc:
        raise ConfigError(f"{path}:1: syntax: {exc}") from None
    if root is None:
        raise ConfigError(f"{path}:1: file is empty")
    if not isinstance(root, yaml.MappingNode):
        raise ConfigError(f"{path}:{root.start_mark.line + 1}: top level must be a mapping of keys")
    lines: dict[KeyPath, int] = {(): 1}
    _collect_lines(path, root, (), lines)
    return data, lines, text


def _collect_lines(path: Path, node: yaml.Node, prefix: KeyPath, lines: dict[KeyPath, int]) -> None:
    if isinstance(node, yaml.MappingNode):
        seen: set[str] = set()
        for key_node, value_node in node.value:
            key = str(key_node.value)
            line = key_node.start_mark.line + 1
            if key in seen:
                dotted = format_key(prefix + (key,))
                raise ConfigError(f"{path}:{line}: {dotted}: duplicate key")
            seen.add(key)
            lines[prefix + (key,)] = line
            _collect_lines(path, value_node, prefix + (key,), lines)
    elif isinstance(node, yaml.SequenceNode):
        for index, item in enumerate(node.value):
            lines[prefix + (index,)] = item.start_mark.line + 1
            _collect_lines(path, item, prefix + (index,), lines)


def format_key(key_path: KeyPath) -> str:
    """`('schedule', 'angles_deg', 3)` → `schedule.angles_deg[3]`."""
    text = ""
    for part in key_path:
        text += f"[{part}]" if isinstance(part, int) else (f".{part}" if text else str(part))
    return text or "(top level)"


def locate(lines: dict[KeyPath, int], loc: tuple[Any, ...]) -> tuple[KeyPath, int]:
    """Map a validation location to the deepest key present in the file and its line.

    Location parts that are not keys of the file (a union member's tag, say) are skipped, so
    `('schedule', 'sphere', 'count')` finds `schedule.count`. A missing key (the last part) is named
    with its parent's line.
    """
    matched: KeyPath = ()
    shown: KeyPath = ()
    for position, part in enumerate(loc):
        candidate = matched + (part,)
        if candidate in lines:
            matched = candidate
            shown = candidate
        elif position == len(loc) - 1 and isinstance(part, str):
            shown = shown + (part,)
    return shown, lines.get(matched, 1)
