#!/usr/bin/env python3
"""ROS 2 interop with a client library that is not ours: rbsim's node seen by ros2-client (Rust,
on RustDDS) through rbsim-ros2-peer (test/ros2_peer/src/main.rs).

RustDDS multicasts discovery, so every case runs the peer and the node in two network namespaces
this test creates (e2e.py's TwoHosts: a veth pair, 10.231.0.1 <-> 10.231.0.2), never on a real
interface; inside them Cyclone DDS may multicast too (ros2-client finds participants by SPDP
multicast). Cases share e2e.py's harness (processes, domains, cleanup) and its exit codes:
0 pass, 1 fail, 77 skip (namespaces not permitted here).
"""
import json
import math
import os
import re
import shutil
import signal
import sys
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "e2e"))
import e2e  # noqa: E402

PEER = os.environ.get("RBSIM_ROS2_PEER", "")


def namespace_config(address):
    """Cyclone inside a test namespace: its one veth interface, multicast allowed (the namespace
    has no other interface: nothing leaves it)."""
    return f"""<?xml version="1.0" encoding="UTF-8"?>
<CycloneDDS xmlns="https://cdds.io/config">
  <Domain Id="any">
    <General>
      <Interfaces><NetworkInterface address="{address}" multicast="true"/></Interfaces>
      <AllowMulticast>spdp</AllowMulticast>
    </General>
    <Discovery><SPDPInterval>0.5 s</SPDPInterval></Discovery>
  </Domain>
</CycloneDDS>
"""


class PeerNet(e2e.TwoHosts):
    """TwoHosts with multicast routed onto each veth and Cyclone configured to use it."""

    def __enter__(self):
        super().__enter__()
        if self.skip:
            return self
        for ns, dev in ((self.a, self.va), (self.b, self.vb)):
            e2e.ip(self.ctx, "-n", ns, "link", "set", dev, "multicast", "on")
            e2e.ip(self.ctx, "-n", ns, "route", "add", "224.0.0.0/4", "dev", dev)
        with open(self.cfg_a, "w") as f:
            f.write(namespace_config("10.231.0.1"))
        return self

    def peer(self, name, *args, side="b"):
        """Starts rbsim-ros2-peer in namespace `side` (b unless said; a is the node's) on the case's domain."""
        env = self.ctx.env()
        env["ROS_DOMAIN_ID"] = str(self.ctx.domain)
        env.setdefault("RUST_LOG", "warn")
        ns = self.a if side == "a" else self.b
        return self.ctx.start(name, ["ip", "netns", "exec", ns, PEER, *map(str, args)], env=env)


def lines(proc):
    out = []
    for line in proc.stdout().splitlines():
        try:
            out.append(json.loads(line))
        except json.JSONDecodeError:
            pass
    return out


def with_node(ctx, body, *node_extra):
    """Runs `body(net, node)` with rbsim node looping a scene in namespace a at real time (more
    node options in `node_extra`); then stops the node (SIGINT, a clean exit within 30 s) unless
    `body` already did."""
    if not PEER or not os.access(PEER, os.X_OK):
        raise e2e.Failure(f"RBSIM_ROS2_PEER={PEER!r} is not an executable: build the rbsim_ros2_peer target")
    with PeerNet(ctx) as net:
        if net.skip:
            print(f"SKIP: {net.skip}")
            return e2e.SKIP
        node = net.rb("node-in-a", "a", *e2e.node_args(ctx, ctx.scene("chain.xml"), "--loop", *node_extra))
        try:
            body(net, node)
        finally:
            if node.alive():
                node.signal(signal.SIGINT)
                e2e.exited_ok(ctx, node, 30, "rbsim node after SIGINT")
    return 0


def case_tf(ctx):
    """ros2-client subscribes to /tf: every body's frame under world, in order, with positions."""
    def body(net, node):
        peer = net.peer("peer-tf", "tf", 20, "--timeout", 60)
        e2e.exited_ok(ctx, peer, 90, "rbsim-ros2-peer tf")
        got = [m for m in lines(peer) if "tf" in m]
        ctx.check(len(got) >= 20, f"peer printed {len(got)} /tf messages, want 20\n{peer.output()}")
        if got:
            ctx.log(f"ros2-client decoded /tf: {got[0]} ... {got[-1]}")
        # The values ros2-client decoded are the run's: body 0's position at each message's stamp
        # equals rbsim run --csv's at that time, bit for bit.
        last = max((m["stamp_ns"] for m in got), default=0)
        csv = ctx.path("chain.csv")
        ctx.rbrun("run-csv", "run", ctx.scene("chain.xml"), "--duration", last / 1e9 + 0.01, "--csv", csv)
        with open(csv) as f:
            rows = [r.split(",") for r in f.read().splitlines()[1:]]
        body0 = {round(float(r[1]) * 1e9): (float(r[3]), float(r[4])) for r in rows if r[2] == "0"}
        for m in got:
            want = body0.get(m["stamp_ns"])
            ctx.check(want == (m["x"], m["y"]),
                      f"/tf at {m['stamp_ns']} ns: body_0 at ({m['x']}, {m['y']}), rbsim run --csv says {want}")
        for m in got:
            ctx.check(m["frame"] == "world" and m["child"] == f"{ctx.ns}/body_0",
                      f"/tf frames {m['frame']} -> {m['child']}, want world -> {ctx.ns}/body_0")
            ctx.check(m["transforms"] > 0, f"/tf message with {m['transforms']} transforms")
    return with_node(ctx, body)


def case_graph(ctx):
    """ros2-client finds the node by its name in ros_discovery_info."""
    def body(net, node):
        peer = net.peer("peer-graph", "graph", f"/{ctx.ns}", "--timeout", 60)
        e2e.exited_ok(ctx, peer, 90, "rbsim-ros2-peer graph")
        found = [m for m in lines(peer) if m.get("node") == f"/{ctx.ns}"]
        ctx.check(bool(found), f"node /{ctx.ns} not in what ros2-client decoded\n{peer.output()}")
        for m in found[:1]:
            ctx.check(m["namespace"] == "/" and m["name"] == ctx.ns,
                      f"node namespace {m['namespace']!r} name {m['name']!r}, want '/' and {ctx.ns!r}")
    return with_node(ctx, body)


def case_rosout(ctx):
    """ros2-client reads the node's start line on /rosout (transient local: a late reader too)."""
    def body(net, node):
        peer = net.peer("peer-rosout", "rosout", "rbsim node:", "--timeout", 60)
        e2e.exited_ok(ctx, peer, 90, "rbsim-ros2-peer rosout")
        got = [m for m in lines(peer) if "rbsim node:" in m.get("rosout", "")]
        ctx.check(bool(got), f"no start line on /rosout\n{peer.output()}")
        for m in got[:1]:
            ctx.check(m["level"] == 20, f"start line level {m['level']}, want 20 (INFO)")
            ctx.check(m["name"] == ctx.ns, f"rosout name {m['name']!r}, want {ctx.ns!r}")
    return with_node(ctx, body)


def case_killed_peer(ctx):
    """A ros2-client subscriber killed (SIGKILL: it never says goodbye, and stays matched until its
    lease expires) while the node publishes reliably to it: Ctrl-C still ends the node at once,
    cleanly (exit 0), instead of after 30 s of blocked writes."""
    def body(net, node):
        peer = net.peer("peer-tf", "tf", 10**9, "--timeout", 120)
        peer.wait_for_text('"tf": 10,', 60)
        peer.signal(signal.SIGKILL)
        time.sleep(1.0)  # the node's writes now block on the dead reader's full window
        t0 = time.monotonic()
        node.signal(signal.SIGINT)
        rc = node.wait(30)
        took = time.monotonic() - t0
        ctx.check(rc == 0, f"node exited with {rc} after SIGINT (want 0)\n{node.output()}")
        ctx.check(took < 5, f"node took {took:.1f} s to stop after SIGINT (want < 5 s)")
        ctx.log(f"node stopped {took:.2f} s after SIGINT with its subscriber dead")
    return with_node(ctx, body)


def peer_json(ctx, net, name, *args, timeout=60):
    """Runs rbsim-ros2-peer to completion in namespace b; its JSON lines (exit 0 required)."""
    peer = net.peer(name, *args, "--timeout", timeout)
    e2e.exited_ok(ctx, peer, timeout + 30, f"rbsim-ros2-peer {' '.join(map(str, args))}")
    return lines(peer)


