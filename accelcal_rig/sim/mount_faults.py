"""What a simulated fixture gets wrong about its DUTs (`simulation.faults`): one plugged in turned from its
configured mount, one loose on its mount (a small random turn at every pose), one with a dead axis (a
broken channel reading its bias whatever the pose). What the early check must find at the first setpoint."""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from accelcal_rig.config.rig import FaultInjection

AXES = "xyz"


class MountFaults:
    """The turn of each DUT's true frame from its configured one, (n, 3, 3), and the dead axis, if any."""

    def __init__(self, faults: FaultInjection, serials: list[str], seed: int) -> None:
        self._fixed = np.broadcast_to(np.eye(3), (len(serials), 3, 3)).copy()
        if faults.sensor_misoriented in serials:
            self._fixed[serials.index(faults.sensor_misoriented)] = Rotation.from_euler(
                faults.sensor_misoriented_about, faults.sensor_misoriented_deg, degrees=True).as_matrix()
        self._loose = serials.index(faults.sensor_loose) if faults.sensor_loose in serials else None
        #: Each component of a loose DUT's turn: normal with this 1σ, so its RMS angle is `sensor_loose_deg`.
        self._loose_sigma_rad = np.radians(faults.sensor_loose_deg) / np.sqrt(3.0)
        self._rng = np.random.default_rng([seed, self._loose or 0, 4])  # its own stream: no other draw changes
        self._pose_key = b""
        self._turns = self._fixed
        #: (DUT index, axis index) of the dead axis, None without one.
        self.dead_axis = ((serials.index(faults.sensor_dead_axis), AXES.index(faults.sensor_dead_axis_name))
                          if faults.sensor_dead_axis in serials else None)

    @property
    def any_turned(self) -> bool:
        return self._loose is not None or not np.allclose(self._fixed, np.eye(3))

    def turns(self, table_angles_deg: np.ndarray) -> np.ndarray:
        """(n, 3, 3): configured DUT frame → true DUT frame with the table at these angles; a loose DUT's
        turn is drawn afresh whenever the table has moved (it shifts on its mount between poses)."""
        if self._loose is None:
            return self._fixed
        key = np.asarray(table_angles_deg, dtype=float).tobytes()
        if key != self._pose_key:
            self._pose_key = key
            wobble = Rotation.from_rotvec(self._rng.normal(0.0, self._loose_sigma_rad, 3)).as_matrix()
            self._turns = self._fixed.copy()
            self._turns[self._loose] = wobble @ self._fixed[self._loose]
        return self._turns

    def reading_g(self, index: int, reading_g: np.ndarray, bias_g: np.ndarray) -> np.ndarray:
        """What DUT `index` reads for `reading_g` (its Eq. 1 reading): its dead axis its bias alone."""
        if self.dead_axis is None or self.dead_axis[0] != index:
            return reading_g
        dead = np.array(reading_g, dtype=float, copy=True)
        dead[..., self.dead_axis[1]] = bias_g[self.dead_axis[1]]
        return dead
