"""What the campaign is doing now, for whoever watches: a snapshot the runner hands to a listener."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from accelcal_rig.core.formatting import format_duration
from accelcal_rig.plan.compile import setpoint_label

#: Engine states as an operator names the phase they belong to.
PHASES = {"move": "poses", "settle": "poses", "acquire": "poses", "store": "poses"}
#: A cool-down's records are all one phase, waits and measurements alike.
COOLDOWN_PHASES = {"move": "cool", "settle": "cool", "acquire": "cool", "store": "cool", "cool": "cool"}


@dataclass(frozen=True)
class Progress:
    state: str                        # the engine state (engine.states.State)
    phase: str                        # what an operator calls it: ramp, soak, poses, safe, …
    setpoint_c: float | None          # None before the first ramp and after the last pose
    setpoint_number: int              # 1-based; 0 before the first ramp
    setpoints_total: int
    phase_elapsed_s: float            # since this phase began
    chamber_c: float | None           # last chamber air reading
    dut_c: tuple[float, ...]          # last DUT readings (empty before the first)
    poses_done: int
    poses_total: int
    clock_s: float                    # campaign clock
    remaining_s: float | None         # estimate; None without one

    def line(self, width: int | None = None) -> str:
        """`T-20 (3/11) soak 0:23:10 · chamber -20.1 °C · DUT -19.61…-19.42 °C · pose 48/264 · 6:12:00 left`.

        Within `width` characters (a terminal's), the DUT and chamber temperatures go first, then the
        phase's time: the time left and the pose count stay to the last."""
        where = self.phase
        if self.setpoint_c is not None:
            where = f"{setpoint_label(self.setpoint_c)} ({self.setpoint_number}/{self.setpoints_total}) {self.phase}"
        parts: list[tuple[int, str]] = [(3, where)]  # (how late it is dropped, text)
        if self.setpoint_c is not None:
            parts[0] = (3, f"{where} {format_duration(self.phase_elapsed_s)}")
        if self.chamber_c is not None:
            parts.append((1, f"chamber {self.chamber_c:.1f} °C"))
        if self.dut_c:
            low, high = min(self.dut_c), max(self.dut_c)
            parts.append((0, f"DUT {low:.2f} °C" if high - low < 0.005 else f"DUT {low:.2f}…{high:.2f} °C"))
        parts.append((4, f"pose {self.poses_done}/{self.poses_total}"))
        if self.remaining_s is not None:
            parts.append((5, f"{format_duration(self.remaining_s)} left"))
        text = " · ".join(t for _, t in parts)
        for drop in (0, 1):
            if width is None or len(text) <= width:
                break
            parts = [(p, t) for p, t in parts if p != drop]
            text = " · ".join(t for _, t in parts)
        if width is not None and len(text) > width:
            parts[0] = (3, where)  # the setpoint without the phase's time
            text = " · ".join(t for _, t in parts)
        if width is not None and len(text) > width:  # a very narrow terminal: the head gives way
            text = "…" + text[len(text) - width + 1:]
        return text


#: Receives a snapshot at every transition, temperature poll and stored pose; must return quickly.
ProgressListener = Callable[[Progress], None]
