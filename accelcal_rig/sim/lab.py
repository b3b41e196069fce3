"""One virtual lab: the chamber, the turntable and every DUT, all evaluated at the shared clock's time."""

from __future__ import annotations

import hashlib
import threading
from collections import deque
from dataclasses import dataclass

import numpy as np

from accelcal_rig.config.procedure import SimulatedEffects
from accelcal_rig.config.rig import RigConfig
from accelcal_rig.core.clock import Clock
from accelcal_rig.core.earth import earth_rate_world_dps
from accelcal_rig.core.geometry import fixture_to_dut
from accelcal_rig.core.humidity import relative_humidity_pct
from accelcal_rig.core.thermal import TEMPERATURE_READ_NOISE_C, ThermalModel
from accelcal_rig.core.units import site_gravity_g
from accelcal_rig.errors import ConfigError
from accelcal_rig.fit.gyro_model import distort_rate
from accelcal_rig.fit.sfem import distort
from accelcal_rig.parts.part import Part
from accelcal_rig.parts.registry import part
from accelcal_rig.plan.kinematics import TurntableKinematics
from accelcal_rig.sim.bias_wander import BiasWander
from accelcal_rig.sim.moisture import ChamberMoisture
from accelcal_rig.sim.mount_faults import MountFaults
from accelcal_rig.sim.truth import (
    DutTruth,
    fixture_parameters_at,
    gyro_range_scale,
    gyro_truth_for_serial,
    mag_truth_for_serial,
    truth_for_serial,
)
from accelcal_rig.sim.turntable_motion import TurntableMotion

#: The quantity the lab's magnetometers measure (a part's channel of it is fed the site's field).
MAGNETIC_FIELD, ACCELERATION = "magnetic field", "acceleration"


class SimulatedDut:
    """A DUT's part, its place on the fixture, its hidden truth and its own thermal time constant."""

    def __init__(self, serial: str, mount_euler_deg: tuple[float, float, float], tau_s: float,
                 dut_part: Part) -> None:
        self.serial = serial
        self.part = dut_part
        #: A gyroscope's hidden truth, where the part has one (its own seed: the acceleration truth is unchanged).
        self.gyro_truth: DutTruth | None = gyro_truth_for_serial(serial) if "gyro" in dut_part.channel_names else None
        #: Its gyroscope's sensitivity at each range relative to the widest (sim/truth.py).
        self.gyro_range_scale = (gyro_range_scale(serial, tuple(dut_part.channel("gyro").ranges))
                                 if self.gyro_truth is not None else {})
        #: A magnetometer's hidden truth (Eq. 1: hard iron, soft iron), where the part has one.
        self.mag_truth: DutTruth | None = (mag_truth_for_serial(serial) if any(
            c.quantity == MAGNETIC_FIELD for c in dut_part.channels) else None)
        #: The hidden Eq. 1 truth of its first channel, what the campaign file's truth records pose by pose: its
        #: accelerometer's, a magnetometer's where the part has no accelerometer.
        accelerometer = any(c.quantity == ACCELERATION for c in dut_part.channels)
        self.truth: DutTruth = truth_for_serial(serial) if accelerometer or self.mag_truth is None else self.mag_truth
        #: Fixture frame → DUT frame.
        self.fixture_to_dut = fixture_to_dut(mount_euler_deg)
        self.tau_s = tau_s
        # Signs of the unmodelled effects on each axis, fixed per DUT like its truth; the rate terms' sizes
        # spread 0.5…1.5 × the procedure's (parts differ).
        signs = hashlib.sha256(f"effects:{serial}".encode()).digest()
        self.hysteresis_signs = np.array([1.0 if b & 1 else -1.0 for b in signs[:3]])
        self.nonlinearity_signs = np.array([1.0 if b & 1 else -1.0 for b in signs[3:6]])
        self.rate_bias_factors = np.array([(1.0 if b & 1 else -1.0) * (0.5 + (b >> 1) / 127.0) for b in signs[6:9]])
        self.rate_scale_factors = np.array([(1.0 if b & 1 else -1.0) * (0.5 + (b >> 1) / 127.0) for b in signs[9:12]])
        #: (t_start, t_end, n, parameters, gravity, temperature) of recently generated sample chunks.
        self.truth_log: deque[tuple] = deque(maxlen=4096)
        #: (t_start, t_end, n, mean wander °/s per axis) of recently generated gyroscope chunks.
        self.gyro_wander_log: deque[tuple] = deque(maxlen=4096)

    def put_out_of_spec(self, channel: str, bias: float, scale_pct: float) -> None:
        """Make this part's `channel` beyond its data sheet (`simulation.faults.sensor_out_of_spec`): `bias` (in the
        channel's unit) added to each axis's bias and `scale_pct` % to each scale factor, at every temperature.
        Both models put the bias first and the scale factors next (Eq. 1's and the rate-table model's)."""
        if channel not in self.part.channel_names:
            raise ConfigError(f"simulation.faults.sensor_out_of_spec_channel: {channel!r}: {self.serial}'s "
                              f"{self.part.label} has {', '.join(self.part.channel_names)}")
        quantity = self.part.channel(channel).quantity
        truth = self.gyro_truth if quantity == "angular rate" else self.mag_truth if quantity == MAGNETIC_FIELD \
            else self.truth
        assert truth is not None
        coefficients = truth.coefficients.copy()
        coefficients[0:3, 0] += bias
        coefficients[3:6, 0] *= 1.0 + scale_pct / 100.0
        changed = DutTruth(truth.serial, coefficients)
        if quantity == "angular rate":
            self.gyro_truth = changed
        elif quantity == MAGNETIC_FIELD:
            self.mag_truth = changed
        if truth is self.truth:
            self.truth = changed


