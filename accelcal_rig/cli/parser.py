"""The `rig` command line's grammar, assembled: the commands in the order `rig --help` lists them, each group's
in its module of accelcal_rig.cli.grammar; and the bash completion script made from it.

Parsing imports nothing heavy: `rig --help` and a mistyped option answer at once.
"""

from __future__ import annotations

import argparse

from accelcal_rig import __version__
from accelcal_rig.cli.grammar.analysis import add_analysis_commands
from accelcal_rig.cli.grammar.approval import add_approve_command
from accelcal_rig.cli.grammar.campaign import add_campaign_commands
from accelcal_rig.cli.grammar.common import Parser
from accelcal_rig.cli.grammar.documents import add_document_commands
from accelcal_rig.cli.grammar.fitting import add_fit_commands
from accelcal_rig.cli.grammar.registry import add_registry_commands
from accelcal_rig.cli.grammar.service import (
    add_completion_command,
    add_init_command,
    add_schema_command,
    add_serve_command,
)


def build_parser() -> argparse.ArgumentParser:
    parser = Parser(prog="rig", description="Run unattended thermal calibration campaigns of MEMS accelerometers, gyroscopes and IMUs.")
    parser.add_argument("--version", action="version", version=f"accelcal-rig {__version__}")
    commands = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    add_init_command(commands)
    add_campaign_commands(commands)     # run, plan, resume, status, repair, check, sim
    add_fit_commands(commands)          # fit, fit-recording
    add_analysis_commands(commands)     # analyze
    add_registry_commands(commands)     # registry
    add_approve_command(commands)       # approve
    add_completion_command(commands)
    add_schema_command(commands)
    add_serve_command(commands)
    add_document_commands(commands)     # report, certificate, export
    return parser


def bash_completion(parser: argparse.ArgumentParser) -> str:
    """A bash completion script generated from the parser itself, so it never falls behind the commands."""
    words: dict[str, list[str]] = {"": []}

    def walk(command: argparse.ArgumentParser, key: str) -> None:
        options = [o for action in command._actions for o in action.option_strings]
        children: list[str] = []
        for action in command._actions:
            if isinstance(action, argparse._SubParsersAction):
                for name, sub in action.choices.items():
                    children.append(name)
                    walk(sub, f"{key} {name}".strip())
        words[key] = children + options

    walk(parser, "")
    cases = "\n".join(f'        "{key}") words="{" ".join(sorted(set(value)))}" ;;' for key, value in sorted(words.items()))
    return f"""# bash completion for rig (accelcal-rig), made by `rig completion bash`
_rig() {{
    local current="${{COMP_WORDS[COMP_CWORD]}}" path="" word words
    for word in "${{COMP_WORDS[@]:1:COMP_CWORD-1}}"; do
        case "$word" in -*) continue ;; esac
        if _rig_words "${{path:+$path }}$word" >/dev/null; then path="${{path:+$path }}$word"; fi
    done
    words=$(_rig_words "$path")
    if [[ "$current" == -* || -n "$words" ]]; then
        COMPREPLY=($(compgen -W "$words" -- "$current"))
    fi
    [[ ${{#COMPREPLY[@]}} -eq 0 ]] && COMPREPLY=($(compgen -f -- "$current"))
    return 0
}}
_rig_words() {{
    local words=""
    case "$1" in
{cases}
        *) return 1 ;;
    esac
    echo "$words"
}}
complete -o filenames -F _rig rig
"""
