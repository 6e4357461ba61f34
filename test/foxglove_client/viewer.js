#!/usr/bin/env node
"use strict";
// The real viewer: Foxglove Studio's last open-source web build (npm @foxglove/studio-base 1.48.0)
// in Debian's headless Chromium with software WebGL, connected to a live `rbsim node --foxglove` (or
// `rbsim replay --foxglove`)
// with docs/foxglove-layout.json, driven over the DevTools protocol (playwright-core, Chromium
// started from /usr/bin/chromium). Every case first waits for the sidebar to list every advertised
// topic. Cases:
//   colours     the 3D panel shows the body colours of the scene's XML, and the Parameters panel
//               lists parameters (foxglove_client.viewer, wind-garden);
//   parameters  the Parameters panel lists exactly the parameters the server sends an independent
//               client; the wind (forces.0.fx) set by typing in that panel and clicking its submit
//               button makes the square of viewer/drift.xml drift right, not before, in the 3D
//               panel's pixels, and the node publishes the set on /rbsim/commands, from "foxglove"
//               (foxglove_client.viewer_parameters);
//   changes     a body spawned through the node's spawn_entity service (called by an independent
//               client) appears in the 3D panel in its fragment's colour, and the scene's square,
//               deleted through delete_entity, disappears, without a reload
//               (foxglove_client.viewer_changes);
//   replay_changes  the same changes from a recording (`rbsim run --commands --record`) played by
//               `rbsim replay --foxglove --start-paused` in exact bursts through its player
//               services: the orange square alone before the spawn, both after it, the blue one
//               alone after the delete, in the 3D panel and in the body states an independent
//               client receives; a client joining at each stage gets the latest scene description
//               and markers (foxglove_client.viewer_replay_changes).
//
//   viewer.js --case colours|parameters|changes|replay_changes --rbsim BUILD/rbsim --source-dir SRC --workdir DIR
//             --npm BUILD/npm --index N [--scene FILE] [--screenshot PNG]
//   (--screenshot: also write the page of case colours there)
const fs = require("fs");
const http = require("http");
const path = require("path");
const lib = require("./lib");
const { Failure, until, Proc, startServer, Client, runMain } = lib;

const { A, workdir } = lib.caseArgs(["case", "rbsim", "source-dir", "workdir", "npm", "index"]);
const need = lib.npmModules(A.npm);
const src = path.resolve(A["source-dir"]);
const CASES = {
  colours: ["foxglove_client.viewer", caseColours],
  parameters: ["foxglove_client.viewer_parameters", caseParameters],
  changes: ["foxglove_client.viewer_changes", caseChanges],
  replay_changes: ["foxglove_client.viewer_replay_changes", caseReplayChanges],
};
if (!CASES[A.case]) throw new Error(`unknown --case ${A.case}`);
const log = lib.log;

const CHROMIUM = "/usr/bin/chromium";
// Headless, software WebGL (SwiftShader), and nothing that reaches for the network: the closed
// network refuses QUIC, component updates, sync and the like, and a fresh profile per run.
const CHROMIUM_ARGS = ["--headless=new", "--no-sandbox", "--disable-gpu", "--use-gl=angle", "--use-angle=swiftshader",
  "--enable-unsafe-swiftshader", "--disable-quic", "--no-first-run", "--disable-background-networking",
  "--disable-component-update", "--disable-sync", "--disable-default-apps", "--disable-extensions"];

// The page, its script, the layout and the three npm packages it loads; nothing else.
function staticServer() {
  const npm = path.join(path.resolve(A.npm), "node_modules");
  const types = { ".js": "text/javascript", ".html": "text/html", ".json": "application/json",
    ".wasm": "application/wasm", ".png": "image/png", ".css": "text/css", ".woff2": "font/woff2", ".ttf": "font/ttf" };
  const files = { "/": "viewer/index.html", "/index.html": "viewer/index.html", "/app.js": "viewer/app.js" };
  const server = http.createServer((req, res) => {
    const p = decodeURIComponent(new URL(req.url, "http://127.0.0.1").pathname);
    let file;
    if (files[p]) file = path.join(__dirname, files[p]);
    else if (p === "/layout.json") file = path.join(src, "docs", "foxglove-layout.json");
    else if (/^\/npm\/(react|react-dom|@foxglove\/studio-base)\/[\w./@-]+$/.test(p) && !p.includes("..")) {
      file = path.join(npm, p.slice(5));
    }
    fs.readFile(file ?? "/nonexistent", (err, data) => {
      res.writeHead(err ? 404 : 200, { "content-type": types[path.extname(file ?? "")] ?? "application/octet-stream" });
      res.end(err ? undefined : data);
    });
  });
  return new Promise((resolve) => server.listen(0, "127.0.0.1", () => resolve(server)));
}

