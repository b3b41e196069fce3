"""docs/performance.md as one current table, made from the benches' own `--json` output. Usage:

    python bench/table.py run [BENCH …] [--quick]   # run benches (default: every one in BENCHES), each result
                                                    # stored as bench/results/BENCH.json
    python bench/table.py write                     # docs/performance.md from bench/results/*.json
    python bench/table.py list                      # the benches, their commands full and quick

Why: a figure is only worth the command, the commit and the date beside it. A stored result keeps the three
with the bench's own output; the page is rendered from those, each row's value read from the output by the
mapping below (BENCHES), so no figure is typed by hand and none outlives the run that measured it. Past
figures are in git history, not in a diary on the page.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

REPO = Path(__file__).resolve().parent.parent
RESULTS = REPO / "bench" / "results"
PAGE = REPO / "docs" / "performance.md"
#: What this script writes: a change there does not make the measured tree dirty.
OUTPUTS = ("bench/results", "docs/performance.md")

Output = dict[str, Any]


@dataclass(frozen=True)
class Row:
    """One figure of a bench: its text, its value read from the bench's JSON output (with units), and the
    target or bound it is held to, with whether the output meets it."""

    figure: str
    value: Callable[[Output], str]
    target: str = ""
    met: Callable[[Output], bool] | None = None


@dataclass(frozen=True)
class Bench:
    """A bench the table runs: `script` with `args` (its full form, `--json` included) or `quick` (under ~3
    minutes on the development machine; None: the full form is that already); `script` None for a figure with
    no bench, whose results file is written by hand from a recorded run."""

    name: str
    script: str | None
    args: tuple[str, ...]
    rows: tuple[Row, ...]
    quick: tuple[str, ...] | None = None
    about: str = ""                # how long the full form takes, for `list` and the not-measured rows
    hand_command: str = ""         # the command of a figure with no bench (script None)

    def command(self, quick: bool = False) -> str:
        if self.script is None:
            return self.hand_command
        return " ".join(["python", f"bench/{self.script}", *(self.quick if quick and self.quick else self.args)])


# --- reading values out of the benches' outputs -------------------------------------------------------------


def thousands(value: float) -> str:
    """12 345 678: groups of three digits split by a space, as the docs write large counts."""
    return f"{value:,.0f}".replace(",", " ")


def count(n: int, noun: str) -> str:
    """'1 seed', '3 seeds'."""
    return f"{n} {noun}{'' if n == 1 else 's'}"


def span(values: Sequence[float], fmt: str = ".2f") -> str:
    """'low … high', or the one value when they print the same."""
    low, high = min(values), max(values)
    return f"{low:{fmt}}" if f"{low:{fmt}}" == f"{high:{fmt}}" else f"{low:{fmt}} … {high:{fmt}}"


def method(output: Output, name: str) -> Output:
    """One method's record of bench/throughput.py (a list) or bench/imu_throughput.py (a dict); KeyError if the
    stored run did not measure it."""
    methods = output["methods"]
    if isinstance(methods, dict):
        return methods[name]
    for record in methods:
        if record["method"] == name:
            return record
    raise KeyError(name)


def within(values: Sequence[float], low: float, high: float) -> bool:
    return all(low <= v <= high for v in values)


def dry_run_paper(r: Output) -> str:
    walls = [run["wall_s"] for run in r["runs"]]
    return (f"median **{r['wall_median_s']:.2f} s** ({span(walls)} s over {len(walls)} runs), peak "
            f"{span([run['peak_rss_mb'] for run in r['runs']], '.0f')} MiB; {span([run['virtual_h'] for run in r['runs']])} h "
            f"of rig time, campaign file {span([run['file_mb'] for run in r['runs']])} MB")


def dry_run_ab(r: Output) -> str:
    return (f"wall median {r['a_wall_median_s']:.1f} s against {r['b_wall_median_s']:.1f} s: ratio **{r['ratio_median']:.2f}** "
            f"({span(r['ratio_range'])}, {len(r['pairs'])} pairs); peak {r['a_peak_median_mib']:.0f} against "
            f"{r['b_peak_median_mib']:.0f} MiB")


def imu_paper(r: Output) -> str:
    ratios = [d["ratio"] for d in r["duts"].values()]
    passed = sum(d["verdict"] == "PASS" for d in r["duts"].values())
    shapes = {tuple(d["gyro_raw_codes_shape"]) for d in r["duts"].values()}
    return (f"{span(ratios)} × (worst **{r['worst_ratio']:.2f} ×**), {passed} of {len(ratios)} PASS; gyroscope raw "
            f"codes stored, shape {' / '.join(str(list(s)) for s in sorted(shapes))}")


def imu_accuracy(r: Output, name: str) -> str:
    m = method(r, name)
    return (f"accelerometer median {m['accel']['ratio_median_of_medians']:.2f} ×, worst **{m['accel']['ratio_worst']:.2f} ×**; "
            f"gyroscope median {m['gyro']['ratio_median_of_medians']:.2f} ×, worst **{m['gyro']['ratio_worst']:.2f} ×** "
            f"(worst IMU of {count(m['seeds'], 'seed')})")


def imu_coverage(r: Output, name: str) -> str:
    m = method(r, name)
    return (f"accelerometer **{span(m['accel']['coverage_k2_range'], '.3f')}**, gyroscope "
            f"**{span(m['gyro']['coverage_k2_range'], '.3f')}** (over {count(m['seeds'], 'seed')})")


def imu_rig_time(r: Output, name: str) -> str:
    m = method(r, name)
    return f"**{m['rig_hours_median']:.2f} h** (median of {count(m['seeds'], 'seed')}; longest {m['rig_hours_worst']:.2f} h)"


FAST = "bidirectional-ramp"


def fast_rig_time(r: Output) -> str:
    m = method(r, FAST)
    return (f"**{m['rig_hours']:.2f} h** ({m['rig_hours_per_dut']:.3f} h per DUT, {m['rig_time_over_lower_bound']:.2f} × "
            f"the lower bound of {m['lower_bound_hours']:.2f} h; median of {count(m['seeds'], 'seed')})")


def fast_verification(r: Output) -> str:
    m = method(r, FAST)
    return (f"median DUT {m['verification_over_expected_median']:.2f} ×, worst DUT **{m['verification_over_expected']:.3f} ×** "
            f"(median over {count(m['seeds'], 'seed')}; the worst of any seed {m['verification_over_expected_any_seed']:.2f} ×)")


def fast_at_rest(r: Output) -> str:
    m = method(r, FAST)
    return (f"at rest **{m['at_rest_rmse_mg']:.4f} mg** RMSE, {m['at_rest_drift_mg']:.3f} mg drift; residual drift "
            f"{m['residual_drift_mg']:.3f} mg; as applied {m['verification_as_applied_rmse_mg']:.3f} mg RMSE; warming "
            f"minus cooling {m['hysteresis_mg']:.3f} mg")


def throughput_method(r: Output, name: str) -> str:
    """A method's figures in one cell: rig time, verification against expected, drift, at rest."""
    m = method(r, name)
    hysteresis = "not visible to it" if m["hysteresis_mg"] is None else f"{m['hysteresis_mg']:.3f} mg"
    return (f"rig {m['rig_hours']:.2f} h ({m['rig_hours_per_dut']:.3f} h per DUT, {m['rig_time_over_lower_bound']:.2f} × "
            f"the lower bound); worst DUT's verification RMSE {m['verification_over_expected']:.2f} × expected; residual "
            f"drift {m['residual_drift_mg']:.3f} mg; at rest {m['at_rest_rmse_mg']:.4f} mg RMSE, {m['at_rest_drift_mg']:.3f} mg "
            f"drift; hysteresis {hysteresis} (median of {count(m['seeds'], 'seed')})")


