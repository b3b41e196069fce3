"""Bring a campaign's journal and file back in step, losing nothing (`rig repair`, and every resume).

A journal with damaged stretches is compacted into a new one holding its whole records byte for byte,
the damaged original kept beside it. A campaign file with no journal (written before the journal
existed, or copied alone) gets one made from it; so does a campaign whose journal has lost its header,
that journal kept beside it. The campaign file is then rebuilt from the journal.
"""

from __future__ import annotations

import os
import shutil
from pathlib import Path

from accelcal_rig.durable import clear_stale_temporaries, disk_errors, fsync_directory, unused_name, write_atomically
from accelcal_rig.errors import ConfigError
from accelcal_rig.store import lock
from accelcal_rig.store.codec import (
    NotACampaignJournal,
    encode_events,
    encode_header,
    encode_instruments,
    encode_pose,
    encode_run,
    encode_soak,
    encode_state,
    replay,
)
from accelcal_rig.store.content import Campaign, take_what_the_file_kept
from accelcal_rig.store.hdf5_file import DamagedFile, campaign_image
from accelcal_rig.store.journal import JournalWriter, read_journal
from accelcal_rig.store.paths import journal_path, progress_path
from accelcal_rig.store.read import file_identity, file_kept_more, read_hdf5_campaign
from accelcal_rig.store.records import StateChange


def journal_bytes_of(campaign: Campaign) -> bytes:
    """Journal records holding `campaign` (to give a campaign file that has none its journal)."""
    records = [encode_header(campaign.header), *(encode_run(r) for r in campaign.runs),
               encode_instruments(campaign.instruments), *(encode_soak(s, campaign.serials) for s in campaign.soaks),
               *(encode_pose(p) for p in campaign.poses)]
    if campaign.events:
        records.append(encode_events(campaign.events))
    if campaign.state != "created":
        records.append(encode_state(StateChange(campaign.state, campaign.abort_reason, campaign.finished)))
    return b"".join(records)


def _keep_copy(journal: Path) -> Path:
    """A second name for the journal as it is now (`….journal.damaged-20261201T081500`, a new name every
    time): a hard link, so the original survives the journal being replaced, whatever happens in between;
    a copy where the file system has no hard links."""
    kept = unused_name(journal, "damaged")
    with disk_errors(kept, "a copy of the damaged journal"):
        try:
            os.link(journal, kept)
        except FileExistsError:
            raise
        except OSError:
            shutil.copy2(journal, kept)
        fsync_directory(journal.parent)
    return kept


def _from_campaign_file(path: Path, why: str) -> Campaign:
    if not path.is_file():
        raise ConfigError(f"{path}: {why}, and there is no campaign file to make one from")
    campaign = read_hdf5_campaign(path)
    if campaign.damage:
        raise ConfigError(f"{path}: {campaign.damage[0]}; {why}: nothing to repair it from, nothing was changed")
    return campaign


def mend_journal(path: Path) -> list[str]:
    """Make the campaign's journal whole and readable (the caller holds the campaign's lock); what was
    done, one line each. A record cut short at the end is left for the journal's writer to cut."""
    journal = journal_path(path)
    if not journal.is_file():
        campaign = _from_campaign_file(path, "it has no journal")
        write_atomically(journal, journal_bytes_of(campaign), "the campaign journal")
        return [f"{path.name} had no journal: {journal.name} made from its {len(campaign.poses)} poses"]
    identity = file_identity(path)  # before the journal: see file_kept_more
    with disk_errors(journal, "the campaign journal"):
        found = read_journal(journal)
    try:
        held = replay(found, journal.name)
    except NotACampaignJournal as exc:
        campaign = _from_campaign_file(path, str(exc))
        kept = _keep_copy(journal)
        write_atomically(journal, journal_bytes_of(campaign), "the campaign journal")
        return [f"{exc}: kept as {kept.name}, {journal.name} made again from {path.name} ({len(campaign.poses)} poses)"]
    held.journal_bytes = found.end
    from_file = file_kept_more(path, identity, held)
    added = take_what_the_file_kept(held, from_file, journal.name, path.name) if from_file is not None else 0
    if added:
        kept = _keep_copy(journal)
        write_atomically(journal, journal_bytes_of(held), "the campaign journal")
        return [f"{journal.name} had lost {added} poses {path.name} still holds: made again with them, the old one "
                f"kept as {kept.name}"]
    if not found.damaged:
        return []
    with disk_errors(journal, "the campaign journal"), journal.open("rb") as original:
        whole = b"".join(os.pread(original.fileno(), r.size, r.offset) for r in found.records)
    kept = _keep_copy(journal)
    write_atomically(journal, whole, "the campaign journal")
    skipped = sum(length for _, length in found.damaged)
    return [f"{journal.name}: {len(found.damaged)} damaged stretches ({skipped} bytes) left out, every whole record "
            f"kept; the original kept as {kept.name}"]


def repair_campaign(path: Path) -> list[str]:
    """Repair the campaign at `path`: what was done, one line each. Refused while a run holds it."""
    with lock.campaign_lock(path, "rig repair"):
        clear_stale_temporaries(path, journal_path(path), progress_path(path))  # what a killed run left half-built
        progress_path(path).unlink(missing_ok=True)  # a killed run's view of itself: no run is live now
        done = mend_journal(path)
        journal, found = JournalWriter.reopen(journal_path(path), 0)
        journal.close()
        if journal.tail_kept is not None:
            done.append(f"{found.tail_bytes} bytes after the journal's last whole record (a record a run that died was "
                        f"writing, or a damaged one) cut off, kept as {journal.tail_kept.name}")
        campaign = replay(found, journal_path(path).name)
        try:
            image = campaign_image(campaign, found.end)
        except DamagedFile as exc:
            raise ConfigError(f"{journal_path(path)}: its campaign {exc}") from None
        write_atomically(path, image, "the campaign file")
        done.append(f"{path.name} rebuilt from its journal: {len(campaign.poses)} of {campaign.poses_planned} poses, "
                    f"{len(campaign.soaks)} soaks, {campaign.run_count} runs, state {campaign.state}")
        return done + campaign.notes
