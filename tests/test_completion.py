"""`rig completion bash`: a script made from the parser itself, which bash loads and completes with."""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

RIG = str(Path(sys.executable).parent / "rig")


def complete(script: str, *words: str) -> list[str]:
    """What bash offers for the last of `words` after `rig`, with the script loaded."""
    array = " ".join(f"'{w}'" for w in ("rig", *words))
    run = subprocess.run(["bash", "-c", f'{script}\nCOMP_WORDS=({array}); COMP_CWORD={len(words)}; _rig; '
                          'printf "%s\\n" "${COMPREPLY[@]}"'], capture_output=True, text=True, timeout=30)
    assert run.returncode == 0, run.stderr
    return run.stdout.split()


def test_bash_completes_commands_actions_and_options() -> None:
    assert shutil.which("bash")
    script = subprocess.run([RIG, "completion", "bash"], capture_output=True, text=True, check=True).stdout
    assert complete(script, "re") == ["registry", "repair", "report", "resume"]
    assert complete(script, "registry", "s") == ["show", "stats"]
    assert complete(script, "registry", "list", "--s") == ["--serial", "--simulated", "--since"]
    assert "--chamber-profile" in complete(script, "run", "--c")
    assert complete(script, "analyze", "t") == ["tilt"]