def uncertainty_site(r: Output, site: str) -> str:
    cells = []
    for mode in ("reference", "norm-only"):
        c = r[f"{site}, {mode}"]
        cells.append(f"{mode} **{100 * c['observed_coverage_k2']:.2f} %** (per DUT and run {100 * c['per_dut_min']:.1f} … "
                     f"{100 * c['per_dut_max']:.1f} %, largest U {c['expanded_uncertainty_mg_worst']:.3f} mg)")
    return "; ".join(cells) + f"; {r[f'{site}, reference']['dut_runs']} DUT-runs"


def uncertainty_honest(r: Output, name: str) -> str:
    m = r["methods"][name]
    return (f"**{100 * m['coverage_k2']:.2f} %** of {thousands(m['axis_errors'])} axis errors (error/u RMS {m['z_rms']:.2f}; "
            f"per DUT and run {100 * m['per_dut_min']:.1f} … {100 * m['per_dut_max']:.1f} %; {count(m['runs'], 'run')} × {m['duts']} DUTs)")


def dashboard_registry(r: Output, registry: str) -> Output:
    for result in r["results"]:
        if result["registry"] == registry:
            return result
    raise KeyError(registry)


def dashboard_load(r: Output, registry: str) -> str:
    x = dashboard_registry(r, registry)
    return (f"`/` p50 {x['/']['p50_s']:.3f} s, p99 **{x['/']['p99_s']:.2f} s**; live page p99 {x['live']['p99_s']:.2f} s; "
            f"static p99 {x['static']['p99_s']:.2f} s; server {x['server_memory']['rss_mib']} MiB resident "
            f"({x['server_memory']['peak_mib']} MiB peak); load: {r['pages']} pages, {r['streams']} streams, "
            f"{r['flood']} wrong logins, {r['seconds']:g} s")


