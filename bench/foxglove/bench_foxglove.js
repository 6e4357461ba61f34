#!/usr/bin/env node
"use strict";
// Driver of scripts/bench-foxglove: the real `rbsim node --foxglove` on 127.0.0.1, Node clients
// from test/foxglove_client/lib.js, every wait bounded. Prints the figures beside their targets
// and exits 1 when one is missed.
//   (a) latency, step published -> decoded, 100 bodies: the Node client over the Foxglove
//       WebSocket against a C++ Cyclone DDS subscriber (rbsim_bench_dds listen), same node, same
//       steps, from the DDS sample's source timestamp (CLOCK_REALTIME, as the DDS receive time;
//       rbsim_bench_dds also gives it on CLOCK_MONOTONIC, the clock of the Node client's receive
//       time, so no two clocks are compared);
//   (b) 1,000 bodies at real time, dt = 1 ms, 3 clients in their own processes: dropped messages.
//       The clients are rbsim_bench_fox_client (bench/foxglove/fanout_client.cpp), which read and
//       check every frame without decoding it: clients that keep up. A Node client decoding
//       ~370 MB/s in JavaScript does not on this hardware; the flow control drops its oldest
//       per-step messages, as the foxglove_client.slow_client test shows;
//   (c) payload bytes per step of the 1,000-body scene's default topics, before and after;
//   (d) steering: 1,000 setParameters (forces.0.fy, alternating) on a 1 kHz node, each from the
//       last body_states step the client had when it sent the request to the first published
//       step that shows the change (the step after the boundary /NS/commands says it applied
//       at): median and p99 in steps (target <= 2 steps), and the wall time to that step.
const fs = require("fs");
const os = require("os");
const path = require("path");
const { spawnSync } = require("child_process");
const lib = require("../../test/foxglove_client/lib");
const { Failure, sleep, Proc, startServer, endLine, Client } = lib;

const A = {};
for (let i = 2; i < process.argv.length; i += 2) A[process.argv[i].replace(/^--/, "")] = process.argv[i + 1];
const need = lib.npmModules(A.npm);
const work = fs.mkdtempSync(path.join(os.tmpdir(), "rbsim_bench_foxglove_"));
const domain = 100 + (process.pid % 100); // the benchmarks' domains (test/e2e uses 200..)

function grid(n, duration) {
  const file = path.join(work, `grid${n}.xml`);
  const r = spawnSync("python3", [path.join(A.root, "bench", "make_grid_scene.py"), n, 0.001, duration],
    { encoding: "utf8" });
  if (r.status !== 0) throw new Failure(r.stderr);
  fs.writeFileSync(file, r.stdout);
  return file;
}

const quantile = (xs, q) => {
  const s = [...xs].sort((a, b) => a - b);
  return s[Math.min(s.length - 1, Math.floor(q * s.length))];
};
const us = (ns) => (ns / 1000).toFixed(0);
const nowNs = () => Number(process.hrtime.bigint()); // CLOCK_MONOTONIC (libuv), to the nanosecond

