"""Run the site's getting-started commands verbatim, as a lab would: the block after the marker in
docs/getting-started.md, in an empty folder holding only dist/ with the built wheel. Its last line, `rig serve`,
runs until it is stopped: it is started in the background, its page fetched, then stopped with Ctrl-C (SIGINT),
which must end it with exit code 0. Then, with --then SCRIPT, SCRIPT runs with that virtual environment as its
argument (CI installs the example plug-in into it: examples/ci-check.sh).

Usage: python3 .ci/getting_started.py DIST_FOLDER [--then SCRIPT]"""

from __future__ import annotations

import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import urllib.request
from pathlib import Path

PAGE = Path(__file__).resolve().parent.parent / "docs" / "getting-started.md"
MARKER = "<!-- CI runs the next block verbatim"


def block() -> list[str]:
    text = PAGE.read_text(encoding="utf-8")
    after = text[text.index(MARKER):]
    found = re.search(r"```sh\n(.*?)```", after, re.S)
    if found is None:
        sys.exit(f"{PAGE}: no sh block after the CI marker")
    return [line for line in found.group(1).splitlines() if line.strip()]


def main() -> int:
    dist = Path(sys.argv[1]).resolve()
    then = Path(sys.argv[3]).resolve() if len(sys.argv) == 4 and sys.argv[2] == "--then" else None
    lines = block()
    if not lines[-1].startswith("rig serve"):
        sys.exit(f"{PAGE}: the block's last line is not rig serve: {lines[-1]!r}")
    folder = Path(tempfile.mkdtemp(prefix="getting-started-"))
    shutil.copytree(dist, folder / "dist")
    log = folder / "serve.out"
    script = "set -euxo pipefail\n" + "\n".join(lines[:-1]) + f"\nexec {lines[-1]} > {log} 2>&1\n"
    # A fresh machine's home: the registries the commands find by default are the folder's, not this user's.
    env = {**os.environ, "XDG_DATA_HOME": str(folder / "home-data")}
    server = subprocess.Popen(["bash", "-c", script], cwd=folder, env=env, start_new_session=True)
    try:
        url = wait_for_address(server, log)
        with urllib.request.urlopen(url, timeout=30) as page:  # noqa: S310 - the local dashboard just started
            body = page.read().decode()
        if "paper" not in body:
            sys.exit(f"the dashboard at {url} does not show the campaign paper.h5")
        print(f"getting started: every command ran; the dashboard at {url} shows the campaign", flush=True)
        server.send_signal(signal.SIGINT)
        code = server.wait(timeout=60)
        if code != 0:
            sys.exit(f"rig serve ended with exit code {code} on Ctrl-C:\n{log.read_text()}")
    finally:
        if server.poll() is None:
            server.kill()
    if then is not None:
        subprocess.run(["bash", str(then), str(folder / "venv")], check=True)
    shutil.rmtree(folder, ignore_errors=True)
    return 0


def wait_for_address(server: subprocess.Popen[bytes], log: Path, deadline_s: float = 900.0) -> str:
    """The dashboard's address once `rig serve` printed it; the commands before it may take minutes (pip)."""
    end = time.monotonic() + deadline_s
    while time.monotonic() < end:
        if server.poll() is not None:
            sys.exit(f"a getting-started command failed (exit {server.returncode})"
                     + (f":\n{log.read_text()}" if log.exists() else ""))
        found = re.search(r"dashboard on (http://\S+)", log.read_text() if log.exists() else "")
        if found:
            return found.group(1)
        time.sleep(0.2)
    sys.exit(f"rig serve printed no address within {deadline_s:.0f} s")


if __name__ == "__main__":
    sys.exit(main())
