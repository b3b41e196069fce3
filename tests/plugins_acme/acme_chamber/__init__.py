"""An ASCII chamber controller on a TCP line, as a third party would ship it for accelcal-rig: the driver,
its simulator and its protocol (one request per line: `*IDN?`, `PV?`, `SP?`, `SP <°C>`, `ALARM?`)."""

from accelcal_rig.instruments.definitions import ChamberDriver
from acme_chamber.driver import open_chamber

CHAMBER = ChamberDriver("acme-ascii", open_chamber, simulator="acme_chamber.simulator:serve",
                        protocol="acme_chamber.driver")