def live_pages(r: Output) -> str:
    d, pages = r["dashboard"], r["dashboard"]["pages"]
    return (f"{d['rigs']} rigs × {d['campaigns_per_rig']} campaigns ({d['backend']}): " + "; ".join(
        f"{name} median {p['median_ms']:.1f} ms (slowest {p['max_ms']:.0f} ms)" for name, p in pages.items()))


def large_fixture(r: Output) -> str:
    runs = r["paper_dry_run"]
    return "; ".join(f"{x['duts']} DUTs {x['wall_s']:.1f} s ({x['wall_s'] / x['duts']:.2f} s per DUT)" for x in runs)


def large_fixture_64(r: Output) -> bool:
    return next(x["wall_s"] for x in r["paper_dry_run"] if x["duts"] == 64) < 30


def soak_criteria(r: Output, duts: int) -> str:
    runs = [x for x in r["runs"] if x["n_duts"] == duts]
    if not runs:
        raise KeyError(duts)
    cells = []
    for x in runs:
        head = f"{x['criterion']}, {x['poll_s']:.0f} s poll: "
        if x["state"] != "done":
            cells.append(head + f"**{x['state']}**")
            continue
        cells.append(head + f"{x['soak_hours']:.2f} h (longest {max(x['soak_minutes']):.0f} min), "
                     f"{x['verification_rmse_mg']:.4f} / {x['residual_drift_mg']:.4f} mg")
    return "; ".join(cells)


def gyro_figures(r: Output) -> str:
    return (f"{thousands(r['truth_errors'])} truth errors: z scatter {r['truth_z_std']:.2f}, "
            f"{100 * r['truth_z_share_within_3']:.1f} % within 3σ; verification rate RMS ≤ "
            f"{r['verification_rmse_before_dps_worst']:.2f} °/s raw → ≤ {r['verification_rmse_after_dps_worst']:.4f} °/s "
            f"compensated; ARW {span(r['arw_over_white_noise_range'])} × the white noise's alone; bias instability "
            f"median {r['bias_instability_bound_median_dph']:.2f} °/h against the simulated "
            f"{r['bias_instability_truth_dph']:g} °/h; {r['wall_s_median']:.0f} s wall per dry run (median)")


def registry_queries(r: Output) -> str:
    ms = {k: 1e3 * r[k] for k in ("history_of_a_serial_s", "valid_calibration_s", "trend_s", "stored_fit_by_id_s")}
    return (f"{ms['history_of_a_serial_s']:.2f} / {ms['valid_calibration_s']:.2f} / {ms['trend_s']:.2f} ms; a stored fit "
            f"by id {ms['stored_fit_by_id_s']:.2f} ms; {thousands(r['listed'])} rows since a date in "
            f"{r['list_since_date_s']:.2f} s; lot statistics of {thousands(r['lot_sensors'])} sensors in "
            f"{r['lot_statistics_of_a_part_s']:.2f} s")


THROUGHPUT_RIG = ("16 ADXL355 on `configs/sim-honest.yaml` (overshoot, cooling slowing towards its floor, slot-to-slot "
                  "air, the fixture's lag) with the sensors' own effects (bench/throughput.py's `SENSOR_EFFECTS`: 0.2 mg "
                  "hysteresis relaxing over 2 h, rate-of-change terms) and 48 verification poses at rest")
IMU_RIG = ("sixteen ICM-42688-P on `configs/sim-imu16.yaml` (the same honest rig physics; the accelerometers given "
           "`SENSOR_EFFECTS`, the gyroscopes their thermal model, noise and 5 °/h bias wander)")
UNCERTAINTY_HONEST = {"soak": "soak (`paper-24pos-thermal`)", "ramp": "ramp (`paper-24pos-ramp`)",
                      "bidirectional-ramp": "bidirectional ramp (`fast-bidirectional-ramp`)"}

