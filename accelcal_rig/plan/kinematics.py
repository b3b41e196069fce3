"""Turntable kinematic chain: axis angles ↔ the gravity direction seen in the fixture frame.

"Gravity direction" here is what a perfect accelerometer at rest reads, in g: the specific force, +1 g
along world up. The world frame has z up; at all-zero angles the fixture frame equals the world frame.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from scipy.optimize import least_squares
from scipy.spatial.transform import Rotation

from accelcal_rig.config.rig import TurntableAxis

#: Largest gravity-direction error (rad) accepted from the inverse kinematics: 0.002″.
_IK_TOLERANCE_RAD = 1e-8


class UnreachablePose(ValueError):
    """No angles inside the axis limits put gravity along the requested fixture direction."""


class TurntableKinematics:
    """Axes listed outermost first; each turns about its direction in its parent's frame."""

    def __init__(self, axes: Sequence[TurntableAxis]):
        self.axes = tuple(axes)
        self._directions = np.array([a.axis for a in self.axes], dtype=float)

    @property
    def axis_names(self) -> tuple[str, ...]:
        return tuple(a.name for a in self.axes)

    def chain_matrices(self, angles_deg: np.ndarray) -> np.ndarray:
        """Rotation matrices taking fixture-frame vectors to the world frame, shape (..., 3, 3)."""
        angles = np.deg2rad(np.asarray(angles_deg, dtype=float))
        flat = angles.reshape(-1, len(self.axes))
        per_axis = Rotation.from_rotvec((flat[:, :, None] * self._directions).reshape(-1, 3)).as_matrix()
        per_axis = per_axis.reshape(flat.shape[0], len(self.axes), 3, 3)
        chain = per_axis[:, 0]
        for k in range(1, len(self.axes)):
            chain = chain @ per_axis[:, k]
        return chain.reshape(angles.shape[:-1] + (3, 3))

    def angular_velocity_in_fixture(self, angles_deg: np.ndarray, rates_deg_s: np.ndarray) -> np.ndarray:
        """The fixture's angular velocity (°/s) in its own frame, shape (..., 3): each axis's rate about its
        direction as its parents have turned it, ω_world = Σ_k rate_k · (R_1 ⋯ R_(k−1)) d_k, brought into
        the fixture frame by Rᵀ."""
        angles = np.deg2rad(np.asarray(angles_deg, dtype=float))
        rates = np.asarray(rates_deg_s, dtype=float)
        flat = angles.reshape(-1, len(self.axes))
        per_axis = Rotation.from_rotvec((flat[:, :, None] * self._directions).reshape(-1, 3)).as_matrix()
        per_axis = per_axis.reshape(flat.shape[0], len(self.axes), 3, 3)
        flat_rates = np.broadcast_to(rates, angles.shape).reshape(-1, len(self.axes))
        parents = np.broadcast_to(np.eye(3), (flat.shape[0], 3, 3))
        omega_world = np.zeros((flat.shape[0], 3))
        for k in range(len(self.axes)):
            omega_world += flat_rates[:, k, None] * (parents @ self._directions[k])
            parents = parents @ per_axis[:, k]
        fixture = np.einsum("nji,nj->ni", parents, omega_world)  # parents is now the whole chain R
        return fixture.reshape(angles.shape[:-1] + (3,))

    def world_in_fixture(self, angles_deg: np.ndarray, vector_world: np.ndarray) -> np.ndarray:
        """A world-frame vector in the fixture frame at these angles: Rᵀ·v, shape (..., 3)."""
        return np.einsum("...ji,j->...i", self.chain_matrices(angles_deg), np.asarray(vector_world, dtype=float))

    def gravity_in_fixture(self, angles_deg: np.ndarray) -> np.ndarray:
        """Unit specific-force direction (+1 g up) in the fixture frame, shape (..., 3).

        World up expressed in the fixture frame is Rᵀ·ẑ, the third row of the chain matrix R.
        """
        return self.chain_matrices(angles_deg)[..., 2, :]

    def wrap(self, angles_deg: np.ndarray) -> np.ndarray:
        """Bring continuous axes into [min_deg, min_deg + 360)."""
        wrapped = np.array(angles_deg, dtype=float)
        for k, axis in enumerate(self.axes):
            if axis.continuous:
                wrapped[..., k] = (wrapped[..., k] - axis.min_deg) % 360.0 + axis.min_deg
        return wrapped

    def solve(self, gravity_fixture: np.ndarray, near_deg: np.ndarray) -> np.ndarray:
        """Angles that put gravity along `gravity_fixture`, preferring the solution nearest `near_deg`.

        A table with more axes than gravity has degrees of freedom (2) leaves some free; a pull towards
        `near_deg` fixes them (least travel): strong to choose the branch, then weak (bias ~1e-12 rad)
        to make the direction exact without drifting along the free directions.
        """
        target = np.asarray(gravity_fixture, dtype=float)
        target = target / np.linalg.norm(target)
        near = np.deg2rad(np.asarray(near_deg, dtype=float))
        lower = np.array([-np.inf if a.continuous else np.deg2rad(a.min_deg) for a in self.axes])
        upper = np.array([np.inf if a.continuous else np.deg2rad(a.max_deg) for a in self.axes])

        def direction_error(angles_rad: np.ndarray) -> np.ndarray:
            return self.gravity_in_fixture(np.rad2deg(angles_rad)) - target

        def pulled(weight: float):
            return lambda angles_rad: np.concatenate([direction_error(angles_rad), weight * (angles_rad - near)])

        best: np.ndarray | None = None
        for start in self._starts(near, lower, upper):
            trial = least_squares(pulled(1e-2), start, bounds=(lower, upper), method="trf")
            if np.linalg.norm(direction_error(trial.x)) > 1e-2:
                continue  # stuck away from the target: this start leads nowhere
            final = least_squares(pulled(1e-6), trial.x, bounds=(lower, upper), method="trf",
                                  xtol=1e-14, ftol=1e-14, gtol=1e-14)
            if np.linalg.norm(direction_error(final.x)) < _IK_TOLERANCE_RAD:
                best = final.x
                break  # starts come nearest first: the first exact solution is the least-travel one
        if best is None:
            raise UnreachablePose(f"gravity direction {np.round(target, 4).tolist()} is out of reach of the "
                                  + (self._geometry_limit(target) or "turntable's axis limits"))
        return self.wrap(np.rad2deg(best))

    def turn_in_fixture(self, index: int, angles_deg: np.ndarray) -> np.ndarray:
        """The direction, in the fixture frame, the fixture turns about when axis `index` turns at these angles:
        its own direction brought through the axes inside it, (R_(k+1) ⋯ R_n)ᵀ d_k."""
        inner = self.chain_matrices_from(index + 1, angles_deg)
        return np.einsum("...ji,j->...i", inner, self._directions[index])

    def chain_matrices_from(self, first: int, angles_deg: np.ndarray) -> np.ndarray:
        """The chain of the axes from `first` inwards (identity where there are none), shape (..., 3, 3)."""
        angles = np.asarray(angles_deg, dtype=float)
        if first >= len(self.axes):
            return np.broadcast_to(np.eye(3), angles.shape[:-1] + (3, 3)).copy()
        return TurntableKinematics(self.axes[first:]).chain_matrices(angles[..., first:])

    def solve_turn(self, index: int, turn_fixture: np.ndarray, near_deg: np.ndarray) -> np.ndarray:
        """Angles at which turning axis `index` turns the fixture about `turn_fixture` (a unit direction in the
        fixture frame), the axes outside it left where `near_deg` holds them: the axes inside it solved as a
        table of their own whose "up" is axis `index`'s direction. The innermost axis turns the fixture about
        its own direction whatever the angles: reached only where that is `turn_fixture`."""
        near = np.asarray(near_deg, dtype=float)
        target = np.asarray(turn_fixture, dtype=float) / np.linalg.norm(turn_fixture)
        direction = self._directions[index]
        if index == len(self.axes) - 1:
            if np.linalg.norm(direction - target) > _IK_TOLERANCE_RAD:
                raise UnreachablePose(f"axis {self.axes[index].name} turns the fixture about "
                                      f"{np.round(direction, 4).tolist()} only")
            return self.wrap(near.copy())
        # Q takes the axis's direction to +z: the axes inside it, seen turned by Q, then bring "up" where Q
        # takes the target.
        to_z = _rotation_to_z(direction)
        inside = [axis.model_copy(update={"axis": tuple(float(v) for v in to_z @ np.array(axis.axis))})
                  for axis in self.axes[index + 1:]]
        solved = TurntableKinematics(inside).solve(to_z @ target, near[index + 1:])
        angles = near.copy()
        angles[index + 1:] = solved
        return self.wrap(angles)

    def _geometry_limit(self, target: np.ndarray) -> str | None:
        """Why no angles at all reach `target`, where the table's geometry (not its limits) is the reason: a table
        whose only axes are a vertical one and one more turns gravity in the fixture frame only about that second
        axis, keeping its angle to it; None where the geometry is not the reason this tells."""
        if len(self.axes) != 2 or abs(abs(self._directions[0] @ np.array([0.0, 0.0, 1.0])) - 1.0) > 1e-9:
            return None
        inner = self._directions[1] / np.linalg.norm(self._directions[1])  # the same in the fixture frame
        allowed_deg = float(np.degrees(np.arccos(np.clip(inner[2], -1.0, 1.0))))
        off_deg = abs(float(np.degrees(np.arccos(np.clip(target @ inner, -1.0, 1.0)))) - allowed_deg)
        if off_deg < 1e-3:
            return None
        return (f"turntable's geometry: its two axes ({self.axes[0].name} vertical, {self.axes[1].name} about "
                f"{np.round(inner, 4).tolist()}) bring only fixture directions {allowed_deg:g}° from the "
                f"{self.axes[1].name} axis to gravity; this one is {off_deg:.1f}° off that circle (a third axis would "
                "reach it)")

    def _starts(self, near: np.ndarray, lower: np.ndarray, upper: np.ndarray) -> list[np.ndarray]:
        """Nearest first: the current angles, then one axis turned by ±90° or 180°, then a coarse grid.

        Antipodal targets (gravity reversed) have a zero gradient at the current angles; the offsets get
        the solver off that saddle, the grid finds a branch hidden behind an axis limit.
        """
        n = len(self.axes)
        starts = [near]
        for offset in np.deg2rad([90.0, -90.0, 180.0]):
            for k in range(n):
                start = near.copy()
                start[k] += offset
                starts.append(start)
        grid = np.deg2rad([-120.0, 0.0, 120.0])
        starts.extend(np.stack(np.meshgrid(*([grid] * n), indexing="ij"), axis=-1).reshape(-1, n))
        return [np.clip(s, lower + 1e-9, upper - 1e-9) for s in starts]


def _rotation_to_z(direction: np.ndarray) -> np.ndarray:
    """A rotation matrix taking the unit `direction` to +z (the identity for +z itself)."""
    z = np.array([0.0, 0.0, 1.0])
    axis = np.cross(direction, z)
    sine, cosine = float(np.linalg.norm(axis)), float(direction @ z)
    if sine < 1e-12:
        return np.eye(3) if cosine > 0 else np.diag([1.0, -1.0, -1.0])
    return Rotation.from_rotvec(axis / sine * np.arctan2(sine, cosine)).as_matrix()
