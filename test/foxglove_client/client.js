#!/usr/bin/env node
"use strict";
// An independent Foxglove WebSocket client against the real `rbsim node --foxglove`: npm
// @foxglove/ws-protocol (FoxgloveClient) over `ws`, decoding with @foxglove/rosmsg and
// @foxglove/rosmsg2-serialization, the stack Foxglove Studio uses.
//
//   client.js --case NAME --rbsim BUILD/rbsim --source-dir SRC --workdir DIR --npm BUILD/npm --index N
//
// Cases: bytes (every payload equals what `rbsim run --record` writes), late_joiner (latched
// topics at once; a new session per loop), hostile (bad input gets a status error or a clean close),
// slow_client (one that stops reading loses messages and is disconnected, another loses nothing),
// faults (killed, cycling and stalled clients do not slow the node; another loses nothing), steer
// (parameters and services through the client's own calls: values, updates, pause/step/resume),
// tls (wss:// with a certificate made here by the openssl CLI: trusted, untrusted, plain ws://).
// Messages are matched by log time, which is simulated time. Only 127.0.0.1; every loop bounded.
const fs = require("fs");
const path = require("path");
const net = require("net");
const lib = require("./lib");
const { Failure, sleep, until, Proc, startServer, endLine, Client, readMcap, runMain } = lib;

const { A, workdir } = lib.caseArgs(["case", "rbsim", "source-dir", "workdir", "npm", "index"]);
const need = lib.npmModules(A.npm);
const ns = `fg_${A.case}_${process.pid}`;
const domain = lib.domainFor(Number(A.index));
const scene = (name) => path.join(A["source-dir"], "scenes", name);
const log = lib.log;
const nodeArgs = (sceneFile, ...extra) => ["node", sceneFile, "--domain", domain, "--namespace", ns, ...extra];
const start = (name, argv) => startServer(A.rbsim, argv, { name, logDir: workdir });

// A grid scene of n octagons with springs (the benchmarks' builder, bench/make_grid_scene.py).
function gridScene(n, dt, duration) {
  const file = path.join(workdir, `grid${n}.xml`);
  const r = require("child_process").spawnSync("python3",
    [path.join(A["source-dir"], "bench", "make_grid_scene.py"), n, dt, duration], { encoding: "utf8" });
  if (r.status !== 0) throw new Failure(`make_grid_scene.py: ${r.stderr}`);
  fs.writeFileSync(file, r.stdout);
  return file;
}

// Topics the node publishes once (latched): one message in the recording.
const latchedIn = (rec) => new Set([...rec].filter(([, t]) => t.messages.length === 1).map(([topic]) => topic));

// Per-step topic messages of a client that kept up: contiguous steps from its first to the last
// one published (times of consecutive steps differ by the recording's step).
function contiguous(check, who, msgs, want) {
  if (!check(msgs.length > 0, `${who}: no messages`)) return;
  const first = want.findIndex((w) => w.time === msgs[0].time);
  if (!check(first >= 0, `${who}: first message at ${msgs[0].time} ns is not a recorded step`)) return;
  const expected = want.length - first;
  check(msgs.length === expected && msgs.every((m, i) => m.time === want[first + i].time),
    `${who}: ${msgs.length} messages from step time ${msgs[0].time} ns, want every one of the ${expected} ` +
      `recorded from there (first gap at ${msgs.findIndex((m, i) => m.time !== want[first + i]?.time)})`);
}

// ---------------------------------------------------------------------------------------------

