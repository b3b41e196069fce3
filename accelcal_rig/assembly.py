"""The one place a rig is put together: its config — and, in a dry run, the simulated lab behind real wires
— becomes drivers on the campaign's clock, behind retries and the rig's write-safety limits.

`rig run`, `rig resume`, `rig check`, `rig sim`, the benches and the tests assemble rigs here; the engine
receives a `RigConnector` and never imports a simulator.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from contextlib import ExitStack, contextmanager
from dataclasses import dataclass, field
from pathlib import Path

from accelcal_rig.config.load import LoadedConfig
from accelcal_rig.config.procedure import Procedure, SimulatedEffects
from accelcal_rig.config.rig import RigConfig
from accelcal_rig.core.clock import Clock, RealClock, VirtualClock
from accelcal_rig.core.logger import LOGGER
from accelcal_rig.engine import session
from accelcal_rig.engine.check import InstrumentCheck, check_instruments
from accelcal_rig.engine.connection import GuardedRig, RigConnector
from accelcal_rig.engine.events import EventLog
from accelcal_rig.engine.preparation import PreparedCampaign
from accelcal_rig.engine.progress import ProgressListener
from accelcal_rig.engine.retry import Retrier
from accelcal_rig.engine.session import RunResult
from accelcal_rig.instruments.connect import (
    EVERY_INSTRUMENT,
    configured_endpoints,
    connect_rig,
    missing_endpoints,
    named_endpoints,
)
from accelcal_rig.instruments.interfaces import RigInstruments
from accelcal_rig.instruments.limits import LimitedChamber, LimitedTurntable
from accelcal_rig.sim.devices import build_simulated_rig
from accelcal_rig.sim.wire_rig import SimulatedRig

#: Builds instruments in this process on the campaign's clock: (rig config, procedure, clock, seed) → them.
InstrumentFactory = Callable[[RigConfig, Procedure, Clock, int], RigInstruments]


@dataclass
class AssembledRig:
    """A connected rig: its devices as connected, and the clock they run on."""

    config: RigConfig
    instruments: RigInstruments
    clock: Clock

    def guarded(self, events: EventLog) -> GuardedRig:
        # Transient failures are retried below the safety limits, so a retried write is checked too.
        retrier = Retrier(self.config.retry, self.clock, events)
        raw = self.instruments
        guarded = RigInstruments(LimitedChamber(retrier.retried_chamber(raw.chamber), self.config.chamber),
                                 LimitedTurntable(retrier.retried_turntable(raw.turntable), self.config.turntable),
                                 [retrier.retried_sensor(s) for s in raw.sensors], raw.truth)
        return GuardedRig(guarded, retrier)


@dataclass
class WiredRig:
    """The rig a config describes, through its real drivers: at the config's endpoints in real time, or —
    `dry_run` — at wire-level simulators of it on a virtual clock. `served` holds the simulators of the
    last dry run connected (tests read the commands that reached them)."""

    rig: LoadedConfig[RigConfig]
    effects: SimulatedEffects = field(default_factory=SimulatedEffects)
    dry_run: bool = False
    served: SimulatedRig | None = None

    @contextmanager
    def __call__(self, seed: int, clock_start_s: float = 0.0) -> Iterator[AssembledRig]:
        if not self.dry_run:
            real_time = RealClock(clock_start_s)
            instruments = connect_rig(self.rig.model, configured_endpoints(self.rig), real_time)
            with _closing(AssembledRig(self.rig.model, instruments, real_time)) as rig:
                yield rig
            return
        virtual = VirtualClock(clock_start_s)
        with served_rig(self.rig.model, virtual, seed, self.effects) as simulated:
            self.served = simulated
            instruments = connect_rig(self.rig.model, simulated.endpoints, virtual)
            instruments.truth = simulated.truth
            with _closing(AssembledRig(self.rig.model, instruments, virtual)) as rig:
                yield rig


@dataclass
class InProcessRig:
    """A rig built in this process by `build` on a virtual clock (test doubles, in-process simulation)."""

    rig: RigConfig
    procedure: Procedure
    build: InstrumentFactory
    dry_run: bool = True

    @contextmanager
    def __call__(self, seed: int, clock_start_s: float = 0.0) -> Iterator[AssembledRig]:
        clock = VirtualClock(clock_start_s)
        with _closing(AssembledRig(self.rig, self.build(self.rig, self.procedure, clock, seed), clock)) as rig:
            yield rig


@contextmanager
def served_rig(rig: RigConfig, clock: Clock, seed: int,
               effects: SimulatedEffects = SimulatedEffects()) -> Iterator[SimulatedRig]:
    """The simulated rig's servers (Modbus TCP, pseudo-terminals) up on `clock`, stopped on leaving."""
    simulated = SimulatedRig(rig, clock, seed, effects)
    simulated.start()
    try:
        yield simulated
    finally:
        simulated.stop()


def checked(rig: LoadedConfig[RigConfig], *, dry_run: bool,
            only: frozenset[str] = EVERY_INSTRUMENT) -> Iterator[InstrumentCheck]:
    """`rig check`: each instrument in `only`, in real time, opened, described and closed on its own (a dry
    run's simulated, its simulators serving until the last is checked)."""
    with ExitStack() as stack:
        if dry_run:
            endpoints, missing = stack.enter_context(served_rig(rig.model, RealClock(), 0)).endpoints, {}
        else:
            endpoints, missing = named_endpoints(rig.model, only), missing_endpoints(rig, only)
        yield from check_instruments(rig.model, endpoints, RealClock(), only, dict(missing))


def connector(prepared: PreparedCampaign, *, dry_run: bool,
              build_instruments: InstrumentFactory | None = None) -> RigConnector:
    """How a campaign connects its rig: through `build_instruments` when given, else its config's wires."""
    if build_instruments is not None:
        return InProcessRig(prepared.rig.model, prepared.procedure.model, build_instruments)
    return WiredRig(prepared.rig, prepared.procedure.model.simulation, dry_run)


def in_process_simulation(prepared: PreparedCampaign) -> RigConnector:
    """The simulated rig in this process, without wires (the benches' in-process baseline)."""
    return InProcessRig(prepared.rig.model, prepared.procedure.model, build_simulated_rig)


def run_campaign(prepared: PreparedCampaign, output: Path, *, dry_run: bool, seed: int, overwrite: bool,
                 calibration: Path | None = None, build_instruments: InstrumentFactory | None = None,
                 resume: bool = False, progress: ProgressListener | None = None) -> RunResult:
    """`rig run`: the campaign on its rig (`dry_run`: the simulated one) — see engine.session.run_campaign."""
    return session.run_campaign(prepared, output, connector(prepared, dry_run=dry_run,
                                                            build_instruments=build_instruments),
                                seed=seed, overwrite=overwrite, calibration=calibration, resume=resume,
                                progress=progress)


def resume_campaign(prepared: PreparedCampaign, output: Path, *, dry_run: bool, calibration: Path | None = None,
                    build_instruments: InstrumentFactory | None = None,
                    progress: ProgressListener | None = None) -> RunResult:
    """`rig resume`: the campaign in `output` continued on its rig — see engine.session.resume_campaign."""
    return session.resume_campaign(prepared, output, connector(prepared, dry_run=dry_run,
                                                               build_instruments=build_instruments),
                                   calibration=calibration, progress=progress)


@contextmanager
def _closing(rig: AssembledRig) -> Iterator[AssembledRig]:
    """Release every connection on leaving; a port that will not close is logged, the outcome stands."""
    try:
        yield rig
    finally:
        for failure in rig.instruments.close():
            LOGGER.error(failure)