def case_parameters(ctx):
    """ros2-client lists, describes, gets and sets the node's parameters through the six
    rcl_interfaces services (ServiceMapping::Cyclone); a change goes out on /parameter_events and
    a bad set changes nothing."""
    def body(net, node):
        node_name = f"/{ctx.ns}"
        names = [m for m in peer_json(ctx, net, "list", "params", node_name, "list") if "list" in m]
        got = names[0]["list"] if names else []
        for want in ("scene", "dt", "integrator", "bodies", "springs", "steps", "rate", "publish_every", "paused",
                     "forces.0.fx", "forces.0.fy", "springs.0.k", "springs.0.l0", "use_sim_time"):
            ctx.check(want in got, f"list_parameters lacks {want}: {got}")
        desc = {m["describe"]: m for m in peer_json(ctx, net, "describe", "params", node_name, "describe", "dt", "rate",
                                                  "publish_every")}
        ctx.check(desc.get("dt", {}).get("read_only") is True, f"dt not read-only: {desc.get('dt')}")
        ctx.check(desc.get("rate", {}).get("type") == 3 and desc["rate"]["read_only"] is False,
                  f"rate not a writable double: {desc.get('rate')}")
        ctx.check(desc.get("publish_every", {}).get("integer_range", [[0]])[0][0] == 1,
                  f"publish_every's range does not start at 1: {desc.get('publish_every')}")
        types = {m["types"]: m["type"] for m in peer_json(ctx, net, "types", "params", node_name, "types", "dt",
                                                          "bodies", "paused", "scene")}
        ctx.check(types == {"dt": 3, "bodies": 2, "paused": 1, "scene": 4}, f"get_parameter_types: {types}")
        events = net.peer("events", "events", "forces.0.fy", "--timeout", 120)
        # The events subscription matched before the set it is to see: another parameter
        # (forces.0.fx, set back to 0 after) is set until its event reaches the subscriber. Not a
        # time: on a busy machine matching can take seconds. At most 10 tries of 2 s each.
        for k in range(10):
            peer_json(ctx, net, f"probe-{k}", "params", node_name, "set", f"forces.0.fx={0.125 * (k + 1)}")
            deadline = time.monotonic() + 2.0
            while time.monotonic() < deadline and events.alive() and \
                    not any(m.get("event") == "forces.0.fx" for m in lines(events)):
                time.sleep(0.05)
            if any(m.get("event") == "forces.0.fx" for m in lines(events)):
                break
        else:
            ctx.require(False, f"/parameter_events: no event reached the subscriber after 10 sets\n{events.output()}")
        peer_json(ctx, net, "probe-back", "params", node_name, "set", "forces.0.fx=0.0")
        sets = peer_json(ctx, net, "set", "params", node_name, "set", "forces.0.fy=-3.7", "rate=2")
        ctx.check([m.get("set") for m in sets] == [True, False],
                  f"set_parameters forces.0.fy=-3.7 (double) and rate=2 (integer for a double): {sets}")
        if len(sets) == 2:
            ctx.check("rate" in sets[1]["reason"], f"the refusal does not name the parameter: {sets[1]}")
        got = {m["get"]: m["value"] for m in peer_json(ctx, net, "get", "params", node_name, "get", "forces.0.fy",
                                                       "rate")}
        ctx.check(got.get("forces.0.fy") == {"double": -3.7} and got.get("rate") == {"double": 1.0},
                  f"after the set: {got}")
        atomic = peer_json(ctx, net, "atomic", "params", node_name, "set-atomic", "forces.0.fx=1.5", "dt=0.5")
        ctx.check([m.get("set-atomic") for m in atomic] == [False], f"atomic set with a read-only dt: {atomic}")
        got = {m["get"]: m["value"] for m in peer_json(ctx, net, "get2", "params", node_name, "get", "forces.0.fx")}
        ctx.check(got.get("forces.0.fx") == {"double": 0.0}, f"a refused atomic batch changed forces.0.fx: {got}")
        e2e.exited_ok(ctx, events, 90, "rbsim-ros2-peer events")
        ev = [m for m in lines(events) if m.get("event") == "forces.0.fy"]
        ctx.check(bool(ev) and ev[0]["value"] == {"double": -3.7} and ev[0]["node"] == node_name,
                  f"/parameter_events: {lines(events)}")
    return with_node(ctx, body)


def case_services(ctx):
    """pause, step N, resume and apply_impulse called by ros2-client: each reply names its step,
    and every published state equals an offline run with the same changes at those steps."""
    def body(net, node):
        svc = f"/{ctx.ns}"
        r = peer_json(ctx, net, "pause", "call", f"{svc}/pause", "trigger")
        ctx.check(r and r[0]["success"], f"pause: {r}")
        r = peer_json(ctx, net, "step-running", "call", f"{svc}/step", "step", 0)
        ctx.check(r and not r[0]["success"], f"step 0 accepted: {r}")
        r = peer_json(ctx, net, "step", "call", f"{svc}/step", "step", 5)
        ctx.check(r and r[0]["success"], f"step 5 while paused: {r}")
        r = peer_json(ctx, net, "impulse-bad", "call", f"{svc}/apply_impulse", "impulse", 999, 1, 0, 0, 0)
        ctx.check(r and not r[0]["success"] and "999" in r[0]["message"], f"impulse on body 999: {r}")
        r = peer_json(ctx, net, "impulse", "call", f"{svc}/apply_impulse", "impulse", 1, 0.5, 2.0, 0.1, 0.0)
        ctx.check(r and r[0]["success"], f"impulse on body 1: {r}")
        r = peer_json(ctx, net, "resume", "call", f"{svc}/resume", "trigger")
        ctx.check(r and r[0]["success"], f"resume: {r}")
        r = peer_json(ctx, net, "running-step", "call", f"{svc}/step", "step", 3)
        ctx.check(r and not r[0]["success"], f"step while running accepted: {r}")
    return with_node(ctx, body)


def recorded_node(ctx, net, scene, duration, live, expected, *node_extra):
    """`rbsim record` of `expected` messages into `live`, and `rbsim node` on `scene` waiting for it."""
    rec = net.rb("record", "a", *e2e.record_args(ctx, live, "--max-messages", expected, "--wall-duration", 120))
    node = net.rb("node", "a", *e2e.node_args(ctx, scene, "--duration", duration, "--wait-for-subscribers", 1,
                                              *node_extra))
    return rec, node


