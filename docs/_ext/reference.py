"""The site's generated reference: every command's help from the parser, and every procedure and rig-config key
from the models' JSON Schemas (types, units, defaults, limits, what each is for). Written into reference/ at the
start of each build, so the reference is the code's own and cannot fall behind it (the pages are not kept in
git: .gitignore)."""

from __future__ import annotations

import argparse
import json
import os
from pathlib import Path
from typing import Any

from sphinx.application import Sphinx

from accelcal_rig.cli.parser import build_parser
from accelcal_rig.config.schemas import schema

#: A key's unit, read off its name's suffix (the code's rule: units in names).
UNITS = [("_m_s2", "m/s²"), ("_dps2", "°/s²"), ("_dps", "°/s"), ("_c_per_min", "°C/min"), ("_c", "°C"),
         ("_deg", "°"), ("_hz", "Hz"), ("_min", "min"), ("_s", "s"), ("_h", "h"), ("_mg", "mg"), ("_ug", "µg"),
         ("_g", "g"), ("_ppm", "ppm"), ("_pct", "%"), ("_percent", "%"), ("_days", "days"), ("_mgauss", "mgauss"),
         ("_gauss", "gauss"), ("_v", "V"), ("_ms", "ms"), ("_mbar", "mbar"), ("_hpa", "hPa")]
GENERATED = ("commands.md", "procedure.md", "rig-config.md")


def setup(app: Sphinx) -> dict[str, Any]:
    app.connect("config-inited", lambda app, config: write_reference(Path(app.srcdir) / "reference"))
    return {"version": "1", "parallel_read_safe": True}


def write_reference(folder: Path) -> None:
    folder.mkdir(exist_ok=True)
    pages = {"commands.md": commands_page(), "procedure.md": schema_page("procedure", "Procedure keys"),
             "rig-config.md": schema_page("rig-config", "Rig-config keys")}
    for name, text in pages.items():
        path = folder / name
        if not path.exists() or path.read_text(encoding="utf-8") != text:  # unchanged pages keep their time
            path.write_text(text, encoding="utf-8")


# --- commands -------------------------------------------------------------------------------------------------

def commands_page() -> str:
    """Every command's and action's --help, as the parser prints it at 100 columns."""
    os.environ["COLUMNS"] = "100"
    parser = build_parser()
    lines = ["# Commands", "", "Generated from `rig`'s own parser: each section is what `rig COMMAND --help` "
             "prints. Every command ends its help with an example; `rig --version` names the version.", "",
             "```text", parser.format_help().rstrip(), "```", ""]
    for name, sub in _subcommands(parser):
        lines += _command_section(f"rig {name}", sub, level=2)
    return "\n".join(lines) + "\n"


def _subcommands(parser: argparse.ArgumentParser) -> list[tuple[str, argparse.ArgumentParser]]:
    for action in parser._actions:  # noqa: SLF001 - argparse offers no public walk of its subcommands
        if isinstance(action, argparse._SubParsersAction):  # noqa: SLF001
            return list(action.choices.items())
    return []


def _command_section(title: str, parser: argparse.ArgumentParser, level: int) -> list[str]:
    lines = [f"{'#' * level} `{title}`", "", "```text", parser.format_help().rstrip(), "```", ""]
    for name, sub in _subcommands(parser):
        lines += _command_section(f"{title} {name}", sub, level + 1)
    return lines


# --- procedure and rig-config keys ----------------------------------------------------------------------------

def schema_page(kind: str, title: str) -> str:
    """A section per object of the schema (the file itself, then each nested model), a row per key."""
    document = schema(kind)
    definitions = document.get("$defs", {})
    lines = [f"# {title}", "", f"Generated from the models that validate a {kind} (the JSON Schema "
             f"`rig schema {kind}` prints, which editors check files with). A unit is read off the key's name "
             "(`_c` °C, `_s` s, `_dps` °/s …); limits are the bounds the model enforces; a key without a default "
             "must be given.", ""]
    if document.get("description"):
        lines += [_one_line(document["description"]), ""]
    lines += _object_section("The file", document, level=2)
    for name in sorted(definitions):
        lines += _object_section(name, definitions[name], level=2)
    return "\n".join(lines) + "\n"


def _object_section(name: str, node: dict[str, Any], level: int) -> list[str]:
    properties = node.get("properties")
    lines = [f"{'#' * level} {name}", ""]
    if node.get("description") and name != "The file":
        lines += [_one_line(node["description"]), ""]
    if not properties:
        return lines + [f"Type: {_type(node)}.", ""]
    required = set(node.get("required", []))
    lines += ["| key | type | unit | default | limits | what it is |", "|---|---|---|---|---|---|"]
    for key in sorted(properties):
        spec = properties[key]
        default = "required" if key in required else _default(spec)
        lines.append("| " + " | ".join([f"`{key}`", _type(spec), _unit(key), default, _limits(spec),
                                         _cell(spec.get("description", ""))]) + " |")
    extra = node.get("additionalProperties")
    if isinstance(extra, dict):
        lines += ["", f"Other keys: each a {_type(extra)}."]
    return lines + [""]


def _type(spec: dict[str, Any]) -> str:
    if "$ref" in spec:
        target = spec["$ref"].rsplit("/", 1)[-1]
        return f"[{target}](#{_anchor(target)})"
    if "anyOf" in spec or "oneOf" in spec:
        options = [_type(option) for option in spec.get("anyOf", spec.get("oneOf", []))]
        return " or ".join(dict.fromkeys(options))
    if "enum" in spec:
        return " \\| ".join(f"`{_value(value)}`" for value in spec["enum"])
    if "const" in spec:
        return f"`{_value(spec['const'])}`"
    kind = spec.get("type")
    if kind == "array":
        items = spec.get("items")
        return f"list of {_type(items)}" if isinstance(items, dict) and items else "list"
    if kind == "object":
        values = spec.get("additionalProperties")
        return f"map to {_type(values)}" if isinstance(values, dict) and values else "map"
    if kind == "null":
        return "null"
    if spec.get("format") == "date":
        return "date (YYYY-MM-DD)"
    return str(kind) if kind else "any"


def _default(spec: dict[str, Any]) -> str:
    """The default as a user would write it; a section's own defaults are in its section."""
    if "default" not in spec:
        return "—"
    value = spec["default"]
    if isinstance(value, dict) and value:
        return "its keys' defaults"
    return '""' if value == "" else _value(value)


def _limits(spec: dict[str, Any]) -> str:
    found = []
    for option in [spec, *spec.get("anyOf", [])]:
        for key, symbol in (("minimum", "≥"), ("exclusiveMinimum", ">"), ("maximum", "≤"), ("exclusiveMaximum", "<"),
                            ("minItems", "items ≥"), ("maxItems", "items ≤"), ("maxLength", "length ≤")):
            if key in option:
                found.append(f"{symbol} {_value(option[key])}")
        if "pattern" in option:
            found.append(f"matches `{option['pattern']}`")
    return ", ".join(dict.fromkeys(found))


def _unit(key: str) -> str:
    return next((unit for suffix, unit in UNITS if key.endswith(suffix)), "")


def _value(value: Any) -> str:
    text = json.dumps(value, ensure_ascii=False) if not isinstance(value, str) else value
    return _cell(text if len(text) <= 60 else text[:57] + "…")


def _one_line(text: str) -> str:
    return " ".join(text.split())


def _cell(text: str) -> str:
    return _one_line(text).replace("|", "\\|")


def _anchor(title: str) -> str:
    return title.lower().replace(" ", "-")
