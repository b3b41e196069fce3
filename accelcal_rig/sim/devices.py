"""In-process simulated instruments backed by the virtual lab, implementing the driver interfaces.

A test double: the engine's tests break them on purpose (wrong identity, stuck chamber, failing
port) without a wire in between. Dry runs do not use them: they go through the real drivers and the
wire-level simulators (`sim/wire_rig.py`). `SimulationTruth` serves both.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from accelcal_rig.config.procedure import Procedure
from accelcal_rig.config.rig import RigConfig
from accelcal_rig.core.clock import Clock
from accelcal_rig.errors import InstrumentError
from accelcal_rig.fit.gyro_model import PARAMETER_NAMES as GYRO_PARAMETER_NAMES
from accelcal_rig.fit.sfem import PARAMETER_NAMES
from accelcal_rig.instruments.interfaces import DeviceIdentity, RigInstruments, SampleBlock
from accelcal_rig.sim.lab import VirtualLab
from accelcal_rig.sim.truth import HALF_RANGE_C, T_REF_C

ENDPOINT = "in-process virtual lab"


class SimulatedChamber:
    endpoint = ENDPOINT

    def __init__(self, lab: VirtualLab) -> None:
        self._lab = lab

    @property
    def lab(self) -> VirtualLab:
        """The virtual lab behind it (its clock, its truth): for tests and fault injection."""
        return self._lab

    def identify(self) -> str:
        return "simulated thermal chamber"

    def read_temperature_c(self) -> float:
        return self._lab.chamber_reading_c()

    def write_setpoint_c(self, setpoint_c: float) -> None:
        self._lab.thermal.set_setpoint(self._lab.clock.now(), setpoint_c)

    def read_setpoint_c(self) -> float:
        return self._lab.thermal.setpoint_c

    def alarm_active(self) -> bool:
        return False

    def controller_limits_c(self) -> tuple[float, float] | None:
        return self._lab.controller_limits_c

    def set_power(self, on: bool) -> None:
        self._lab.thermal.set_power(self._lab.clock.now(), on)

    def close(self) -> None:
        """Nothing to release: the lab lives in this process."""


class SimulatedTurntable:
    endpoint = ENDPOINT

    def __init__(self, lab: VirtualLab) -> None:
        self._lab = lab

    def identify(self) -> str:
        return f"simulated {len(self._lab.kinematics.axes)}-axis turntable"

    def move_to(self, angles_deg: np.ndarray) -> None:
        self._lab.motion.command(self._lab.clock.now(), angles_deg)

    def read_angles_deg(self) -> np.ndarray:
        return self._lab.motion.position_deg(self._lab.clock.now())

    def in_position(self) -> bool:
        return self._lab.motion.in_position(self._lab.clock.now())

    def stop(self) -> None:
        self._lab.motion.stop(self._lab.clock.now())

    def rotate_at(self, axis: int, rate_deg_s: float, acceleration_deg_s2: float) -> None:
        self._lab.motion.rotate(self._lab.clock.now(), axis, rate_deg_s, acceleration_deg_s2)

    def read_rate_deg_s(self, axis: int) -> float:
        return self._lab.motion.read_rate_deg_s(self._lab.clock.now(), axis)

    def hold(self, axis: int) -> None:
        self._lab.motion.hold(self._lab.clock.now(), axis)

    def close(self) -> None:
        """Nothing to release: the lab lives in this process."""


class SimulatedAccelerometer:
    """A DUT (of its rig config's part) whose samples come from its hidden truth, the table's true angles and
    white noise: its accelerometer, and its gyroscope where the part has one (the test double's IMU)."""

    endpoint = ENDPOINT
    capture_capacity_samples = 0  # read one thread per DUT, as a host draining FIFOs would

    def __init__(self, lab: VirtualLab, index: int) -> None:
        self._lab = lab
        self._index = index
        self.serial = lab.duts[index].serial
        self.part = lab.duts[index].part
        self._range_g: float = self.part.channel("accel").ranges[0]
        self._ranges: dict[str, float] = {c.name: c.ranges[0] for c in self.part.channels}
        self._odr_hz = 125.0
        self._measuring = False

    @property
    def measuring(self) -> bool:
        """Whether it measures (not in standby): what the safe state must leave False."""
        return self._measuring

    def identify(self) -> DeviceIdentity:
        return DeviceIdentity(self.part.identity, 1)

    def reset(self) -> None:
        self._measuring = False
        self._range_g, self._odr_hz = self.part.channel("accel").ranges[0], self.part.output_data_rates_hz[0]  # the reset state
        self._ranges = {c.name: c.ranges[0] for c in self.part.channels}

    def configure(self, ranges: Mapping[str, float], odr_hz: float) -> None:
        if self._measuring:
            raise InstrumentError(f"sensor {self.serial}: range and filter can only change in standby")
        self._range_g = ranges["accel"]
        self._ranges = {c.name: ranges[c.name] for c in self.part.channels}
        self._odr_hz = odr_hz

    def start_measurement(self) -> None:
        self._measuring = True

    def standby(self) -> None:
        self._measuring = False

    def read_settings(self) -> tuple[dict[str, float], float]:
        return dict(self._ranges), self._odr_hz

    def read_temperature_c(self) -> float:
        return self._lab.dut_reading_c(self._index)

    def noise_g(self) -> float:
        return self._lab.noise_g(self._index, self._odr_hz)

    def acquire(self, n_samples: int) -> SampleBlock:
        if not self._measuring:
            raise InstrumentError(f"sensor {self.serial}: acquire while in standby")
        clock = self._lab.clock
        temperature_before = self.read_temperature_c()
        t_start = clock.now()
        clock.sleep(n_samples / self._odr_hz)
        codes = {"accel": self._lab.dut_samples(self._index, t_start, n_samples, self._odr_hz, self._range_g)}
        if "gyro" in self._ranges:  # the table's rate at the end of the block: a rate step holds it constant
            codes["gyro"] = self._lab.dut_gyro_samples(self._index, t_start, n_samples, self._odr_hz,
                                                       self._ranges["gyro"])
        return SampleBlock(codes, t_start, t_start + (n_samples - 1) / self._odr_hz,
                           (temperature_before, self.read_temperature_c()))

    def close(self) -> None:
        """Nothing to release: the lab lives in this process."""


class SimulationTruth:
    """The hidden truth of a simulated rig, for the campaign file's `simulation_truth` group."""

    def __init__(self, lab: VirtualLab) -> None:
        self._lab = lab
        self._index = {d.serial: i for i, d in enumerate(lab.duts)}

    def describe(self, serial: str, odr_hz: float) -> dict[str, np.ndarray | str | float]:
        dut = self._lab.duts[self._index[serial]]
        return {
            "polynomial_coefficients": dut.truth.coefficients,
            "parameter_names": ",".join(PARAMETER_NAMES),
            "t_ref_c": T_REF_C,
            "half_range_c": HALF_RANGE_C,
            "fixture_time_constant_s": dut.tau_s,
            "noise_g_per_sample": self._lab.noise_g(self._index[serial], odr_hz),
            **self._gyro(serial, odr_hz),
            **self._mag(serial, odr_hz),
        }

    def _mag(self, serial: str, odr_hz: float) -> dict[str, np.ndarray | str | float]:
        """A magnetometer's hidden model (Eq. 1's parameters, the bias in gauss) and the site's true field."""
        index = self._index[serial]
        dut = self._lab.duts[index]
        if dut.mag_truth is None:
            return {}
        return {"mag_polynomial_coefficients": dut.mag_truth.coefficients,
                "mag_noise_gauss_per_sample": self._lab.mag_noise_gauss(index, odr_hz),
                "field_world_gauss": np.asarray(self._lab.field_world_gauss, dtype=float)}

    def _gyro(self, serial: str, odr_hz: float) -> dict[str, np.ndarray | str | float]:
        """A gyroscope's hidden model beside the accelerometer's (fit.gyro_model's parameters, the same cubics)."""
        index = self._index[serial]
        dut = self._lab.duts[index]
        if dut.gyro_truth is None:
            return {}
        return {"gyro_polynomial_coefficients": dut.gyro_truth.coefficients,
                "gyro_parameter_names": ",".join(GYRO_PARAMETER_NAMES),
                "gyro_noise_dps_per_sample": self._lab.gyro_noise_dps(index, odr_hz),
                "gyro_bias_instability_dph": 3600.0 * float(self._lab.bias_wander[index].sigma > 0)
                * self._lab.gyro_bias_instability_dps,
                "earth_rate_world_dps": np.asarray(self._lab.earth_rate_world_dps, dtype=float),
                # Each range's sensitivity relative to the widest's: (ranges, δ per axis).
                "gyro_range_scale": np.array([[r, *d] for r, d in sorted(dut.gyro_range_scale.items())])}

    def block_truth(self, serial: str, block: SampleBlock) -> dict[str, np.ndarray]:
        return self._lab.truth_between(self._index[serial], block.t_start_s, block.t_end_s)


def build_simulated_rig(rig: RigConfig, procedure: Procedure, clock: Clock, seed: int) -> RigInstruments:
    """The whole rig as in-process simulations on `clock`, reproducible for a given `seed`; the procedure
    may switch on sensor effects beyond Eq. 1."""
    lab = VirtualLab(rig, clock, seed, procedure.simulation)
    sensors = [SimulatedAccelerometer(lab, i) for i in range(len(lab.duts))]
    return RigInstruments(SimulatedChamber(lab), SimulatedTurntable(lab), list(sensors), SimulationTruth(lab))
