"""Mutated procedure and rig files: what a careless edit, a bad merge, a damaged disk or a hostile user
could hand `rig`. Each case is reproducible from its number.

A case starts from a shipped procedure and rig, picks one of them, and applies one mutation: a value
replaced with something hostile (non-finite, huge, tiny, of the wrong type, thousands of digits), a key
removed or repeated, a value nested a thousand levels deep, an alias bomb, an alias that contains
itself, bytes flipped, a null byte, the file cut short, padded beyond any config's size, emptied.
"""

from __future__ import annotations

import random
from dataclasses import dataclass
from pathlib import Path

import yaml

REPO = Path(__file__).resolve().parents[2]
PROCEDURES = sorted((REPO / "procedures").glob("*.yaml"))
RIGS = [REPO / "configs" / "sim.yaml", REPO / "configs" / "example-lab.yaml"]

HOSTILE_VALUES = [
    ".inf", "-.inf", ".nan", "1e308", "-1e308", "1e-300", "-1e-300", "0", "-0.0", "-1", "-273.15", "1e9", "-1e9",
    "3" * 5000, "-" + "9" * 400, "0x7fffffffffffffff", "true", "null", "''", "'x'", "[]", "{}", "[1, 2, 3]",
    "{a: 1}", "'" + "x" * 70000 + "'", "[" + ", ".join(["1"] * 2000) + "]", "2026-12-01", "!!binary aGVsbG8=",
    "'\\u0000'", "\"\\0\"", "~", "[.nan, .inf, 1]", "[[1, 2], [3, .inf]]", "1_000_000", "0o777", "+.inf",
]


@dataclass(frozen=True)
class ConfigCase:
    """One mutated pair: the procedure and the rig it names (`rig: rig.yaml`)."""

    number: int
    mutated: str                 # "procedure" or "rig"
    seed: str                    # the shipped file it started from
    mutation: str                # what was done, one line
    procedure: bytes
    rig: bytes

    def write(self, folder: Path) -> Path:
        """Both files into `folder`; returns the procedure's path."""
        folder.mkdir(parents=True, exist_ok=True)
        (folder / "rig.yaml").write_bytes(self.rig)
        (folder / "procedure.yaml").write_bytes(self.procedure)
        return folder / "procedure.yaml"


def _scalar_spans(text: str) -> list[tuple[int, int, bool]]:
    """(start, end, is_key) of every scalar in the document, by character offset."""
    spans: list[tuple[int, int, bool]] = []

    def walk(node: yaml.Node) -> None:
        if isinstance(node, yaml.ScalarNode):
            spans.append((node.start_mark.index, node.end_mark.index, False))
        elif isinstance(node, yaml.MappingNode):
            for key, value in node.value:
                spans.append((key.start_mark.index, key.end_mark.index, True))
                walk(value)
        else:
            for item in node.value:
                walk(item)

    walk(yaml.compose(text, Loader=yaml.SafeLoader))
    return spans


def _bomb(levels: int = 9, width: int = 9) -> str:
    lines = [f"lol0: &lol0 [{', '.join(['lol'] * width)}]"]
    lines += [f"lol{k}: &lol{k} [{', '.join([f'*lol{k - 1}'] * width)}]" for k in range(1, levels + 1)]
    return "\n".join(lines) + "\n"


def mutate(text: str, rng: random.Random) -> tuple[bytes, str]:
    """One mutation of a YAML file's text: (new bytes, what was done)."""
    spans = _scalar_spans(text)
    values = [s for s in spans if not s[2]]
    keys = [s for s in spans if s[2]]
    kind = rng.choices(["value", "value", "value", "value", "key", "structure", "bytes"], k=1)[0]
    if kind == "value":
        start, end, _ = rng.choice(values)
        hostile = rng.choice(HOSTILE_VALUES)
        return (text[:start] + hostile + text[end:]).encode(), f"value {text[start:end]!r} at {start} → {hostile[:40]!r}"
    if kind == "key":
        start, end, _ = rng.choice(keys)
        how = rng.choice(["remove", "rename", "repeat"])
        if how == "remove":
            line_start, line_end = text.rfind("\n", 0, start) + 1, text.find("\n", end)
            line_end = len(text) if line_end == -1 else line_end
            return (text[:line_start] + text[line_end + 1:]).encode(), f"line of key {text[start:end]!r} removed"
        if how == "rename":
            return (text[:start] + "colour" + text[end:]).encode(), f"key {text[start:end]!r} renamed 'colour'"
        line_start, line_end = text.rfind("\n", 0, start) + 1, text.find("\n", end)
        line = text[line_start:line_end if line_end != -1 else len(text)]
        return (text[:line_start] + line + "\n" + text[line_start:]).encode(), f"line of key {text[start:end]!r} repeated"
    if kind == "structure":
        start, end, _ = rng.choice(values)
        how = rng.choice(["deep", "bomb", "self", "bomb-top"])
        if how == "deep":
            depth = rng.choice([40, 200, 5000])
            return (text[:start] + "[" * depth + "1" + "]" * depth + text[end:]).encode(), f"value nested {depth} deep"
        if how == "self":
            return (text[:start] + "&me [*me, 1]" + text[end:]).encode(), "value an alias that contains itself"
        if how == "bomb":
            return (_bomb() + text[:start] + "*lol9" + text[end:]).encode(), "value an alias bomb (9^10 values)"
        return (_bomb(6, 6) + text).encode(), "an alias bomb of unused keys (6^7 values)"
    data = bytearray(text.encode())
    how = rng.choice(["flip", "null", "cut", "pad", "empty", "binary", "tabs", "list"])
    if how == "flip":
        for _ in range(rng.randint(1, 8)):
            data[rng.randrange(len(data))] ^= 1 << rng.randrange(8)
        return bytes(data), "bits flipped"
    if how == "null":
        position = rng.randrange(len(data))
        return bytes(data[:position] + b"\0" + data[position:]), f"a null byte at {position}"
    if how == "cut":
        position = rng.randrange(len(data))
        return bytes(data[:position]), f"cut at byte {position}"
    if how == "pad":
        return bytes(data) + b"#" + b"x" * (2 << 20) + b"\n", "padded with a 2 MiB comment"
    if how == "empty":
        return b"", "emptied"
    if how == "binary":
        return bytes(rng.randrange(256) for _ in range(rng.randint(1, 4096))), "random bytes"
    if how == "tabs":
        return bytes(data).replace(b"  ", b"\t"), "indented with tabs"
    return b"- " + bytes(data).replace(b"\n", b"\n  "), "the whole file a list item"


def config_case(number: int) -> ConfigCase:
    """Case `number`: reproducible, half of them mutate the procedure and half the rig."""
    rng = random.Random(number)
    procedure_path = rng.choice(PROCEDURES)
    rig_path = rng.choice(RIGS)
    procedure = procedure_path.read_text().replace("rig: ../configs/sim.yaml", "rig: rig.yaml")
    rig = rig_path.read_text()
    if number % 2 == 0:
        mutated, description = mutate(procedure, rng)
        return ConfigCase(number, "procedure", procedure_path.name, description, mutated, rig.encode())
    mutated, description = mutate(rig, rng)
    return ConfigCase(number, "rig", rig_path.name, description, procedure.encode(), mutated)