#: Every bench the table shows, in the page's order, each with its rows. A bench not here is not run by `run`.
BENCHES: tuple[Bench, ...] = (
    Bench("dry_run_paper", "dry_run_paper.py", ("--runs", "3", "--json"), about="1 min", rows=(
        Row("the paper campaign's dry run, whole process: `rig run procedures/paper-24pos-thermal.yaml --dry-run` "
            "(432 poses × 4 ADXL355 through the wire-level simulators, the fit, four certificates with PDFs)",
            dry_run_paper, "< 20 s", lambda r: r["wall_median_s"] < 20),
        Row("the same campaign alone (fit incl., imports and certificates excl.): through the wires against the "
            "in-process simulated instruments, interleaved",
            lambda r: (f"{r['campaign_alone']['wire_median_s']:.2f} s / {r['campaign_alone']['in_process_median_s']:.2f} s "
                       f"= **{r['campaign_alone']['ratio']:.2f} ×** (medians)"),
            "≤ 2 ×", lambda r: r["campaign_alone"]["ratio"] <= 2),
    )),
    Bench("dry_run_ab", "dry_run_ab.py", ("--runs", "3", "--json"), quick=("--runs", "1", "--json"), about="1.5 min", rows=(
        Row("the IMU paper dry run (`paper-24pos-imu.yaml`: 432 poses × 4 ICM-42688-P, the FIFO captured by the "
            "bridge) against the ADXL355 paper dry run (the same poses × 4), `--no-pdf --no-publish --seed 11`, "
            "alternated pair by pair", dry_run_ab, "IMU ≤ 2 × ADXL355", lambda r: r["ratio_median"] <= 2),
    )),
    Bench("imu_paper", "imu_paper.py", ("--json",), about="15 s", rows=(
        Row("the paper campaign on four ICM-42688-P (`paper-24pos-imu.yaml`, seed 11): `rig run --dry-run --no-pdf`, "
            "whole process", lambda r: f"{r['wall_s']:.1f} s wall"),
        Row("its accelerometers: each IMU's verification \\|g\\| RMSE over its expected fit RMSE", imu_paper,
            "≤ 1.2 ×", lambda r: r["worst_ratio"] <= 1.2),
    )),
    Bench("large_fixture", "large_fixture.py", ("--json",), quick=("--sizes", "4,16", "--json"), about="1.5 min", rows=(
        Row("the paper dry run (432 poses, the fit of every DUT, `--no-pdf`) by fixture size, each DUT behind its own "
            "simulated bridge, one `rig run` process each: wall time", large_fixture, "64 DUTs < 30 s",
            large_fixture_64),
    )),
    Bench("throughput", "throughput.py", ("--seeds", "3", "--json"), about="2.5 min", quick=("--quick", "--json"), rows=(
        Row(f"the fast method (bidirectional ramp, `fast-bidirectional-ramp.yaml`), {THROUGHPUT_RIG}: rig time",
            fast_rig_time),
        Row("the fast method: each DUT's verification \\|g\\| RMSE over its expected RMSE (what the noise alone "
            "would leave on the checks)", fast_verification,
            "every DUT ≤ 1.2 ×", lambda r: method(r, FAST)["verification_over_expected"] <= 1.2),
        Row("the fast method against the simulation's truth at rest (100 orientations every 0.5 °C of the calibrated "
            "range); its verification's residual drift; the calibration alone as applied; the hysteresis it finds "
            "(simulated: 2 × 0.2 mg)", fast_at_rest,
            "residual drift ≤ 0.3 mg", lambda r: method(r, FAST)["residual_drift_mg"] <= 0.3),
        Row("the paper's soak at every setpoint (`paper-24pos-thermal.yaml`), the same rig and sensors",
            lambda r: throughput_method(r, "soak")),
        Row("the one-way ramp (`paper-24pos-ramp.yaml`, 0.5 °C/min), the same rig and sensors",
            lambda r: throughput_method(r, "ramp")),
    )),
    Bench("imu_throughput", "imu_throughput.py", ("--seeds", "2", "--methods", "fast,soak", "--json"), about="3.5 min",
          quick=("--quick", "--methods", "fast,soak", "--json"), rows=(
        Row(f"the fast IMU method (`imu-fast.yaml`, the bidirectional ramp with poses and rate steps in every band), "
            f"{IMU_RIG}: rig time", lambda r: imu_rig_time(r, "fast"), "≤ 6 h",
            lambda r: method(r, "fast")["rig_hours_worst"] <= 6),
        Row("the fast IMU method: each IMU's verification RMSE over its expected RMSE (`verification.expected_rmse_*`)",
            lambda r: imu_accuracy(r, "fast"), "every IMU ≤ 1.2 ×, both sensors",
            lambda r: max(method(r, "fast")[s]["ratio_worst"] for s in ("accel", "gyro")) <= 1.2),
        Row("the fast IMU method: k = 2 coverage of the verification errors against the truth, pooled over the IMUs",
            lambda r: imu_coverage(r, "fast"), "93–97 %",
            lambda r: within(method(r, "fast")["accel"]["coverage_k2_range"] + method(r, "fast")["gyro"]["coverage_k2_range"],
                             0.93, 0.97)),
        Row("the IMU soak method (`imu-thermal.yaml`), the same rig: rig time; verification over expected; coverage",
            lambda r: f"{imu_rig_time(r, 'soak')}; {imu_accuracy(r, 'soak')}; coverage {imu_coverage(r, 'soak')}"),
    )),
    Bench("soak_criteria", "soak_criteria.py", ("--duts", "4,64", "--json"), quick=("--duts", "4", "--json"),
          about="2 min", rows=(
        Row("the paper campaign's soaks (seed 0, plain simulated rig) by the band criterion (10 min window, 0.3 °C) and "
            "the settling criterion (20 min window, 0.1 °C still to come), polled every 30 s and 10 s, 4 DUTs: total "
            "soak time (longest soak), worst verification \\|g\\| RMSE / residual drift", lambda r: soak_criteria(r, 4)),
        Row("the same with 64 DUTs", lambda r: soak_criteria(r, 64)),
    )),
    Bench("uncertainty", "uncertainty.py", ("--runs", "10", "--json"), quick=("--runs", "3", "--json"), about="2 min",
          rows=tuple(
        Row(f"is the stated uncertainty true? Dry runs of the paper campaign (new noise, the same sensors) fitted in "
            f"both modes, {site}: each verification pose's axis errors against the truth inside U (k = 2)",
            lambda r, site=site: uncertainty_site(r, site), "93–97 %",
            lambda r, site=site: within([r[f"{site}, {m}"]["observed_coverage_k2"] for m in ("reference", "norm-only")],
                                        0.93, 0.97))
        for site in ("standard gravity", "site gravity 9.8123 ± 0.0002 m/s²"))),
    Bench("uncertainty_honest", "uncertainty.py", ("--honest", "--runs", "10", "--json"), about="13 min",
          quick=("--honest", "--runs", "1", "--json"), rows=tuple(
        Row(f"the same on bench/throughput.py's honest rig (16 DUTs, the sensors' effects), {label}, fitted as the "
            f"procedure says: axis errors against the truth inside U (k = 2)",
            lambda r, name=name: uncertainty_honest(r, name), "93–97 %",
            lambda r, name=name: 0.93 <= r["methods"][name]["coverage_k2"] <= 0.97)
        for name, label in UNCERTAINTY_HONEST.items())),
    Bench("gyro_coverage", "gyro_coverage.py", ("--seeds", "6", "--json"), quick=("--seeds", "1", "--json"),
          about="1 min", rows=(
        Row("a gyroscope's calibration over dry runs (tests/fit/test_gyro_fit.py's IMU campaign, −40 … 60 °C in 5 "
            "setpoints, degree 3, 120 s noise records, verified between the setpoints): k = 2 coverage against the truth",
            lambda r: (f"**{r['coverage_k2_mean']:.3f}** over {r['runs'] * r['duts_per_run']} IMUs (per IMU "
                       f"{span(r['coverage_k2_range'])}; {count(r['runs'], 'run')})"),
            "93–97 %", lambda r: 0.93 <= r["coverage_k2_mean"] <= 0.97),
        Row("the same runs: truth errors in units of their σ, rate errors, noise figures, wall time", gyro_figures),
    )),
    Bench("dashboard_load", "dashboard_load.py", ("--json",), about="1.5 min", rows=tuple(
        Row(f"`rig serve` under load (open pages polling the rigs fragment and the campaigns list, event-stream "
            f"clients, a flood of wrong logins), {label}: `/`, a published campaign's live page and a static file "
            f"fetched over and over from 1 s in; the server's memory", lambda r, key=key: dashboard_load(r, key),
            "p99 of `/` ≤ 1 s", lambda r, key=key: dashboard_registry(r, key)["/"]["p99_s"] <= 1.0)
        for key, label in (("sqlite", "SQLite registry"), ("postgresql", "PostgreSQL registry (a private server)"),
                           ("silent postgresql", "a PostgreSQL registry that accepts connections and never answers")))),
    Bench("dashboard", "dashboard.py", ("--json",), about="15 s", rows=(
        Row("the dashboard (`rig serve`, over HTTP on loopback) watching copies of the paper campaign's dry run "
            "(432 poses × 4 DUTs each): the front page, first load (every campaign read from its journal)",
            lambda r: f"{thousands(1e3 * r['first_front_page_s'])} ms ({r['campaigns']} campaigns)"),
        Row("the same, later loads (each campaign read again only when it changes; medians): the front page / "
            "`/api/campaigns` (what the page polls) / one campaign's page",
            lambda r: (f"**{1e3 * r['front_page_s']:.1f}** / {1e3 * r['campaigns_json_s']:.1f} / "
                       f"{1e3 * r['campaign_page_s']:.1f} ms")),
    )),
    Bench("live_status", "live_status.py", ("--runs", "3", "--json"), about="2 min", rows=(
        Row("publishing live status: the paper dry run publishing to an SQLite registry against `--no-publish`, "
            "alternated, medians",
            lambda r: (f"{r['publish']['with_s']:.2f} s against {r['publish']['without_s']:.2f} s: ratio "
                       f"**{r['publish']['ratio']:.2f}** ({r['publish']['runs']} runs each); "
                       f"{r['publish']['events_last_run']} events and {r['publish']['temperature_points_last_run']} "
                       f"temperature points published per run")),
        Row("the lab's dashboard on a full registry (each campaign 200 events, 840 temperature points, one running per "
            "rig), through the app: the front page, `/api/rigs`, a published campaign", live_pages),
    )),
    Bench("registry", "registry.py", ("--json",), quick=("--count", "20000", "--json"), about="35 s", rows=(
        Row("the registry (SQLite, a new file): recording calibrations, each a copy of one real quick-6pos "
            "calibration with its own serial, part lot and date, in batches of 500",
            lambda r: (f"{thousands(r['count'])} in {r['insert_s']:.1f} s, **{thousands(r['insert_per_s'])} /s**; "
                       f"1 000 already registered skipped in {r['add_again_s']:.2f} s; {thousands(r['file_mb'])} MB on disk")),
        Row("its queries: a serial's history / its valid calibration / its trend; one stored fit; a date-filtered "
            "list (fits left out); a part's lot statistics", registry_queries),
    )),
    Bench("startup", "startup.py", ("--runs", "20", "--json"), about="5 s", rows=(
        Row("`rig --help`, whole process: wall time (median over the runs, after a warm-up) and the heavy libraries "
            "it imports",
            lambda r: f"**{r['median_wall_ms']:.0f} ms**; imports {', '.join(r['heavy_imports']) or 'none of them'}",
            "none of h5py, scipy, pyserial, pymodbus, matplotlib, numpy, pydantic, PyYAML",
            lambda r: not r["heavy_imports"]),
    )),
    Bench("bridge_throughput", "bridge_throughput.py", ("--seconds", "5", "--json"), about="15 s", rows=(
        Row("one ADXL355 at 4000 Hz through the bridge driver and the simulated bridge on a pseudo-terminal, "
            "4000-sample blocks: gap-free samples per second, the bridge capturing blocks (protocol version 2) / the "
            "host draining the FIFO every 30 samples (version 1)",
            lambda r: f"**{thousands(r['captured']['samples_per_s'])}** / {thousands(r['drained']['samples_per_s'])} samples/s",
            "> 4000 /s", lambda r: min(r["captured"]["samples_per_s"], r["drained"]["samples_per_s"]) > 4000),
    )),
    Bench("firmware_throughput", "firmware_throughput.py", ("--seconds", "10", "--json"), about="15 s", rows=(
        Row("the reference bridge firmware (`firmware/`, built for the host in front of its C model of an ADXL355, on a "
            "pseudo-terminal) through the project's driver: back-to-back captures at 4000 Hz",
            lambda r: (f"**{thousands(r['sustained']['samples_per_s'])} gap-free samples/s** "
                       f"({100 * r['sustained']['share_of_odr']:.1f} % of the part's output; "
                       f"{r['sustained']['capture_requests']:.0f} `C` requests for {r['sustained']['blocks']:.0f} blocks "
                       f"of {r['block']})")),
        Row("the same firmware: a complete 4096-sample capture fetched again and again (the line's own rate)",
            lambda r: (f"{thousands(r['refetch']['samples_per_s'])} samples/s "
                       f"({r['refetch']['hex_characters_per_s'] / 1e6:.1f} M hex characters/s)")),
    )),
    Bench("ci", None, (), hand_command="CI=true bash .ci/run", rows=(
        Row("the test suite and CI on a fresh clone (install, lint, import layers, types, the firmware's cross build, "
            "the documentation site, the wheel and the getting-started commands with it, the example plug-in, the tests)",
            lambda r: (f"{thousands(r['tests'])} tests in {r['pytest_wall_s']:.0f} s on {r['workers']} workers "
                       f"(pytest-xdist); the whole script {r['script_wall_s']:.0f} s ({r['script_wall_s'] / 60:.1f} min)"),
            "~20 min", lambda r: r["script_wall_s"] <= 20 * 60),
    )),
)
BY_NAME = {bench.name: bench for bench in BENCHES}


