"""Who calibrates, where, and against what: the rig config's `lab:` and `references:` sections and the identity
of each instrument, which a certificate must state (ISO/IEC 17025:2017 §7.8.2.1, §7.8.4.1) and which the
campaign file records when it is created, so a certificate reads them from the campaign, not from today's file."""

from __future__ import annotations

import datetime as dt
import re
from dataclasses import dataclass
from typing import Annotated

from pydantic import BeforeValidator, Field

from accelcal_rig.config.bounds import StrictModel

#: A name or number as a person writes it on a certificate: one line, no control characters.
ONE_LINE = r"^[^\x00-\x1f\x7f]*$"
#: Text that may run over lines (an address).
TEXT_LINES = r"^[^\x00-\x09\x0b-\x1f\x7f]*$"


def iso_date(value: object) -> dt.date:
    """A calendar date written YYYY-MM-DD (a date YAML read, or its text); ValueError saying so otherwise."""
    if isinstance(value, dt.date) and not isinstance(value, dt.datetime):
        return value
    text = str(value)
    if isinstance(value, str) and re.fullmatch(r"\d{4}-\d{2}-\d{2}", value):
        try:
            return dt.date.fromisoformat(value)
        except ValueError as exc:
            raise ValueError(f"{text!r} is not a date: {exc}") from None
    raise ValueError(f"{text!r} is not a date: write it YYYY-MM-DD")


#: A date in a config file, YYYY-MM-DD.
IsoDate = Annotated[dt.date, BeforeValidator(iso_date)]


class LabConfig(StrictModel):
    """The laboratory that issues the certificates, and where its rig stands."""

    name: str = Field(min_length=1, max_length=200, pattern=ONE_LINE, description="the laboratory's name as its "
                      "certificates state it")
    address: str = Field(min_length=1, max_length=1000, pattern=TEXT_LINES, description="its postal address (lines "
                         "may be separated by newlines)")
    place_of_calibration: str = Field("", max_length=1000, pattern=TEXT_LINES, description="where the rig stands and the "
                                      "calibrations are performed (a room, a site, a customer's premises); empty: "
                                      "at the address")


class InstrumentIdentity(StrictModel):
    """An instrument as a certificate names it: make, model and serial number (empty: not stated)."""

    make: str = Field("", max_length=128, pattern=ONE_LINE, description="its manufacturer")
    model: str = Field("", max_length=128, pattern=ONE_LINE, description="its model designation")
    serial: str = Field("", max_length=128, pattern=ONE_LINE, description="its serial number")

    def identity(self) -> str:
        """`make model, serial S`, or what of it is stated; "" when nothing is."""
        name = " ".join(p for p in (self.make, self.model) if p)
        return ", ".join(p for p in (name, f"serial {self.serial}" if self.serial else "") if p)


class ReferenceConfig(InstrumentIdentity):
    """One reference's calibration: what makes a quantity the rig sets or measures traceable to SI."""

    certificate: str = Field(min_length=1, max_length=128, pattern=ONE_LINE, description="the number of the reference's "
                             "calibration certificate (or survey report)")
    issuer: str = Field(min_length=1, max_length=200, pattern=ONE_LINE, description="who issued it (the calibration "
                        "laboratory, with its accreditation)")
    due_date: IsoDate = Field(description="when its calibration is due again (YYYY-MM-DD); from the day after, it "
                              "is overdue")


#: The references a rig config names, with what each makes traceable (in the order a certificate lists them).
REFERENCE_LABELS = {
    "turntable_angle": "turntable angle (every pose's reference gravity direction)",
    "turntable_rate": "turntable rate (every rate step's reference rate)",
    "site_gravity": "site gravity (gravity_m_s2)",
    "site_magnetic_field": "site magnetic field (magnetic_field: every magnetometer's reference)",
    "temperature": "temperature (the chamber's air temperature)",
}


class References(StrictModel):
    """The rig's references, each with its own certificate; a reference not stated is said so on certificates."""

    turntable_angle: ReferenceConfig | None = Field(None, description="the table's angle encoders (or the "
                                                    "calibration of its positioning)")
    turntable_rate: ReferenceConfig | None = Field(None, description="the table's rate (a table with a rate mode)")
    site_gravity: ReferenceConfig | None = Field(None, description="the determination of the site's gravity "
                                                 "(a gravimeter survey's report)")
    site_magnetic_field: ReferenceConfig | None = Field(None, description="the determination of the site's "
                                                        "magnetic field where the fixture is (a survey's report, "
                                                        "the reference magnetometer's certificate)")
    temperature: ReferenceConfig | None = Field(None, description="the temperature reference the chamber's "
                                                "readings are traced to (a reference thermometer)")


@dataclass(frozen=True)
class Receipt:
    """What a campaign states of every DUT whose fixture entry does not (`rig run --customer`, `--received`,
    `--condition`): whose it is, when it arrived, in what condition."""

    customer: str = ""
    received_date: dt.date | None = None
    contact: str = ""                 # the customer's contact (`rig run --contact`)
    condition: str = ""
    lot: str = ""                     # the lab's lot (`rig run --lot`), not the part number
