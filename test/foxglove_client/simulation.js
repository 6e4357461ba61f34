#!/usr/bin/env node
"use strict";
// simulation_interfaces' services called from Foxglove's own client (npm @foxglove/ws-protocol,
// requests and replies in cdr through @foxglove/rosmsg2-serialization from the advertised schemas,
// and in json, which the server converts by the same schemas):
//
//   simulation.js --rbsim BUILD/rbsim --source-dir SRC --workdir DIR --npm BUILD/npm --index N [--via bridge]
//
// `rbsim node --foxglove` offers /NS/get_simulation_state ... get_entity_bounds beside its
// controls; with --via bridge the client talks to `rbsim bridge`, which forwards each call as raw
// CDR to the node's DDS service of that name. The client reads PLAYING, pauses through
// set_simulation_state and reads PAUSED, steps 300 while a second client keeps receiving
// body_states (the call's wait holds up no one's data), reads body_1's state and checks it against
// the body_states of the step reached, and ends the node with STATE_QUITTING (exit 0). The pause
// goes in json, and get_simulation_state and get_entity_state are called in json too, their json
// replies equal to the cdr calls'; a json request with a field its type lacks is refused naming
// it. Through the bridge, a call after the node is gone fails with a serviceCallFailure naming
// the service.
// Only 127.0.0.1 and its own DDS domain; every wait bounded.
const path = require("path");
const lib = require("./lib");
const { Failure, until, Proc, startServer, Client, runMain } = lib;

const { A, workdir } = lib.caseArgs(["rbsim", "source-dir", "workdir", "npm", "index"]);
const need = lib.npmModules(A.npm);
const ns = `fg_sim_${process.pid}`;
const domain = lib.domainFor(Number(A.index));
const log = lib.log;
const bigint = (k, v) => (typeof v === "bigint" ? Number(v) : v);
const viaBridge = A.via === "bridge";
if (A.via !== undefined && !viaBridge) throw new Error(`--via ${A.via}: only "bridge"`);
const RESULT_OK = 1;
const [PLAYING, PAUSED, QUITTING] = [1, 2, 3]; // simulation_interfaces/msg/SimulationState

