"""The limit gates and the retry stand-ins are typed delegates: each is a capability exactly when what it
wraps is one, and passes every call on (through the retry, where it is the retry's)."""

from __future__ import annotations

from itertools import combinations

import numpy as np
import pytest

from accelcal_rig.config.rig import ChamberConfig, RetryPolicy, TurntableAxis, TurntableConfig
from accelcal_rig.core.clock import VirtualClock
from accelcal_rig.engine.retry import Retrier
from accelcal_rig.errors import InstrumentError, TransientInstrumentError
from accelcal_rig.instruments.capabilities import (
    AlarmReporting,
    ConstantRateRotation,
    ControllerLimits,
    HumiditySensing,
    Purging,
    Reconnecting,
    SetpointResolution,
    alarm_active,
    controller_limits,
    has_purge,
    humidity_pct,
    set_purge,
    setpoint_decimals,
)
from accelcal_rig.instruments.interfaces import Chamber, Positioning
from accelcal_rig.instruments.limits import LimitedChamber, LimitedTurntable
from accelcal_rig.instruments.retrying import RetryingChamber, RetryingTurntable


class CoreChamber:
    """Only what every chamber has."""

    endpoint = "test-chamber"

    def __init__(self) -> None:
        self.writes: list[float] = []
        self.purge: list[bool] = []
        self.reconnects = 0

    def identify(self) -> str:
        return "core chamber"

    def read_temperature_c(self) -> float:
        return 21.5

    def write_setpoint_c(self, setpoint_c: float) -> None:
        self.writes.append(setpoint_c)

    def read_setpoint_c(self) -> float:
        return self.writes[-1]

    def set_power(self, on: bool) -> None: ...

    def close(self) -> None: ...


class WithAlarm(CoreChamber):
    def alarm_active(self) -> bool:
        return True


class WithLimits(CoreChamber):
    def controller_limits_c(self) -> tuple[float, float] | None:
        return (-20.0, 50.0)


class WithPurge(CoreChamber):
    def set_purge(self, on: bool) -> None:
        self.purge.append(on)


class WithHumidity(CoreChamber):
    def read_humidity_pct(self) -> float | None:
        return 40.0


class WithResolution(CoreChamber):
    setpoint_decimals = 1


class WithReconnect(CoreChamber):
    def reconnect(self) -> None:
        self.reconnects += 1


FEATURES = {AlarmReporting: WithAlarm, ControllerLimits: WithLimits, Purging: WithPurge,
            HumiditySensing: WithHumidity, SetpointResolution: WithResolution, Reconnecting: WithReconnect}
#: Each capability alone, none, all, and a few pairs.
CHOSEN = [(), tuple(FEATURES), *[(c,) for c in FEATURES], *list(combinations(FEATURES, 2))[::3]]
LIMITS = ChamberConfig(min_setpoint_c=-40, max_setpoint_c=85, safe_setpoint_c=20)


def chamber_with(capabilities: tuple[type, ...]) -> CoreChamber:
    mixins = tuple(FEATURES[c] for c in capabilities)
    return type("Double", (*mixins, CoreChamber) if mixins else (CoreChamber,), {})()


def retrier() -> Retrier:
    return Retrier(RetryPolicy(attempts=3, first_backoff_s=0.5, max_backoff_s=2.0), VirtualClock(), Events())


class Events:
    def __init__(self) -> None:
        self.warnings: list[str] = []

    def warning(self, kind: str, message: str) -> None:
        self.warnings.append(message)


WRAPPERS = {
    "limited": lambda inner: LimitedChamber(inner, LIMITS),
    "retrying": lambda inner: RetryingChamber(inner, retrier().call),
    "limited over retrying": lambda inner: LimitedChamber(RetryingChamber(inner, retrier().call), LIMITS),
}


@pytest.mark.parametrize("wrap", list(WRAPPERS.values()), ids=list(WRAPPERS))
@pytest.mark.parametrize("chosen", CHOSEN, ids=lambda c: "+".join(p.__name__ for p in c) or "core")
def test_a_chamber_wrapper_has_a_capability_exactly_when_its_chamber_has_it(chosen, wrap) -> None:
    inner = chamber_with(chosen)
    wrapper = wrap(inner)
    assert isinstance(wrapper, Chamber)
    for capability in FEATURES:
        assert isinstance(wrapper, capability) == isinstance(inner, capability) == (capability in chosen), capability


