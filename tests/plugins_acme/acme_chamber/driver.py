"""The ACME ASCII chamber driver over pyserial's socket:// line."""

from accelcal_rig.instruments.line_port import LinePort


class AcmeChamber:
    def __init__(self, line: LinePort, endpoint: str) -> None:
        self._line = line
        self.endpoint = endpoint

    def identify(self) -> str:
        return f"{self._line.ask('*IDN?')} (PV {self.read_temperature_c():.1f} °C)"

    def read_temperature_c(self) -> float:
        return float(self._line.ask("PV?"))

    def read_setpoint_c(self) -> float:
        return float(self._line.ask("SP?"))

    def write_setpoint_c(self, setpoint_c: float) -> None:
        self._line.ask(f"SP {setpoint_c:.2f}")

    def set_power(self, on: bool) -> None:
        raise NotImplementedError("the ACME TC-1 has no power event")

    def alarm_active(self) -> bool:
        return self._line.ask("ALARM?") != "0"

    def controller_limits_c(self):
        return None  # the ACME TC-1 does not say

    def close(self) -> None:
        self._line.close()


def open_chamber(config, endpoint: str) -> AcmeChamber:
    return AcmeChamber(LinePort.open(f"socket://{endpoint}", "chamber", 9600, config.timeout_s), f"acme {endpoint}")
