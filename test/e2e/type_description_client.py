#!/usr/bin/env python3
"""An independent client of a node's ~/get_type_description (type_description_interfaces/srv/
GetTypeDescription, Jazzy), on the Python `cyclonedds` package: the types are declared here from
the .srv/.msg files and rmw_cyclonedds_cpp's wire format alone (none of rbsim's code), as
player_client.py does for the player's services.

It reads the USER_DATA of the node's writer on --topic from DDS discovery ("typehash=RIHS01_...;"),
asks the node for that hash with include_type_sources, and hashes the description it gets back
as REP 2011 says (rosidl_generator_type_description's JSON without default values, json.dumps
with separators ", " and ": ", SHA-256), here in Python. Prints one JSON line: the announced hash,
the reply (successful, failure_reason, the root type name, its fields, the sources) and the hash of
the returned description; also a second reply, for a hash no type has. With --expect-none it waits
for the node's writer on --topic, then 3 s for the service to match, and prints whether each did.
Exit 0 when a reply (or, with --expect-none, the wait) came, 2 otherwise."""

import argparse
import hashlib
import json
import random
import sys
import time
from dataclasses import dataclass

from cyclonedds.builtin import BuiltinDataReader, BuiltinTopicDcpsPublication
from cyclonedds.core import Listener, Policy, Qos
from cyclonedds.domain import DomainParticipant
from cyclonedds.idl import IdlStruct
import cyclonedds.idl.types as types
from cyclonedds.pub import DataWriter
from cyclonedds.sub import DataReader
from cyclonedds.topic import Topic
from cyclonedds.util import duration

MSG = "type_description_interfaces::msg::dds_::"
SRV = "type_description_interfaces::srv::dds_::"


@dataclass
class FieldType_(IdlStruct, typename=MSG + "FieldType_"):
    type_id: types.uint8
    capacity: types.uint64
    string_capacity: types.uint64
    nested_type_name: types.bounded_str[255]


@dataclass
class Field_(IdlStruct, typename=MSG + "Field_"):
    name: str
    type: FieldType_
    default_value: str


@dataclass
class IndividualTypeDescription_(IdlStruct, typename=MSG + "IndividualTypeDescription_"):
    type_name: types.bounded_str[255]
    fields: types.sequence[Field_]


@dataclass
class TypeDescription_(IdlStruct, typename=MSG + "TypeDescription_"):
    type_description: IndividualTypeDescription_
    referenced_type_descriptions: types.sequence[IndividualTypeDescription_]


@dataclass
class TypeSource_(IdlStruct, typename=MSG + "TypeSource_"):
    type_name: str
    encoding: str
    raw_file_contents: str


@dataclass
class KeyValue_(IdlStruct, typename=MSG + "KeyValue_"):
    key: str
    value: str


@dataclass
class GetTypeDescription_Request_(IdlStruct, typename=SRV + "GetTypeDescription_Request_"):
    guid: types.uint64  # rmw_cyclonedds_cpp's request header
    seq: types.int64
    type_name: str
    type_hash: str
    include_type_sources: bool


@dataclass
class GetTypeDescription_Response_(IdlStruct, typename=SRV + "GetTypeDescription_Response_"):
    guid: types.uint64
    seq: types.int64
    successful: bool
    failure_reason: str
    type_description: TypeDescription_
    type_sources: types.sequence[TypeSource_]
    extra_information: types.sequence[KeyValue_]


def rep2011_hash(td):
    """RIHS01 of a TypeDescription_ as rosidl_generator_type_description computes it."""
    def individual(d):
        return {"type_name": d.type_name,
                "fields": [{"name": f.name, "type": {"type_id": f.type.type_id, "capacity": f.type.capacity,
                                                     "string_capacity": f.type.string_capacity,
                                                     "nested_type_name": f.type.nested_type_name}}
                           for f in d.fields]}
    text = json.dumps({"type_description": individual(td.type_description),
                       "referenced_type_descriptions": [individual(d) for d in td.referenced_type_descriptions]},
                      separators=(", ", ": "))
    return "RIHS01_" + hashlib.sha256(text.encode()).hexdigest()


