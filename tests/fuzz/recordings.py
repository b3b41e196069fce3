"""Mutated hand-held recordings and options for `rig fit-recording`: a CSV a logger, a spreadsheet or a
hostile user could produce (non-numbers, NaN and infinite times and values, fields megabytes long,
repeated or backwards times, missing columns, odd delimiters, a byte-order mark, bytes that are not text,
a file cut short) and option values no one should give (NaN, infinite, zero, negative, enormous, an
output that is a folder). Case `number` is reproducible."""

from __future__ import annotations

import random
from dataclasses import dataclass
from pathlib import Path

import numpy as np

HEADER = "time,x,y,z,temperature"
HOSTILE_FIELDS = ["nan", "NaN", "inf", "-inf", "1e309", "-1e309", "", "x", "1,2", '"', "0x10", "1e-320", "  ",
                  "9" * 400, "\0", "1.5.2", "--1", "1e308"]
HOSTILE_OPTIONS = ["nan", "inf", "-inf", "0", "-1", "1e308", "1e-308", "-0"]
FLOAT_OPTIONS = ["--rate-hz", "--counts-per-g", "--zero-code", "--temperature-c", "--window-s", "--init-s",
                 "--threshold-factor", "--min-interval-s"]


def clean_recording(seed: int = 0) -> str:
    """A plausible hand-held recording in g at 100 Hz: still at first, then 14 orientations held 3 s each."""
    from accelcal_rig.sim.handheld import handheld_recording

    recording = handheld_recording("ADX355-A001", 14, 100.0, np.random.default_rng(seed))
    rows = [HEADER] + [f"{t:.4f},{a[0]:.7f},{a[1]:.7f},{a[2]:.7f},{c:.2f}"
                       for t, a, c in zip(recording.t_s, recording.raw_g, recording.temperature_c)]
    return "\n".join(rows) + "\n"


@dataclass(frozen=True)
class RecordingCase:
    number: int
    mutation: str
    csv: bytes
    options: list[str]           # extra command-line options (the output is added by the caller)
    output_is_folder: bool = False

    def argv(self, folder: Path) -> list[str]:
        folder.mkdir(parents=True, exist_ok=True)
        (folder / "recording.csv").write_bytes(self.csv)
        output = folder / ("out" if self.output_is_folder else "out.yaml")
        if self.output_is_folder:
            output.mkdir(exist_ok=True)
        return ["fit-recording", str(folder / "recording.csv"), "--columns", "time,x,y,z,temperature", "-o",
                str(output), *self.options]


def recording_case(number: int, clean: str) -> RecordingCase:
    rng = random.Random(number)
    lines = clean.splitlines()
    kind = rng.choice(["field", "field", "row", "time", "structure", "bytes", "option", "option", "output"])
    if kind == "field":
        row, column = rng.randrange(1, len(lines)), rng.randrange(5)
        fields = lines[row].split(",")
        fields[column] = rng.choice(HOSTILE_FIELDS)
        lines[row] = ",".join(fields)
        return RecordingCase(number, f"row {row} column {column} → {fields[column][:20]!r}", "\n".join(lines).encode(), [])
    if kind == "row":
        row = rng.randrange(1, len(lines))
        how = rng.choice(["short", "long", "empty", "huge"])
        lines[row] = {"short": "1.0,2.0", "long": lines[row] + ",1,2,3", "empty": "",
                      "huge": "1," + "7" * (2 << 20) + ",0,0,0"}[how]
        return RecordingCase(number, f"row {row} {how}", "\n".join(lines).encode(), [])
    if kind == "time":
        data = np.array([[float(v) for v in line.split(",")] for line in lines[1:]])
        how = rng.choice(["reversed", "repeated", "constant", "negative", "shuffled", "nan-all"])
        if how == "reversed":
            data[:, 0] = data[::-1, 0]
        elif how == "repeated":
            data[1::2, 0] = data[::2, 0][:len(data[1::2, 0])]
        elif how == "constant":
            data[:, 0] = 1.0
        elif how == "negative":
            data[:, 0] -= 1e6
        elif how == "shuffled":
            np.random.default_rng(number).shuffle(data)
        else:
            data[:, 0] = np.nan
        text = "\n".join([HEADER] + [",".join(repr(float(v)) for v in row) for row in data])
        return RecordingCase(number, f"times {how}", text.encode(), [])
    if kind == "structure":
        how = rng.choice(["header only", "no header", "semicolons", "bom", "missing column", "ten rows", "empty",
                          "one column", "values huge", "values tiny", "still forever"])
        text = "\n".join(lines)
        if how == "header only":
            text = HEADER + "\n"
        elif how == "no header":
            text = "\n".join(lines[1:])
        elif how == "semicolons":
            text = text.replace(",", ";")
        elif how == "bom":
            text = "\ufeff" + text
        elif how == "missing column":
            text = "\n".join(",".join(line.split(",")[:4]) for line in lines)
        elif how == "ten rows":
            text = "\n".join(lines[:11])
        elif how == "empty":
            text = ""
        elif how == "one column":
            text = "\n".join(line.split(",")[0] for line in lines)
        elif how == "values huge":
            text = "\n".join([HEADER] + [",".join([r.split(",")[0], "1e300", "-1e300", "1e300", "25"]) for r in lines[1:]])
        elif how == "values tiny":
            text = "\n".join([HEADER] + [",".join([r.split(",")[0], "1e-300", "0", "0", "25"]) for r in lines[1:]])
        else:
            text = "\n".join([HEADER] + [",".join([r.split(",")[0], "0", "0", "1", "25"]) for r in lines[1:]])
        return RecordingCase(number, how, text.encode(), [])
    if kind == "bytes":
        data = bytearray("\n".join(lines).encode())
        how = rng.choice(["flip", "cut", "binary", "latin1"])
        if how == "flip":
            for _ in range(rng.randint(1, 30)):
                data[rng.randrange(len(data))] ^= 1 << rng.randrange(8)
        elif how == "cut":
            data = data[:rng.randrange(len(data))]
        elif how == "binary":
            data = bytearray(rng.randrange(256) for _ in range(rng.randint(1, 5000)))
        else:
            data = bytearray(("\n".join(lines) + "\n# température °C").encode("latin-1", errors="replace"))
        return RecordingCase(number, f"bytes {how}", bytes(data), [])
    if kind == "option":
        option, value = rng.choice(FLOAT_OPTIONS), rng.choice(HOSTILE_OPTIONS)
        extra = [option, value]
        if option in ("--counts-per-g", "--zero-code"):
            extra += ["--units", "counts"] + ([] if option == "--counts-per-g" else ["--counts-per-g", "1000"])
        if option == "--rate-hz":
            extra = ["--columns", "time,x,y,z,temperature", "--time-unit", "samples", *extra]
        return RecordingCase(number, f"{option} {value}", clean.encode(), extra)
    return RecordingCase(number, "output is a folder", clean.encode(), [], output_is_folder=True)
