"""JSON Schemas of the YAML a user writes — procedures and rig configs — generated from the models that validate
them, so an editor with the YAML language server completes and checks keys as `rig` will (each shipped file
names its schema in its first line: `# yaml-language-server: $schema=…`). The schemas ship in the package
(accelcal_rig/starter/schemas/); `rig schema KIND` prints one, and a test keeps the shipped ones equal to the models."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from pydantic import BaseModel

from accelcal_rig.config.procedure import Procedure
from accelcal_rig.config.rig import RigConfig

#: Each kind of file: its model and the schema's file name in the package.
KINDS: dict[str, tuple[type[BaseModel], str]] = {
    "procedure": (Procedure, "procedure.schema.json"),
    "rig-config": (RigConfig, "rig-config.schema.json"),
}
#: Where the shipped schemas are.
SHIPPED = Path(__file__).resolve().parent.parent / "starter" / "schemas"


def schema(kind: str) -> dict[str, Any]:
    """The JSON Schema (draft 2020-12) of a kind of file, as its model validates it (what it accepts as input:
    a date as text, a number as a number)."""
    model = KINDS[kind][0]
    generated = _bounds_as_keywords(model.model_json_schema(mode="validation"))
    return {"$schema": "https://json-schema.org/draft/2020-12/schema",
            "title": f"accelcal-rig {kind}", **{k: v for k, v in generated.items() if k != "title"}}


#: The bounds of the models' own number types, as pydantic passes them on, and JSON Schema's keyword for each.
_BOUNDS = {"ge": "minimum", "le": "maximum", "gt": "exclusiveMinimum", "lt": "exclusiveMaximum"}


def _bounds_as_keywords(node: Any) -> Any:
    """The schema with a number's `ge`/`le`/`gt`/`lt` (the models' Real and Whole carry their bounds so) written
    as the JSON Schema keywords an editor checks."""
    if isinstance(node, list):
        return [_bounds_as_keywords(item) for item in node]
    if not isinstance(node, dict):
        return node
    numeric = node.get("type") in ("number", "integer")
    return {(_BOUNDS[key] if numeric and key in _BOUNDS else key): _bounds_as_keywords(value)
            for key, value in node.items()}


def schema_text(kind: str) -> str:
    """The schema as the shipped file holds it (sorted keys, two-space indent, a final newline)."""
    return json.dumps(schema(kind), indent=2, sort_keys=True, ensure_ascii=False) + "\n"


def shipped(kind: str) -> Path:
    return SHIPPED / KINDS[kind][1]
