"""One public client, unchanged, driven method by method for tests/protocols/client_sweep.py, in a process of
its own (so that a client blocked on a silent controller can be ended by its deadline, and so that a client
written for Python 2.7, as ESPEC's ChamberConnectLibrary is, runs on the interpreter it was written for).

This file is Python 2.7 and Python 3 at once: no f-strings, no annotations, no keyword-only arguments.

The parent writes one JSON line on stdin (what to construct, and how: `factory`), then `call <k>` lines;
this process answers with `@@SWEEP <json>` lines on its own copy of stdout (the client's prints go to
stderr): the construction, the plan (every public member of the client's class, enumerated with inspect,
each with the calls generated for it from its signature and docstring), then one result per call.

Arguments are generated, not listed by hand: a parameter's default; an Enum annotation (one call per
member); a type named in the annotation or in the docstring's line for that parameter (`N (int): ...`,
`mode: string, "STANDBY" or "OFF"`, `time: {"hour":int,"minute":int}`), with one call per quoted choice,
per flipped boolean default and per documented keyword of **kwargs. Only a parameter that cannot be derived
so takes its value from the parent's table, keyed by the parameter's name (`$not_callable` there: the method
is listed, not called, with that reason).

Transport: only its construction is touched, where a client hard-codes it (see FACTORIES).
"""

import datetime
import importlib
import inspect
import json
import os
import re
import sys
import traceback

TEXT = type(b"".decode("ascii"))  # unicode on Python 2, str on Python 3
STRINGS = (str, TEXT)
try:
    import enum
except ImportError:  # Python 2.7 without the enum34 backport
    enum = None

#: Names that end a client's session: called after every other member.
SESSION_ENDERS = ("close", "disconnect", "terminate")
#: At most this many calls of one member (variants of its arguments).
MAX_CALLS = 8
MAX_CHOICES = 4

_PROTOCOL = None


def send(message):
    _PROTOCOL.write("@@SWEEP " + json.dumps(message) + "\n")
    _PROTOCOL.flush()


def short_repr(value, limit=300):
    try:
        text = repr(value)
    except Exception as exc:  # noqa: BLE001 - a client's own repr may fail
        text = "<unrepresentable: " + type(exc).__name__ + ">"
    return text if len(text) <= limit else text[:limit] + "..."


# ---------------------------------------------------------------------- the client's construction
def substitute(value, spec):
    """The parent's placeholders: `$host`, `$port` in strings, `{"$pyvisa_rm": library}`."""
    if isinstance(value, dict):
        if "$pyvisa_rm" in value:
            import pyvisa

            return pyvisa.ResourceManager(value["$pyvisa_rm"])
        return dict((key, substitute(item, spec)) for key, item in value.items())
    if isinstance(value, list):
        return [substitute(item, spec) for item in value]
    if isinstance(value, STRINGS):
        text = value.replace("$host", spec["host"]).replace("$port", str(spec["port"]))
        return int(text) if value == "$port" else text
    return value


def factory_plain(spec):
    """The class constructed with the parent's keyword arguments (the endpoint the client's own way)."""
    cls = getattr(importlib.import_module(spec["module"]), spec["class"])
    return cls(**substitute(spec.get("kwargs", {}), spec)), cls, None


def factory_basil(spec):
    """basil: a Dut of one Socket transfer layer and the chamber's hardware-layer driver."""
    from basil.dut import Dut

    conf = {"transfer_layer": [{"name": "Socket", "type": "Socket",
                                "init": substitute(spec["transfer_init"], spec)}],
            "hw_drivers": [{"name": "chamber", "type": spec["driver"], "interface": "Socket",
                            "init": spec.get("driver_init", {})}]}
    dut = Dut(conf)
    dut.init()
    obj = dut["chamber"]
    return obj, type(obj), None


