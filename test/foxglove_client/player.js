#!/usr/bin/env node
"use strict";
// rosbag2's player controls driven from Foxglove: `rbsim replay --foxglove --start-paused` offers
// the player's services (/rbsim_player/pause ... burst, rosbag2_interfaces, cdr) and Foxglove's own
// client (npm @foxglove/ws-protocol, requests written with @foxglove/rosmsg2-serialization from the
// advertised schemas) calls them, checking what reaches it on /NS/body_states:
//
//   player.js --rbsim BUILD/rbsim --source-dir SRC --workdir DIR --npm BUILD/npm --index N
//
// paused: nothing per step arrives; play_next: exactly one message; burst 5: five; set_rate and
// get_rate; seek to 2 s then play_next: the message of step 2000; toggle_paused: the replay plays on
// from there; pause: it stops again. A json request is answered in json, equal to cdr's reply; one
// with an unknown field and an unknown service are refused.
// Only 127.0.0.1 and its own DDS domain; every wait bounded.
const path = require("path");
const lib = require("./lib");
const { Failure, until, sleep, Proc, startServer, Client, runMain } = lib;

const { A, workdir } = lib.caseArgs(["rbsim", "source-dir", "workdir", "npm", "index"]);
const need = lib.npmModules(A.npm);
const ns = `fg_player_${process.pid}`;
const domain = lib.domainFor(Number(A.index));
const log = lib.log;

