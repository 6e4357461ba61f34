#!/usr/bin/env python3
"""rbsim's MCAP writer against the Foxglove SDK's (PyPI foxglove-sdk, Rust core) and a plain
buffered write, on the message stream of a 1,000-body run (scripts/bench-mcap-sdk runs this).

1. Captures the stream: rbsim_bench_mcap_stream capture runs a generated 1,000-body grid scene
   (bench/make_grid_scene.py) through the run driver and the MCAP sink of `rbsim run --record`,
   default topics, uncompressed chunks.
2. For every setting (compression none / lz4 / zstd at the same level; CRCs on / off; one thread
   or two), in `runs` interleaved rounds (rbsim then the SDK, the other way round every other
   round), writes that stream to `tmp` with
     rbsim   rbsim_bench_mcap_stream CAPTURE OUT --writer rbsim ... (a child process that reads
             the capture first, untimed, then times open, schemas, channels, every message, close)
     SDK     foxglove.open_mcap(OUT, writer_options=MCAPWriteOptions(...)), every message logged
             through its channel, close(); timed in this process, the capture already in memory
             and the (bound log method, payload, log time) list built beforehand
   and, once per round, a plain buffered write of the same payloads (--writer plain: fwrite each).
   Same schemas (name, ros2msg encoding, text), channels (topic, cdr, metadata), log times,
   payloads and order; same chunk size; same compression level.
3. Checks that both writers' files of the first round read back with the official `mcap` Python
   reader with the same messages (count, topics, log times, payload digests), the requested
   compression in every chunk and CRCs present or absent as asked.
4. Prints the medians (MB/s of message payload over wall time) and each ratio (the median of the
   per-round ratios, each round's runs being adjacent) beside its target:
   rbsim >= 1.0x the SDK in every setting; uncompressed rbsim >= 0.6x the plain write. Exit 1 when
   a target is missed (or a check fails).
"""
import argparse
import hashlib
import json
import os
import statistics
import subprocess
import sys
import time

import foxglove
from foxglove.mcap import MCAPCompression, MCAPWriteOptions
from mcap.reader import make_reader
from mcap.records import Chunk, DataEnd, Footer
from mcap.stream_reader import StreamReader


def parse_args():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--bench", required=True, help="rbsim_bench_mcap_stream")
    p.add_argument("--root", required=True, help="the rbsim source tree")
    p.add_argument("--tmp", default="/dev/shm")
    p.add_argument("--bodies", type=int, default=1000)
    p.add_argument("--steps", type=int, default=200)
    p.add_argument("--runs", type=int, default=5)
    p.add_argument("--chunk-size", type=int, default=1 << 20)
    p.add_argument("--zstd-level", type=int, default=1, help="rbsim records with zstd level 1")
    p.add_argument("--lz4-level", type=int, default=0)
    p.add_argument("--only", default="", help="comma-separated codecs to run (none,lz4,zstd)")
    return p.parse_args()


def load_capture(path):
    """Schemas, channels and messages of an MCAP file, in file order."""
    with open(path, "rb") as f:
        reader = make_reader(f)
        summary = reader.get_summary()
        schemas = dict(summary.schemas)
        channels = dict(summary.channels)
        messages = [(m.channel_id, m.log_time, m.publish_time, m.data)
                    for _, _, m in reader.iter_messages(log_time_order=False)]
    return schemas, channels, messages


def digest(path):
    """(message count, per-topic count and SHA-256 of log times and payloads in file order)."""
    per_topic = {}
    count = 0
    with open(path, "rb") as f:
        for _, channel, m in make_reader(f, validate_crcs=True).iter_messages(log_time_order=False):
            h = per_topic.setdefault(channel.topic, [0, hashlib.sha256()])
            h[0] += 1
            h[1].update(m.log_time.to_bytes(8, "little"))
            h[1].update(m.data)
            count += 1
    return count, {t: (n, h.hexdigest()) for t, (n, h) in sorted(per_topic.items())}


