"""What a kind of plan step is done by: a handler that runs it on the rig and estimates its duration against
the rig's model. Handlers keep no state of their own: a run's state is in its RunContext, an estimate's in
its PlayedRig."""

from __future__ import annotations

from typing import Protocol, TypeVar

from accelcal_rig.engine.played import PlayedRig
from accelcal_rig.engine.run_context import RunContext

StepT = TypeVar("StepT", contravariant=True)


class StepHandler(Protocol[StepT]):
    def run(self, step: StepT, run: RunContext) -> None:
        """Do the step on the rig."""

    def estimate(self, step: StepT, played: PlayedRig) -> None:
        """Advance `played` by the time the step would take on the rig its model describes."""
