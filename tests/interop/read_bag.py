"""Reads a recorder bag with two readers nobody here wrote and prints what they found as JSON.

usage: read_bag.py BAG_DIR MSGS_DIR

- rosbags (AnyReader over the rosbag2 folder: metadata.yaml + .mcap), every message
  deserialised with a typestore built from the .msg files in MSGS_DIR;
- mcap (the PyPI package) with mcap-ros2-support, every message decoded with the ros2msg schema
  the file carries.

Output, one fact per line: `rosbags TOPIC COUNT`, `mcap TOPIC COUNT`, `gap FILE:TOPIC SEQS`,
`error TEXT`, `last_part_count N`, `first_log_time NS`, `last_log_time NS`.
"""

import sys
from collections import defaultdict
from pathlib import Path

from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory
from rosbags.highlevel import AnyReader
from rosbags.typesys import Stores, get_types_from_msg, get_typestore


def typestore_from(msgs_dir: Path):
    store = get_typestore(Stores.ROS2_HUMBLE)  # for builtin_interfaces/msg/Time
    types = {}
    for f in sorted(msgs_dir.glob("*.msg")):
        types.update(get_types_from_msg(f.read_text(), f"cnc_msgs/msg/{f.stem}"))
    store.register(types)
    return store


def main() -> int:
    bag = Path(sys.argv[1])
    store = typestore_from(Path(sys.argv[2]))
    out = {
        "rosbags": defaultdict(int),
        "mcap": defaultdict(int),
        "sequence_gaps": {},
        "errors": [],
        "last_part_count": None,
        "first_log_time": None,
        "last_log_time": None,
    }
    with AnyReader([bag], default_typestore=store) as reader:
        for conn, _t, raw in reader.messages():
            try:
                msg = store.deserialize_cdr(raw, conn.msgtype)
            except Exception as e:  # noqa: BLE001 - every failure is reported
                out["errors"].append(f"rosbags {conn.topic}: {e}")
                continue
            out["rosbags"][conn.topic] += 1
            if conn.topic.endswith("/part_count"):
                out["last_part_count"] = msg.count
    sequences = defaultdict(list)
    for f in sorted(bag.glob("*.mcap"), key=lambda p: int(p.stem.rsplit("_", 1)[1])):
        with f.open("rb") as fh:
            reader = make_reader(fh, decoder_factories=[DecoderFactory()])
            for _schema, channel, message, decoded in reader.iter_decoded_messages(
                log_time_order=False
            ):
                if decoded is None:
                    out["errors"].append(f"mcap {channel.topic}: not decoded")
                    continue
                out["mcap"][channel.topic] += 1
                sequences[(f.name, channel.topic)].append(message.sequence)
                t = message.log_time
                if out["first_log_time"] is None or t < out["first_log_time"]:
                    out["first_log_time"] = t
                if out["last_log_time"] is None or t > out["last_log_time"]:
                    out["last_log_time"] = t
    for (fname, topic), seqs in sequences.items():
        if sorted(seqs) != list(range(1, len(seqs) + 1)):
            out["sequence_gaps"][f"{fname}:{topic}"] = seqs[:20]
    for reader_name in ("rosbags", "mcap"):
        for topic, n in sorted(out[reader_name].items()):
            print(f"{reader_name} {topic} {n}")
    for where, seqs in out["sequence_gaps"].items():
        print(f"gap {where} {seqs}")
    for e in out["errors"]:
        print("error " + e.replace("\n", " "))
    for key in ("last_part_count", "first_log_time", "last_log_time"):
        if out[key] is not None:
            print(f"{key} {out[key]}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