def case_steered(ctx):
    """A session steered by ros2-client (pause, a parameter, step N, an impulse, resume), each command
    on /NS/commands with its step, read back by ros2-client; the session recorded by
    `rbsim record` over DDS, equals `rbsim run --commands` with the same changes at the steps the
    replies name, every message; the run without them diverges first at the step after the first
    change."""
    if not PEER or not os.access(PEER, os.X_OK):
        raise e2e.Failure(f"RBSIM_ROS2_PEER={PEER!r} is not an executable: build the rbsim_ros2_peer target")
    scene, duration, dt = ctx.scene("chain.xml"), 6.0, 0.001
    steps = round(duration / dt)
    expected = len(e2e.LATCHED) + len(e2e.PER_STEP) * (steps + 1) + 5  # and the 5 commands
    live = ctx.path("live.mcap")
    with PeerNet(ctx) as net:
        if net.skip:
            print(f"SKIP: {net.skip}")
            return e2e.SKIP
        rec, node = recorded_node(ctx, net, scene, duration, live, expected)
        svc = f"/{ctx.ns}"
        try:
            pause = peer_json(ctx, net, "pause", "call", f"{svc}/pause", "trigger")
            ctx.require(pause and pause[0]["success"], f"pause: {pause}")
            s0 = int(pause[0]["message"].rsplit(" ", 1)[-1])  # "paused at step N"
            sets = peer_json(ctx, net, "set", "params", svc, "set-atomic", "forces.0.fy=-3.7")
            ctx.require([m.get("set-atomic") for m in sets] == [True], f"set forces.0.fy: {sets}")
            stepped = peer_json(ctx, net, "step", "call", f"{svc}/step", "step", 5)
            # The reply names the step the stepping ends at.
            ctx.require(stepped and stepped[0]["success"] and stepped[0]["step"] == s0 + 5, f"step 5 at {s0}: {stepped}")
            kick = peer_json(ctx, net, "impulse", "call", f"{svc}/apply_impulse", "impulse", 2, 0.5, 2.0, 0.1, 0.0)
            ctx.require(kick and kick[0]["success"], f"impulse: {kick}")
            s1 = kick[0]["step"]
            ctx.check(s1 == s0 + 5, f"the impulse applied at step {s1}, want {s0 + 5} (paused after step 5)")
            resume = peer_json(ctx, net, "resume", "call", f"{svc}/resume", "trigger")
            ctx.require(resume and resume[0]["success"], f"resume: {resume}")
            # Every command as data on /NS/commands, read by a late subscriber (transient local).
            got = peer_json(ctx, net, "commands", "commands", f"{svc}/commands", 5)
            want = [(0, 1, s0, 0), (1, 0, s0, 0), (2, 3, s0, 5), (3, 5, s1, 0), (4, 2, s1, 0)]  # seq, kind, step, steps
            ctx.check([(c["seq"], c["kind"], c["step"], c["steps"]) for c in got] == want,
                      f"/NS/commands: {got}, want (seq, kind, step, steps) {want}")
            ctx.check(all(c["success"] and c["source"] == "ros2 service" for c in got), f"/NS/commands: {got}")
            ctx.check(got[1:2] and got[1]["parameters"] == ["forces.0.fy"] and got[3]["body"] == 2
                      and got[3]["j"] == [0.5, 2.0] and got[3]["p"] == [0.1, 0.0], f"/NS/commands arguments: {got}")
        finally:
            e2e.exited_ok(ctx, node, 60, "rbsim node")
            e2e.exited_ok(ctx, rec, 60, "rbsim record")
    ctx.log(f"ros2-client paused at step {s0}, set forces.0.fy, stepped 5, kicked body 2 at step {s1}, resumed")
    script = ctx.path("commands.yaml")
    with open(script, "w") as f:
        f.write(f"- {{step: {s0}, pause: true}}\n- {{step: {s0}, set: {{forces.0.fy: -3.7}}}}\n"
                f"- {{step: {s0}, steps: 5}}\n"
                f"- {{step: {s1}, impulse: {{body: 2, j: [0.5, 2.0], p: [0.1, 0.0]}}}}\n"
                f"- {{step: {s1}, resume: true}}\n")
    rerun, plain = ctx.path("rerun.mcap"), ctx.path("plain.mcap")
    ctx.rbrun("rerun", "run", scene, "--duration", duration, "--commands", script, "--record", rerun,
              "--namespace", ctx.ns)
    ctx.rbrun("plain", "run", scene, "--duration", duration, "--record", plain, "--namespace", ctx.ns)
    e2e.rbsim_check(ctx, live, rerun, "check-rerun", live=True)
    # The recording re-simulated from its own commands: every message equal, commands included.
    again = ctx.path("again.mcap")
    ctx.rbrun("again", "run", scene, "--duration", duration, "--commands", live, "--record", again, "--namespace", ctx.ns)
    e2e.rbsim_check(ctx, live, again, "check-again", live=True)
    e2e.rbsim_check(ctx, again, rerun, "check-again-rerun", live=False)
    # Against the run without the changes: the commands are the first divergence; the states first
    # differ at the step after the first change.
    rc, out, err = ctx.rbrun("check-plain", "check", live, plain, "--ignore-log-time", ok=False)
    ctx.check(rc == 1, f"the live session matched the run without its changes (exit {rc})\n{out}{err}")
    ctx.check(f"first divergence: topic /{ctx.ns}/commands" in out, f"the commands are not the first divergence\n{out}")
    rc, out, err = ctx.rbrun("check-states", "check", live, plain, "--ignore-log-time", "--topics", "body_states",
                             ok=False)
    ctx.check(rc == 1 and f"body_states, step {s0 + 1}," in out, f"the states do not first differ at step {s0 + 1}\n{out}")
    return 0


# ---------------------------------------------------------------------------------------------
# Hostile clients (issue 22 point 4), all through ros2-client


def end_line(ctx, node):
    """(service calls received, dropped) from the node's end line (tools/cli/node.cpp)."""
    for line in node.stderr().splitlines():
        m = re.search(r"rbsim node: (?:stopped|done) after .*, (\d+) service calls?(?: \((\d+) dropped\))?, ", line)
        if m:
            return int(m.group(1)), int(m.group(2) or 0)
    ctx.check(False, f"no end line counting service calls\n{node.output()}")
    return None, None


def stop_node(ctx, node):
    """SIGINT: a clean exit within 30 s; its end line's (received, dropped)."""
    node.signal(signal.SIGINT)
    e2e.exited_ok(ctx, node, 30, "rbsim node after SIGINT")
    return end_line(ctx, node)


def sim_rate(tf, t0, t1, span=1.0):
    """The slowest pace of simulated time against wall time over any `span` seconds of the /tf lines
    received between wall times t0 and t1 (ns): simulated seconds per wall second (a node that
    stalls and then catches up shows the stall), and how many lines there were."""
    got = [m for m in tf if t0 <= m.get("wall_ns", -1) <= t1]
    worst, j = None, 0
    for i, m in enumerate(got):
        while j < len(got) and got[j]["wall_ns"] - m["wall_ns"] < span * 1e9:
            j += 1
        if j == len(got):
            break
        rate = (got[j]["stamp_ns"] - m["stamp_ns"]) / (got[j]["wall_ns"] - m["wall_ns"])
        worst = rate if worst is None else min(worst, rate)
    return worst, len(got)


FLOOD = (("resume", "trigger"), ("get_parameters", "get"), ("step", "step"))  # (service, peer kind)
FLOOD_CALLS = 500


def case_flood(ctx):
    """Three ros2-client peers at once each send 500 requests back to back without waiting (resume,
    get_parameters, step while running; after one answered call, so their writer is matched), with
    request and reply QoS deep enough that nothing is lost on their side: every request reaches the node and is answered once or dropped by the
    node's bounded queue (its end line counts both), the node keeps real time meanwhile (its /tf
    stamps against their wall arrival), a normal call right after is answered, Ctrl-C ends it."""
    def body(net, node):
        svc = f"/{ctx.ns}"
        tf = net.peer("peer-tf", "tf", 10**9, "--timeout", 120)
        tf.wait_for_text('"tf": 10,', 60)
        floods = [net.peer(f"flood-{name}", "flood", f"{svc}/{name}", kind, FLOOD_CALLS, "--timeout", 30)
                  for name, kind in FLOOD]
        got = {}
        for (name, _), p in zip(FLOOD, floods):
            e2e.exited_ok(ctx, p, 90, f"rbsim-ros2-peer flood {name}")
            r = [m for m in lines(p) if "flood" in m]
            if ctx.check(len(r) == 1, f"flood {name} printed {len(r)} results\n{p.output()}"):
                got[name] = r[0]
                ctx.log(f"flood {name}: {r[0]}")
        time.sleep(0.5)
        tf.signal(signal.SIGTERM)
        tf.wait(10)
        ctx.require(len(got) == len(FLOOD), "a flood peer gave no result")
        for name, r in got.items():
            ctx.check(r["sent"] == FLOOD_CALLS and r["send_errors"] == 0,
                      f"flood {name}: sent {r['sent']} of {FLOOD_CALLS} ({r['send_errors']} send errors)")
            ctx.check(0 < r["answered"] <= r["sent"], f"flood {name}: {r['answered']} answered of {r['sent']}")
            ctx.check(r["duplicates"] == 0 and r["unknown"] == 0,
                      f"flood {name}: {r['duplicates']} duplicate replies, {r['unknown']} to requests never sent")
        # What each answer says: resume while running succeeds ("already running"), step while
        # running never does, every get_parameters reply holds the one value asked for.
        ctx.check(got["resume"]["successes"] == got["resume"]["answered"], f"resume replies: {got['resume']}")
        ctx.check(got["step"]["successes"] == 0, f"step while running accepted: {got['step']}")
        ctx.check(got["get_parameters"]["successes"] == got["get_parameters"]["answered"],
                  f"get_parameters replies: {got['get_parameters']}")
        t0 = min(r["start_ns"] for r in got.values())
        t1 = max(r["end_ns"] for r in got.values())
        rate, n = sim_rate(lines(tf), t0, t1)
        ctx.log(f"during the flood ({(t1 - t0) / 1e9:.2f} s, {n} /tf messages): at worst {rate} simulated s "
                f"per wall s over 1 s")
        ctx.check(rate is not None and rate >= 0.8,
                  f"the node fell behind real time during the flood: {rate} simulated s per wall s over 1 s "
                  f"at worst ({n} /tf)")
        r = peer_json(ctx, net, "after", "call", f"{svc}/resume", "trigger")
        ctx.check(r and r[0]["success"], f"resume right after the flood: {r}")
        values = {m["get"]: m["value"] for m in peer_json(ctx, net, "after-get", "params", svc, "get", "rate")}
        ctx.check(values.get("rate") == {"double": 1.0}, f"get_parameters right after the flood: {values}")
        received, dropped = stop_node(ctx, node)
        if received is None:
            return
        sent = sum(r["sent"] + r["probes"] for r in got.values())
        answered = sum(r["answered"] + 1 for r in got.values())  # a probe's one reply is the last of them
        ctx.log(f"node: {received} service calls, {dropped} dropped; peers: {sent} sent, {answered} answered")
        ctx.check(received == sent + 2, f"the node received {received} requests, the peers sent {sent} + 2")
        ctx.check(dropped > 0, f"the node dropped none of {received} requests: its queue bound was never reached")
        ctx.check(answered + dropped == sent,
                  f"{answered} answered + {dropped} dropped != {sent} sent: a request went neither way")
        ctx.check(all(r["probes"] == 1 for r in got.values()), f"a probe was not answered at once: {got}")
    return with_node(ctx, body, "--publish-every", 10)