// sRGB bytes of the scene's body colours, distinct.
function expectedColours(sceneFile) {
  const seen = new Map();
  for (const c of lib.sceneColours(sceneFile)) {
    const rgb = c.map((v) => Math.round(v * 255));
    seen.set(rgb.join(","), rgb);
  }
  return [...seen.values()];
}

// Pixels of the PNG within `tol` of each colour (per channel), inside rect.
function countColours(png, rect, colours, tol) {
  const counts = colours.map(() => 0);
  for (let y = Math.max(0, rect.y); y < Math.min(png.height, rect.y + rect.height); y++) {
    for (let x = Math.max(0, rect.x); x < Math.min(png.width, rect.x + rect.width); x++) {
      const i = (y * png.width + x) * 4;
      colours.forEach((c, k) => {
        if (Math.abs(png.data[i] - c[0]) <= tol && Math.abs(png.data[i + 1] - c[1]) <= tol &&
          Math.abs(png.data[i + 2] - c[2]) <= tol) counts[k]++;
      });
    }
  }
  return counts;
}

// Centre (x, y) and count of the PNG's pixels within `tol` of `colour` (per channel).
function centroid(png, colour, tol) {
  let n = 0, sx = 0, sy = 0;
  for (let y = 0; y < png.height; y++) {
    for (let x = 0; x < png.width; x++) {
      const i = (y * png.width + x) * 4;
      if ([0, 1, 2].every((k) => Math.abs(png.data[i + k] - colour[k]) <= tol)) [n, sx, sy] = [n + 1, sx + x, sy + y];
    }
  }
  return { n, x: sx / n, y: sy / n };
}

// Starts `rbsim ARGS --domain D --foxglove 127.0.0.1:0` (a node on a scene, in namespace rbsim, the
// layout's, or a replay of a recording made in it) and Studio on it, waits for every advertised
// topic in the sidebar, runs body({ page, url, PNG, canvas }) and closes everything.
async function withStudio(check, args, body) {
  if (!fs.existsSync(CHROMIUM)) throw new Failure(`${CHROMIUM} not found: run scripts/setup`);
  const { chromium } = need("playwright-core");
  const { PNG } = need("pngjs");
  need("@foxglove/studio-base/package.json");
  need("react-dom/package.json");
  const [node, url] = await startServer(A.rbsim, [...args, "--domain", lib.domainFor(Number(A.index))],
    { name: args[0], logDir: workdir });
  // The topics the server advertises, seen by an independent client.
  const probe = await new Client(need, url, { name: "probe", subscribeAll: false }).ready();
  const topics = probe.topics();
  probe.close();
  log(`server ${url}: ${topics.join(" ")}`);

  const web = await staticServer();
  const page0 = `http://127.0.0.1:${web.address().port}/index.html`;
  const browser = await chromium.launch({ executablePath: CHROMIUM, headless: true, args: CHROMIUM_ARGS });
  try {
    const page = await browser.newPage({ viewport: { width: 1600, height: 900 } });
    const errors = [];
    page.on("pageerror", (e) => errors.push(e.message));
    // Anything but 127.0.0.1 is refused before it leaves the browser.
    await page.route(/^(?!(https?|wss?):\/\/127\.0\.0\.1[:/])/, (route) => route.abort());
    const t0 = performance.now();
    await page.goto(`${page0}?ds=foxglove-websocket&ds.url=${encodeURIComponent(url)}&layoutId=rbsim`,
      { timeout: 60000 });
    // The data source sidebar lists every topic once the player has connected.
    let missing = topics;
    for (const deadline = Date.now() + 60000; Date.now() < deadline && missing.length; ) {
      const t = await page.evaluate(() => document.body.innerText);
      missing = topics.filter((topic) => !t.includes(topic));
      if (missing.length) await page.waitForTimeout(250);
    }
    log(`topics listed ${((performance.now() - t0) / 1000).toFixed(1)} s after opening the page`);
    if (!check(missing.length === 0, `topics not listed in Foxglove: ${missing.join(" ")}`)) return;
    // Let it draw, then dismiss the 3D panel's first-use hint (it covers the plot's legend).
    await page.waitForTimeout(3000);
    const hint = page.getByText("Open settings to configure topics and layers.");
    await hint.locator("xpath=ancestor::div[.//button][1]//button").first().click({ timeout: 3000 }).catch(() => {});
    await hint.waitFor({ state: "hidden", timeout: 2000 }).catch(() => {});
    // The 3D panel's canvas: the largest one (the plot's is smaller).
    const canvas = await page.evaluate(() => {
      const cs = [...document.querySelectorAll("canvas")].map((c) => c.getBoundingClientRect())
        .sort((a, b) => b.width * b.height - a.width * a.height);
      return cs.length ? { x: Math.round(cs[0].x), y: Math.round(cs[0].y), width: Math.round(cs[0].width),
        height: Math.round(cs[0].height) } : undefined;
    });
    if (!check(canvas && canvas.width > 200 && canvas.height > 200, `no 3D canvas (${JSON.stringify(canvas)})`)) return;
    await body({ page, url, PNG, canvas });
    check(errors.length === 0, `page errors: ${errors.join("; ")}`);
  } finally {
    await browser.close();
    web.close();
    node.kill("SIGINT");
    check((await node.wait(15000)) === 0, `${args[0]} exited with ${node.code}\n${node.output()}`);
  }
}

