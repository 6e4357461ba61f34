"""An independent client of rosbag2's player services (rosbag2_interfaces/srv, Jazzy), on the
Python `cyclonedds` package: the types are declared here from the .srv files and rmw_cyclonedds_cpp's
wire format alone (none of rbsim's code), as test/dds/service_client.py does: requests on
rq/<service>Request and replies on rr/<service>Reply, types rosbag2_interfaces::srv::dds_::Name_Request_
/ _Response_, each sample the request header (u64 client guid, i64 sequence number) then the
fields; a half without fields carries rosidl's placeholder `uint8 structure_needs_at_least_one_member`.
Used by e2e.py's player case."""

import random
import time
from dataclasses import dataclass


def player_types():
    from cyclonedds.idl import IdlStruct
    import cyclonedds.idl.types as types

    @dataclass
    class Time_(IdlStruct, typename="builtin_interfaces::msg::dds_::Time_"):
        sec: types.int32
        nanosec: types.uint32

    def empty(name, half):
        @dataclass
        class Empty(IdlStruct, typename=f"rosbag2_interfaces::srv::dds_::{name}_{half}_"):
            guid: types.uint64
            seq: types.int64
            structure_needs_at_least_one_member: types.uint8 = 0
        return Empty

    @dataclass
    class IsPaused_Response_(IdlStruct, typename="rosbag2_interfaces::srv::dds_::IsPaused_Response_"):
        guid: types.uint64
        seq: types.int64
        paused: bool

    @dataclass
    class GetRate_Response_(IdlStruct, typename="rosbag2_interfaces::srv::dds_::GetRate_Response_"):
        guid: types.uint64
        seq: types.int64
        rate: types.float64

    @dataclass
    class SetRate_Request_(IdlStruct, typename="rosbag2_interfaces::srv::dds_::SetRate_Request_"):
        guid: types.uint64
        seq: types.int64
        rate: types.float64

    @dataclass
    class SetRate_Response_(IdlStruct, typename="rosbag2_interfaces::srv::dds_::SetRate_Response_"):
        guid: types.uint64
        seq: types.int64
        success: bool

    @dataclass
    class Seek_Request_(IdlStruct, typename="rosbag2_interfaces::srv::dds_::Seek_Request_"):
        guid: types.uint64
        seq: types.int64
        time: Time_

    @dataclass
    class Seek_Response_(IdlStruct, typename="rosbag2_interfaces::srv::dds_::Seek_Response_"):
        guid: types.uint64
        seq: types.int64
        success: bool

    @dataclass
    class PlayNext_Response_(IdlStruct, typename="rosbag2_interfaces::srv::dds_::PlayNext_Response_"):
        guid: types.uint64
        seq: types.int64
        success: bool

    @dataclass
    class Burst_Request_(IdlStruct, typename="rosbag2_interfaces::srv::dds_::Burst_Request_"):
        guid: types.uint64
        seq: types.int64
        num_messages: types.uint64

    @dataclass
    class Burst_Response_(IdlStruct, typename="rosbag2_interfaces::srv::dds_::Burst_Response_"):
        guid: types.uint64
        seq: types.int64
        actually_burst: types.uint64

    @dataclass
    class Snapshot_Response_(IdlStruct, typename="rosbag2_interfaces::srv::dds_::Snapshot_Response_"):
        guid: types.uint64
        seq: types.int64
        success: bool

    return {
        "snapshot": (empty("Snapshot", "Request"), Snapshot_Response_),  # the recorder's
        "split_bagfile": (empty("SplitBagfile", "Request"), empty("SplitBagfile", "Response")),
        "pause": (empty("Pause", "Request"), empty("Pause", "Response")),
        "resume": (empty("Resume", "Request"), empty("Resume", "Response")),
        "toggle_paused": (empty("TogglePaused", "Request"), empty("TogglePaused", "Response")),
        "is_paused": (empty("IsPaused", "Request"), IsPaused_Response_),
        "get_rate": (empty("GetRate", "Request"), GetRate_Response_),
        "set_rate": (SetRate_Request_, SetRate_Response_),
        "seek": (Seek_Request_, Seek_Response_),
        "play_next": (empty("PlayNext", "Request"), PlayNext_Response_),
        "burst": (Burst_Request_, Burst_Response_),
    }, Time_


