import pytest

from accelcal_rig.core.signals import signals_deferred, stop_when_safe


def test_stop_outside_a_critical_section_is_immediate() -> None:
    with pytest.raises(KeyboardInterrupt):
        stop_when_safe(KeyboardInterrupt())


def test_stop_inside_nested_sections_waits_for_the_outermost_end() -> None:
    done = []
    with pytest.raises(KeyboardInterrupt):
        with signals_deferred():
            with signals_deferred():
                stop_when_safe(KeyboardInterrupt())
                done.append("inner write")
            done.append("outer write")  # the stop does not cut the outer section short either
    assert done == ["inner write", "outer write"]
    with signals_deferred():  # and nothing is left pending afterwards
        pass
