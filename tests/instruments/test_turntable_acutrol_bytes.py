"""The serial turntable driver on the acutrol3000 profile, byte for byte in memory: setup before the first
move, every axis's move in one compound line, completion by rate over polls in a row, faults named by axis."""

from __future__ import annotations

import numpy as np
import pytest

from accelcal_rig.errors import InstrumentError
from accelcal_rig.instruments.turntable_serial import SerialTurntable
from accelcal_rig.protocols.turntable_line import turntable_protocol
from tests.instruments.expected_protocol import expected_protocol

ACUTROL = turntable_protocol("acutrol3000", {"setup_pause_s": 0.0})  # no wall-clock pauses in memory
SETUP = [(b":interlock:close 1\n", None), (b":interlock:close 2\n", None),
         (b":mode:position 1\n", None), (b":mode:position 2\n", None)]
HEALTHY = [(b":interlock? 1\n", b"Closed\n"), (b":interlock? 2\n", b"Closed\n")]


def rates(first: bytes, second: bytes) -> list[tuple[bytes, bytes | None]]:
    return [(b":read:rate? 1\n", first + b"\n"), (b":read:rate? 2\n", second + b"\n")]


def test_setup_goes_out_once_then_moves_are_one_line_for_all_axes() -> None:
    with expected_protocol([*SETUP, (b":demand:position 1,0.00000;:demand:position 2,90.00000\n", None),
                            (b":demand:position 1,180.00000;:demand:position 2,-45.12346\n", None)]) as line:
        table = SerialTurntable(line, "memory", ACUTROL, 2)
        table.move_to(np.array([0.0, 90.0]))
        table.move_to(np.array([180.0, -45.123456]))


def test_a_move_is_complete_after_three_polls_at_rest_in_a_row() -> None:
    moving = [*HEALTHY, *rates(b"0.00000", b"12.50000")]
    resting = [*HEALTHY, *rates(b"0.00000", b"-0.00200")]
    with expected_protocol([*moving, *resting, *resting, *moving, *resting, *resting, *resting]) as line:
        table = SerialTurntable(line, "memory", ACUTROL, 2)
        assert [table.in_position() for _ in range(7)] == [False, False, False, False, False, False, True]


def test_a_tripped_interlock_names_its_axis() -> None:
    with expected_protocol([(b":interlock? 1\n", b"Closed\n"), (b":interlock? 2\n", b"Fault\n")]) as line:
        with pytest.raises(InstrumentError, match=r"turntable \(memory\): axis 2: controller fault Fault"):
            SerialTurntable(line, "memory", ACUTROL, 2).in_position()


def test_stop_holds_each_axis_at_zero_rate_and_the_next_move_sets_up_again() -> None:
    stop = [(b":demand:rate 1,0;:mode:rate 1;:demand:rate 1,0\n", None),
            (b":demand:rate 2,0;:mode:rate 2;:demand:rate 2,0\n", None)]
    move = (b":demand:position 1,0.00000;:demand:position 2,0.00000\n", None)
    with expected_protocol([*SETUP, move, *stop, *SETUP, move]) as line:
        table = SerialTurntable(line, "memory", ACUTROL, 2)
        table.move_to(np.zeros(2))
        table.stop()
        table.move_to(np.zeros(2))


def test_positions_are_read_axis_by_axis() -> None:
    with expected_protocol([(b":read:position? 1\n", b"359.99990\n"), (b":read:position? 2\n", b"-0.00010\n")]) as line:
        angles = SerialTurntable(line, "memory", ACUTROL, 2).read_angles_deg()
    np.testing.assert_allclose(angles, [359.9999, -0.0001])
