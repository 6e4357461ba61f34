#!/usr/bin/env python3
"""An independent service client for rbsim's services, on the Python `cyclonedds` package.

Starts service_test_server (test/dds/service_test_server.cpp) and calls its services the way
rmw_cyclonedds_cpp's clients do, built here from the wire format alone (none of rbsim's code):
requests on rq/<service>Request, replies on rr/<service>Reply, types
pkg::srv::dds_::Name_Request_ / _Response_, each sample the request header (u64 client guid,
i64 sequence number) then the message's fields: declared below as one IDL struct per sample, the
header's two fields first. QoS as rmw_qos_profile_services_default, USER_DATA "clientid=<id>;" on
the writer and reader of one client.

Checks: replies carry the request header back and go to the client that asked (two clients, each
reading every reply on the shared topic and keeping its own); rbsim_msgs/srv/Step and
rcl_interfaces/srv/GetParameters (a sequence of ParameterValue: int64 and float64 after strings,
sequences of strings) decode with these types; a client that vanishes right after its request
leaves the server answering the others. Exit status 0 when every check passes.
"""

import argparse
import os
import random
import subprocess
import sys
import time
from dataclasses import dataclass

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "support", "python"))
from rbsim_venv import ensure_venv  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--server", required=True)
    ap.add_argument("--domain", type=int, required=True)
    ap.add_argument("--venv", required=True)
    ap.add_argument("--requirements", required=True)
    args = ap.parse_args()
    ensure_venv(args.venv, args.requirements)
    return run(args)


