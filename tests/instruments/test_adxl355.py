import numpy as np

from accelcal_rig.instruments import adxl355


def test_fifo_decoding_handles_empty_entries_resync_and_a_sample_split_across_bursts() -> None:
    codes = np.array([[256000, -256000, 0], [2**19 - 1, -(2**19), -1], [12, -12, 3]])
    raw = adxl355.encode_fifo(codes)
    decoded, tail = adxl355.decode_fifo(adxl355.empty_fifo_entries(2) + raw[3:] + adxl355.empty_fifo_entries(1))
    np.testing.assert_array_equal(decoded, codes[1:])      # resynchronised on the next X marker
    assert tail == b""
    first, tail = adxl355.decode_fifo(raw[:24])            # 8 entries: the part was still writing z of sample 3
    np.testing.assert_array_equal(first, codes[:2])
    second, tail = adxl355.decode_fifo(raw[24:] + adxl355.empty_fifo_entries(3), carried=tail)
    np.testing.assert_array_equal(second, codes[2:])        # completed by the next burst, nothing lost
    assert tail == b""


def test_data_registers_decode_like_the_datasheet() -> None:
    # +1 g at ±2 g is 256 000 = 0x3E800 → bytes 3E 80 00; −1 g is 0xC1800 → C1 80 00
    np.testing.assert_array_equal(adxl355.decode_data_bytes(bytes([0x3E, 0x80, 0x00, 0xC1, 0x80, 0x00])),
                                  [256000, -256000])
