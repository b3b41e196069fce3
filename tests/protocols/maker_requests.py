"""Conformance from the makers' side, as data: for each chamber line profile, the exact requests the makers'
own libraries and other public clients send (each cited by repository, path and function), in the order a
client's session would send them, and what must happen to each on a controller of that profile: understood
as a profile operation (its reply read by the driver's pattern, its values the simulated chamber's state),
answered as the client reads it, refused with the answer the public protocol gives, or met with silence.

tests/protocols/test_maker_requests.py replays every conversation against the simulator over TCP and feeds
the replies through the driver's reply parsing. Requests are written without their line terminator (the
profile's is sent). Requests the public clients send that the simulator does not model are listed in
NOT_SIMULATED, with the reason, so that the gap is on record rather than hidden.

Facts: /docs/instruments.md, "Where each profile's facts come from".
"""

from __future__ import annotations

from dataclasses import dataclass, field

from accelcal_rig.protocols.chamber_lines import Operation

S = "\u00b6"  # SIMSERV's field separator (byte 0xB6)


@dataclass(frozen=True)
class Row:
    """One request as a client sends it, and what must come of it."""

    request: str
    where: str  # path in the client's repository, and function
    operation: Operation | None = None  # understood as this profile operation: its reply read by the driver
    reply: str | None = None  # a regular expression the whole reply must match (how the client reads it)
    refused: str | None = None  # the exact refusal the public protocol gives
    silent: bool = False  # no reply (SCPI settings; an SCPI header the F4T does not know)
    setpoint_c: float | None = None  # afterwards the controller's set point is this
    powered: bool | None = None  # afterwards the chamber conditions (runs) or not
    purge: bool | None = None  # afterwards the dry-air purge output is on or off
    ending: str | None = None  # the line end the client sends, where it is not the profile's write_terminator


@dataclass(frozen=True)
class Conversation:
    """A client's requests to one controller, replayed in order on a fresh simulated controller."""

    profile: str
    client: str  # owner/repository (or the standard, for grammar rows)
    licence: str
    rows: tuple[Row, ...]
    overrides: dict[str, object] = field(default_factory=dict)  # the profile as that rig would configure it


_N = r"-?\d+\.\d+"
_ESPEC_MODES = "OFF|STANDBY|CONSTANT|RUN"

