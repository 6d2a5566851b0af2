"""Reads the cell supervisor's audit bag with rosbags (a reader nobody here wrote) and prints
every command event and decision it holds, one per line, tab-separated:

    TOPIC  COMMAND  DETAIL  CLIENT  ACCEPTED  MESSAGE

and, for the supervisor's state topic, one line `state COMPLETE MACHINE:STATUS:COUNT ...`.

usage: read_cell_bag.py BAG_DIR MSGS_DIR
"""

import sys
from pathlib import Path

from rosbags.highlevel import AnyReader
from rosbags.typesys import Stores, get_types_from_msg, get_typestore


def main() -> int:
    bag, msgs = Path(sys.argv[1]), Path(sys.argv[2])
    store = get_typestore(Stores.ROS2_HUMBLE)
    types = {}
    for f in sorted(msgs.glob("*.msg")):
        types.update(get_types_from_msg(f.read_text(), f"cnc_msgs/msg/{f.stem}"))
    store.register(types)
    with AnyReader([bag], default_typestore=store) as reader:
        for conn, _t, raw in reader.messages():
            msg = store.deserialize_cdr(raw, conn.msgtype)
            if conn.msgtype == "cnc_msgs/msg/CommandEvent":
                fields = [conn.topic, msg.command, msg.detail, msg.client, str(msg.accepted), msg.message]
                print("\t".join(f.replace("\t", " ").replace("\n", " ") for f in fields))
            elif conn.msgtype == "cnc_msgs/msg/CellState":
                machines = " ".join(f"{m.name}:{m.status}:{m.count}" for m in msg.machines)
                print(f"state {msg.complete} {machines}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
