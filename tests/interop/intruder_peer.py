"""An outsider on the cell's DDS domain (Eclipse Cyclone DDS, types from msgs/), as issue 25 found one.

The cell allows only /lathe1/supervisor. This bare participant announces no ROS 2 node. It
1. looks for the machine's internal topics in DDS discovery: there must be none (the nodes of
   one machine talk over the machine bus), while the public topics and services are there;
2. writes on the old internal names anyway: a program load and start, motion blocks (one with
   run id 2^64-1), overrides of 255 %, eight zero bytes' worth of overrides; on the public
   alarm_events topic a fake alarm and a fake CLEARED; on sim/input cycle start and emergency stop;
3. calls start_program, load_program and delete_program: each must be refused;
4. watches for a while: the machine stays READY, no axis moves, the spindle stays off, no part
   is counted and no alarm appears.

Exit 0 when every check holds; otherwise print what failed and exit 1.
"""

import time

from cyclonedds.core import Policy, Qos
from cyclonedds.pub import DataWriter
from cyclonedds.topic import Topic
from cyclonedds.util import duration

from cyclone_peer import Session, run

COMMANDS = Qos(Policy.Reliability.Reliable(duration(milliseconds=100)), Policy.Durability.Volatile,
               Policy.History.KeepLast(1024))
PROGRAM = "O0666\nG00 X120 Z80\nS2000 M03\nG01 X0 F3000\nM30\n"