def layout(path):
    """(set of chunk compressions, any chunk CRC non-zero, data section CRC non-zero, summary CRC non-zero)."""
    compressions, chunk_crc, data_crc, summary_crc = set(), False, False, False
    with open(path, "rb") as f:
        for record in StreamReader(f, emit_chunks=True, validate_crcs=True).records:
            if isinstance(record, Chunk):
                compressions.add(record.compression)
                chunk_crc |= record.uncompressed_crc != 0
            elif isinstance(record, DataEnd):
                data_crc = record.data_section_crc != 0
            elif isinstance(record, Footer):
                summary_crc = record.summary_crc != 0
    return compressions, chunk_crc, data_crc, summary_crc


class SdkWriter:
    """The Foxglove SDK writing the captured stream: a context of its own with one channel per
    captured channel (same topic, schema, encodings and metadata)."""

    def __init__(self, schemas, channels, messages):
        self.context = foxglove.Context()
        by_id = {}
        for cid, ch in sorted(channels.items()):
            schema = None
            if ch.schema_id != 0:
                s = schemas[ch.schema_id]
                schema = foxglove.Schema(name=s.name, encoding=s.encoding, data=s.data)
            by_id[cid] = foxglove.Channel(ch.topic, schema=schema, message_encoding=ch.message_encoding,
                                          context=self.context, metadata=dict(ch.metadata))
        # The SDK's per-message call, bound beforehand: BaseChannel.log(bytes, log_time) (Channel.log
        # adds only Python type checks around it). publish_time is the log time in the SDK, as in
        # the capture.
        self.items = [(by_id[cid].base.log, data, log_time) for cid, log_time, _, data in messages]

    def write(self, path, options):
        """(wall seconds, CPU seconds of the process, every thread) of open, log all, close."""
        c0, t0 = time.process_time(), time.perf_counter()
        writer = foxglove.open_mcap(path, allow_overwrite=True, context=self.context, writer_options=options)
        for log, data, log_time in self.items:  # bounded: one pass over the captured messages
            log(data, log_time)
        writer.close()
        return time.perf_counter() - t0, time.process_time() - c0


def main():
    a = parse_args()
    tag = f"rbsim_mcap_sdk_{os.getpid()}"
    scene = os.path.join(a.tmp, f"{tag}_grid{a.bodies}.xml")
    capture = os.path.join(a.tmp, f"{tag}_capture.mcap")
    made = [scene, capture]
    try:
        return run(a, tag, scene, capture, made)
    finally:
        for p in made:
            if os.path.exists(p):
                os.remove(p)