async function latency() {
  const seconds = 8;
  const scene = grid(100, seconds);
  const ns = `bench_fg_${process.pid}`;
  // Both DDS ends on rbsim's loopback configuration (as scripts/bench-dds).
  const env = { ...lib.rbsimEnv(), CYCLONEDDS_URI: `file://${path.join(A.root, "node", "config", "cyclonedds-loopback.xml")}` };
  // A C++ DDS subscriber that decodes each sample with rbsim's decoder (bench/dds: listen).
  const dds = new Proc("dds", [A["bench-dds"], "listen", `/${ns}/body_states`, String(seconds + 10), "--domain",
    String(domain)], { env });
  await dds.waitFor(/READY/, 30000);
  const [node, url] = await startServer(A.rbsim, ["node", scene, "--rate", 1, "--domain", domain, "--namespace", ns],
    { env });
  const c = new Client(need, url, { name: "latency", subscribeAll: false });
  const fox = new Map(); // step -> received ns
  let size = 0;
  c.onmessage = (m) => {
    fox.set(Number(m.decoded.step), nowNs());
    size = m.data.length;
  };
  c.messages = { push() {} }; // keep nothing: a growing heap would add collector pauses to the client's latency
  await c.ready();
  for (const ch of c.channels.values()) if (ch.topic.endsWith("/body_states")) c.subscribe(ch);
  await node.wait(seconds * 1000 + 30000);
  await dds.wait(30000);
  const rows = dds.out.trim().split("\n").map((l) => l.split(" ").map(Number));
  // Steps both received, past the first second (discovery, subscription, warm-up).
  const both = rows.filter(([step]) => step >= 1000 && fox.has(step));
  if (both.length < 1000) throw new Failure(`latency: only ${both.length} steps received by both\n${dds.output()}`);
  const ddsLat = both.map(([, src, rcv]) => rcv - src);
  const foxLat = both.map(([step, , , srcMono]) => fox.get(step) - srcMono);
  const [dm, d99, fm, f99] = [quantile(ddsLat, 0.5), quantile(ddsLat, 0.99), quantile(foxLat, 0.5), quantile(foxLat, 0.99)];
  const ratio = fm / dm;
  const ratio99 = f99 / d99;
  const ok = ratio <= 2 && ratio99 <= 2;
  console.log(`(a) latency, step published -> decoded, 100 bodies (BodyStates ${size} B), ` +
    `${both.length} steps at real time, clock resolution 1 ns:`);
  console.log(`    DDS (C++ subscriber) median ${us(dm)} us, p99 ${us(d99)} us; ` +
    `Foxglove WebSocket (Node client) median ${us(fm)} us, p99 ${us(f99)} us`);
  console.log(`    ratio of medians ${ratio.toFixed(2)}x, of p99 ${ratio99.toFixed(2)}x (target <= 2x both)` +
    `: ${ok ? "met" : "MISSED"}`);
  return ok;
}

async function fanOut() {
  const seconds = 5;
  const scene = grid(1000, seconds);
  // The same node with no client: what this machine sustains without the server's work.
  const [alone] = await startServer(A.rbsim, ["node", scene, "--rate", 1, "--domain", domain,
    "--namespace", `bench_fg0_${process.pid}`]);
  await alone.wait(seconds * 1000 + 120000);
  const [node, url] = await startServer(A.rbsim, ["node", scene, "--rate", 1, "--domain", domain,
    "--namespace", `bench_fg3_${process.pid}`]);
  const clients = [0, 1, 2].map((k) => new Proc(`client${k}`, [A["fox-client"], url, "--dt-ns", "1000000",
    "--timeout", "600"], {}));
  await node.wait(seconds * 1000 + 120000);
  const results = [];
  for (const c of clients) {
    await c.wait(30000);
    results.push(JSON.parse(c.out.trim().split("\n").at(-1) || "{}"));
  }
  const end = endLine(node);
  const fox = /; (foxglove: .*)/.exec(node.err)?.[1] ?? "?";
  console.log(`(b) 1,000 bodies, dt = 1 ms, real time: node alone ${endLine(alone)?.rate} steps/s; with 3 clients ` +
    `${end?.rate} steps/s over ${end?.steps} steps; ${fox}`);
  results.forEach((r, k) => console.log(`    client ${k}: ${r.messages} messages, ${(r.bytes / 1e6).toFixed(0)} MB, ` +
    `${r.gaps} gaps in per-step topics, ${r.statuses?.length ?? "?"} status warnings`));
  const dropped = Number(/(\d+) dropped/.exec(fox)?.[1] ?? NaN);
  const ok = dropped === 0 && results.every((r) => r.gaps === 0) && end && end.rate >= 0.9 * 1000;
  console.log(`    dropped ${dropped} (target 0 for clients that keep up), real time ${end && end.rate >= 900 ? "kept" : "NOT kept"}: ${ok ? "met" : "MISSED"}`);
  return ok;
}

// Payload bytes per step of the default topics of `rbsim` (a recording, uncompressed): per-step
// topics per step, and the latched ones once.
function bytesPerStep(rbsim, tag, ...extra) {
  const steps = 100;
  const scene = grid(1000, steps * 0.001);
  const out = path.join(work, `${tag}.mcap`);
  const r = spawnSync(rbsim, ["run", scene, "--record", out, "--compression", "none", "-q", ...extra],
    { encoding: "utf8" });
  if (r.status !== 0) throw new Failure(`${rbsim} run --record: ${r.stderr}`);
  let perStep = 0;
  let once = 0;
  const topics = [];
  for (const [topic, { messages }] of lib.readMcap(need, out)) {
    const bytes = messages.reduce((s, m) => s + m.data.length, 0);
    if (messages.length === 1) once += bytes;
    else perStep += bytes / messages.length;
    topics.push(topic);
  }
  return { perStep, once, topics };
}