def peer_no_reply(ctx, net, name, *args, timeout=8):
    """A call that must get no reply: the peer gives up after `timeout` (exit 1, "no reply")."""
    peer = net.peer(name, *args, "--timeout", timeout)
    rc = peer.wait(timeout + 30)
    ctx.check(rc == 1 and "no reply within" in peer.stderr(), f"{' '.join(map(str, args))}: want no reply\n"
              f"{peer.output()}")


def case_bad_requests(ctx):
    """Every bad request of issue 22 through ros2-client: an unknown body, NaN and inf in an
    impulse, step while running, step 0, step past the run's last step, and requests shorter than
    their type (the node receives truncated CDR): each gets an unsuccessful reply naming the
    problem, or none (a parameter request has no field to say so), the node never stops, and good
    calls after them are answered."""
    def body(net, node):
        svc = f"/{ctx.ns}"

        def refused(name, service, *args, says=""):
            r = peer_json(ctx, net, name, "call", f"{svc}/{service}", *args)
            ctx.check(r and not r[0]["success"] and says in r[0]["message"],
                      f"{service} {' '.join(map(str, args))}: want a refusal saying {says!r}, got {r}")
            ctx.check(node.alive(), f"the node stopped after {name}\n{node.output()}")
        refused("unknown-body", "apply_impulse", "impulse", 999, 1, 0, 0, 0, says="no body 999")
        refused("nan", "apply_impulse", "impulse", 1, "NaN", 0, 0, 0, says="finite")
        refused("inf", "apply_impulse", "impulse", 1, 0, 0, "inf", 0, says="finite")
        refused("step-running", "step", "step", 3, says="only while paused")
        refused("short-impulse", "apply_impulse", "impulse-short", 1, says="malformed or truncated")
        refused("short-step-running", "step", "step-short", says="malformed or truncated")
        peer_no_reply(ctx, net, "short-get", "call", f"{svc}/get_parameters", "get-short")
        ctx.check(node.alive(), f"the node stopped after a truncated get_parameters\n{node.output()}")
        r = peer_json(ctx, net, "pause", "call", f"{svc}/pause", "trigger")
        ctx.check(r and r[0]["success"], f"pause: {r}")
        refused("step-0", "step", "step", 0, says="must be >= 1")
        refused("step-past", "step", "step", 4_000_000_000, says="past the run's last step")
        refused("short-step", "step", "step-short", says="malformed or truncated")
        # Good calls are still answered, and do what they say.
        r = peer_json(ctx, net, "step", "call", f"{svc}/step", "step", 5)
        ctx.check(r and r[0]["success"], f"step 5 after the bad requests: {r}")
        r = peer_json(ctx, net, "impulse", "call", f"{svc}/apply_impulse", "impulse", 1, 0.5, 2.0, 0.1, 0.0)
        ctx.check(r and r[0]["success"], f"impulse after the bad requests: {r}")
        values = {m["get"]: m["value"] for m in peer_json(ctx, net, "get", "params", svc, "get", "rate", "paused")}
        ctx.check(values == {"rate": {"double": 1.0}, "paused": True}, f"get_parameters after the bad requests: {values}")
        r = peer_json(ctx, net, "resume", "call", f"{svc}/resume", "trigger")
        ctx.check(r and r[0]["success"], f"resume: {r}")
        received, dropped = stop_node(ctx, node)
        ctx.check(received == 15 and dropped == 1,
                  f"end line: {received} service calls ({dropped} dropped), want 15 (1 dropped: the truncated get)")
    return with_node(ctx, body)


def case_killed_client(ctx):
    """Clients that send requests and are SIGKILLed before they read a reply, while the node runs
    and while it is paused with a `step` in progress: a fresh client is answered promptly after
    each, the node goes on stepping and ends on Ctrl-C."""
    def body(net, node):
        svc = f"/{ctx.ns}"

        sent = []

        def killed(name, service, kind, n):
            p = net.peer(name, "send", f"{svc}/{service}", kind, n, "--timeout", 60)
            p.wait_for_text('"sent"', 60)
            p.signal(signal.SIGKILL)
            p.wait(10)
            sent.extend(m["sent"] + m["probes"] for m in lines(p) if "sent" in m)

        def fresh(name, service="pause"):
            r = peer_json(ctx, net, name, "call", f"{svc}/{service}", "trigger")
            ctx.check(r and r[0]["success"] and r[0]["took_ms"] < 1000,
                      f"{service} from a fresh client after killed ones: want a prompt success, got {r}")
            return r[0]["message"] if r else ""
        for name, service, kind, n in (("get", "get_parameters", "get", 200), ("resume", "resume", "trigger", 100),
                                       ("step", "step", "step", 100)):
            killed(f"killed-{name}", service, kind, n)
        fresh("fresh-running", "resume")
        fresh("pause")
        r = peer_json(ctx, net, "step", "call", f"{svc}/step", "step", 30000)  # 30 s at --rate 1
        ctx.check(r and r[0]["success"], f"step 30000 while paused: {r}")
        at = r[0]["step"] - 30000 if r else 0  # the reply names where the stepping ends
        for name, service, kind, n in (("step-paused", "step", "step", 50), ("pause-paused", "pause", "trigger", 50),
                                       ("get-paused", "get_parameters", "get", 100)):
            killed(f"killed-{name}", service, kind, n)
        # While the step is in progress, a fresh pause ("already paused at step K") names a later
        # step each time: the node steps on.
        first = re.search(r"step (\d+)", fresh("fresh-stepping-1"))
        time.sleep(0.5)
        second = re.search(r"step (\d+)", fresh("fresh-stepping-2"))
        ctx.check(first and second and at < int(first.group(1)) < int(second.group(1)),
                  f"not stepping after killed clients: step call at {at}, then {first and first.group(0)}, "
                  f"{second and second.group(0)}")
        fresh("resume-after", "resume")
        tf = peer_json(ctx, net, "tf", "tf", 20)
        stamps = [m["stamp_ns"] for m in tf if "tf" in m]
        ctx.check(len(stamps) == 20 and stamps == sorted(stamps) and stamps[-1] > stamps[0],
                  f"/tf after resuming: {stamps}")
        received, dropped = stop_node(ctx, node)
        ctx.log(f"end line: {received} service calls, {dropped} dropped; the killed clients sent {sum(sent)}")
        # The killed clients' requests reached the node (most of them: a client killed right after
        # its last write may take some of them with it), 7 calls besides.
        ctx.check(len(sent) == 6 and received is not None and sum(sent) // 2 + 7 <= received <= sum(sent) + 7,
                  f"the node counted {received} service calls; the killed clients sent {sent}, and 7 more")
    return with_node(ctx, body)


