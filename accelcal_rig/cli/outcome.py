"""How a command ends: its exit codes, and an error's message as the one line it prints."""

from __future__ import annotations

EXIT_INTERRUPTED = 130
#: A failure the program did not foresee (a bug): one line, and this code.
EXIT_INTERNAL = 70
#: `--fail-on-reject`: the campaign and the fit went through, and at least one DUT failed its limits.
EXIT_REJECTED = 3
#: `rig check`: an instrument failed its check (as an instrument's error is).
EXIT_CHECK_FAILED = 2
#: `rig run`/`rig resume`: the campaign, its fit and certificates are done, but its registry rows could not be
#: recorded (the registry down, full, refusing): `rig resume FILE` records them. Above EXIT_REJECTED: with
#: both, the DUTs' verdicts are in the summary it printed.
EXIT_NOT_RECORDED = 4


def one_line(error: BaseException) -> str:
    """An error's message as one line, whatever text from a file it quotes."""
    return " ".join(str(error).splitlines())
