#!/usr/bin/env python3
"""Driver of scripts/bench-node-spawn (issue 38, point 5): spawning into a large world in real time.

`rbsim node` runs a --bodies grid scene (bench/make_grid_scene.py: octagons, gravity, wind, one
spring per body; dt = 1 ms) at --rate 1, i.e. 1,000 steps per wall second, publishing /clock and
the latched scene description and markers (--topics; the per-step body and spring states of 10,000
bodies, megabytes a step, are left out: they measure the network, not a spawn). A client on the
Python `cyclonedds` package (types declared here from the .srv files, as rmw_cyclonedds_cpp puts
them on the wire: none of rbsim's code) calls simulation_interfaces' spawn_entity --spawns times,
one call at a time (each waits for its reply), and reads /clock throughout.

Figures, each against the rate (the limit, 1 / dt steps per wall second) measured in the same run:
  * steps completed in every whole wall-clock second while spawning, from /clock (the simulated
    time of the last clock received in each second, minus that of the second before): the
    minimum over the rate must be >= 0.95; the same before the first spawn, for comparison;
  * wall time per call (median, p99, mean), as a fraction of the time between steps;
  * the node's CPU per spawn: its CPU time (/proc, every thread) while spawning, less its CPU per
    step without spawns times the steps it took meanwhile, over the spawns.
Exit status 1 when the minimum misses 0.95 or a spawn fails. Every wait is bounded; the script
runs this in a network namespace of its own (loopback only)."""
import argparse
import os
import random
import signal
import statistics
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass

TARGET = 0.95  # the slowest second's steps over the rate
TICK = os.sysconf("SC_CLK_TCK")
SETPRIV = next((p for p in ("/usr/bin/setpriv", "/bin/setpriv") if os.path.exists(p)), None)
FRAGMENT = ('<scene>\n  <rigidbodyvertex x="-0.1" y="0" m="1"/>\n  <rigidbodyvertex x="0.1" y="0" m="1"/>\n'
            '  <rigidbody p="0" p="1" vx="0.5" vy="0" omega="0" r="0.05"/>\n</scene>\n')


class Failure(Exception):
    pass


def types():
    """The IDL types of /clock and SpawnEntity's request and reply (the request header first)."""
    from cyclonedds.idl import IdlStruct
    import cyclonedds.idl.types as t

    @dataclass
    class Time_(IdlStruct, typename="builtin_interfaces::msg::dds_::Time_"):
        sec: t.int32
        nanosec: t.uint32

    @dataclass
    class Clock_(IdlStruct, typename="rosgraph_msgs::msg::dds_::Clock_"):
        clock: Time_

    @dataclass
    class Header_(IdlStruct, typename="std_msgs::msg::dds_::Header_"):
        stamp: Time_
        frame_id: str

    @dataclass
    class Point_(IdlStruct, typename="geometry_msgs::msg::dds_::Point_"):
        x: t.float64
        y: t.float64
        z: t.float64

    @dataclass
    class Quaternion_(IdlStruct, typename="geometry_msgs::msg::dds_::Quaternion_"):
        x: t.float64
        y: t.float64
        z: t.float64
        w: t.float64

    @dataclass
    class Pose_(IdlStruct, typename="geometry_msgs::msg::dds_::Pose_"):
        position: Point_
        orientation: Quaternion_

    @dataclass
    class PoseStamped_(IdlStruct, typename="geometry_msgs::msg::dds_::PoseStamped_"):
        header: Header_
        pose: Pose_

    @dataclass
    class Resource_(IdlStruct, typename="simulation_interfaces::msg::dds_::Resource_"):
        uri: str
        resource_string: str

    @dataclass
    class Result_(IdlStruct, typename="simulation_interfaces::msg::dds_::Result_"):
        result: t.uint8
        error_message: str

    @dataclass
    class SpawnEntity_Request_(IdlStruct, typename="simulation_interfaces::srv::dds_::SpawnEntity_Request_"):
        guid: t.uint64
        seq: t.int64
        name: str
        allow_renaming: bool
        entity_resource: Resource_
        entity_namespace: str
        initial_pose: PoseStamped_

    @dataclass
    class SpawnEntity_Response_(IdlStruct, typename="simulation_interfaces::srv::dds_::SpawnEntity_Response_"):
        guid: t.uint64
        seq: t.int64
        result: Result_
        entity_name: str

    def request(guid, seq, k, x, y):
        pose = PoseStamped_(Header_(Time_(0, 0), ""), Pose_(Point_(x, y, 0.0), Quaternion_(0.0, 0.0, 0.0, 1.0)))
        return SpawnEntity_Request_(guid, seq, f"spawned_{k}", False, Resource_("", FRAGMENT), "", pose)
    return Clock_, SpawnEntity_Request_, SpawnEntity_Response_, request