// `rbsim node SCENE ARGS` in the layout's namespace.
const nodeArgs = (sceneFile, ...args) => ["node", sceneFile, ...args, "--namespace", "rbsim"];

async function caseColours(check) {
  const sceneFile = path.resolve(A.scene ?? path.join(src, "scenes", "creative", "wind-garden.xml"));
  const colours = expectedColours(sceneFile);
  if (!colours.length) throw new Failure(`${sceneFile} has no <rigidbodycolor>`);
  // 50 Hz for the scene's 2 ms steps, a viewer's pace: Chromium's single main thread, with software
  // WebGL, on a busy 2-core machine, falls behind every step's messages and then never paints.
  await withStudio(check, nodeArgs(sceneFile, "--rate", 1, "--loop", "--publish-every", 10), async ({ page, PNG, canvas }) => {
    // The layout's Parameters panel lists the node's parameters (got over the protocol's parameters
    // capability); the Service Call buttons are newer than Studio 1.48 (it shows them as unknown).
    let params = [];
    for (const deadline = Date.now() + 20000; Date.now() < deadline && params.length < 2; ) {
      const t = await page.evaluate(() => document.body.innerText);
      params = ["publish_every", "forces.0.fy"].filter((p) => t.includes(p));
      if (params.length < 2) await page.waitForTimeout(250);
    }
    check(params.length === 2, `the Parameters panel does not list publish_every and forces.0.fy (found: ${params})`);
    // Drawn when drawn: on a loaded machine software WebGL paints its first frames late, so the
    // panel is looked at until every colour shows (bounded), never once after a fixed wait.
    const shot = path.join(workdir, "viewer.png");
    let counts = colours.map(() => 0);
    let shown = [];
    const t0 = performance.now();
    for (const deadline = Date.now() + 60000; ; ) {
      await page.screenshot({ path: shot });
      counts = countColours(PNG.sync.read(fs.readFileSync(shot)), canvas, colours, 10);
      shown = colours.filter((_, k) => counts[k] >= 20);
      if (shown.length === colours.length || Date.now() >= deadline) break;
      await page.waitForTimeout(500);
    }
    if (A.screenshot) fs.copyFileSync(shot, path.resolve(A.screenshot));
    log(`screenshot ${shot} ${((performance.now() - t0) / 1000).toFixed(1)} s after the panels were up; ` +
      `3D canvas ${JSON.stringify(canvas)}`);
    log(`scene colours in the 3D panel (pixels): ${colours.map((c, k) => `rgb(${c}) ${counts[k]}`).join(", ")}`);
    check(shown.length === colours.length,
      `${colours.length - shown.length} of the scene's ${colours.length} body colours not drawn in the 3D panel: ` +
        colours.filter((_, k) => counts[k] < 20).map((c) => `rgb(${c})`).join(" "));
  });
}

