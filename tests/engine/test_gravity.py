"""The site's gravity: references, the simulated lab and the fit all use it, in standard g."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from accelcal_rig.assembly import run_campaign
from accelcal_rig.core.units import STANDARD_GRAVITY_M_S2
from accelcal_rig.engine.preparation import prepare
from accelcal_rig.fit.calibration import apply, load_calibration
from accelcal_rig.fit.campaign_fit import FitOptions, fit_campaign
from accelcal_rig.store.read import load_campaign
from tests.conftest import TINY_PROCEDURE


def campaign_at(write, workdir: Path, gravity: str, name: str) -> Path:
    (workdir / f"{name}.yaml").write_text((workdir / "sim.yaml").read_text() + gravity)
    procedure = write(f"{name}-p.yaml", TINY_PROCEDURE.replace("rig: sim.yaml", f"rig: {name}.yaml"))
    output = workdir / f"{name}.h5"
    run_campaign(prepare(procedure), output, dry_run=True, seed=3, overwrite=False,
                 calibration=workdir / f"{name}.cal.yaml")
    return output


@pytest.mark.parametrize("mode", ["reference", "norm-only"])
def test_a_site_with_stronger_gravity_reads_more_than_1_g_and_is_fitted_to_it(write, workdir: Path, mode: str) -> None:
    output = campaign_at(write, workdir, "gravity_m_s2: 9.8123\n", f"site-{mode}")
    campaign = load_campaign(output)
    site_g = 9.8123 / STANDARD_GRAVITY_M_S2
    references = np.linalg.norm(campaign.channel_column(campaign.serials[0], "accel", "reference"), axis=1)
    truths = np.linalg.norm(campaign.truth_column(campaign.serials[0], "gravity_g"), axis=1)
    np.testing.assert_allclose(references, site_g, rtol=1e-12)
    np.testing.assert_allclose(truths, site_g, rtol=1e-9)  # no uncertainty stated: the site is as stated
    assert campaign.unusable_reasons() == []  # references as long as the site's gravity are plausible, not damage
    free = "all" if mode == "reference" else "bias-scale"  # six poses: norm-only sees bias and scale only
    _, report = fit_campaign(campaign, FitOptions(mode=mode, degree=0, free=free), {"campaign": str(output)})
    for dut in report.values():  # 0.29 mg of |g| would remain if the fit aimed at 1 g
        r = dut["channels"]["accel"]
        assert r["rmse_after_mg"] < 2 * r["noise_floor_mg"] < 0.1 and r["gravity_m_s2"] == pytest.approx(9.8123)
    sensor = load_calibration(workdir / f"site-{mode}.cal.yaml").channel(campaign.serials[0], "accel")
    raw = campaign.channel_column(campaign.serials[0], "accel", "mean")
    temperature = campaign.dut_column(campaign.serials[0], "temperature_c").mean(axis=1)
    compensated = np.linalg.norm(apply(sensor, raw, np.clip(temperature, *sensor.validity_c)), axis=1)
    assert np.mean(compensated) == pytest.approx(site_g, abs=2e-5)


def test_a_stated_uncertainty_is_drawn_for_the_simulated_site(write, workdir: Path) -> None:
    output = campaign_at(write, workdir, "gravity_m_s2: 9.8123\ngravity_uncertainty_m_s2: 0.001\n", "uncertain")
    campaign = load_campaign(output)
    truth = float(np.linalg.norm(campaign.truth_column(campaign.serials[0], "gravity_g"), axis=1).mean())
    stated = 9.8123 / STANDARD_GRAVITY_M_S2
    assert truth != pytest.approx(stated, abs=1e-9) and abs(truth - stated) < 5 * 0.001 / STANDARD_GRAVITY_M_S2
    assert float(campaign.attrs["gravity_uncertainty_m_s2"]) == 0.001
