#!/usr/bin/env python3
"""An independent ROS 2 graph observer for the end-to-end tests, on the Python `cyclonedds`
package: types declared here from rmw_dds_common's and rcl_interfaces' .msg files (Gid is char[16]
on Jazzy, char[24] on Humble), not from rbsim's code.

Waits (at most --timeout seconds) until ros_discovery_info names the node --name, and /rosout has
a message from it, then prints one JSON line: the node's namespace, the GIDs it lists (hex), the
GUIDs DDS discovery reports for its participant's endpoints (DCPSPublication, DCPSSubscription,
with their topics), the participant's USER_DATA, and the first /rosout message of the node.
Exit 0 when all were seen, 2 otherwise (the JSON says what is missing).
"""

import argparse
import json
import sys
import time
from dataclasses import dataclass

from cyclonedds.builtin import (BuiltinDataReader, BuiltinTopicDcpsParticipant, BuiltinTopicDcpsPublication,
                                BuiltinTopicDcpsSubscription)
from cyclonedds.core import Policy, Qos
from cyclonedds.domain import DomainParticipant
from cyclonedds.idl import IdlStruct
import cyclonedds.idl.types as types
from cyclonedds.internal import InvalidSample
from cyclonedds.sub import DataReader
from cyclonedds.topic import Topic
from cyclonedds.util import duration


def entities_types(gid_size):
    @dataclass
    class Gid_(IdlStruct, typename="rmw_dds_common::msg::dds_::Gid_"):
        data: types.array[types.uint8, gid_size]

    @dataclass
    class NodeEntitiesInfo_(IdlStruct, typename="rmw_dds_common::msg::dds_::NodeEntitiesInfo_"):
        node_namespace: types.bounded_str[256]
        node_name: types.bounded_str[256]
        reader_gid_seq: types.sequence[Gid_]
        writer_gid_seq: types.sequence[Gid_]

    @dataclass
    class ParticipantEntitiesInfo_(IdlStruct, typename="rmw_dds_common::msg::dds_::ParticipantEntitiesInfo_"):
        gid: Gid_
        node_entities_info_seq: types.sequence[NodeEntitiesInfo_]

    return ParticipantEntitiesInfo_


@dataclass
class Time_(IdlStruct, typename="builtin_interfaces::msg::dds_::Time_"):
    sec: types.int32
    nanosec: types.uint32


@dataclass
class Log_(IdlStruct, typename="rcl_interfaces::msg::dds_::Log_"):
    stamp: Time_
    level: types.uint8
    name: str
    msg: str
    file: str
    function: str
    line: types.uint32


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--domain", type=int, required=True)
    ap.add_argument("--name", required=True, help="the node's name (its last segment)")
    ap.add_argument("--gid-size", type=int, choices=(16, 24), required=True)
    ap.add_argument("--timeout", type=float, default=30.0)
    args = ap.parse_args()

    dp = DomainParticipant(args.domain)
    latched = Qos(Policy.Reliability.Reliable(duration(seconds=1)), Policy.Durability.TransientLocal,
                  Policy.History.KeepAll)
    info_reader = DataReader(dp, Topic(dp, "ros_discovery_info", entities_types(args.gid_size)), qos=latched)
    log_reader = DataReader(dp, Topic(dp, "rt/rosout", Log_), qos=latched)
    parts = BuiltinDataReader(dp, BuiltinTopicDcpsParticipant)
    pubs = BuiltinDataReader(dp, BuiltinTopicDcpsPublication)
    subs = BuiltinDataReader(dp, BuiltinTopicDcpsSubscription)

    out = {"entry": None, "log": None, "user_data": None, "writers": {}, "readers": {}}
    deadline = time.monotonic() + args.timeout

    def take_entries():  # the latest entry wins
        for s in info_reader.take(N=64):
            if isinstance(s, InvalidSample):
                continue
            for n in s.node_entities_info_seq:
                if n.node_name == args.name:
                    out["entry"] = {"participant": bytes(s.gid.data).hex(), "namespace": n.node_namespace,
                                    "readers": [bytes(g.data).hex() for g in n.reader_gid_seq],
                                    "writers": [bytes(g.data).hex() for g in n.writer_gid_seq]}

    while time.monotonic() < deadline:
        take_entries()
        for s in log_reader.take(N=64):
            if not isinstance(s, InvalidSample) and out["log"] is None and s.name.split(".")[-1] == args.name:
                out["log"] = {"level": s.level, "name": s.name, "msg": s.msg, "function": s.function,
                              "sec": s.stamp.sec}
        if out["entry"] and out["log"]:
            break
        time.sleep(0.05)

    def read_discovery(key):
        for p in parts.read(N=256):
            if p.key.hex == key:
                ud = p.qos[Policy.Userdata]
                out["user_data"] = ud.data.decode("latin-1") if ud else ""
        for reader, kind in ((pubs, "writers"), (subs, "readers")):
            out[kind] = {}
            for e in reader.read(N=1024):
                if e.participant_key.hex == key:
                    out[kind][e.key.hex] = e.topic_name

    def agree():  # what the entry lists is what discovery reports (but the entry's own writer)
        e = out["entry"]
        listed_w, listed_r = sorted(g[:32] for g in e["writers"]), sorted(g[:32] for g in e["readers"])
        found_w = sorted(k for k, t in out["writers"].items() if t != "ros_discovery_info")
        return out["user_data"] is not None and listed_w == found_w and listed_r == sorted(out["readers"])

    if out["entry"]:
        # Discovery of the participant's endpoints, and any later entry (the node has created all its
        # endpoints before it prints its start line, but samples of two topics may arrive in any
        # order): read until the two agree (not for a time: on a busy machine discovery can take
        # seconds), within the same deadline; what was read last is printed either way.
        while True:
            take_entries()
            read_discovery(out["entry"]["participant"][:32])
            if agree() or time.monotonic() >= deadline:
                break
            time.sleep(0.05)
    print(json.dumps(out), flush=True)
    return 0 if out["entry"] and out["log"] else 2


if __name__ == "__main__":
    sys.exit(main())