async function caseBytes(check) {
  // The same scene recorded by `rbsim run --record` (every step, uncompressed for @mcap/core).
  const sceneFile = scene("airplane.xml");
  const duration = 3;
  const mcap = path.join(workdir, "run.mcap");
  const run = new Proc("run", [A.rbsim, "run", sceneFile, "--duration", duration, "--record", mcap,
    "--compression", "none", "--namespace", ns].map(String), { logDir: workdir });
  if ((await run.wait(60000)) !== 0) throw new Failure(`rbsim run exited with ${run.code}\n${run.output()}`);
  const rec = readMcap(need, mcap);
  const latched = latchedIn(rec);
  log(`recording: ${[...rec].map(([t, v]) => `${t} ${v.messages.length}`).join(", ")}`);

  // Real time, so a client that connects right after the listening line sees nearly every step.
  const [node, url] = await start("node", nodeArgs(sceneFile, "--rate", 1, "--duration", duration));
  // Decoded after the run: a receive path light enough to keep up at 1,000 steps/s on a busy machine.
  const c = await new Client(need, url, { name: "client", decode: "later" }).ready();
  check(c.ws.protocol === "foxglove.websocket.v1", `negotiated subprotocol ${c.ws.protocol}`);
  check(c.serverInfo.capabilities.includes("time"), `serverInfo capabilities ${c.serverInfo.capabilities}`);
  check(typeof c.serverInfo.sessionId === "string" && c.serverInfo.sessionId.length > 0, "serverInfo has no sessionId");
  // Every recorded topic, and the node's commands (a run without commands records none).
  const served = [...rec.keys(), `/${ns}/commands`].sort();
  check(JSON.stringify(c.topics()) === JSON.stringify(served), `advertised ${c.topics()}, want ${served}`);
  for (const ch of c.channels.values()) {
    const want = rec.get(ch.topic)?.channel;
    if (!want) continue;
    check(ch.encoding === "cdr" && ch.schemaEncoding === "ros2msg",
      `${ch.topic}: encoding ${ch.encoding}, schemaEncoding ${ch.schemaEncoding}`);
    check(ch.schemaName === want.schemaName, `${ch.topic}: schema name ${ch.schemaName}, MCAP ${want.schemaName}`);
    check(ch.schema === want.schema, `${ch.topic}: schema text differs from the MCAP's`);
  }
  check((await node.wait(60000)) === 0, `node exited with ${node.code}\n${node.output()}`);
  await until("the server to close the connection", 5000, () => c.closed);
  c.decodeAll();
  // A client that fell behind anyway (a CPU-starved machine) loses the oldest per-step messages:
  // then it must have been told so (a status warning); otherwise every step must be there.
  const warned = c.statuses.some((s) => s.level === 1);

  const got = c.byTopic();
  let compared = 0;
  for (const [topic, { messages: want }] of rec) {
    const msgs = got.get(topic) ?? [];
    const byTime = new Map(want.map((w) => [w.time, w.data]));
    let bad = 0;
    for (const m of msgs) {
      const data = latched.has(topic) ? want[0].data : byTime.get(m.time);
      if (!data || !data.equals(m.data)) bad++;
      compared++;
    }
    check(bad === 0, `${topic}: ${bad} of ${msgs.length} payloads differ from the recording's (matched by log time)`);
    if (latched.has(topic)) {
      check(msgs.length === 1, `${topic} (latched): ${msgs.length} messages, want exactly 1`);
    } else {
      if (!warned) contiguous(check, topic, msgs, want);
      check(msgs.length >= want.length / 2, `${topic}: only ${msgs.length} of ${want.length} steps received`);
      for (const m of msgs) {
        const stamp = m.decoded.header?.stamp ?? m.decoded.clock ?? m.decoded.transforms?.[0]?.header.stamp;
        if (stamp && BigInt(stamp.sec) * 1000000000n + BigInt(stamp.nanosec) !== m.time) {
          check(false, `${topic}: decoded stamp ${stamp.sec}.${stamp.nanosec} != log time ${m.time}`);
          break;
        }
      }
    }
  }
  check(c.messages.every((m) => m.decoded !== undefined), "a message was not decoded");
  check(c.times.length > 0 && c.times.every((t, i) => i === 0 || t >= c.times[i - 1]),
    `time messages: ${c.times.length}, want some, non-decreasing`);
  log(`${compared} payloads compared byte for byte, ${c.times.length} time messages` +
    (warned ? `; fell behind: ${c.statuses.map((s) => s.message).join("; ")}` : ""));
}

// The topics a run publishes once (latched), from a short `rbsim run --record` of the scene.
async function latchedTopics(sceneFile) {
  const mcap = path.join(workdir, "latched.mcap");
  const run = new Proc("run-latched", [A.rbsim, "run", sceneFile, "--duration", "0.01", "--record", mcap,
    "--compression", "none", "--namespace", ns], { logDir: workdir });
  if ((await run.wait(60000)) !== 0) throw new Failure(`rbsim run exited with ${run.code}\n${run.output()}`);
  return [...latchedIn(readMcap(need, mcap))];
}

async function caseLateJoiner(check) {
  const sceneFile = scene("cantilever.xml");
  const latched = await latchedTopics(sceneFile);
  const [node, url] = await start("node", nodeArgs(sceneFile, "--rate", 1, "--duration", 1, "--loop"));
  const a = new Client(need, url, { name: "early" });
  const seenByA = new Set();
  a.client.on("serverInfo", (info) => seenByA.add(info.sessionId));
  await a.ready();
  await sleep(1500); // past the first loop: the latched messages went out long ago
  const t0 = performance.now();
  const b = new Client(need, url, { name: "late" });
  await b.ready();
  const session = b.serverInfo.sessionId;
  check(latched.length > 0 && latched.every((t) => b.topics().includes(t)),
    `latched topics ${latched} not all advertised (${b.topics()})`);
  await until("latched messages for the late joiner", 2000, () =>
    latched.every((t) => b.messages.some((m) => m.topic === t)));
  log(`late joiner got ${latched} ${(performance.now() - t0).toFixed(0)} ms after connecting`);
  for (const t of latched) {
    const first = b.messages.findIndex((m) => m.topic === t);
    const early = a.messages.filter((m) => m.topic === t).at(-1);
    check(early && early.data.equals(b.messages[first].data), `${t}: late joiner's copy differs from the early client's`);
  }
  // A new session on every start of the scene: serverInfo again with a new sessionId.
  await until("a new session for the late joiner", 10000, () => b.serverInfo.sessionId !== session).catch(() => {});
  check(b.serverInfo.sessionId !== session, "the late joiner saw no new sessionId within 10 s of a 1 s looping scene");
  check(seenByA.size >= 3, `the early client saw ${seenByA.size} sessionIds over 3 passes of the scene, want 3`);
  node.kill("SIGINT");
  check((await node.wait(15000)) === 0, `node exited with ${node.code} on SIGINT\n${node.output()}`);
}

