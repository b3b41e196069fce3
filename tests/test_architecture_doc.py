"""docs/architecture.md is the map of the house: every file, module and package it names exists, so a move or a
removal that leaves the page behind fails here."""

from __future__ import annotations

import re

from tests.conftest import REPO

PAGE = REPO / "docs" / "architecture.md"
PACKAGE = REPO / "accelcal_rig"


def _named_paths(text: str) -> set[str]:
    """Every `code` span that is a path of a source or config file or a folder (`fit/sfem.py`, `cli/grammar/`,
    `configs/sim-mixed.yaml`)."""
    spans = re.findall(r"`([^`\s]+)`", text)
    return {s for s in spans if re.fullmatch(r"[A-Za-z0-9_./-]+(\.py|\.yaml|/)", s)}


def _exists(path: str) -> bool:
    return any((root / path).exists() for root in (PACKAGE, REPO))


def test_every_file_the_page_names_exists() -> None:
    named = _named_paths(PAGE.read_text(encoding="utf-8"))
    assert len(named) > 40  # the page names the files one adds: a regex that found none would prove nothing
    assert sorted(p for p in named if not _exists(p)) == []


def test_every_package_in_its_layers_table_exists() -> None:
    rows = [line for line in PAGE.read_text(encoding="utf-8").splitlines() if line.startswith("| ")]
    table = rows[rows.index(next(r for r in rows if r.startswith("| layer |"))) + 1:]
    names = {name for row in table if len(row.split("|")) > 3 for name in re.findall(r"`([a-z_]+)`", row.split("|")[2])}
    assert {"cli", "fit", "engine", "errors"} <= names
    assert sorted(n for n in names if not (PACKAGE / n).is_dir() and not (PACKAGE / f"{n}.py").is_file()) == []


def test_the_proof_lists_the_magnetometers_files() -> None:
    proof = PAGE.read_text(encoding="utf-8").split("## The proof: a magnetometer")[1]
    for path in ("parts/lis3mdl.py", "instruments/lis3mdl_driver.py", "sim/lis3mdl_registers.py",
                 "fit/magnetic_field.py", "engine/references.py", "configs/sim-mixed.yaml"):
        assert f"`{path}`" in proof and _exists(path)
