"""The grammar of the commands that run and watch campaigns and the rig: `rig run | plan | resume | status |
repair | check | sim`."""

from __future__ import annotations

from pathlib import Path

from accelcal_rig.cli.grammar.common import (
    CHAMBER_PROFILE_HELP,
    FAULTS_HELP,
    SEED,
    Commands,
    campaign_output_options,
    command,
    number,
)


def add_campaign_commands(commands: Commands) -> None:
    """`rig run | plan | resume | status | repair | check | sim`, in this order."""
    for add in (_add_run, _add_plan, _add_resume, _add_status, _add_repair, _add_check, _add_characterise, _add_sim):
        add(commands)


def _add_run(commands: Commands) -> None:
    """Run a campaign."""
    run = command(commands, "run", "run a campaign from a procedure file",
                  "Run a campaign: ramp and soak at each setpoint, measure every pose, store pose by pose, "
                  "make the rig safe, fit.",
                  "rig run procedures/paper-24pos-thermal.yaml --dry-run -o campaign.h5")
    run.add_argument("procedure", type=Path, help="procedure YAML file")
    run.add_argument("-o", "--output", type=Path, required=True, help="campaign file to create (HDF5)")
    run.add_argument("--config", type=Path, help="rig config YAML (overrides the procedure's `rig`)")
    run.add_argument("--dry-run", action="store_true", help="simulated rig in virtual time")
    run.add_argument("--seed", type=SEED, default=0, help="seed of the simulated noise (default 0)")
    run.add_argument("--faults", metavar="KEY=VALUE,...", help=FAULTS_HELP)
    run.add_argument("--chamber-profile", metavar="PROFILE", help=f"with --dry-run: {CHAMBER_PROFILE_HELP}")
    run.add_argument("--overwrite", action="store_true", help="replace an existing campaign file")
    run.add_argument("--resume", action="store_true",
                     help="continue the campaign in the output file if it exists (after a crash, a fault or "
                          "Ctrl-C), else start it")
    run.add_argument("--customer", metavar="NAME", default="",
                     help="whose DUTs they are, for every DUT whose fixture entry names no customer (recorded in the "
                          "campaign file, stated on the certificates)")
    run.add_argument("--contact", metavar="TEXT", default="",
                     help="the customer's contact, for every DUT whose fixture entry has no contact")
    run.add_argument("--received", metavar="YYYY-MM-DD", default="",
                     help="when the DUTs were received, for every DUT whose fixture entry has no received_date")
    run.add_argument("--condition", metavar="TEXT", default="",
                     help="the DUTs' condition on receipt, for every DUT whose fixture entry states none")
    run.add_argument("--lot", metavar="LOT", default="",
                     help="the lab's lot of the DUTs (its own word: a production or incoming lot, not the part "
                          "number), for every DUT whose fixture entry names none (recorded in the registry)")
    campaign_output_options(run)


def _add_plan(commands: Commands) -> None:
    """Show what a procedure will do."""
    plan = command(commands, "plan", "validate a procedure, show its schedule and estimate its duration",
                   "Validate the procedure and its rig config, compile the plan and print it: setpoints, soak "
                   "criterion, every pose with its turntable angles and gravity direction, samples, and the "
                   "time each setpoint's ramp, soak and poses will take. Touches no instrument.",
                   "rig plan procedures/paper-24pos-thermal.yaml")
    plan.add_argument("procedure", type=Path, help="procedure YAML file")
    plan.add_argument("--config", type=Path, help="rig config YAML (overrides the procedure's `rig`)")
    plan.add_argument("--json", action="store_true", help="print one JSON object")


def _add_resume(commands: Commands) -> None:
    """Continue a stopped campaign."""
    resume = command(commands, "resume", "continue a campaign that stopped before it was complete",
                     "Continue a campaign from its file: with the procedure it was started with (its path is "
                     "in the file) and the same rig (ports may differ), the rig made safe first if the last "
                     "run died, a fresh soak at the first setpoint with poses missing, then every pose not "
                     "stored yet. A dry run resumes as a dry run.",
                     "rig resume campaign.h5")
    resume.add_argument("campaign", type=Path, help="campaign file (HDF5)")
    resume.add_argument("--procedure", type=Path, help="procedure YAML (default: the path stored in the file)")
    resume.add_argument("--config", type=Path, help="rig config YAML (overrides the procedure's `rig`)")
    resume.add_argument("--faults", metavar="KEY=VALUE,...", help=FAULTS_HELP)
    campaign_output_options(resume)