async function main(check) {
  // 4 s of the chain at dt 0.001, body states recorded every 10 steps: 401 messages, step = 10 k.
  const scene = path.join(A["source-dir"], "scenes", "chain.xml");
  const recording = path.join(workdir, "run.mcap");
  const run = new Proc("run", [A.rbsim, "run", scene, "--duration", 4, "--record", recording, "--record-every", 10,
    "--namespace", ns].map(String), { logDir: workdir });
  check((await run.wait(120000)) === 0, `rbsim run exited with ${run.code}\n${run.output()}`);
  const [replay, url] = await startServer(A.rbsim, ["replay", recording, "--domain", domain, "--start-paused",
    "--topics", "body_states"], { name: "replay", logDir: workdir });

  const c = new Client(need, url, { name: "player", subscribeAll: false });
  const responses = new Map();
  const failures = new Map();
  let services;
  c.client.on("advertiseServices", (s) => (services = s));
  c.client.on("serviceCallResponse", (r) => responses.set(r.callId, r));
  c.client.on("serviceCallFailure", (f) => failures.set(f.callId, f));
  await c.ready();
  check(c.serverInfo.capabilities.includes("services"), `capabilities ${c.serverInfo.capabilities}`);
  check(!c.serverInfo.capabilities.includes("parameters"), `a replay offers no parameters: ${c.serverInfo.capabilities}`);
  await until("advertiseServices", 5000, () => services);
  const names = services.map((s) => s.name).sort();
  const want = ["burst", "get_rate", "is_paused", "pause", "play_next", "resume", "seek", "set_rate", "toggle_paused"]
    .map((n) => `/rbsim_player/${n}`);
  check(JSON.stringify(names) === JSON.stringify(want), `services ${names}`);
  const states = [...c.channels.values()].find((ch) => ch.topic === `/${ns}/body_states`);
  if (!states) throw new Failure(`no /${ns}/body_states channel`);
  c.subscribe(states);

  const { parse } = need("@foxglove/rosmsg");
  const { MessageWriter, MessageReader } = need("@foxglove/rosmsg2-serialization");
  let callId = 0;
  const send = (name, request, encoding = "cdr") => {
    const s = services.find((x) => x.name === `/rbsim_player/${name}`);
    const id = ++callId;
    const data = !s ? new Uint8Array(4) : encoding === "cdr"
      ? new MessageWriter(parse(s.request.schema, { ros2: true })).writeMessage(request)
      : new TextEncoder().encode(JSON.stringify(request));
    c.client.sendServiceCallRequest({ serviceId: s ? s.id : 99, callId: id, encoding,
      data: new DataView(data.buffer, data.byteOffset, data.byteLength) });
    return [s, id];
  };
  const call = async (name, request = {}) => {
    const [s, id] = send(name, request);
    const r = await until(`the reply to ${name}`, 15000, () => responses.get(id) ?? failures.get(id));
    if (!r.data) throw new Failure(`${name}: ${r.message}`);
    return new MessageReader(parse(s.response.schema, { ros2: true })).readMessage(r.data);
  };
  const received = () => c.messages.filter((m) => m.topic === `/${ns}/body_states`);
  const steps = () => received().map((m) => Number(m.decoded.step));

  check((await call("is_paused")).paused === true, "is_paused: want true (--start-paused)");
  await sleep(500);
  check(received().length === 0, `paused, yet ${received().length} body states arrived`);
  check((await call("play_next")).success === true, "play_next: want success");
  await until("the message play_next published", 5000, () => received().length >= 1);
  await sleep(300);
  check(JSON.stringify(steps()) === "[0]", `after play_next: steps ${steps()}, want [0]`);
  const burst = await call("burst", { num_messages: 5n });
  check(Number(burst.actually_burst) === 5, `burst: ${burst.actually_burst}, want 5`);
  await until("the burst's messages", 5000, () => received().length >= 6);
  await sleep(300);
  check(JSON.stringify(steps()) === "[0,10,20,30,40,50]", `after burst 5: steps ${steps()}`);

  check((await call("set_rate", { rate: 2.0 })).success === true, "set_rate 2: want success");
  check((await call("get_rate")).rate === 2.0, "get_rate: want 2");
  check((await call("set_rate", { rate: -1.0 })).success === false, "set_rate -1: want refused");

  check((await call("seek", { time: { sec: 2, nanosec: 0 } })).success === true, "seek 2 s: want success");
  check((await call("play_next")).success === true, "play_next after the seek: want success");
  await until("the message after the seek", 5000, () => received().length >= 7);
  check(steps()[6] === 2000, `the first message after seeking to 2 s has step ${steps()[6]}, want 2000`);

  await call("toggle_paused");
  check((await call("is_paused")).paused === false, "is_paused after toggle_paused: want false");
  await until("playing on from the seek", 10000, () => steps().at(-1) >= 2300);
  await call("pause");
  check((await call("is_paused")).paused === true, "is_paused after pause: want true");
  await sleep(300);
  const held = received().length;
  await sleep(700);
  check(received().length === held, `paused again, yet ${received().length - held} more arrived`);
  const after = steps().slice(6);
  check(after.every((s, i) => i === 0 || s === after[i - 1] + 10), `steps after the seek not contiguous: ${after}`);

  // A json request, converted by the service's schemas: the reply in json, equal to the cdr one's.
  const [, jsonId] = send("get_rate", {}, "json");
  const jsonReply = await until("the json reply", 5000, () => responses.get(jsonId) ?? failures.get(jsonId));
  check(jsonReply.encoding === "json" && jsonReply.data, `json request: ${JSON.stringify(jsonReply)}`);
  const jsonRate = JSON.parse(new TextDecoder().decode(jsonReply.data));
  const cdrRate = await call("get_rate");
  check(JSON.stringify(jsonRate) === JSON.stringify({ rate: cdrRate.rate }),
    `get_rate in json ${JSON.stringify(jsonRate)}, in cdr ${cdrRate.rate}`);
  // Refusals: a json request with a field its type lacks, an unknown service id.
  const [, badId] = send("set_rate", { speed: 3 }, "json");
  const refused = await until("the json refusal", 5000, () => failures.get(badId));
  check(/speed: no such field/.test(refused.message), `json request: ${refused.message}`);
  const [, unknownId] = send("nope", {});
  const unknown = await until("the unknown service's refusal", 5000, () => failures.get(unknownId));
  check(/unknown service/.test(unknown.message), `unknown service: ${unknown.message}`);
  log(`play_next, burst 5, rate 2, seek to 2 s, played to step ${steps().at(-1)}, paused; ${received().length} body states`);

  c.close();
  replay.kill("SIGINT");
  check((await replay.wait(30000)) === 0, `replay exited with ${replay.code}\n${replay.output()}`);
}

runMain("foxglove_client.player", main);