def announced_hash(dp, topic, deadline):
    reader = BuiltinDataReader(dp, BuiltinTopicDcpsPublication)
    while time.monotonic() < deadline:
        for s in reader.take(N=256):
            if getattr(s, "topic_name", None) != "rt" + topic:
                continue
            data = s.qos[Policy.Userdata].data if Policy.Userdata in s.qos else b""
            text = data.decode()
            if text.startswith("typehash=") and text.endswith(";"):
                return text[len("typehash="):-1]
        time.sleep(0.05)
    return None


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--domain", type=int, required=True)
    ap.add_argument("--node", required=True, help='the node, "/ns"')
    ap.add_argument("--topic", required=True, help='a topic the node publishes, "/ns/body_states"')
    ap.add_argument("--type", required=True, help="its type, pkg/msg/Name")
    ap.add_argument("--timeout", type=float, default=30)
    ap.add_argument("--expect-none", action="store_true")
    a = ap.parse_args()
    deadline = time.monotonic() + a.timeout
    dp = DomainParticipant(a.domain)
    qos = Qos(Policy.Reliability.Reliable(duration(seconds=1)), Policy.History.KeepLast(10),
              Policy.Durability.Volatile, Policy.Userdata(b"clientid=type_description;"))
    matched = {"w": 0, "r": 0}

    def on_pub(_w, status):
        matched["w"] = status.current_count

    def on_sub(_r, status):
        matched["r"] = status.current_count
    service = a.node + "/get_type_description"
    writer = DataWriter(dp, Topic(dp, f"rq{service}Request", GetTypeDescription_Request_), qos=qos,
                        listener=Listener(on_publication_matched=on_pub))
    reader = DataReader(dp, Topic(dp, f"rr{service}Reply", GetTypeDescription_Response_), qos=qos,
                        listener=Listener(on_subscription_matched=on_sub))
    if a.expect_none:
        # The node is up once its writer is discovered; its service would match within seconds.
        seen = announced_hash(dp, a.topic, deadline) is not None
        until = time.monotonic() + 3.0
        while time.monotonic() < until and not (matched["w"] or matched["r"]):
            time.sleep(0.02)
        print(json.dumps({"node_seen": seen, "matched": bool(matched["w"] or matched["r"])}))
        return 0
    while time.monotonic() < deadline and not (matched["w"] and matched["r"]):
        time.sleep(0.02)
    if not (matched["w"] and matched["r"]):
        print(json.dumps({"error": f"{service} never matched"}))
        return 2
    guid = random.getrandbits(63) | 1
    seq = 0

    def call(type_name, type_hash):
        nonlocal seq
        seq += 1
        writer.write(GetTypeDescription_Request_(guid=guid, seq=seq, type_name=type_name, type_hash=type_hash,
                                                 include_type_sources=True))
        while time.monotonic() < deadline:
            for s in reader.take(N=16):
                if getattr(s, "guid", None) == guid and s.seq == seq:
                    return s
            time.sleep(0.005)
        return None

    hash_ = announced_hash(dp, a.topic, deadline)
    reply = call(a.type, hash_ or "")
    unknown = call(a.type, "RIHS01_" + "0" * 64)
    if reply is None or unknown is None:
        print(json.dumps({"error": "no reply", "announced": hash_}))
        return 2
    td = reply.type_description
    print(json.dumps({
        "announced": hash_,
        "successful": reply.successful, "failure_reason": reply.failure_reason,
        "type_name": td.type_description.type_name,
        "fields": [[f.name, f.type.type_id, f.default_value] for f in td.type_description.fields],
        "referenced": [d.type_name for d in td.referenced_type_descriptions],
        "sources": [[s.type_name, s.encoding, s.raw_file_contents] for s in reply.type_sources],
        "description_hash": rep2011_hash(td),
        "unknown": [unknown.successful, unknown.failure_reason],
    }))
    return 0


if __name__ == "__main__":
    sys.exit(main())