# --- run ----------------------------------------------------------------------------------------------------


def git(*args: str) -> str:
    return subprocess.run(["git", *args], cwd=REPO, capture_output=True, text=True, check=True).stdout.strip()


def commit() -> str:
    """The checkout's short commit, "+dirty" when a tracked file differs from it (as `git describe --dirty`
    sees it), this script's own outputs aside."""
    changed = git("status", "--porcelain", "--untracked-files=no", "--", ".", *(f":(exclude){p}" for p in OUTPUTS))
    return git("rev-parse", "--short", "HEAD") + ("+dirty" if changed else "")


def last_json(text: str) -> Output:
    """The JSON object a bench ends its output with: all of stdout, or its last top-level object after lines of
    text (some benches print their lines and then the object)."""
    try:
        found = json.loads(text)
    except json.JSONDecodeError:
        lines = text.rstrip().splitlines()
        for start in range(len(lines) - 1, -1, -1):
            if lines[start].startswith("{"):
                try:
                    found = json.loads("\n".join(lines[start:]))
                    break
                except json.JSONDecodeError:
                    continue
        else:
            raise ValueError("no JSON object at the end of the output") from None
    if not isinstance(found, dict):
        raise ValueError("the output's JSON is not an object")
    return found


def bench_environment(registry_folder: Path) -> dict[str, str]:
    """The benches import this checkout (not whichever one the interpreter has installed), and the dry runs they
    start record their calibrations in a throw-away registry, never the user's."""
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(p for p in (str(REPO), env.get("PYTHONPATH", "")) if p)
    env["ACCELCAL_REGISTRY"] = str(registry_folder / "registry.sqlite")
    env["ACCELCAL_DRY_RUN_REGISTRY"] = str(registry_folder / "dry-runs.sqlite")
    env["PYTHONUNBUFFERED"] = "1"
    return env