async function caseParameters(check) {
  const sceneFile = path.join(__dirname, "viewer", "drift.xml");
  const [colour] = expectedColours(sceneFile);
  await withStudio(check, nodeArgs(sceneFile, "--rate", 1, "--publish-every", 10), async ({ page, url, PNG, canvas }) => {
    // An independent client: the parameter names the server sends, and /rbsim/commands.
    const c = new Client(need, url, { name: "params", subscribeAll: false });
    const values = [];
    c.client.on("parameterValues", (m) => values.push(m));
    await c.ready();
    const commands = [...c.channels.values()].find((ch) => ch.topic === "/rbsim/commands");
    if (!commands) throw new Failure(`no /rbsim/commands channel: ${c.topics()}`);
    c.subscribe(commands);
    c.client.getParameters([], "all");
    const names = (await until("parameterValues", 5000, () => values.find((v) => v.id === "all")))
      .parameters.map((p) => p.name).sort();
    // The Parameters panel: a table headed Parameter | Value, a name per row.
    const listed = () => page.evaluate(() => {
      const t = [...document.querySelectorAll("table")].find((e) => /^Parameter\s+Value/.test(e.tHead?.innerText ?? ""));
      return t ? [...t.tBodies[0].rows].map((r) => r.cells[0].innerText.trim()).sort() : [];
    });
    let shown = [];
    for (const deadline = Date.now() + 20000; Date.now() < deadline && shown.join() !== names.join(); ) {
      shown = await listed();
      if (shown.join() !== names.join()) await page.waitForTimeout(250);
    }
    log(`the Parameters panel lists the ${shown.length} parameters the server sends`);
    check(names.includes("forces.0.fx") && shown.join() === names.join(),
      `the Parameters panel lists ${shown.join(" ")}; the server sends ${names.join(" ")}`);

    // The square, in the 3D panel's pixels: drawn, and still while the wind is still.
    const square = async () => centroid(PNG.sync.read(await page.screenshot({ clip: canvas })), colour, 10);
    await page.waitForTimeout(1000);
    const before = await square();
    await page.waitForTimeout(1000);
    const still = await square();
    log(`square before: ${JSON.stringify(before)}, 1 s later ${JSON.stringify(still)}`);
    if (!check(before.n >= 200 && Math.hypot(still.x - before.x, still.y - before.y) < 3,
      `the square is not drawn, or moves in a still wind: ${JSON.stringify([before, still])}`)) return;

    // The wind set through the panel: its value typed in the row's editor, then its submit button.
    const row = page.locator("tbody tr", { has: page.locator('[title="forces.0.fx"]') });
    await row.locator("textarea").click({ timeout: 5000 });
    await page.keyboard.press("Control+A");
    await page.keyboard.type("2.5");
    await row.getByRole("button", { name: "Submit change" }).click({ timeout: 5000 });
    const set = await until("the set on /rbsim/commands", 10000, () => c.messages.find((m) => m.topic === "/rbsim/commands"));
    const cmd = set.decoded;
    const p = cmd.parameters;
    const text = JSON.stringify(cmd, (k, v) => (typeof v === "bigint" ? Number(v) : v));
    log(`/rbsim/commands: ${text}`);
    check(cmd.kind === 0 && cmd.source === "foxglove" && cmd.success && p.length === 1 && p[0].name === "forces.0.fx" &&
      p[0].value.type === 3 && p[0].value.double_value === 2.5,
    `the command on /rbsim/commands is not forces.0.fx = 2.5 from foxglove, applied: ${text}`);

    // The square drifts: wait until it moved 60 px, then it must have moved right, not up or down.
    let after = still;
    for (const deadline = Date.now() + 15000; Date.now() < deadline && Math.hypot(after.x - still.x, after.y - still.y) < 60; ) {
      after = await square();
    }
    log(`square after the set: ${JSON.stringify(after)}`);
    const [dx, dy] = [after.x - still.x, after.y - still.y];
    check(after.n >= 200 && dx >= 60 && Math.abs(dy) < dx / 4,
      `the square did not drift right after forces.0.fx = 2.5: moved (${dx.toFixed(1)}, ${dy.toFixed(1)}) px`);
    check(c.messages.filter((m) => m.topic === "/rbsim/commands").length === 1, "more than one command published");
    await page.screenshot({ path: path.join(workdir, "viewer.png") });
    c.close();
  });
}

