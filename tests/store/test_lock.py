"""The campaign lock: one writer, named when another process asks, gone with its process."""

from __future__ import annotations

import os
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest

from accelcal_rig.store import lock
from accelcal_rig.store.lock import CampaignBusy, campaign_lock, holder

HOLD = ("import sys, time; from pathlib import Path; from accelcal_rig.store.lock import acquire; "
        "acquire(Path(sys.argv[1]), 'rig run'); print('held', flush=True); time.sleep(60)")


@pytest.fixture
def held_elsewhere(tmp_path: Path):
    campaign = tmp_path / "c.h5"
    process = subprocess.Popen([sys.executable, "-c", HOLD, str(campaign)], stdout=subprocess.PIPE, text=True)
    assert process.stdout.readline().strip() == "held"
    yield campaign, process
    process.kill()
    process.wait()


def test_another_process_is_refused_with_its_holder_named(held_elsewhere, monkeypatch) -> None:
    campaign, process = held_elsewhere
    monkeypatch.setattr(lock, "ACQUIRE_PATIENCE_S", 0.1)
    with pytest.raises(CampaignBusy, match=rf"c.h5: in use by pid {process.pid} on {socket.gethostname()} "
                                           r"\(rig run since .*\); nothing was changed"):
        lock.acquire(campaign, "rig resume")
    assert holder(campaign).startswith(f"pid {process.pid} on {socket.gethostname()} (rig run since ")


def test_the_lock_goes_with_a_killed_process(held_elsewhere) -> None:
    campaign, process = held_elsewhere
    os.kill(process.pid, signal.SIGKILL)
    process.wait()
    assert holder(campaign) is None
    with campaign_lock(campaign, "rig resume"):
        assert holder(campaign).startswith("this process")


def test_the_lock_is_reentrant_and_readers_never_create_it(tmp_path: Path) -> None:
    campaign = tmp_path / "c.h5"
    assert holder(campaign) is None and not (tmp_path / "c.h5.lock").exists()
    with campaign_lock(campaign, "rig run"):
        with campaign_lock(campaign, "rig run"):
            pass
        assert lock.holds(campaign)
    assert not lock.holds(campaign) and holder(campaign) is None


WAIT = ("import sys; from pathlib import Path; from accelcal_rig.store import lock; lock.ACQUIRE_PATIENCE_S = 60; "
        "lock.acquire(Path(sys.argv[1]), 'rig resume'); print('held', flush=True); sys.stdin.read()")


def test_a_lock_file_removed_by_its_holder_is_never_held_twice(tmp_path: Path) -> None:
    """A run whose campaign never started removes the lock file it made, while holding it; a writer that was
    waiting on that file then locks the file at the path, so two writers never hold two files."""
    campaign = tmp_path / "c.h5"
    lock.acquire(campaign, "rig run")
    waiter = subprocess.Popen([sys.executable, "-c", WAIT, str(campaign)], stdin=subprocess.PIPE,
                              stdout=subprocess.PIPE, text=True)
    try:
        give_up = time.monotonic() + 30.0
        while holder(campaign) is None or not _waiting_on(waiter.pid, tmp_path / "c.h5.lock"):
            assert waiter.poll() is None and time.monotonic() < give_up, "the waiter never opened the lock file"
            time.sleep(0.005)
        lock.remove_lock_file(campaign)
        lock.release(campaign)
        assert waiter.stdout.readline().strip() == "held"
        assert (tmp_path / "c.h5.lock").exists() and holder(campaign).startswith(f"pid {waiter.pid} ")
        with pytest.raises(CampaignBusy):
            lock.ACQUIRE_PATIENCE_S, patience = 0.05, lock.ACQUIRE_PATIENCE_S
            try:
                lock.acquire(campaign, "rig run")
            finally:
                lock.ACQUIRE_PATIENCE_S = patience
    finally:
        waiter.kill()
        waiter.wait()


def _waiting_on(pid: int, lock_file: Path) -> bool:
    """Whether process `pid` has `lock_file` open (it is then waiting for the lock, or about to)."""
    try:
        return any(os.path.realpath(f"/proc/{pid}/fd/{fd}") == str(lock_file.resolve())
                   for fd in os.listdir(f"/proc/{pid}/fd"))
    except OSError:
        return False
