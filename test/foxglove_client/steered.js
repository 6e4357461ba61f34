#!/usr/bin/env node
"use strict";
// A session steered from Foxglove's own client (npm @foxglove/ws-protocol), recorded over DDS by
// `rbsim record` and re-simulated from that recording:
//
//   steered.js --rbsim BUILD/rbsim --source-dir SRC --workdir DIR --npm BUILD/npm --index N [--via bridge]
//
// With --via bridge the client talks to `rbsim bridge`, which relays everything to the node's ROS 2
// services over DDS (the node records the commands with source "ros2 service"); the session and
// its re-simulation are the same.
// `rbsim node --foxglove` waits for the recorder; the client sets forces.0.fy (setParameters),
// pauses and steps 5 (services, cdr), applies an impulse (a command published on /NS/command_in,
// json: clientPublish), steps 1 and resumes (published, cdr). The recording's /NS/commands holds the six
// with source "foxglove", the published body_states react to the impulse, and
// `rbsim run --commands live.mcap --record rerun.mcap` then `rbsim check rerun.mcap live.mcap
// --ignore-log-time` passes, while the same check against a run without the commands fails.
// Only 127.0.0.1 and its own DDS domain; every wait bounded.
const fs = require("fs");
const path = require("path");
const lib = require("./lib");
const { Failure, until, Proc, startServer, Client, readMcap, runMain } = lib;

const { A, workdir } = lib.caseArgs(["rbsim", "source-dir", "workdir", "npm", "index"]);
const need = lib.npmModules(A.npm);
const ns = `fg_steered_${process.pid}`;
const domain = lib.domainFor(Number(A.index));
const log = lib.log;
const bigint = (k, v) => (typeof v === "bigint" ? Number(v) : v);
const viaBridge = A.via === "bridge";
if (A.via !== undefined && !viaBridge) throw new Error(`--via ${A.via}: only "bridge"`);
// What the node records as the commands' source: the bridge calls the node's ROS 2 services.
const source = viaBridge ? "ros2 service" : "foxglove";

// rbsim's own commands, each bounded; `ok`: exit 0 required.
async function rbsim(name, argv, ok = true) {
  const p = new Proc(name, [A.rbsim, ...argv.map(String)], { logDir: workdir });
  const code = await p.wait(120000);
  if (ok && code !== 0) throw new Failure(`rbsim ${argv.join(" ")} exited with ${code}\n${p.output()}`);
  return p;
}

