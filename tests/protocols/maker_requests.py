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
    limits_c: tuple[float, float] | None = None  # afterwards the controller's set point limits are these


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
        Row("CONSTANT SET?,HUMI", "chamberconnectlibrary/p300.py read_constant_humi", refused="NA:CONT NOT READY-1"),
        Row("HUMI, S50.0", "chamberconnectlibrary/p300.py write_humi", refused="NA:CONT NOT READY-1"),
    ), overrides={"humidity": None}),
    # Beyond the profile (issue 43): ChamberConnectLibrary 2.2.5's P300 and Espec classes' every request that
    # reads or sets what the simulated controller holds, answered in the format the library's parser reads
    # (p300.py), each setting echoed `OK:<command as received>` (EHS manual §1.3) and carried out.
    Conversation("espec-p300", "EspecNorthAmerica/ChamberConnectLibrary", "MIT", (
        Row("ROM?", "chamberconnectlibrary/p300.py read_rom (espec.py process_controller: startswith('P3') is a "
            "P300; syndesi sh242.py test: 9-20 characters)", reply=r"P3.{7,18}"),
        Row("ROM?,DISP", "chamberconnectlibrary/p300.py read_rom(display=True)", reply=r".{9,20}"),
        Row("CONSTANT SET?,TEMP", "chamberconnectlibrary/p300.py read_constant_temp (espec.py get_loop_sp)",
            reply=rf"{_N},ON"),
        Row("TEMP, S-12.5", "chamberconnectlibrary/p300.py write_temp", "write_setpoint", setpoint_c=-12.5),
        Row("CONSTANT SET?,TEMP", "chamberconnectlibrary/p300.py read_constant_temp", reply=r"-12\.5,ON"),
        Row("TEMP, L-40.0", "chamberconnectlibrary/p300.py write_temp(min=…) (espec.py set_loop_range)",
            reply="OK:TEMP, L-40.0", limits_c=(-40.0, 180.0)),
        Row("TEMP, H100.0", "chamberconnectlibrary/p300.py write_temp(max=…) (espec.py set_loop_range)",
            reply="OK:TEMP, H100.0", limits_c=(-40.0, 100.0)),
        Row("TEMP?", "chamberconnectlibrary/p300.py read_temp (espec.py get_loop_range)", "read_high_limit"),
        Row("TYPE?", "chamberconnectlibrary/p300.py read_type: the chamber's maximum stays", reply=r"T,T,[^,]+,180\.0"),
        Row("TEMP, S25.0 H120.0 L-50.0", "chamberconnectlibrary/p300.py write_temp(setpoint, max, min)",
            reply="OK:TEMP, S25.0 H120.0 L-50.0", setpoint_c=25.0, limits_c=(-50.0, 120.0)),
        Row("TEMP, H200.0", "especinteract.py 'DATA OUT OF RANGE' (beyond TYPE?'s maximum)",
            refused="NA:DATA OUT OF RANGE", limits_c=(-50.0, 120.0)),
        Row("TEMP, L-80.0", "especinteract.py 'DATA OUT OF RANGE' (below the chamber's range)",
            refused="NA:DATA OUT OF RANGE", limits_c=(-50.0, 120.0)),
        Row("HUMI, S25.0", "chamberconnectlibrary/p300.py write_humi (espec.py set_loop_sp(2))",
            reply="OK:HUMI, S25.0"),
        Row("CONSTANT SET?,HUMI", "chamberconnectlibrary/p300.py read_constant_humi (espec.py get_loop_sp(2))",
            reply="25,ON"),
        Row("HUMI?", "chamberconnectlibrary/p300.py read_humi", "humidity", reply=r"\d+,25,100,0"),
        Row("HUMI, S50.0 H90.0 L10.0", "chamberconnectlibrary/p300.py write_humi(setpoint, max, min)",
            reply="OK:HUMI, S50.0 H90.0 L10.0"),
        Row("HUMI?", "chamberconnectlibrary/p300.py read_humi", "humidity", reply=r"\d+,50,90,10"),
        Row("HUMI,SOFF", "chamberconnectlibrary/p300.py write_humi(enable=False) (espec.py set_loop_en(2))",
            reply="OK:HUMI,SOFF"),
        Row("CONSTANT SET?,HUMI", "chamberconnectlibrary/p300.py read_constant_humi", reply="50,OFF"),
        Row("HUMI, H120.0", "especinteract.py 'DATA OUT OF RANGE' (above 100 % RH)", refused="NA:DATA OUT OF RANGE"),
        Row("SET,REF6", "chamberconnectlibrary/p300.py write_set('manual', 100) (encode_refrig)", reply="OK:SET,REF6"),
        Row("SET?", "chamberconnectlibrary/p300.py read_set (reflookup)", reply="REF6"),
        Row("CONSTANT SET?,REF", "chamberconnectlibrary/p300.py read_constant_ref (espec.py get_refrig)",
            reply="100"),
        Row("REF?", "chamberconnectlibrary/p300.py read_ref (conditioning, manual refrigeration)", reply="6,ON1"),
        Row("RELAY,ON,1,3", "chamberconnectlibrary/p300.py write_relay (espec.py set_event)",
            reply="OK:RELAY,ON,1,3"),
        Row("RELAY?", "chamberconnectlibrary/p300.py read_relay (espec.py get_event)", reply="2,1,3"),
        Row("RELAY,OFF,1", "chamberconnectlibrary/p300.py write_relay", reply="OK:RELAY,OFF,1"),
        Row("CONSTANT SET?,RELAY", "chamberconnectlibrary/p300.py read_constant_relay", reply="1,3"),
        Row("RELAY,ON,13", "especinteract.py 'DATA OUT OF RANGE' (time signals 1-12)", refused="NA:DATA OUT OF RANGE"),
        Row("KEYPROTECT,ON", "chamberconnectlibrary/p300.py write_keyprotect", reply="OK:KEYPROTECT,ON"),
        Row("KEYPROTECT?", "chamberconnectlibrary/p300.py read_keyprotect", reply="ON"),
        Row("KEYPROTECT,off", "chamberconnectlibrary/p300.py write_keyprotect(False)", reply="OK:KEYPROTECT,off"),
        Row("KEYPROTECT?", "chamberconnectlibrary/p300.py read_keyprotect", reply="OFF"),
        Row("MASK,01000000", "chamberconnectlibrary/p300.py write_mask(alarm=True)", reply="OK:MASK,01000000"),
        Row("MASK?", "chamberconnectlibrary/p300.py read_mask", reply="01000000"),
        Row("SRQ,RESET", "chamberconnectlibrary/p300.py write_srq", reply="OK:SRQ,RESET"),
        Row("TIME,12:30:0", "chamberconnectlibrary/p300.py write_time (espec.py set_datetime)",
            reply="OK:TIME,12:30:0"),
        Row("DATE,25.1/15. WED", "chamberconnectlibrary/p300.py write_date (espec.py set_datetime)",
            reply="OK:DATE,25.1/15. WED"),
        Row("DATE?", "chamberconnectlibrary/p300.py read_date (syndesi sh242.py: '%y.%m/%d')", reply=r"25\.01/15"),
        Row("TIME?", "chamberconnectlibrary/p300.py read_time (syndesi sh242.py: '%H:%M:%S'; the clock stood still)",
            reply="12:30:00"),
        Row("IPSET,192.168.0.10,255.255.255.0,192.168.0.1", "chamberconnectlibrary/p300.py write_ip_set",
            reply="OK:IPSET,192.168.0.10,255.255.255.0,192.168.0.1"),
        Row("IPSET?", "chamberconnectlibrary/p300.py read_ip_set (espec.py get_network_settings)",
            reply=r"192\.168\.0\.10,255\.255\.255\.0,192\.168\.0\.1"),
        Row("TIMER ON?", "chamberconnectlibrary/p300.py read_timer_on (none on)", reply="0"),
        Row("TIMER USE?", "chamberconnectlibrary/p300.py read_timer_use (none set)", reply="0"),
        Row("PRGM USE?,RAM", "chamberconnectlibrary/p300.py read_prgm_use (syndesi: 'N, 1, 2, 5'; none stored)",
            reply="0"),
        Row("MODE,STANDBY", "chamberconnectlibrary/p300.py write_mode_standby", "power_off", powered=False),
        Row("REF?", "chamberconnectlibrary/p300.py read_ref (not conditioning)", reply="6,OFF1"),
        Row("POWER,off", "chamberconnectlibrary/p300.py write_power(False)", reply="OK:POWER,off", powered=False),
        Row("KEYPROTECT,ON", "especinteract.py 'CONT NOT READY-4' (the controller is off)",
            refused="NA:CONT NOT READY-4"),
    )),
    Conversation("espec-p300", "leandrolanzieri/espec_pr3j", "MIT (metadata; LGPL-3.0 licence file)", (
        Row("TEMP, H 100.0", "src/espec_pr3j/espec_pr3j.py set_temperature_limits (f'{upper: 0.1f}')",
            reply=r"OK:TEMP, H \d+.\d+", limits_c=(-70.0, 100.0)),
        Row("TEMP, L 0.0", "src/espec_pr3j/espec_pr3j.py set_temperature_limits", reply=r"OK:TEMP, L \d+.\d+",
            limits_c=(0.0, 100.0)),
        Row("HUMI, H100.0", "src/espec_pr3j/espec_pr3j.py set_humidity_limits (str(float))", reply=r"OK:HUMI, H\d+.*"),  # re.match
        Row("HUMI, L0.0", "src/espec_pr3j/espec_pr3j.py set_humidity_limits", reply=r"OK:HUMI, L\d+.*"),
        Row("HUMI, S45.0", "src/espec_pr3j/espec_pr3j.py set_target_humidity", reply=r"OK:HUMI, S\d+.*\d*"),
        Row("HUMI, SOFF", "src/espec_pr3j/espec_pr3j.py set_target_humidity(None)", reply="OK:HUMI, SOFF"),
        Row("HUMI?", "src/espec_pr3j/espec_pr3j.py get_humidity_status", "humidity",
            reply=r"(\d+),(OFF),(\d+),(\d+)"),
        Row("MODE, RUN", "src/espec_pr3j/espec_pr3j.py set_mode(RUN) (no program number: MODE,RUN<n>, p300.py "
            "write_mode_run)", refused="NA:PARA ERR"),
    )),
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
        Row("*IDN?", "f4tscpi/f4t_interface.py get_id (the F4T list: Watlow Electric | <string> | <integer> | "
            "<string>)", "identify", reply=r"Watlow Electric,[^,]*,\d+,[^,]*"),
        Row(":UNIT:TEMPERATURE?", "f4tscpi/f4t_interface.py get_units", "units", reply="C|F"),
        Row(":SOURCE:CLOOP1:PVALUE?", "f4tscpi/f4t_interface.py get_pv", "read_temperature"),
        Row("SOURCE:CLOOP1:SPOINT 25.0", "f4tscpi/f4t_interface.py write_sp (no leading colon, str(float))",
            "write_setpoint", silent=True, setpoint_c=25.0),
        Row(":SOURCE:CLOOP1:SPOINT?", "f4tscpi/f4t_interface.py get_sp", "read_setpoint"),
        Row(":SOURCE:CLOOP2:PVALUE?", "f4tscpi/f4t_interface.py get_pv (loop 2)", "humidity"),
        # Beyond the profile (issue 43): the F4T list's headers (PaulNongL/WatlowF4TscpiLibrary
        # f4t_scpi_cmds/f4t_scpi_commands.ods) the library sends, held and read back
        Row(":SOURCE:CLOOP2:SPOINT 45.0", "f4tscpi/f4t_interface.py write_sp(45.0, 2) (Write SP)", silent=True),
        Row(":SOURCE:CLOOP2:SPOINT?", "f4tscpi/f4t_interface.py get_sp(2) (Read SP)", reply=r"45\.00"),
        Row(":SOURCE:CLOOP1:RACTION OFF", "f4tscpi/f4t_interface.py ramp_mode (Set ramping off)", silent=True),
        Row(":SOURCE:CLOOP1:RSCALE MINUTES", "f4tscpi/f4t_interface.py set_rampScale (Write ramp scale to minutes)",
            silent=True),
        Row(":SOURCE:CLOOP1:RRATE 2.0", "f4tscpi/f4t_interface.py set_ramp('rate') (Write ramp rate)", silent=True),
        Row(":SOURCE:CLOOP1:RRATE?", "f4tscpi/f4t_interface.py get_ramp('rate') (Read ramp rate)", reply=r"2\.00"),
        Row(":SOURCE:CLOOP1:RTIME 30", "f4tscpi/f4t_interface.py set_ramp('time') (Write ramp time)", silent=True),
        Row(":SOURCE:CLOOP1:RTIME?", "f4tscpi/f4t_interface.py get_ramp('time') (Read ramp time)", reply=r"30\.00"),
        Row(":SOURCE:CLOOP1:ERROR?", "the F4T list: Query input error → ERROR|NONE", reply="NONE"),
        Row(":OUTPUT3:STATE?", "f4tscpi/f4t_interface.py get_ts(3) (Query event output state)", reply="OFF"),
        Row(":OUTPUT3:STATE ON", "f4tscpi/f4t_interface.py set_output(3) (Set event output on)", silent=True),
        Row(":OUTPUT3:STATE?", "f4tscpi/f4t_interface.py set_output (read back)", reply="ON"),
        Row(":PROGRAM:NUMBER 1", "f4tscpi/f4t_interface.py select_profile (Select a profile, 1-40)", silent=True),
        Row(":PROGRAM:NAME?", "f4tscpi/f4t_interface.py get_profiles (Read selected profile name; none stored: "
            "empty, where the library stops)", reply=""),
    )),
    Conversation("watlow-f4t-scpi", "DAsh0244/te107_control", "MIT", (
        Row("SOURCE:CLOOP1:SPOINT 30.0", "src/f4t_control.py set_temperature", "write_setpoint", silent=True,
            setpoint_c=30.0),
        Row(":UNITS:TEMPERATURE C", "src/f4t_control.py (UNITS is no F4T header: UNIT is)", silent=True),
    )),
    Conversation("watlow-f4t-scpi", "PyPI py-lab-hal 2.5.20241201", "Apache-2.0", (
        Row(":SOURCE:CLOOP1:SPOINT -12.50", "py_lab_hal/instrument/temp_chamber/testequity_107.py Testequity107",
            "write_setpoint", silent=True, setpoint_c=-12.5),
        Row("OUTPUT1:STATE ON", "py_lab_hal/instrument/temp_chamber/testequity_107.py enable_power(True) (an event "
            "output wired to nothing simulated: held)", silent=True),
        Row(":OUTPUT1:STATE?", "the F4T list: Query event output state", reply="ON"),
        Row(":SOURCE:CLOOP1:RACTION OFF", "py_lab_hal/instrument/temp_chamber/testequity_107.py enable_ramp(False)",
            silent=True),
        Row(":SOURCE:CLOOP1:RRATE 1.50", "py_lab_hal/instrument/temp_chamber/testequity_107.py set_ramp_rate",
            silent=True),
        Row(":SOURCE:CLOOP1:RRATE?", "the F4T list: Read ramp rate", reply=r"1\.50"),
        Row(":PROGRAM:NUMBER 2", "py_lab_hal/instrument/temp_chamber/testequity_107.py run_profile", silent=True),
    )),
    # A TestEquity chamber: output 1 enables the chamber (TestEquity's F4T manual), the profile's power command
    # by override (docs/instruments.md); reading the output back is reading the chamber's run.
    Conversation("watlow-f4t-scpi", "PyPI py-lab-hal 2.5.20241201", "Apache-2.0", (
        Row("OUTPUT1:STATE OFF", "py_lab_hal/instrument/temp_chamber/testequity_107.py enable_power(False)", "power_off",
            silent=True, powered=False),
        Row(":OUTPUT1:STATE?", "the F4T list: Query event output state", reply="OFF"),
        Row("OUTPUT1:STATE ON", "py_lab_hal/instrument/temp_chamber/testequity_107.py enable_power(True)", "power_on",
            silent=True, powered=True),
        Row(":OUTPUT1:STATE?", "the F4T list: Query event output state", reply="ON"),
    ), overrides={"power_on": {"send": ":OUTPut1:STATe ON"}, "power_off": {"send": ":OUTPut1:STATe OFF"}}),
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