// A raw WebSocket (no FoxgloveClient) for inputs no well-behaved client sends.
function raw(url, protocols) {
  const WebSocket = need("ws");
  const ws = new WebSocket(url, protocols, { maxPayload: 64 << 20 });
  const r = { ws, statuses: [], opened: false, closeCode: undefined, refused: undefined };
  ws.on("open", () => (r.opened = true));
  ws.on("message", (data, isBinary) => {
    if (isBinary) return;
    const msg = JSON.parse(data.toString());
    if (msg.op === "status") r.statuses.push(msg);
  });
  ws.on("unexpected-response", (_req, res) => {
    r.refused = res.statusCode;
    ws.terminate();
  });
  ws.on("error", (e) => (r.error = e.message));
  ws.on("close", (code) => (r.closeCode = code));
  return r;
}

// Sends `frames` on a fresh connection; the server must answer with a status error or close
// cleanly (a close frame, not a dropped socket).
async function expectRejected(check, url, what, send) {
  const r = raw(url, ["foxglove.websocket.v1"]);
  await until(`${what}: open`, 5000, () => r.opened || r.closeCode !== undefined);
  send(r.ws);
  await until(`${what}: a status error or a close`, 5000,
    () => r.statuses.some((s) => s.level === 2) || r.closeCode !== undefined).catch(() => {});
  const clean = r.closeCode !== undefined && r.closeCode !== 1006;
  check(r.statuses.some((s) => s.level === 2) || clean,
    `${what}: no status error, close code ${r.closeCode}`);
  log(`${what}: ${r.statuses.length ? `status "${r.statuses.at(-1).message}"` : `closed ${r.closeCode}`}`);
  r.ws.terminate();
}

async function caseHostile(check) {
  const [node, url] = await start("node", nodeArgs(scene("cantilever.xml"), "--rate", 1, "--loop"));
  // The handshake: any subprotocol but Foxglove's two is refused; either of those is accepted.
  for (const protos of [["foo.bar.v1"], []]) {
    const r = raw(url, protos);
    await until(`handshake ${protos}`, 5000, () => r.opened || r.refused !== undefined || r.closeCode !== undefined);
    check(!r.opened, `subprotocols [${protos}] accepted: want the handshake refused`);
    r.ws.terminate();
  }
  for (const protos of [["foxglove.sdk.v1"], ["foxglove.websocket.v1"], ["x", "foxglove.sdk.v1"]]) {
    const r = raw(url, protos);
    await until(`handshake ${protos}`, 5000, () => r.opened || r.closeCode !== undefined);
    check(r.opened && protos.includes(r.ws.protocol), `subprotocols [${protos}]: opened ${r.opened}, chose ${r.ws.protocol}`);
    r.ws.terminate();
  }
  await expectRejected(check, url, "malformed JSON", (ws) => ws.send("{\"op\": \"subscribe\", "));
  await expectRejected(check, url, "not an object", (ws) => ws.send("[1, 2, 3]"));
  await expectRejected(check, url, "unknown op", (ws) => ws.send(JSON.stringify({ op: "frobnicate" })));
  await expectRejected(check, url, "subscribe without fields", (ws) => ws.send(JSON.stringify({ op: "subscribe" })));
  await expectRejected(check, url, "unknown channel id", (ws) =>
    ws.send(JSON.stringify({ op: "subscribe", subscriptions: [{ id: 1, channelId: 987654 }] })));
  await expectRejected(check, url, "unknown subscription id", (ws) =>
    ws.send(JSON.stringify({ op: "unsubscribe", subscriptionIds: [424242] })));
  await expectRejected(check, url, "client binary frame", (ws) => ws.send(Buffer.from([1, 7, 0, 0, 0, 1, 2, 3])));
  await expectRejected(check, url, "empty binary frame", (ws) => ws.send(Buffer.alloc(0)));
  await expectRejected(check, url, "text frame over 1 MiB", (ws) =>
    ws.send(JSON.stringify({ op: "subscribe", subscriptions: [], pad: "x".repeat((1 << 20) + 10) })));
  await expectRejected(check, url, "binary frame over 1 MiB", (ws) => ws.send(Buffer.alloc((1 << 20) + 10, 1)));

  // Hundreds of connects and disconnects: clean closes, abrupt resets, TCP connections that never
  // finish the handshake, 20 at a time.
  const port = Number(new URL(url).port);
  const t0 = performance.now();
  for (let round = 0; round < 15; round++) {
    await Promise.all(Array.from({ length: 20 }, (_, k) => churn(url, port, (round * 20 + k) % 4)));
  }
  log(`300 connects/disconnects in ${((performance.now() - t0) / 1000).toFixed(1)} s`);
  check(node.alive(), `the node died\n${node.output()}`);
  // Still serving: a well-behaved client gets advertisements and data.
  const c = await new Client(need, url, { name: "after" }).ready();
  await until("data after the abuse", 5000, () => c.messages.length > 50);
  c.close();
  node.kill("SIGINT");
  check((await node.wait(15000)) === 0, `node exited with ${node.code}\n${node.output()}`);
  check(endLine(node) !== undefined, `no end line\n${node.err}`);
}

