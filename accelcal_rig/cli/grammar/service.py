"""The grammar of the commands that serve the operator's tools: `rig init`, `rig completion`, `rig schema` and
`rig serve`."""

from __future__ import annotations

from pathlib import Path

from accelcal_rig.cli.grammar.common import Commands, command, number, registry_option


def add_init_command(commands: Commands) -> None:
    """`rig init`: a lab folder with the starting set of procedures, rig configs and schemas."""
    init = command(commands, "init", "write a lab folder: the shipped procedures, rig configs and schemas to edit",
                   "Write the starting set the package ships into FOLDER (new, or empty: nothing of yours is "
                   "replaced): procedures/ (the paper's campaign, a quick one, IMU campaigns), configs/ (simulated "
                   "rigs for --dry-run, and example-lab.yaml, the template of a real rig) and schemas/ (the JSON "
                   "Schemas each file names in its first line, for an editor), with a README. Then, in FOLDER: "
                   "rig run procedures/paper-24pos-thermal.yaml --dry-run -o paper.h5",
                   "rig init lab")
    init.add_argument("folder", type=Path, help="the folder to write (new, or empty)")


def add_completion_command(commands: Commands) -> None:
    """`rig completion`: a shell completion script."""
    completion = command(commands, "completion", "print a shell completion script",
                         "Print a completion script for bash (commands, their actions and options; file names "
                         "elsewhere). Load it now with eval \"$(rig completion bash)\", or for good: "
                         "rig completion bash > ~/.local/share/bash-completion/completions/rig",
                         "rig completion bash > ~/.local/share/bash-completion/completions/rig")
    completion.add_argument("shell", choices=["bash"])


def add_schema_command(commands: Commands) -> None:
    """`rig schema`: the JSON Schema of a procedure or a rig config, for an editor."""
    schema = command(commands, "schema", "print the JSON Schema of a procedure or a rig config, for an editor",
                     "Print (or write with -o) the JSON Schema the procedure or rig-config models validate against: "
                     "an editor with the YAML language server completes and checks keys with it when a file's "
                     "first line names it (# yaml-language-server: $schema=PATH). The package ships both "
                     "(rig init writes them into a lab folder's schemas/), and every shipped procedure and rig config names "
                     "its own.",
                     "rig schema procedure -o procedure.schema.json")
    schema.add_argument("kind", choices=["procedure", "rig-config"])
    schema.add_argument("-o", "--output", type=Path, help="write it here (default: standard output)")


def add_serve_command(commands: Commands) -> None:
    """`rig serve`: the web dashboard."""
    serve = command(commands, "serve", "a local web dashboard of campaigns and the registry",
                    "Serve the dashboard: running and recent campaigns of the watched folders (state, phase, "
                    "setpoint, temperatures, poses, time left, warnings, refreshed live), each campaign's "
                    "temperature plot, report and certificates, and the registry (a serial's history and "
                    "trend, a part's lot). Campaign files are only read, as rig status reads them. It listens "
                    "on 127.0.0.1; another address needs --token (and TLS is advised: --tls-cert, --tls-key). "
                    "Needs: pip install 'accelcal-rig[dashboard]'.",
                    "rig serve --campaigns campaigns/ --port 8040")
    serve.add_argument("--campaigns", type=Path, action="append", metavar="DIR",
                       help="a folder of campaign files to show (repeatable; default: the current folder)")
    registry_option(serve)
    serve.add_argument("--config", type=Path, metavar="RIG", help="rig config whose registry: to use")
    serve.add_argument("--host", default="127.0.0.1", help="address to listen on (default 127.0.0.1)")
    serve.add_argument("--port", type=number(0, 65535, integer=True), default=8040,
                       help="port (default 8040; 0: any free one, printed)")
    serve.add_argument("--token", help="a secret every request must carry (needed off 127.0.0.1; default "
                                       "$ACCELCAL_DASHBOARD_TOKEN)")
    serve.add_argument("--tls-cert", type=Path, help="TLS certificate (PEM), with --tls-key: serve HTTPS")
    serve.add_argument("--tls-key", type=Path, help="its private key (PEM)")
    serve.add_argument("--user-header", metavar="HEADER",
                       help="the lab's reverse proxy authenticates users and names them in this header (e.g. "
                            "X-Remote-User): approvers are those the registry gives the approver role. Use only "
                            "behind a proxy that sets it and strips it from what clients send; without it, "
                            "approvers log in with their registry password")
