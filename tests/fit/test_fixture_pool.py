"""A large fixture's DUTs fitted in worker processes: the same results, in order, warnings raised here."""

from __future__ import annotations

import os
import warnings

import pytest

from accelcal_rig.fit.fixture_pool import PARALLEL_FROM_DUTS, map_over_duts


def square_warning_on_odd(value: int) -> tuple[int, int]:
    if value % 2:
        warnings.warn(f"odd {value}", RuntimeWarning, stacklevel=1)
    return value * value, os.getpid()


def test_many_duts_are_fitted_in_workers_in_order_with_their_warnings() -> None:
    items = list(range(PARALLEL_FROM_DUTS + 3))
    with pytest.warns(RuntimeWarning) as caught:
        results = map_over_duts(square_warning_on_odd, items)
    assert [square for square, _ in results] == [k * k for k in items]
    assert os.getpid() not in {pid for _, pid in results}  # fitted elsewhere
    assert [str(w.message) for w in caught] == [f"odd {k}" for k in items if k % 2]
    raised_at = square_warning_on_odd.__code__.co_firstlineno + 2  # its warnings.warn line
    assert {(w.filename, w.lineno) for w in caught} == {(__file__, raised_at)}  # where the worker raised them


def test_a_small_fixture_is_fitted_here() -> None:
    with pytest.warns(RuntimeWarning, match="odd 1"):
        assert map_over_duts(square_warning_on_odd, [1, 2]) == [(1, os.getpid()), (4, os.getpid())]


def test_without_workers_the_fixture_is_fitted_here_and_says_so(monkeypatch) -> None:
    import accelcal_rig.fit.fixture_pool as pool

    def no_workers(*args, **kwargs):
        raise OSError("no room for a process")

    monkeypatch.setattr(pool, "ProcessPoolExecutor", no_workers)
    items = list(range(PARALLEL_FROM_DUTS))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        results = map_over_duts(square_warning_on_odd, items)
    assert results == [(k * k, os.getpid()) for k in items]
    assert "fit workers unavailable (OSError: no room for a process)" in str(caught[0].message)
