#!/usr/bin/env python3
"""Driver of scripts/bench-services: the round trip of a ROS 2 service call made by ros2-client
(rbsim-ros2-peer's `bench` verb, ServiceMapping::Cyclone) in network namespace b to rbsim node's
service in namespace a, beside the same client calling a ros2-client server of the same type
(`serve`) in namespace a, in the same run. Two modes:
  trigger  /NS/pause (std_srvs/srv/Trigger; "already paused" after the first), chain.xml running
  states   /NS/get_entities_states (simulation_interfaces/srv/GetEntitiesStates, no filter: every
           body) of a --bodies grid scene (bench/make_grid_scene.py) on a node started paused
           (STOPPED: -p paused:=true; the bench measures the service, not the stepping beside it),
           against a ros2-client server answering a canned reply of as many entities (the same
           size to the byte: names body_<i>, frame world)
Namespaces as the ros2_peer tests make them (PeerNet: a veth pair, RustDDS multicasts only there).
Prints median and p99 of both and their ratio; exit 1 when the median ratio misses the target."""
import argparse
import contextlib
import io
import os
import signal
import statistics
import subprocess
import sys

root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(root, "test", "ros2_peer"))
sys.path.insert(0, os.path.join(root, "test", "e2e"))
import e2e  # noqa: E402
import ros2_peer_test  # noqa: E402

TARGET = 1.5  # rbsim's median round trip at most 1.5x ros2-client's own server's
RUSTDDS_MAX_ENTITIES = 340  # the largest GetEntitiesStates reply (about 64 KiB) a RustDDS 0.15.1 writer delivers (below)


