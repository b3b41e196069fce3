"""A simulated ADXL355 behind a serial bridge, on a pseudo-terminal: the register map, including the
96-entry FIFO that fills at the output data rate on the shared clock, fed by the lab's sensor model,
and the bridge's own block capture (protocol version 2 on), which drains the FIFO as firmware would. The
bridge answers as the reference firmware does (sim/bridge_requests.py); the part does with a write what the
reference firmware's C model of it does (firmware/host/adxl355_model.h): a read-only register, or RANGE and
FILTER while measuring, ignore it (the bridge refuses those before they reach the part)."""

from __future__ import annotations

import math

import numpy as np

from accelcal_rig.config.rig import SensorConfig
from accelcal_rig.instruments import adxl355
from accelcal_rig.instruments.adxl355_transport import BRIDGE_GREETING
from accelcal_rig.sim.bridge_capture import CaptureBuffer, CaptureRequests, CaptureRules
from accelcal_rig.sim.bridge_registers import RegisterMap, RegisterRequests
from accelcal_rig.sim.bridge_requests import BridgeRequests
from accelcal_rig.sim.faults import InstrumentFaults, ReplyFaults
from accelcal_rig.sim.lab import VirtualLab
from accelcal_rig.sim.register_bridge_server import BridgeOnPty

_FIFO_REGISTERS = frozenset({adxl355.REG_STATUS, adxl355.REG_FIFO_ENTRIES, adxl355.REG_FIFO_DATA})  # ID, status, data and FIFO registers
_SAMPLES_IN_FIFO = adxl355.FIFO_CAPACITY_ENTRIES // 3
#: FILTER's ODR_LPF codes 11…15 are reserved: the part is taken to run at the slowest rate (code 10), as the C model.
_SLOWEST_ODR_CODE = 10
#: Samples the simulated bridge's capture buffer holds (9 bytes each: 36 kB, a small microcontroller's RAM).
CAPTURE_CAPACITY_SAMPLES = 4096
#: Writes that end a running capture (RANGE and FILTER would too, but they are written only in standby).
_STREAM_REGISTERS = frozenset({adxl355.REG_FIFO_SAMPLES, adxl355.REG_POWER_CTL, adxl355.REG_RESET})
#: The register map as the bridge enforces it (ADXL355, ADXL357, ADXL359 alike).
REGISTER_MAP = RegisterMap(last=adxl355.REG_LAST, read_only=adxl355.READ_ONLY_REGISTERS,
                           burst_stays=adxl355.REG_FIFO_DATA, standby_only=adxl355.STANDBY_ONLY_REGISTERS)


