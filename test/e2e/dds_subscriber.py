#!/usr/bin/env python3
"""An independent DDS subscriber for the end-to-end tests, on the Python `cyclonedds` package.

Subscribes to <namespace>/poses and <namespace>/body_states (ROS 2 naming: DDS topics
rt/<namespace>/<name>, types pkg::msg::dds_::Name_) with types declared here as cyclonedds.idl
dataclasses, written from rbsim's IDL (generated from tools/msgs/definitions by msg2idl.py), not
from rbsim's code. Prints "READY" once both readers exist, then takes samples until it has
--count of each (or --timeout seconds passed, or SIGINT/SIGTERM) and writes them as JSON lines to
--out: {"topic": "body_states", "sec": .., "nanosec": .., "frame_id": .., "step": .., "bodies": [[id, x, y,
theta, vx, vy, omega], ...]} and {"topic": "poses", ..., "poses": [[px, py, pz, qx, qy, qz, qw], ...]}.
Floats are written with repr(), so they read back bit-exact.
"""

import argparse
import json
import signal
import sys
import time
from dataclasses import dataclass

from cyclonedds.core import Policy, Qos
from cyclonedds.domain import DomainParticipant
from cyclonedds.idl import IdlStruct
import cyclonedds.idl.types as types
from cyclonedds.internal import InvalidSample
from cyclonedds.sub import DataReader
from cyclonedds.topic import Topic
from cyclonedds.util import duration


# builtin_interfaces/msg/Time, std_msgs/msg/Header ------------------------------------------------
@dataclass
class Time_(IdlStruct, typename="builtin_interfaces::msg::dds_::Time_"):
    sec: types.int32
    nanosec: types.uint32


@dataclass
class Header_(IdlStruct, typename="std_msgs::msg::dds_::Header_"):
    stamp: Time_
    frame_id: str


# rbsim_msgs/msg/BodyState(s) ------------------------------------------------------------------
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


# geometry_msgs/msg/PoseArray ------------------------------------------------------------------
@dataclass
class Point_(IdlStruct, typename="geometry_msgs::msg::dds_::Point_"):
    x: types.float64
    y: types.float64
    z: types.float64


@dataclass
class Quaternion_(IdlStruct, typename="geometry_msgs::msg::dds_::Quaternion_"):
    x: types.float64
    y: types.float64
    z: types.float64
    w: types.float64


@dataclass
class Pose_(IdlStruct, typename="geometry_msgs::msg::dds_::Pose_"):
    position: Point_
    orientation: Quaternion_


@dataclass
class PoseArray_(IdlStruct, typename="geometry_msgs::msg::dds_::PoseArray_"):
    header: Header_
    poses: types.sequence[Pose_]


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--domain", type=int, required=True)
    ap.add_argument("--namespace", required=True)
    ap.add_argument("--count", type=int, required=True, help="samples of each topic to wait for")
    ap.add_argument("--timeout", type=float, default=60.0)
    ap.add_argument("--out", required=True)
    args = ap.parse_args()

    stop = []
    signal.signal(signal.SIGINT, lambda *_: stop.append(1))
    signal.signal(signal.SIGTERM, lambda *_: stop.append(1))

    # What the node offers: reliable, volatile. Keep everything so nothing is dropped on our side.
    qos = Qos(Policy.Reliability.Reliable(duration(seconds=1)), Policy.Durability.Volatile, Policy.History.KeepAll)
    dp = DomainParticipant(args.domain)
    ns = args.namespace.strip("/")
    # The body-state reader last: the node's --wait-for-subscribers counts body-state
    # subscriptions, and Cyclone announces readers in creation order, so when the node sees
    # this one it has seen the poses reader too.
    poses_reader = DataReader(dp, Topic(dp, f"rt/{ns}/poses", PoseArray_), qos=qos)
    states_reader = DataReader(dp, Topic(dp, f"rt/{ns}/body_states", BodyStates_), qos=qos)
    print("READY", flush=True)

    got = {"body_states": 0, "poses": 0}
    deadline = time.monotonic() + args.timeout
    with open(args.out, "w") as out:
        while not stop and time.monotonic() < deadline and min(got.values()) < args.count:
            idle = True
            for s in states_reader.take(N=256):
                idle = False
                if isinstance(s, InvalidSample):  # an instance state change (the writer left), no data
                    continue
                got["body_states"] += 1
                out.write(json.dumps({
                    "topic": "body_states", "sec": s.header.stamp.sec, "nanosec": s.header.stamp.nanosec,
                    "frame_id": s.header.frame_id, "step": s.step,
                    "bodies": [[b.id, repr(b.x), repr(b.y), repr(b.theta), repr(b.vx), repr(b.vy), repr(b.omega)]
                               for b in s.bodies]}) + "\n")
            for s in poses_reader.take(N=256):
                idle = False
                if isinstance(s, InvalidSample):
                    continue
                got["poses"] += 1
                out.write(json.dumps({
                    "topic": "poses", "sec": s.header.stamp.sec, "nanosec": s.header.stamp.nanosec,
                    "frame_id": s.header.frame_id,
                    "poses": [[repr(p.position.x), repr(p.position.y), repr(p.position.z), repr(p.orientation.x),
                               repr(p.orientation.y), repr(p.orientation.z), repr(p.orientation.w)]
                              for p in s.poses]}) + "\n")
            if idle:
                time.sleep(0.005)
    print(f"received body_states {got['body_states']} poses {got['poses']}", flush=True)
    return 0 if min(got.values()) >= args.count else 2


if __name__ == "__main__":
    sys.exit(main())