def _add_status(commands: Commands) -> None:
    """A campaign file's state."""
    status = command(commands, "status", "show a campaign file's state and progress",
                     "Show a campaign's state and progress (works on finished, aborted and running files).",
                     "rig status campaign.h5 --json")
    status.add_argument("campaign", type=Path, help="campaign file (HDF5)")
    status.add_argument("--json", action="store_true", help="print one JSON object")
    status.add_argument("--calibration", type=Path, help="its calibration file, for the verdicts (default: beside "
                                                         "the campaign, .calibration.yaml)")
    status.add_argument("--watch", nargs="?", const=2.0, type=number(0.2, 3600, "s"), metavar="S",
                        help="show it again every S seconds (default 2) until the campaign ends or Ctrl-C")


def _add_repair(commands: Commands) -> None:
    """Mend a campaign from its journal."""
    repair = command(commands, "repair", "rebuild a campaign file from its journal",
                     "Bring a campaign's files back in step without losing a record: the campaign file (HDF5) "
                     "rebuilt from its journal; a journal with damaged stretches compacted to its whole records "
                     "(the original kept beside it); a campaign file without a journal given one. Refused while "
                     "a run holds the campaign.",
                     "rig repair campaign.h5")
    repair.add_argument("campaign", type=Path, help="campaign file (HDF5)")


def _add_check(commands: Commands) -> None:
    """Contact a rig's instruments."""
    check = command(commands, "check", "contact every instrument of a rig and describe each in one line",
                    "Connect to the chamber, the turntable and every sensor of a rig config, check their "
                    "identities and print what they report. Run it before leaving a campaign overnight.",
                    "rig check configs/example-lab.yaml")
    check.add_argument("rig", type=Path, help="rig config YAML")
    check.add_argument("--dry-run", action="store_true", help="check the rig's simulators instead")
    check.add_argument("--only", action="append", choices=["chamber", "turntable", "sensors"],
                       help="check only this instrument (repeat for more); the rig config may then leave out the "
                            "others' sections")
    check.add_argument("--faults", metavar="KEY=VALUE,...", help=FAULTS_HELP)


def _add_characterise(commands: Commands) -> None:
    """Fit a rig's thermal constants to a finished campaign."""
    characterise = command(
        commands, "characterise", "fit the rig's thermal constants to a finished campaign's ramps and soaks",
        "Fit the chamber's heating and cooling rates (and the floor cooling slows towards), its air's lag and "
        "overshoot, and each DUT's lag, to the air and DUT temperatures a campaign polled during its ramps and "
        "soaks; compare the campaign's duration with its estimate, with the constants it ran with and with the "
        "fitted ones; on a dry run, print the simulator's constants beside them. --write puts them into a rig "
        "config's thermal: section (its comments kept), so rig plan's next estimate is the rig's own.",
        "rig characterise campaign.h5 --write configs/lab-2.yaml")
    characterise.add_argument("campaign", type=Path, help="campaign file (HDF5)")
    characterise.add_argument("--write", type=Path, metavar="RIG", help="write the constants into this rig config")
    characterise.add_argument("--json", action="store_true", help="print one JSON object")


def _add_sim(commands: Commands) -> None:
    """Serve the simulated rig."""
    sim = command(commands, "sim", "serve the simulated rig as real endpoints until interrupted",
                  "Start the simulated rig of a rig config: the chamber on Modbus TCP or its line protocol "
                  "over TCP (127.0.0.1), the turntable and each sensor bridge on a pseudo-terminal, in real "
                  "time. The first line on "
                  "stdout is one JSON object with the endpoints. Ctrl-C stops it.",
                  "rig sim configs/sim.yaml")
    sim.add_argument("rig", type=Path, help="rig config YAML")
    sim.add_argument("--seed", type=SEED, default=0, help="seed of the simulated noise (default 0)")
    sim.add_argument("--faults", metavar="KEY=VALUE,...", help=FAULTS_HELP)
    sim.add_argument("--chamber-profile", metavar="PROFILE", help=CHAMBER_PROFILE_HELP)
