"""A cell client on Eclipse Cyclone DDS (PyPI `cyclonedds`), a DDS implementation nobody here wrote.

Its types are built at run time from the interface files in msgs/ (nothing hand-copied), so a
field that differs between a .msg file and what the nodes send makes this fail. Services are
called with the rmw_cyclonedds mapping: a 16-byte header (client GUID half, sequence number)
before the request, echoed in the reply.

Exit 0 when every check holds; otherwise print what failed and exit 1.
"""

import argparse
import faulthandler
import os
import pathlib
import sys
import time
import traceback
import types as pytypes
from dataclasses import dataclass

import cyclonedds.idl.types as t
from cyclonedds.core import Policy, Qos
from cyclonedds.internal import InvalidSample
from cyclonedds.domain import DomainParticipant
from cyclonedds.idl import IdlStruct
from cyclonedds.pub import DataWriter
from cyclonedds.sub import DataReader
from cyclonedds.topic import Topic
from cyclonedds.util import duration

PRIMITIVES = {
    "bool": bool, "uint8": t.uint8, "int8": t.int8, "uint16": t.uint16, "int16": t.int16,
    "uint32": t.uint32, "int32": t.int32, "uint64": t.uint64, "int64": t.int64,
    "float32": t.float32, "float64": t.float64, "string": str,
}
BUILTIN = {("builtin_interfaces", "Time"): "int32 sec\nuint32 nanosec\n"}
CYCLONE_HEADER = [("guid", t.array[t.uint8, 8]), ("seq_high", t.int32), ("seq_low", t.uint32)]


def fields_of(text):
    out = []
    for raw in text.splitlines():
        line = raw.split("#")[0].strip()
        if not line:
            continue
        ty, rest = line.split(None, 1)
        if "=" in rest:
            continue  # constant
        out.append((rest.split()[0], ty))
    return out or [("structure_needs_at_least_one_member", "uint8")]


def struct(typename, fields):
    cls = pytypes.new_class(typename.split("::")[-1], (IdlStruct,), {"typename": typename},
                            lambda ns: ns.update({"__annotations__": dict(fields)}))
    return dataclass(cls)


class Interfaces:
    def __init__(self, root):
        self.root = root
        self.cache = {}

    def resolve(self, ty, pkg="cnc_msgs"):
        if ty.endswith("[]"):
            return t.sequence[self.resolve(ty[:-2], pkg)]
        if ty in PRIMITIVES:
            return PRIMITIVES[ty]
        p, n = ty.split("/") if "/" in ty else (pkg, ty)
        return self.msg(p, n)

    def msg(self, pkg, name):
        key = (pkg, name)
        if key not in self.cache:
            text = BUILTIN.get(key) or (self.root / "msg" / f"{name}.msg").read_text()
            fields = [(f, self.resolve(ty, pkg)) for f, ty in fields_of(text)]
            self.cache[key] = struct(f"{pkg}::msg::dds_::{name}_", fields)
        return self.cache[key]

    def srv(self, name):
        request, response = (self.root / "srv" / f"{name}.srv").read_text().split("\n---")
        req = [(f, self.resolve(ty)) for f, ty in fields_of(request)]
        resp = [(f, self.resolve(ty)) for f, ty in fields_of(response)]
        return (struct(f"cnc_msgs::srv::dds_::{name}_Request_", CYCLONE_HEADER + req),
                struct(f"cnc_msgs::srv::dds_::{name}_Response_", CYCLONE_HEADER + resp))


STATE = Qos(Policy.Reliability.Reliable(duration(milliseconds=100)), Policy.Durability.TransientLocal,
            Policy.History.KeepLast(1))
SERVICE = Qos(Policy.Reliability.Reliable(duration(milliseconds=100)), Policy.Durability.Volatile,
              Policy.History.KeepLast(10))