function bytes() {
  const after = bytesPerStep(A.rbsim, "after");
  const before = A.before ? bytesPerStep(A.before, "before") : undefined;
  const kb = (b) => `${(b / 1000).toFixed(1)} KB`;
  console.log(`(c) bytes per step, 1,000 bodies, default topics (payloads, uncompressed):`);
  if (before) console.log(`    before (${A.before}): ${kb(before.perStep)} per step + ${kb(before.once)} once [${before.topics.join(" ")}]`);
  console.log(`    after: ${kb(after.perStep)} per step + ${kb(after.once)} once [${after.topics.join(" ")}]`);
  if (!before) {
    console.log("    no --before binary: ratio not measured: MISSED");
    return false;
  }
  const ratio = before.perStep / after.perStep;
  console.log(`    ${ratio.toFixed(2)}x smaller (target >= 3x): ${ratio >= 3 ? "met" : "MISSED"}`);
  // For information: what a viewer needs (--topics tf,springs,clock; the markers come latched).
  const viewer = bytesPerStep(A.rbsim, "viewer", "--topics", "tf,springs,clock,markers");
  console.log(`    a viewer's topics only (--topics tf,springs,clock,markers): ${kb(viewer.perStep)} per step, ` +
    `${(before.perStep / viewer.perStep).toFixed(2)}x smaller than before`);
  return ratio >= 3;
}

async function steering() {
  const calls = 1000;
  const ns = `bench_steer_${process.pid}`;
  const env = { ...lib.rbsimEnv(), CYCLONEDDS_URI: `file://${path.join(A.root, "node", "config", "cyclonedds-loopback.xml")}` };
  const [node, url] = await startServer(A.rbsim, ["node", grid(100, 600), "--rate", 1, "--domain", domain, "--namespace", ns],
    { env });
  const c = new Client(need, url, { name: "steering", subscribeAll: false });
  c.messages = { push() {} };
  let lastStep = -1;
  const applied = new Map(); // command seq -> boundary step
  const seen = new Map(); // step -> received ns
  c.onmessage = (m) => {
    if (m.topic.endsWith("/body_states")) {
      lastStep = Number(m.decoded.step);
      seen.set(lastStep, nowNs());
    } else if (m.topic.endsWith("/commands")) {
      applied.set(Number(m.decoded.seq), Number(m.decoded.step));
    }
  };
  await c.ready();
  for (const ch of c.channels.values()) if (/\/(body_states|commands)$/.test(ch.topic)) c.subscribe(ch);
  await lib.until("body_states", 20000, () => lastStep > 100);
  const steps = [], wall = [];
  for (let k = 0; k < calls; k++) {
    const from = lastStep, sent = nowNs();
    c.client.setParameters([{ name: "forces.0.fy", value: k % 2 ? -9.81 : -3.7 }], `s${k}`);
    await lib.until(`command ${k}`, 5000, () => applied.has(k));
    const shown = applied.get(k) + 1; // a change at boundary b shows from step b + 1 on
    await lib.until(`step ${shown}`, 5000, () => seen.has(shown));
    steps.push(shown - from);
    wall.push(seen.get(shown) - sent);
    seen.clear();
  }
  c.close();
  node.kill("SIGINT");
  await node.wait(30000);
  const med = quantile(steps, 0.5), p99 = quantile(steps, 0.99);
  console.log(`(d) steering, ${calls} setParameters on a 1 kHz node (100 bodies): request to the first published step showing it`);
  console.log(`    steps: median ${med}, p99 ${p99} (target <= 2): ${p99 <= 2 ? "met" : med <= 2 ? "median met, p99 MISSED" : "MISSED"}`);
  console.log(`    wall: median ${us(quantile(wall, 0.5))} us, p99 ${us(quantile(wall, 0.99))} us`);
  return med <= 2 && p99 <= 2;
}

(async () => {
  const only = A.only ? A.only.split(",") : ["a", "b", "c", "d"];
  const results = [];
  try {
    if (only.includes("a")) results.push(await latency());
    if (only.includes("b")) results.push(await fanOut());
    if (only.includes("c")) results.push(bytes());
    if (only.includes("d")) results.push(await steering());
  } catch (e) {
    console.log(`bench-foxglove: ${e instanceof Failure ? e.message : e.stack}`);
    results.push(false);
  }
  fs.rmSync(work, { recursive: true, force: true });
  await sleep(10);
  process.exit(results.every(Boolean) ? 0 : 1);
})();
