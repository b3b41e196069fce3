"""The house's layers as pyproject.toml's import-linter contracts state them, checked where import-linter cannot
look: every top-level module and every module of the command line is in its layers contract (a new one outside
it fails here), and the "module:attribute" references parts and drivers hold, which point up the layers on
purpose (a part names its driver and its simulator without importing them), all load, and each is resolved
only by a module at or above the layer of what it names."""

from __future__ import annotations

import ast
import tomllib
from pathlib import Path

import pytest

import accelcal_rig
from accelcal_rig.instruments.definitions import ChamberDriver, SensorDriver, TurntableDriver
from accelcal_rig.parts.registry import known_parts
from accelcal_rig.plugins import GROUPS, drivers, load_driver, load_object

PACKAGE = Path(accelcal_rig.__file__).parent
CONTRACTS = tomllib.loads((PACKAGE.parent / "pyproject.toml").read_text())["tool"]["importlinter"]["contracts"]


def _layers(container: str | None) -> list[list[str]]:
    """Each layer's modules, top first, of the layers contract over `container` (None: the package's own)."""
    contract = next(c for c in CONTRACTS if c["type"] == "layers" and c.get("containers", [None]) == [container])
    return [[name.strip() for name in layer.replace(":", "|").split("|")] for layer in contract["layers"]]


def _modules(folder: Path) -> set[str]:
    """The modules and packages directly inside `folder`, by name (its `__init__` aside)."""
    found = {p.stem for p in folder.glob("*.py") if p.stem != "__init__"}
    return found | {p.name for p in folder.iterdir() if (p / "__init__.py").is_file()}


def _layer_of(module: str) -> int:
    """Where a module of the package stands, 0 the top: the layer of its top-level module."""
    top = ".".join(module.split(".")[:2])
    return next(i for i, layer in enumerate(_layers(None)) if top in layer)


def test_every_top_level_module_is_in_the_layers_contract() -> None:
    named = {name.removeprefix("accelcal_rig.") for layer in _layers(None) for name in layer}
    assert _modules(PACKAGE) - named == set(), "add it to pyproject.toml's layers contract"
    assert named - _modules(PACKAGE) == set(), "the contract names a module that does not exist"


def test_every_module_of_the_command_line_is_in_its_layers_contract() -> None:
    named = {name for layer in _layers("accelcal_rig.cli") for name in layer}
    assert named == _modules(PACKAGE / "cli")


def _references() -> list[tuple[str, str, str]]:
    """(what, "module:attribute", the module that resolves it) of every built-in part and driver."""
    found = []
    for part in known_parts().values():
        found += [(f"part {part.name}'s device", part.device, "accelcal_rig.instruments.connect"),
                  (f"part {part.name}'s simulator", part.simulator, "accelcal_rig.sim.sensor_bridges")]
    for kind in GROUPS:
        for name, reference in drivers(kind).items():  # type: ignore[arg-type]
            found.append((f"{kind} driver {name}", reference, "accelcal_rig.instruments.connect"))
            simulator = load_driver(kind, name).simulator  # type: ignore[arg-type]
            if simulator:
                found.append((f"{kind} driver {name}'s simulator", simulator, "accelcal_rig.sim.wire_rig"))
    return found


@pytest.mark.parametrize(("what", "reference", "resolver"), _references(), ids=lambda v: str(v))
def test_each_reference_loads_and_is_resolved_at_or_above_its_layer(what: str, reference: str, resolver: str) -> None:
    target = load_object(reference, what)
    assert callable(target) or isinstance(target, ChamberDriver | TurntableDriver | SensorDriver), what
    module = reference.partition(":")[0]
    assert _layer_of(resolver) <= _layer_of(module), f"{what}: {resolver} resolves {module}, a layer above it"


def test_only_the_resolvers_resolve_references() -> None:
    """`load_object` and `load_driver` are called where the test above says, nowhere else."""
    callers = set()
    for path in PACKAGE.rglob("*.py"):
        tree = ast.parse(path.read_text(encoding="utf-8"))
        names = {n.func.id for n in ast.walk(tree) if isinstance(n, ast.Call) and isinstance(n.func, ast.Name)}
        if names & {"load_object", "load_driver"} and path.name != "plugins.py":
            callers.add(".".join(path.relative_to(PACKAGE.parent).with_suffix("").parts))
    assert callers <= {"accelcal_rig.instruments.connect", "accelcal_rig.sim.sensor_bridges",
                       "accelcal_rig.sim.wire_rig"}, callers
