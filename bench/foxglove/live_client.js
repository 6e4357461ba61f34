#!/usr/bin/env node
"use strict";
// One Foxglove WebSocket client for scripts/bench-record-live, in its own process: connects to
// URL (127.0.0.1 only), subscribes to every channel, keeps nothing (decode: false), prints
// "READY <channels>" once every channel is advertised and subscribed, and one JSON line when
// the server closes: messages and bytes in all, per topic the count and the first and last
// log time (simulated ns), and gaps (a per-step topic whose consecutive log times differ by
// other than --dt-ns). Every wait is bounded (--timeout-s, default 900 s).
//   node live_client.js --url ws://127.0.0.1:PORT --npm BUILD/npm --dt-ns 1000000 [--timeout-s S]
const lib = require("../../test/foxglove_client/lib");

const A = {};
for (let i = 2; i < process.argv.length; i += 2) A[process.argv[i].replace(/^--/, "")] = process.argv[i + 1];

async function main() {
  if (!A.url || !A.url.startsWith("ws://127.0.0.1:")) throw new lib.Failure(`--url must be ws://127.0.0.1:PORT (got ${A.url})`);
  const dt = BigInt(A["dt-ns"] ?? "1000000");
  const timeoutMs = 1000 * Number(A["timeout-s"] ?? 900);
  const c = new lib.Client(lib.npmModules(A.npm), A.url, { name: "live_client", decode: false });
  const topics = new Map(); // topic -> { count, first, last } (times as strings: JSON has no bigint)
  const last = new Map();
  const stats = { messages: 0, bytes: 0, gaps: 0, gapTopics: {}, statuses: [], topics: {} };
  c.messages = { push() {} }; // count only: keep nothing
  c.onmessage = (m) => {
    stats.messages++;
    stats.bytes += m.data.length;
    const prev = last.get(m.topic);
    if (prev !== undefined && m.time - prev !== dt) {
      stats.gaps++;
      stats.gapTopics[m.topic] = (stats.gapTopics[m.topic] ?? 0) + 1;
    }
    last.set(m.topic, m.time);
    const t = topics.get(m.topic);
    if (t) {
      t.count++;
      t.last = m.time;
    } else {
      topics.set(m.topic, { count: 1, first: m.time, last: m.time });
    }
  };
  await c.ready(30000);
  console.log(`READY ${c.channels.size}`);
  await lib.until("the server to close", timeoutMs, () => c.closed, 50);
  stats.statuses = c.statuses.map((s) => s.message);
  for (const [topic, t] of topics) stats.topics[topic] = { count: t.count, first: String(t.first), last: String(t.last) };
  console.log(JSON.stringify(stats));
}

main()
  .then(() => process.exit(0))
  .catch((e) => {
    console.error(e instanceof lib.Failure ? e.message : e.stack);
    process.exit(1);
  });
