"""A participant without credentials (Eclipse Cyclone DDS, no DDS Security, types from msgs/) on
the domain of a cell that runs DDS Security (issue 25, must-show 2). While the cell runs it
1. reads the machine's state topics for a while: it must hear nothing (the machine's writers do
   not match a participant that did not authenticate);
2. must not see the machine's endpoints in discovery (its axes writer, its start_program
   request reader);
3. presses cycle start on sim/input and calls load_program and start_program: no reply may
   come back (the machine's request readers do not match it either).
The calling test checks that the machine did not move. Exit 0 when every check holds.
"""

import time

from cyclonedds.core import Policy, Qos
from cyclonedds.pub import DataWriter
from cyclonedds.topic import Topic
from cyclonedds.util import duration

from cyclone_peer import Session, run

LISTEN_SECONDS = 8.0
PROGRAM = "O0666\nG00 X120 Z80\nS2000 M03\nG01 X0 F3000\nM30\n"


def main():
    session = Session({"machine_state": "MachineState", "axes": "AxisState", "spindle": "SpindleState",
                       "part_count": "PartCount", "alarms": "ActiveAlarms"})
    peer, check = session.peer, session.check
    ns = peer.ns

    # 1 and 2: listen, and look at discovery.
    readers, writers = session.endpoints(LISTEN_SECONDS)
    print("machine readers seen:", readers, flush=True)
    print("machine writers seen:", writers, flush=True)
    check(f"rt/{ns}/axes" not in writers and f"rq/{ns}/start_programRequest" not in readers,
          "discovery shows none of the machine's endpoints")
    heard = sorted(t for t, v in peer.latest.items() if v is not None)
    check(not heard, f"nothing heard on the machine's state topics in {LISTEN_SECONDS:.0f} s: {heard}")

    # 3: write what would move the machine.
    qos = Qos(Policy.Reliability.Reliable(duration(milliseconds=100)), Policy.Durability.Volatile,
              Policy.History.KeepLast(64))
    input_t = peer.ifc.msg("cnc_msgs", "SimInput")
    w_input = DataWriter(peer.dp, Topic(peer.dp, f"rt/{ns}/sim/input", input_t), qos=qos)
    for _ in range(20):
        w_input.write(input_t(input=11, value=True))  # cycle start key
        time.sleep(0.05)
    check(not w_input.get_matched_subscriptions(), "no reader of sim/input matched this participant")
    for service, srv, fields in [("load_program", "LoadProgram", {"name": "evil.nc", "text": PROGRAM}),
                                 ("start_program", "StartProgram", {"name": "good.nc"})]:
        try:
            r = peer.call(service, srv, timeout=4.0, **fields)
            check(False, f"{service}: no reply, but one came: {r}")
        except TimeoutError:
            check(True, f"{service}: no reply (no server matched this participant)")
    return session.exit_code()


if __name__ == "__main__":
    run(main)