// One connect/disconnect of a given kind, bounded by a 5 s timer.
function churn(url, port, kind) {
  return new Promise((resolve) => {
    const done = () => {
      clearTimeout(timer);
      resolve();
    };
    const timer = setTimeout(done, 5000);
    if (kind === 3) {
      // TCP only, half a handshake, then gone.
      const s = net.connect(port, "127.0.0.1", () => {
        s.write("GET / HTTP/1.1\r\nHost: 127.0.0.1\r\nUpgrade: websocket\r\n");
        s.destroy();
        done();
      });
      s.on("error", done);
      return;
    }
    const r = raw(url, ["foxglove.websocket.v1"]);
    r.ws.on("open", () => {
      if (kind === 0) r.ws.close(1000);
      else if (kind === 1) r.ws.terminate();
      else r.ws.send(JSON.stringify({ op: "subscribe", subscriptions: [{ id: 1, channelId: 1 }] }), () => r.ws.terminate());
    });
    r.ws.on("close", done);
    r.ws.on("error", done);
  });
}

// Stops reading from the socket: the kernel buffers fill, then the server's queue.
const stall = (client) => client.ws._socket.pause();

async function caseSlowClient(check) {
  const duration = 12;
  const sceneFile = gridScene(100, 0.001, duration);
  const [node, url] = await start("node", nodeArgs(sceneFile, "--rate", 1));
  const good = await new Client(need, url, { name: "good", decode: false }).ready();
  const slow = await new Client(need, url, { name: "slow", decode: false }).ready();
  await until("data", 5000, () => slow.messages.length > 100);
  stall(slow);
  const stalledAt = slow.messages.length;
  log(`slow client stops reading after ${stalledAt} messages`);
  await sleep(9000);
  slow.ws._socket.resume();
  // Whatever was in flight arrives, then the status warning and the close (or the reset).
  await until("the stalled client to be disconnected", 8000, () => slow.closed);
  check(slow.closed, "the client that stopped reading was not disconnected");
  check((await node.wait(60000)) === 0, `node exited with ${node.code}\n${node.output()}`);
  log(node.err.trim().split("\n").at(-1));
  check(/\d+ disconnected for not reading/.test(node.err), `end line does not count the disconnect\n${node.err}`);
  const perStep = [...good.byTopic()].filter(([t]) => !/\/(scene|markers)$/.test(t));
  check(perStep.length > 0, "good client: no per-step topics");
  for (const [topic, msgs] of perStep) {
    // The good client kept up: every step from its first to the node's last.
    const last = msgs.at(-1).time;
    const dt = msgs.length > 1 ? msgs[1].time - msgs[0].time : 1n;
    const expected = Number((last - msgs[0].time) / dt) + 1;
    check(msgs.length === expected, `good client lost ${expected - msgs.length} of ${expected} on ${topic}`);
    check(last === BigInt(Math.round(duration * 1e9)),
      `good client: last ${topic} at ${last} ns, want the last step's ${duration} s`);
  }
}

// A client in a child process: prints STREAMING once messages flow; with keep, on the server's
// close one JSON line { topic: [count, first ns, last ns, gaps] } of what it received.
function childClient(url, name, keep = false) {
  return new Proc(name, [process.execPath, __filename, "--case", "child", "--url", url, "--npm", A.npm, "--keep",
    keep ? "1" : "", "--rbsim", "-", "--source-dir", "-", "--workdir", path.join(workdir, name), "--index", "0"],
  { logDir: workdir });
}