# ---------------------------------------------------------------------------------------------
# simulation_interfaces 2.1.0 and get_type_description (issue 37), through ros2-client


SIM_FEATURES = {0, 1, 5, 6, 8, 9, 10, 11, 12, 20, 23, 24, 25, 26, 31, 32, 33, 40, 41, 43, 44, 45, 50}  # the README's list, by value
OK, UNSUPPORTED, NOT_FOUND, FAILED = 1, 0, 2, 4  # simulation_interfaces/msg/Result
ALREADY, INCORRECT = 101, 103  # SetSimulationState's own codes
STOPPED, PLAYING, PAUSED = 0, 1, 2
DT_NS = 1_000_000  # chain.xml's dt, 0.001 s


def sim(ctx, net, name, *ops, timeout=90):
    """Runs the ops (lists of words) in one rbsim-ros2-peer `sim` process; its JSON lines, one per op."""
    words = []
    for k, o in enumerate(ops):
        words += ([","] if k else []) + [str(w) for w in o]
    got = {m["op"]: m for m in peer_json(ctx, net, name, "sim", f"/{ctx.ns}", *words, timeout=timeout) if "op" in m}
    ctx.require(sorted(got) == list(range(len(ops))), f"sim {name}: {len(got)} answers to {len(ops)} ops: {got}")
    return [got[k] for k in range(len(ops))]


def csv_rows(ctx, name, scene, steps):
    """`rbsim run --csv` of `scene` for `steps` steps: {(step, body): row} (step,t,body,x,y,theta,vx,vy,omega,...)."""
    path = ctx.path(f"{name}.csv")
    ctx.rbrun(name, "run", scene, "--steps", steps, "--csv", path)
    with open(path) as f:
        return {(int(r[0]), int(r[2])): r for r in (line.split(",") for line in f.read().splitlines()[1:])}


def same_as_csv(ctx, what, reply, rows):
    """Every entity state of a GetEntitiesStates reply equal, value for value, to the CSV row of its
    body at the step its stamp names: pose (x, y, 0) and (0, 0, sin(theta/2), cos(theta/2)), twist
    (vx, vy, 0; 0, 0, omega), frame world. The step it names."""
    states = reply["states"]
    ctx.require(reply["result"] == OK and states, f"{what}: {reply}")
    step = states[0]["stamp_ns"] // DT_NS
    bad = []
    for name, st in zip(reply["entities"], states):
        i = int(name.removeprefix("body_"))
        r = rows.get((step, i))
        if r is None:
            bad.append(f"{name}: no CSV row at step {step}")
            continue
        x, y, theta, vx, vy, omega = (float(v) for v in r[3:9])
        want = {"stamp_ns": round(float(r[1]) * 1e9), "frame": "world", "position": [x, y, 0.0],
                "orientation": [0.0, 0.0, math.sin(0.5 * theta), math.cos(0.5 * theta)],
                "linear": [vx, vy, 0.0], "angular": [0.0, 0.0, omega]}
        got = {k: st[k] for k in want}
        if got != want:
            bad.append(f"{name} at step {step}: {got} != rbsim run --csv's {want}")
    ctx.check(len(states) == len({b for (_, b) in rows}) and not bad,
              f"{what}: {len(states)} states; differences: {bad[:3]}")
    ctx.log(f"{what}: {len(states)} entity states at step {step} equal to rbsim run --csv's, value for value")
    return step


def expect(ctx, got, op, **want):
    """Checks the fields of op `op`'s answer."""
    m = got[op]
    ctx.check(all(m.get(k) == v for k, v in want.items()), f"op {op} ({m.get('verb')}): want {want}, got {m}")
    return m


def case_simulation_state(ctx):
    """simulation_interfaces through ros2-client: GetSimulatorFeatures lists exactly the README's
    features, each listed interface answers and the unlisted ones (tags and convex-hull filters,
    reset scopes TIME, STATE alone, set_acceleration) answer RESULT_FEATURE_UNSUPPORTED;
    pause, StepSimulation of N and of 1 (each answered at the step reached: the next state read
    names it), play; STOPPED (step 0) then play starts the world again from step 0 (the states
    equal `rbsim run --csv`'s at the step they name); reset scopes; every SetSimulationState code."""
    def body(net, node):
        box = ("box", -0.05, -0.05, 0, 0.05, 0.05, 0)  # around body_0's first vertex at step 0, no other body
        ops = [("features",), ("state",), ("set-state", PLAYING), ("step", 5), ("set-state", PAUSED), ("state",),
               ("entity", "body_0"), ("step", 25), ("entity", "body_0"), ("step", 1), ("entity", "body_0"),
               ("step", 0), ("set-state", PLAYING), ("state",), ("set-state", STOPPED), ("state",),
               ("states", "all"), ("set-state", STOPPED), ("set-state", PLAYING), ("set-state", PAUSED),
               ("states", "all"),
               ("reset", 1), ("reset", 2), ("reset", 4), ("step", 10), ("reset", 3), ("entity", "body_0"),
               ("state",), ("step", 10), ("reset", 0), ("entity", "body_0"), ("step", 10), ("reset", 255),
               ("entity", "body_0"),
               ("set-state", 4), ("set-state", 5), ("set-state", 9),
               ("bounds", "body_0"), ("info", "body_0"), ("entities", "all"), ("entities", "category", 4),
               ("entities", "category", 1), ("entities", *box), ("entities", "regex", "^body_1$"),
               ("entities", "tags", "x"), ("entities", "hull"), ("entity", "nobody"),
               ("set-entity", "body_0", "accel"), ("set-state", PLAYING), ("state",)]
        g = sim(ctx, net, "sim", *ops)
        ctx.check(set(g[0]["features"]) == SIM_FEATURES and len(g[0]["features"]) == len(SIM_FEATURES),
                  f"features {g[0]['features']}, want {sorted(SIM_FEATURES)}")
        expect(ctx, g, 1, state=PLAYING, result=OK)
        expect(ctx, g, 2, result=ALREADY)
        expect(ctx, g, 3, result=FAILED)  # StepSimulation while playing
        expect(ctx, g, 4, result=OK)
        expect(ctx, g, 5, state=PAUSED)
        s0 = g[6]["state"]["stamp_ns"] // DT_NS
        expect(ctx, g, 7, result=OK)
        ctx.check(g[8]["state"]["stamp_ns"] == (s0 + 25) * DT_NS, f"paused at step {s0}, stepped 25: {g[8]}")
        expect(ctx, g, 9, result=OK)
        ctx.check(g[10]["state"]["stamp_ns"] == (s0 + 26) * DT_NS, f"then 1 step more: {g[10]}")
        expect(ctx, g, 11, result=FAILED)  # 0 steps
        expect(ctx, g, 12, result=OK)
        expect(ctx, g, 13, state=PLAYING)
        expect(ctx, g, 14, result=OK)
        expect(ctx, g, 15, state=STOPPED)
        expect(ctx, g, 17, result=ALREADY)
        expect(ctx, g, 18, result=OK)
        expect(ctx, g, 19, result=OK)
        stopped = [st["stamp_ns"] for st in g[16]["states"]]
        ctx.check(stopped and set(stopped) == {0}, f"STOPPED: states stamped {set(stopped)}, want step 0 only")
        s1 = g[20]["states"][0]["stamp_ns"] // DT_NS
        rows = csv_rows(ctx, "csv", ctx.scene("chain.xml"), max(s1, 1))
        same_as_csv(ctx, "STOPPED", g[16], rows)
        # Played from step 0 after STOPPED: at the step it then paused at, the world is the one
        # `rbsim run` reaches from the scene (it did not go on from where it had been).
        same_as_csv(ctx, "STOPPED, played, paused", g[20], rows)
        for k in (21, 22):
            expect(ctx, g, k, result=UNSUPPORTED)  # SCOPE_TIME, SCOPE_STATE alone
        expect(ctx, g, 23, result=OK)  # SCOPE_SPAWNED: nothing was spawned, nothing changes
        expect(ctx, g, 24, result=OK)
        for k in (25, 29, 32):
            expect(ctx, g, k, result=OK)  # TIME | STATE, DEFAULT, ALL: a full reset
            ctx.check(g[k + 1]["state"]["stamp_ns"] == 0, f"after reset scope {ops[k][1]}: {g[k + 1]}")
        expect(ctx, g, 27, state=PAUSED)  # paused as before
        for k in (34, 35, 36):
            expect(ctx, g, k, result=INCORRECT)  # NO_WORLD, LOADING_WORLD, an unknown state
        b = expect(ctx, g, 37, result=OK, type=1)
        ctx.check(len(b.get("points", [])) == 2, f"bounds: {b}")
        expect(ctx, g, 38, result=OK, category=4)
        everyone = g[39]["entities"]
        ctx.check(everyone == [f"body_{i}" for i in range(len(everyone))] and len(everyone) == len(g[16]["states"]),
                  f"entities: {everyone}")
        expect(ctx, g, 40, result=OK, entities=everyone)
        expect(ctx, g, 41, result=OK, entities=[])
        expect(ctx, g, 42, result=OK, entities=["body_0"])
        expect(ctx, g, 43, result=OK, entities=["body_1"])
        expect(ctx, g, 44, result=UNSUPPORTED)  # ENTITY_TAGS not listed
        expect(ctx, g, 45, result=UNSUPPORTED)  # ENTITY_BOUNDS_CONVEX not listed
        expect(ctx, g, 46, result=NOT_FOUND)
        expect(ctx, g, 47, result=UNSUPPORTED)  # set_acceleration
        expect(ctx, g, 48, result=OK)
        expect(ctx, g, 49, state=PLAYING)
    return with_node(ctx, body)


