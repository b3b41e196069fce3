"""A synthetic hand-held calibration recording: a simulated sensor put down in one orientation after
another, carried by hand between them, recording continuously.

Still periods: gravity only, plus the sensor's white noise. Moves: a smooth rotation from one orientation
to the next (a minimum-jerk profile), the hand's push and stop (a sine pulse of up to `hand_accel_g`) and
tremor; what the sensor reads is its Eq. 1 distortion of that specific force. Orientations: each face of
the sensor down and up once, tilted by up to 20° at random as a hand puts it, then random ones.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation, Slerp

from accelcal_rig.fit.sfem import distort
from accelcal_rig.sim.truth import truth_for_serial

FACES = np.array([[0, 0, 1], [0, 0, -1], [1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0]], dtype=float)


@dataclass(frozen=True)
class HandheldRecording:
    t_s: np.ndarray               # (n,)
    raw_g: np.ndarray             # (n, 3) what the sensor reads, in g, before quantisation
    temperature_c: np.ndarray     # (n,)
    truth_parameters: np.ndarray  # (12,) Eq. 1 parameters at the recording's temperature
    still: np.ndarray             # (n,) bool: the sensor lay still
    orientations: int


def _rotation_to(up_in_sensor: np.ndarray, rng: np.random.Generator) -> Rotation:
    """A sensor attitude (sensor → world) in which world-up reads `up_in_sensor`, any heading."""
    align, _ = Rotation.align_vectors([[0.0, 0.0, 1.0]], [up_in_sensor])
    return Rotation.from_euler("z", rng.uniform(0, 360), degrees=True) * align


def _up_directions(n: int, rng: np.random.Generator) -> np.ndarray:
    tilted = []
    for face in FACES[: min(n, 6)]:
        tilt = Rotation.from_rotvec(rng.normal(size=3) * np.radians(20.0) / np.sqrt(3))
        tilted.append(tilt.apply(face))
    random = rng.normal(size=(max(n - 6, 0), 3))
    directions = np.vstack([tilted, random]) if len(random) else np.array(tilted)
    order = rng.permutation(len(directions))
    return directions[order] / np.linalg.norm(directions[order], axis=1, keepdims=True)


def handheld_recording(serial: str, orientations: int, rate_hz: float, rng: np.random.Generator, *,
                       temperature_c: float = 25.0, still_s: tuple[float, float] = (3.0, 6.0),
                       move_s: tuple[float, float] = (1.5, 3.0), initial_still_s: float = 5.0,
                       noise_g: float = 2e-4, hand_accel_g: float = 0.4, tremor_g: float = 0.02) -> HandheldRecording:
    truth = truth_for_serial(serial).parameters_at(temperature_c)
    ups = _up_directions(orientations, rng)
    attitudes = [_rotation_to(up, rng) for up in ups]
    pieces_f, still_flags = [], []
    for index, attitude in enumerate(attitudes):
        duration = initial_still_s if index == 0 else rng.uniform(*still_s)
        n = int(duration * rate_hz)
        pieces_f.append(np.tile(attitude.inv().apply([0.0, 0.0, 1.0]), (n, 1)))
        still_flags.append(np.ones(n, dtype=bool))
        if index + 1 == len(attitudes):
            break
        n = int(rng.uniform(*move_s) * rate_hz)
        u = np.linspace(0.0, 1.0, n)
        profile = 10 * u**3 - 15 * u**4 + 6 * u**5  # minimum jerk
        keys = Rotation.concatenate([attitude, attitudes[index + 1]])
        path = Slerp([0.0, 1.0], keys)(profile)
        push = rng.normal(size=3)
        push *= rng.uniform(0.3, 1.0) * hand_accel_g / np.linalg.norm(push)
        hand = np.sin(2 * np.pi * u)[:, None] * push + rng.normal(0.0, tremor_g, (n, 3))
        pieces_f.append(path.inv().apply(np.array([0.0, 0.0, 1.0]) + hand))
        still_flags.append(np.zeros(n, dtype=bool))
    specific_force = np.vstack(pieces_f)
    raw = distort(specific_force, truth) + rng.normal(0.0, noise_g, specific_force.shape)
    t = np.arange(len(raw)) / rate_hz
    temperature = temperature_c + 0.05 * rng.standard_normal(len(raw))
    return HandheldRecording(t, raw, temperature, truth, np.concatenate(still_flags), len(attitudes))


def write_csv(recording: HandheldRecording, path, *, counts_per_g: float | None = None, zero_code: float = 0.0,
              bits: int | None = None) -> None:
    """As g, or as integer codes (`counts_per_g`, `zero_code`; clipped to `bits` when given)."""
    values = recording.raw_g
    if counts_per_g is not None:
        values = np.rint(values * counts_per_g + zero_code)
        if bits is not None:
            low = zero_code - 2 ** (bits - 1) if zero_code == 0 else 0
            values = np.clip(values, low, low + 2**bits - 1)
    lines = ["time_s,ax,ay,az,temp_c"]
    fmt = "{:.0f}" if counts_per_g is not None else "{:.9f}"
    lines += [f"{t:.5f},{fmt.format(x)},{fmt.format(y)},{fmt.format(z)},{c:.3f}"
              for t, (x, y, z), c in zip(recording.t_s, values, recording.temperature_c)]
    path.write_text("\n".join(lines) + "\n")
