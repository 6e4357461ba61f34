#!/usr/bin/env node
"use strict";
// The real viewer: Foxglove Studio's last open-source web build (npm @foxglove/studio-base 1.48.0)
// in Debian's headless Chromium with software WebGL, connected to a live `rbsim node --foxglove`
// with docs/foxglove-layout.json, driven over the DevTools protocol (playwright-core, Chromium
// started from /usr/bin/chromium). Both cases first wait for the sidebar to list every advertised
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
//               (foxglove_client.viewer_changes).
//
//   viewer.js --case colours|parameters --rbsim BUILD/rbsim --source-dir SRC --workdir DIR
//             --npm BUILD/npm --index N [--scene FILE] [--screenshot PNG]
//   (--screenshot: also write the page of case colours there)
const fs = require("fs");
const http = require("http");
const path = require("path");
const lib = require("./lib");
const { Failure, until, startServer, Client, runMain } = lib;

const { A, workdir } = lib.caseArgs(["case", "rbsim", "source-dir", "workdir", "npm", "index"]);
const need = lib.npmModules(A.npm);
const src = path.resolve(A["source-dir"]);
const CASES = {
  colours: ["foxglove_client.viewer", caseColours],
  parameters: ["foxglove_client.viewer_parameters", caseParameters],
  changes: ["foxglove_client.viewer_changes", caseChanges],
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

// Starts the node on `sceneFile` (namespace rbsim, the layout's) and Studio on it, waits for every
// advertised topic in the sidebar, runs body({ page, url, PNG, canvas }) and closes everything.
async function withStudio(check, sceneFile, nodeArgs, body) {
  if (!fs.existsSync(CHROMIUM)) throw new Failure(`${CHROMIUM} not found: run scripts/setup`);
  const { chromium } = need("playwright-core");
  const { PNG } = need("pngjs");
  need("@foxglove/studio-base/package.json");
  need("react-dom/package.json");
  const [node, url] = await startServer(A.rbsim, ["node", sceneFile, ...nodeArgs,
    "--domain", lib.domainFor(Number(A.index)), "--namespace", "rbsim"], { logDir: workdir });
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
    check((await node.wait(15000)) === 0, `node exited with ${node.code}\n${node.output()}`);
  }
}

async function caseColours(check) {
  const sceneFile = path.resolve(A.scene ?? path.join(src, "scenes", "creative", "wind-garden.xml"));
  const colours = expectedColours(sceneFile);
  if (!colours.length) throw new Failure(`${sceneFile} has no <rigidbodycolor>`);
  // 50 Hz for the scene's 2 ms steps, a viewer's pace: Chromium's single main thread, with software
  // WebGL, on a busy 2-core machine, falls behind every step's messages and then never paints.
  await withStudio(check, sceneFile, ["--rate", 1, "--loop", "--publish-every", 10], async ({ page, PNG, canvas }) => {
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
  await withStudio(check, sceneFile, ["--rate", 1, "--publish-every", 10], async ({ page, url, PNG, canvas }) => {
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

async function caseChanges(check) {
  const sceneFile = path.join(__dirname, "viewer", "drift.xml");
  const [orange] = expectedColours(sceneFile);
  const blue = [0.1, 0.35, 0.95].map((v) => Math.round(v * 255));
  await withStudio(check, sceneFile, ["--rate", 1, "--publish-every", 10], async ({ page, url, PNG, canvas }) => {
    // The node's services, called in json by an independent client.
    const c = new Client(need, url, { name: "changes", subscribeAll: false });
    let services;
    const responses = new Map();
    c.client.on("advertiseServices", (s) => (services = s));
    c.client.on("serviceCallResponse", (r) => responses.set(r.callId, r));
    await c.ready();
    await until("advertiseServices", 5000, () => services);
    let callId = 0;
    const call = async (name, request) => {
      const s = services.find((x) => x.name === `/rbsim/${name}`);
      if (!s) throw new Failure(`no service /rbsim/${name}: ${services.map((x) => x.name)}`);
      const id = ++callId;
      const data = new TextEncoder().encode(JSON.stringify(request));
      c.client.sendServiceCallRequest({ serviceId: s.id, callId: id, encoding: "json",
        data: new DataView(data.buffer, data.byteOffset, data.byteLength) });
      const r = await until(`the answer to ${name}`, 10000, () => responses.get(id));
      return JSON.parse(new TextDecoder().decode(r.data));
    };
    // Pixels of a colour in the 3D panel, looked at until `want` holds (bounded: software WebGL on
    // a busy machine paints late).
    const seen = async (what, want) => {
      let counts;
      for (const deadline = Date.now() + 30000; ; ) {
        const png = PNG.sync.read(await page.screenshot({ clip: canvas }));
        counts = { orange: centroid(png, orange, 10).n, blue: centroid(png, blue, 10).n };
        if (want(counts) || Date.now() >= deadline) break;
        await page.waitForTimeout(250);
      }
      log(`${what}: ${JSON.stringify(counts)} pixels`);
      return check(want(counts), `${what}: ${JSON.stringify(counts)} pixels`);
    };
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
    await page.screenshot({ path: path.join(workdir, "viewer.png") });
    c.close();
  });
}

runMain(CASES[A.case][0], CASES[A.case][1]);
