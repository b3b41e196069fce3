"""docs/procedures.md documents every key the models accept."""

import typing

from pydantic import BaseModel

from accelcal_rig.config.procedure import Procedure
from accelcal_rig.config.rig import RigConfig
from tests.conftest import REPO


def keys(model: type[BaseModel], prefix: str = "") -> set[str]:
    """Dotted leaf keys (`soak.band_c`, `turntable.axes[].name`); sections themselves are headings."""
    found = set()
    for name, field in model.model_fields.items():
        key = f"{prefix}{name}"
        annotation = field.annotation
        is_list = typing.get_origin(annotation) is list
        submodels = [
            inner
            for member in typing.get_args(annotation) or (annotation,)
            for inner in typing.get_args(member) or (member,)
            if isinstance(inner, type) and issubclass(inner, BaseModel)
        ]
        if not submodels:
            found.add(key)
        for submodel in submodels:
            found |= keys(submodel, f"{key}[]." if is_list else f"{key}.")
    return found


def test_every_procedure_and_rig_key_is_documented() -> None:
    doc = (REPO / "docs" / "procedures.md").read_text()
    missing = sorted(k for k in keys(Procedure) | keys(RigConfig) if f"`{k}`" not in doc)
    assert not missing, f"undocumented keys: {missing}"


def test_every_numeric_key_has_its_range_in_the_docs() -> None:
    from tests.config.bounds import numeric_keys, shown

    doc = (REPO / "docs" / "procedures.md").read_text()
    ranges = doc[doc.index("### Ranges"):doc.index("## Procedure")]
    missing = [f"`{key}` {shown(limits)}" for model in (Procedure, RigConfig) for key, _, limits in numeric_keys(model)
               if shown(limits) and f"`{key}` {shown(limits)}" not in " ".join(ranges.split())]
    assert not missing, f"ranges missing or wrong in docs/procedures.md: {missing}"
