"use strict";
// Shared by the Foxglove tests (client.js, viewer.js) and scripts/bench-foxglove: the npm packages
// scripts/setup installs under the build folder, rbsim processes, a Foxglove WebSocket client that
// decodes with the stack Foxglove Studio uses, and MCAP recordings read with the official reader.
// Only 127.0.0.1 is ever connected to; every wait is bounded in time.
const fs = require("fs");
const path = require("path");
const { spawn } = require("child_process");
const { createRequire } = require("module");

class Failure extends Error {}

// require() from <npmDir>/node_modules (scripts/setup: npm ci of test/foxglove_client/package-lock.json).
// A missing package is a failure: in CI scripts/setup has installed them all.
function npmModules(npmDir) {
  const req = createRequire(path.join(path.resolve(npmDir), "package.json"));
  return (name) => {
    try {
      return req(name);
    } catch (err) {
      throw new Failure(`npm package ${name} not found under ${npmDir}/node_modules (${err.code}): run scripts/setup`);
    }
  };
}

const sleep = (ms) => new Promise((resolve) => setTimeout(resolve, ms));

async function until(what, timeoutMs, cond, stepMs = 20) {
  const deadline = Date.now() + timeoutMs;
  for (;;) {
    const v = cond();
    if (v) return v;
    if (Date.now() > deadline) throw new Failure(`timed out after ${timeoutMs} ms waiting for ${what}`);
    await sleep(stepMs);
  }
}

// rbsim with the compiled-in loopback DDS configuration: none of a developer's DDS or ROS 2
// settings gets in (as test/e2e/e2e.py does).
function rbsimEnv() {
  const env = { ...process.env };
  for (const k of ["CYCLONEDDS_URI", "ROS_DOMAIN_ID", "ROS_AUTOMATIC_DISCOVERY_RANGE", "ROS_STATIC_PEERS",
    "ROS_LOCALHOST_ONLY"]) {
    delete env[k];
  }
  return env;
}

// setpriv --pdeathsig: a child dies with the driver (CTest kills the driver on a timeout).
const SETPRIV = ["/usr/bin/setpriv", "/bin/setpriv"].find((p) => fs.existsSync(p));
const live = new Set();
process.on("exit", () => {
  for (const p of live) p.kill("SIGKILL");
});

class Proc {
  constructor(name, argv, { env = rbsimEnv(), logDir } = {}) {
    this.name = name;
    this.out = "";
    this.err = "";
    this.code = undefined;
    const [cmd, ...args] = SETPRIV ? [SETPRIV, "--pdeathsig", "KILL", ...argv] : argv;
    this.child = spawn(cmd, args, { env, stdio: ["ignore", "pipe", "pipe"] });
    live.add(this.child);
    this.child.stdout.on("data", (d) => (this.out += d));
    this.child.stderr.on("data", (d) => (this.err += d));
    this.exited = new Promise((resolve) =>
      this.child.on("close", (code, signal) => {
        live.delete(this.child);
        this.code = code ?? 128 + (require("os").constants.signals[signal] ?? 0);
        if (logDir) fs.writeFileSync(path.join(logDir, `${name}.log`), this.output());
        resolve(this.code);
      }),
    );
  }
  alive() {
    return this.code === undefined;
  }
  output() {
    return `--- ${this.name} stdout ---\n${this.out}--- ${this.name} stderr ---\n${this.err}`;
  }
  async waitFor(re, timeoutMs) {
    const deadline = Date.now() + timeoutMs;
    for (;;) {
      const m = re.exec(this.out + this.err);
      if (m) return m;
      if (!this.alive() || Date.now() > deadline) {
        throw new Failure(`${this.name}: no ${re} within ${timeoutMs} ms (${this.alive() ? "running" : `exit ${this.code}`})\n${this.output()}`);
      }
      await sleep(20);
    }
  }
  async wait(timeoutMs) {
    const t = setTimeout(() => this.child.kill("SIGKILL"), timeoutMs);
    const code = await this.exited;
    clearTimeout(t);
    return code;
  }
  kill(sig = "SIGKILL") {
    if (this.alive()) this.child.kill(sig);
  }
}