async function caseChild() {
  const c = new Client(need, A.url, { name: "child", decode: false });
  const topics = {};
  let n = 0;
  c.messages = { push: () => ++n === 100 && console.log("STREAMING") }; // keep nothing but counts
  c.onmessage = (m) => {
    const t = (topics[m.topic] ??= [0, m.time, m.time, 0, []]);
    if (t[0] > 0 && m.time - BigInt(t[2]) !== 1000000n && t[3]++ < 3) t[4].push(`${t[2]}..${m.time}`);
    t[0]++;
    t[2] = m.time;
  };
  await until("the server to close", A.keep ? 120000 : 60000, () => c.closed, 50).catch(() => {});
  if (A.keep) console.log(JSON.stringify(topics, (_, v) => (typeof v === "bigint" ? Number(v) : v)));
}

async function caseFaults(check) {
  // Real time with dt = 1 ms: the node's step rate is the real-time rate while nothing holds it up.
  const steps = 6000;
  // 20 bodies: light enough that the node keeps real time on a busy 2-core machine, so a server
  // that held it up would show.
  const sceneFile = gridScene(20, 0.001, steps / 1000);
  const [base] = await start("baseline", nodeArgs(sceneFile, "--rate", 1));
  check((await base.wait(60000)) === 0, `baseline node exited with ${base.code}\n${base.output()}`);
  const want = endLine(base);
  if (!want) throw new Failure(`baseline: no end line\n${base.err}`);

  const [node, url] = await start("node", nodeArgs(sceneFile, "--rate", 1));
  // The client that must lose nothing in its own process, away from this one's churn.
  const good = childClient(url, "good", true);
  await good.waitFor(/STREAMING/, 10000);
  const stalled = await new Client(need, url, { name: "stalled", decode: false }).ready();
  stall(stalled);
  const port = Number(new URL(url).port);
  // Clients in other processes killed mid-stream, while 100 connect/disconnect cycles run.
  const children = Array.from({ length: 4 }, (_, k) => childClient(url, `killed${k}`));
  const cycles = (async () => {
    for (let k = 0; k < 100; k++) await churn(url, port, k % 4);
  })();
  for (const [k, child] of children.entries()) {
    await child.waitFor(/STREAMING/, 10000); // killed with messages flowing
    await sleep(300 * k);
    child.kill("SIGKILL");
  }
  await cycles;
  check((await node.wait(60000)) === 0, `node exited with ${node.code}\n${node.output()}`);
  const got = endLine(node);
  log(`no clients: ${want.rate} steps/s; with killed, cycling, stalled and one good client: ${got?.rate} steps/s`);
  log(node.err.trim().split("\n").at(-1));
  check(got && got.steps === want.steps, `node ran ${got?.steps} steps, want ${want.steps}`);
  if (A.sanitized) {
    log("sanitized build: step rates not compared (instrumented binaries)");
  } else {
    check(got && Math.abs(got.rate - want.rate) <= 0.1 * want.rate,
      `step rate ${got?.rate} steps/s, want within 10% of ${want.rate} (no clients)`);
  }
  await good.wait(20000);
  const got1 = JSON.parse(good.out.trim().split("\n").at(-1) || "{}");
  check(Object.keys(got1).length > 0, `good client: nothing received\n${good.output()}`);
  for (const [topic, [count, first, last, gaps, where]] of Object.entries(got1)) {
    if (count === 1) continue; // latched
    check(gaps === 0, `good client: ${gaps} gaps in ${topic} (${count} messages from ${first} ns; ${where} ns)`);
    check(last === steps * 1e6, `good client: last ${topic} at ${last} ns, want the last step's ${steps * 1e6} ns`);
  }
}

