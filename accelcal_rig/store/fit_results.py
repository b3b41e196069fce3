"""The `fit/` group of a campaign file: replaced whole on every fit, never touching measured data."""

from __future__ import annotations

import json
from typing import Any

import h5py
import numpy as np

from accelcal_rig.store.atomic import signals_deferred
from accelcal_rig.store.campaign_file import TEXT, utc_now


def write_fit_group(file: h5py.File, attrs: dict[str, Any], per_dut: dict[str, dict[str, Any]]) -> None:
    """Replace `fit/` with these results. `per_dut[serial]` holds arrays and a JSON-able `metrics` dict."""
    with signals_deferred():
        if "fit" in file:
            del file["fit"]
        group = file.create_group("fit")
        group.attrs.update({"created": utc_now(), **attrs})
        for serial, results in per_dut.items():
            dut = group.create_group(serial)
            for name, value in results.items():
                if name == "metrics":
                    dut.create_dataset("metrics_json", data=json.dumps(value), dtype=TEXT)
                elif name == "polynomial_domain_c":
                    dut.attrs[name] = np.asarray(value)
                else:
                    dut.create_dataset(name, data=np.asarray(value))
        file.flush()
