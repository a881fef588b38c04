// The control room: the session list, the followed session's views with their HUDs, plots.
"use strict";
(() => {
  const D = Downpour, $ = D.$;
  const hiddenViews = new Set();
  let shownKey = "", frameLoop = null, sessionsKey = "", status = null;
  const plots = new D.Plots($("plots"), $("plots-note"));

  function banner(text, info) {
    const b = $("banner");
    b.hidden = !text;
    b.textContent = text || "";
    b.className = "banner" + (info ? " info" : "");
  }

  function renderSessions(s) {
    const key = JSON.stringify([s.sessions, s.session_id, s.selected, s.drive && s.drive.session_id, s.server.state]);
    if (key === sessionsKey) return;
    sessionsKey = key;
    const body = $("sessions");
    body.innerHTML = "";
    $("no-sessions").hidden = s.sessions.length > 0;
    $("no-sessions").textContent = s.server.state === "up" ? "No sessions on the server." : "The server does not answer.";
    for (const x of s.sessions) {
      const mine = s.drive && x.session_id === s.drive.session_id;
      const fps = x.mode === "realtime"
        ? `${D.num(x.achieved_fps, 1)} / ${D.num(x.fps, 0)} ` + (x.late ? '<span class="badge late">LATE</span>' : "")
        : `${D.num(x.achieved_fps, 1)} <span class="sub">(${D.num(x.fps, 0)})</span>`;
      const row = D.el("tr", {class: "session" + (x.session_id === s.session_id ? " followed" : ""),
                              "data-session": x.session_id, title: "follow this session"});
      const shortId = x.session_id.length > 18 ? x.session_id.slice(0, 16) + "…" : x.session_id;
      row.innerHTML =
        `<td><div class="id" title="${D.esc(x.session_id)}">${D.esc(shortId)}${mine ? ' <span class="badge mine">YOURS</span>' : ""}</div>` +
        `<div class="sub">${D.esc(x.owner || "–")} · ${D.esc(x.road_network || "?")}${x.roads > 1 ? " (" + x.roads + " roads)" : ""}</div>` +
        `<div class="sub">${x.views.map((v) => `${v.view} ${v.width}×${v.height}`).join(" · ")}</div></td>` +
        `<td>${x.mode}<div class="sub">${D.num(x.sim_time_s, 0)} s</div></td>` +
        `<td class="fps">${fps}</td><td>${x.frames_late}</td>`;
      row.addEventListener("click", () => follow(x.session_id));
      body.append(row);
    }
    $("auto").hidden = !s.selected;
  }

  async function follow(id) {
    try { await D.postJSON("/api/follow", {session_id: id}); } catch (e) { banner("Could not follow: " + e.message); }
    sessionsKey = "";
  }
  $("auto").addEventListener("click", () => follow(""));

  function renderViews(s) {
    const names = s.views.map((v) => v.view);
    const key = s.generation + ":" + names.join(",") + ":" + [...hiddenViews].join(",");
    if (key !== shownKey) {
      shownKey = key;
      if (frameLoop) frameLoop.stop();
      const canvases = {};
      const box = $("views");
      box.innerHTML = "";
      const pick = $("viewpick");
      pick.innerHTML = "";
      const hudBox = D.el("input", {type: "checkbox", id: "hud-toggle"});
      hudBox.checked = !document.body.classList.contains("hudoff");
      hudBox.addEventListener("change", () => document.body.classList.toggle("hudoff", !hudBox.checked));
      if (names.length) pick.append(D.el("label", {title: "show the stats over the images"}, [hudBox, " HUD"]));
      for (const name of names) {
        const box2 = D.el("input", {type: "checkbox", "data-view": name});
        box2.checked = !hiddenViews.has(name);
        box2.addEventListener("change", () => {
          if (box2.checked) hiddenViews.delete(name); else hiddenViews.add(name);
        });
        pick.append(D.el("label", {}, [box2, " " + name]));
        if (hiddenViews.has(name)) continue;
        const canvas = D.el("canvas", {role: "img", "aria-label": name + " view", id: "frame-" + name});
        box.append(D.el("figure", {class: "view", id: "view-" + name}, [
          canvas, D.el("div", {class: "hud", id: "hud-" + name}), D.el("span", {class: "name", text: name.toUpperCase()}),
          D.el("figcaption", {id: "cap-" + name})]));
        canvases[name] = canvas;
      }
      frameLoop = new D.FrameLoop(canvases);
      if (!names.length) box.append(D.el("div", {class: "empty", text: s.state === "watching" ? "waiting for the first frames…" : "Pick a session on the left, or drive it yourself."}));
    }
    const mine = s.drive && s.drive.session_id === s.session_id && s.session_id;
    for (const v of s.views) {
      const hud = $("hud-" + v.view);
      const extra = mine ? {weather: s.drive.weather_in_effect, wipers: s.drive.wipers_in_effect, speed_kmh: s.drive.speed_kmh} : {};
      if (hud) hud.innerHTML = D.hudHTML(v.stats, v.fps, extra);
      const cap = $("cap-" + v.view);
      if (cap) { cap.innerHTML = D.captionHTML(v.stats, extra); cap.title = cap.textContent; }
    }
  }

  function render(s) {
    status = s;
    const down = s.server.state === "down" || /^server /.test(s.error || "");
    if (down) s.server = {state: "down", error: s.server.error || s.error};
    D.serverPill($("server"), s.server);
    if (down) banner("The Downpour server is down (" + (s.server.error || "no answer") + ") — retrying every second.");
    else if (s.state !== "watching" && s.error) banner(s.error.charAt(0).toUpperCase() + s.error.slice(1) + " — waiting for a session.", true);
    else if (s.state !== "watching" && s.server.state === "up" && !s.sessions.length) banner("No sessions on the server yet — waiting (start one, or drive it yourself).", true);
    else banner("");
    renderSessions(s);
    const info = s.sessions.find((x) => x.session_id === s.session_id);
    $("followed").innerHTML = s.session_id ? '<span class="id">' + D.esc(s.session_id) + "</span>" +
      (info ? ` · ${info.mode} · ${D.num(info.achieved_fps, 1)} of ${D.num(info.fps, 0)} fps` : "") : "no session followed";
    $("late").innerHTML = info && info.late ? '<span class="badge late" id="late-badge">LATE</span>' : (info && info.mode === "realtime" && info.frames_rendered > 2 * info.fps ? '<span class="badge ok">ON TIME</span>' : "");
    renderViews(s);
  }

  async function poll() {
    try { render(await D.getJSON("/status.json")); }
    catch (e) { banner("The viewer is not reachable (" + e.message + ") — retrying."); D.serverPill($("server"), null); }
    setTimeout(poll, 250);
  }

  async function pollHistory() {
    try {
      const h = await D.getJSON("/api/history.json");
      const info = status && status.sessions.find((x) => x.session_id === h.session_id);
      plots.update(h, info ? info.fps : 0);
    } catch (e) { /* the banner says so */ }
    setTimeout(pollHistory, 1000);
  }

  poll();
  pollHistory();
})();
