"""The `rig` command line: its grammar (`grammar/`, `parser.py`), each command's work that is not the engine's
(`campaign.py`, `registry.py`, `approval.py`, …), what the commands print (`format_*.py`, `status_text.py`) and
`commands.py`, which dispatches. `accelcal_rig.entry` starts it."""

from accelcal_rig.cli.commands import main, run_program

__all__ = ["main", "run_program"]