def factory_chamberconnect(spec):
    """ESPEC's ChamberConnectLibrary. Its TCP transports take no port from the controller classes:
    EspecTCP (especinteract.py) connects to 10001 and ModbusTCP (modbus.py) to 502, so the name each
    controller module imported is replaced by the same class with the port given; nothing else is touched.
    A ControllerInterface class is connected once (connect()) and again whenever a member left it
    unconnected (close(), init_common()), as a program using it would."""
    module = importlib.import_module(spec["module"])
    port = int(spec["port"])
    transport = spec["transport"]  # the name the module imported: EspecTCP or ModbusTCP
    original = getattr(importlib.import_module(spec["transport_module"]), transport)

    def with_port(*args, **kwargs):
        kwargs["port"] = port
        return original(*args, **kwargs)

    setattr(importlib.import_module(spec["patch_module"]), transport, with_port)
    cls = getattr(module, spec["class"])
    obj = cls(**substitute(spec.get("kwargs", {}), spec))
    hook = None
    if hasattr(obj, "connect") and hasattr(obj, "client"):
        obj.connect()

        def hook():
            if getattr(obj, "client", None) is None:
                obj.connect()
    return obj, cls, hook


def factory_syndesi(spec):
    """syndesi's drivers: the driver class given the adapter a syndesi user builds (syndesi.adapters.IP), with
    the endpoint's address and port (SH242 sets its default port, 57732, only where none is given)."""
    from syndesi.adapters import IP

    adapter = IP(**substitute(spec["adapter"], spec))
    cls = getattr(importlib.import_module(spec["module"]), spec["class"])
    return cls(adapter), cls, None


def factory_pylabhal(spec):
    """py-lab-hal: its builder, as its own builder.py's example uses it: a ConnectConfig naming the socket
    interface, the endpoint and the terminators, the InstrumentConfig's defaults, then build_instrument."""
    from py_lab_hal import builder
    from py_lab_hal.cominterface import cominterface

    builder_ = builder.PyLabHALBuilder()
    builder_.connection_config = cominterface.ConnectConfig(
        interface_type="socket",
        network=cominterface.NetworkConfig(host=spec["host"], port=int(spec["port"])),
        terminator=cominterface.TerminatorConfig(**spec.get("terminator", {})),
        timeout=cominterface.TimeoutConfig(**spec.get("timeout", {})))
    enum_name, member = spec["model"].split(".")  # e.g. TempChamber.PU3J: the builder's own enum of models
    obj = builder_.build_instrument(getattr(getattr(builder, enum_name), member))
    return obj, type(obj), None


FACTORIES = {"plain": factory_plain, "basil": factory_basil, "chamberconnect": factory_chamberconnect,
             "syndesi": factory_syndesi, "pylabhal": factory_pylabhal}


# ---------------------------------------------------------------------- enumeration
def defining_class(cls, name):
    for klass in inspect.getmro(cls):
        if name in vars(klass):
            return klass, vars(klass)[name]
    return None, None


def unwrap(function):
    """The function a decorator wraps (functools.wraps' __wrapped__, or a closure's only function when the
    wrapper takes (*args, **kwargs) as ChamberConnectLibrary's `exclusive` does)."""
    seen = 0
    while seen < 5:
        seen += 1
        inner = getattr(function, "__wrapped__", None)
        if inner is None and getattr(function, "__closure__", None):
            spec = argspec(function)
            if spec["varargs"] and spec["varkw"] and len(spec["args"]) <= 1:
                cells = []
                for cell in function.__closure__:
                    try:
                        contents = cell.cell_contents
                    except ValueError:
                        continue
                    if inspect.isfunction(contents):
                        cells.append(contents)
                inner = cells[0] if len(cells) == 1 else None
        if inner is None:
            return function
        function = inner
    return function


def argspec(function):
    if hasattr(inspect, "getfullargspec"):
        spec = inspect.getfullargspec(function)
        return {"args": list(spec.args), "varargs": spec.varargs, "varkw": spec.varkw,
                "defaults": list(spec.defaults or ()), "kwonly": list(spec.kwonlyargs or ()),
                "kwonlydefaults": dict(spec.kwonlydefaults or {}), "annotations": dict(spec.annotations or {})}
    spec = inspect.getargspec(function)
    return {"args": list(spec.args), "varargs": spec.varargs, "varkw": spec.keywords,
            "defaults": list(spec.defaults or ()), "kwonly": [], "kwonlydefaults": {}, "annotations": {}}


