"""Every service of the cell and its one client input topic with random, extreme and non-finite
values, from Eclipse Cyclone DDS (issue 26).

The requests are built from the interface files in msgs/srv (so a service added later is fuzzed
too): strings empty, huge, path-like, numeric-looking; floats 0, ±1e308, ±inf, NaN, denormals;
integers at their extremes; arrays of random length. Requests go one at a time, each must get a
reply, and a refusal must say why (for set_parameter it names the parameter, for set_overrides
the override). Meanwhile `axes` and `spindle` are watched: no commanded position leaves the
rated travel and the spindle never turns faster than its rating. Then the cell still answers.

Exit 0 when every check holds; otherwise print what failed and exit 1.
"""

import math
import os
import pathlib
import random
import re
import time

from cyclonedds.pub import DataWriter
from cyclonedds.topic import Topic

from cyclone_peer import SERVICE, Session, fields_of, run

# sim_lathe.yaml's ratings: X (diameter) -2..300, Z -400..150, spindle 3000 rpm.
TRAVEL = {"X": (-2.0, 300.0), "Z": (-400.0, 150.0)}
SPINDLE_MAX = 3000.0
ROUNDS = 4
INTS = {"uint8": (0, 255), "int8": (-128, 127), "uint16": (0, 65535), "int16": (-32768, 32767),
        "uint32": (0, 2**32 - 1), "int32": (-2**31, 2**31 - 1), "uint64": (0, 2**64 - 1),
        "int64": (-2**63, 2**63 - 1)}
FLOATS = [0.0, -0.0, 1e308, -1e308, math.inf, -math.inf, math.nan, 5e-324, 1.0, -1.0, 123.456, 1e9]
STRINGS = ["", "O0001", "part.nc", "../../etc/passwd", "/etc/passwd", "1e308", "nan", "-inf", ".inf",
           "machine.axes.X.max", "machine.axes.X.max_velocity", "machine.axes.Z.max_acceleration",
           "servo.lookahead", "sim.spindle_acceleration", "limits.spindle_max_rpm", "G00 X2000 Z900",
           "G00 X1e308", "S99999 M03", "M98 P1 L99999999", "x=1e308", "1 2 3 4 5 6", "ä€😀", "\t\n",
           "A" * 70000, "G01 X10 F0\n" * 50]


def rust_quoted(text):
    """`text` as Rust's `{:?}` prints a string, without its quotes: backslash, double quote and
    control characters escaped, the rest as it is."""
    named = {"\t": "\\t", "\r": "\\r", "\n": "\\n", "\\": "\\\\", '"': '\\"', "\0": "\\0"}
    return "".join(named.get(c) or (f"\\u{{{ord(c):x}}}" if ord(c) < 0x20 or 0x7F <= ord(c) < 0xA0 else c)
                   for c in text)


def names(name, message):
    """Whether a refusal names `name`: as given, or quoted as the cell quotes names (so that a
    name with quotes or line breaks reads unambiguously)."""
    return name in message or rust_quoted(name) in message


def snake(name):
    return re.sub(r"(?<!^)([A-Z])", r"_\1", name).lower()


def value_for(ty, ifc, rnd):
    if ty.endswith("[]"):
        return [value_for(ty[:-2], ifc, rnd) for _ in range(rnd.randint(0, 4))]
    if ty == "bool":
        return rnd.random() < 0.5
    if ty in INTS:
        lo, hi = INTS[ty]
        return rnd.choice([lo, hi, 0, 1, rnd.randint(lo, hi)])
    if ty in ("float64", "float32"):
        v = rnd.choice(FLOATS + [rnd.uniform(-1e6, 1e6)])
        return v
    if ty == "string":
        return rnd.choice(STRINGS + ["".join(chr(rnd.randint(32, 126)) for _ in range(rnd.randint(1, 40)))])
    pkg, name = ty.split("/") if "/" in ty else ("cnc_msgs", ty)
    cls = ifc.msg(pkg, name)
    text = (ifc.root / "msg" / f"{name}.msg").read_text()
    return cls(**{f: value_for(t, ifc, rnd) for f, t in fields_of(text)})