// A blue square, spawned 3 m right of drift.xml's orange one (which then goes).
const BLUE_SQUARE = `<scene>
  <rigidbodyvertex x="-1" y="-1" m="1"/><rigidbodyvertex x="1" y="-1" m="1"/>
  <rigidbodyvertex x="1" y="1" m="1"/><rigidbodyvertex x="-1" y="1" m="1"/>
  <rigidbody p="0" p="1" p="2" p="3" vx="0" vy="0" omega="0" r="0.05"/>
  <rigidbodycolor body="0" r="0.1" g="0.35" b="0.95"/>
</scene>`;
const BLUE = [0.1, 0.35, 0.95].map((v) => Math.round(v * 255));

// An independent client's json calls of the server's services named `${prefix}/NAME`; made before
// the client is ready (the services are advertised once, with serverInfo).
function serviceCaller(c, prefix) {
  let services;
  const replies = new Map();
  c.client.on("advertiseServices", (s) => (services = s));
  c.client.on("serviceCallResponse", (r) => replies.set(r.callId, r));
  c.client.on("serviceCallFailure", (f) => replies.set(f.callId, f));
  let callId = 0;
  return async (name, request) => {
    await until("advertiseServices", 5000, () => services);
    const s = services.find((x) => x.name === `${prefix}/${name}`);
    if (!s) throw new Failure(`no service ${prefix}/${name}: ${services.map((x) => x.name)}`);
    const id = ++callId;
    const data = new TextEncoder().encode(JSON.stringify(request));
    c.client.sendServiceCallRequest({ serviceId: s.id, callId: id, encoding: "json",
      data: new DataView(data.buffer, data.byteOffset, data.byteLength) });
    const r = await until(`the answer to ${name}`, 15000, () => replies.get(id));
    if (!r.data) throw new Failure(`${prefix}/${name}: ${r.message}`);
    return JSON.parse(new TextDecoder().decode(r.data));
  };
}

// The 3D panel's pixels of each of `colours` ({ name: [r, g, b] }): look() counts them once;
// seen(what, want) looks until want(counts) holds (bounded: software WebGL on a busy machine
// paints late), then logs and checks it.
function painter(check, { page, PNG, canvas }, colours) {
  const look = async () => {
    const png = PNG.sync.read(await page.screenshot({ clip: canvas }));
    return Object.fromEntries(Object.entries(colours).map(([k, c]) => [k, centroid(png, c, 10).n]));
  };
  const seen = async (what, want) => {
    let counts;
    for (const deadline = Date.now() + 30000; ; ) {
      counts = await look();
      if (want(counts) || Date.now() >= deadline) break;
      await page.waitForTimeout(250);
    }
    log(`${what}: ${JSON.stringify(counts)} pixels`);
    if (!want(counts)) await page.screenshot({ path: path.join(workdir, "failed.png") });
    return check(want(counts), `${what}: ${JSON.stringify(counts)} pixels (the page: failed.png)`);
  };
  return { look, seen };
}

async function caseChanges(check) {
  const sceneFile = path.join(__dirname, "viewer", "drift.xml");
  const [orange] = expectedColours(sceneFile);
  await withStudio(check, nodeArgs(sceneFile, "--rate", 1, "--publish-every", 10), async (studio) => {
    // The node's services, called in json by an independent client.
    const c = new Client(need, studio.url, { name: "changes", subscribeAll: false });
    const call = serviceCaller(c, "/rbsim");
    await c.ready();
    const { seen } = painter(check, studio, { orange, blue: BLUE });
    if (!(await seen("the scene's orange square alone", (n) => n.orange >= 200 && n.blue < 20))) return;
    const spawned = await call("spawn_entity", {
      name: "blue", allow_renaming: false, entity_namespace: "",
      entity_resource: { uri: "", resource_string: BLUE_SQUARE },
      initial_pose: { header: { stamp: { sec: 0, nanosec: 0 }, frame_id: "" },
        pose: { position: { x: -3, y: 0, z: 0 }, orientation: { x: 0, y: 0, z: 0, w: 1 } } },
    });
    check(spawned.result?.result === 1 && spawned.entity_name === "blue", `spawn_entity: ${JSON.stringify(spawned)}`);
    if (!(await seen("spawned: both squares", (n) => n.orange >= 200 && n.blue >= 200))) return;
    const deleted = await call("delete_entity", { entity: "body_0" });
    check(deleted.result?.result === 1, `delete_entity: ${JSON.stringify(deleted)}`);
    await seen("deleted: the blue square alone", (n) => n.orange < 20 && n.blue >= 200);
    await studio.page.screenshot({ path: path.join(workdir, "viewer.png") });
    c.close();
  });
}