def trigger_types(names=("pause", "resume")):
    """std_srvs/srv/Trigger (rbsim node's pause, resume, reset) as rmw_cyclonedds_cpp puts it on the
    wire: for Player(..., types=trigger_types())."""
    from cyclonedds.idl import IdlStruct
    import cyclonedds.idl.types as types

    @dataclass
    class Trigger_Request_(IdlStruct, typename="std_srvs::srv::dds_::Trigger_Request_"):
        guid: types.uint64
        seq: types.int64
        structure_needs_at_least_one_member: types.uint8 = 0

    @dataclass
    class Trigger_Response_(IdlStruct, typename="std_srvs::srv::dds_::Trigger_Response_"):
        guid: types.uint64
        seq: types.int64
        success: bool
        message: str

    return {name: (Trigger_Request_, Trigger_Response_) for name in names}


class Player:
    """One rmw_cyclonedds-style client per service of the player node `node` ("/rbsim_player"), or
    of the services named in `names` (the recorder's: snapshot, split_bagfile, pause, resume, is_paused)."""

    PLAYER = ("pause", "resume", "toggle_paused", "is_paused", "get_rate", "set_rate", "seek", "play_next", "burst")

    def __init__(self, domain, node, config_uri=None, names=PLAYER, types=None):
        import os
        if config_uri:  # read by Cyclone when the domain is created (rbsim's loopback configuration)
            os.environ["CYCLONEDDS_URI"] = config_uri
        from cyclonedds.core import Listener, Policy, Qos
        from cyclonedds.domain import DomainParticipant
        from cyclonedds.pub import DataWriter
        from cyclonedds.sub import DataReader
        from cyclonedds.topic import Topic
        from cyclonedds.util import duration

        self.dp = DomainParticipant(domain)
        self.types, self.Time = player_types()
        if types is not None:  # another node's services (rbsim node's Trigger services)
            self.types = types
        self.clients = {}
        for name, (req, rep) in self.types.items():
            if name not in names:
                continue
            c = {"guid": random.getrandbits(63) | 1, "seq": 0, "req": req, "matches": {"w": 0, "r": 0}}
            qos = Qos(Policy.Reliability.Reliable(duration(seconds=1)), Policy.History.KeepLast(10),
                      Policy.Durability.Volatile, Policy.Userdata(f"clientid={name};".encode()))
            m = c["matches"]

            def on_pub(_w, status, m=m):
                m["w"] = status.current_count

            def on_sub(_r, status, m=m):
                m["r"] = status.current_count
            service = f"{node}/{name}"
            c["writer"] = DataWriter(self.dp, Topic(self.dp, f"rq{service}Request", req), qos=qos,
                                     listener=Listener(on_publication_matched=on_pub))
            c["reader"] = DataReader(self.dp, Topic(self.dp, f"rr{service}Reply", rep), qos=qos,
                                     listener=Listener(on_subscription_matched=on_sub))
            self.clients[name] = c

    def wait_matched(self, timeout):
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            if all(c["matches"]["w"] > 0 and c["matches"]["r"] > 0 for c in self.clients.values()):
                return True
            time.sleep(0.02)
        return False

    def call(self, name, timeout=15.0, **fields):
        """The reply of one call (the response sample), or None when none came within `timeout`."""
        c = self.clients[name]
        c["seq"] += 1
        c["writer"].write(c["req"](guid=c["guid"], seq=c["seq"], **fields))
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            for s in c["reader"].take(N=16):
                if hasattr(s, "guid") and s.guid == c["guid"] and s.seq == c["seq"]:
                    return s
            time.sleep(0.005)
        return None
