#!/usr/bin/env python3
"""The DDS half of scripts/bench-foxglove's latency figure: subscribes to <ns>/body_states with the
Python cyclonedds package (blocking on a WaitSet, decoding each sample) and, for every step,
prints one line "STEP SOURCE_NS RECEIVED_NS": the writer's source timestamp (the moment the node
published the step) and the wall clock once the sample is decoded. Both are CLOCK_REALTIME on the
one machine, as the Node client's receive times are. Prints READY first; stops after --seconds."""
import argparse
import sys
import time
from dataclasses import dataclass

from cyclonedds.core import Policy, Qos, ReadCondition, SampleState, ViewState, InstanceState, WaitSet
from cyclonedds.domain import DomainParticipant
from cyclonedds.idl import IdlStruct
import cyclonedds.idl.types as types
from cyclonedds.internal import InvalidSample
from cyclonedds.sub import DataReader
from cyclonedds.topic import Topic
from cyclonedds.util import duration


@dataclass
class Time_(IdlStruct, typename="builtin_interfaces::msg::dds_::Time_"):
    sec: types.int32
    nanosec: types.uint32


@dataclass
class Header_(IdlStruct, typename="std_msgs::msg::dds_::Header_"):
    stamp: Time_
    frame_id: str


@dataclass
class BodyState_(IdlStruct, typename="rbsim_msgs::msg::dds_::BodyState_"):
    id: types.int32
    x: types.float64
    y: types.float64
    theta: types.float64
    vx: types.float64
    vy: types.float64
    omega: types.float64


@dataclass
class BodyStates_(IdlStruct, typename="rbsim_msgs::msg::dds_::BodyStates_"):
    header: Header_
    step: types.uint64
    bodies: types.sequence[BodyState_]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--domain", type=int, required=True)
    ap.add_argument("--namespace", required=True)
    ap.add_argument("--seconds", type=float, required=True)
    a = ap.parse_args()
    qos = Qos(Policy.Reliability.Reliable(duration(seconds=1)), Policy.Durability.Volatile, Policy.History.KeepAll)
    dp = DomainParticipant(a.domain)
    reader = DataReader(dp, Topic(dp, f"rt/{a.namespace}/body_states", BodyStates_), qos=qos)
    ws = WaitSet(dp)
    ws.attach(ReadCondition(reader, SampleState.Any | ViewState.Any | InstanceState.Any))
    print("READY", flush=True)
    out = []
    deadline = time.monotonic() + a.seconds
    while time.monotonic() < deadline:
        ws.wait(duration(milliseconds=100))
        for s in reader.take(N=64):
            if isinstance(s, InvalidSample):
                continue
            out.append(f"{s.step} {s.sample_info.source_timestamp} {time.time_ns()}")
    sys.stdout.write("\n".join(out) + "\n")


if __name__ == "__main__":
    main()