// Steering through Foxglove's own client: the parameters listed and set (the update reaches a
// subscriber), then pause, step and resume called over cdr (and step over json), each reply
// checked and the published body_states stopping, advancing and going on as the replies say.
async function caseSteer(check) {
  const [node, url] = await start("node", nodeArgs(scene("cantilever.xml"), "--rate", 1, "--duration", 120));
  const c = new Client(need, url, { name: "steer", subscribeAll: false });
  const values = [];
  const responses = new Map();
  const failures = [];
  let services;
  c.client.on("parameterValues", (m) => values.push(m));
  c.client.on("advertiseServices", (s) => (services = s));
  c.client.on("serviceCallResponse", (r) => responses.set(r.callId, r));
  c.client.on("serviceCallFailure", (f) => failures.push(f));
  await c.ready();
  const caps = c.serverInfo.capabilities;
  check(["time", "parameters", "parametersSubscribe", "services"].every((k) => caps.includes(k)), `capabilities ${caps}`);
  check(JSON.stringify(c.serverInfo.supportedEncodings) === JSON.stringify(["cdr", "json"]),
    `supportedEncodings ${c.serverInfo.supportedEncodings}`);
  await until("advertiseServices", 5000, () => services);
  const svc = (name) => services.find((s) => s.name === `/${ns}/${name}`);
  check(["pause", "resume", "reset", "step", "apply_impulse"].every(svc), `services ${services.map((s) => s.name)}`);
  const states = [...c.channels.values()].find((ch) => ch.topic === `/${ns}/body_states`);
  if (!states) throw new Failure(`no /${ns}/body_states channel`);
  c.subscribe(states);
  const lastStep = () => {
    const m = c.messages.at(-1);
    return m ? Number(m.decoded.step) : -1;
  };
  await until("body_states", 5000, () => lastStep() > 0);

  // Parameters: all of them, typed; a set answered and seen by the subscription.
  const answer = (id) => until(`parameterValues ${id}`, 5000, () => values.find((v) => v.id === id));
  c.client.getParameters([], "all");
  const all = await answer("all");
  const param = (m, name) => m.parameters.find((p) => p.name === name);
  check(param(all, "forces.0.fy")?.type === "float64", `forces.0.fy: ${JSON.stringify(param(all, "forces.0.fy"))}`);
  check(param(all, "bodies")?.type === undefined && Number.isInteger(param(all, "bodies")?.value),
    `bodies: ${JSON.stringify(param(all, "bodies"))}`);
  check(param(all, "paused")?.value === false, `paused: ${JSON.stringify(param(all, "paused"))}`);
  log(`${all.parameters.length} parameters: ${all.parameters.map((p) => p.name).join(", ")}`);
  c.client.subscribeParameterUpdates(["forces.0.fy", "paused"]);
  c.client.getParameters(["paused"], "sync");  // answered after the subscription took effect
  await answer("sync");
  c.client.setParameters([{ name: "forces.0.fy", value: -3.7 }], "set");
  const set = await answer("set");
  check(param(set, "forces.0.fy")?.value === -3.7, `set answer ${JSON.stringify(set)}`);
  const update = (name, value) => until(`an update of ${name} to ${value}`, 5000,
    () => values.find((v) => v.id === undefined && param(v, name)?.value === value));
  await update("forces.0.fy", -3.7);
  c.client.setParameters([{ name: "bodies", value: 9 }, { name: "rate", value: "fast" }], "bad");
  await answer("bad");
  const refusal = await until("a status error naming the refused parameters", 5000,
    () => c.statuses.find((s) => s.level === 2 && /bodies/.test(s.message) && /rate/.test(s.message)));
  log(`refused: ${refusal.message}`);

  // Services over cdr with the advertised schemas (and json), as Foxglove Studio calls them.
  const { parse } = need("@foxglove/rosmsg");
  const { MessageWriter, MessageReader } = need("@foxglove/rosmsg2-serialization");
  let callId = 0;
  const call = async (name, request, encoding = "cdr") => {
    const s = svc(name);
    const id = ++callId;
    const data = encoding === "cdr"
      ? new MessageWriter(parse(s.request.schema, { ros2: true })).writeMessage(request)
      : new TextEncoder().encode(JSON.stringify(request));
    c.client.sendServiceCallRequest({ serviceId: s.id, callId: id, encoding, data: new DataView(data.buffer, data.byteOffset, data.byteLength) });
    const r = await until(`the reply to ${name}`, 10000, () => responses.get(id) ?? failures.find((f) => f.callId === id));
    if (r.op === "serviceCallFailure") throw new Failure(`${name}: serviceCallFailure ${r.message}`);
    check(r.serviceId === s.id && r.encoding === encoding, `${name}: reply for service ${r.serviceId} in ${r.encoding}`);
    return encoding === "cdr"
      ? new MessageReader(parse(s.response.schema, { ros2: true })).readMessage(r.data)
      : JSON.parse(new TextDecoder().decode(r.data));
  };
  const steady = async (what, want) => {
    await until(`${what}: body_states at step ${want}`, 5000, () => lastStep() >= want);
    await sleep(400);
    check(lastStep() === want, `${what}: published up to step ${lastStep()}, want ${want}`);
  };
  const paused = await call("pause", {});
  const at = Number(/paused at step (\d+)/.exec(paused.message)?.[1]);
  check(paused.success === true && at > 0, `pause: ${JSON.stringify(paused)}`);
  await update("paused", true);
  await steady("paused", at);
  const stepped = await call("step", { steps: 5 });
  check(stepped.success === true && Number(stepped.step) === at + 5, `step: ${JSON.stringify(stepped, (k, v) => (typeof v === "bigint" ? Number(v) : v))}`);
  await steady("stepped 5", at + 5);
  const jsonStep = await call("step", { steps: 2 }, "json");
  check(jsonStep.success === true && jsonStep.step === at + 7, `step (json): ${JSON.stringify(jsonStep)}`);
  await steady("stepped 2 more", at + 7);
  const resumed = await call("resume", {});
  check(resumed.success === true, `resume: ${JSON.stringify(resumed)}`);
  await update("paused", false);
  await until("body_states after the resume", 5000, () => lastStep() > at + 100);
  log(`paused at ${at}, stepped to ${at + 7}, resumed: now at ${lastStep()}`);
  // A call of a service that does not exist.
  c.client.sendServiceCallRequest({ serviceId: 999, callId: 4242, encoding: "cdr", data: new DataView(new ArrayBuffer(0)) });
  const unknown = await until("a serviceCallFailure", 5000, () => failures.find((f) => f.callId === 4242));
  check(/unknown service 999/.test(unknown.message), `unknown service: ${unknown.message}`);
  c.close();
  node.kill("SIGINT");
  check((await node.wait(15000)) === 0, `node exited with ${node.code}\n${node.output()}`);
  check(/foxglove: .*\d+ requests/.test(node.err), `the end line counts no requests\n${node.err}`);
}