ESPEC = (
    Conversation("espec-p300", "EspecNorthAmerica/ChamberConnectLibrary", "MIT", (
        Row("TYPE?", "chamberconnectlibrary/p300.py read_type", "identify",
            reply=rf"T,T,[^,]+,{_N}"),  # drybulb,wetbulb,controller,tempmax (3 fields: temperature-only)
        Row("TEMP?", "chamberconnectlibrary/p300.py read_temp", "read_temperature"),
        Row("HUMI?", "chamberconnectlibrary/p300.py read_humi", "humidity"),
        Row("MON?", "chamberconnectlibrary/p300.py read_mon", reply=rf"{_N},\d+,CONSTANT,0"),
        Row("MODE?", "chamberconnectlibrary/p300.py read_mode", reply="CONSTANT"),
        Row("MODE?,DETAIL", "chamberconnectlibrary/p300.py read_mode (espec.py get_status)", reply="CONSTANT"),
        Row("ALARM?", "chamberconnectlibrary/p300.py read_alarm", "alarm"),
        Row("TEMP, S-12.5", "chamberconnectlibrary/p300.py write_temp", "write_setpoint",
            reply="OK:TEMP, S-12.5", setpoint_c=-12.5),
        Row("TEMP?", "chamberconnectlibrary/p300.py read_temp", "read_setpoint"),
        Row("MODE,STANDBY", "chamberconnectlibrary/p300.py write_mode_standby (Espec.stop)", "power_off",
            reply="OK:MODE,STANDBY", powered=False),
        Row("MODE?", "chamberconnectlibrary/p300.py read_mode", reply="STANDBY"),
        Row("MODE,CONSTANT", "chamberconnectlibrary/p300.py write_mode_constant (Espec.const_start)", "power_on",
            reply="OK:MODE,CONSTANT", powered=True),
        Row("POWER,off", "chamberconnectlibrary/p300.py write_power", reply="OK:POWER,off", powered=False),
        Row("MODE?", "chamberconnectlibrary/p300.py read_mode", reply="OFF"),
        Row("MON?,DETAIL", "chamberconnectlibrary/p300.py read_mon", reply=rf"{_N},\d+,OFF,0"),
        Row("POWER,ON", "chamberconnectlibrary/p300.py write_power", reply="OK:POWER,ON", powered=True),
        Row("MODE,OFF", "chamberconnectlibrary/p300.py write_mode_off", reply="OK:MODE,OFF", powered=False),
        Row("PRGM,PAUSE", "chamberconnectlibrary/p300.py write_prgm_pause", refused="NA:CONT NOT READY-2"),  # none runs
    )),
    Conversation("espec-p300", "akaeba/ATWG", "GPL-3.0", (
        Row("TYPE?", "driver/espec/sh641.py (RSP_CH_ID in sh641Const.py)", "identify", reply=rf"T,T,[^,]+,{_N}"),
        Row("TEMP?", "driver/espec/sh641.py parse", "read_temperature"),
        Row("HUMI?", "driver/espec/sh641.py parse", "humidity"),
        Row("TEMP,S35.2", "driver/espec/sh641.py set_clima", "write_setpoint", reply="OK:TEMP,S35.2", setpoint_c=35.2),
        Row("POWER,ON", "driver/espec/sh641.py start (set_power)", reply="OK:POWER,ON", powered=True),
        Row("MODE,CONSTANT", "driver/espec/sh641.py start (set_mode)", "power_on", reply="OK:MODE,CONSTANT",
            powered=True),
        Row("MODE,STANDBY", "driver/espec/sh641.py stop (set_mode)", "power_off", reply="OK:MODE,STANDBY",
            powered=False),
        Row("POWER,OFF", "driver/espec/sh641.py stop (set_power)", reply="OK:POWER,OFF", powered=False),
    )),
    Conversation("espec-p300", "leandrolanzieri/espec_pr3j", "MIT (metadata; LGPL-3.0 licence file)", (
        Row("TEMP?", "src/espec_pr3j/espec_pr3j.py get_temperature_status", "read_temperature"),
        Row("HUMI?", "src/espec_pr3j/espec_pr3j.py get_humidity_status", "humidity",
            reply=r"(\d+),(OFF|\d+),(\d+),(\d+)"),
        Row("MON?", "src/espec_pr3j/espec_pr3j.py get_test_area_state", reply=r"(\d+\.\d+),(\d+),(\w+),(\d+)"),
        Row("MODE?", "src/espec_pr3j/espec_pr3j.py get_mode", reply=_ESPEC_MODES),
        Row("TEMP, S31.0", "src/espec_pr3j/espec_pr3j.py set_target_temperature", "write_setpoint",
            reply=r"OK:TEMP, S\d+.\d+", setpoint_c=31.0),
        Row("MODE, STANDBY", "src/espec_pr3j/espec_pr3j.py set_mode", "power_off", reply="OK:MODE, STANDBY",
            powered=False),
        Row("MODE, CONSTANT", "src/espec_pr3j/espec_pr3j.py set_mode", "power_on", reply="OK:MODE, CONSTANT",
            powered=True),
        Row("MODE, OFF", "src/espec_pr3j/espec_pr3j.py set_mode", reply="OK:MODE, OFF", powered=False),
    )),
    Conversation("espec-p300", "vincesum/ESPEC-Temperature-Control-UI", "none stated", (
        Row("1,TYPE?", "src/ESPEC.py SH241", "identify"),
        Row("1,MODE?", "src/ESPEC.py SH241", reply=_ESPEC_MODES),
        Row("1,MON?", "src/ESPEC.py SH241", reply=rf"{_N},\d*,({_ESPEC_MODES}),\d+"),
        Row("1,TEMP?", "src/ESPEC.py SH241", "read_temperature"),
        Row("1,TEMP,S31.0", "src/ESPEC.py SH241", "write_setpoint", reply="OK:TEMP,S31.0", setpoint_c=31.0),
        Row("1,POWER,ON", "src/ESPEC.py SH241", reply="OK:POWER,ON", powered=True),
        Row("1,MODE,STANDBY", "src/ESPEC.py SH241", "power_off", powered=False),
        Row("1,MODE,CONSTANT", "src/ESPEC.py SH241", "power_on", powered=True),
        Row("1,POWER,OFF", "src/ESPEC.py SH241", reply="OK:POWER,OFF", powered=False),
    ), overrides={"request_prefix": "1,"}),
    Conversation("espec-p300", "PyPI py-lab-hal 2.5.20241201", "Apache-2.0", (
        Row("TEMP?", "py_lab_hal/instrument/temp_chamber/pu3j.py Pu3j", "read_temperature"),
        Row("TEMP, S25.00", "py_lab_hal/instrument/temp_chamber/pu3j.py Pu3j", "write_setpoint", setpoint_c=25.0),
        Row("POWER, OFF", "py_lab_hal/instrument/temp_chamber/pu3j.py Pu3j", reply="OK:POWER, OFF", powered=False),
        Row("POWER, ON", "py_lab_hal/instrument/temp_chamber/pu3j.py Pu3j", reply="OK:POWER, ON", powered=True),
    )),
    # A temperature-only chamber (the profile without humidity): TYPE? has three fields, MON?'s humidity is
    # empty, and HUMI? is refused as ESPEC's library reads it ("Chamber does not support PTCON/Humidity").
    Conversation("espec-p300", "EspecNorthAmerica/ChamberConnectLibrary", "MIT", (
        Row("TYPE?", "chamberconnectlibrary/p300.py read_type", "identify", reply=rf"T,[^,]+,{_N}"),
        Row("MON?", "chamberconnectlibrary/p300.py read_mon", reply=rf"{_N},,CONSTANT,0"),
        Row("HUMI?", "chamberconnectlibrary/espec.py process_controller", refused="NA:CONT NOT READY-1"),
    ), overrides={"humidity": None}),
)