def run_bench(bench: Bench, quick: bool, measured_commit: str, results: Path) -> bool:
    """Runs one bench, echoing its output to stderr as it comes; stores its JSON with the command, date, commit
    and machine. False (and nothing stored, the previous result kept) when it gave no JSON object."""
    assert bench.script is not None
    argv = [sys.executable, str(REPO / "bench" / bench.script), *(bench.quick if quick and bench.quick else bench.args)]
    print(f"== {bench.command(quick)}  (full form: about {bench.about})", file=sys.stderr, flush=True)
    date = datetime.now(UTC).isoformat(timespec="seconds").replace("+00:00", "Z")
    load = os.getloadavg()
    with tempfile.TemporaryDirectory(prefix="accelcal-table-") as registry_folder:
        started = time.perf_counter()
        process = subprocess.Popen(argv, cwd=REPO, env=bench_environment(Path(registry_folder)),
                                   stdout=subprocess.PIPE, text=True)
        assert process.stdout is not None
        lines = []
        for line in process.stdout:
            lines.append(line)
            print(f"   {line}", end="", file=sys.stderr, flush=True)
        code = process.wait()
        wall_s = time.perf_counter() - started
    try:
        output = last_json("".join(lines))
    except ValueError as exc:
        print(f"== {bench.name}: exit {code} after {wall_s:.0f} s, {exc}: nothing stored", file=sys.stderr)
        return False
    record = {"bench": bench.name, "command": bench.command(quick), "quick": bool(quick and bench.quick),
              "date": date, "commit": measured_commit, "exit_code": code, "wall_s": round(wall_s, 1),
              "machine": {"cpus": os.cpu_count(), "python": platform.python_version(),
                          "load_average_at_start": [round(x, 2) for x in load]},
              "output": output}
    results.mkdir(parents=True, exist_ok=True)
    (results / f"{bench.name}.json").write_text(json.dumps(record, indent=1, ensure_ascii=False) + "\n", encoding="utf-8")
    print(f"== {bench.name}: exit {code} in {wall_s:.0f} s, stored {results / f'{bench.name}.json'}", file=sys.stderr)
    return True