def case_simulate_steps(ctx):
    """The SimulateSteps action through ros2-client's ActionClient (rcl_action's protocol): a goal
    while playing and one of 0 steps rejected; a goal accepted while paused, its feedback
    (completed + remaining = steps, never going back, the last at the end), SUCCEEDED with
    RESULT_OK, the world at the step reached; a goal cancelled mid-way ends CANCELED, its result's
    message says how many steps ran, and the world is paused exactly that many steps on."""
    def body(net, node):
        g = sim(ctx, net, "sim", ("goal", 100), ("set-state", PAUSED), ("entity", "body_0"), ("goal", 0),
                ("goal", 300), ("entity", "body_0"), ("goal", 50000, "cancel-after", 150), ("entity", "body_0"),
                ("state",), ("set-state", PLAYING))
        expect(ctx, g, 0, accepted=False)  # not paused
        s0 = g[2]["state"]["stamp_ns"] // DT_NS
        expect(ctx, g, 3, accepted=False)  # 0 steps
        done = expect(ctx, g, 4, accepted=True, status="SUCCEEDED", result=OK)
        fb = done.get("feedback", [])
        ctx.check(fb and fb[-1] == [300, 0] and all(a + b == 300 for a, b in fb)
                  and all(x[0] <= y[0] for x, y in zip(fb, fb[1:])), f"feedback of a 300-step goal: {fb}")
        ctx.check(g[5]["state"]["stamp_ns"] == (s0 + 300) * DT_NS, f"at step {s0}, 300 steps: {g[5]}")
        cut = expect(ctx, g, 6, accepted=True, status="CANCELED", result=OK)
        ran = re.search(r"(\d+) steps?", cut.get("message", ""))
        ctx.check(ran is not None and cut.get("cancel", {}).get("return_code") == 0
                  and cut["cancel"]["canceling"] == 1, f"cancelled goal: {cut}")
        if ran and "cancel" in cut:
            n = int(ran.group(1))
            ctx.check(cut["cancel"]["after"] <= n < 50000, f"{n} steps ran, cancelled after {cut['cancel']['after']}")
            ctx.check(g[7]["state"]["stamp_ns"] == (s0 + 300 + n) * DT_NS and f"step {s0 + 300 + n}" in cut["message"],
                      f"the result says {n} steps ran from step {s0 + 300}: {g[7]}")
            ctx.log(f"cancelled after {cut['cancel']['after']} steps reported: {cut['message']!r}, "
                    f"{len(cut['feedback'])} feedback messages")
        ctx.check(cut.get("feedback") and all(a + b == 50000 for a, b in cut["feedback"]), f"feedback: {cut}")
        ctx.check(done.get("status_topic") == "SUCCEEDED" and cut.get("status_topic") == "CANCELED",
                  f"status topic: {done.get('status_topic')}, {cut.get('status_topic')}")
        expect(ctx, g, 8, state=PAUSED)
        expect(ctx, g, 9, result=OK)
    return with_node(ctx, body)


def case_entities(ctx):
    """GetEntitiesStates equal, value for value, to `rbsim run --csv` at the step the reply names;
    SetEntityState on a moving body while paused (read back at once; refusals INVALID_POSE,
    NOT_FOUND, FEATURE_UNSUPPORTED change nothing), step, play; the session `rbsim record` recorded
    re-simulated by `rbsim run --commands` equals it, every message, and differs from the run
    without the set from the step after it."""
    if not PEER or not os.access(PEER, os.X_OK):
        raise e2e.Failure(f"RBSIM_ROS2_PEER={PEER!r} is not an executable: build the rbsim_ros2_peer target")
    scene, duration = ctx.scene("chain.xml"), 8.0  # the peer pauses it well before its end
    steps = round(duration * 1e9 / DT_NS)
    commands = 4  # pause, set_entity_state, step, resume (the refused sets are no commands)
    expected = len(e2e.LATCHED) + len(e2e.PER_STEP) * (steps + 1) + commands
    live = ctx.path("live.mcap")
    theta = 0.3
    q = (0, 0, math.sin(0.5 * theta), math.cos(0.5 * theta))
    with PeerNet(ctx) as net:
        if net.skip:
            print(f"SKIP: {net.skip}")
            return e2e.SKIP
        rec, node = recorded_node(ctx, net, scene, duration, live, expected)
        try:
            g = sim(ctx, net, "sim", ("set-state", PAUSED), ("states", "all"), ("entity", "body_3"),
                    ("set-entity", "body_3", "pose", 3.5, -0.1, *q, "twist", 0.75, -0.5, 1.5), ("entity", "body_3"),
                    ("set-entity", "body_3", "pose", 0, 0, 0, 0, 0.6, 0.6),
                    ("set-entity", "body_3", "pose", 0, 0, 0.6, 0, 0, 0.8),
                    ("set-entity", "body_3", "pose", 0, 0, 0, 0, 0, "nan"),
                    ("set-entity", "nobody", "twist", 0, 0, 0), ("set-entity", "body_3", "twist", 0, 0, 0, "accel"),
                    ("entity", "body_3"), ("step", 5), ("entity", "body_3"), ("set-state", PLAYING))
        finally:
            e2e.exited_ok(ctx, node, 60, "rbsim node")
            e2e.exited_ok(ctx, rec, 60, "rbsim record")
    expect(ctx, g, 0, result=OK)
    s0 = g[1]["states"][0]["stamp_ns"] // DT_NS if g[1].get("states") else 0
    rows = csv_rows(ctx, "csv", scene, max(s0, 1))
    same_as_csv(ctx, "paused", g[1], rows)
    moving = g[2]["state"]
    ctx.check(moving["stamp_ns"] == s0 * DT_NS and any(v != 0 for v in moving["linear"]), f"body_3 moving: {moving}")
    expect(ctx, g, 3, result=OK)
    got = g[4]["state"]
    ctx.check(got["stamp_ns"] == s0 * DT_NS and got["position"] == [3.5, -0.1, 0.0] and got["linear"] == [0.75, -0.5, 0.0]
              and got["angular"] == [0.0, 0.0, 1.5] and all(abs(a - b) < 1e-15 for a, b in zip(got["orientation"], q)),
              f"body_3 read right after the set: {got}")
    for k in (5, 6, 7):
        expect(ctx, g, k, result=101)  # INVALID_POSE: not unit, not about z, not finite
    expect(ctx, g, 8, result=NOT_FOUND)
    expect(ctx, g, 9, result=UNSUPPORTED)
    ctx.check(g[10]["state"] == got, f"a refused set changed body_3: {g[10]['state']} != {got}")
    expect(ctx, g, 11, result=OK)
    ctx.check(g[12]["state"]["stamp_ns"] == (s0 + 5) * DT_NS, f"5 steps from {s0}: {g[12]}")
    expect(ctx, g, 13, result=OK)
    # The recording re-simulated from its own commands: every message equal, commands included.
    again, plain = ctx.path("again.mcap"), ctx.path("plain.mcap")
    ctx.rbrun("again", "run", scene, "--duration", duration, "--commands", live, "--record", again, "--namespace", ctx.ns)
    e2e.rbsim_check(ctx, live, again, "check-again", live=True)
    ctx.rbrun("plain", "run", scene, "--duration", duration, "--record", plain, "--namespace", ctx.ns)
    rc, out, err = ctx.rbrun("check-states", "check", live, plain, "--ignore-log-time", "--topics", "body_states",
                             ok=False)
    ctx.check(rc == 1 and f"body_states, step {s0 + 1}," in out,
              f"the states without the set do not first differ at step {s0 + 1}\n{out}{err}")
    return 0