_CCL = "EspecNorthAmerica/ChamberConnectLibrary"
_F4T_LIB = "EspecNorthAmerica/WatlowF4T-SCPI-Lib"
_NO_CASCADE = "no cascade: the F4T list gives the CASCADE headers for controllers with cascade control only"

#: (profile, request, client, where, why the simulator does not serve it): requests public clients send that
#: a real controller understands but the simulated one does not model. It answers them with the profile's
#: `unsupported_answer`, the controller's own 'not supported' (ESPEC `NA:INVALID REQ`, "unsupported function
#: … this chamber does not have the necessary options"; SIMSERV `-8`, data could not be read), or where the
#: profile has none, as an unknown request (silence on the Thermotron and the F4T, which document no error
#: reply).
NOT_SIMULATED: tuple[tuple[str, str, str, str, str], ...] = (
    ("espec-p300", "SRQ?", _CCL, "p300.py read_srq", "no service requests: the simulated controller raises none"),
    ("espec-p300", "%?", "leandrolanzieri/espec_pr3j", "espec_pr3j.py get_heater_percentage (p300.py read_htr)",
     "no heater outputs: the thermal model has no heater"),
    ("espec-p300", "PRGM DATA WRITE,PGM1,EDIT START", _CCL, "p300.py write_prgm_data_edit (espec.py set_program)",
     "no program memory: the simulated controller stores no program (so EDIT END / CANCEL answer PRGM WRITE "
     "ERR-3 and steps ERR-2, not in edit mode)"),
    ("espec-p300", "PRGM DATA WRITE,PGM1,OVER WRITE START", _CCL, "p300.py write_prgm_data_edit(overwrite=True)",
     "no program memory: the simulated controller stores no program"),
    *(("espec-p300", request, _CCL, where, "no timers: none can be set (so TIMER LIST?, TIMER ERASE and TIMER,ON "
       "answer DATA NOT READY)") for request, where in (
        ("TIMER WRITE,NO0,12:30,STANDBY", "p300.py write_timer_quick"),
        ("TIMER WRITE,NO0,12:30,OFF", "p300.py write_timer_quick"),
        ("TIMER WRITE,NO0,12:30,CONSTANT", "p300.py write_timer_quick"),
        ("TIMER WRITE,NO1,MODE1,25.1/15,12:30,CONSTANT", "p300.py write_timer_start"),
        ("TIMER WRITE,NO2,MODE3,12:30,STANDBY", "p300.py write_timer_stop"))),
    ("espec-p300", "RUN PRGM, TEMP25.0 TIME1:1", _CCL, "p300.py write_run_prgm",
     "no remote programs: the simulated controller runs none (RUN PRGM? and RUN PRGM MON? answer CONT NOT READY-2)"),
    ("espec-p300", "TEMP, SOFF", "syndesi-project/drivers", "Python/syndesi_drivers/instruments/ovens/espec/sh242.py "
     "set_temperature('OFF')", "temperature control switched off: not simulated (the chamber conditions in "
     "CONSTANT and stops in STANDBY)"),
    ("thermotron-8800", "MODE?", "pymeasure/pymeasure", "thermotron3800.py mode", "no mode register"),
    ("thermotron-8800", "INIT", "pymeasure/pymeasure", "thermotron3800.py initalize_oven", "nothing to initialise"),
    ("simserv", f"11068{S}1{S}1{S}3", "IzaakWN/ClimateChamberMonitor", "chamber_commands.py forceWarmUp",
     "no gradients (answered -8)"),
    ("simserv", f"14010{S}1{S}5", "SiLab-Bonn/basil", "weiss_labevent.py _get_feature_status",
     "outputs have no names (answered -8)"),
    ("simserv", f"11072{S}1{S}1{S}3", "IzaakWN/ClimateChamberMonitor", "chamber_commands.py forceWarmUp",
     "no gradients (answered -8)"),
    *(("simserv", f"99997{S}1{S}{item}", "SengerM/VotschTechnik-climate-chamber-Python",
       f"VotschTechnikClimateChamber/ClimateChamber.py {where}", f"the simulated chamber has no {what} (GET "
       f"CHAMBER INFO item {item} as the client reads it; answered -8, data could not be read)")
      for item, where, what in (("2", "year_manufactured", "year of manufacture"),
                                ("3", "serial_number", "serial number"))),
    *(("simserv", f"{number}{S}1", "IzaakWN/ClimateChamberMonitor", f"chamber_commands.py {where}",
       f"{why} (answered -8, data could not be read)") for number, where, why in (
        ("17002", "checkActiveWarnings / getActiveWarnings", "no message list: the simulated chamber keeps no "
         "messages (its alarms and warnings are the status bits of 10012)"),
        ("19204", "getRunStatus", "no program engine: the simulated chamber runs no program"),
        ("19210", "forceWarmUp / stopClimateChamber", "no program engine: the simulated chamber runs no program"))),
    *(("watlow-f4t-scpi", request, _F4T_LIB, f"f4tscpi/f4t_interface.py {where}", _NO_CASCADE) for request, where in (
        (":SOURCE:CASCADE1:SPOINT?", "get_cascadeSP"), (":SOURCE:CASCADE1:OUTER:PVALUE?", "get_cascadeLoopPV"),
        (":SOURCE:CASCADE1:INNER:PVALUE?", "get_cascadeLoopPV"), (":SOURCE:CASCADE1:OUTER:SPOINT?", "get_cascadeLoopSP"),
        (":SOURCE:CASCADE1:INNER:SPOINT?", "get_cascadeLoopSP"))),
    *(("watlow-f4t-scpi", request, client, where, "no profile engine: the simulated F4T stores and runs no profile "
       "(a selected profile's name reads empty)") for request, client, where in (
        (":PROGRAM:SELECTED:STATE START", _F4T_LIB, "f4tscpi/f4t_interface.py prog_mode"),
        (":PROGRAM:SELECTED:STATE STOP", "PyPI py-lab-hal 2.5.20241201", "testequity_107.py run_profile(n, False)"))),
    *(("watlow-f4t-scpi", request, client, where, "no ramping: the simulated air follows a set point at the chamber's "
       "own rate (the rig config's ramp_rate_c_per_min), as with RACTION OFF; rate, time and scale are held")
      for request, client, where in (
        (":SOURCE:CLOOP1:RACTION SETPOINT", _F4T_LIB, "f4tscpi/f4t_interface.py ramp_mode (its docstring: OFF, "
         "STARTUP, SETPOINT, BOTH)"),
        (":SOURCE:CLOOP1:RACTION BOTH", "PyPI py-lab-hal 2.5.20241201", "testequity_107.py enable_ramp(True)"))),
    *(("watlow-f4t-scpi", request, "PyPI py-lab-hal 2.5.20241201", f"py_lab_hal/instrument/instrument.py {where}",
       "an IEEE 488.2 common command that py-lab-hal's Instrument base class sends to every instrument: the "
       "simulated F4T answers *IDN? only and leaves the others unanswered, as every header it does not know (the "
       "F4T list's rows for them were not checked here)") for request, where in (
        ("*RST", "reset (and open_instrument at construction)"), ("*CLS", "clear (and open_instrument)"),
        ("*ESR?", "event_status_register"), ("*TST?", "self_test"), ("*OPC?", "wait_task"))),
    ("watlow-f4t-scpi", ":UNITS:TEMPERATURE C", "DAsh0244/te107_control", "src/f4t_control.py set_units",
     "not an F4T header (its own ref/scpi_commands.csv has :UNIT:TEMPERATURE): unanswered, as every header the F4T "
     "does not have, and nothing carried out"),
    ("watlow-f4t-scpi", ":SOURCE:CLOOP1:RSCALE RampScale.MINUTES", "DAsh0244/te107_control",
     "src/f4t_control.py set_ramp_scale", "the client's own slip: it formats the Enum member (str(), "
     "'RampScale.MINUTES') where the list takes MINUTES or HOURS; the F4T documents no error reply: unanswered, "
     "nothing carried out"),
    ("watlow-f4t-scpi", ":OUTPUT1:NAME?", _F4T_LIB, "f4tscpi/f4t_interface.py get_tsName",
     "not in the F4T's SCPI command list (the library's own): unanswered, as every header the F4T does not have"),
)