def docstring(cls, name, function):
    """The member's docstring, or the first a base class gives the same name (an abstract method's)."""
    if function is not None and getattr(function, "__doc__", None):
        return function.__doc__
    for klass in inspect.getmro(cls):
        raw = vars(klass).get(name)
        if raw is None:
            continue
        target = raw.fget if isinstance(raw, property) else getattr(raw, "__func__", raw)
        target = unwrap(target) if inspect.isfunction(target) else target
        if getattr(target, "__doc__", None):
            return target.__doc__
    return ""


def members(cls, own_prefix):
    """Every public member of the class: (name, kind, defined in, raw attribute); kind is `method`,
    `property`, `inherited` (defined outside the client's own package: a framework primitive) or `other`."""
    found = []
    for name in sorted(dir(cls)):
        if name.startswith("_"):
            continue
        klass, raw = defining_class(cls, name)
        if klass is None:
            continue
        where = klass.__module__ + "." + klass.__name__
        if inspect.isclass(raw):
            kind = "class"
        elif isinstance(raw, property):
            kind = "property"
        elif isinstance(raw, (staticmethod, classmethod)) or inspect.isfunction(raw):
            kind = "method"
        else:
            kind = "attribute"
        if kind in ("method", "property") and not klass.__module__.startswith(own_prefix):
            kind = "inherited"
        found.append((name, kind, where, raw))
    enders = [m for m in found if m[0] in SESSION_ENDERS]
    return [m for m in found if m[0] not in SESSION_ENDERS] + enders


# ---------------------------------------------------------------------- arguments
_SAMPLE_TYPES = (("datetime", "datetime"), ("dict", "dict"), ("bool", "bool"), ("float", "float"),
                 ("double", "float"), ("int", "int"), ("str", "str"), ("list", "list"))


def doc_line(doc, name):
    """What the docstring says of a parameter: `name (type): text`, `name: type, text`, `` `name`: text``."""
    pattern = re.compile(r"^(\s*)`?" + re.escape(name) + r"`?\s*(\(([^)]*)\))?\s*:\s*(.*)$")
    lines = (doc or "").splitlines()
    for index, line in enumerate(lines):
        match = pattern.match(line)
        if match:
            text = ((match.group(3) or "") + " " + match.group(4)).strip()
            indent = len(match.group(1))
            for more in lines[index + 1:]:  # its continuation: the lines indented under it
                if not more.strip() or len(more) - len(more.lstrip()) <= indent:
                    break
                text += " " + more.strip()
            return text
    return None


def number_for(name, kind):
    """A plausible number of the kind named, from the parameter's name (a limit's end, a count, a level)."""
    lowered = name.lower()
    for word, value in (("year", 2025), ("month", 1), ("day", 15), ("hour", 12), ("minute", 30), ("second", 0)):
        if lowered == word:
            return value
    if kind == "int":
        return 1
    if any(word in lowered for word in ("max", "high", "upper", "positive")):
        return 100.0
    if any(word in lowered for word in ("min", "low", "lower", "negative")):
        return -40.0 if "temp" in lowered or lowered in ("min", "minimum", "low", "lower") else 0.0
    if "humi" in lowered:
        return 50.0
    return 25.0


def literal(text, hint=""):
    """A documented structure (`{"hour":int,"minute":int}`, `[boolean]`) with a sample of each type."""
    text = text.strip().lstrip("(").strip()
    if not text or text[0] not in "{[":
        return None
    depth, end = 0, None
    for index, character in enumerate(text):
        depth += {"{": 1, "[": 1, "}": -1, "]": -1}.get(character, 0)
        if depth == 0:
            end = index + 1
            break
    if end is None:
        return None
    body = text[:end]
    if body.startswith("[") and re.match(r"^\[\s*(\w+)\s*\]$", body):
        inner = re.match(r"^\[\s*(\w+)\s*\]$", body).group(1)
        choice = re.search(r'i\.e\.\s*"([^"]+)"', text)
        if choice and inner.startswith("str"):
            return [choice.group(1)]
        sample = from_type(inner, hint)
        return None if sample is None else [sample]
    keyed = re.sub(r'"(\w+)"\s*:\s*(\w+)', lambda m: '"' + m.group(1) + '": ' + json.dumps(
        from_type(m.group(2), m.group(1), inside=True)), body)
    keyed = re.sub(r"\[\s*(int|float|boolean|bool|string|str)\s*\]",
                   lambda m: json.dumps([from_type(m.group(1), inside=True)]), keyed)
    try:
        return json.loads(keyed)
    except ValueError:
        return None