BALL = ('<scene>\n  <rigidbodyvertex x="-0.1" y="0" m="1"/>\n  <rigidbodyvertex x="0.1" y="0" m="1"/>\n'
        '  <rigidbody p="0" p="1" vx="0.5" vy="0" omega="0" r="0.05"/>\n</scene>\n')


def case_spawn(ctx):
    """SpawnEntity (three fragments as resource_string, one renamed into a namespace), DeleteEntity and
    SetEntityState on a spawned body through ros2-client while paused, then step and play; `rbsim
    record` records every change (a scene description, markers and the step again); the session
    re-simulated from its recorded commands equals it, every message; `log export` of the live
    recording equals the re-run's CSV, byte for byte."""
    if not PEER or not os.access(PEER, os.X_OK):
        raise e2e.Failure(f"RBSIM_ROS2_PEER={PEER!r} is not an executable: build the rbsim_ros2_peer target")
    scene, duration = ctx.scene("chain.xml"), 8.0
    steps = round(duration * 1e9 / DT_NS)
    ball = ctx.path("ball.xml")
    with open(ball, "w") as f:
        f.write(BALL)
    commands, changes = 8, 4  # pause, 3 spawns, delete, set_entity_state, step, play; 3 spawns and a delete
    expected = (len(e2e.LATCHED) + len(e2e.PER_STEP) * (steps + 1) + commands
                + changes * (len(e2e.LATCHED) + len(e2e.PER_STEP)))
    live = ctx.path("live.mcap")
    with PeerNet(ctx) as net:
        if net.skip:
            print(f"SKIP: {net.skip}")
            return e2e.SKIP
        rec, node = recorded_node(ctx, net, scene, duration, live, expected)
        try:
            g = sim(ctx, net, "sim", ("set-state", PAUSED), ("spawn", "ball", "string", ball, 0.5, 2.0, 0.25),
                    ("spawn", "ball", "string", ball, -0.5, 2.0, 0.0, "rename"),
                    ("spawn", "crate", "string", ball, 1.0, 3.0, 0.5, "ns", "/team"),
                    ("delete", "ball_1"), ("set-entity", "ball", "twist", 0.0, 1.0, 2.0), ("entity", "ball"),
                    ("step", 5), ("entities", "all"), ("entity", "ball"), ("set-state", PLAYING))
        finally:
            e2e.exited_ok(ctx, node, 60, "rbsim node")
            e2e.exited_ok(ctx, rec, 60, "rbsim record")
    expect(ctx, g, 0, result=OK)
    expect(ctx, g, 1, result=OK, entity_name="ball")
    expect(ctx, g, 2, result=OK, entity_name="ball_1")
    expect(ctx, g, 3, result=OK, entity_name="team/crate")
    expect(ctx, g, 4, result=OK)
    expect(ctx, g, 5, result=OK)
    placed = g[6]["state"]
    ctx.check(placed["position"] == [0.5, 2.0, 0.0] and placed["linear"] == [0.0, 1.0, 0.0]
              and placed["angular"] == [0.0, 0.0, 2.0], f"ball read back after its spawn and twist: {placed}")
    expect(ctx, g, 7, result=OK)
    ctx.check(g[8]["entities"] == [f"body_{i}" for i in range(5)] + ["ball", "team/crate"], f"entities: {g[8]}")
    ctx.check(g[9]["state"]["stamp_ns"] == placed["stamp_ns"] + 5 * DT_NS, f"5 steps on: {g[9]}")
    expect(ctx, g, 10, result=OK)
    # The recording re-simulated from its own commands: every message equal, commands included.
    again = ctx.path("again.mcap")
    ctx.rbrun("again", "run", scene, "--duration", duration, "--commands", live, "--record", again,
              "--namespace", ctx.ns, "--csv", ctx.path("again.csv"))
    e2e.rbsim_check(ctx, live, again, "check-again", live=True)
    ctx.rbrun("export", "log", "export", live, "--csv", ctx.path("live.csv"))
    with open(ctx.path("live.csv")) as a, open(ctx.path("again.csv")) as b:
        ctx.check(a.read() == b.read(), "log export of the live recording differs from the re-run's CSV")
    ctx.log(f"spawned 3 bodies, deleted one, set a twist while paused at step {placed['stamp_ns'] // DT_NS}; "
            "re-simulated from the recording: every message equal")
    return 0


# A world of one body in the wind, 0.05 s long at the chain's dt.
WIND = ('<scene>\n  <description text="a square in the wind"/>\n  <duration time="0.05"/>\n'
        '  <rigidbodyintegrator type="symplectic-euler" dt="0.001"/>\n'
        '  <rigidbodyvertex x="0" y="0" m="1"/><rigidbodyvertex x="1" y="0" m="1"/>\n'
        '  <rigidbodyvertex x="1" y="1" m="1"/><rigidbodyvertex x="0" y="1" m="1"/>\n'
        '  <rigidbody p="0" p="1" p="2" p="3" vx="0.5" vy="1.0" omega="0.3" r="0.1"/>\n'
        '  <rigidbodygravityforce fx="0.0" fy="-9.81"/>\n'
        '  <rigidbodywindforce beta="0.2" fx="1.0" fy="0.5" pointsperedge="3"/>\n</scene>\n')