async function main(check) {
  const scene = path.join(A["source-dir"], "scenes", "chain.xml");
  const duration = 3; // simulated seconds at dt 0.001, real time: the node runs about 3 s plus its pause
  const steps = 3000;
  const live = path.join(workdir, "live.mcap");
  // scene + markers, 6 per-step topics at steps 0..steps, and the 6 commands: then the recorder stops.
  const expected = 2 + 6 * (steps + 1) + 6;
  const rec = new Proc("record", [A.rbsim, "record", live, "--domain", domain, "--namespace", ns, "--max-messages",
    expected, "--wall-duration", 120, "--compression", "none"].map(String), { logDir: workdir });
  const nodeArgs = ["node", scene, "--domain", domain, "--namespace", ns, "--duration", duration];
  let node, url, bridge;
  if (viaBridge) {
    // The recorder and the bridge both subscribe to the body states: the node waits for both.
    node = new Proc("node", [A.rbsim, ...nodeArgs, "--wait-for-subscribers", 2].map(String), { logDir: workdir });
    [bridge, url] = await startServer(A.rbsim, ["bridge", "--domain", domain, "--namespace", ns],
      { name: "bridge", logDir: workdir });
  } else {
    [node, url] = await startServer(A.rbsim, [...nodeArgs, "--wait-for-subscribers", 1], { name: "node", logDir: workdir });
  }
  const c = new Client(need, url, { name: "steered", subscribeAll: false });
  const values = [];
  const responses = new Map();
  let services;
  c.client.on("parameterValues", (m) => values.push(m));
  c.client.on("advertiseServices", (s) => (services = s));
  c.client.on("serviceCallResponse", (r) => responses.set(r.callId, r));
  await c.ready();
  check(c.serverInfo.capabilities.includes("clientPublish"), `capabilities ${c.serverInfo.capabilities}`);
  await until("advertiseServices", 5000, () => services);
  const states = [...c.channels.values()].find((ch) => ch.topic === `/${ns}/body_states`);
  if (!states) throw new Failure(`no /${ns}/body_states channel`);
  c.subscribe(states);
  const last = () => c.messages.at(-1)?.decoded;
  await until("body_states", 20000, () => Number(last()?.step ?? 0) > 10);

  const { parse } = need("@foxglove/rosmsg");
  const { MessageWriter, MessageReader } = need("@foxglove/rosmsg2-serialization");
  let callId = 0;
  const call = async (name, request) => {
    const s = services.find((x) => x.name === `/${ns}/${name}`);
    const id = ++callId;
    const data = new MessageWriter(parse(s.request.schema, { ros2: true })).writeMessage(request);
    c.client.sendServiceCallRequest({ serviceId: s.id, callId: id, encoding: "cdr",
      data: new DataView(data.buffer, data.byteOffset, data.byteLength) });
    const r = await until(`the reply to ${name}`, 10000, () => responses.get(id));
    const reply = new MessageReader(parse(s.response.schema, { ros2: true })).readMessage(r.data);
    check(reply.success === true, `${name}: ${JSON.stringify(reply, bigint)}`);
    return reply;
  };
  // clientPublish: one json channel and one cdr channel on /NS/command_in.
  const def = (name) => fs.readFileSync(path.join(A["source-dir"], "tools/msgs/definitions", `${name}.msg`), "utf8");
  const commandSchema = [def("rbsim_msgs/msg/Command"), ...["builtin_interfaces/msg/Time", "rcl_interfaces/msg/Parameter",
    "rcl_interfaces/msg/ParameterValue"].map((n) => `${"=".repeat(80)}\nMSG: ${n.replace("/msg/", "/")}\n${def(n)}`)].join("\n");
  const jsonChannel = c.client.advertise({ topic: `/${ns}/command_in`, encoding: "json", schemaName: "rbsim_msgs/msg/Command" });
  const cdrChannel = c.client.advertise({ topic: `/${ns}/command_in`, encoding: "cdr", schemaName: "rbsim_msgs/msg/Command" });
  const statuses = () => c.statuses.filter((s) => s.level === 2).map((s) => s.message);

  if (viaBridge) {
    // The bridge's table is the node's, read over DDS.
    c.client.getParameters([], "all");
    const all = await until("the parameter list", 5000, () => values.find((v) => v.id === "all"));
    check(all.parameters.some((p) => p.name === "forces.0.fy") && all.parameters.length > 5,
      `the bridge's parameters: ${all.parameters.map((p) => p.name)}`);
  }
  c.client.setParameters([{ name: "forces.0.fy", value: -4.5 }], "set");
  await until("the set's answer", 5000, () => values.find((v) => v.id === "set"));
  const paused = await call("pause", {});
  const at = Number(/paused at step (\d+)/.exec(paused.message)?.[1]);
  await call("step", { steps: 5 });
  await until(`body_states at step ${at + 5}`, 5000, () => Number(last()?.step) >= at + 5);
  c.client.sendMessage(jsonChannel, new TextEncoder().encode(JSON.stringify({ kind: 5, body: 2, jx: 0.5, jy: 2.0, px: 0.1 })));
  // Paused: the impulse applies at the next boundary, which a step reaches; then resume (cdr).
  await call("step", { steps: 1 });
  await until(`body_states at step ${at + 6}`, 5000, () => Number(last()?.step) >= at + 6);
  const resume = new MessageWriter(parse(commandSchema, { ros2: true })).writeMessage({
    seq: 0n, step: 0n, stamp: { sec: 0, nanosec: 0 }, kind: 2, source: "", parameters: [], atomic: true, steps: 0n,
    pause_seconds: 0, body: 0, jx: 0, jy: 0, px: 0, py: 0, success: false, message: "" });
  c.client.sendMessage(cdrChannel, resume);
  await until("the run going on after the resume", 10000, () => Number(last()?.step) > at + 50);
  check(statuses().length === 0, `status errors: ${statuses()}`);
  log(`paused at ${at}, stepped 5 + 1 with an impulse, resumed; now at step ${last()?.step}`);
  check((await node.wait(60000)) === 0, `node exited with ${node.code}\n${node.output()}`);
  check((await rec.wait(60000)) === 0, `rbsim record exited with ${rec.code}\n${rec.output()}`);
  c.close();
  if (bridge) {
    bridge.kill("SIGINT");
    check((await bridge.wait(20000)) === 0, `bridge exited with ${bridge.code}\n${bridge.output()}`);
    check(/6 commands relayed to \//.test(bridge.err), `the bridge's end line: ${bridge.err}`);
  }

  // The recording's commands: the six, from Foxglove, each applied.
  const recorded = readMcap(need, live);
  const topic = recorded.get(`/${ns}/commands`);
  if (!topic) throw new Failure(`no /${ns}/commands in the recording: ${[...recorded.keys()]}`);
  const reader = new MessageReader(parse(topic.channel.schema, { ros2: true }));
  const commands = topic.messages.map((m) => reader.readMessage(m.data));
  const summary = commands.map((m) => `${m.kind}@${m.step} ${m.source} ${m.success}`);
  log(`/NS/commands: ${summary.join(", ")}`);
  check(JSON.stringify(commands.map((m) => m.kind)) === JSON.stringify([0, 1, 3, 5, 3, 2]) ||
    JSON.stringify(commands.map((m) => m.kind)) === JSON.stringify([0, 1, 3, 3, 5, 2]),
  `/NS/commands kinds ${summary}`);
  check(commands.every((m) => m.source === source && m.success), `/NS/commands: ${summary}`);
  const impulse = commands.find((m) => m.kind === 5);
  // Through the bridge the impulse and the step are two services' calls, which the node may take in
  // either order: the impulse then applies at the step's boundary or at the one after it.
  const impulseSteps = viaBridge ? [at + 5, at + 6] : [at + 5];
  check(impulse && impulse.body === 2 && impulse.jy === 2.0 && impulseSteps.includes(Number(impulse.step)),
    `impulse ${JSON.stringify(impulse, bigint)}, want body 2 at step ${impulseSteps.join(" or ")}`);

  // Re-simulated from the recording: the same session; without the commands: not.
  const rerun = path.join(workdir, "rerun.mcap");
  const plain = path.join(workdir, "plain.mcap");
  await rbsim("rerun", ["run", scene, "--duration", duration, "--commands", live, "--record", rerun, "--namespace", ns]);
  await rbsim("plain", ["run", scene, "--duration", duration, "--record", plain, "--namespace", ns]);
  const same = await rbsim("check-rerun", ["check", rerun, live, "--ignore-log-time"], false);
  check(same.code === 0, `rbsim check rerun.mcap live.mcap exited with ${same.code}\n${same.output()}`);
  const differs = await rbsim("check-plain", ["check", plain, live, "--ignore-log-time"], false);
  check(differs.code === 1, `rbsim check plain.mcap live.mcap exited with ${differs.code}, want 1\n${differs.output()}`);
  // The state itself changed, not only the commands topic.
  const states2 = await rbsim("check-states", ["check", plain, live, "--ignore-log-time", "--topics", "body_states"], false);
  check(states2.code === 1, `body_states of the plain run equal the steered session's (exit ${states2.code})`);
}

runMain(viaBridge ? "foxglove_client.bridge_steered" : "foxglove_client.steered", main);