class Peer:
    def __init__(self, domain, ns, interfaces):
        self.dp = DomainParticipant(domain)
        self.ns = ns
        self.ifc = interfaces
        self.guid = list(os.urandom(8))
        self.seq = 0
        self.services = {}
        self.latest = {}

    def subscribe(self, topic, msg):
        reader = DataReader(self.dp, Topic(self.dp, f"rt/{self.ns}/{topic}", self.ifc.msg("cnc_msgs", msg)), qos=STATE)
        self.latest[topic] = None
        return reader

    def call(self, service, srv_type, timeout=20.0, **fields):
        if service not in self.services:
            req_t, resp_t = self.ifc.srv(srv_type)
            w = DataWriter(self.dp, Topic(self.dp, f"rq/{self.ns}/{service}Request", req_t), qos=SERVICE)
            r = DataReader(self.dp, Topic(self.dp, f"rr/{self.ns}/{service}Reply", resp_t), qos=SERVICE)
            self.services[service] = (req_t, w, r)
            # A request sent before the server's reader matched is lost, and a reply sent before
            # its writer matched our reader too: a repeated start would then be answered "a
            # program is running" although the first copy started it. Wait for both matches.
            until = time.time() + 10.0
            while time.time() < until and not (w.get_matched_subscriptions() and r.get_matched_publications()):
                time.sleep(0.02)
            time.sleep(0.3)  # the server's side of the same discovery
        req_t, w, r = self.services[service]
        sent = []
        deadline = time.time() + timeout
        last = 0.0
        while time.time() < deadline:
            # Requests written before discovery matched the server are lost: repeat, at most 3.
            if len(sent) < 3 and time.time() - last > 1.0:
                self.seq += 1
                sent.append(self.seq)
                w.write(req_t(guid=self.guid, seq_high=0, seq_low=self.seq, **fields))
                last = time.time()
            for reply in r.take(N=16):
                if isinstance(reply, InvalidSample):
                    continue
                if list(reply.guid) == self.guid and reply.seq_low in sent:
                    return reply
            time.sleep(0.005)
        raise TimeoutError(f"{service}: no reply with our header within {timeout} s")


GOOD = "O0042\nG00 X60 Z5\nS700 M03\nG01 X40 Z0 F600\nZ-15\nG02 X50 Z-20 R5\nM05\nM30\n"
BAD = "G00 X100 Z20\nG77 X5\nM30\n"


class Session:
    """A peer with its state readers and its checks: `check` prints ok/FAIL lines, `wait` polls
    the readers until a condition holds."""

    def __init__(self, topics):
        ap = argparse.ArgumentParser()
        ap.add_argument("--domain", type=int, required=True)
        ap.add_argument("--namespace", default="lathe1")
        ap.add_argument("--msgs", default=str(pathlib.Path(__file__).resolve().parents[2] / "msgs"))
        args = ap.parse_args()
        self.peer = Peer(args.domain, args.namespace, Interfaces(pathlib.Path(args.msgs)))
        self.readers = {topic: self.peer.subscribe(topic, msg) for topic, msg in topics.items()}
        self.failures = []
        self.on_sample = lambda topic, sample: None

    def check(self, ok, what):
        print(("ok   " if ok else "FAIL ") + what, flush=True)
        if not ok:
            self.failures.append(what)

    def poll(self):
        for topic, r in self.readers.items():
            for sample in r.take(N=64):
                # A writer gone (its node stopped) arrives as an InvalidSample: no state.
                if isinstance(sample, InvalidSample):
                    continue
                self.peer.latest[topic] = sample
                self.on_sample(topic, sample)

    def wait(self, cond, timeout):
        end = time.time() + timeout
        while time.time() < end:
            self.poll()
            if cond():
                return True
            time.sleep(0.01)
        return False

    def endpoints(self, seconds):
        """The machine's readers and writers (topic names under its namespace) that discovery
        shows this participant within `seconds`, polling the state readers meanwhile."""
        from cyclonedds.builtin import BuiltinDataReader, BuiltinTopicDcpsPublication, BuiltinTopicDcpsSubscription
        subs = BuiltinDataReader(self.peer.dp, BuiltinTopicDcpsSubscription)
        pubs = BuiltinDataReader(self.peer.dp, BuiltinTopicDcpsPublication)
        readers, writers = set(), set()
        end = time.time() + seconds
        while time.time() < end:
            self.poll()
            readers.update(s.topic_name for s in subs.take(N=256))
            writers.update(s.topic_name for s in pubs.take(N=256))
            time.sleep(0.05)
        mine = lambda names: sorted(n for n in names if f"/{self.peer.ns}/" in n)
        return mine(readers), mine(writers)

    def exit_code(self):
        print(f"{len(self.failures)} failed", flush=True)
        return 1 if self.failures else 0