def from_type(text, name="", inside=False):
    """A sample of the type a docstring or annotation names; None: not a type this knows."""
    lowered = (text or "").lower().strip()
    if lowered.startswith(("{", "[")):
        return literal(text, name)
    for word, kind in _SAMPLE_TYPES:
        if re.match(r"^" + word, lowered):
            if kind == "datetime":
                return {"$datetime": "2025-01-15T12:30:00"}
            if kind == "bool":
                return True
            if kind in ("int", "float"):
                return number_for(name, kind)
            if kind == "str" and inside:
                return ""  # a text inside a documented structure: present, empty
            return None  # a text, a dict or a list whose content is not documented
    return None


def choices(text):
    """Quoted alternatives a docstring offers (`"quick" or "start" or "stop"`)."""
    found = re.findall(r"[\"']([A-Za-z][A-Za-z0-9 _/-]*)[\"']", text or "")
    seen = []
    for item in found:
        if item not in seen:
            seen.append(item)
    return seen


def range_of(text):
    """An integer range a docstring gives (`int,2007-2049`, `1-12`): its first value."""
    match = re.search(r"(-?\d+)\s*-\s*(-?\d+)", text or "")
    return int(match.group(1)) if match else None


def values_for(name, annotation, doc_text, table):
    """The values to try for a parameter: (list of values, how derived) or (None, reason)."""
    if annotation is not None and enum is not None:
        target = annotation
        args = getattr(annotation, "__args__", None)
        if args:  # Optional[X]
            real = [a for a in args if a is not type(None)]
            target = real[0] if len(real) == 1 else annotation
        if inspect.isclass(target) and issubclass(target, enum.Enum):
            return [{"$enum": target.__module__ + ":" + target.__name__ + ":" + m.name} for m in target], \
                "annotation " + target.__name__
        for kind, builtin in (("bool", bool), ("int", int), ("float", float)):
            if target is builtin:
                return [from_type(kind, name)], "annotation " + kind
    if doc_text is not None:
        structure = literal(doc_text, name)
        if structure is not None:
            return [structure], "docstring structure"
        options = choices(doc_text)
        lowered = doc_text.lower()
        if options and re.search(r"\b(str|string)\b|\bor\b|\boptions\b|\bmode\b", lowered):
            return options[:MAX_CHOICES], "docstring choices"
        first = re.split(r"[ ,:)]", lowered.strip("( "), maxsplit=1)[0]
        if first.startswith("int"):
            low = range_of(doc_text)
            return [low if low is not None else 1], "docstring int"
        sample = from_type(first, name)
        if sample is not None:
            return [sample], "docstring " + first
    if name in table:
        return [table[name]], "table"
    return None, "not derivable from the signature or docstring, and not in the client's table"


def documented_keywords(doc):
    """**kwargs keys a docstring documents: lines `key: type` / `key (type): ...` after the first line."""
    keys = []
    for line in (doc or "").splitlines()[1:]:
        match = re.match(r"^\s*`?(\w+)`?\s*(\([^)]*\))?\s*:\s*(\S.*)$", line)
        if match and match.group(1).lower() not in ("args", "kwargs", "returns", "return", "raises", "params",
                                                      "parameters", "example", "note"):
            keys.append(match.group(1))
    return keys


