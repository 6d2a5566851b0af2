"""A burst of service requests from Eclipse Cyclone DDS while the machine runs a program (issue 26).

2,000 requests, 500 each on start_program (refused: a program runs), list_programs,
get_parameters and set_overrides, written as fast as Cyclone takes them, with KeepAll writers
and readers (so nothing is lost on this side). Every request must get exactly one reply:
answered, or refused with a reason ("busy" when the bridge's queue for the service is full).
The counts are printed; the program still runs to its end with no alarm.

Exit 0 when every check holds; otherwise print what failed and exit 1.
"""

import time

from cyclonedds.core import Policy, Qos
from cyclonedds.internal import InvalidSample
from cyclonedds.pub import DataWriter
from cyclonedds.sub import DataReader
from cyclonedds.topic import Topic
from cyclonedds.util import duration

from cyclone_peer import Session, run

# About 15 s of cutting: the burst lands while it runs.
LONG = "O0077\nG00 X60 Z5\nS600 M03\nG01 X50 F600\nZ-60 F200\nX60\nG00 Z5\nM05\nM30\n"
KEEP_ALL = Qos(Policy.Reliability.Reliable(duration(seconds=1)), Policy.Durability.Volatile,
               Policy.History.KeepAll)
PER_SERVICE = 500
SERVICES = [
    ("start_program", "StartProgram", {"name": "long.nc"}),
    ("list_programs", "ListPrograms", {"structure_needs_at_least_one_member": 0}),
    ("get_parameters", "GetParameters", {"prefix": "servo."}),
    ("set_overrides", "SetOverrides", {"feed_percent": 100, "spindle_percent": 100, "rapid_percent": 100}),
]


def main():
    session = Session({"machine_state": "MachineState", "alarms": "ActiveAlarms"})
    peer, check, wait = session.peer, session.check, session.wait
    state = lambda: peer.latest["machine_state"]
    check(wait(lambda: state() is not None and state().execution_name != "WAIT", 30), "machine ready")
    r = peer.call("load_program", "LoadProgram", name="long.nc", text=LONG)
    check(r.accepted, f"program loaded: {r.message}")
    r = peer.call("start_program", "StartProgram", name="long.nc")
    check(r.accepted, f"program started: {r.message}")
    check(wait(lambda: state().execution_name == "ACTIVE", 20), "the program runs")

    ends = []
    for service, srv_type, fields in SERVICES:
        req_t, resp_t = peer.ifc.srv(srv_type)
        w = DataWriter(peer.dp, Topic(peer.dp, f"rq/{peer.ns}/{service}Request", req_t), qos=KEEP_ALL)
        r = DataReader(peer.dp, Topic(peer.dp, f"rr/{peer.ns}/{service}Reply", resp_t), qos=KEEP_ALL)
        ends.append((service, req_t, w, r, fields))
    time.sleep(2.0)  # discovery matches the new writers and readers with the bridge's

    sent = {}
    t0 = time.time()
    for i in range(PER_SERVICE):
        for service, req_t, w, _, fields in ends:
            peer.seq += 1
            sent[peer.seq] = service
            w.write(req_t(guid=peer.guid, seq_high=0, seq_low=peer.seq, **fields))
    burst = time.time() - t0
    print(f"burst: {len(sent)} requests written in {burst:.3f} s", flush=True)

    replies = {}
    duplicates = 0
    deadline = time.time() + 180
    while len(replies) < len(sent) and time.time() < deadline:
        for service, _, _, r, _ in ends:
            for reply in r.take(N=256):
                if isinstance(reply, InvalidSample) or list(reply.guid) != peer.guid or reply.seq_low not in sent:
                    continue
                if reply.seq_low in replies:
                    duplicates += 1
                replies[reply.seq_low] = (service, reply)
        time.sleep(0.01)
    took = time.time() - t0

    counts = {}
    for seq, (service, reply) in replies.items():
        if reply.accepted:
            kind = "answered"
        elif reply.message.startswith("busy"):
            kind = "refused busy"
        else:
            kind = "refused"
        counts[(service, kind)] = counts.get((service, kind), 0) + 1
    for (service, kind), n in sorted(counts.items()):
        print(f"  {service:16s} {kind:13s} {n}", flush=True)
    print(f"replies: {len(replies)} of {len(sent)} in {took:.1f} s, duplicates {duplicates}", flush=True)
    check(len(replies) == len(sent), f"every request got a reply ({len(replies)} of {len(sent)})")
    check(duplicates == 0, "no request was answered twice")
    wrong = [seq for seq, (service, _) in replies.items() if sent[seq] != service]
    check(not wrong, "each reply came on its own service")
    starts = [reply for _, (service, reply) in replies.items() if service == "start_program"]
    check(all(not s.accepted for s in starts), "no second start while the program runs")
    refusals = [reply.message for _, (_, reply) in replies.items() if not reply.accepted]
    check(all(m.strip() for m in refusals), "every refusal says why")
    reads = [reply for _, (service, reply) in replies.items()
             if service == "get_parameters" and reply.accepted]
    check(all(len(r.names) > 0 for r in reads), "every answered read carries its data")

    def active():
        a = peer.latest["alarms"]
        return "; ".join(f"{x.number} {x.source} line {x.line}: {x.text}"
                         for x in (a.alarms if a is not None else []))

    check(wait(lambda: state().execution_name == "PROGRAM_COMPLETED", 90),
          f"the program ran to its end: {state().execution_name} (alarms: {active() or 'none'})")
    check(not state().alarm_active, f"no alarm ({active() or 'none'})")
    return session.exit_code()


if __name__ == "__main__":
    run(main)