#: (profile, RS-485 address prefix, request, client, where, what the simulator answers, why): requests in a
#: spelling the maker's documents do not give, so that what a real controller answers is not known; the
#: simulated one answers as recorded here (test_maker_requests.py checks it), and the client sweep lists them
#: as not simulated with this reason.
UNDOCUMENTED_SPELLINGS: tuple[tuple[str, str, str, str, str, str, str], ...] = (
    *(("espec-p300", "1,", request, "vincesum/ESPEC-Temperature-Control-UI", f"src/ESPEC.py {where}", "NA:CMD ERR",
       "`PGM:1` (a colon) where the P300's documented form is `PGM1` (ChamberConnectLibrary p300.py "
       "write_prgm_data_edit; RAM:1 for PRGM ERASE); the client's own comment says the colon form works on its "
       "chamber. The simulated controller stores no program and does not take the colon: NA:CMD ERR")
      for request, where in (
        ("PRGM DATA WRITE,PGM:1,EDIT START", "SH241.ProgramWrite"),
        ("PRGM DATA WRITE,PGM:1,STEP1,TEMP30.0,TRAMPON,TIME00:01,", "SH241.ProgramWrite"),
        ("PRGM DATA WRITE,PGM:1,COUNT,(1.1.1)", "SH241.ProgramWrite"),
        ("PRGM DATA WRITE,PGM:1,END,HOLD", "SH241.ProgramWrite"),
        ("PRGM DATA WRITE,PGM:1,EDIT END", "SH241.ProgramWrite"),
        ("PRGM ERASE,PGM:1", "SH241.ProgramErase (and ProgramWrite)"))),
    ("espec-p300", "1,", "MODE,RUN 1", "vincesum/ESPEC-Temperature-Control-UI", "src/ESPEC.py SH241.SetModeProgram",
     "NA:PARA ERR", "a blank between RUN and the program number, where the P300's form is MODE,RUN<n> "
     "(ChamberConnectLibrary p300.py write_mode_run; the simulated controller refuses that DATA NOT READY, no "
     "program stored); this spelling it answers PARA ERR ('parameter missing or unrecognizable')"),
)