def run(args):
    from cyclonedds.core import Listener, Policy, Qos
    from cyclonedds.domain import DomainParticipant
    from cyclonedds.idl import IdlStruct
    import cyclonedds.idl.types as types
    from cyclonedds.pub import DataWriter
    from cyclonedds.sub import DataReader
    from cyclonedds.topic import Topic
    from cyclonedds.util import duration

    @dataclass
    class Step_Request_(IdlStruct, typename="rbsim_msgs::srv::dds_::Step_Request_"):
        guid: types.uint64
        seq: types.int64
        steps: types.uint32

    @dataclass
    class Step_Response_(IdlStruct, typename="rbsim_msgs::srv::dds_::Step_Response_"):
        guid: types.uint64
        seq: types.int64
        success: bool
        message: str
        step: types.uint64

    @dataclass
    class ParameterValue_(IdlStruct, typename="rcl_interfaces::msg::dds_::ParameterValue_"):
        type: types.uint8
        bool_value: bool
        integer_value: types.int64
        double_value: types.float64
        string_value: str
        byte_array_value: types.sequence[types.uint8]
        bool_array_value: types.sequence[bool]
        integer_array_value: types.sequence[types.int64]
        double_array_value: types.sequence[types.float64]
        string_array_value: types.sequence[str]

    @dataclass
    class GetParameters_Request_(IdlStruct, typename="rcl_interfaces::srv::dds_::GetParameters_Request_"):
        guid: types.uint64
        seq: types.int64
        names: types.sequence[str]

    @dataclass
    class GetParameters_Response_(IdlStruct, typename="rcl_interfaces::srv::dds_::GetParameters_Response_"):
        guid: types.uint64
        seq: types.int64
        values: types.sequence[ParameterValue_]

    ns = f"/svc_py_{os.getpid()}"
    failures = []

    def check(cond, what):
        if not cond:
            failures.append(what)
            print(f"FAIL: {what}", file=sys.stderr)

    class Client:
        """One rmw_cyclonedds-style client: a request writer and a reply reader sharing a clientid."""

        def __init__(self, dp, service, req_type, rep_type, name):
            self.guid = random.getrandbits(63) | 1
            self.seq = 0
            qos = Qos(Policy.Reliability.Reliable(duration(seconds=1)), Policy.History.KeepLast(10),
                      Policy.Durability.Volatile, Policy.Userdata(f"clientid={name};".encode()))
            self.rq = Topic(dp, f"rq{service}Request", req_type)
            self.rr = Topic(dp, f"rr{service}Reply", rep_type)
            matches = self.matches = {"writer": 0, "reader": 0}  # the listeners hold the dict, not self

            def on_pub(_writer, status):
                matches["writer"] = status.current_count

            def on_sub(_reader, status):
                matches["reader"] = status.current_count
            self.writer = DataWriter(dp, self.rq, qos=qos, listener=Listener(on_publication_matched=on_pub))
            self.reader = DataReader(dp, self.rr, qos=qos, listener=Listener(on_subscription_matched=on_sub))
            self.replies = {}   # seq -> reply, this client's
            self.others = 0     # replies to other clients, seen on the shared topic

        def matched(self):
            return self.matches["writer"] > 0 and self.matches["reader"] > 0

        def send(self, make):
            self.seq += 1
            self.writer.write(make(self.guid, self.seq))
            return self.seq

        def poll(self):
            for s in self.reader.take(N=64):
                if not hasattr(s, "guid"):
                    continue  # an invalid sample (a writer's state change)
                if s.guid == self.guid:
                    self.replies[s.seq] = s
                else:
                    self.others += 1

    def wait(cond, seconds, what):
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            if cond():
                return True
            time.sleep(0.01)
        check(False, what)
        return False

    server = subprocess.Popen([args.server, str(args.domain), ns], stdin=subprocess.PIPE,
                              stdout=subprocess.PIPE, text=True)
    try:
        line = server.stdout.readline().strip()
        if line != "READY":
            print(f"FAIL: the server said {line!r}", file=sys.stderr)
            return 1
        dp = DomainParticipant(args.domain)
        a = Client(dp, f"{ns}/step", Step_Request_, Step_Response_, "py-a")
        b = Client(dp, f"{ns}/step", Step_Request_, Step_Response_, "py-b")
        wait(lambda: a.matched() and b.matched(), 10, "both Step clients matched the server")

        sent = {}
        for i in range(1, 6):
            sa = a.send(lambda g, s: Step_Request_(guid=g, seq=s, steps=i))
            sent[(a.guid, sa)] = i
            sb = b.send(lambda g, s: Step_Request_(guid=g, seq=s, steps=100 + i))
            sent[(b.guid, sb)] = 100 + i

        def all_in():
            a.poll()
            b.poll()
            return len(a.replies) == 5 and len(b.replies) == 5
        wait(all_in, 10, "five replies for each client")
        for c in (a, b):
            for seq, r in c.replies.items():
                steps = sent[(c.guid, seq)]
                # The header came back unchanged, and the server saw the one we wrote.
                check(r.guid == c.guid and r.seq == seq, f"reply header {r.guid}:{r.seq}")
                check(r.success and r.step == 10 * steps, f"Step({steps}) -> {r.step}")
                check(r.message == f"{c.guid}:{seq}", f"the server read header {r.message}, sent {c.guid}:{seq}")
            check(c.others == 5, f"each client also sees the other's 5 replies on the topic (saw {c.others})")

        # rcl_interfaces/srv/GetParameters: sequences of strings and of ParameterValue.
        g = Client(dp, f"{ns}/get_parameters", GetParameters_Request_, GetParameters_Response_, "py-g")
        wait(g.matched, 10, "the GetParameters client matched the server")
        names = ["rate", "forces.0.fy", ""]
        seq = g.send(lambda gu, s: GetParameters_Request_(guid=gu, seq=s, names=names))
        wait(lambda: (g.poll(), seq in g.replies)[1], 10, "a GetParameters reply")
        if seq in g.replies:
            values = g.replies[seq].values
            check(len(values) == len(names), f"{len(values)} values for {len(names)} names")
            for name, v in zip(names, values):
                check(v.type == 2 and v.integer_value == len(name) and v.string_value == name
                      and v.double_value == 0.5 * len(name) and list(v.string_array_value) == [name, name]
                      and len(v.byte_array_value) == 0 and len(v.double_array_value) == 0,
                      f"value of {name!r}: {v}")

        # A client that vanishes: its reply reader first, then a request, then the rest. The server
        # does not answer it (it waits 0.1 s for that reader, without stalling) and answers the others.
        dp2 = DomainParticipant(args.domain)
        gone = Client(dp2, f"{ns}/step", Step_Request_, Step_Response_, "py-gone")
        wait(gone.matched, 10, "the vanishing client matched the server")
        gone.reader = None
        time.sleep(0.5)  # the server's reply writer unmatches it
        gone.send(lambda gu, s: Step_Request_(guid=gu, seq=s, steps=7))
        gone = None
        dp2 = None
        seq = a.send(lambda gu, s: Step_Request_(guid=gu, seq=s, steps=9))
        wait(lambda: (a.poll(), seq in a.replies)[1], 10, "a reply after a client vanished")
        if seq in a.replies:
            check(a.replies[seq].step == 90, "Step(9) after the vanished client")
        time.sleep(0.5)  # past the server's wait for the vanished client's reply reader (0.1 s)
    finally:
        out, _ = server.communicate(timeout=30)
    stats = dict(kv.split("=") for kv in out.strip().split("STATS ", 1)[-1].split())
    print(f"server: {stats}")
    check(server.returncode == 0, f"server exit status {server.returncode}")
    check(stats.get("malformed") == "0", "no request was malformed")
    n = {k: int(v) for k, v in stats.items()}
    # Every request answered but the vanished client's: gone, or its reply reader never matched.
    check(n["received"] == 12 and n["answered"] == 11 and n["client_gone"] + n["client_unmatched"] == 1,
          "12 Step requests: 11 answered, the vanished client's dropped")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
