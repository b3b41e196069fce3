"""The host build of the bridge firmware, made once per session for every test of tests/firmware."""

from __future__ import annotations

from pathlib import Path

import pytest

from tests.firmware.host_firmware import make


@pytest.fixture(scope="session")
def bridge_host(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The host build, made once per session in a folder of its own (the source tree stays clean)."""
    build = tmp_path_factory.mktemp("firmware-build")
    make("host", build)
    return build / "host" / "bridge-host"
