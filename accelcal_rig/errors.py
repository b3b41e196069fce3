"""Errors a technician sees as one line, each with the exit code the CLI returns for it."""


class RigError(Exception):
    """Base of every error the CLI reports as a single line instead of a traceback."""

    exit_code = 1


class ConfigError(RigError):
    """Bad input: a procedure or rig config file that is malformed or inconsistent (exit code 2)."""

    exit_code = 2


class InstrumentError(RigError):
    """An instrument misbehaved or answered something it must not (wrong identity, refused command)."""

    exit_code = 2


class TransientInstrumentError(InstrumentError):
    """A failure worth retrying: no reply in time, a garbled reply, a port that went away. `reconnect`:
    the connection itself failed and should be opened again before the next attempt."""

    def __init__(self, message: str, reconnect: bool = False) -> None:
        super().__init__(message)
        self.reconnect = reconnect


class WaitTimeout(RigError):
    """A wait passed its deadline: the awaited condition (setpoint, soak, position) never held."""


class CampaignAborted(RigError):
    """The campaign stopped before its end; the rig was put in its safe state."""


class DiskFull(RigError):
    """No space left where a campaign writes: it stops, everything stored stays readable (exit code 1)."""


class InsufficientSpace(RigError):
    """Free space is below what the rest of a campaign needs, found before it would run out."""