def plan_calls(cls, name, kind, raw, table):
    """The calls of one member: [{"args": {...}, "text": ..., "derived": ...}] or a reason it is not called."""
    if kind == "property":
        calls = [{"op": "get", "kwargs": {}, "text": name, "derived": "property read"}]
        if raw.fset is not None:
            doc = raw.__doc__ or ""
            sample = from_type(first_type_word(doc), name)
            if sample is None:
                values, how = values_for("value", None, None, table)
                sample = values[0] if values else None
            else:
                how = "docstring"
            if sample is None:
                return calls, "setter: " + how
            calls.append({"op": "set", "value": sample, "text": name + " = " + short_repr(decode(sample)),
                          "derived": how})
        return calls, None
    function = raw.__func__ if isinstance(raw, (staticmethod, classmethod)) else raw
    function = unwrap(function)
    spec = argspec(function)
    doc = docstring(cls, name, function)
    positional = spec["args"][1:] if not isinstance(raw, staticmethod) else spec["args"]
    defaults = dict(zip(positional[len(positional) - len(spec["defaults"]):], spec["defaults"])) \
        if spec["defaults"] else {}
    defaults.update(spec["kwonlydefaults"])
    names = positional + spec["kwonly"]
    base, how, variants = {}, [], []
    for parameter in names:
        annotation = spec["annotations"].get(parameter)
        if parameter in defaults:
            default = defaults[parameter]
            base[parameter] = default
            if isinstance(default, bool):
                variants.append((parameter, [not default]))
            continue
        values, derived = values_for(parameter, annotation, doc_line(doc, parameter), table)
        if values is None:
            return [], parameter + ": " + derived
        if len(values) == 1 and isinstance(values[0], dict) and "$not_callable" in values[0]:
            return [], values[0]["$not_callable"]
        base[parameter] = values[0]
        how.append(parameter + " from " + derived)
        if len(values) > 1:
            variants.append((parameter, values[1:]))
    calls = [dict(base)]
    for parameter, others in variants:
        for value in others:
            call = dict(base)
            call[parameter] = value
            calls.append(call)
    if spec["varkw"]:
        keys = [k for k in documented_keywords(doc) if k not in names]
        extra = {}
        seen = doc_line(doc, spec["varkw"]) or ""
        referred = re.search(r"\bsee (\w+)", seen)
        if referred and hasattr(cls, referred.group(1)):  # "see read_prgm_data_step for parameters": its returns
            returns = returned_structure(docstring(cls, referred.group(1), None))
            if isinstance(returns, dict):
                keys = [k for k in keys if k != spec["varkw"]]
                extra.update(returns)
                how.append("**" + spec["varkw"] + " from " + referred.group(1) + "'s documented return")
        for key in [k for k in keys if k not in extra]:
            values, derived = values_for(key, None, doc_line(doc, key), table)
            if values is not None and not (isinstance(values[0], dict) and "$not_callable" in values[0]):
                extra[key] = values[0]
        if extra:
            how.append("**kwargs from docstring: " + ", ".join(sorted(extra)))
            together = dict(base)
            together.update(extra)
            calls = [together] + ([dict(base, **{k: v}) for k, v in sorted(extra.items())] if len(extra) > 1 else [])
    planned = []
    for call in calls[:MAX_CALLS]:
        text = name + "(" + ", ".join(k + "=" + short_repr(decode(v), 80) for k, v in sorted(call.items())) + ")"
        planned.append({"op": "call", "kwargs": call, "text": text, "derived": "; ".join(how) or "no arguments"})
    return planned, None


def returned_structure(doc):
    """The structure a docstring says its method returns (`returns: {...}`), with samples."""
    match = re.search(r"returns?:\s*(\{.*)", doc or "", re.IGNORECASE | re.DOTALL)
    return literal(" ".join(match.group(1).split())) if match else None


def first_type_word(doc):
    match = re.search(r"\((float|int|bool|str)\)", doc or "")
    return match.group(1) if match else ""