THERMOTRON = (
    Conversation("thermotron-8800", "pymeasure/pymeasure", "MIT", (
        Row("IDEN?", "pymeasure/instruments/thermotron/thermotron3800.py id", "identify"),
        Row("PVAR1?", "pymeasure/instruments/thermotron/thermotron3800.py temperature", "read_temperature"),
        Row("SETP1,25", "pymeasure/instruments/thermotron/thermotron3800.py setpoint (SETP1,%g)", "write_setpoint",
            reply="0", setpoint_c=25.0),
        Row("SETP1?", "pymeasure/instruments/thermotron/thermotron3800.py setpoint", "read_setpoint"),
        Row("STOP", "pymeasure/instruments/thermotron/thermotron3800.py stop", "power_off", reply="0", powered=False),
        Row("RUNM", "pymeasure/instruments/thermotron/thermotron3800.py run", "power_on", reply="0", powered=True),
        Row("SETP1,-12.5", "pymeasure/instruments/thermotron/thermotron3800.py setpoint (SETP1,%g)",
            "write_setpoint", reply="0", setpoint_c=-12.5),
        # Thermotron3800 leaves the terminators to its user: PyVISA's default CR LF, or LF, each ends a request
        Row("IDEN?", "thermotron3800.py id (PyVISA's write_termination, CR LF)", "identify", ending="\r\n"),
        Row("PVAR1?", "thermotron3800.py temperature (write_termination='\\n')", "read_temperature", ending="\n"),
        Row("SETP1,-20", "thermotron3800.py setpoint (write_termination='\\n')", "write_setpoint", reply="0",
            setpoint_c=-20.0, ending="\n"),
        Row("SETP1?", "thermotron3800.py setpoint (the profile's CR again)", "read_setpoint"),
    )),
)