def main():
    session = Session({"machine_state": "MachineState", "axes": "AxisState", "spindle": "SpindleState",
                       "alarms": "ActiveAlarms", "part_count": "PartCount"})
    peer, check, wait, poll = session.peer, session.check, session.wait, session.poll
    ns = peer.ns
    check(wait(lambda: all(v is not None for v in peer.latest.values()), 30),
          "the public state topics arrive")
    check(wait(lambda: peer.latest["machine_state"].execution_name == "READY", 30), "machine READY")
    before = {a.name: a.actual_position for a in peer.latest["axes"].axes}
    parts = peer.latest["part_count"].count

    # 1. What the machine offers on DDS.
    readers, writers = session.endpoints(3.0)
    print("machine readers:", readers, flush=True)
    print("machine writers:", writers, flush=True)
    check(f"rq/{ns}/start_programRequest" in readers, "discovery works: the start_program service is seen")
    check(f"rt/{ns}/axes" in writers, "discovery works: the axes topic is seen")
    internal = [n for n in readers + writers if "_internal" in n]
    check(not internal, f"no internal topic on DDS: {internal}")

    # 2. Writing on the old internal names and on the public alarm and input topics.
    def writer(path, msg):
        return DataWriter(peer.dp, Topic(peer.dp, f"rt/{ns}/{path}", peer.ifc.msg("cnc_msgs", msg)), qos=COMMANDS)

    command_t, block_t = peer.ifc.msg("cnc_msgs", "TaskCommand"), peer.ifc.msg("cnc_msgs", "MotionBlock")
    motion_t = peer.ifc.msg("cnc_msgs", "MotionCommand")
    overrides_t, event_t = peer.ifc.msg("cnc_msgs", "Overrides"), peer.ifc.msg("cnc_msgs", "AlarmEvent")
    alarm_t, time_t = peer.ifc.msg("cnc_msgs", "Alarm"), peer.ifc.msg("builtin_interfaces", "Time")
    input_t = peer.ifc.msg("cnc_msgs", "SimInput")
    w_cmd, w_block = writer("_internal/task_command", "TaskCommand"), writer("_internal/motion_blocks", "MotionBlock")
    w_over, w_alarm = writer("_internal/panel_overrides", "Overrides"), writer("alarm_events", "AlarmEvent")
    w_input = writer("sim/input", "SimInput")
    w_motion = writer("_internal/motion_command", "MotionCommand")

    def block(run_id, seq, kind, end, feed=0.0):
        return block_t(run_id=run_id, seq=seq, program="O0666", line=seq, kind=kind, end=end, center=[],
                       plane=[], feed=feed, dwell_seconds=0.0, lead=0.0, start_angle=0.0, flag=False,
                       aux_kind=0, aux_code=0, aux_value=0.0, origin=[], work_frame=[])

    offset_t, work_t = peer.ifc.msg("cnc_msgs", "ToolOffset"), peer.ifc.msg("cnc_msgs", "WorkOffset")

    def task_command(id, kind, program="", text=""):
        return command_t(id=id, kind=kind, program=program, text=text, start_at="", mode=0, axis="",
                         direction=0, feed=0.0, increment=0.0,
                         tool_offset=offset_t(number=0, x=0.0, z=0.0, wear_x=0.0, wear_z=0.0, radius=0.0, tip=0),
                         work_offset=work_t(code="", axes=[], values=[]))

    def motion_command(id, kind, axis=0, direction=0, feed=0.0):
        return motion_t(id=id, kind=kind, axis=axis, direction=direction, feed=feed, increment=0.0, mode=0)

    fake = alarm_t(number=9999, severity=2, text="fake", source="interpreter", program="", line=0,
                   stamp=time_t(sec=0, nanosec=0), acknowledged=False)
    for i in range(20):  # over two seconds: writes before discovery matched a reader are lost
        w_cmd.write(task_command(900 + i, 1, program="evil.nc", text=PROGRAM))  # load
        w_cmd.write(task_command(950 + i, 2, program="evil.nc"))  # start
        w_motion.write(motion_command(970 + i, 6, axis=0, direction=1, feed=5000.0))  # jog
        w_motion.write(motion_command(990 + i, 5))  # reference return
        w_block.write(block(1, 1 + i, 0, [150.0, 90.0]))
        w_block.write(block(2**64 - 1, 1, 0, [150.0, 90.0]))
        w_over.write(overrides_t(feed_percent=255, spindle_percent=255, rapid_percent=255))
        w_over.write(overrides_t(feed_percent=0, spindle_percent=0, rapid_percent=0))
        w_alarm.write(event_t(kind=1, alarm=fake))
        w_input.write(input_t(input=11, value=True))  # cycle start key
        w_input.write(input_t(input=1, value=True))   # emergency stop
        time.sleep(0.1)
    w_alarm.write(event_t(kind=2, alarm=fake))

    # 3. Services: refused, since this participant is nobody the cell allows.
    r = peer.call("load_program", "LoadProgram", name="evil.nc", text=PROGRAM)
    check(not r.accepted and "may not move" in r.message, f"load_program refused: {r.message}")
    r = peer.call("delete_program", "DeleteProgram", name="good.nc")
    check(not r.accepted and "may not move" in r.message, f"delete_program refused: {r.message}")
    r = peer.call("start_program", "StartProgram", name="good.nc")
    check(not r.accepted and "may not move" in r.message, f"start_program refused: {r.message}")

    # 4. Nothing happened.
    moved, states, rpm = [], set(), 0.0
    end = time.time() + 3.0
    while time.time() < end:
        poll()
        states.add(peer.latest["machine_state"].execution_name)
        rpm = max(rpm, abs(peer.latest["spindle"].actual_rpm), abs(peer.latest["spindle"].commanded_rpm))
        for a in peer.latest["axes"].axes:
            if abs(a.actual_position - before.get(a.name, a.actual_position)) > 1e-6:
                moved.append((a.name, a.actual_position))
        time.sleep(0.02)
    check(states == {"READY"}, f"the machine stayed READY: {sorted(states)}")
    check(not moved, f"no axis moved: {moved[:3]}")
    check(rpm == 0.0, f"the spindle stayed off: {rpm}")
    check(peer.latest["part_count"].count == parts, "no part counted")
    check(len(peer.latest["alarms"].alarms) == 0,
          f"no alarm (fake or emergency stop): {[a.number for a in peer.latest['alarms'].alarms]}")
    return session.exit_code()


if __name__ == "__main__":
    run(main)
