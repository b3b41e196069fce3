"""Sustained sample throughput of the bridge's reference firmware (firmware/), built for the host in front of
its C model of an ADXL355 and served on a pseudo-terminal, through the project's own driver, on the wall
clock: back-to-back version 2 captures at the part's top data rate (4000 Hz), and how fast a complete
capture can be fetched again (the line's own rate, which bounds how many sensors a link could carry). Usage:

    python bench/firmware_throughput.py [--seconds 5] [--block 4000] [--json]

The model makes samples in real time, so the first figure cannot exceed 4000 samples/s: what it measures is
how little of the part's output is lost between captures (the FIFO emptied by each `C`, the fetch's delay).
"""

from __future__ import annotations

import argparse
import json
import subprocess
import tempfile
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path

from accelcal_rig.core.clock import RealClock
from accelcal_rig.instruments.adxl355_driver import Adxl355
from accelcal_rig.instruments.adxl355_transport import SerialBridge

REPO = Path(__file__).resolve().parent.parent
ODR_HZ = 4000.0


def build(folder: Path) -> Path:
    """The host firmware, built with the firmware's own Makefile."""
    subprocess.run(["make", "-C", str(REPO / "firmware"), "host", f"BUILD={folder}"], check=True,
                   capture_output=True)
    return folder / "host" / "bridge-host"


@contextmanager
def firmware_sensor(binary: Path) -> Iterator[Adxl355]:
    """The driver on the running firmware's pseudo-terminal, measuring at 4000 Hz, ±2 g."""
    process = subprocess.Popen([str(binary), "--exit-with-stdin"], stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                               text=True)
    assert process.stdout is not None and process.stdin is not None
    sensor = Adxl355(SerialBridge.open(process.stdout.readline().strip()), "FW-BENCH", RealClock())
    try:
        sensor.reset()
        sensor.standby()
        sensor.configure({"accel": 2}, ODR_HZ)
        sensor.start_measurement()
        yield sensor
    finally:
        sensor.close()
        process.stdin.close()
        process.wait(timeout=5)


def sustained(sensor: Adxl355, seconds: float, block: int) -> dict[str, float]:
    """Back-to-back captures of `block` samples for about `seconds`: gap-free samples per wall second, and
    how many `C` requests that took (more than one per block: a capture lost samples and was taken again)."""
    bridge: SerialBridge = sensor._bus  # type: ignore[assignment]
    # A `C` goes out as a posted request (several bridges start at once) or, its reply lost, a plain one: count both.
    sent = {"post_capture": 0, "start_capture": 0}
    real = {name: getattr(bridge, name) for name in sent}

    def counted(name: str) -> Callable[[int], object]:
        def send(n_samples: int) -> object:
            sent[name] += 1
            return real[name](n_samples)
        return send

    for name in sent:
        setattr(bridge, name, counted(name))
    samples, blocks, begun = 0, 0, time.perf_counter()
    while time.perf_counter() - begun < seconds:
        samples += len(sensor.acquire(block).codes["accel"])
        blocks += 1
    wall = time.perf_counter() - begun
    for name, method in real.items():
        setattr(bridge, name, method)
    return {"samples": samples, "wall_s": wall, "samples_per_s": samples / wall, "blocks": blocks,
            "capture_requests": sum(sent.values()), "share_of_odr": samples / wall / ODR_HZ}


def refetch(sensor: Adxl355, seconds: float) -> dict[str, float]:
    """A complete 4096-sample capture fetched again and again (`G 0`): samples per second the line carries."""
    bridge: SerialBridge = sensor._bus  # type: ignore[assignment]
    bridge.start_capture(4096)
    time.sleep(4096 / ODR_HZ + 0.05)
    samples, fetches, begun = 0, 0, time.perf_counter()
    while time.perf_counter() - begun < seconds:
        data, end_temperature = bridge.fetch_capture(0)
        assert end_temperature is not None and len(data) == 4096 * 9
        samples += 4096
        fetches += 1
    wall = time.perf_counter() - begun
    return {"fetches": fetches, "wall_s": wall, "samples_per_s": samples / wall,
            "hex_characters_per_s": samples * 18 / wall}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=5.0)
    parser.add_argument("--block", type=int, default=4000, help="samples per capture (1…4096)")
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as folder, firmware_sensor(build(Path(folder))) as sensor:
        captured = sustained(sensor, args.seconds, args.block)
        fetched = refetch(sensor, min(args.seconds, 2.0))
    print(f"firmware (host build) at {ODR_HZ:.0f} Hz, back-to-back captures of {args.block}: "
          f"{captured['samples']:.0f} gap-free samples in {captured['wall_s']:.2f} s wall = "
          f"{captured['samples_per_s']:,.0f} samples/s ({captured['share_of_odr']:.1%} of the part's output; "
          f"{captured['capture_requests']:.0f} C requests for {captured['blocks']:.0f} blocks)")
    print(f"firmware (host build), a complete 4096-sample capture fetched again: {fetched['samples_per_s']:,.0f} "
          f"samples/s on the line ({fetched['hex_characters_per_s']:,.0f} hex characters/s, "
          f"{fetched['fetches']:.0f} fetches)")
    if args.json:
        print(json.dumps({"odr_hz": ODR_HZ, "block": args.block, "sustained": captured, "refetch": fetched}))


if __name__ == "__main__":
    main()
