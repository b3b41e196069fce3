"""The channel models by quantity: the built-in ones (acceleration, angular rate, magnetic field) and any a package registers
under the entry-point group `accelcal_rig.channel_models` (an entry point's object a `ChannelModel` whose
`quantity` is the entry point's name). A built-in quantity cannot be taken over by a plug-in."""

from __future__ import annotations

from functools import cache
from importlib.metadata import entry_points

from accelcal_rig.errors import ConfigError
from accelcal_rig.fit import acceleration, angular_rate, magnetic_field
from accelcal_rig.fit.calibration import ChannelCalibration
from accelcal_rig.fit.channel_model import ChannelModel

ENTRY_POINT_GROUP = "accelcal_rig.channel_models"
_BUILT_IN: dict[str, ChannelModel] = {model.quantity: model for model in (acceleration.MODEL, angular_rate.MODEL,
                                                                           magnetic_field.MODEL)}


@cache
def channel_models() -> dict[str, ChannelModel]:
    """Every channel model by the quantity it calibrates."""
    found: dict[str, ChannelModel] = {}
    for entry in entry_points(group=ENTRY_POINT_GROUP):
        try:
            model = entry.load()
        except Exception as exc:  # noqa: BLE001 - a broken plug-in is one line naming it, not a traceback
            raise ConfigError(f"channel model plug-in {entry.name!r} ({entry.value}): cannot load: {exc}") from None
        if not (isinstance(model, ChannelModel) and model.quantity == entry.name):
            raise ConfigError(f"channel model plug-in {entry.name!r} ({entry.value}): not a ChannelModel of the "
                              f"quantity {entry.name!r}")
        found[entry.name] = model
    return {**found, **_BUILT_IN}


def model_for_quantity(quantity: str) -> ChannelModel | None:
    """The model that calibrates `quantity`; None where none does."""
    return channel_models().get(quantity)


def known_quantities() -> list[str]:
    return sorted(channel_models())


def model_of(calibration: ChannelCalibration) -> ChannelModel:
    """The model of a channel's calibration (one that validated has one)."""
    model = model_for_quantity(calibration.quantity)
    if model is None:
        raise KeyError(f"no channel model calibrates {calibration.quantity!r}")
    return model