class Client:
    """/clock's reader and one rmw_cyclonedds-style spawn_entity client, waited on together."""

    def __init__(self, domain, ns):
        from cyclonedds.core import Listener, Policy, Qos, ReadCondition, SampleState, ViewState, InstanceState, WaitSet
        from cyclonedds.domain import DomainParticipant
        from cyclonedds.pub import DataWriter
        from cyclonedds.sub import DataReader
        from cyclonedds.topic import Topic
        from cyclonedds.util import duration
        clock_t, req_t, rep_t, self.make = types()
        self.dp = DomainParticipant(domain)
        self.guid, self.seq = random.getrandbits(63) | 1, 0
        matched = self.matched_counts = {"writer": 0, "reader": 0}  # the listeners hold the dict

        def on_pub(_w, status):
            matched["writer"] = status.current_count

        def on_sub(_r, status):
            matched["reader"] = status.current_count
        qos = Qos(Policy.Reliability.Reliable(duration(seconds=1)), Policy.History.KeepLast(10),
                  Policy.Durability.Volatile, Policy.Userdata(b"clientid=bench_node_spawn;"))
        self.writer = DataWriter(self.dp, Topic(self.dp, f"rq/{ns}/spawn_entityRequest", req_t), qos=qos,
                                 listener=Listener(on_publication_matched=on_pub))
        self.replies = DataReader(self.dp, Topic(self.dp, f"rr/{ns}/spawn_entityReply", rep_t), qos=qos,
                                  listener=Listener(on_subscription_matched=on_sub))
        self.clock = DataReader(self.dp, Topic(self.dp, "rt/clock", clock_t),
                                qos=Qos(Policy.Reliability.BestEffort, Policy.History.KeepLast(4096)))
        self.ws = WaitSet(self.dp)
        mask = SampleState.Any | ViewState.Any | InstanceState.Any
        for r in (self.replies, self.clock):
            self.ws.attach(ReadCondition(r, mask))
        self.duration = duration
        self.ticks = []  # (wall monotonic s at receipt, simulated ns)

    def matched(self):
        return self.matched_counts["writer"] > 0 and self.matched_counts["reader"] > 0

    def drain_clock(self):
        now = time.monotonic()
        for s in self.clock.take(N=4096):
            if hasattr(s, "clock"):
                self.ticks.append((now, s.clock.sec * 10**9 + s.clock.nanosec))

    def wait(self, seconds):
        self.ws.wait(self.duration(seconds=seconds))
        self.drain_clock()

    def idle(self, seconds):
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            self.wait(min(0.05, max(end - time.monotonic(), 0.0)))

    def spawn(self, k, timeout_s):
        """One call, waited for: (wall seconds, result code, error message)."""
        self.seq += 1
        seq, start = self.seq, time.perf_counter()
        cols = 100
        self.writer.write(self.make(self.guid, seq, k, 3.0 * (k % cols), -10.0 - 3.0 * (k // cols)))
        deadline = time.monotonic() + timeout_s
        while time.monotonic() < deadline:
            for r in self.replies.take(N=16):
                if getattr(r, "guid", None) == self.guid and r.seq == seq:
                    took = time.perf_counter() - start
                    self.drain_clock()
                    return took, r.result.result, r.result.error_message
            self.wait(0.05)
        raise Failure(f"spawn {k}: no reply within {timeout_s} s")


def proc_cpu_s(pid):
    with open(f"/proc/{pid}/stat") as f:
        fields = f.read().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / TICK


def per_second(ticks, start, end, dt_ns):
    """Steps completed in each whole wall second in [start, end): the last simulated time received
    in the second minus the last received before it, in steps."""
    out, k = [], 0
    last_before = None
    t = start
    while t + 1.0 <= end:
        while k < len(ticks) and ticks[k][0] < t:
            last_before = ticks[k][1]
            k += 1
        j, last = k, None
        while j < len(ticks) and ticks[j][0] < t + 1.0:
            last = ticks[j][1]
            j += 1
        if last_before is not None and last is not None:
            out.append((last - last_before) / dt_ns)
        t += 1.0
    return out


def start_node(a, scene, work, env):
    argv = [a.rbsim, "node", scene, "--rate", "1", "--topics", a.topics, "--namespace", a.ns,
            "--domain", str(a.domain), "--duration", "3600", "--quiet"]
    err = open(os.path.join(work, "node.stderr"), "w")
    node = subprocess.Popen(([SETPRIV, "--pdeathsig", "KILL"] if SETPRIV else []) + argv, env=env,
                            stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=err)
    return node, err


def sim_ns_at(ticks, t):
    """The last simulated time received before wall time t."""
    last = ticks[0][1]
    for wall, sim in ticks:
        if wall >= t:
            break
        last = sim
    return last


def measure(a, client, node, dt_ns):
    """Warm-up, a quiet window, then the spawns: the figures as a dict."""
    deadline = time.monotonic() + 60
    while not (client.matched() and len(client.ticks) > 2000):
        if time.monotonic() > deadline or node.poll() is not None:
            raise Failure(f"no spawn_entity server or /clock within 60 s (node {'running' if node.poll() is None else 'exited'})")
        client.wait(0.05)
    quiet_start, cpu0 = time.monotonic(), proc_cpu_s(node.pid)
    client.idle(a.quiet)
    quiet_end, cpu1 = time.monotonic(), proc_cpu_s(node.pid)
    calls, bad = [], []
    spawn_start = time.monotonic()
    for k in range(a.spawns):
        took, code, why = client.spawn(k, 60.0)
        calls.append(took)
        if code != 1:
            bad.append(f"spawn {k}: result {code} {why}")
        if time.monotonic() - spawn_start > a.max_seconds:
            raise Failure(f"{k + 1} spawns took over {a.max_seconds} s")
    spawn_end, cpu2 = time.monotonic(), proc_cpu_s(node.pid)
    client.idle(1.5)  # the last second's clocks arrive
    idle_rate = (cpu1 - cpu0) / (quiet_end - quiet_start)
    steps = [(sim_ns_at(client.ticks, t1) - sim_ns_at(client.ticks, t0)) / dt_ns
             for t0, t1 in ((quiet_start, quiet_end), (spawn_start, spawn_end))]
    per_step = (cpu1 - cpu0) / steps[0]
    return {
        "quiet": per_second(client.ticks, quiet_start, quiet_end, dt_ns),
        "spawning": per_second(client.ticks, spawn_start, spawn_end, dt_ns),
        "calls": calls, "bad": bad, "spawn_s": spawn_end - spawn_start, "idle_cores": idle_rate,
        "cpu_per_spawn": ((cpu2 - cpu1) - per_step * steps[1]) / a.spawns, "per_step": per_step,
        "cpu_raw_per_spawn": (cpu2 - cpu1) / a.spawns,
    }


def report(a, m, rate):
    step_us = 1e6 / rate
    calls = sorted(m["calls"])
    p99 = calls[min(len(calls) - 1, int(0.99 * len(calls)))]
    low = min(m["spawning"]) / rate if m["spawning"] else 0.0
    ok = low >= TARGET and not m["bad"] and m["spawning"]
    print(f"rbsim node, {a.bodies:,} bodies, {rate:.0f} steps/s (rate 1, dt {1e3 / rate:g} ms), "
          f"topics {a.topics}: {a.spawns:,} spawn_entity calls one at a time over {m['spawn_s']:.1f} s "
          f"(load average {os.getloadavg()[0]:.1f})")
    for name, secs in (("before spawning", m["quiet"]), ("while spawning", m["spawning"])):
        if secs:
            print(f"  steps/s {name:<16} min {min(secs):7.0f} = {min(secs) / rate:.3f}x rate, median "
                  f"{statistics.median(secs):7.0f} = {statistics.median(secs) / rate:.3f}x  ({len(secs)} whole seconds)")
    print(f"  wall per call         median {1e6 * statistics.median(calls):8.0f} us = "
          f"{1e6 * statistics.median(calls) / step_us:.2f} steps, p99 {1e6 * p99:8.0f} us, "
          f"mean {1e6 * statistics.mean(calls):8.0f} us")
    print(f"  node CPU per spawn    {1e6 * m['cpu_per_spawn']:8.0f} us = {1e6 * m['cpu_per_spawn'] / step_us:.2f} "
          f"steps' time ({1e6 * m['cpu_raw_per_spawn']:.0f} us before the steps' own are taken off: "
          f"{1e6 * m['per_step']:.0f} us each, {m['idle_cores']:.2f} cores at the rate)")
    print(f"  min steps/s while spawning / rate: {low:.3f}x (target >= {TARGET}: {'met' if ok else 'MISSED'})")
    if a.verbose:
        print("  steps in each second while spawning: " + " ".join(f"{s:.0f}" for s in m["spawning"]))
    for b in m["bad"][:5]:
        print(f"  {b}")
    return 0 if ok else 1


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rbsim", required=True)
    ap.add_argument("--root", required=True)
    ap.add_argument("--bodies", type=int, default=10000)
    ap.add_argument("--spawns", type=int, default=1000)
    ap.add_argument("--dt", type=float, default=0.001)
    ap.add_argument("--topics", default="clock,scene,markers")
    ap.add_argument("--quiet", type=float, default=5.0, help="wall seconds measured before the first spawn")
    ap.add_argument("--max-seconds", type=float, default=300.0, help="the spawns' bound")
    ap.add_argument("--domain", type=int, default=77)
    ap.add_argument("--ns", default="bench_spawn")
    ap.add_argument("--verbose", action="store_true", help="print every second's steps")
    a = ap.parse_args()
    work = tempfile.mkdtemp(prefix="bench-node-spawn-")
    scene = os.path.join(work, "grid.xml")
    with open(scene, "w") as f:
        subprocess.run([sys.executable, os.path.join(a.root, "bench", "make_grid_scene.py"), str(a.bodies),
                        repr(a.dt), "3600"], stdout=f, check=True)
    env = dict(os.environ, CYCLONEDDS_URI="file://" + os.path.join(a.root, "node", "config", "cyclonedds-loopback.xml"))
    for k in ("ROS_DOMAIN_ID", "ROS_AUTOMATIC_DISCOVERY_RANGE", "ROS_STATIC_PEERS", "ROS_LOCALHOST_ONLY"):
        env.pop(k, None)
    os.environ["CYCLONEDDS_URI"] = env["CYCLONEDDS_URI"]
    node, err = start_node(a, scene, work, env)
    status = 1
    try:
        client = Client(a.domain, a.ns)
        m = measure(a, client, node, round(a.dt * 1e9))
        status = report(a, m, 1.0 / a.dt)
    except Failure as e:
        print(f"scripts/bench-node-spawn: {e}", file=sys.stderr)
    finally:
        if node.poll() is None:
            node.send_signal(signal.SIGINT)
        try:
            node.wait(30)
        except subprocess.TimeoutExpired:
            node.kill()
            node.wait(10)
        err.close()
        if status != 0:
            sys.stderr.write(open(os.path.join(work, "node.stderr")).read()[-4000:])
        subprocess.run(["rm", "-rf", work], check=False)
    return status


if __name__ == "__main__":
    sys.exit(main())