@dataclass(frozen=True)
class _Instant:
    """The fixture's truth at one time `t_s`, one row per DUT."""

    t_s: float
    temperature_c: np.ndarray  # (n,)
    parameters: np.ndarray     # (n, 12) Eq. 1 parameters
    gravity_g: np.ndarray      # (n, 3) true specific force in each DUT's frame
    reading_g: np.ndarray      # (n, 3) what each reads for it by Eq. 1, before noise and unmodelled effects


@dataclass(frozen=True)
class _Path:
    """The fixture at each sample of a block taken while the table moves, in the fixture frame."""

    angles_deg: np.ndarray        # (n, axes)
    up_fixture: np.ndarray        # (n, 3) unit specific force
    rate_fixture_dps: np.ndarray  # (n, 3) the table's rate and the Earth's


class VirtualLab:
    def __init__(self, rig: RigConfig, clock: Clock, seed: int, effects: SimulatedEffects = SimulatedEffects()) -> None:
        sim = rig.simulation
        self.clock = clock
        self.effects = effects
        #: Simulators answer from their own threads (wire-level servers): one lab, one request at a time.
        self.lock = threading.RLock()
        self.rng = np.random.default_rng(seed)  # chamber and turntable: one request at a time
        # One stream per DUT: sensors read concurrently draw their noise in their own order only; their
        # temperature sensors' noise another, so how often a driver reads temperatures changes no sample.
        self.dut_rngs = [np.random.default_rng([seed, index]) for index in range(len(rig.fixture.sensors))]
        self.temperature_rngs = [np.random.default_rng([seed, index, 1]) for index in range(len(rig.fixture.sensors))]
        #: A gyroscope's noise its own stream, so a six-axis part's acceleration draws are those of its accelerometer
        #: alone, and a rig without gyroscopes draws nothing more.
        self.gyro_rngs = [np.random.default_rng([seed, index, 2]) for index in range(len(rig.fixture.sensors))]
        self.gyro_bias_instability_dps = sim.gyro_bias_instability_dph / 3600.0
        #: Each gyroscope's bias wander (its bias instability), from a stream of its own.
        self.bias_wander = [BiasWander(sim.gyro_bias_instability_dph / 3600.0, np.random.default_rng([seed, index, 3]))
                            for index in range(len(rig.fixture.sensors))]
        self.chamber_noise_c = sim.chamber_noise_c
        self.controller_limits_c = sim.controller_limits_c
        self.kinematics = TurntableKinematics(rig.turntable.axes)
        serials = [s.serial for s in rig.fixture.sensors]
        self.duts = [SimulatedDut(s.serial, s.mount_euler_deg, tau_s, part(s.part))
                     for s, tau_s in zip(rig.fixture.sensors, sim.fixture_time_constants_s(serials))]
        for dut in self.duts:
            if dut.serial == sim.faults.sensor_out_of_spec:
                dut.put_out_of_spec(sim.faults.sensor_out_of_spec_channel, sim.faults.sensor_out_of_spec_bias,
                                    sim.faults.sensor_out_of_spec_scale_pct)
        #: Each DUT's accelerometer's noise density: the rig config's, or its part's (none without an accelerometer).
        self.noise_density_g_per_rthz = [1e-6 * (_accelerometer_noise(d.part) if sim.noise_density_ug_per_rthz
                                                 is None else sim.noise_density_ug_per_rthz) for d in self.duts]
        #: Each magnetometer's noise stream, its own (a rig without magnetometers draws nothing more).
        self.mag_rngs = [np.random.default_rng([seed, index, 4]) for index in range(len(rig.fixture.sensors))]
        self.thermal = ThermalModel(
            ambient_c=sim.ambient_c,
            ramp_rate_c_per_s=rig.chamber.ramp_rate_c_per_min / 60.0,
            chamber_tau_s=sim.chamber_time_constant_min * 60.0,
            dut_tau_s=[d.tau_s for d in self.duts],
            self_heating_c=sim.self_heating_c,
            free_cooling_tau_s=sim.free_cooling_time_constant_min * 60.0,
            overshoot_fraction=sim.chamber_overshoot_pct / 100.0,
            cooling_floor_c=sim.cooling_floor_c,
            slot_offset_per_c=sim.slot_offsets_per_c(len(serials)),
            hysteresis_span_c=effects.hysteresis_span_c,
            hysteresis_time_constant_s=None if effects.hysteresis_time_constant_h is None
            else effects.hysteresis_time_constant_h * 3600.0,
        )
        self.moisture = ChamberMoisture(sim.room_dew_point_c, sim.purge_dew_point_c,
                                        sim.moisture_time_constant_min * 60.0, self.thermal.air_c, clock.now())
        self.motion = TurntableMotion(
            speeds_deg_s=np.array([a.speed_deg_s for a in rig.turntable.axes]),
            accuracy_deg=rig.turntable.accuracy_arcsec / 3600.0,
            settle_s=sim.turntable_settle_s,
            rng=self.rng,
            # A rate table's error and wobble, each its own stream: a rig that never turns at a rate draws
            # nothing more from the others.
            rate_offsets=np.random.default_rng([seed, 1_000_007]).uniform(-1.0, 1.0, len(rig.turntable.axes))
            * (rig.turntable.rate_accuracy_pct or 0.0) / 100.0,
            rate_stability=(rig.turntable.rate_stability_pct or 0.0) / 100.0,
            rate_rng=np.random.default_rng([seed, 1_000_009]),
        )
        #: The acceleration of a rate command that names none (a profile setting it as a limit of its own).
        self.rate_acceleration_deg_s2 = [a.max_acceleration_dps2 or 100.0 for a in rig.turntable.axes]
        #: Each axis's highest commanded rate (°/s; None: no rate mode), a simulated controller's rate limit.
        self.max_rates_deg_s: list[float | None] = [a.max_rate_dps for a in rig.turntable.axes]
        self._gravity_angles_key = b""
        self._gravity_fixture = np.array([0.0, 0.0, 1.0])
        self._truth_coefficients = np.stack([d.truth.coefficients for d in self.duts]) if self.duts \
            else np.zeros((0, 12, 4))
        self._fixture_to_duts = np.stack([d.fixture_to_dut for d in self.duts]) if self.duts else np.zeros((0, 3, 3))
        self._instant_cache: _Instant | None = None
        self._path_cache: tuple[tuple[float, int, float], _Path | None] | None = None
        #: A DUT mounted otherwise than configured, a loose one, a dead axis (`simulation.faults`).
        self.mount_faults = MountFaults(sim.faults, serials, seed)
        #: The simulated site's true gravity in standard g: the rig config's value, off by a draw of its stated
        #: uncertainty (its own stream, so a stated uncertainty of zero changes no other draw).
        draw = np.random.default_rng([seed, 1_000_003]).normal() if rig.gravity_uncertainty_m_s2 > 0 else 0.0
        self.site_gravity_g = site_gravity_g(rig.gravity_m_s2 + rig.gravity_uncertainty_m_s2 * draw)
        #: The Earth's rate in the lab's world frame: at the rig config's site, else the simulation's (the
        #: Earth turns in every lab, whether the rig config says where it is or not).
        heading_deg = sim.heading_deg if rig.heading_deg is None else rig.heading_deg
        self.earth_rate_world_dps = earth_rate_world_dps(
            sim.latitude_deg if rig.latitude_deg is None else rig.latitude_deg, heading_deg)
        #: The site's magnetic field in the lab's world frame, gauss: the rig config's, else the simulation's, off
        #: by a draw of its stated uncertainty (its own stream).
        field = rig.magnetic_field or sim.magnetic_field
        draw = (np.random.default_rng([seed, 1_000_011]).normal() * field.total_intensity_uncertainty_nt
                / field.total_intensity_nt)
        self.field_world_gauss = field.world_gauss(heading_deg) * (1.0 + draw)

    def chamber_reading_c(self) -> float:
        """Chamber air as its controller reads it, with regulation noise."""
        return self.thermal.air_c(self.clock.now()) + float(self.rng.normal(0.0, self.chamber_noise_c))

    def chamber_humidity_pct(self) -> float:
        """The air's relative humidity as the controller's sensor reads it (no noise: it is read rarely)."""
        now = self.clock.now()
        return relative_humidity_pct(self.thermal.air_c(now), self.moisture.dew_point_c(now))

    def dut_true_c(self, index: int) -> float:
        return self.thermal.dut_c(self.clock.now(), index)

    def dut_reading_c(self, index: int) -> float:
        """What the DUT's temperature sensor reports, in °C: its code, converted as its data sheet says."""
        return float(self.duts[index].part.temperature.celsius(self.dut_reading_raw(index)))

    def dut_reading_raw(self, index: int) -> int:
        """The DUT's temperature sensor's code now (true temperature, read noise, the part's format)."""
        noisy = self.dut_true_c(index) + float(self.temperature_rngs[index].normal(0.0, TEMPERATURE_READ_NOISE_C))
        return int(self.duts[index].part.temperature.raw(noisy))

    def unmodelled_g(self, index: int, gravity_g: np.ndarray) -> np.ndarray:
        """What the DUT adds beyond Eq. 1 (zero unless the procedure switches effects on), in g: hysteresis
        by its state, bias and scale by its rate of temperature change, a square law."""
        dut, effects = self.duts[index], self.effects
        hysteresis = 0.5e-3 * effects.hysteresis_mg * self.thermal.hysteresis_state[index] * dut.hysteresis_signs
        rate_c_per_min = 60.0 * float(self.thermal.dut_rate_c_per_s[index])
        rate_bias = 1e-3 * effects.rate_bias_mg_per_c_per_min * rate_c_per_min * dut.rate_bias_factors
        rate_scale = 1e-6 * effects.rate_scale_ppm_per_c_per_min * rate_c_per_min * dut.rate_scale_factors * gravity_g
        nonlinearity = 1e-3 * effects.nonlinearity_mg_per_g2 * dut.nonlinearity_signs * gravity_g**2
        return hysteresis + rate_bias + rate_scale + nonlinearity

    def noise_g(self, index: int, odr_hz: float) -> float:
        """DUT `index`'s per-sample white noise: density × √(equivalent noise bandwidth of the ODR/4 low-pass,
        ×π/2)."""
        return self.noise_density_g_per_rthz[index] * float(np.sqrt(np.pi / 2 * odr_hz / 4))

    def dut_samples(self, index: int, t_start_s: float, n_samples: int, odr_hz: float, range_g: float) -> np.ndarray:
        """`n_samples` codes (n, 3) of DUT `index` from `t_start_s` on, at the DUT's state now (temperature
        changes negligibly within a FIFO's worth; where the table turns through the samples, gravity as each
        sample felt it); the truth behind them is recorded."""
        dut, instant = self.duts[index], self._instant()
        # Copies: the log keeps its rows for hours, not each instant's whole fixture behind them.
        temperature, params = float(instant.temperature_c[index]), instant.parameters[index].copy()
        gravity, reading = instant.gravity_g[index].copy(), instant.reading_g[index]
        path = self._path(t_start_s, n_samples, odr_hz)
        if path is not None:  # a turn changes gravity through the samples: each sample its own
            gravity = self._gravity_along(index, path)
            reading = distort(gravity, params)
        noise = self.dut_rngs[index].normal(0.0, self.noise_g(index, odr_hz), (n_samples, 3))
        reading_g = self.mount_faults.reading_g(index, reading, params[0:3])
        raw_g = reading_g + self.unmodelled_g(index, gravity) + noise
        dut.truth_log.append((t_start_s, t_start_s + n_samples / odr_hz, n_samples, params,
                              gravity if gravity.ndim == 1 else gravity.mean(axis=0), temperature))
        return dut.part.channel("accel").quantise(raw_g, range_g)

    def _path(self, t_start_s: float, n_samples: int, odr_hz: float) -> _Path | None:
        """What the fixture felt at each sample of a block where any table axis moves through it (one path
        for every DUT sampled at these instants); None where the table holds still."""
        key = (t_start_s, n_samples, odr_hz)
        if self._path_cache is None or self._path_cache[0] != key:
            angles, rates = self.motion.path_deg(t_start_s + np.arange(n_samples) / odr_hz)
            path = None
            if np.any(rates) or np.any(angles != angles[0]):
                path = _Path(angles, self.kinematics.gravity_in_fixture(angles),
                             self.kinematics.angular_velocity_in_fixture(angles, rates)
                             + self.kinematics.world_in_fixture(angles, self.earth_rate_world_dps))
            self._path_cache = (key, path)
        return self._path_cache[1]

    def _gravity_along(self, index: int, path: _Path) -> np.ndarray:
        """The true specific force (n, 3) in DUT `index`'s frame at each sample of `path` (a mount fault's turn
        taken where the table stands now)."""
        gravity = self.site_gravity_g * path.up_fixture @ self.duts[index].fixture_to_dut.T
        if self.mount_faults.any_turned:
            turn = self.mount_faults.turns(self.motion.position_deg(self.clock.now()))[index]
            gravity = gravity @ turn.T
        return gravity

    def gyro_noise_dps(self, index: int, odr_hz: float) -> float:
        """DUT `index`'s gyroscope's per-sample white noise: its part's density × √(ENBW of an ODR/4 low-pass)."""
        density = 1e-6 * self.duts[index].part.channel("gyro").noise_density_micro_per_rthz
        return density * float(np.sqrt(np.pi / 2 * odr_hz / 4))

    def true_rate_dps(self, index: int) -> np.ndarray:
        """The DUT's true angular rate in its own frame now, °/s: the table's axes turning (a rate step, a
        move) and the Earth's rotation."""
        now = self.clock.now()
        angles = self.motion.position_deg(now)
        table = self.kinematics.angular_velocity_in_fixture(angles, self.motion.rate_deg_s(now))
        earth = self.kinematics.world_in_fixture(angles, self.earth_rate_world_dps)
        return self.duts[index].fixture_to_dut @ (table + earth)

    def dut_gyro_samples(self, index: int, t_start_s: float, n_samples: int, odr_hz: float,
                         range_dps: float) -> np.ndarray:
        """`n_samples` gyroscope codes (n, 3) of DUT `index` from `t_start_s` on: its hidden truth at its
        temperature now applied to the true rate and the specific force it feels, white noise and the bias's
        wander from streams of its own, its part's codes."""
        dut, instant = self.duts[index], self._instant()
        if dut.gyro_truth is None:
            raise ValueError(f"{dut.serial}: the {dut.part.label} has no gyroscope")
        parameters = dut.gyro_truth.parameters_at(float(instant.temperature_c[index]))
        path = self._path(t_start_s, n_samples, odr_hz)
        if path is None:
            reading = distort_rate(self.true_rate_dps(index), instant.gravity_g[index], parameters)
        else:  # the table turns through the samples: each sample's rate (the Earth's turned too) and gravity
            reading = distort_rate(path.rate_fixture_dps @ dut.fixture_to_dut.T, self._gravity_along(index, path),
                                   parameters)
        reading = reading * (1.0 + dut.gyro_range_scale.get(float(range_dps), np.zeros(3)))
        noise = self.gyro_rngs[index].normal(0.0, self.gyro_noise_dps(index, odr_hz), (n_samples, 3))
        wander = self.bias_wander[index].at(t_start_s + np.arange(n_samples) / odr_hz)
        dut.gyro_wander_log.append((t_start_s, t_start_s + n_samples / odr_hz, n_samples, wander.mean(axis=0)))
        return dut.part.channel("gyro").quantise(reading + noise + wander, range_dps)

    def mag_noise_gauss(self, index: int, odr_hz: float) -> float:
        """DUT `index`'s magnetometer's per-sample white noise: its part's density × √(ENBW of an ODR/4 low-pass)."""
        channel = next(c for c in self.duts[index].part.channels if c.quantity == MAGNETIC_FIELD)
        return 1e-6 * channel.noise_density_micro_per_rthz * float(np.sqrt(np.pi / 2 * odr_hz / 4))

    def dut_field_samples(self, index: int, t_start_s: float, n_samples: int, odr_hz: float,
                          range_gauss: float) -> np.ndarray:
        """`n_samples` magnetometer codes (n, 3) of DUT `index` from `t_start_s` on: the site's field in its frame
        at the table's true angles, through its hidden Eq. 1 (hard and soft iron) at its temperature now, white
        noise from a stream of its own, its part's codes; the fixture's truth behind them recorded as an
        accelerometer's block records it."""
        dut, instant = self.duts[index], self._instant()
        if dut.mag_truth is None:
            raise ValueError(f"{dut.serial}: the {dut.part.label} has no magnetometer")
        temperature = float(instant.temperature_c[index])
        field = dut.fixture_to_dut @ self.kinematics.world_in_fixture(self.motion.position_deg(self.clock.now()),
                                                                      self.field_world_gauss)
        parameters = dut.mag_truth.parameters_at(temperature)
        reading = distort(field, parameters)
        noise = self.mag_rngs[index].normal(0.0, self.mag_noise_gauss(index, odr_hz), (n_samples, 3))
        # The truth's parameters are the DUT's first channel's (its magnetometer's: it has no accelerometer).
        dut.truth_log.append((t_start_s, t_start_s + n_samples / odr_hz, n_samples, parameters,
                              instant.gravity_g[index].copy(), temperature))
        channel = next(c for c in dut.part.channels if c.quantity == MAGNETIC_FIELD)
        return channel.quantise(reading + noise, range_gauss)

    def _instant(self) -> _Instant:
        """Every DUT's truth at the clock's time, evaluated for the whole fixture at once: all its sensors are
        sampled at the same instants (a capture fetched from each in turn), and 64 evaluations of Eq. 1 one
        by one cost more than the samples they describe."""
        now = self.clock.now()
        if self._instant_cache is None or self._instant_cache.t_s != now:
            temperature_c = self.thermal.duts_c(now)
            parameters = fixture_parameters_at(self._truth_coefficients, temperature_c)
            gravity_g = self.site_gravity_g * (self._fixture_to_duts @ self._gravity_in_fixture(now))
            if self.mount_faults.any_turned:
                gravity_g = np.einsum("nij,nj->ni", self.mount_faults.turns(self.motion.position_deg(now)), gravity_g)
            self._instant_cache = _Instant(now, temperature_c, parameters, gravity_g, distort(gravity_g, parameters))
        return self._instant_cache

    def truth_between(self, index: int, t_start_s: float, t_end_s: float) -> dict[str, np.ndarray]:
        """The truth behind the samples of [t_start_s, t_end_s], averaged over the chunks that made them; for a
        DUT with a gyroscope, also its bias's wander over them (`gyro_wander_dps`: what the part read beyond
        its model then, which a check of its calibration against the truth must count as a reading does)."""
        dut = self.duts[index]
        chunks = _chunks_between(dut.truth_log, t_start_s, t_end_s)
        if not chunks:
            raise ValueError(f"no samples of {dut.serial} between {t_start_s:g} and {t_end_s:g} s")
        weights = np.array([c[2] for c in chunks], dtype=float)
        mean = lambda k: np.average(np.array([c[k] for c in chunks]), axis=0, weights=weights)  # noqa: E731
        truth = {"parameters": mean(3), "gravity_g": mean(4), "temperature_c": np.asarray(mean(5), dtype=float)}
        gyro = _chunks_between(dut.gyro_wander_log, t_start_s, t_end_s)
        if gyro:
            truth["gyro_wander_dps"] = np.average(np.array([c[3] for c in gyro]), axis=0,
                                                  weights=np.array([c[2] for c in gyro], dtype=float))
        return truth

    def gravity_in_dut(self, index: int) -> np.ndarray:
        """True specific force at rest (the site's gravity, up) in DUT `index`'s frame at the table's actual
        angles, in standard g."""
        return self.site_gravity_g * (self.duts[index].fixture_to_dut @ self._gravity_in_fixture(self.clock.now()))

    def _gravity_in_fixture(self, t_s: float) -> np.ndarray:
        """The unit 'up' in the fixture frame at the table's actual angles at `t_s`."""
        angles = self.motion.position_deg(t_s)
        key = angles.tobytes()
        if key != self._gravity_angles_key:  # the table stands still between moves: one chain per pose
            self._gravity_angles_key, self._gravity_fixture = key, self.kinematics.gravity_in_fixture(angles)
        return self._gravity_fixture


def _accelerometer_noise(dut_part: Part) -> float:
    """A part's accelerometer's noise density, µg/√Hz (0 for a part without one)."""
    return next((c.noise_density_micro_per_rthz for c in dut_part.channels if c.quantity == ACCELERATION), 0.0)


def _chunks_between(log: deque[tuple], t_start_s: float, t_end_s: float) -> list[tuple]:
    """The chunks of a log (t_start, t_end, …) that overlap [t_start_s, t_end_s], in time order: only the newest
    are looked at."""
    chunks = []
    for chunk in reversed(log):
        if chunk[1] <= t_start_s:
            break
        if chunk[0] <= t_end_s:
            chunks.append(chunk)
    chunks.reverse()
    return chunks
