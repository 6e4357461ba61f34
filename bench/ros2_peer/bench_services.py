#!/usr/bin/env python3
"""Driver of scripts/bench-services: the round trip of a ROS 2 service call made by ros2-client
(rbsim-ros2-peer's `bench` verb, ServiceMapping::Cyclone) in network namespace b to rbsim node's
/NS/pause (std_srvs/srv/Trigger; "already paused" after the first) in namespace a, beside the same
client calling a ros2-client server of the same type (`serve`) in namespace a, in the same run.
Namespaces as the ros2_peer tests make them (PeerNet: a veth pair, RustDDS multicasts only there).
Prints median and p99 of both and their ratio; exit 1 when the median ratio misses the target."""
import argparse
import contextlib
import io
import os
import signal
import statistics
import sys

root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(root, "test", "ros2_peer"))
sys.path.insert(0, os.path.join(root, "test", "e2e"))
import e2e  # noqa: E402
import ros2_peer_test  # noqa: E402

TARGET = 1.5  # rbsim's median round trip at most 1.5x ros2-client's own server's


def bench(ctx, net, name, service, calls, warmup):
    """Runs the timed client against `service` to the end; its JSON result."""
    p = net.peer(name, "bench", service, calls, warmup, "--timeout", 300)
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
    a = ap.parse_args()
    ros2_peer_test.PEER = os.path.abspath(a.peer)
    args = argparse.Namespace(rbsim=a.rbsim, source_dir=a.root, index=60, case="bench_services",
                              workdir=os.path.join(os.path.dirname(os.path.abspath(a.rbsim)), "bench-services"))
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
            node = net.rb("node", "a", *e2e.node_args(ctx, ctx.scene("chain.xml"), "--loop"))
            node.wait_for_text("rbsim node:", 30, stream="stderr")
            ours = f"/{ctx.ns}_server/pause"
            server = net.peer("server", "serve", ours, "--timeout", 900, side="a")
            server.wait_for_text('"serving"', 30)
            # Interleaved rounds (this machine's load changes over a minute), medians of the rounds.
            rounds = {"rb": [], "peer": []}
            per_round = max(a.calls // a.rounds, 1)
            for k in range(a.rounds):
                rounds["rb"].append(bench(ctx, net, f"bench-rbsim-{k}", f"/{ctx.ns}/pause", per_round, a.warmup))
                rounds["peer"].append(bench(ctx, net, f"bench-ros2-client-{k}", ours, per_round, a.warmup))
            rb, peer = ({"median_us": statistics.median(r["median_us"] for r in rounds[w]),
                         "p99_us": statistics.median(r["p99_us"] for r in rounds[w]),
                         "last_message": rounds[w][-1].get("last_message", "")} for w in ("rb", "peer"))
            node.signal(signal.SIGINT)
            e2e.exited_ok(ctx, node, 30, "rbsim node after SIGINT")
            ctx.check(rb["last_message"].startswith("already paused"), f"rbsim's pause said {rb['last_message']!r}")
            median, p99 = rb["median_us"] / peer["median_us"], rb["p99_us"] / peer["p99_us"]
            print(f"service round trip, ros2-client client in one namespace, server in the other (veth), "
                  f"{a.rounds} interleaved rounds of {per_round} sequential calls after {a.warmup} warm-up each, medians "
                  f"of the rounds (load average {os.getloadavg()[0]:.1f}):")
            print(f"  rbsim node /pause (Cyclone DDS)   median {rb['median_us']:8.1f} us   p99 {rb['p99_us']:8.1f} us")
            print(f"  ros2-client server (RustDDS)      median {peer['median_us']:8.1f} us   p99 {peer['p99_us']:8.1f} us")
            met = median <= TARGET
            print(f"  rbsim / ros2-client server: median {median:.2f}x (target <= {TARGET}x: "
                  f"{'met' if met else 'MISSED'}), p99 {p99:.2f}x")
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