def case_worlds(ctx):
    """Spawns (a fragment as resource_string and one by uri from --spawnables), a state set, then
    LoadWorld of another world by uri from --worlds (stopped at its step 0, listed by
    GetAvailableWorlds, named by GetCurrentWorld), 5 steps in it, and back to the first world (by
    uri too: RustDDS panics writing a LoadWorld request whose resource_string holds the chain's
    2.6 kB, in write_to_vec_fast's length assertion; the text form is test/sim's, over Cyclone), 3 steps and play, all through ros2-client while `rbsim record` records; the session
    re-simulated from its recorded commands (no file needed) equals it, every message, and `log
    export` reads the recording, both worlds."""
    if not PEER or not os.access(PEER, os.X_OK):
        raise e2e.Failure(f"RBSIM_ROS2_PEER={PEER!r} is not an executable: build the rbsim_ros2_peer target")
    duration, steps = 0.5, 500
    first, spawnables, worlds = ctx.path("first.xml"), ctx.path("spawnables"), ctx.path("worlds")
    os.makedirs(spawnables)
    os.makedirs(worlds)
    with open(ctx.scene("chain.xml")) as f:
        chain = f.read()
    first_text = re.sub(r'<duration time="[^"]*"/>', f'<duration time="{duration}"/>', chain)
    for path, text in ((first, first_text), (os.path.join(worlds, "first.xml"), first_text),
                       (os.path.join(spawnables, "ball.xml"), BALL), (os.path.join(worlds, "wind.xml"), WIND)):
        with open(path, "w") as f:
            f.write(text)
    latched, per_step, commands = len(e2e.LATCHED), len(e2e.PER_STEP), 8
    # Step 0, two spawns and two loads each write every topic again; 5 steps, 3 steps, then the rest.
    expected = 5 * latched + (1 + 2 + 1 + 5 + 1 + 3 + (steps - 3)) * per_step + commands
    live = ctx.path("live.mcap")
    with PeerNet(ctx) as net:
        if net.skip:
            print(f"SKIP: {net.skip}")
            return e2e.SKIP
        rec, node = recorded_node(ctx, net, first, duration, live, expected, "--spawnables", spawnables,
                                  "--worlds", worlds, "--ros-args", "-p", "paused:=true")
        try:
            g = sim(ctx, net, "sim", ("state",), ("spawn", "ball", "string", ctx.path("spawnables/ball.xml"), 0.5, 2.0, 0.25),
                    ("spawn", "crate", "uri", "ball.xml", 1.0, 3.0, 0.5), ("set-entity", "ball", "twist", 0.0, 1.0, 2.0),
                    ("available-worlds",), ("load-world", "uri", "wind.xml"), ("state",), ("current-world",),
                    ("step", 5), ("entities", "all"), ("load-world", "uri", "first.xml"), ("step", 3),
                    ("entities", "all"), ("set-state", PLAYING))
        finally:
            e2e.exited_ok(ctx, node, 60, "rbsim node")
            e2e.exited_ok(ctx, rec, 60, "rbsim record")
    ctx.check(g[0]["state"] == STOPPED, f"started paused at step 0: {g[0]}")
    expect(ctx, g, 1, result=OK, entity_name="ball")
    expect(ctx, g, 2, result=OK, entity_name="crate")
    expect(ctx, g, 3, result=OK)
    ctx.check(g[4]["result"] == OK and [w["name"] for w in g[4]["worlds"]] == ["first", "wind"]
              and g[4]["worlds"][1]["description"] == "a square in the wind", f"available worlds: {g[4]}")
    expect(ctx, g, 5, result=OK)
    ctx.check(g[5]["world"]["name"] == "wind" and g[5]["world"]["uri"] == "wind.xml", f"loaded: {g[5]}")
    ctx.check(g[6]["state"] == STOPPED, f"a loaded world is stopped: {g[6]}")
    ctx.check(g[7]["result"] == OK and g[7]["world"]["name"] == "wind", f"current world: {g[7]}")
    expect(ctx, g, 8, result=OK)
    ctx.check(g[9]["entities"] == ["body_0"], f"the wind world's entities: {g[9]}")
    expect(ctx, g, 10, result=OK)
    expect(ctx, g, 11, result=OK)
    ctx.check(g[12]["entities"] == [f"body_{i}" for i in range(5)], f"back in the first world, as loaded: {g[12]}")
    expect(ctx, g, 13, result=OK)
    # The recording re-simulated from its own commands, the world files gone: every message equal.
    shutil.rmtree(worlds)
    shutil.rmtree(spawnables)
    again = ctx.path("again.mcap")
    ctx.rbrun("again", "run", first, "--duration", duration, "--commands", live, "--record", again,
              "--namespace", ctx.ns)
    e2e.rbsim_check(ctx, live, again, "check-again", live=True)
    ctx.rbrun("export", "log", "export", live, "--csv", ctx.path("live.csv"))
    with open(ctx.path("live.csv")) as f:
        rows = f.read().splitlines()[1:]
    # The first world never stepped: its step 0 was recorded again by the load, and the last wins.
    ctx.check(len(rows) == 1 * 6 + 5 * (1 + steps),
              f"log export: {len(rows)} rows, want the wind world's 0..5 (1 body; the first world's step 0 "
              f"recorded again as the wind world's, the last recording of the step) and the first world's "
              f"0..{steps} (5 bodies)")
    # The oracle: each world as loaded steps as its scene run alone, row for row.
    with open(ctx.path("wind.xml"), "w") as f:
        f.write(WIND)
    for name, scene, n, want in (("wind", ctx.path("wind.xml"), 5, rows[:6]),
                                 ("first", first, steps, rows[6:])):
        ctx.rbrun(f"alone-{name}", "run", scene, "--steps", n, "--csv", ctx.path(f"alone-{name}.csv"))
        with open(ctx.path(f"alone-{name}.csv")) as f:
            alone = f.read().splitlines()[1:]
        ctx.check(alone == want, f"the {name} world as loaded differs from the scene run alone "
                                 f"({len(want)} rows vs {len(alone)})")
    ctx.log("spawned 2 bodies (text, uri), loaded a world by uri and the first again; re-simulated from the "
            "recording with no file: every message equal; each world as loaded equals its scene run alone")
    return 0


def rosbags_hash(ctx, type_name):
    """The RIHS01 hash `rosbags` computes for `type_name` (test/msgs/data/rihs01_rosbags.txt, the
    table test/python/check_type_hashes.py checks against rosbags on every run)."""
    with open(os.path.join(ctx.src, "test", "msgs", "data", "rihs01_rosbags.txt")) as f:
        for line in f:
            words = line.split()
            if len(words) == 2 and words[0] == type_name:
                return words[1]
    raise e2e.Failure(f"{type_name}: not in rihs01_rosbags.txt")


def case_type_description(ctx):
    """~/get_type_description called by ros2-client. A topic's type, asked for by the hash the
    node's writer announces in its USER_DATA as RustDDS's discovery reports it: the description it
    returns hashes (REP 2011, SHA-256, computed in the peer) to that very hash. A service's type
    (simulation_interfaces/srv/GetEntitiesStates, asked for by the hash rosbags computes: a
    service's endpoints announce their _Request and _Response types, which rcl's node type cache
    does not hold, so the node answers for those as rcl does, "not currently in use"): its
    description hashes to rosbags' hash, and its _Request and _Response parts, cut out of it, to
    what the request reader and the reply writer announce. Sources come with both; a hash of no
    type the node uses is refused in rcl's words."""
    def body(net, node):
        ns, srv = ctx.ns, "simulation_interfaces/srv/GetEntitiesStates"
        g = sim(ctx, net, "sim", ("typedesc", f"rt/{ns}/body_states", "rbsim_msgs/msg/BodyStates"),
                ("typedesc-hash", rosbags_hash(ctx, srv), srv),
                ("announced", f"rq/{ns}/get_entities_statesRequest"), ("announced", f"rr/{ns}/get_entities_statesReply"),
                ("typedesc", f"rr/{ns}/get_entities_statesReply", f"{srv}_Response"),
                ("typedesc-hash", "RIHS01_" + "0" * 64, "rbsim_msgs/msg/BodyStates"))
        for m, want, hash_ in ((g[0], "rbsim_msgs/msg/BodyStates", g[0]["announced"]), (g[1], srv, rosbags_hash(ctx, srv))):
            ctx.check(m["successful"] and hash_.startswith("RIHS01_") and m["description_hash"] == hash_
                      and m["type_name"] == want and m["sources"],
                      f"type description of {want}: want its hash {hash_}, got {m}")
            ctx.log(f"{want}: asked for {hash_}, described ({m['fields']} fields, {len(m['referenced'])} referenced "
                    f"types) hashing to {m['description_hash']}")
        parts = g[1].get("part_hashes", {})
        for op, part in ((2, "_Request"), (3, "_Response")):
            ctx.check(parts.get(srv + part) == g[op]["announced"] and g[op]["announced"] == rosbags_hash(ctx, srv + part),
                      f"{srv}{part}: its description in the service's hashes to {parts.get(srv + part)}, the endpoint "
                      f"announces {g[op]['announced']}, rosbags says {rosbags_hash(ctx, srv + part)}")
        ctx.check(not g[4]["successful"] and "not currently in use" in g[4]["failure_reason"],
                  f"{srv}_Response (announced, not in the node type cache, as rcl): {g[4]}")
        ctx.check(not g[5]["successful"] and "not currently in use" in g[5]["failure_reason"], f"unknown hash: {g[5]}")
    return with_node(ctx, body)


e2e.CASES.clear()
e2e.CASES.update({"tf": case_tf, "graph": case_graph, "rosout": case_rosout, "killed_peer": case_killed_peer,
                  "parameters": case_parameters, "services": case_services, "flood": case_flood,
                  "bad_requests": case_bad_requests, "killed_client": case_killed_client, "steered": case_steered,
                  "simulation_state": case_simulation_state, "simulate_steps": case_simulate_steps,
                  "entities": case_entities, "spawn": case_spawn, "worlds": case_worlds,
                  "type_description": case_type_description})

if __name__ == "__main__":
    sys.exit(e2e.main())
