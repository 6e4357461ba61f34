#!/usr/bin/env node
"use strict";
// The real viewer: Foxglove Studio's last open-source web build (npm @foxglove/studio-base 1.48.0)
// in Debian's headless Chromium with software WebGL, connected to a live `rbsim node --foxglove`
// with docs/foxglove-layout.json, driven over the DevTools protocol (playwright-core, Chromium
// started from /usr/bin/chromium). Passes when the sidebar lists every advertised topic and the 3D
// panel shows the body colours of the scene's XML.
//
//   viewer.js --rbsim BUILD/rbsim --source-dir SRC --workdir DIR --npm BUILD/npm --index N
//             [--scene FILE] [--screenshot PNG]   (--screenshot: also write the whole page there)
const fs = require("fs");
const http = require("http");
const path = require("path");
const lib = require("./lib");
const { Failure, startServer, Client, runMain } = lib;

const A = {};
for (let i = 2; i < process.argv.length; i += 2) A[process.argv[i].replace(/^--/, "")] = process.argv[i + 1];
const need = lib.npmModules(A.npm);
const src = path.resolve(A["source-dir"]);
const workdir = path.resolve(A.workdir);
fs.rmSync(workdir, { recursive: true, force: true });
fs.mkdirSync(workdir, { recursive: true });
const log = (msg) => console.log(`[${(performance.now() / 1000).toFixed(2)}] ${msg}`);

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

runMain("foxglove_client.viewer", async (check) => {
  if (!fs.existsSync(CHROMIUM)) throw new Failure(`${CHROMIUM} not found: run scripts/setup`);
  const { chromium } = need("playwright-core");
  const { PNG } = need("pngjs");
  need("@foxglove/studio-base/package.json");
  need("react-dom/package.json");

  const sceneFile = path.resolve(A.scene ?? path.join(src, "scenes", "creative", "wind-garden.xml"));
  const colours = expectedColours(sceneFile);
  if (!colours.length) throw new Failure(`${sceneFile} has no <rigidbodycolor>`);
  // 50 Hz for the scene's 2 ms steps, a viewer's pace: Chromium's single main thread, with software
  // WebGL, on a busy 2-core machine, falls behind every step's messages and then never paints.
  const [node, url] = await startServer(A.rbsim, ["node", sceneFile, "--rate", 1, "--loop", "--publish-every", 10,
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
    const text = () => page.evaluate(() => document.body.innerText);
    let missing = topics;
    for (const deadline = Date.now() + 60000; Date.now() < deadline && missing.length; ) {
      const t = await text();
      missing = topics.filter((topic) => !t.includes(topic));
      if (missing.length) await page.waitForTimeout(250);
    }
    log(`topics listed ${((performance.now() - t0) / 1000).toFixed(1)} s after opening the page`);
    check(missing.length === 0, `topics not listed in Foxglove: ${missing.join(" ")}`);
    // The layout's Parameters panel lists the node's parameters (got over the protocol's parameters
    // capability); the Service Call buttons are newer than Studio 1.48 (it shows them as unknown).
    let params = [];
    for (const deadline = Date.now() + 20000; Date.now() < deadline && params.length < 2; ) {
      const t = await text();
      params = ["publish_every", "forces.0.fy"].filter((p) => t.includes(p));
      if (params.length < 2) await page.waitForTimeout(250);
    }
    check(params.length === 2, `the Parameters panel does not list publish_every and forces.0.fy (found: ${params})`);
    // Let it draw, then dismiss the 3D panel's first-use hint (it covers the plot's legend).
    await page.waitForTimeout(3000);
    const hint = page.getByText("Open settings to configure topics and layers.");
    await hint.locator("xpath=ancestor::div[.//button][1]//button").first().click({ timeout: 3000 }).catch(() => {});
    await hint.waitFor({ state: "hidden", timeout: 2000 }).catch(() => {});
    // The 3D panel's canvas: the largest one (the plot's is smaller).
    const rect = await page.evaluate(() => {
      const cs = [...document.querySelectorAll("canvas")].map((c) => c.getBoundingClientRect())
        .sort((a, b) => b.width * b.height - a.width * a.height);
      return cs.length ? { x: Math.round(cs[0].x), y: Math.round(cs[0].y), width: Math.round(cs[0].width),
        height: Math.round(cs[0].height) } : undefined;
    });
    const shot = path.join(workdir, "viewer.png");
    await page.screenshot({ path: shot });
    if (A.screenshot) fs.copyFileSync(shot, path.resolve(A.screenshot));
    log(`screenshot ${shot}; 3D canvas ${JSON.stringify(rect)}`);
    if (!check(rect && rect.width > 200 && rect.height > 200, `no 3D canvas (${JSON.stringify(rect)})`)) return;
    const png = PNG.sync.read(fs.readFileSync(shot));
    const counts = countColours(png, rect, colours, 10);
    const shown = colours.filter((_, k) => counts[k] >= 20);
    log(`scene colours in the 3D panel (pixels): ${colours.map((c, k) => `rgb(${c}) ${counts[k]}`).join(", ")}`);
    check(shown.length === colours.length,
      `${colours.length - shown.length} of the scene's ${colours.length} body colours not drawn in the 3D panel: ` +
        colours.filter((_, k) => counts[k] < 20).map((c) => `rgb(${c})`).join(" "));
    check(errors.length === 0, `page errors: ${errors.join("; ")}`);
  } finally {
    await browser.close();
    web.close();
    node.kill("SIGINT");
    check((await node.wait(15000)) === 0, `node exited with ${node.code}\n${node.output()}`);
  }
});
