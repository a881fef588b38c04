// The control room and "drive it yourself" in a real headless Chromium.
//
//   npm ci --prefix tests/viewer && npm ci --prefix clients/viewer
//   node tests/viewer/drive_test.mjs
//
// Starts build/downpour-server and clients/viewer/viewer.py, opens /drive, waits for frames,
// holds the throttle, switches the wipers to high, moves the rain slider, then checks that the
// cockpit image changed, the HUD shows the new rain rate, the car sped up and the session is in
// the control room's list; Stop closes the session; with the server gone the page says so.
// Screenshots go to $DOWNPOUR_TEST_SCREENSHOTS (else a temporary folder, printed).
//
// Environment: DOWNPOUR_SERVER (the server binary), DOWNPOUR_PYTHON_STUBS (generated Python
// modules), DOWNPOUR_PYTHON (default /usr/bin/python3), CHROMIUM (default /usr/bin/chromium).
// Exits 77 (ctest: skipped) when puppeteer-core or Chromium is missing.

import {spawn} from "node:child_process";
import {createHash} from "node:crypto";
import fs from "node:fs";
import os from "node:os";
import path from "node:path";
import {fileURLToPath} from "node:url";

const HERE = path.dirname(fileURLToPath(import.meta.url));
const REPO = path.resolve(HERE, "..", "..");
const SERVER = process.env.DOWNPOUR_SERVER || path.join(REPO, "build", "downpour-server");
const STUBS = process.env.DOWNPOUR_PYTHON_STUBS || path.join(REPO, "build", "python");
const PYTHON = process.env.DOWNPOUR_PYTHON || "/usr/bin/python3";
const CHROMIUM = process.env.CHROMIUM || "/usr/bin/chromium";
const OVERALL_TIMEOUT_MS = 150_000;
const SKIP = 77;

const started = Date.now();
const work = fs.mkdtempSync(path.join(os.tmpdir(), "downpour-browser-"));
const shots = process.env.DOWNPOUR_TEST_SCREENSHOTS || path.join(work, "screenshots");
fs.mkdirSync(shots, {recursive: true});
const children = [];
let browser = null;

const log = (...args) => console.log(`[${((Date.now() - started) / 1000).toFixed(1).padStart(5)} s]`, ...args);
const sleep = (ms) => new Promise((resolve) => setTimeout(resolve, ms));

function check(condition, message) {
  if (!condition) throw new Error("check failed: " + message);
  log("ok:", message);
}

async function waitFor(what, fn, timeoutMs = 20_000, everyMs = 200) {
  const deadline = Date.now() + timeoutMs;
  let last;
  while (Date.now() < deadline) {
    try {
      last = await fn();
      if (last) return last;
    } catch (e) { last = e.message; }
    await sleep(everyMs);
  }
  throw new Error(`timed out after ${timeoutMs / 1000} s waiting for ${what} (last: ${JSON.stringify(last)})`);
}

function start(name, command, args, env) {
  const out = fs.openSync(path.join(work, name + ".log"), "w");
  const child = spawn(command, args, {env: {...process.env, ...env}, stdio: ["ignore", "pipe", out]});
  child.output = "";
  child.stdout.on("data", (chunk) => { child.output += chunk; fs.appendFileSync(path.join(work, name + ".log"), chunk); });
  child.name = name;
  children.push(child);
  return child;
}

async function stopChild(child) {
  if (child.exitCode !== null || child.signalCode !== null) return;
  const exited = new Promise((resolve) => child.once("exit", resolve));
  child.kill("SIGTERM");
  if (await Promise.race([exited.then(() => true), sleep(8000).then(() => false)]) === false) {
    child.kill("SIGKILL");
    await exited;
  }
}

async function cleanup() {
  if (browser) await browser.close().catch(() => {});
  for (const child of children.reverse()) await stopChild(child);
}

async function json(url, options) {
  const response = await fetch(url, options);
  if (!response.ok) throw new Error(`${url}: HTTP ${response.status}`);
  return response.json();
}