class SimulatedAdxl355:
    """One DUT's ADXL355 (or ADXL357, ADXL359: the lab's part for it) at register level."""

    def __init__(self, lab: VirtualLab, index: int, wrong_part_id: bool = False,
                 stuck_after_s: float | None = None, temperature_tear_rate: float = 0.0) -> None:
        self._lab = lab
        #: A real ADXL355's TEMP2/TEMP1 are not double-buffered: this share of reads tears across the high
        #: nibble. Its own stream, so a rate of zero changes no other draw.
        self._tear_rate = temperature_tear_rate
        self._tear_rng = np.random.default_rng([index, 7_000_003])
        self._index = index
        self._part = lab.duts[index].part
        # The wrong part fitted by mistake: an ADXL359 (PARTID 0xE9) where another part belongs, else an ADXL355.
        self._part_id = (0xED if self._part.identity[2] == 0xE9 else 0xE9) if wrong_part_id else self._part.identity[2]
        self._stuck_after_s = stuck_after_s
        self._stuck_codes: np.ndarray | None = None
        self.reset()

    def reset(self) -> None:
        self._regs = bytearray(0x30)
        self._regs[0:4] = bytes([*self._part.identity[:2], self._part_id, 0x01])
        self._regs[adxl355.REG_RANGE] = 0x81
        self._regs[adxl355.REG_POWER_CTL] = adxl355.POWER_CTL_STANDBY
        self._regs[adxl355.REG_FIFO_SAMPLES] = 0x60
        self._fifo = bytearray()
        self._fifo_pending = 0  # the newest samples in the FIFO, made only when FIFO_DATA is read
        self._overflow = False
        self._next_sample_s: float | None = None
        self._capture = CaptureBuffer(9)

    @property
    def measuring(self) -> bool:
        """Whether the part measures (POWER_CTL's standby bit clear): what the safe state must leave False."""
        return not self._regs[adxl355.REG_POWER_CTL] & adxl355.POWER_CTL_STANDBY

    @property
    def lab(self) -> VirtualLab:
        """The virtual lab behind it (its clock, its truth): for tests and fault injection."""
        return self._lab

    @property
    def capturing(self) -> bool:
        """Whether the bridge's capture still wants samples (as of now on the clock)."""
        self._fill_fifo()
        return self._capture.left > 0

    @property
    def captured_samples(self) -> int:
        """Samples in the bridge's capture buffer now."""
        self._fill_fifo()
        return self._capture.samples

    @property
    def _odr_hz(self) -> float:
        return self._part.output_data_rates_hz[min(self._regs[adxl355.REG_FILTER] & 0x0F, _SLOWEST_ODR_CODE)]

    @property
    def _range_g(self) -> int:
        """RANGE's range; its reserved code 0 as the lowest range (code 1), as the C model takes it."""
        ranges = {code: g for g, code in self._part.channel("accel").range_codes.items()}
        return ranges[self._regs[adxl355.REG_RANGE] & 0x03 or 1]

    def read(self, address: int, count: int) -> bytes:
        if not _FIFO_REGISTERS.isdisjoint(range(address, address + count)):
            self._fill_fifo()  # a temperature or ID read leaves the FIFO to be filled when it is looked at
        if address == adxl355.REG_FIFO_DATA:  # no auto-increment: a burst drains the FIFO
            self._make_pending_samples()
            taken, self._fifo = bytes(self._fifo[:count]), self._fifo[count:]
            return taken + adxl355.empty_fifo_entries((count - len(taken)) // 3)
        held = self._samples_in_fifo()
        self._regs[adxl355.REG_STATUS] = (
            (adxl355.STATUS_FIFO_OVR if self._overflow else 0)
            | (0x02 if held >= _SAMPLES_IN_FIFO else 0)
            | (adxl355.STATUS_DATA_RDY if held else 0)
        )
        self._regs[adxl355.REG_FIFO_ENTRIES] = 3 * held
        raw = self._temperature_raw()
        if self._tear_rate and address <= adxl355.REG_TEMP2 + 1 and adxl355.REG_TEMP2 < address + count \
                and self._tear_rng.random() < self._tear_rate:
            # TEMP2 read before, TEMP1 after an update that carried into the high nibble (or the other way).
            raw = int(np.clip(raw + (256 if self._tear_rng.random() < 0.5 else -256), 0, 0xFFF))
        self._regs[adxl355.REG_TEMP2], self._regs[adxl355.REG_TEMP2 + 1] = raw >> 8, raw & 0xFF
        if address <= adxl355.REG_STATUS < address + count:
            self._overflow = False  # reading STATUS clears FIFO_OVR
        return bytes(self._regs[address:address + count])

    def write(self, address: int, value: int) -> None:
        """What the part does with a write: RESET takes only its code; a read-only register, a register past the
        map, and RANGE or FILTER while measuring ignore it (as the reference firmware's C model of the part)."""
        if address == adxl355.REG_RESET:
            if value == adxl355.RESET_CODE:
                self.reset()
            return
        if address in adxl355.READ_ONLY_REGISTERS or address >= len(self._regs):
            return
        if address in adxl355.STANDBY_ONLY_REGISTERS and self.measuring:
            return
        self._fill_fifo()
        was_measuring = self.measuring
        self._regs[address] = value
        if address == adxl355.REG_POWER_CTL and was_measuring != self.measuring:
            self._fifo.clear()  # standby resets the FIFO; measuring starts a fresh one
            self._fifo_pending = 0
            self._overflow = False
            self._capture.stop()
            self._next_sample_s = self._lab.clock.now() if self.measuring else None

    def start_capture(self, n_samples: int) -> int:
        """The bridge empties the FIFO and captures the next `n_samples` itself; returns the raw
        temperature as it starts. The bridge has checked the part measures and the count fits its buffer
        (sim/bridge_capture.py)."""
        assert self.measuring and 0 < n_samples <= CAPTURE_CAPACITY_SAMPLES
        self._fill_fifo()
        self._fifo.clear()
        self._fifo_pending = 0
        self._overflow = False
        self._capture.start(n_samples)
        return self._temperature_raw()

    def stop_capture(self) -> None:
        """The bridge ends its capture early (a write changed the stream): samples go to the FIFO again."""
        self._fill_fifo()
        self._capture.stop()

    def fetch_capture(self, first: int) -> tuple[bytes, int | None]:
        """(the capture's samples from index `first` on, raw temperature at its end once it is complete).
        The capture stays until the next one starts, so a reply lost on the line can be asked for again."""
        self._fill_fifo()
        return self._capture.fetch(first)

    def _fill_fifo(self) -> None:
        """Add the samples due since the last look: first to a capture under way, then to the FIFO, which
        beyond 32 samples overflows (oldest lost)."""
        if self._next_sample_s is None:
            return
        now = self._lab.clock.now()
        due = math.floor((now - self._next_sample_s) * self._odr_hz + 1e-9)
        if due > 0 and self._capture.left > 0:
            due -= self._capture_next(min(due, self._capture.left))
        if due <= 0:
            return
        excess = self._samples_in_fifo() + due - _SAMPLES_IN_FIFO
        if excess > 0:
            self._overflow = True
            self._fifo = self._fifo[9 * min(excess, len(self._fifo) // 9):]
        self._fifo_pending = min(self._fifo_pending + due, _SAMPLES_IN_FIFO - len(self._fifo) // 9)
        self._next_sample_s += due / self._odr_hz

    def _samples(self, t_first_s: float, count: int) -> np.ndarray:
        """`count` codes from the lab's sensor model; a part whose output froze repeats one sample."""
        codes = self._lab.dut_samples(self._index, t_first_s, count, self._odr_hz, self._range_g)
        if self._stuck_after_s is not None and self._lab.clock.now() >= self._stuck_after_s:
            if self._stuck_codes is None:
                self._stuck_codes = codes[0].copy()
            codes = np.broadcast_to(self._stuck_codes, codes.shape)
        return codes

    def _temperature_raw(self) -> int:
        return self._lab.dut_reading_raw(self._index)

    def _samples_in_fifo(self) -> int:
        return len(self._fifo) // 9 + self._fifo_pending

    def _make_pending_samples(self) -> None:
        """The FIFO's newest samples, from the lab's state now (as filling at each look would)."""
        if self._fifo_pending and self._next_sample_s is not None:
            t_first = self._next_sample_s - self._fifo_pending / self._odr_hz
            self._fifo += adxl355.encode_fifo(self._samples(t_first, self._fifo_pending))
            self._fifo_pending = 0

    def _capture_next(self, count: int) -> int:
        """Move the next `count` samples into the capture buffer; returns how many samples were due."""
        assert self._next_sample_s is not None
        self._capture.take(adxl355.encode_fifo(self._samples(self._next_sample_s, count)), count, self._temperature_raw)
        self._next_sample_s += count / self._odr_hz
        return count


def capture_rules() -> CaptureRules:
    """The ADXL355's capture: its FIFO_DATA, the writes that end it; ready whenever it measures."""
    return CaptureRules(adxl355.REG_FIFO_DATA, _STREAM_REGISTERS, lambda: None)


class SimulatedBridgeServer(BridgeOnPty):
    """The bridge line protocol on a pseudo-terminal, in front of one simulated ADXL355: version 3 as the
    reference firmware speaks it (`part=adxl355`, as it names any part whose DEVID_AD is 0xAD), or version 2
    (its greeting without `part=`) or 1 (no capture)."""

    def __init__(self, lab: VirtualLab, index: int, protocol_version: int = 3, faults: ReplyFaults | None = None,
                 wrong_part_id: bool = False, stuck_after_s: float | None = None,
                 temperature_tear_rate: float = 0.0) -> None:
        self._version = protocol_version
        self.device = SimulatedAdxl355(lab, index, wrong_part_id, stuck_after_s, temperature_tear_rate)
        device = self.device
        capture = CaptureRequests(device, CAPTURE_CAPACITY_SAMPLES, capture_rules()) if protocol_version >= 2 else None
        registers = RegisterRequests(device, REGISTER_MAP, lambda: not device.measuring, capture)
        super().__init__(lab, index, BridgeRequests(self._greeting, registers, "adxl355", capture,
                                                    verbs="?RWCG" if capture is not None else "?RW"), faults)

    @property
    def version(self) -> int:
        """The bridge protocol version it speaks."""
        return self._version

    def _greeting(self) -> str:
        part = " part=adxl355" if self._version >= 3 else ""
        capture = f" capture={CAPTURE_CAPACITY_SAMPLES}" if self._version >= 2 else ""
        return f"{BRIDGE_GREETING} {self._version}{part}{capture} accelcal-rig simulated bridge"


def serve_bridge(lab: VirtualLab, config: SensorConfig, faults: InstrumentFaults) -> SimulatedBridgeServer:
    """The sensor drivers' simulator: a version 3 bridge in front of the DUT's simulated part."""
    settings = faults.settings
    index = [d.serial for d in lab.duts].index(config.serial)
    return SimulatedBridgeServer(lab, index, faults=faults.replies, wrong_part_id=config.serial == settings.sensor_wrong_id,
                                 stuck_after_s=faults.after_s(settings.sensor_stuck_after_min)
                                 if config.serial == settings.sensor_stuck else None,
                                 temperature_tear_rate=settings.sensor_temperature_tear_rate)
