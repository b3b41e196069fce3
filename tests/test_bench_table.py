"""bench/table.py renders docs/performance.md from stored results: a stored result gives its value, command, date
and commit; a bench with none still has its rows, saying how to measure it. No bench is run here."""

from __future__ import annotations

import importlib.util
import json
import sys
from pathlib import Path
from types import ModuleType

from tests.conftest import REPO


def table_module() -> ModuleType:
    """bench/table.py, imported by path (bench/ is a folder of scripts, not a package)."""
    spec = importlib.util.spec_from_file_location("bench_table", REPO / "bench" / "table.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module   # the dataclasses look their module up by name
    spec.loader.exec_module(module)
    return module


def rows_of(page: str, command: str) -> list[list[str]]:
    """The table's rows whose command cell is `command`, split into their cells."""
    return [[c.strip() for c in line.strip("|").split(" | ")] for line in page.splitlines()
            if line.startswith("| ") and f"`{command}`" in line]


def test_a_stored_result_gives_its_value_commit_and_date_and_a_missing_one_says_how_to_measure(tmp_path: Path) -> None:
    table = table_module()
    stored = {"bench": "startup", "command": "python bench/startup.py --runs 5 --json", "quick": False,
              "date": "2031-02-03T04:05:06Z", "commit": "abc1234+dirty", "exit_code": 0, "wall_s": 1.0,
              "machine": {"cpus": 2, "python": "3.11.7", "load_average_at_start": [0.1, 0.1, 0.1]},
              "output": {"median_wall_ms": 44.6, "heavy_imports": []}}
    (tmp_path / "startup.json").write_text(json.dumps(stored), encoding="utf-8")

    page = table.render(tmp_path)

    [startup] = rows_of(page, "python bench/startup.py --runs 5 --json")
    figure, _, value, date, commit = startup
    assert figure.startswith('<a id="startup"></a>`rig --help`')
    assert "**45 ms**" in value and "imports none of them" in value and value.endswith(": met")
    assert (date, commit) == ("2031-02-03", "abc1234+dirty")

    registry = rows_of(page, "python bench/registry.py --json")
    assert len(registry) == len(table.BY_NAME["registry"].rows) >= 1
    for _, _, value, date, commit in registry:
        assert value.startswith("not measured yet — run: `python bench/table.py run registry`")
        assert (date, commit) == ("—", "—")
    assert '<a id="registry"></a>' in page and '<a id="dashboard"></a>' in page   # docs/registry.md, dashboard.md
    assert page.count("| figure | command | value | date | commit |") == 1


def test_a_figure_the_stored_run_did_not_measure_says_so(tmp_path: Path) -> None:
    table = table_module()
    quick = {"bench": "large_fixture", "command": "python bench/large_fixture.py --sizes 4 --json", "date": "2031-02-03",
             "commit": "abc1234", "output": {"paper_dry_run": [{"duts": 4, "wall_s": 6.0, "cpu_s": 9.0, "peak_rss_mb": 200}]}}
    (tmp_path / "large_fixture.json").write_text(json.dumps(quick), encoding="utf-8")
    (tmp_path / "throughput.json").write_text(json.dumps({**quick, "bench": "throughput", "command": "python bench/throughput.py",
                                                          "output": {"methods": []}}), encoding="utf-8")

    page = table.render(tmp_path)

    [fixture] = rows_of(page, "python bench/large_fixture.py --sizes 4 --json")
    assert "4 DUTs 6.0 s (1.50 s per DUT)" in fixture[2] and fixture[2].endswith("target 64 DUTs < 30 s")  # no verdict
    assert all(r[2].startswith("not in the stored run") for r in rows_of(page, "python bench/throughput.py"))


def test_the_output_a_bench_ends_with_is_found_after_its_lines() -> None:
    table = table_module()
    assert table.last_json('{"a": 1}') == {"a": 1}
    assert table.last_json('rig --help: median 44 ms\n{"median_wall_ms": 44.0}\n') == {"median_wall_ms": 44.0}
    assert table.last_json('3 trials\n{\n "x": {\n  "y": 2\n }\n}\n') == {"x": {"y": 2}}


def test_the_page_is_the_table_of_the_stored_results() -> None:
    """docs/performance.md is written by the script, never by hand: a result stored without the page rewritten,
    or the page edited, fails here."""
    table = table_module()
    assert table.PAGE.read_text(encoding="utf-8") == table.render(table.RESULTS), "run: python bench/table.py write"