// `rbsim node --foxglove-tls CERT KEY` serves wss://: a client trusting the test certificate
// (made here with the openssl CLI for 127.0.0.1) gets serverInfo and the node's messages; one that
// does not trust it is refused by its own certificate check, and a plain ws:// client gets no
// WebSocket.
async function caseTls(check) {
  const cert = path.join(workdir, "cert.pem");
  const key = path.join(workdir, "key.pem");
  const r = require("child_process").spawnSync("openssl", ["req", "-x509", "-newkey", "rsa:2048", "-nodes",
    "-keyout", key, "-out", cert, "-days", "1", "-subj", "/CN=127.0.0.1", "-addext", "subjectAltName=IP:127.0.0.1"],
  { encoding: "utf8" });
  if (r.status !== 0) throw new Failure(`openssl req: ${r.stderr}`);
  const node = new Proc("node", [A.rbsim, ...nodeArgs(scene("airplane.xml"), "--rate", 1, "--duration", 30),
    "--foxglove", "127.0.0.1:0", "--foxglove-tls", cert, key].map(String), { logDir: workdir });
  const url = (await node.waitFor(/foxglove: listening on (wss:\/\/127\.0\.0\.1:\d+)/, 20000))[1];
  // The link is the line after the listening one: wait for it (its own line), then check it.
  const link = (await node.waitFor(/foxglove: open (\S+)\n/, 20000))[1];
  check(/^https:\/\/app\.foxglove\.dev\/\?ds=foxglove-websocket&ds\.url=wss%3A%2F%2F127\.0\.0\.1/.test(link),
    `the printed link is not wss://: ${link}`);
  const c = await new Client(need, url, { name: "trusting", wsOptions: { ca: fs.readFileSync(cert) } }).ready();
  check(c.serverInfo.capabilities.includes("parameters"), `serverInfo capabilities ${c.serverInfo.capabilities}`);
  await until("messages over wss://", 10000, () => c.messages.length >= 20);
  const untrusting = new Client(need, url, { name: "untrusting", decode: false });
  await until("the untrusting client's refusal", 10000, () => untrusting.error || untrusting.closed);
  check(!untrusting.serverInfo, "a client that does not trust the certificate got serverInfo");
  check(/certificate/i.test(String(untrusting.error?.message ?? untrusting.error)),
    `untrusting client: ${untrusting.error?.message ?? "no error"}, want a certificate error`);
  const plain = new Client(need, url.replace("wss://", "ws://"), { name: "plain", decode: false });
  await until("the plain ws:// client's refusal", 10000, () => plain.error || plain.closed);
  check(!plain.serverInfo, "a plain ws:// client got serverInfo from the wss:// server");
  const before = c.messages.length;
  await until("messages after the refused clients", 10000, () => c.messages.length > before + 10);
  node.kill("SIGINT");
  check((await node.wait(30000)) === 0, `node exited with ${node.code}\n${node.output()}`);
  check(/foxglove: 1 client,/.test(node.err), `end line: want 1 client\n${node.output()}`);
  log(`${c.messages.length} messages over wss://`);
}