const sha = (buffer) => createHash("sha1").update(buffer).digest("hex");

async function main() {
  let puppeteer;
  try {
    puppeteer = (await import("puppeteer-core")).default;
  } catch (e) {
    console.log("SKIP: puppeteer-core is not installed (run: npm ci --prefix tests/viewer)");
    return SKIP;
  }
  if (!fs.existsSync(CHROMIUM)) {
    console.log(`SKIP: no Chromium at ${CHROMIUM} (apt-get install chromium, or set CHROMIUM)`);
    return SKIP;
  }
  if (!fs.existsSync(path.join(REPO, "clients", "viewer", "node_modules", "uplot"))) {
    log("note: clients/viewer/node_modules is missing: the page runs without plots (npm ci --prefix clients/viewer)");
  }
  // The server binary may be briefly missing while it is rebuilt.
  await waitFor(`the server binary ${SERVER}`, () => fs.existsSync(SERVER), 60_000, 1000);

  const portFile = path.join(work, "port");
  const server = start("server", SERVER, ["--listen", "127.0.0.1:0", "--port-file", portFile],
                       {EGL_PLATFORM: "surfaceless", LP_NUM_THREADS: "2"});
  const port = await waitFor("the server's port file", () => {
    if (server.exitCode !== null) throw new Error("the server exited; see " + path.join(work, "server.log"));
    const text = fs.existsSync(portFile) ? fs.readFileSync(portFile, "utf8").trim() : "";
    return text ? Number(text) : 0;
  }, 30_000, 100);
  log("server on port", port);

  const viewer = start("viewer", PYTHON, [path.join(REPO, "clients", "viewer", "viewer.py"),
                                          "--server", `127.0.0.1:${port}`, "--port", "0"],
                       {PYTHONPATH: path.join(REPO, "clients", "python"), DOWNPOUR_PYTHON_STUBS: STUBS});
  const base = await waitFor("the viewer's banner", () => {
    if (viewer.exitCode !== null) throw new Error("the viewer exited; see " + path.join(work, "viewer.log"));
    const m = /http:\/\/([0-9.]+:\d+)\//.exec(viewer.output);
    return m ? "http://" + m[1] : "";
  }, 20_000, 100);
  log("viewer at", base);

  browser = await puppeteer.launch({
    executablePath: CHROMIUM, headless: false,
    args: ["--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
           "--hide-scrollbars", "--mute-audio", "--window-size=1440,960"],
    defaultViewport: {width: 1440, height: 960},
  });
  const page = await browser.newPage();
  const pageErrors = [];
  page.on("pageerror", (e) => pageErrors.push(e.message));
  page.on("console", (m) => { if (m.type() === "error" && !m.text().startsWith("Failed to load resource")) pageErrors.push(m.text()); });
  page.on("response", (r) => { if (r.status() >= 400) pageErrors.push(`HTTP ${r.status()} for ${r.url()}`); });

  // The drive page creates the viewer's own session and shows its frames.
  await page.goto(base + "/drive", {waitUntil: "domcontentloaded"});
  const drive0 = await waitFor("the drive session", async () => {
    const d = await json(base + "/api/drive/state.json");
    return d.state === "driving" && d.session_id ? d : null;
  }, 30_000);
  const sessionId = drive0.session_id;
  log("driving session", sessionId);
  await waitFor("frames in both views", () => page.evaluate(() =>
    Number(document.getElementById("frame-cockpit").dataset.frame || 0) > 2 &&
    Number(document.getElementById("frame-road").dataset.frame || 0) > 2), 45_000);
  // The HUD's stats come from the viewer's own watch of the session, which starts after the drive's
  // first frames: as long a wait as for those.
  try {
    await waitFor("the HUD", () => page.$eval("#hud-cockpit", (e) => e.textContent.includes("render")), 45_000);
  } catch (e) {
    // What the page and the viewer said, for the log (the viewer's log is kept beside it).
    log(`the HUD: ${await page.$eval("#hud-cockpit", (el) => el.innerText).catch((x) => x.message)}`);
    log(`the page's session: ${await page.$eval("#session", (el) => el.innerText).catch((x) => x.message)}`);
    log(`the viewer's drive: ${JSON.stringify(await json(base + "/api/drive/state.json").catch((x) => x.message))}`);
    throw e;
  }
  await page.screenshot({path: path.join(shots, "01-drive-start.png")});

  // The frames' stream read from chunks cut anywhere: a byte at a time, and 7 bytes at a time.
  const parsed = await page.evaluate(() => {
    const enc = new TextEncoder();
    const part = (n, body) => [enc.encode(`--b\r\nContent-Type: image/jpeg\r\nX-View: v${n}\r\nX-Frame-Number: ${n}\r\n` +
                                          `Content-Length: ${body.length}\r\n\r\n`), body, enc.encode("\r\n")];
    const bytes = new Uint8Array([].concat(part(41, new Uint8Array([1, 13, 10, 13, 10, 2])), part(42, new Uint8Array(300).fill(7)))
                                   .flatMap((a) => [...a]));
    return [1, 7].map((size) => {
      const reader = new Downpour.MultipartReader(), got = [];
      for (let i = 0; i < bytes.length; i += size) {
        for (const p of reader.push(bytes.slice(i, i + size))) got.push(`${p.view}:${p.frame}:${p.body.length}:${p.body[1]}`);
      }
      return got.join(" ");
    });
  });
  check(parsed.every((p) => p === "v41:41:6:13 v42:42:300:7"), `the stream's parts read from any chunks: ${parsed.join(" / ")}`);
  const cockpit = await page.$("#frame-cockpit");
  const frameBefore = Number(await page.$eval("#frame-cockpit", (e) => e.dataset.frame));
  const imageBefore = sha(await cockpit.screenshot());
  const speedBefore = (await json(base + "/api/drive/state.json")).speed_mps;

  // Throttle for three seconds: the page sends the held key five times a second.
  await page.keyboard.down("KeyW");
  await waitFor("the W key shown pressed", () => page.$eval("#key-throttle", (e) => e.classList.contains("down")), 5000);
  await sleep(3000);
  const throttled = await json(base + "/api/drive/state.json");
  await page.keyboard.up("KeyW");
  check(throttled.keys.throttle === true, "the viewer got the held throttle");
  check(throttled.speed_mps > speedBefore + 5,
        `speed went up with the throttle: ${speedBefore.toFixed(1)} -> ${throttled.speed_mps.toFixed(1)} m/s`);
  const shownSpeed = Number(await page.$eval("#speed", (e) => e.textContent));
  check(shownSpeed > 15, `the page shows the speed (${shownSpeed} km/h)`);

  // A wiper key: 3 = high.
  await page.keyboard.press("Digit3");
  await waitFor("wipers high in effect", async () => (await json(base + "/api/drive/state.json")).wipers_in_effect === "high", 5000);
  check(await page.$eval('[data-wipers="high"]', (e) => e.classList.contains("on")), "the page shows the wipers on high");

  // The rain slider, moved with the mouse to about 80% of its travel.
  const slider = await page.$("#slider-rain_rate_mm_h");
  const box = await slider.boundingBox();
  await page.mouse.click(box.x + box.width * 0.8, box.y + box.height / 2);
  const rain = Number(await page.$eval("#slider-rain_rate_mm_h", (e) => e.value));
  check(rain > 80 && rain !== 20, `the rain slider moved to ${rain} mm/h`);
  const wanted = rain.toFixed(1) + " mm/h";
  await waitFor(`the HUD showing ${wanted}`, () => page.$eval("#hud-cockpit [data-k=rain]", (e) => e.textContent).then((t) => t === wanted), 8000);
  check(true, `the HUD shows the rain in effect: ${wanted}`);
  check((await json(base + "/api/drive/state.json")).weather_in_effect.rain_rate_mm_h === rain,
        "the server accepted the new rain rate");

  // The frames keep coming and the picture changed (the car moved, the rain, the wipers).
  await waitFor("newer frames", () => page.$eval("#frame-cockpit", (e, before) => Number(e.dataset.frame) > before + 5, frameBefore), 20_000);
  await sleep(1500);  // a second and a half of heavier rain and wipers for the screenshot
  const imageAfter = sha(await cockpit.screenshot());
  check(imageAfter !== imageBefore, "the cockpit image changed");
  await page.screenshot({path: path.join(shots, "02-drive-rain.png")});
  const hud = await page.$eval("#hud-cockpit", (e) => e.innerText);
  check(/render [0-9.]+/.test(hud) && /glass [0-9.]+%/.test(hud), "the HUD shows render time and wet fractions");

  // The control room, in a second tab (leaving the drive page would close its session).
  const room = await browser.newPage();
  room.on("pageerror", (e) => pageErrors.push("control room: " + e.message));
  room.on("response", (r) => { if (r.status() >= 400) pageErrors.push(`control room: HTTP ${r.status()} for ${r.url()}`); });
  await room.goto(base + "/", {waitUntil: "domcontentloaded"});
  await waitFor("the session in the list", () => room.$(`tr[data-session="${sessionId}"]`), 10_000);
  const rowText = await room.$eval(`tr[data-session="${sessionId}"]`, (e) => e.innerText);
  check(rowText.includes("realtime") && rowText.includes("YOURS"), "the control room lists the drive session as realtime and yours");
  await waitFor("the followed session's views", () => room.$eval("#frame-cockpit", (e) => Number(e.dataset.frame || 0) > 0), 20_000);
  const plotsShown = await room.evaluate(() => typeof window.uPlot === "function");
  if (plotsShown) await waitFor("the plots", () => room.$$eval("#plots .uplot", (l) => l.length === 3), 10_000);
  await sleep(2500);  // a few plot points
  await room.screenshot({path: path.join(shots, "03-control-room.png"), fullPage: true});

  // Stop closes the session on the server.
  await page.bringToFront();
  await page.click("#stop");
  await waitFor("the session closed on the server", async () =>
    !(await json(base + "/api/sessions.json")).sessions.some((s) => s.session_id === sessionId), 10_000);
  check(true, "Stop closed the session");
  await page.screenshot({path: path.join(shots, "04-drive-stopped.png")});

  // The server goes away: the control room says so in a banner and keeps retrying.
  await stopChild(server);
  await room.bringToFront();
  await waitFor("the server-down banner", () => room.evaluate(() => !document.getElementById("banner").hidden &&
    document.getElementById("banner").textContent.includes("server is down") &&
    document.getElementById("server").textContent === "server down"), 10_000);
  check(true, "the control room shows that the server is down");
  await room.screenshot({path: path.join(shots, "05-server-down.png")});
  const viewerLog = fs.readFileSync(path.join(work, "viewer.log"), "utf8");
  check(!viewerLog.includes("Traceback"), "the viewer logged no traceback");
  check(pageErrors.length === 0, "no script errors on the pages" + (pageErrors.length ? ": " + pageErrors.join("; ") : ""));
  return 0;
}

const timer = setTimeout(() => {
  console.error(`FAIL: the test ran past ${OVERALL_TIMEOUT_MS / 1000} s`);
  cleanup().finally(() => process.exit(1));
}, OVERALL_TIMEOUT_MS);

let code = 1;
try {
  code = await main();
} catch (e) {
  console.error("FAIL:", e.message);
  console.error("logs in", work);
  code = 1;
}
await cleanup();
clearTimeout(timer);
if (code !== SKIP) {
  log("screenshots in", shots);
  log(code === 0 ? "PASS" : "FAIL");
}
process.exit(code);