SIMSERV = (
    Conversation("simserv", "SiLab-Bonn/basil", "BSD-3-Clause", (
        Row(f"99997{S}1{S}1", "basil/HL/weiss_labevent.py get_info", "identify"),
        Row(f"10012{S}1{S}1", "basil/HL/weiss_labevent.py get_status", reply=f"1{S}3"),  # running
        Row(f"11004{S}1{S}1", "basil/HL/weiss_labevent.py get_temperature", "read_temperature"),
        Row(f"11001{S}1{S}1{S}25.0", "basil/HL/weiss_labevent.py set_temperature", "write_setpoint", reply="1",
            setpoint_c=25.0),
        Row(f"11002{S}1{S}1", "basil/HL/weiss_labevent.py get_temperature_setpoint", "read_setpoint"),
        Row(f"14001{S}1{S}1{S}0", "basil/HL/weiss_labevent.py stop_manual_mode", "power_off", reply="1",
            powered=False),
        Row(f"10012{S}1{S}1", "basil/HL/weiss_labevent.py get_status", reply=f"1{S}1"),  # idle
        Row(f"14001{S}1{S}1{S}1", "basil/HL/weiss_labevent.py start_manual_mode", "power_on", reply="1",
            powered=True),
        Row(f"14001{S}1{S}5{S}1", "basil/HL/weiss_labevent.py set_compressed_air (output id + 1)", reply="1"),
        Row(f"14003{S}1{S}5", "basil/HL/weiss_labevent.py get_compressed_air", reply=f"1{S}1"),
    )),
    Conversation("simserv", "IzaakWN/ClimateChamberMonitor", "none stated", (
        Row(f"10012{S}1", "chamber_commands.py getRunStatus", "alarm", reply=f"1{S}3"),
        Row(f"11004{S}1{S}1", "chamber_commands.py getTemp", "read_temperature"),
        Row(f"11004{S}1{S}2", "chamber_commands.py (actual value, variable 2)", "humidity"),
        Row(f"11002{S}1{S}1", "chamber_commands.py getSetp", "read_setpoint"),
        Row(f"11001{S}1{S}1{S}56.7", "simple_test.py", "write_setpoint", reply="1", setpoint_c=56.7),
        Row(f"14001{S}1{S}1{S}0", "run_manual.py (START MANUAL [1,0])", "power_off", reply="1", powered=False),
        Row(f"10012{S}1", "chamber_commands.py getRunStatus", "alarm", reply=f"1{S}1"),
        Row(f"14001{S}1{S}1{S}1", "run_manual.py (START MANUAL [1,1])", "power_on", reply="1", powered=True),
        Row(f"14001{S}1{S}8{S}1", "chamber_commands.py (SET DIGI_OUT VAL [8,1], dryer)", "purge_on", reply="1",
            purge=True),
        Row(f"14003{S}1{S}8", "chamber_commands.py getDryer", reply=f"1{S}1"),
        Row(f"14001{S}1{S}8{S}0", "chamber_commands.py (SET DIGI_OUT VAL [8,0])", "purge_off", reply="1", purge=False),
        Row(f"14001{S}1{S}7{S}1", "chamber_commands.py (SET DIGI_OUT VAL [7,1], compressed air)", reply="1"),
        Row(f"14003{S}1{S}7", "chamber_commands.py getAir", reply=f"1{S}1"),
        # the status codes its dictionary documents: -5 unknown number, -6 too few or incorrect parameters
        Row(f"12345{S}1", "chamber_commands.py (status -5)", refused="-5"),
        Row(f"99997{S}1", "chamber_commands.py (status -6; our old identify)", refused="-6"),
        Row(f"14001{S}1{S}1", "chamber_commands.py (status -6)", refused="-6"),
    )),
    Conversation("simserv", "SengerM/VotschTechnik-climate-chamber-Python", "MIT", (
        Row(f"99997{S}1{S}1", "VotschTechnikClimateChamber/ClimateChamber.py test_system_type", "identify"),
        Row(f"11004{S}1{S}1", "VotschTechnikClimateChamber/ClimateChamber.py temperature_measured",
            "read_temperature"),
        Row(f"11001{S}1{S}1{S}-20.0", "VotschTechnikClimateChamber/ClimateChamber.py temperature_set_point (str)",
            "write_setpoint", reply="1", setpoint_c=-20.0),
        Row(f"14001{S}1{S}1{S}0", "VotschTechnikClimateChamber/ClimateChamber.py stop", "power_off", powered=False),
        Row(f"14003{S}1{S}1", "VotschTechnikClimateChamber/ClimateChamber.py is_running", reply=f"1{S}0"),
        Row(f"14001{S}1{S}1{S}1", "VotschTechnikClimateChamber/ClimateChamber.py start", "power_on", powered=True),
        Row(f"14003{S}1{S}1", "VotschTechnikClimateChamber/ClimateChamber.py is_running", reply=f"1{S}1"),
    )),
)

