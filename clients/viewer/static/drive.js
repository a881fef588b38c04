// Drive it yourself: the viewer owns a realtime session and moves the car from these keys.
"use strict";
(() => {
  const D = Downpour, $ = D.$;
  const SLIDERS = [
    {name: "rain_rate_mm_h", label: "Rain", unit: "mm/h", min: 0, max: 150, step: 1, digits: 0},
    {name: "wind_speed_mps", label: "Wind", unit: "m/s", min: 0, max: 30, step: 0.5, digits: 1},
    {name: "wind_direction_deg", label: "Wind towards", unit: "°", min: -180, max: 180, step: 5, digits: 0},
    {name: "fog_density", label: "Fog", unit: "", min: 0, max: 1, step: 0.01, digits: 2},
    {name: "cloudiness", label: "Cloudiness", unit: "", min: 0, max: 1, step: 0.01, digits: 2},
    {name: "sun_altitude_deg", label: "Sun altitude", unit: "°", min: -20, max: 90, step: 1, digits: 0},
  ];
  const KEYS = {KeyW: "throttle", ArrowUp: "throttle", KeyS: "brake", ArrowDown: "brake",
                KeyA: "left", ArrowLeft: "left", KeyD: "right", ArrowRight: "right"};
  const WIPER_KEYS = {Digit0: "off", Digit1: "intermittent", Digit2: "low", Digit3: "high", Digit4: "single",
                      Numpad0: "off", Numpad1: "intermittent", Numpad2: "low", Numpad3: "high", Numpad4: "single"};
  const keys = {throttle: false, brake: false, left: false, right: false};
  let targetFps = 20, sessionId = "", state = "idle", frameLoop = null, pendingWeather = null, pendingWipers = null;
  // Drives begun on this page: a status asked for before the latest one was driving tells nothing
  // of it (on a loaded machine, a status asked for while the session was being made came back
  // after the start's answer, said "no session", and stopped the page's controls: the viewer then
  // closed the drive for want of them).
  let drives = 0;
  const plots = new D.Plots($("plots"), $("plots-note"));

  function banner(text, info) {
    const b = $("banner");
    b.hidden = !text; b.textContent = text || ""; b.className = "banner" + (info ? " info" : "");
  }

  // Sliders
  const inputs = {};
  for (const s of SLIDERS) {
    const input = D.el("input", {type: "range", min: s.min, max: s.max, step: s.step, id: "slider-" + s.name});
    const out = D.el("output", {id: "out-" + s.name});
    input.addEventListener("input", () => {
      out.textContent = D.num(input.value, s.digits) + (s.unit ? " " + s.unit : "");
      pendingWeather = Object.assign(pendingWeather || {}, {[s.name]: Number(input.value)});
      send();
    });
    inputs[s.name] = {input, out, spec: s};
    $("sliders").append(D.el("label", {class: "slider"}, [D.el("span", {text: s.label}), input, out]));
  }
  function setSliders(weather) {
    for (const {input, out, spec} of Object.values(inputs)) {
      if (weather[spec.name] === undefined) continue;
      input.value = weather[spec.name];
      out.textContent = D.num(weather[spec.name], spec.digits) + (spec.unit ? " " + spec.unit : "");
    }
  }

  // Keys
  function keyEvent(e, down) {
    if (e.target && e.target.tagName === "INPUT" && e.target.type !== "range") return;
    const k = KEYS[e.code];
    if (k) {
      e.preventDefault();
      if (keys[k] !== down) { keys[k] = down; send(); }
    } else if (down && e.code === "KeyH") {
      document.body.classList.toggle("hudoff");
    } else if (down && WIPER_KEYS[e.code]) {
      e.preventDefault();
      setWipers(WIPER_KEYS[e.code]);
    }
  }
  document.addEventListener("keydown", (e) => keyEvent(e, true));
  document.addEventListener("keyup", (e) => keyEvent(e, false));
  window.addEventListener("blur", () => { for (const k in keys) keys[k] = false; send(); });
  for (const b of document.querySelectorAll("[data-wipers]")) b.addEventListener("click", () => setWipers(b.dataset.wipers));
  function setWipers(mode) { pendingWipers = mode; send(); }

  // Controls go to the viewer on every change and five times a second (the viewer releases the
  // keys when it has not heard from the page for a second, and closes the session after 15 s).
  let sending = false, again = false;
  async function send() {
    if (state !== "driving") return;
    if (sending) { again = true; return; }
    sending = true;
    const body = Object.assign({}, keys);
    if (pendingWeather) { body.weather = pendingWeather; pendingWeather = null; }
    if (pendingWipers) { body.wipers = pendingWipers; pendingWipers = null; }
    try { showDrive(await D.postJSON("/api/drive/controls", body)); }
    catch (e) {
      if (body.weather) pendingWeather = Object.assign(body.weather, pendingWeather || {});
      if (body.wipers && !pendingWipers) pendingWipers = body.wipers;
    }
    sending = false;
    if (again) { again = false; send(); }
  }
  setInterval(send, 200);

  function showDrive(d) {
    if (!d) return;
    $("speed").textContent = D.num(d.speed_kmh, 0);
    for (const k in keys) $("key-" + k).classList.toggle("down", !!(d.keys && d.keys[k]) || keys[k]);
    $("track-s").textContent = D.num(d.s_m, 1) + " m";
    $("track-lateral").textContent = D.num(d.lateral_m, 2) + " m";
    $("odometer").textContent = D.num(d.odometer_m / 1000, 2) + " km";
    for (const b of document.querySelectorAll("[data-wipers]")) b.classList.toggle("on", b.dataset.wipers === d.wipers);
    const w = d.weather_in_effect || {};
    $("weather-effect").innerHTML = w.rain_rate_mm_h === undefined ? "in effect: –" : "in effect: " + D.weatherText(w);
  }

  async function start() {
    state = "starting";
    $("start").hidden = true; $("stop").hidden = false;
    banner("Creating a realtime session…", true);
    try {
      // (A session may take a while to create on a loaded server.)
      const d = await D.postJSON("/api/drive/start", {width: 480, height: 270, fps: 20}, 30000);
      if (d.state !== "driving") throw new Error(d.error || "the session was not created");
      sessionId = d.session_id; state = "driving"; ++drives;
      setSliders(d.weather);
      showDrive(d);
      banner("");
      if (frameLoop) frameLoop.stop();
      frameLoop = new D.FrameLoop({cockpit: $("frame-cockpit"), road: $("frame-road")});
    } catch (e) {
      state = "idle";
      banner("Could not start a drive: " + e.message + " — retrying in 2 s.");
      setTimeout(() => { if (state === "idle") start(); }, 2000);
    }
  }

  async function stop() {
    state = "stopped";
    if (frameLoop) frameLoop.stop();
    frameLoop = null;
    try { await D.postJSON("/api/drive/stop", {reason: "stopped on the page"}); } catch (e) { /* shown below */ }
    $("start").hidden = false; $("stop").hidden = true;
    banner("Session closed. Start a new drive to go on.", true);
  }
  $("stop").addEventListener("click", stop);
  $("start").addEventListener("click", start);
  window.addEventListener("pagehide", () => {
    if (state === "driving") navigator.sendBeacon("/api/drive/stop", JSON.stringify({reason: "the page was closed"}));
  });

  async function poll() {
    try {
      const asked = drives;
      const s = await D.getJSON("/status.json");
      D.serverPill($("server"), s.server);
      const d = s.drive || {};
      if (state === "driving" && asked === drives) {
        if (d.state === "ended" || (d.session_id && d.session_id !== sessionId) || !d.session_id) {
          state = "stopped";
          $("start").hidden = false; $("stop").hidden = true;
          banner("The session ended (" + (d.error || "closed") + "). Start a new drive to go on.");
        } else if (s.server.state === "down") {
          banner("The Downpour server is down (" + s.server.error + ") — retrying every second.");
        } else if (d.error) {
          banner("Updates failing: " + d.error);
        } else banner("");
        if (s.session_id !== sessionId && s.selected !== sessionId && sessionId) {
          D.postJSON("/api/follow", {session_id: sessionId}).catch(() => {});
        }
        showDrive(d);
      }
      const info = s.sessions.find((x) => x.session_id === sessionId);
      if (info) targetFps = info.fps;
      $("session").textContent = sessionId && state === "driving"
        ? `${sessionId} · ${info ? D.num(info.achieved_fps, 1) : "–"} / ${info ? D.num(info.fps, 0) : "–"} fps` : "no session";
      $("session").className = "pill" + (state === "driving" ? " up" : "");
      document.body.classList.toggle("stopped", state === "stopped");
      $("late").innerHTML = info && info.late && state === "driving" ? '<span class="badge late">LATE</span>' : "";
      const mine = s.session_id === sessionId && state === "driving";
      for (const name of ["cockpit", "road"]) {
        const v = mine ? s.views.find((x) => x.view === name) : null;
        const extra = v ? {weather: d.weather_in_effect, wipers: d.wipers_in_effect, speed_kmh: d.speed_kmh} : {};
        $("hud-" + name).innerHTML = state === "stopped" ? '<div class="row">session closed</div>'
          : D.hudHTML(v && v.stats, v && v.fps, extra);
        $("cap-" + name).innerHTML = D.captionHTML(v && v.stats, extra);
        $("cap-" + name).title = $("cap-" + name).textContent;
      }
    } catch (e) {
      banner("The viewer is not reachable (" + e.message + ") — retrying.");
    }
    setTimeout(poll, 250);
  }

  async function pollHistory() {
    try {
      const h = await D.getJSON("/api/history.json");
      if (h.session_id === sessionId && state === "driving") plots.update(h, targetFps);
    } catch (e) { /* the banner says so */ }
    setTimeout(pollHistory, 1000);
  }

  start();
  poll();
  pollHistory();
})();
