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


class WaitTimeout(RigError):
    """A wait passed its deadline: the awaited condition (setpoint, soak, position) never held."""


class CampaignAborted(RigError):
    """The campaign stopped before its end; the rig was put in its safe state."""