@pytest.mark.parametrize("wrap", list(WRAPPERS.values()), ids=list(WRAPPERS))
def test_what_a_wrapper_has_it_passes_on(wrap) -> None:
    inner = chamber_with(tuple(FEATURES))
    wrapper = wrap(inner)
    assert alarm_active(wrapper) is True and humidity_pct(wrapper) == 40.0
    assert controller_limits(wrapper) == (-20.0, 50.0) and setpoint_decimals(wrapper) == 1
    set_purge(wrapper, True)
    wrapper.reconnect()
    wrapper.write_setpoint_c(21.04)
    assert inner.purge == [True] and inner.reconnects == 1
    assert inner.writes == ([21.0] if isinstance(wrapper, LimitedChamber) else [21.04])  # the gate rounds


@pytest.mark.parametrize("wrap", list(WRAPPERS.values()), ids=list(WRAPPERS))
def test_what_a_wrapper_lacks_the_helpers_answer_for(wrap) -> None:
    wrapper = wrap(chamber_with(()))
    assert alarm_active(wrapper) is False and humidity_pct(wrapper) is None and not has_purge(wrapper)
    assert controller_limits(wrapper) is None and setpoint_decimals(wrapper) is None
    with pytest.raises(InstrumentError, match=r"chamber \(test-chamber\): no dry-air purge output"):
        set_purge(wrapper, True)


def test_the_limit_gate_keeps_the_controllers_limits_read_at_connect() -> None:
    inner = chamber_with((ControllerLimits,))
    gate = LimitedChamber(inner, LIMITS)
    with pytest.raises(InstrumentError, match=r"the controller's own limits are -20…50 °C"):
        gate.write_setpoint_c(60.0)
    assert inner.writes == []


class PurgeFailingOnce(WithPurge, WithReconnect):
    def set_purge(self, on: bool) -> None:
        if not self.purge:
            self.purge.append(not on)  # a marker: the first attempt reached the chamber
            raise TransientInstrumentError("chamber (test-chamber): no reply", reconnect=True)
        super().set_purge(on)


def test_a_capabilitys_calls_go_through_the_retry_and_its_reconnect() -> None:
    inner = PurgeFailingOnce()
    retry = retrier()
    wrapper = retry.retried_chamber(inner)
    set_purge(wrapper, True)
    assert inner.purge == [False, True] and inner.reconnects == 1


class CoreTurntable:
    endpoint = "test-table"

    def __init__(self) -> None:
        self.moves: list[np.ndarray] = []

    def identify(self) -> str:
        return "table"

    def move_to(self, angles_deg: np.ndarray) -> None:
        self.moves.append(angles_deg)

    def read_angles_deg(self) -> np.ndarray:
        return self.moves[-1]

    def in_position(self) -> bool:
        return True

    def stop(self) -> None: ...

    def close(self) -> None: ...


class ReconnectingTurntable(CoreTurntable):
    def reconnect(self) -> None: ...


@pytest.mark.parametrize("inner_type", [CoreTurntable, ReconnectingTurntable])
def test_a_turntable_wrapper_positions_and_reconnects_exactly_when_its_table_does(inner_type) -> None:
    config = TurntableConfig(axes=[TurntableAxis(name="tilt", axis=(1, 0, 0), min_deg=-90, max_deg=90)])
    inner = inner_type()
    for wrapper in (LimitedTurntable(inner, config), RetryingTurntable(inner, retrier().call),
                    LimitedTurntable(RetryingTurntable(inner, retrier().call), config)):
        assert isinstance(wrapper, Positioning) and not isinstance(wrapper, ConstantRateRotation)
        assert isinstance(wrapper, Reconnecting) == (inner_type is ReconnectingTurntable)
        wrapper.move_to(np.array([10.0]))
        assert wrapper.in_position() and wrapper.read_angles_deg().tolist() == [10.0]
    assert len(inner.moves) == 3