// Starts `rbsim ARGS... --foxglove 127.0.0.1:0` and returns [proc, ws url] once it listens.
async function startServer(rbsim, args, opts = {}) {
  const proc = new Proc(opts.name ?? "node", [rbsim, ...args.map(String), "--foxglove", "127.0.0.1:0"], opts);
  const m = await proc.waitFor(/foxglove: listening on (ws:\/\/127\.0\.0\.1:\d+)/, opts.timeoutMs ?? 20000);
  return [proc, m[1]];
}

// The node's closing line: steps and steps per second.
function endLine(proc) {
  const m = /rbsim \w+: (?:done|stopped) after (\d+) steps in .+? \(([\d.e+]+) steps\/s\)/.exec(proc.err);
  return m ? { steps: Number(m[1]), rate: Number(m[2]) } : undefined;
}

// A Foxglove WebSocket client: FoxgloveClient over `ws`, decoding every message from its
// channel's advertised ros2msg schema with @foxglove/rosmsg + @foxglove/rosmsg2-serialization.
class Client {
  // `wsOptions`: more options for `ws` (wss://: `ca`, the certificate to trust).
  constructor(need, url, { protocol, name = "client", subscribeAll = true, decode = true, wsOptions = {} } = {}) {
    const { FoxgloveClient } = need("@foxglove/ws-protocol");
    const WebSocket = need("ws");
    this.need = need;
    this.name = name;
    this.channels = new Map(); // id -> channel
    this.readers = new Map(); // channel id -> MessageReader
    this.subs = new Map(); // subscription id -> channel
    this.messages = []; // { topic, time (bigint ns), data (Buffer), decoded, received (ms) }
    this.statuses = [];
    this.times = [];
    this.closed = false;
    this.error = undefined;
    this.decode = decode;
    this.subscribeAll = subscribeAll;
    this.ws = new WebSocket(url, protocol ?? FoxgloveClient.SUPPORTED_SUBPROTOCOL, { maxPayload: 64 << 20, ...wsOptions });
    this.client = new FoxgloveClient({ ws: this.ws });
    this.client.on("serverInfo", (info) => (this.serverInfo = info));
    this.client.on("status", (s) => this.statuses.push(s));
    this.client.on("time", (t) => this.times.push(t.timestamp));
    this.client.on("error", (e) => (this.error = e));
    this.client.on("close", () => (this.closed = true));
    this.client.on("advertise", (chans) => {
      for (const c of chans) {
        this.channels.set(c.id, c);
        if (this.subscribeAll) this.subscribe(c);
      }
    });
    this.client.on("unadvertise", (ids) => ids.forEach((id) => this.channels.delete(id)));
    this.client.on("message", ({ subscriptionId, timestamp, data }) => this.onMessage(subscriptionId, timestamp, data));
  }
  subscribe(c) {
    const id = this.client.subscribe(c.id);
    this.subs.set(id, c);
    return id;
  }
  reader(c) {
    if (!this.readers.has(c.id)) {
      const { parse } = this.need("@foxglove/rosmsg");
      const { MessageReader } = this.need("@foxglove/rosmsg2-serialization");
      this.readers.set(c.id, new MessageReader(parse(c.schema, { ros2: true })));
    }
    return this.readers.get(c.id);
  }
  onMessage(subId, timestamp, data) {
    const c = this.subs.get(subId);
    const bytes = Buffer.from(data.buffer, data.byteOffset, data.byteLength);
    const m = { topic: c ? c.topic : `?sub${subId}`, time: timestamp, data: Buffer.from(bytes), received: performance.now() };
    if (c && this.decode === true) m.decoded = this.reader(c).readMessage(m.data);
    this.messages.push(m);
    if (this.onmessage) this.onmessage(m);
  }
  // Resolves once serverInfo came and no new channel was advertised for quietMs.
  async ready(timeoutMs = 10000, quietMs = 300) {
    await until(`${this.name}: serverInfo`, timeoutMs, () => this.serverInfo || this.closed);
    if (this.closed) throw new Failure(`${this.name}: closed before serverInfo`);
    let n = -1;
    let since = Date.now();
    await until(`${this.name}: advertisements`, timeoutMs, () => {
      if (this.channels.size !== n) [n, since] = [this.channels.size, Date.now()];
      return n > 0 && Date.now() - since >= quietMs;
    });
    return this;
  }
  // Decodes what was received undecoded (decode: "later" keeps the receive path light).
  decodeAll() {
    const byTopic = new Map([...this.channels.values()].map((c) => [c.topic, c]));
    for (const m of this.messages) {
      if (!m.decoded && byTopic.has(m.topic)) m.decoded = this.reader(byTopic.get(m.topic)).readMessage(m.data);
    }
  }
  topics() {
    return [...new Set([...this.channels.values()].map((c) => c.topic))].sort();
  }
  byTopic() {
    const out = new Map();
    for (const m of this.messages) {
      if (!out.has(m.topic)) out.set(m.topic, []);
      out.get(m.topic).push(m);
    }
    return out;
  }
  close() {
    if (!this.closed) this.ws.close();
  }
  terminate() {
    this.ws.terminate();
  }
}