WATLOW_F4T = (
    Conversation("watlow-f4t-scpi", "EspecNorthAmerica/WatlowF4T-SCPI-Lib", "MIT", (
        Row("*IDN?", "f4tscpi/f4t_interface.py get_id", "identify"),
        Row(":UNIT:TEMPERATURE?", "f4tscpi/f4t_interface.py get_units", "units", reply="C|F"),
        Row(":SOURCE:CLOOP1:PVALUE?", "f4tscpi/f4t_interface.py get_pv", "read_temperature"),
        Row("SOURCE:CLOOP1:SPOINT 25.0", "f4tscpi/f4t_interface.py write_sp (no leading colon, str(float))",
            "write_setpoint", silent=True, setpoint_c=25.0),
        Row(":SOURCE:CLOOP1:SPOINT?", "f4tscpi/f4t_interface.py get_sp", "read_setpoint"),
        Row(":SOURCE:CLOOP2:PVALUE?", "f4tscpi/f4t_interface.py get_pv (loop 2)", "humidity"),
    )),
    Conversation("watlow-f4t-scpi", "DAsh0244/te107_control", "MIT", (
        Row("SOURCE:CLOOP1:SPOINT 30.0", "src/f4t_control.py set_temperature", "write_setpoint", silent=True,
            setpoint_c=30.0),
        Row(":UNITS:TEMPERATURE C", "src/f4t_control.py (UNITS is no F4T header: UNIT is)", silent=True),
    )),
    Conversation("watlow-f4t-scpi", "PyPI py-lab-hal 2.5.20241201", "Apache-2.0", (
        Row(":SOURCE:CLOOP1:SPOINT -12.50", "py_lab_hal/instrument/temp_chamber/testequity_107.py Testequity107",
            "write_setpoint", silent=True, setpoint_c=-12.5),
    )),
    # SCPI-99 vol. 1 §6-7: the spellings the manuals' notation (:SOURce:CLOop1:SPOint) allows.
    Conversation("watlow-f4t-scpi", "SCPI-99 program header grammar", "standard", (
        Row(":sour:clo1:spo 30", "short forms, lower case", "write_setpoint", silent=True, setpoint_c=30.0),
        Row(":SOURce:CLOOp1:PVALUE?", "mixed case (an AutoIt client's spelling)", "read_temperature"),
        Row("SOUR:CLO:SPO?", "no leading colon, suffix 1 left out", "read_setpoint"),
        Row(":source:cloop2:pvalue?", "long forms, lower case, loop 2", "humidity"),
        Row("*idn?", "common command, lower case", "identify"),
        Row(":SOURCE:CLOOP1:SPOINTS 40", "not a mnemonic: the F4T documents no error reply", silent=True),
    )),
)

CONVERSATIONS: tuple[Conversation, ...] = (*ESPEC, *THERMOTRON, *SIMSERV, *WATLOW_F4T)

#: (profile, request, client, where, why the simulator does not serve it): requests public clients send that
#: a real controller understands but the simulated one does not model. It answers them as an unknown
#: request (ESPEC `NA:CMD ERR`, SIMSERV `-8` for a known number, silence on Thermotron and F4T).
NOT_SIMULATED: tuple[tuple[str, str, str, str, str], ...] = (
    ("espec-p300", "ROM?", "EspecNorthAmerica/ChamberConnectLibrary", "p300.py read_rom", "no ROM version"),
    ("espec-p300", "SRQ?", "EspecNorthAmerica/ChamberConnectLibrary", "p300.py read_srq", "no service requests"),
    ("espec-p300", "%?", "leandrolanzieri/espec_pr3j", "espec_pr3j.py get_heater_percentage", "no heater outputs"),
    ("espec-p300", "TEMP, H 30.0", "leandrolanzieri/espec_pr3j", "espec_pr3j.py set_temperature_limits",
     "limits are the simulation's, not writable"),
    ("espec-p300", "HUMI, SOFF", "leandrolanzieri/espec_pr3j", "espec_pr3j.py set_target_humidity",
     "humidity is measured, not controlled"),
    ("thermotron-8800", "MODE?", "pymeasure/pymeasure", "thermotron3800.py mode", "no mode register"),
    ("thermotron-8800", "INIT", "pymeasure/pymeasure", "thermotron3800.py initalize_oven", "nothing to initialise"),
    ("simserv", f"11068{S}1{S}1{S}3", "IzaakWN/ClimateChamberMonitor", "chamber_commands.py forceWarmUp",
     "no gradients (answered -8)"),
    ("simserv", f"14010{S}1{S}5", "SiLab-Bonn/basil", "weiss_labevent.py _get_feature_status",
     "outputs have no names (answered -8)"),
    ("watlow-f4t-scpi", "OUTPUT1:STATE ON", "PyPI py-lab-hal 2.5.20241201", "testequity_107.py enable_power",
     "no event outputs in the profile (TestEquity wires output 1 to chamber enable)"),
)