// A node serving with a token (RBSIM_FOXGLOVE_TOKEN) under attack on its Foxglove port while an
// authenticated viewer watches at 1 kHz: 200 clients with wrong tokens (401, then 429 once the
// address is rate-limited), 100 sockets that never speak (closed at the 5 s handshake timeout), an
// oversized header; once the failure window passed, a wrong token then the right one. The viewer
// loses no step (every body_states in order, 0 dropped in the end line) and the node keeps its
// real-time step rate; the end line counts each refusal.
async function caseAccess(check) {
  const token = "rbsim-access-test-token-0123456789";
  const env = { ...lib.rbsimEnv(), RBSIM_FOXGLOVE_TOKEN: token };
  const duration = 25;
  const [node, url] = await startServer(A.rbsim, nodeArgs(scene("chain.xml"), "--rate", 1, "--duration", duration),
    { name: "node", logDir: workdir, env });
  check(/token required/.test(node.err), `the listening line does not say a token is required:\n${node.err}`);
  const viewer = new Client(need, `${url}/?token=${token}`, { name: "viewer", subscribeAll: false, decode: "later" });
  viewer.client.on("advertise", (chans) => chans.filter((c) => c.topic === `/${ns}/body_states`).forEach((c) => viewer.subscribe(c)));
  await viewer.ready();
  await until("the viewer's first body states", 10000, () => viewer.messages.length > 100);

  const refused = (query, headers = {}) => new Promise((resolve) => {
    const WebSocket = need("ws");
    const ws = new WebSocket(`${url}/${query}`, ["foxglove.websocket.v1"], { headers });
    const done = (v) => { ws.terminate(); resolve(v); };
    ws.on("unexpected-response", (_req, res) => done(res.statusCode));
    ws.on("open", () => done(101));
    ws.on("error", (e) => done(e.message));
  });
  const codes = new Map();
  for (let batch = 0; batch < 10; batch++) {
    const got = await Promise.all(Array.from({ length: 20 }, (_, i) => refused(`?token=wrong-${batch}-${i}`)));
    for (const c of got) codes.set(c, (codes.get(c) ?? 0) + 1);
  }
  check([...codes.keys()].every((c) => c === 401 || c === 429) && (codes.get(401) ?? 0) >= 1,
    `200 wrong tokens: ${JSON.stringify([...codes])}, want only 401 and 429`);
  const silent = Array.from({ length: 100 }, () => net.connect(Number(new URL(url).port), "127.0.0.1"));
  const closed = silent.map((s) => new Promise((resolve) => s.on("close", resolve)));
  silent.forEach((s) => s.on("error", () => {}));
  const big = await refused(`?token=${token}`, { "X-Padding": "x".repeat(20000) });
  check(big === 431 || big === 429 || typeof big === "string", `an oversized header got ${big}`);
  await Promise.race([Promise.all(closed), sleep(12000)]);
  check(silent.every((s) => s.destroyed), `${silent.filter((s) => !s.destroyed).length} silent sockets still open`);
  await sleep(10500); // the failure window (10 s) passes: the address is no longer rate-limited
  check((await refused("?token=still-wrong")) === 401, "a wrong token after the window: want 401");
  const late = new Client(need, `${url}/?token=${token}`, { name: "late", subscribeAll: false, decode: false });
  await late.ready();
  check(!!late.serverInfo, "the right token after the attack got no serverInfo");
  late.close();

  check((await node.wait(60000)) === 0, `node exited with ${node.code}\n${node.output()}`);
  await until("the viewer's last body states", 5000, () => viewer.closed).catch(() => {});
  viewer.decodeAll();
  const steps = viewer.messages.map((m) => Number(m.decoded.step));
  const gaps = steps.filter((s, i) => i > 0 && s !== steps[i - 1] + 1).length;
  check(gaps === 0, `the viewer's body states have ${gaps} gaps (${steps.length} received, ${steps[0]}..${steps.at(-1)})`);
  check(steps.at(-1) === duration * 1000, `the viewer's last step ${steps.at(-1)}, want ${duration * 1000}`);
  const end = endLine(node);
  check(end, `no end line:\n${node.err}`);
  if (end && !A.sanitized) check(end.rate > 950 && end.rate < 1050, `the node's step rate ${end.rate}, want 1000 (real time)`);
  check(/ 0 dropped for slow clients/.test(node.err), `end line: want 0 dropped\n${node.err}`);
  const counted = Number(/(\d+) refused without the right token/.exec(node.err)?.[1] ?? 0) +
    Number(/(\d+) rate-limited/.exec(node.err)?.[1] ?? 0);
  check(counted >= 201, `end line: ${counted} refused or rate-limited, want >= 201\n${node.err}`);
  check(/100 closed for an unfinished handshake/.test(node.err), `end line: want 100 handshake timeouts\n${node.err}`);
  log(`viewer: ${steps.length} steps, no gap; refusals ${JSON.stringify([...codes])}; node ${end?.rate} steps/s`);
}

const cases = { bytes: caseBytes, late_joiner: caseLateJoiner, hostile: caseHostile, slow_client: caseSlowClient,
  faults: caseFaults, steer: caseSteer, tls: caseTls, access: caseAccess };
if (A.case === "child") caseChild();
else if (!cases[A.case]) throw new Error(`unknown case ${A.case}`);
else runMain(`foxglove_client.${A.case}`, cases[A.case]);