@dataclass(frozen=True)
class Refusal:
    """A refusal the maker documents for requests on a controller in the simulated state: each example is
    answered with it (test_maker_requests.py), and the client sweep (client_sweep.py) takes it as the answer
    the maker documents."""

    profile: str
    request: str  # a regular expression over the request as sent (its terminator cut)
    reply: str  # the refusal, exactly
    state: str  # the simulated controller's state it is the answer for
    source: str
    examples: tuple[str, ...]
    inferred: bool = False  # the code matched to the state by the error table's meanings, not stated per command


_ESPEC_ERRORS = "ChamberConnectLibrary especinteract.py ERROR_DESCIPTIONS"
REFUSALS: tuple[Refusal, ...] = (
    Refusal("espec-p300", r"(MON |TEMP |SET )?PTC\?|CONSTANT SET\?, ?PTC|SYSTEM SET\?, ?.*|PRGM DATA PTC\?, ?.*"
            r"|TEMP PTC, ?.*|PTC, ?.*", "NA:CONT NOT READY-1", "no product temperature control (PTCON)",
            f"{_ESPEC_ERRORS}: 'CONT NOT READY-1': 'Chamber does not support PTCON/Humidity'; espec.py "
            "process_controller takes a refused TEMP PTC? as a chamber without PTCON",
            ("MON PTC?", "TEMP PTC?", "SET PTC?", "PTC?", "CONSTANT SET?,PTC", "SYSTEM SET?,PTCOPT",
             "PRGM DATA PTC?,RAM:1", "PRGM DATA PTC?,RAM:1,DETAIL", "PRGM DATA PTC?,RAM:1,STEP1",
             "TEMP PTC, PTCON, DEVP100.0, DEVN0.0", "PTC,100.0,-40.0,1.0,0.0,1.0,0.0,0.0"), inferred=True),
    Refusal("espec-p300", r"PRGM (MON|SET)\?|RUN PRGM( MON)?\?|PRGM, ?(PAUSE|CONTINUE|ADVANCE|END.*)",
            "NA:CONT NOT READY-2", "no program running",
            f"{_ESPEC_ERRORS}: 'CONT NOT READY-2': 'Chamber is not running a program'",
            ("PRGM MON?", "PRGM SET?", "RUN PRGM MON?", "RUN PRGM?", "PRGM,PAUSE", "PRGM,CONTINUE", "PRGM,ADVANCE",
             "PRGM,END,STANDBY"), inferred=True),
    Refusal("espec-p300", r"PRGM DATA\?, ?R[AO]M:\d+.*|PRGM USE\?, ?R[AO]M:\d+|PRGM ERASE, ?R[AO]M:\d+"
            r"|PRGM, ?RUN, ?R[AO]M:\d+.*|MODE, ?RUN\d+", "NA:DATA NOT READY", "no program stored",
            f"{_ESPEC_ERRORS}: 'DATA NOT READY': 'Specified program does not exist'",
            ("PRGM DATA?,RAM:1", "PRGM DATA?,RAM:1,DETAIL", "PRGM DATA?,RAM:1,STEP1", "PRGM USE?,RAM:40",
             "PRGM ERASE,RAM:1", "PRGM,RUN,RAM:1,STEP1", "MODE,RUN1"), inferred=True),
    Refusal("espec-p300", r"TIMER LIST\?, ?[0-2]|TIMER ERASE, ?NO[0-2]|TIMER, ?(ON|OFF), ?[0-2]", "NA:DATA NOT READY",
            "no timer set", "syndesi-project/drivers Python/syndesi_drivers/instruments/ovens/espec/sh242.py "
            "SH242Exception: 'DATA NOT READY': 'Specified data does not exist'",
            ("TIMER LIST?,0", "TIMER LIST?,1", "TIMER LIST?,2", "TIMER ERASE,NO1", "TIMER,ON,2", "TIMER,OFF,0"),
            inferred=True),
    Refusal("espec-p300", r"MODE, ?RUN|IPSET,,,", "NA:PARA ERR", "a parameter missing",
            f"{_ESPEC_ERRORS}: 'PARA ERR': 'Parameter missing or unrecognizable'", ("MODE, RUN", "IPSET,,,"),
            inferred=True),
    Refusal("espec-p300", r"HUMI, ?.*[SHL] ?-\d.*", "NA:DATA OUT OF RANGE", "a humidity below 0 % RH",
            f"{_ESPEC_ERRORS}: 'DATA OUT OF RANGE': 'Data not with in valid range' (0-100 % RH)",
            ("HUMI, L-40.0", "HUMI, S25.0 H100.0 L-40.0", "HUMI, S-5"), inferred=True),
    Refusal("espec-p300", r"\*[A-Z]{3}\??", "NA:CMD ERR", "any state: the P300 command set has no IEEE 488.2 "
            "common commands (py-lab-hal's Instrument base class sends them to every instrument)",
            f"{_ESPEC_ERRORS}: 'CMD ERR': 'Unrocognized command'; syndesi-drivers espec_sh242.py SH242Exception: "
            "'Main command error, the command has probably been mistyped'",
            ("*IDN?", "*RST", "*CLS", "*ESR?", "*TST?", "*OPC?"), inferred=True),
    Refusal("espec-p300", r"PRGM DATA WRITE, ?PGM\d+, ?EDIT (END|CANCEL)", "NA:PRGM WRITE ERR-3",
            "no program being edited", f"{_ESPEC_ERRORS}: 'PRGM WRITE ERR-3': 'Edit request not allowed not in "
            "edit mode'", ("PRGM DATA WRITE,PGM1,EDIT END", "PRGM DATA WRITE,PGM1,EDIT CANCEL"), inferred=True),
    Refusal("espec-p300", r"PRGM DATA WRITE, ?PGM\d+, ?(STEP|COUNT|NAME|END|[HL](TEMP|HUMI)|PRE ).*",
            "NA:PRGM WRITE ERR-2", "no program being edited", f"{_ESPEC_ERRORS}: 'PRGM WRITE ERR-2': 'Not in program "
            "edit/overwrite mode'", ("PRGM DATA WRITE,PGM1,STEP1", "PRGM DATA WRITE,PGM1,STEP1,TEMP25.0,TIME1:0",
                                     "PRGM DATA WRITE,PGM1,NAME,SAMPLE"), inferred=True),
)