def bench(ctx, net, name, service, calls, warmup, kind=()):
    """Runs the timed client against `service` to the end; its JSON result."""
    p = net.peer(name, "bench", service, calls, warmup, *kind, "--timeout", 300)
    e2e.exited_ok(ctx, p, 330, f"rbsim-ros2-peer bench {service}")
    got = [m for m in ros2_peer_test.lines(p) if "bench" in m]
    ctx.require(len(got) == 1, f"bench {service}: no result\n{p.output()}")
    return got[0]


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rbsim", required=True)
    ap.add_argument("--peer", required=True, help="rbsim-ros2-peer")
    ap.add_argument("--root", required=True)
    ap.add_argument("--calls", type=int, default=2000)
    ap.add_argument("--warmup", type=int, default=200)
    ap.add_argument("--rounds", type=int, default=5, help="interleaved rounds of calls / rounds each")
    ap.add_argument("--mode", choices=("trigger", "states"), default="trigger")
    ap.add_argument("--bodies", type=int, default=1000, help="states: bodies of the grid scene (entities in a reply)")
    a = ap.parse_args()
    ros2_peer_test.PEER = os.path.abspath(a.peer)
    args = argparse.Namespace(rbsim=a.rbsim, source_dir=a.root, index=60, case=f"bench_services_{a.mode}",
                              workdir=os.path.join(os.path.dirname(os.path.abspath(a.rbsim)), f"bench-services-{a.mode}"))
    first = io.StringIO()
    with contextlib.redirect_stdout(first):
        ctx = e2e.Ctx(args)
    log = open(ctx.path("bench.log"), "w")  # the harness's progress lines: kept out of the figures
    log.write(first.getvalue())
    ctx.log = lambda msg: print(msg, file=log, flush=True)
    status = 1
    try:
        with ros2_peer_test.PeerNet(ctx) as net:
            if net.skip:
                print(f"scripts/bench-services: {net.skip}", file=sys.stderr)
                return 2
            # The series: (name, label, service, peer kind, reply words), each timed in every round.
            if a.mode == "trigger":
                kind, pair = (), None
                node = net.rb("node", "a", *e2e.node_args(ctx, ctx.scene("chain.xml"), "--loop"))
                node.wait_for_text("rbsim node:", 30, stream="stderr")
                nodes = [node]
                series = [("rb", "rbsim node /pause (Cyclone DDS)", f"/{ctx.ns}/pause", "already paused")]
                serve = ()
            else:
                kind = ("states",)
                # A RustDDS 0.15.1 writer delivers a sample it fragments only when every fragment
                # goes out in one datagram: over the veth's MTU of 1500 its replies of 8 entities
                # (1.5 kB) or more never arrive (rbsim's, from Cyclone, do; debug builds of the
                # peer panic in RustDDS's Message::write_to_vec_fast). So for this mode the veth
                # gets loopback's MTU (64 KiB datagrams, for both servers alike), and ros2-client's
                # server answers at most RUSTDDS_MAX_ENTITIES (about 64 KiB): the pair is compared
                # at that size, and rbsim alone at --bodies.
                for ns, dev in ((net.a, net.va), (net.b, net.vb)):
                    e2e.ip(ctx, "-n", ns, "link", "set", dev, "mtu", "65535")
                pair = min(a.bodies, RUSTDDS_MAX_ENTITIES)
                nodes, series = [], []
                for n, ns in [(pair, ctx.ns)] + ([(a.bodies, f"{ctx.ns}_big")] if a.bodies > pair else []):
                    scene = ctx.path(f"grid-{n}.xml")
                    with open(scene, "w") as f:
                        f.write(subprocess.run([sys.executable, os.path.join(a.root, "bench", "make_grid_scene.py"),
                                                str(n), "0.001", "2.0"], capture_output=True, text=True,
                                               check=True).stdout)
                    # Paused from the start (STOPPED): the service is measured, not the stepping beside it.
                    node = net.rb(f"node-{n}", "a", *e2e.node_args(ctx, scene, "--loop", "--ros-args", "-p", "paused:=true",
                                                                    ns=ns))
                    node.wait_for_text("rbsim node:", 60, stream="stderr")
                    nodes.append(node)
                    series.append((f"rb-{n}", f"rbsim node /get_entities_states, {n} entities (Cyclone DDS)",
                                   f"/{ns}/get_entities_states", f"{n} entities, result 1"))
                serve = ("states", pair)
            service = series[0][2].rsplit("/", 1)[1]
            ours = f"/{ctx.ns}_server/{service}"
            server = net.peer("server", "serve", ours, *serve, "--timeout", 900, side="a")
            server.wait_for_text('"serving"', 30)
            label = "ros2-client server (RustDDS)" + (f", {pair} entities" if pair else "")
            series.insert(1, ("peer", label, ours, f"{pair} entities, result 1" if pair else "ok"))
            # Interleaved rounds (this machine's load changes over a minute), medians of the rounds.
            rounds = {name: [] for name, *_ in series}
            per_round = max(a.calls // a.rounds, 1)
            for k in range(a.rounds):
                for name, _, path, _ in series:
                    rounds[name].append(bench(ctx, net, f"bench-{name}-{k}", path, per_round, a.warmup, kind))
            got = {w: {"median_us": statistics.median(r["median_us"] for r in rounds[w]),
                       "p99_us": statistics.median(r["p99_us"] for r in rounds[w]),
                       "last_message": rounds[w][-1].get("last_message", "")} for w in rounds}
            for node in nodes:
                node.signal(signal.SIGINT)
                e2e.exited_ok(ctx, node, 30, "rbsim node after SIGINT")
            for name, _, _, says in series:
                ctx.check(got[name]["last_message"].startswith(says), f"{name}: the reply said {got[name]['last_message']!r}")
            rb, peer = got[series[0][0]], got["peer"]
            median, p99 = rb["median_us"] / peer["median_us"], rb["p99_us"] / peer["p99_us"]
            print(f"service round trip, ros2-client client in one namespace, server in the other (veth), "
                  f"{a.rounds} interleaved rounds of {per_round} sequential calls after {a.warmup} warm-up each, medians "
                  f"of the rounds (load average {os.getloadavg()[0]:.1f}):")
            width = max(len(label) for _, label, _, _ in series)
            for name, label, _, _ in series:
                print(f"  {label:<{width}}   median {got[name]['median_us']:8.1f} us   p99 {got[name]['p99_us']:8.1f} us")
            met = median <= TARGET
            print(f"  rbsim / ros2-client server{f' at {pair} entities' if pair else ''}: median {median:.2f}x "
                  f"(target <= {TARGET}x: {'met' if met else 'MISSED'}), p99 {p99:.2f}x")
            status = 0 if met and not ctx.failures else 1
    except e2e.Failure as e:
        ctx.failures.append(str(e))
    finally:
        ctx.cleanup()
    for f in ctx.failures:
        print(f"scripts/bench-services: {f}\n(log: {log.name})", file=sys.stderr)
    return 1 if ctx.failures else status


if __name__ == "__main__":
    sys.exit(main())