def decode(value):
    """The placeholders of a generated value made real (a datetime, an Enum member)."""
    if isinstance(value, dict):
        if "$datetime" in value:
            return datetime.datetime.strptime(value["$datetime"], "%Y-%m-%dT%H:%M:%S")
        if "$enum" in value:
            module, cls, member = value["$enum"].split(":")
            return getattr(getattr(importlib.import_module(module), cls), member)
        return dict((k, decode(v)) for k, v in value.items())
    if isinstance(value, list):
        return [decode(v) for v in value]
    return value


# ---------------------------------------------------------------------- calling
def client_frames(tb, own_prefix):
    """Where in the client's own source an exception passed: [path:line function: source], innermost last."""
    frames = []
    for filename, line, function, source in traceback.extract_tb(tb):
        parts = filename.replace("\\", "/").split("/")
        top = own_prefix.split(".")[0]
        if top in parts:
            where = "/".join(parts[parts.index(top):])
            frames.append(where + ":" + str(line) + " " + function + ": " + (source or "").strip())
    return frames[-4:]


def run_call(state, name, call, own_prefix):
    """One call; a member that left the object unusable (a reset of its settings: ChamberConnectLibrary's
    init_common()) is followed by a new object, built as the first was, before the next call."""
    try:
        if state["hook"] is not None:
            try:
                state["hook"]()
            except Exception:  # noqa: BLE001 - the object cannot reconnect: built again
                state["obj"], _, state["hook"] = FACTORIES[state["spec"]["factory"]](state["spec"])
        obj = state["obj"]
        if call["op"] == "get":
            value = getattr(obj, name)
        elif call["op"] == "set":
            setattr(obj, name, decode(call["value"]))
            value = None
        else:
            value = getattr(obj, name)(**decode(call["kwargs"]))
        return {"outcome": "returned", "value": short_repr(value)}
    except BaseException as exc:  # noqa: BLE001 - whatever the client raises is what is recorded
        return {"outcome": "raised", "error": type(exc).__name__ + ": " + short_repr(str(exc), 400).strip("'\""),
                "frames": client_frames(sys.exc_info()[2], own_prefix)}


def main():
    global _PROTOCOL
    _PROTOCOL = os.fdopen(os.dup(1), "w")
    os.dup2(2, 1)  # whatever the client prints goes to stderr, not into the protocol
    spec = json.loads(sys.stdin.readline())
    own_prefix = spec["own_prefix"]
    try:
        obj, cls, hook = FACTORIES[spec["factory"]](spec)
    except BaseException as exc:  # noqa: BLE001 - reported, then this process ends
        send({"event": "constructed", "ok": False, "error": type(exc).__name__ + ": " + short_repr(str(exc), 400),
              "frames": client_frames(sys.exc_info()[2], own_prefix)})
        return
    state = {"obj": obj, "hook": hook, "spec": spec}
    send({"event": "constructed", "ok": True, "class": cls.__module__ + "." + cls.__name__,
          "python": sys.version.split()[0]})
    plan, listed = [], []
    for name, kind, where, raw in members(cls, own_prefix):
        entry = {"name": name, "kind": kind, "defined_in": where, "calls": []}
        if kind in ("method", "property"):
            try:
                calls, reason = plan_calls(cls, name, kind, raw, spec.get("table", {}))
            except Exception as exc:  # noqa: BLE001 - a member whose signature cannot be read is listed so
                calls, reason = [], "its arguments could not be generated: " + type(exc).__name__ + ": " + str(exc)
            for call in calls:
                entry["calls"].append(len(plan))
                plan.append(dict(call, member=name))
            entry["not_called"] = reason
        elif kind == "inherited":
            entry["not_called"] = "inherited from " + where + ": a framework primitive that sends what its caller " \
                                  "gives it (the client's own members are its requests)"
        listed.append(entry)
    send({"event": "plan", "members": listed,
          "calls": [{"member": c["member"], "text": c["text"], "derived": c["derived"]} for c in plan]})
    while True:
        line = sys.stdin.readline()
        if not line or line.strip() == "exit":
            return
        index = int(line.split()[1])
        call = plan[index]
        result = run_call(state, call["member"], call, own_prefix)
        result.update({"event": "result", "index": index})
        send(result)


if __name__ == "__main__":
    main()
