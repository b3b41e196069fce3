"""Fitting a large fixture on every core: each DUT's fit is independent of the others' (~0.15 s for the
paper campaign), so from `PARALLEL_FROM_DUTS` DUTs on they are shared among worker processes.

Workers come from a fork server (never forked from a process whose simulator or driver threads may hold
locks) that has loaded the fit's modules with one BLAS thread (`fixture_worker`: a fit's matrices are
small, and two workers with two BLAS threads each are slower than one process); the warnings a worker's
fit raises are raised again here, in the order the DUTs come.
"""

from __future__ import annotations

import multiprocessing
import multiprocessing.context
import multiprocessing.forkserver
import os
import sys
import warnings
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import ProcessPoolExecutor
from concurrent.futures.process import BrokenProcessPool
from contextlib import contextmanager
from typing import TypeVar

T = TypeVar("T")
R = TypeVar("R")

#: Below this many DUTs a worker's start (~1 s: its imports) costs more than it saves.
PARALLEL_FROM_DUTS = 16


def _cores() -> int:
    return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (os.cpu_count() or 1)


def _context() -> multiprocessing.context.ForkServerContext:
    context = multiprocessing.get_context("forkserver")
    context.set_forkserver_preload(["accelcal_rig.fit.fixture_worker"])  # not the main module: see above
    return context  # type: ignore[return-value]


def warm_up_workers(n_duts: int) -> None:
    """Start the fork server now if a fit of `n_duts` will use it: it loads the fit's modules (a second or
    two) on another core while the campaign measures, and the workers fork from it at once."""
    if n_duts >= PARALLEL_FROM_DUTS and _cores() >= 2:
        _context()
        with _main_module_hidden():
            multiprocessing.forkserver.ensure_running()


def map_over_duts(fit: Callable[[T], R], items: Sequence[T]) -> list[R]:
    """`[fit(item) for item in items]`, in worker processes when there are many items and cores."""
    cores = _cores()
    if len(items) < PARALLEL_FROM_DUTS or cores < 2:
        return [fit(item) for item in items]
    workers = min(cores, len(items))
    try:
        with _main_module_hidden(), ProcessPoolExecutor(workers, mp_context=_context()) as pool:
            outcomes = list(pool.map(_recording_warnings, [fit] * len(items), items,
                                     chunksize=max(1, len(items) // (4 * workers))))
    except (BrokenProcessPool, OSError) as exc:  # no workers here (a sandbox, no room): fitted in this process
        warnings.warn(f"fit workers unavailable ({type(exc).__name__}: {exc}); fitting {len(items)} DUTs in "
                      "one process", RuntimeWarning, stacklevel=2)
        return [fit(item) for item in items]
    results = []
    shown: dict = {}  # as one process's warnings: the same text from the same line once
    for result, caught in outcomes:
        for category, message, filename, lineno in caught:
            warnings.warn_explicit(message, category, filename, lineno, registry=shown)
        results.append(result)
    return results


@contextmanager
def _main_module_hidden() -> Iterator[None]:
    """While workers start: a worker is told which main module to import again (as multiprocessing does for
    its spawned children) unless the main module has neither a file nor a spec. A worker needs only the
    fit's modules; importing a script again would run its top level a second time (a script without a
    `__main__` guard would start its campaign again in every worker)."""
    main = sys.modules.get("__main__")
    if main is None:
        yield
        return
    saved: dict[str, object] = {name: main.__dict__[name] for name in ("__file__", "__spec__") if name in main.__dict__}
    main.__dict__.pop("__file__", None)
    main.__dict__["__spec__"] = None
    try:
        yield
    finally:
        main.__dict__.pop("__spec__", None)
        main.__dict__.update(saved)


def _recording_warnings(fit: Callable[[T], R], item: T) -> tuple[R, list[tuple[type[Warning], str, str, int]]]:
    """The fit's result and its warnings, each with the file and line that raised it (re-raised there)."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result = fit(item)
    return result, [(w.category, str(w.message), w.filename, w.lineno) for w in caught]