// Every message of an MCAP file (written with --compression none) with the official TypeScript
// reader (@mcap/core, CRCs checked): { topic -> [{ time, data }] } and { topic -> channel info }.
function readMcap(need, file) {
  const { McapStreamReader } = need("@mcap/core");
  const reader = new McapStreamReader({ validateCrcs: true });
  reader.append(fs.readFileSync(file));
  const schemas = new Map();
  const channels = new Map();
  const topics = new Map();
  for (let rec; (rec = reader.nextRecord()); ) {
    if (rec.type === "Schema") schemas.set(rec.id, rec);
    else if (rec.type === "Channel" && !channels.has(rec.id)) {  // again in the summary section
      const s = schemas.get(rec.schemaId);
      channels.set(rec.id, { ...rec, schemaName: s.name, schemaEncoding: s.encoding, schema: Buffer.from(s.data).toString() });
      topics.set(rec.topic, { channel: channels.get(rec.id), messages: [] });
    } else if (rec.type === "Message") {
      topics.get(channels.get(rec.channelId).topic).messages.push({ time: rec.logTime, data: Buffer.from(rec.data) });
    }
  }
  if (!reader.done()) throw new Failure(`${file}: not a complete MCAP file`);
  return topics;
}

// A distinct DDS domain per test index (80..99): clear of the e2e tests (200..232), the benchmarks
// (100..199) and test/foxglove (61).
const domainFor = (index) => 80 + (index % 20);

// The colours of a FOSSSim scene's bodies, [r, g, b] in 0..1, from its <rigidbodycolor> elements.
function sceneColours(xmlFile) {
  const xml = fs.readFileSync(xmlFile, "utf8");
  return [...xml.matchAll(/<rigidbodycolor\b[^>]*>/g)].map((m) =>
    ["r", "g", "b"].map((k) => Number(new RegExp(`\\b${k}="([^"]+)"`).exec(m[0])[1])),
  );
}

// Runs `main(check)`; prints every failed check and the closing line CTest and CI read; exit 1 on any.
function runMain(title, main) {
  const failures = [];
  const check = (cond, what) => {
    if (!cond) {
      failures.push(what);
      console.log(`FAIL: ${what}`);
    }
    return cond;
  };
  const t0 = Date.now();
  main(check)
    .catch((err) => failures.push(err instanceof Failure ? err.message : err.stack))
    .finally(() => {
      for (const p of live) p.kill("SIGKILL");
      const s = ((Date.now() - t0) / 1000).toFixed(1);
      if (failures.length) {
        console.log(`${title}: FAILED in ${s} s:\n- ${failures.join("\n- ")}`);
        process.exit(1);
      }
      console.log(`${title}: passed in ${s} s`);
      process.exit(0);
    });
}

// A test script's options (--key value pairs; each of `required` must be there) and its work
// folder (--workdir), emptied: { A, workdir }.
function caseArgs(required) {
  const A = {};
  for (let i = 2; i < process.argv.length; i += 2) A[process.argv[i].replace(/^--/, "")] = process.argv[i + 1];
  for (const k of required) {
    if (A[k] === undefined) throw new Error(`missing --${k}`);
  }
  const workdir = path.resolve(A.workdir);
  fs.rmSync(workdir, { recursive: true, force: true });
  fs.mkdirSync(workdir, { recursive: true });
  return { A, workdir };
}

// A line of the test's log, with the seconds since it started.
const log = (msg) => console.log(`[${(performance.now() / 1000).toFixed(2)}] ${msg}`);

module.exports = { Failure, npmModules, sleep, until, rbsimEnv, Proc, startServer, endLine, Client, readMcap, domainFor,
  sceneColours, runMain, caseArgs, log };