# --- write --------------------------------------------------------------------------------------------------


def cell(text: str) -> str:
    """Text fit for a table cell: one line, its pipes escaped (a `\\|g\\|` already escaped stays so)."""
    return " ".join(text.split()).replace("\\|", "|").replace("|", "\\|")


def not_measured(bench: Bench, why: str) -> str:
    quick = "; `--quick` for a shorter form" if bench.quick else ""
    return f"{why} — run: `python bench/table.py run {bench.name}` (about {bench.about}{quick})"


def row_value(bench: Bench, row: Row, stored: Output | None) -> str:
    """A row's value cell: the value with its target (met or not), or what is missing and how to measure it."""
    if stored is None:
        if bench.script is None:
            return "not recorded yet — a results file copied by hand from a recorded run"
        return not_measured(bench, "not measured yet")
    output = stored["output"]
    try:
        value = row.value(output)
    except (KeyError, IndexError, TypeError, StopIteration):
        return not_measured(bench, "not in the stored run (its command measured less)")
    if row.target:
        verdict = ""
        if row.met is not None:
            try:
                verdict = ": met" if row.met(output) else ": **not met**"
            except (KeyError, IndexError, TypeError, StopIteration):
                verdict = ""   # the stored run did not measure what the target is about
        value += f" — target {row.target}{verdict}"
    if stored.get("exit_code", 0) != 0:
        value += f" (the bench exited {stored['exit_code']})"
    if stored.get("hand_written"):
        value += f" ({stored['hand_written']})"
    return value


def load_results(results: Path) -> dict[str, Output]:
    return {path.stem: json.loads(path.read_text(encoding="utf-8")) for path in sorted(results.glob("*.json"))}


