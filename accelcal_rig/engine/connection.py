"""What the engine receives from whoever assembles the rig (`accelcal_rig.assembly`): a way to connect it
on the campaign's clock, and the connected rig behind its retries and limits. The engine never builds one."""

from __future__ import annotations

from contextlib import AbstractContextManager
from dataclasses import dataclass
from typing import Protocol

from accelcal_rig.core.clock import Clock
from accelcal_rig.engine.events import EventLog
from accelcal_rig.engine.retry import Retrier
from accelcal_rig.instruments.interfaces import RigInstruments


@dataclass(frozen=True)
class GuardedRig:
    """Every device behind its retries and the rig's write-safety limits, and the retrier itself for the
    operations retried whole (an identity check, the blocks of a pose)."""

    instruments: RigInstruments
    retrier: Retrier


class ConnectedRig(Protocol):
    #: The devices as connected: for the file's instrument record, the simulation's truth, closing.
    instruments: RigInstruments
    clock: Clock

    def guarded(self, events: EventLog) -> GuardedRig:
        """The devices wrapped for a run whose retries are events in `events`."""


class RigConnector(Protocol):
    #: A simulated rig on a virtual clock: recorded in the campaign, which resumes only as one.
    dry_run: bool

    def __call__(self, seed: int, clock_start_s: float = 0.0) -> AbstractContextManager[ConnectedRig]:
        """Connect every instrument, the clock starting at `clock_start_s`; close them all on leaving."""