def main():
    session = Session({"axes": "AxisState", "spindle": "SpindleState", "machine_state": "MachineState"})
    peer, check, wait = session.peer, session.check, session.wait
    seed = int(os.environ.get("CNC_FUZZ_SEED") or time.time())  # the seed printed repeats a run
    print(f"seed {seed}", flush=True)
    rnd = random.Random(seed)
    out_of_limits = []

    def watch(topic, sample):
        if topic == "axes":
            for a in sample.axes:
                lo, hi = TRAVEL.get(a.name, (-math.inf, math.inf))
                if not (lo - 1e-6 <= a.commanded_position <= hi + 1e-6):
                    out_of_limits.append(f"{a.name} commanded {a.commanded_position}")
        elif topic == "spindle" and not abs(sample.actual_rpm) <= SPINDLE_MAX + 1.0:
            out_of_limits.append(f"spindle {sample.actual_rpm} rpm")

    session.on_sample = watch
    check(wait(lambda: peer.latest["machine_state"] is not None, 30), "machine state arrives")
    r = peer.call("load_program", "LoadProgram", name="part.nc",
                  text="G00 X60 Z5\nS800 M03\nG01 X50 F600\nZ-10\nG00 X60\nM05\nM30\n")
    check(r.accepted, f"a program to start: {r.message}")
    guard_text = "O0999\nG00 X100\nM30\n"
    r = peer.call("load_program", "LoadProgram", name="guard.nc", text=guard_text)
    check(r.accepted, f"a program no fuzzed name can reach: {r.message}")

    srv_dir = peer.ifc.root / "srv"
    services = sorted(p.stem for p in srv_dir.glob("*.srv"))
    calls = refused = 0
    silent = []
    unnamed = []
    reasons = {}  # service → the refusals' reasons, shortened, for the log
    for round_ in range(ROUNDS):
        for srv in services:
            request_text = (srv_dir / f"{srv}.srv").read_text().split("\n---")[0]
            fields = {f: value_for(t, peer.ifc, rnd) for f, t in fields_of(request_text)}
            if srv == "SetParameter":
                # Parameters are written in MDI mode: there the value itself is checked.
                peer.call("set_mode", "SetMode", mode=1)
            try:
                reply = peer.call(snake(srv), srv, timeout=20.0, **fields)
            except TimeoutError as e:
                silent.append(f"{srv}: {e}")
                continue
            except Exception as e:  # a value Cyclone itself cannot encode (e.g. an int out of range)
                print(f"  {srv}: not sent: {e}", flush=True)
                continue
            calls += 1
            session.poll()
            if hasattr(reply, "accepted") and not reply.accepted:
                refused += 1
                msg = reply.message
                reasons.setdefault(srv, set()).add(re.sub(r"\s+", " ", msg)[:90])
                if not msg.strip():
                    unnamed.append(f"{srv} refused without a reason")
                elif srv == "SetParameter" and not names(fields["name"].strip(), msg) and "program runs" not in msg:
                    unnamed.append(f"set_parameter {fields['name']!r} = {fields['value']!r}: {msg[:120]}")
                elif srv == "SetOverrides" and "override" not in msg:
                    unnamed.append(f"set_overrides: {msg[:120]}")
        # The client input topic too (inputs are refused unless the client is allowed).
        w = DataWriter(peer.dp, Topic(peer.dp, f"rt/{peer.ns}/sim/input", peer.ifc.msg("cnc_msgs", "SimInput")),
                       qos=SERVICE)
        for _ in range(20):
            w.write(peer.ifc.msg("cnc_msgs", "SimInput")(input=rnd.randint(0, 255), value=rnd.random() < 0.5))
        session.wait(lambda: False, 0.5)

    print(f"{calls} calls, {refused} refused", flush=True)
    for srv, why in sorted(reasons.items()):
        print(f"  {srv}: " + " | ".join(sorted(why)), flush=True)
    check(not silent, f"every request was answered: {silent[:5]}")
    check(not unnamed, f"every refusal says why, naming the field: {unnamed[:5]}")
    check(not out_of_limits, f"nothing outside the ratings reached motion: {out_of_limits[:5]}")
    r = peer.call("list_programs", "ListPrograms", structure_needs_at_least_one_member=0)
    kept = dict(zip(r.names, r.sizes))
    check(r.accepted and kept.get("guard.nc") == len(guard_text),
          "the cell still answers, its program memory intact")
    return session.exit_code()


if __name__ == "__main__":
    run(main)