INTRO = """\
# Performance and accuracy

<!-- Written by `python bench/table.py write` from bench/results/*.json: edit the script or re-run a bench,
not this page. -->

Each row is one figure a bench measures: what it is, the command that measured it, its value (with the target
or bound it is held to, and whether the run met it), and the date (UTC) and commit of that run ("+dirty":
tracked files differed from the commit). The figures are of the simulated rig's dry runs and the software
around them, on the machine of the run: its results file in `bench/results/` names the cores, the Python and
the load average at the start. Wall-clock figures move with the machine's load, so compare figures measured
in the same hour, not rows of different dates. A command with fewer seeds, runs or sizes than the bench's
default is its quick form.

Re-measure a figure, or all of them, and rewrite this page (the benches import the checkout the script is in):

    python bench/table.py run BENCH …    # e.g. startup: stores bench/results/startup.json
    python bench/table.py run --quick    # every bench, each in a form of under ~3 minutes (fewer seeds or runs)
    python bench/table.py run            # every bench in full (about half an hour, 13 min of it uncertainty_honest)
    python bench/table.py write          # this page, from bench/results/
    python bench/table.py list           # the benches, their full and quick commands

Not in the table: the kill, disk-full, concurrency, signal, fault and fuzz trials (`bench/reliability.py`,
`bench/follow_up.py`, `bench/fuzz.py`, `bench/registry_first_use.py`; their figures are in
[reliability.md](reliability.md#figures) and [registry.md](registry.md)), and the benches with no `--json`
mode yet (`bench/fit_accuracy.py`, `bench/operator.py`, `bench/ramp_vs_soak.py`, `bench/wire_round_trips.py`).
The CI row has no bench: its results file is copied by hand from a recorded CI run, and its row says so. The
figures of past issues, and how each was reached, are in this page's history: `git log -p docs/performance.md`,
the last of them in `git show ed0b3a4:docs/performance.md`.
"""


def render(results: Path) -> str:
    """The page: the intro, then one table of every bench's rows, measured or not."""
    stored = load_results(results)
    for name in sorted(set(stored) - set(BY_NAME)):
        print(f"{results / name}.json: no bench of that name in BENCHES, left out", file=sys.stderr)
    lines = [INTRO, "| figure | command | value | date | commit |", "|---|---|---|---|---|"]
    for bench in BENCHES:
        found = stored.get(bench.name)
        command = found["command"] if found else bench.command()
        date = found["date"][:10] if found else "—"
        measured = found["commit"] if found else "—"
        for k, row in enumerate(bench.rows):
            anchor = f'<a id="{bench.name}"></a>' if k == 0 else ""   # docs link here (performance.md#registry)
            lines.append(f"| {anchor}{cell(row.figure)} | `{cell(command)}` | {cell(row_value(bench, row, found))} | "
                         f"{date} | {measured} |")
    return "\n".join(lines) + "\n"


# --- the command line ---------------------------------------------------------------------------------------


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    commands = parser.add_subparsers(dest="command", required=True)
    run = commands.add_parser("run", help="run benches and store their results")
    run.add_argument("benches", nargs="*", metavar="BENCH", help="default: every bench with a script")
    run.add_argument("--quick", action="store_true", help="each bench's quick form (under ~3 minutes)")
    run.add_argument("--results", type=Path, default=RESULTS, help=argparse.SUPPRESS)
    write = commands.add_parser("write", help="render docs/performance.md from the stored results")
    write.add_argument("--results", type=Path, default=RESULTS, help=argparse.SUPPRESS)
    write.add_argument("--page", type=Path, default=PAGE, help=argparse.SUPPRESS)
    commands.add_parser("list", help="the benches and their commands")
    args = parser.parse_args(argv)
    if args.command == "list":
        for bench in BENCHES:
            quick = f"\n    quick: {bench.command(True)}" if bench.quick else ""
            about = f"about {bench.about}" if bench.script else "no bench: a results file copied by hand"
            print(f"{bench.name}: {bench.command()}  ({about}){quick}")
        return 0
    if args.command == "write":
        args.page.write_text(render(args.results), encoding="utf-8")
        print(f"wrote {args.page}", file=sys.stderr)
        return 0
    unknown = [name for name in args.benches if name not in BY_NAME]
    if unknown:
        parser.error(f"unknown bench(es): {', '.join(unknown)}; known: {', '.join(BY_NAME)}")
    chosen = [BY_NAME[name] for name in args.benches] if args.benches else list(BENCHES)
    handmade = [bench.name for bench in chosen if bench.script is None]
    if handmade and args.benches:
        parser.error(f"{', '.join(handmade)}: no bench; its results file is written by hand from a recorded run")
    measured_commit = commit()   # once, before any result is written
    failed = [b.name for b in chosen if b.script is not None and not run_bench(b, args.quick, measured_commit, args.results)]
    print(f"== done{'; no result from: ' + ', '.join(failed) if failed else ''}; now: python bench/table.py write",
          file=sys.stderr)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