def main():
    session = Session({"spindle": "SpindleState", "part_count": "PartCount",
                       "alarms": "ActiveAlarms", "machine_state": "MachineState"})
    peer, check, wait = session.peer, session.check, session.wait
    max_rpm = 0.0

    def track_rpm(topic, sample):
        nonlocal max_rpm
        if topic == "spindle" and abs(sample.commanded_rpm - 700.0) < 1e-9:
            max_rpm = max(max_rpm, sample.actual_rpm)

    session.on_sample = track_rpm

    check(wait(lambda: all(v is not None for v in peer.latest.values()), 30),
          "transient-local spindle, part_count, alarms and machine_state arrive on joining")
    start_count = peer.latest["part_count"].count if peer.latest["part_count"] else None
    check(peer.latest["alarms"] is not None and len(peer.latest["alarms"].alarms) == 0, "no active alarms at start")
    # A supervisor waits for the machine to leave WAIT (no axis position yet) before cycle start.
    check(wait(lambda: peer.latest["machine_state"].execution_name != "WAIT", 30),
          "machine_state leaves WAIT")

    r = peer.call("load_program", "LoadProgram", name="interop.nc", text=GOOD)
    check(r.accepted, f"LoadProgram (Cyclone mapping) accepted: {r.message}")
    r = peer.call("start_program", "StartProgram", name="interop.nc")
    check(r.accepted, f"StartProgram (Cyclone mapping) accepted: {r.message}")
    check(wait(lambda: peer.latest["part_count"].count == start_count + 1, 60),
          f"part_count {start_count} -> {peer.latest['part_count'].count}")
    # The part is counted at M30; the cycle is complete once motion has finished the program end.
    check(wait(lambda: peer.latest["machine_state"].execution_name == "PROGRAM_COMPLETED", 20),
          f"machine_state {peer.latest['machine_state'].execution_name} after the cycle")
    check(abs(max_rpm - 700.0) <= 14.0, f"spindle reached the programmed 700 rpm: max actual {max_rpm:.1f}")

    r = peer.call("start_program", "StartProgram", name="missing.nc")
    check(not r.accepted and "not found" in r.message, f"unknown program refused with its reason: {r.message}")

    peer.call("load_program", "LoadProgram", name="bad.nc", text=BAD)
    peer.call("start_program", "StartProgram", name="bad.nc")

    def bad_alarm():
        a = peer.latest["alarms"]
        return a is not None and any(x.number == 7 and x.line == 2 and x.program == "bad.nc" for x in a.alarms)

    check(wait(bad_alarm, 30), "alarm 7 on line 2 of bad.nc appears on alarms")
    r = peer.call("reset", "Reset", structure_needs_at_least_one_member=0)
    check(r.accepted, f"Reset (Cyclone mapping) accepted: {r.message}")
    check(wait(lambda: len(peer.latest["alarms"].alarms) == 0, 20), "alarms empty after reset")
    return session.exit_code()


def run(main):
    """Runs a peer's `main` and ends the process with its exit code at once, also after an
    exception: Cyclone's teardown at interpreter exit was seen to hang after a traceback, and
    the calling test then waited for the peer instead of failing. A peer that is still running
    after PEER_LIMIT_S seconds (a hang inside Cyclone's C code, where no Python signal handler
    runs) prints every thread's stack and exits, so the test fails with where it hung."""
    faulthandler.dump_traceback_later(float(os.environ.get("PEER_LIMIT_S", "300")), exit=True)
    try:
        code = main()
    except SystemExit as e:
        code = e.code if isinstance(e.code, int) else 1
    except BaseException:
        traceback.print_exc()
        code = 1
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(code if isinstance(code, int) else 0)


if __name__ == "__main__":
    run(main)
