"""What a new campaign file records about itself before the first step: the procedure and rig as written,
the plan, the DUTs and their parts (whose each is, when it arrived and in what condition), the instruments by
make, model and serial, the laboratory, the references and their certificates, the fit options, and in a dry
run the simulation's truth: what a certificate states, read from the campaign rather than from today's
config files."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from accelcal_rig.config.lab import Receipt, ReferenceConfig
from accelcal_rig.config.procedure import Procedure
from accelcal_rig.config.rig import RigConfig, SensorConfig
from accelcal_rig.config.traceability import expected_references
from accelcal_rig.engine.connection import ConnectedRig
from accelcal_rig.engine.preparation import PreparedCampaign
from accelcal_rig.fit.recorded_options import options_attrs
from accelcal_rig.instruments.interfaces import RigInstruments
from accelcal_rig.parts.part import odr_hz_of
from accelcal_rig.plan.compile import Plan
from accelcal_rig.plan.steps import Measurement
from accelcal_rig.store.records import ChannelInfo, StoredPlan
from accelcal_rig.store.writer import CampaignWriter


def instrument_info(instruments: RigInstruments, rig: RigConfig) -> dict[str, dict[str, str]]:
    """Each instrument as the run reached it (driver, endpoint: for the lab) and as the rig config names it
    (make, model, serial: for a certificate)."""
    return {
        name: {"driver": type(reached).__name__, "endpoint": reached.endpoint,
               "make": config.make, "model": config.model, "serial": config.serial}
        for name, reached, config in (("chamber", instruments.chamber, rig.chamber),
                                      ("turntable", instruments.turntable, rig.turntable))
    }


def reference_info(rig: RigConfig) -> dict[str, dict[str, str]]:
    """Each reference the rig's campaigns rely on, as its certificate states it ({}: not stated in the rig config)."""
    def info(reference: ReferenceConfig | None) -> dict[str, str]:
        if reference is None:
            return {}
        return {"certificate": reference.certificate, "issuer": reference.issuer,
                "due_date": reference.due_date.isoformat(), "make": reference.make, "model": reference.model,
                "serial": reference.serial}

    return {key: info(getattr(rig.references, key)) for key in expected_references(rig)}


def receipt_info(sensor: SensorConfig, default: Receipt) -> dict[str, str]:
    """Whose the DUT is, their contact, when it was received and in what condition: its fixture entry's, else the campaign's
    (`rig run --customer` …); "" for what neither states."""
    received = sensor.received_date or default.received_date
    return {"customer": sensor.customer or default.customer, "contact": sensor.contact or default.contact,
            "received_date": received.isoformat() if received else "",
            "condition": sensor.condition or default.condition, "lot": sensor.lot or default.lot}


def create_campaign_file(prepared: PreparedCampaign, output: Path, connected: ConnectedRig, *,
                 dry_run: bool, seed: int, overwrite: bool) -> CampaignWriter:
    rig, instruments, clock = prepared.rig, connected.instruments, connected.clock
    procedure = prepared.procedure.model
    acquisition = procedure.acquisition
    mounts = {s.serial: s for s in rig.model.fixture.sensors}
    duts = [
        {"serial": s.serial, "name": mounts[s.serial].name, "mount_euler_deg": list(mounts[s.serial].mount_euler_deg),
         "part": s.part.name, "odr_hz": odr_hz_of(s.part, acquisition.odr_hz), "driver": type(s).__name__, "endpoint": s.endpoint,
         **receipt_info(mounts[s.serial], prepared.receipt)}
        for s in instruments.sensors
    ]
    ranges = acquisition.ranges
    channels = {s.serial: tuple(ChannelInfo(c.name, c.quantity, c.unit, c.axes, ranges[c.name], c.lsb(ranges[c.name]))
                                for c in s.part.channels) for s in instruments.sensors}
    truth = ({s.serial: instruments.truth.describe(s.serial, odr_hz_of(s.part, acquisition.odr_hz)) for s in instruments.sensors}
             if instruments.truth is not None else {})
    lab = rig.model.lab
    attrs = {"procedure_name": procedure.name, "procedure_version": procedure.version,
             "procedure_path": str(prepared.procedure.path.resolve()),
             "rig_name": rig.model.name, "rig_path": str(rig.path.resolve()), "dry_run": dry_run, "seed": seed,
             "clock": clock.kind, "samples_per_pose": acquisition.samples_per_pose,
             "gravity_m_s2": rig.model.gravity_m_s2, "gravity_uncertainty_m_s2": rig.model.gravity_uncertainty_m_s2,
             "chamber_profile": prepared.chamber_profile or "",
             "lab_name": lab.name if lab else "", "lab_address": lab.address if lab else "",
             "place_of_calibration": lab.place_of_calibration if lab else "",
             "follow_up": prepared.follow_up, **fit_attrs(procedure)}
    return CampaignWriter.create(
        output, {"attrs": attrs, "procedure_yaml": prepared.procedure.text, "rig_yaml": rig.text,
                 "plan": stored_plan(prepared.plan), "duts": duts, "instruments": instrument_info(instruments, rig.model),
                 "references": reference_info(rig.model),
                 "turntable_accuracy_arcsec": rig.model.turntable.accuracy_arcsec, "truth": truth,
                 "channels": channels},
        overwrite=overwrite, storage=prepared.storage(dry_run))


def stored_plan(plan: Plan) -> StoredPlan:
    records, n_axes = plan.records, len(plan.axis_names)
    poses = [s.pose if isinstance(s, Measurement) else None for s in records]
    return StoredPlan(
        step_key=tuple(s.key for s in records), kind=tuple(s.stored_kind for s in records),
        setpoint_c=np.array([s.setpoint_c for s in records], dtype=float),
        pose_number=np.array([p.number if p else 0 for p in poses], dtype=np.int64),
        angles_deg=np.array([p.angles_deg if p else (np.nan,) * n_axes for p in poses], dtype=float).reshape(
            len(records), n_axes),
        gravity_fixture=np.array([p.gravity_fixture if p else (np.nan,) * 3 for p in poses], dtype=float),
        fingerprint=plan.fingerprint, axis_names=tuple(plan.axis_names))


def fit_attrs(procedure: Procedure) -> dict[str, object]:
    fit = procedure.fit
    return options_attrs(fit.mode, fit.polynomial_degree, fit.parameters, fit.out_of_range, fit.temperature_model,
                         fit.hysteresis)
