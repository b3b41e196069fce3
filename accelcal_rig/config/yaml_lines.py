"""YAML loading that remembers the line of every key, so validation errors can say `file:line: key`.

A config file is small and written by a person; anything else is refused before it can cost time or
memory: files over `MAX_FILE_BYTES`, characters YAML does not allow (a null byte), nesting deeper than
`MAX_DEPTH`, more than `MAX_NODES` values once aliases are expanded (an alias bomb), an alias that
contains itself, numbers longer than `MAX_NUMBER_CHARS` characters.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import yaml

from accelcal_rig.durable import read_regular_file
from accelcal_rig.errors import ConfigError

KeyPath = tuple[str | int, ...]

MAX_FILE_BYTES = 1 << 20
MAX_DEPTH = 32
MAX_NODES = 100_000


class PersonLoader(yaml.SafeLoader):
    """A person's file: a date is read as its text, so the model validating it names the key and line of a bad
    one (`due_date: 2025-13-01`) instead of the YAML parser failing on it at line 1; and a number is read as
    YAML 1.2 (and JSON, and every calculator) reads one, not as PyYAML's YAML 1.1 does (docs/procedures.md,
    "Numbers")."""


_INT = "tag:yaml.org,2002:int"
_FLOAT = "tag:yaml.org,2002:float"
#: YAML 1.2 core schema integers: decimal (a leading zero is still decimal: 010 is ten, where YAML 1.1
#: reads octal eight), 0o octal, 0x hexadecimal. No `2_0` (YAML 1.1: 20) and no base 60 (`1:30`, YAML 1.1:
#: 90): those stay text, which a number's key refuses.
YAML12_INT = re.compile(r"^(?:[-+]?[0-9]+|0o[0-7]+|0x[0-9a-fA-F]+)$")
#: YAML 1.2 core schema floats: an exponent needs neither a point nor a sign (`1e3`, `1.0e3`, which YAML 1.1
#: reads as text), and .inf/.nan (which the models refuse by name).
YAML12_FLOAT = re.compile(r"^(?:[-+]?(?:\.[0-9]+|[0-9]+(?:\.[0-9]*)?)(?:[eE][-+]?[0-9]+)?"
                          r"|[-+]?\.(?:inf|Inf|INF)|\.(?:nan|NaN|NAN))$")


def _construct_int(loader: yaml.SafeLoader, node: yaml.ScalarNode) -> int:
    """A YAML 1.2 integer (PyYAML's own constructor would read 010 as octal)."""
    text = str(loader.construct_scalar(node))
    if text.startswith(("0x", "0o")):
        return int(text[2:], 16 if text[1] == "x" else 8)
    return int(text, 10)


PersonLoader.yaml_implicit_resolvers = {
    first: [(tag, pattern) for tag, pattern in resolvers if tag not in (_INT, _FLOAT)]
    for first, resolvers in yaml.SafeLoader.yaml_implicit_resolvers.items()
}
PersonLoader.add_implicit_resolver(_INT, YAML12_INT, list("-+0123456789"))
PersonLoader.add_implicit_resolver(_FLOAT, YAML12_FLOAT, list("-+0123456789."))
PersonLoader.add_constructor(_INT, _construct_int)
PersonLoader.add_constructor("tag:yaml.org,2002:timestamp", PersonLoader.construct_yaml_str)


@dataclass(frozen=True)
class YamlLimits:
    """How large a file of one kind may be: what a person writes (procedures, rig configs) or what the
    program writes (a calibration of many DUTs over many setpoints)."""

    file_bytes: int
    nodes: int
    #: Parse with libyaml where PyYAML has it: a program-written file may hold megabytes (a 64-DUT
    #: calibration is 2 MB, 15 s in the pure-Python parser); a person's file keeps PyYAML's messages.
    machine_written: bool = False

    @property
    def loader(self) -> type:
        return getattr(yaml, "CSafeLoader", yaml.SafeLoader) if self.machine_written else PersonLoader


CONFIG_LIMITS = YamlLimits(MAX_FILE_BYTES, MAX_NODES)
CALIBRATION_LIMITS = YamlLimits(64 << 20, 5_000_000, machine_written=True)
MAX_SCALAR_CHARS = 65_536
MAX_NUMBER_CHARS = 40
#: Characters YAML 1.1 forbids in a stream (PyYAML's reader would refuse them with a two-line message).
_NOT_ALLOWED = re.compile("[^\x09\x0a\x0d\x20-\x7e\x85\xa0-\ud7ff\ue000-\ufffd\U00010000-\U0010ffff]")
_NUMBER_TAGS = frozenset({"tag:yaml.org,2002:int", "tag:yaml.org,2002:float"})


def _line_of(text: str, index: int) -> int:
    return text.count("\n", 0, index) + 1


def _check_events(text: str, where: str, limits: YamlLimits) -> None:
    """One pass over the event stream (PyYAML's parser is not recursive): syntax, depth, sizes."""
    depth = count = 0
    try:
        for event in yaml.parse(text, Loader=limits.loader):
            count += 1
            line = event.start_mark.line + 1 if event.start_mark else 1
            if count > limits.nodes:
                raise ConfigError(f"{where}:{line}: more than {limits.nodes} values: not a config file")
            if isinstance(event, yaml.CollectionStartEvent):
                depth += 1
                if depth > MAX_DEPTH:
                    raise ConfigError(f"{where}:{line}: nested more than {MAX_DEPTH} levels deep")
            elif isinstance(event, yaml.CollectionEndEvent):
                depth -= 1
            elif isinstance(event, yaml.ScalarEvent) and len(event.value) > MAX_SCALAR_CHARS:
                raise ConfigError(f"{where}:{line}: a value of {len(event.value)} characters (at most {MAX_SCALAR_CHARS})")
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark or exc.context_mark
        line = mark.line + 1 if mark is not None else 1
        problem = (exc.problem or exc.context or "invalid YAML").strip()
        raise ConfigError(f"{where}:{line}: syntax: {problem}") from None
    except yaml.YAMLError as exc:
        raise ConfigError(f"{where}:1: syntax: {str(exc).splitlines()[0]}") from None


def _check_expansion(root: yaml.Node, where: str, limits: YamlLimits) -> None:
    """Count the values the document holds with its aliases expanded, without expanding them."""
    sizes: dict[int, tuple[int, int]] = {}  # node id → (values, depth) once counted
    visiting: set[int] = set()

    def size(node: yaml.Node, depth: int) -> tuple[int, int]:
        key = id(node)
        line = node.start_mark.line + 1
        if key in sizes:
            if depth + sizes[key][1] > MAX_DEPTH:
                raise ConfigError(f"{where}:{line}: nested more than {MAX_DEPTH} levels deep (through aliases)")
            return sizes[key]
        if key in visiting:
            raise ConfigError(f"{where}:{line}: an alias that contains itself")
        if depth > MAX_DEPTH:
            raise ConfigError(f"{where}:{line}: nested more than {MAX_DEPTH} levels deep (through aliases)")
        if isinstance(node, yaml.ScalarNode):
            if node.tag in _NUMBER_TAGS and len(node.value) > MAX_NUMBER_CHARS:
                raise ConfigError(f"{where}:{line}: a number of {len(node.value)} characters (at most {MAX_NUMBER_CHARS})")
            return 1, 0
        visiting.add(key)
        children = [c for pair in node.value for c in pair] if isinstance(node, yaml.MappingNode) else node.value
        total, deepest = 1, 0
        for child in children:
            values, child_depth = size(child, depth + 1)
            total, deepest = total + values, max(deepest, child_depth + 1)
            if total > limits.nodes:
                raise ConfigError(f"{where}:{line}: more than {limits.nodes} values once its aliases are expanded")
        visiting.discard(key)
        sizes[key] = (total, deepest)
        return sizes[key]

    size(root, 0)


def parse_yaml_text(text: str, where: str) -> Any:
    """The data of one YAML document, within the bounds above; ConfigError `where:line: problem`."""
    return _parse(text, where, CONFIG_LIMITS)[0]


def _parse(text: str, where: str, limits: YamlLimits) -> tuple[Any, yaml.Node | None]:
    bad = _NOT_ALLOWED.search(text)
    if bad:
        raise ConfigError(f"{where}:{_line_of(text, bad.start())}: syntax: character U+{ord(bad.group()):04X} is "
                          "not allowed in YAML")
    _check_events(text, where, limits)
    loader = limits.loader(text)
    try:
        root = loader.get_single_node()
        if root is None:
            return None, None
        _check_expansion(root, where, limits)
        return loader.construct_document(root), root
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark or exc.context_mark
        line = mark.line + 1 if mark is not None else 1
        problem = (exc.problem or exc.context or "invalid YAML").strip()
        raise ConfigError(f"{where}:{line}: syntax: {problem}") from None
    except (yaml.YAMLError, ValueError, TypeError, OverflowError) as exc:
        raise ConfigError(f"{where}:1: syntax: {str(exc).splitlines()[0] if str(exc) else type(exc).__name__}") from None
    finally:
        loader.dispose()


def load_yaml_with_lines(path: Path, limits: YamlLimits = CONFIG_LIMITS) -> tuple[Any, dict[KeyPath, int], str]:
    """Parse `path`; return (data, {key path: 1-based line}, raw text).

    Syntax errors, duplicate keys (which PyYAML would silently overwrite) and files beyond the bounds
    above become ConfigError.
    """
    raw = read_regular_file(path, limits.file_bytes, "a procedure, rig or calibration file")
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = raw[:exc.start].count(b"\n") + 1
        raise ConfigError(f"{path}:{line}: not UTF-8 text (byte 0x{raw[exc.start]:02x})") from None
    return yaml_text_with_lines(text, path, limits)


def yaml_text_with_lines(text: str, path: Path, limits: YamlLimits = CONFIG_LIMITS) -> tuple[Any, dict[KeyPath, int], str]:
    """As load_yaml_with_lines, for the text of `path` (a file about to be written: checked first)."""
    data, root = _parse(text, str(path), limits)
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
            key = str(key_node.value) if isinstance(key_node, yaml.ScalarNode) else "(complex key)"
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
