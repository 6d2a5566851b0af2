"""A robot on Eclipse Cyclone DDS (PyPI `cyclonedds`) doing the load/unload handshake with the cell.

It follows /<ns>/robot_handshake and calls /<ns>/robot_request (rmw_cyclonedds mapping), with
types built from msgs/ as in cyclone_peer.py. The cell runs a program once (started by the
supervisor through start_program); then the robot:
waits for cycle complete, is refused a door open while the spindle turns or the cycle runs (if it
catches that moment) and unclamp/close with reasons, opens the door, reports not clear (going in),
unclamps, reports clear (out again), clamps, closes the door and starts the next cycle, which
completes too.

Exit 0 when every check holds; otherwise print what failed and exit 1.
"""


from cyclone_peer import Session, run

DOOR_OPEN, DOOR_CLOSE, CHUCK_UNCLAMP, CHUCK_CLAMP, CLEAR, NOT_CLEAR, CYCLE_START = range(1, 8)

# Long enough (about 4 s of cutting) for the robot to ask during the cycle.
PART = "O0050\nG00 X60 Z5\nS600 M03\nG01 X50 F600\nZ-40\nX60\nG00 Z5\nM05\nM30\n"


def main():
    session = Session({"robot_handshake": "RobotHandshake", "machine_state": "MachineState",
                       "part_count": "PartCount"})
    peer, check, wait, poll = session.peer, session.check, session.wait, session.poll

    def hs():
        return peer.latest["robot_handshake"]

    def robot(request):
        return peer.call("robot_request", "RobotRequest", timeout=30.0, request=request)

    check(wait(lambda: all(v is not None for v in peer.latest.values()), 30),
          "robot_handshake, machine_state and part_count arrive on joining")
    check(wait(lambda: peer.latest["machine_state"].execution_name != "WAIT", 30), "machine ready")
    check(hs().door_closed and hs().chuck_clamped and hs().robot_clear,
          "door closed, chuck clamped, robot clear at start")
    start_count = peer.latest["part_count"].count

    r = robot(CYCLE_START)
    check(not r.accepted and "no program" in r.message, f"cycle start before any program refused: {r.message}")
    r = peer.call("load_program", "LoadProgram", name="part.nc", text=PART)
    check(r.accepted, f"program loaded: {r.message}")
    r = peer.call("start_program", "StartProgram", name="part.nc")
    check(r.accepted, f"first cycle started by the supervisor: {r.message}")
    check(wait(lambda: hs().cycle_active and hs().spindle_turning, 20), "cycle active, spindle turning")
    r = robot(DOOR_OPEN)
    check(not r.accepted and ("cycle active" in r.message or "spindle turning" in r.message),
          f"door open during the cycle refused with its reason: {r.message}")
    r = robot(CHUCK_UNCLAMP)
    check(not r.accepted and "refused" in r.message, f"unclamp during the cycle refused: {r.message}")

    check(wait(lambda: hs().cycle_complete and not hs().cycle_active, 60), "cycle complete")
    check(wait(lambda: not hs().spindle_turning, 20), "spindle stopped")
    check(peer.latest["part_count"].count == start_count + 1, "part counted")

    for request, name, done in [
        (DOOR_OPEN, "door open", lambda h: h.door_open),
        (NOT_CLEAR, "robot in the work area", lambda h: not h.robot_clear),
        (CHUCK_UNCLAMP, "chuck unclamped", lambda h: h.chuck_unclamped),
    ]:
        r = robot(request)
        poll()
        check(r.accepted and done(hs()), f"{name}: {r.message}")
    r = robot(DOOR_CLOSE)
    check(not r.accepted and "robot not clear" in r.message,
          f"door close with the robot inside refused: {r.message}")
    r = robot(CYCLE_START)
    check(not r.accepted and "refused" in r.message, f"cycle start with the robot inside refused: {r.message}")
    for request, name, done in [
        (CLEAR, "robot clear", lambda h: h.robot_clear),
        (CHUCK_CLAMP, "chuck clamped", lambda h: h.chuck_clamped),
        (DOOR_CLOSE, "door closed", lambda h: h.door_closed),
    ]:
        r = robot(request)
        poll()
        check(r.accepted and done(hs()), f"{name}: {r.message}")
    r = robot(CYCLE_START)
    check(r.accepted, f"next cycle started by the robot: {r.message}")
    check(wait(lambda: peer.latest["part_count"].count == start_count + 2, 60),
          f"second part counted: {peer.latest['part_count'].count - start_count}")
    check(wait(lambda: hs().cycle_complete, 20), "cycle complete again")
    r = robot(99)
    check(not r.accepted and "unknown robot request" in r.message, f"unknown request refused: {r.message}")
    return session.exit_code()


if __name__ == "__main__":
    run(main)