// The recording of case replay_changes: drift.xml's orange square alone, the blue square spawned 3 m
// right of it at step 2000 (t = 4 s), the orange one deleted at step 3000 (t = 6 s), 8 s in all;
// every 20th step recorded, uncompressed (read back here by the official reader).
const START_STEP = 500; // --start-offset 1 (s): Studio's first clock is not 0 (see caseReplayChanges)
const SPAWN_STEP = 2000;
const DELETE_STEP = 3000;
const RECORD_EVERY = 20;

async function recordChanges(sceneFile) {
  fs.writeFileSync(path.join(workdir, "blue.xml"), BLUE_SQUARE);
  const script = path.join(workdir, "changes.yaml");
  fs.writeFileSync(script, `- {step: ${SPAWN_STEP}, spawn: {file: blue.xml, name: blue, x: [-3, 0], theta: 0}}\n` +
    `- {step: ${DELETE_STEP}, delete: body_0}\n`);
  const recording = path.join(workdir, "changes.mcap");
  const run = new Proc("run", [A.rbsim, "run", sceneFile, "--duration", 8, "--commands", script, "--record", recording,
    "--record-every", RECORD_EVERY, "--compression", "none"].map(String), { logDir: workdir });
  if ((await run.wait(60000)) !== 0) throw new Failure(`rbsim run exited with ${run.code}\n${run.output()}`);
  return recording;
}

// What `burst` counts in the replay of `recording` from log time `start` (ns, --start-offset): every
// message from there in log-time order but the scene description and markers sent before them.
// played(step): how many there are up to the body states of `step` (its log time) inclusive.
function replayOrder(recording, start) {
  const topics = lib.readMcap(need, recording);
  const { parse } = need("@foxglove/rosmsg");
  const { MessageReader } = need("@foxglove/rosmsg2-serialization");
  const states = topics.get("/rbsim/body_states");
  const reader = new MessageReader(parse(states.channel.schema, { ros2: true }));
  const timeOf = new Map(states.messages.map((m) => [Number(reader.readMessage(m.data).step), m.time]));
  const all = [...topics].flatMap(([topic, t]) => t.messages.map((m) => ({ topic, time: m.time })));
  const latched = new Set(["/rbsim/scene", "/rbsim/markers"]);
  const counted = all.filter((m) => m.time > start || (m.time === start && !latched.has(m.topic)));
  return (step) => {
    if (!timeOf.has(step)) throw new Failure(`step ${step} is not in ${recording}`);
    return counted.filter((m) => m.time <= timeOf.get(step)).length;
  };
}

// What a client that joins now gets: its first time message (s), the scene description's bodies
// (their colours, rgb bytes) and stamp (s), and the markers' body frames and whether they start
// with a DELETEALL.
async function lateJoiner(url, name) {
  const c = new Client(need, url, { name, subscribeAll: false });
  await c.ready();
  for (const ch of c.channels.values()) if (["/rbsim/scene", "/rbsim/markers"].includes(ch.topic)) c.subscribe(ch);
  const got = (topic) => c.messages.find((m) => m.topic === topic)?.decoded;
  await until(`${name}: the scene description and markers`, 5000, () => got("/rbsim/scene") && got("/rbsim/markers"));
  const [scene, markers] = [got("/rbsim/scene"), got("/rbsim/markers")];
  c.close();
  return {
    time: c.times.length ? Number(c.times[0]) / 1e9 : undefined,
    colours: scene.bodies.map((b) => [b.color.r, b.color.g, b.color.b].map((v) => Math.round(v * 255)).join(",")),
    stamp: scene.header.stamp.sec + scene.header.stamp.nanosec * 1e-9,
    frames: [...new Set(markers.markers.map((m) => m.header.frame_id).filter((f) => f !== "world"))].sort(),
    deleteAll: markers.markers[0]?.action === 3,
  };
}

