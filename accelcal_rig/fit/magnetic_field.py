"""The magnetometer's channel model: Eq. 1 against the site's magnetic field (fit/vector_model.py), the bias its
hard-iron offset and M·C·S its soft-iron matrix.

Its reference at a pose is the site's field (the rig config's `magnetic_field`: total intensity, inclination,
declination) turned into the DUT's frame by the commanded pose, the table's heading and the mount. Without the
table's heading (`heading_deg`) only the field's size is known: the magnetometer is then fitted norm-only against
it (whatever the procedure's fit mode), and the figures that need the field's direction are not stated. A dry run
describes its truth (`mag_polynomial_coefficients`), evaluated at each pose's true temperature.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np
import yaml

from accelcal_rig.fit.vector_model import Eq1Model, VectorQuantity
from accelcal_rig.store.content import Campaign
from accelcal_rig.store.read import VectorPoses, described_truth

#: nT per gauss.
NT_PER_GAUSS = 1e5


def site_field(campaign: Campaign) -> tuple[float, float]:
    """The site's field intensity and its standard uncertainty, gauss, as the campaign recorded its rig config."""
    field = _recorded_field(campaign)
    if field is None:
        raise ValueError("the campaign's rig config states no magnetic_field: a magnetometer's reference is unknown")
    return (float(field["total_intensity_nt"]) / NT_PER_GAUSS,
            float(field.get("total_intensity_uncertainty_nt") or 0.0) / NT_PER_GAUSS)


def direction_known(campaign: Campaign) -> bool:
    """Whether the campaign's rig config places the field's direction (it states the table's heading)."""
    return _recorded_rig(campaign).get("heading_deg") is not None


def _recorded_rig(campaign: Campaign) -> dict[str, Any]:
    try:
        rig = yaml.safe_load(campaign.header.rig_yaml) or {}
    except yaml.YAMLError:
        rig = {}
    return rig if isinstance(rig, dict) else {}


def _recorded_field(campaign: Campaign) -> dict[str, Any] | None:
    field = _recorded_rig(campaign).get("magnetic_field")
    return field if isinstance(field, dict) else None


def _described_truth(campaign: Campaign, serial: str, channel: str,
                     poses: VectorPoses) -> tuple[np.ndarray | None, np.ndarray | None]:
    """A dry run's true hard and soft iron at each pose's true temperature (no true field stored per pose)."""
    truth = described_truth(campaign, serial, channel)
    return (None if truth is None else truth[poses.rows]), None


def _statements(figures: Mapping[str, Any]) -> list[tuple[str, str]]:
    field = figures.get("site_magnetic_field")
    if not isinstance(field, dict):
        return []
    text = (f"F = {field['total_intensity_nt']:.0f} nT, inclination {field['inclination_deg']:g}°, declination "
            f"{field['declination_deg']:g}° (the rig config's)")
    if not field.get("direction_known", True):
        text += "; the table's heading not stated: fitted against the field's size alone"
    return [("magnetic field", text)]


MAGNETIC_FIELD = VectorQuantity(
    quantity="magnetic field", sensor="magnetometer", unit="gauss", milli="mgauss", magnitude_label="|B|",
    reference_label="field", magnitude_figure=("field_gauss", 1.0), angle="direction", site=site_field,
    truth=_described_truth, method="Eq. 1, B = M·C·S·(U − b): b the hard-iron offset, M·C·S the soft-iron matrix",
    micro="µgauss", magnitude_source="site's field intensity", size_source="field_intensity",
    angle_label="largest direction error", statements=_statements, c_token="mag",
    paper_departure=", its method applied against the site's magnetic field instead of gravity",
    direction_known=direction_known, site_description=_recorded_field,
)

MODEL = Eq1Model(MAGNETIC_FIELD)