async function main(check) {
  const scene = path.join(A["source-dir"], "scenes", "chain.xml"); // dt 0.001
  const dt = 0.001;
  // Real time, long enough never to end on its own: the node ends through STATE_QUITTING.
  const nodeArgs = ["node", scene, "--domain", domain, "--namespace", ns, "--duration", 100];
  let node, url, bridge;
  if (viaBridge) {
    node = new Proc("node", [A.rbsim, ...nodeArgs].map(String), { logDir: workdir });
    [bridge, url] = await startServer(A.rbsim, ["bridge", "--domain", domain, "--namespace", ns],
      { name: "bridge", logDir: workdir });
  } else {
    [node, url] = await startServer(A.rbsim, nodeArgs, { name: "node", logDir: workdir });
  }
  const c = new Client(need, url, { name: "caller", subscribeAll: false });
  const watcher = new Client(need, url, { name: "watcher", subscribeAll: false });
  const responses = new Map();
  const failures = new Map();
  let services;
  c.client.on("advertiseServices", (s) => (services = s));
  // What the watcher had received when each reply came (the step call's wait held up no one's data).
  const watcherSeen = new Map();
  c.client.on("serviceCallResponse", (r) => {
    responses.set(r.callId, r);
    watcherSeen.set(r.callId, watcher.messages.length);
  });
  c.client.on("serviceCallFailure", (f) => failures.set(f.callId, f));
  await c.ready();
  await watcher.ready();
  check(c.serverInfo.capabilities.includes("services"), `capabilities ${c.serverInfo.capabilities}`);
  await until("advertiseServices", 5000, () => services);
  const names = services.map((s) => s.name);
  for (const n of ["get_simulator_features", "get_simulation_state", "set_simulation_state", "reset_simulation",
    "step_simulation", "get_entities", "get_entity_info", "get_entity_state", "get_entities_states",
    "set_entity_state", "get_entity_bounds", "pause", "step"]) {
    check(names.includes(`/${ns}/${n}`), `/${ns}/${n} not among the services: ${names}`);
  }
  const topicOf = (client) => [...client.channels.values()].find((ch) => ch.topic === `/${ns}/body_states`);
  if (!topicOf(c) || !topicOf(watcher)) throw new Failure(`no /${ns}/body_states channel`);
  c.subscribe(topicOf(c));
  watcher.subscribe(topicOf(watcher));
  const last = () => c.messages.at(-1)?.decoded;
  await until("body_states", 20000, () => Number(last()?.step ?? 0) > 10);

  const { parse } = need("@foxglove/rosmsg");
  const { MessageWriter, MessageReader } = need("@foxglove/rosmsg2-serialization");
  let callId = 0;
  const service = (name) => {
    const s = services.find((x) => x.name === `/${ns}/${name}`);
    if (!s) throw new Failure(`no service /${ns}/${name}`);
    return s;
  };
  const send = (name, request, encoding = "cdr") => {
    const s = service(name);
    const id = ++callId;
    const data = encoding === "cdr"
      ? new MessageWriter(parse(s.request.schema, { ros2: true })).writeMessage(request)
      : new TextEncoder().encode(JSON.stringify(request));
    c.client.sendServiceCallRequest({ serviceId: s.id, callId: id, encoding,
      data: new DataView(data.buffer, data.byteOffset, data.byteLength) });
    return id;
  };
  const answer = async (name, id, timeoutMs = 10000) => {
    const r = await until(`the answer to ${name}`, timeoutMs, () => responses.get(id) || failures.get(id));
    if (failures.has(id)) throw new Failure(`${name}: serviceCallFailure ${failures.get(id).message}`);
    return new MessageReader(parse(service(name).response.schema, { ros2: true })).readMessage(r.data);
  };
  const call = async (name, request) => {
    const reply = await answer(name, send(name, request));
    check(reply.result?.result === RESULT_OK, `${name}: ${JSON.stringify(reply, bigint)}`);
    return reply;
  };
  // The same in json: the reply comes in the request's encoding, as the JSON the server writes.
  const callJson = async (name, request) => {
    const id = send(name, request, "json");
    const r = await until(`the json answer to ${name}`, 10000, () => responses.get(id) || failures.get(id));
    if (failures.has(id)) throw new Failure(`${name} (json): serviceCallFailure ${failures.get(id).message}`);
    check(r.encoding === "json", `${name}: a json call answered in ${r.encoding}`);
    const reply = JSON.parse(new TextDecoder().decode(r.data));
    check(reply.result?.result === RESULT_OK, `${name} (json): ${JSON.stringify(reply)}`);
    return reply;
  };
  const same = (name, fromJson, fromCdr) => check(JSON.stringify(fromJson) === JSON.stringify(fromCdr, bigint),
    `${name}: json reply ${JSON.stringify(fromJson)}, cdr reply ${JSON.stringify(fromCdr, bigint)}`);

  const playing = await call("get_simulation_state", {});
  check(playing.state.state === PLAYING, `state ${playing.state.state}, want PLAYING (${PLAYING})`);
  await callJson("set_simulation_state", { state: { state: PAUSED } });
  const paused = await call("get_simulation_state", {});
  check(paused.state.state === PAUSED, `state ${paused.state.state}, want PAUSED (${PAUSED})`);
  same("get_simulation_state", await callJson("get_simulation_state", {}), paused);
  // Paused: the step the world stands at, from a read's stamp; body_states reaches it and stops.
  const before = (await call("get_entity_state", { entity: "body_1" })).state.header.stamp;
  const at = Math.round((before.sec + before.nanosec * 1e-9) / dt);
  await until(`body_states at step ${at}`, 5000, () => Number(last()?.step) >= at);
  check(Number(last().step) === at, `paused: body_states at step ${last().step}, want ${at}`);

  // 300 steps at real time: about 0.3 s during which the reply is awaited and data flows on.
  const steps = 300;
  const seen = watcher.messages.length;
  const id = send("step_simulation", { steps: BigInt(steps) });
  const stepped = await answer("step_simulation", id);
  check(stepped.result.result === RESULT_OK, `step_simulation: ${JSON.stringify(stepped, bigint)}`);
  const between = watcher.messages.slice(seen, watcherSeen.get(id)).map((m) => Number(m.decoded.step));
  check(between.some((s) => s > at && s < at + steps),
    `no body_states between steps ${at} and ${at + steps} reached the watcher while step_simulation waited ` +
    `(it got steps ${between.slice(0, 5)}...)`);
  // Answered when the steps are done: the world stands at at + steps, and stays there (paused).
  await until(`body_states at step ${at + steps}`, 5000, () => Number(last()?.step) >= at + steps);
  check(Number(last().step) === at + steps, `body_states at step ${last().step}, want ${at + steps}`);

  const got = await call("get_entity_state", { entity: "body_1" });
  same("get_entity_state", await callJson("get_entity_state", { entity: "body_1" }), got);
  const body = last().bodies.find((b) => b.id === 1);
  const st = got.state;
  const stamp = st.header.stamp.sec + st.header.stamp.nanosec * 1e-9;
  check(Math.abs(stamp - (at + steps) * dt) < 1e-6, `get_entity_state's stamp ${stamp}, want ${(at + steps) * dt}`);
  check(st.header.frame_id === "world", `frame ${st.header.frame_id}`);
  check(st.pose.position.x === body.x && st.pose.position.y === body.y,
    `pose ${JSON.stringify(st.pose.position)}, body_states (${body.x}, ${body.y})`);
  check(Math.abs(st.pose.orientation.z - Math.sin(body.theta / 2)) < 1e-12 &&
    Math.abs(st.pose.orientation.w - Math.cos(body.theta / 2)) < 1e-12,
  `orientation ${JSON.stringify(st.pose.orientation)}, theta ${body.theta}`);
  check(st.twist.linear.x === body.vx && st.twist.angular.z === body.omega,
    `twist ${JSON.stringify(st.twist)}, body_states (${body.vx}, ${body.omega})`);
  const missing = await answer("get_entity_state", send("get_entity_state", { entity: "body_99" }));
  check(missing.result.result === 2, `body_99: ${JSON.stringify(missing.result)}, want RESULT_NOT_FOUND (2)`);
  // A json request that does not convert is refused, naming the field.
  const jsonId = send("get_entity_state", { entity: "body_1", name: "body_1" }, "json");
  const refused = await until("the json call's failure", 5000, () => failures.get(jsonId) || responses.get(jsonId));
  check(failures.has(jsonId) && refused.message.includes("name: no such field"), `json call: ${JSON.stringify(refused)}`);
  log(`PLAYING, paused at ${at}, stepped ${steps} to ${last().step}; body_1 at (${body.x}, ${body.y})`);

  const quit = await call("set_simulation_state", { state: { state: QUITTING } });
  check(quit.result.result === RESULT_OK, `quitting: ${JSON.stringify(quit.result)}`);
  check((await node.wait(30000)) === 0, `node exited with ${node.code}\n${node.output()}`);
  if (bridge) {
    // The node is gone: the bridge's forward fails the call, naming the service.
    const goneId = send("get_simulation_state", {});
    const gone = await until("the call after the node quit", 20000, () => failures.get(goneId) || responses.get(goneId));
    check(failures.has(goneId) && gone.message.includes(`/${ns}/get_simulation_state: `),
      `a call with no node: ${JSON.stringify(gone)}`);
    log(`with the node gone: ${gone.message}`);
  }
  c.close();
  watcher.close();
  if (bridge) {
    bridge.kill("SIGINT");
    check((await bridge.wait(20000)) === 0, `bridge exited with ${bridge.code}\n${bridge.output()}`);
  }
}

runMain(viaBridge ? "foxglove_client.bridge_simulation" : "foxglove_client.simulation", main);