// `rbsim replay --foxglove` of a recording whose bodies change (made by `rbsim run --commands
// --record`), started paused; the player's burst service (an independent client) plays it on in
// exact message counts while Studio watches: a recorded step at a time until the orange square is
// drawn (Studio subscribed and painted; before the spawn), then to step 2500 (both squares), then
// to step 3500 (the blue one alone), each state seen in the 3D panel and in the body states the
// client receives; at each, a client that joins late gets the time the replay stands at and the
// latest scene description and markers. It starts at step 500 (--start-offset), so Studio's first
// clock is the 1 s the server gives a new client (the replay starts each session with the time it
// plays from), not 0: Studio 1.48 may drop what it was given at clock 0 when its clock first moves
// (its first "seek" clears the 3D panel).
async function caseReplayChanges(check) {
  const sceneFile = path.join(__dirname, "viewer", "drift.xml");
  const [orange] = expectedColours(sceneFile);
  const recording = await recordChanges(sceneFile);
  const played = replayOrder(recording, BigInt(START_STEP) * 2000000n);
  await withStudio(check, ["replay", recording, "--start-paused", "--start-offset", START_STEP * 0.002], async (studio) => {
    const c = new Client(need, studio.url, { name: "player", subscribeAll: false });
    const call = serviceCaller(c, "/rbsim_player");
    await c.ready();
    const states = [...c.channels.values()].find((ch) => ch.topic === "/rbsim/body_states");
    if (!states) throw new Failure(`no /rbsim/body_states channel: ${c.topics()}`);
    c.subscribe(states);
    check((await call("is_paused", {})).paused === true, "is_paused: want true (--start-paused)");
    // Plays on to `step` (all its messages) and returns the ids of the bodies its body states hold.
    let at = 0;
    const playTo = async (step) => {
      const n = played(step) - at;
      const r = await call("burst", { num_messages: n });
      if (!check(Number(r.actually_burst) === n, `burst ${n} to step ${step}: ${JSON.stringify(r)}`)) return [];
      at += n;
      const last = await until(`the body states of step ${step}`, 10000, () => {
        const m = c.messages.filter((x) => x.topic === "/rbsim/body_states").at(-1);
        return m && Number(m.decoded.step) === step && m;
      });
      return last.decoded.bodies.map((b) => b.id);
    };
    const { look, seen } = painter(check, studio, { orange, blue: BLUE });
    let step = START_STEP;
    let ids = await playTo(step);
    for (let counts = await look(); counts.orange < 200 && step + RECORD_EVERY < SPAWN_STEP; counts = await look()) {
      step += RECORD_EVERY;
      ids = await playTo(step);
    }
    log(`played to step ${step} a recorded step per burst, until the orange square was drawn`);
    check(JSON.stringify(ids) === "[0]", `step ${step}: body states of ids ${ids}, want [0]`);
    if (!(await seen(`step ${step}, before the spawn: the orange square alone`,
      (n) => n.orange >= 200 && n.blue < 20))) return;
    const expect = async (when, want) => {
      const got = await lateJoiner(studio.url, `late joiner at ${when}`);
      log(`a late joiner at ${when}: ${JSON.stringify(got)}`);
      check(JSON.stringify(got) === JSON.stringify(want), `a late joiner at ${when}: ${JSON.stringify(got)}, want ${
        JSON.stringify(want)}`);
    };
    const [rgbOrange, rgbBlue] = [orange.join(","), BLUE.join(",")];
    await expect(`step ${step}`, { time: step * 0.002, colours: [rgbOrange], stamp: 0, frames: ["rbsim/body_0"],
      deleteAll: false });

    ids = await playTo(2500);
    check(JSON.stringify(ids) === "[0,1]", `step 2500: body states of ids ${ids}, want [0,1]`);
    if (!(await seen("step 2500, after the spawn: both squares", (n) => n.orange >= 200 && n.blue >= 200))) return;
    await expect("step 2500", { time: 5, colours: [rgbOrange, rgbBlue], stamp: 4, frames: ["rbsim/blue", "rbsim/body_0"],
      deleteAll: true });

    ids = await playTo(3500);
    check(JSON.stringify(ids) === "[1]", `step 3500: body states of ids ${ids}, want [1]`);
    await seen("step 3500, after the delete: the blue square alone", (n) => n.orange < 20 && n.blue >= 200);
    await expect("step 3500", { time: 7, colours: [rgbBlue], stamp: 6, frames: ["rbsim/blue"], deleteAll: true });
    check((await call("is_paused", {})).paused === true, "is_paused at the end: want true");
    await studio.page.screenshot({ path: path.join(workdir, "viewer.png") });
    c.close();
  });
}

runMain(CASES[A.case][0], CASES[A.case][1]);