def run(a, tag, scene, capture, made):
    with open(scene, "w") as f:
        subprocess.run([sys.executable, os.path.join(a.root, "bench", "make_grid_scene.py"), str(a.bodies),
                        "0.001", "1000"], stdout=f, check=True)
    subprocess.run([a.bench, "capture", scene, str(a.steps), capture], check=True)
    schemas, channels, messages = load_capture(capture)
    payload = sum(len(m[3]) for m in messages)
    per_topic = {}
    for cid, _, _, data in messages:
        n, b = per_topic.get(channels[cid].topic, (0, 0))
        per_topic[channels[cid].topic] = (n + 1, b + len(data))
    print(f"capture: {a.bodies}-body grid scene, {a.steps} steps, default topics: {len(messages)} messages, "
          f"{payload / 1e6:.1f} MB of payload, {len(channels)} channels")
    for topic, (n, b) in sorted(per_topic.items(), key=lambda kv: -kv[1][1]):
        print(f"  {topic:<24}{n:>7} messages {b / n / 1e3:>9.1f} kB each")

    sdk = SdkWriter(schemas, channels, messages)
    codecs = [c for c in ("none", "lz4", "zstd") if not a.only or c in a.only.split(",")]
    levels = {"none": 0, "lz4": a.lz4_level, "zstd": a.zstd_level}
    sdk_codec = {"none": None, "lz4": MCAPCompression.Lz4, "zstd": MCAPCompression.Zstd}
    # threads: 1 = everything on the writing thread (rbsim: no background compression; SDK:
    # compression_threads=0); 2 = a second thread may compress (rbsim: background_compression, as
    # rbsim's recordings do; SDK: zstd's multithreaded compression with 2 workers; the SDK's lz4
    # and uncompressed chunks have no such option, so they are single-threaded in both rows).
    settings = [(c, crc, th) for c in codecs for crc in ("on", "off") for th in (1, 2)]

    def sdk_options(codec, crc, threads):
        on = crc == "on"
        return MCAPWriteOptions(compression=sdk_codec[codec], chunk_size=a.chunk_size, profile="ros2",
                                compression_level=levels[codec], compression_threads=0 if threads == 1 else 2,
                                calculate_chunk_crcs=on, calculate_data_section_crc=on,
                                calculate_summary_section_crc=on, calculate_attachment_crcs=on)

    def rbsim(out, codec, crc, threads, writer="rbsim"):
        args = [a.bench, capture, out, "--writer", writer]
        if writer == "rbsim":
            args += ["--compression", codec, "--level", str(levels[codec]), "--chunk-size", str(a.chunk_size),
                     "--crc", crc, "--threads", str(threads)]
        r = json.loads(subprocess.run(args, check=True, capture_output=True, text=True).stdout)
        if r["payload_bytes"] != payload or r["messages"] != len(messages):
            sys.exit(f"rbsim_bench_mcap_stream read {r['messages']} messages, {r['payload_bytes']} bytes; "
                     f"the capture has {len(messages)}, {payload}")
        return r["seconds"], r["cpu_seconds"], r["file_bytes"]

    times = {s: {"rbsim": [], "sdk": []} for s in settings}
    cpu = {s: {"rbsim": [], "sdk": []} for s in settings}
    sizes = {}
    plain = []
    failed = False
    print(f"\n{a.runs} interleaved rounds of {len(settings)} settings x (rbsim, SDK) + a plain write, to {a.tmp}")
    for rnd in range(a.runs):  # bounded: a.runs rounds
        for s in settings:
            codec, crc, th = s
            name = f"{codec}_crc{crc}_t{th}"
            out_r = os.path.join(a.tmp, f"{tag}_{name}_rbsim.mcap")
            out_s = os.path.join(a.tmp, f"{tag}_{name}_sdk.mcap")
            made += [out_r, out_s]
            for who in ("rbsim", "sdk") if rnd % 2 == 0 else ("sdk", "rbsim"):  # alternating order
                if who == "rbsim":
                    sec, cpu_sec, size_r = rbsim(out_r, *s)
                else:
                    sec, cpu_sec = sdk.write(out_s, sdk_options(*s))
                times[s][who].append(sec)
                cpu[s][who].append(cpu_sec)
            if rnd == 0:
                sizes[s] = (size_r, os.path.getsize(out_s))
                failed |= not verify(out_r, out_s, s, len(messages))
            os.remove(out_r)
            os.remove(out_s)
        out_p = os.path.join(a.tmp, f"{tag}_plain.bin")
        made.append(out_p)
        sec, _, size_p = rbsim(out_p, "none", "on", 1, writer="plain")
        if size_p != payload:
            sys.exit(f"plain write: {size_p} bytes, expected {payload}")
        plain.append(sec)
        os.remove(out_p)
        print(f"  round {rnd + 1}/{a.runs} done", flush=True)

    mbps = lambda secs: payload / statistics.median(secs) / 1e6  # noqa: E731
    # A ratio is judged as the median of the per-round ratios: the runs of a round are adjacent, so
    # each pair shares the machine's load (this machine is shared); the ratio of the medians is
    # printed beside it.
    paired = lambda ours, theirs: statistics.median(t / o for o, t in zip(ours, theirs))  # noqa: E731
    plain_rate = mbps(plain)
    print()
    print(f"Medians of {a.runs} interleaved runs, MB/s of message payload ({payload / 1e6:.1f} MB) over wall "
          f"time, chunk size {a.chunk_size} B, zstd level {a.zstd_level}, lz4 level {a.lz4_level}. threads: 1 = all "
          f"on the writing thread; 2 = rbsim compresses chunks on a second thread too, the SDK's zstd uses 2 "
          f"workers (its lz4 and none have no threads option). ratio: median of the per-round rbsim/SDK "
          f"ratios (judged); of medians: ratio of the two medians. CPU: the same MB over the process's CPU time "
          f"(user + system, every thread; for information). MB: file sizes.")
    head = (f"{'codec':<6}{'CRCs':<5}{'thr':>4} | {'rbsim MB/s':>10} {'SDK MB/s':>9} | {'ratio':>6} {'target':>7} "
            f"{'met':>4} | {'of medians':>10} | {'CPU rbsim':>9} {'SDK':>5} {'ratio':>6} | {'rbsim MB':>8} "
            f"{'SDK MB':>7}")
    print(head)
    print("-" * len(head))
    for s in settings:
        codec, crc, th = s
        r, k = mbps(times[s]["rbsim"]), mbps(times[s]["sdk"])
        ratio = paired(times[s]["rbsim"], times[s]["sdk"])
        ok = ratio >= 1.0
        failed |= not ok
        cr, ck = mbps(cpu[s]["rbsim"]), mbps(cpu[s]["sdk"])
        print(f"{codec:<6}{crc:<5}{th:>4} | {r:>10.0f} {k:>9.0f} | {ratio:>5.2f}x {'>= 1.0x':>7} "
              f"{'yes' if ok else 'NO':>4} | {r / k:>9.2f}x | {cr:>9.0f} {ck:>5.0f} {cr / ck:>5.2f}x | "
              f"{sizes[s][0] / 1e6:>8.1f} {sizes[s][1] / 1e6:>7.1f}")
    print()
    print(f"Uncompressed rbsim against a plain buffered write of the same payloads (fwrite each message), "
          f"{plain_rate:.0f} MB/s (median); ratio: median of the per-round ratios (each round's plain write "
          f"follows its rbsim runs)")
    for s in settings:
        codec, crc, th = s
        if codec != "none":
            continue
        r = mbps(times[s]["rbsim"])
        ratio = paired(times[s]["rbsim"], plain)
        ok = ratio >= 0.6
        failed |= not ok
        print(f"  none, CRCs {crc:<3}, threads {th}: {r:>6.0f} MB/s, {ratio:.2f}x plain (of medians "
              f"{r / plain_rate:.2f}x)  target >= 0.6x  {'met' if ok else 'MISSED'}")
    print()
    print("Notes: the SDK's time includes one Python call per message (BaseChannel.log, bound beforehand); "
          "rbsim's includes none (C++).")
    print("PASS: every target met" if not failed else "FAIL: a target was missed or a check failed")
    return 1 if failed else 0


def verify(out_r, out_s, setting, count):
    """Both files read back with the official reader: same messages, the requested layout."""
    codec, crc, _ = setting
    ok = True
    dr, ds = digest(out_r), digest(out_s)
    if dr[0] != count or ds[0] != count or dr != ds:
        print(f"  CHECK FAILED {setting}: rbsim {dr[0]} messages, SDK {ds[0]}, capture {count}; "
              f"same topics, times and payloads: {dr == ds}")
        ok = False
    want = set() if codec == "none" else {codec}
    for who, path in (("rbsim", out_r), ("SDK", out_s)):
        comp, chunk_crc, data_crc, summary_crc = layout(path)
        got = comp - {""}
        crcs = (chunk_crc, data_crc, summary_crc)
        if got != want or (crc == "on" and not all(crcs)) or (crc == "off" and any(crcs)):
            print(f"  CHECK FAILED {setting} {who}: chunk compression {sorted(comp)}, CRCs (chunk, data, summary) "
                  f"{crcs}")
            ok = False
    return ok


if __name__ == "__main__":
    sys.exit(main())
