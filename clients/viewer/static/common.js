// Shared by the control room and the drive page: fetch helpers, frame loops, the HUD, plots.
"use strict";

const Downpour = (() => {
  const $ = (id) => document.getElementById(id);

  function el(tag, attrs = {}, children = []) {
    const node = document.createElement(tag);
    for (const [k, v] of Object.entries(attrs)) {
      if (k === "class") node.className = v;
      else if (k === "text") node.textContent = v;
      else if (k.startsWith("on")) node.addEventListener(k.slice(2), v);
      else node.setAttribute(k, v);
    }
    for (const c of [].concat(children)) node.append(c);
    return node;
  }

  // A request that has not answered in this long is given up (and its caller tries again), so that
  // one lost request never stalls what waits on it.
  const REQUEST_TIMEOUT_MS = 4000;

  async function getJSON(path) {
    const response = await fetch(path, {cache: "no-store", signal: AbortSignal.timeout(REQUEST_TIMEOUT_MS)});
    if (!response.ok) throw new Error(path + ": HTTP " + response.status);
    return response.json();
  }

  async function postJSON(path, body, timeoutMs = REQUEST_TIMEOUT_MS) {
    const response = await fetch(path, {
      method: "POST", headers: {"Content-Type": "application/json"},
      body: JSON.stringify(body || {}), keepalive: true, signal: AbortSignal.timeout(timeoutMs),
    });
    const value = await response.json().catch(() => ({}));
    if (!response.ok) throw new Error(value.error || path + ": HTTP " + response.status);
    return value;
  }

  const esc = (s) => String(s).replace(/[&<>"]/g, (c) => ({"&": "&amp;", "<": "&lt;", ">": "&gt;", '"': "&quot;"}[c]));
  const num = (v, digits = 1) => (v === undefined || v === null || !isFinite(v)) ? "–" : Number(v).toFixed(digits);
  const pct = (v) => num(100 * (v || 0), 1) + "%";

  // Shows views' frames in canvases as they come ({view: canvas}). /stream/<view>,<view> sends
  // each new frame of those views as one part of a multipart answer, over one held connection for
  // all of a page's views (a browser holds six to a host; MultipartReader); each is decoded off
  // the page's thread (createImageBitmap) and drawn. A view's frame that comes while its last is
  // still being decoded waits in its place, and a newer one replaces it: a canvas shows the
  // newest, and a slow page never piles frames up. (A request for each frame cost headless
  // Chromium about twice the CPU for two 480x270 views at 20 fps.)
  class FrameLoop {
    constructor(canvases) {
      this.canvases = canvases;
      this.running = true;
      this.abort = new AbortController();
      this.decoding = {}; this.waiting = {};
      this.loop();
    }
    stop() {
      this.running = false;
      this.abort.abort();
    }
    async loop() {
      const views = Object.keys(this.canvases);
      const url = "/stream/" + views.map(encodeURIComponent).join(",");
      while (this.running && views.length) {
        let parts = 0;
        try {
          const response = await fetch(url, {cache: "no-store", signal: this.abort.signal});
          // 204: no frame came in 2 s, or no session is followed.
          if (response.status !== 200 || !response.body) { await sleep(400); continue; }
          const reader = response.body.getReader(), reading = new MultipartReader();
          try {
            for (;;) {
              const {value, done} = await reader.read();
              if (done || !this.running) break;
              for (const part of reading.push(value)) { ++parts; this.show(part.view || views[0], part); }
            }
          } finally {
            reader.cancel().catch(() => {});  // closes the connection (a part it could not read)
          }
        } catch (e) {
          if (this.running) await sleep(500);
        }
        if (parts < 2 && this.running) await sleep(400);  // a stream that ends at once: the viewer closing
      }
    }
    show(view, part) {
      const canvas = this.canvases[view];
      if (!canvas) return;
      if (this.decoding[view]) { this.waiting[view] = part; return; }
      this.decoding[view] = true;
      createImageBitmap(new Blob([part.body], {type: "image/jpeg"})).then((bitmap) => {
        if (this.running) {
          if (canvas.width !== bitmap.width || canvas.height !== bitmap.height) {
            canvas.width = bitmap.width; canvas.height = bitmap.height;
          }
          canvas.getContext("2d").drawImage(bitmap, 0, 0);
          canvas.dataset.frame = part.frame;
        }
        bitmap.close();
      }, () => {}).finally(() => {
        this.decoding[view] = false;
        const next = this.waiting[view];
        this.waiting[view] = null;
        if (next && this.running) this.show(view, next);
      });
    }
  }

  // The parts of the viewer's multipart stream, from its bytes as they arrive in chunks of any
  // size: "--boundary", header lines (Content-Length, X-View and X-Frame-Number), a blank
  // line, the body, CRLF. Throws on a part it cannot read (the loop then opens a new stream).
  class MultipartReader {
    constructor() { this.buffer = new Uint8Array(0); this.text = new TextDecoder(); }
    push(chunk) {
      if (this.buffer.length) {
        const joined = new Uint8Array(this.buffer.length + chunk.length);
        joined.set(this.buffer); joined.set(chunk, this.buffer.length);
        this.buffer = joined;
      } else this.buffer = chunk;
      const parts = [];
      for (;;) {
        const b = this.buffer, end = headerEnd(b);
        if (end < 0) {
          if (b.length > 4096) throw new Error("a part's headers run past 4 KB");
          break;
        }
        const head = this.text.decode(b.subarray(0, end));
        const length = /^content-length:\s*(\d+)\s*$/im.exec(head);
        if (!length) throw new Error("a part without a Content-Length");
        const first = end + 4, last = first + Number(length[1]);
        if (b.length < last + 2) break;  // the body and its CRLF are still coming
        const frame = (/^x-frame-number:\s*(\d+)\s*$/im.exec(head) || [])[1] || "";
        const view = (/^x-view:\s*(\S+)\s*$/im.exec(head) || [])[1] || "";
        parts.push({view, frame, body: b.subarray(first, last)});
        this.buffer = b.subarray(last + 2);
      }
      return parts;
    }
  }

  // Where a part's headers end (the index of their blank line's CRLFCRLF), or -1.
  function headerEnd(b) {
    for (let i = 0, n = Math.min(b.length, 4096) - 3; i < n; ++i) {
      if (b[i] === 13 && b[i + 1] === 10 && b[i + 2] === 13 && b[i + 3] === 10) return i;
    }
    return -1;
  }

  const sleep = (ms) => new Promise((resolve) => setTimeout(resolve, ms));

  function weatherText(w) {
    if (!w || w.rain_rate_mm_h === undefined) return "";
    return `rain <span class="hi" data-k="rain">${num(w.rain_rate_mm_h, 1)} mm/h</span>` +
      ` · wind ${num(w.wind_speed_mps, 1)} m/s → ${num(w.wind_direction_deg, 0)}°` +
      ` · fog ${num(w.fog_density, 2)} · cloud ${num(w.cloudiness, 2)} · sun ${num(w.sun_altitude_deg, 0)}°`;
  }

  const ROAD_STATES = ["dry", "wet", "drench", "puddle"];

  // The HUD over a view, compact: s is a view entry's "stats" from /status.json; extra may carry
  // the weather in effect, the wipers and the car's speed (the viewer's own session).
  function hudHTML(s, fps, extra = {}) {
    if (!s) return '<div class="row">waiting for frames…</div>';
    const r = s.road_states || {};
    const states = ROAD_STATES.filter((k) => r[k] >= 0.005);
    const road = states.length
      ? `<div class="row"><span class="k">road</span><span class="bar">` +
        ROAD_STATES.map((k) => `<i class="c-${k}" style="width:${100 * (r[k] || 0)}%"></i>`).join("") +
        `</span>` + states.map((k) => `<span class="legend"><i class="c-${k}"></i></span>${k} ${num(100 * r[k], 0)}%`).join(" ") + `</div>`
      : "";
    const lat = s.latency_ms > 0 ? ` · lat ${num(s.latency_ms, 0)}` : "";
    const speed = extra.speed_kmh !== undefined ? ` · <span class="hi" data-k="speed">${num(extra.speed_kmh, 0)} km/h</span>` : "";
    const rows = [
      `<div class="row">#${s.frame_number} · t ${num(s.sim_time_s, 1)} s · <span class="hi">${num(fps, 1)} fps</span>${speed}</div>`,
      `<div class="row"><span class="k">ms</span> render ${num(s.render_ms, 0)} · enc ${num(s.encode_ms, 1)}${lat}</div>`,
      `<div class="row"><span class="k">wet</span> glass ${pct(s.glass_wet_fraction)} · view ${pct(s.view_wet_fraction)}</div>`,
      road,
    ];
    if (extra.weather && extra.weather.rain_rate_mm_h !== undefined) {
      rows.push(`<div class="row">rain <span class="hi" data-k="rain">${num(extra.weather.rain_rate_mm_h, 1)} mm/h</span>` +
        (extra.wipers ? ` · wipers ${esc(extra.wipers)}` : "") + `</div>`);
    }
    return rows.join("");
  }

  // The line under a view: what the HUD leaves out.
  function captionHTML(s, extra = {}) {
    if (!s) return "";
    const parts = [`${s.width}×${s.height}`, `vis ${s.visibility_m > 0 ? num(s.visibility_m, 0) + " m" : "–"}`,
                   `${s.drops_on_glass} drops`, `${s.rain_streaks} streaks`];
    if (s.frames_dropped) parts.push(`${s.frames_dropped} dropped here`);
    const place = s.ego_place;
    if (place) parts.push(`${esc(place.road_id)} s ${num(place.s_m, 0)} m lane ${place.lane_id} t ${num(place.t_m, 2)} m` +
                          (place.on_road ? "" : ' <span class="hi">off road</span>'));
    if (extra.weather && extra.weather.wind_speed_mps !== undefined) {
      const w = extra.weather;
      parts.push(`wind ${num(w.wind_speed_mps, 1)} m/s → ${num(w.wind_direction_deg, 0)}° · fog ${num(w.fog_density, 2)} · ` +
                 `cloud ${num(w.cloudiness, 2)} · sun ${num(w.sun_altitude_deg, 0)}°`);
    }
    return parts.join(" · ");
  }

  // Three uPlot charts (fps, ms, wet fractions) fed from /api/history.json.
  class Plots {
    constructor(container, note) {
      this.container = container; this.note = note; this.charts = null; this.key = "";
      this.available = typeof window.uPlot === "function";
      if (!this.available && note) {
        note.hidden = false;
        note.textContent = "Plots unavailable: uPlot is not installed (run npm ci --prefix clients/viewer).";
      }
    }
    make(views) {
      this.container.innerHTML = "";
      const width = Math.max(220, Math.floor((this.container.clientWidth - 24) / 3) - 14);
      const colors = ["#4aa3ff", "#ffb347", "#3fb950", "#f85149", "#b56cff", "#e3e3e3"];
      const clock = (u, ticks) => ticks.map((t) => new Date(t * 1000).toTimeString().slice(0, 8));
      const plain = (u, ticks) => ticks.map((t) => String(Math.round(t * 10) / 10));
      const axes = [{stroke: "#8b96a3", grid: {stroke: "#252c35"}, ticks: {stroke: "#252c35"}, values: clock, space: 70},
                    {stroke: "#8b96a3", grid: {stroke: "#252c35"}, ticks: {stroke: "#252c35"}, size: 46, values: plain}];
      const chart = (title, series, range) => {
        const box = el("div", {class: "plot"}, [el("div", {class: "title", text: title})]);
        this.container.append(box);
        return new uPlot({
          width, height: 160, legend: {show: true, live: false}, cursor: {show: false},
          scales: {x: {time: true, range: (u, min, max) => [max - 60, max]}, y: range ? {range} : {auto: true}},
          axes, series: [{}].concat(series.map((s, i) => Object.assign({stroke: colors[i % colors.length], width: 1.5, points: {show: false}}, s))),
        }, [[], ...series.map(() => [])], box);
      };
      const v0 = views[0] || "";
      this.charts = {
        fps: chart("frames per second", [{label: "target"}, {label: "session"}, ...views.map((v) => ({label: v + " here"}))],
                   (u, min, max) => [0, Math.max(5, max * 1.15)]),
        ms: chart("milliseconds (" + v0 + ")", [{label: "latency"}, {label: "render"}, {label: "encode"}],
                  (u, min, max) => [0, Math.max(10, max * 1.15)]),
        wet: chart("wet fractions, % (" + v0 + ")", [{label: "glass"}, {label: "view"}, {label: "road"}], [0, 100]),
      };
      this.charts.fps.series[1].dash = [4, 4];
    }
    update(history, targetFps) {
      if (!this.available) return;
      const views = Object.keys(history.views || {}).sort((a, b) => order(a) - order(b));
      const key = history.generation + ":" + views.join(",");
      if (!views.length) {  // nothing followed: no empty charts
        if (this.charts) { this.container.innerHTML = ""; this.charts = null; }
        this.key = key;
        return;
      }
      if (key !== this.key || !this.charts) { this.key = key; this.make(views); }
      const first = history.views[views[0]];
      const t = first.t;
      const align = (h, name) => t.map((x) => nearest(h, x, name));
      this.charts.fps.setData([t, t.map(() => targetFps || null), first.session_fps.map((v) => v || null),
                               ...views.map((v) => align(history.views[v], "fps"))]);
      this.charts.ms.setData([t, first.latency_ms.map((v) => v || null), first.render_ms, first.encode_ms]);
      this.charts.wet.setData([t, first.glass_wet.map((v) => 100 * v), first.view_wet.map((v) => 100 * v),
                               first.road_wet.map((v) => 100 * v)]);
    }
  }

  function nearest(h, x, name) {
    if (!h || !h.t.length) return null;
    let lo = 0, hi = h.t.length - 1;
    while (lo < hi) { const mid = (lo + hi) >> 1; if (h.t[mid] < x) lo = mid + 1; else hi = mid; }
    return Math.abs(h.t[lo] - x) < 1 ? h[name][lo] : null;
  }

  const VIEW_ORDER = ["cockpit", "road", "windshield", "rain"];
  const order = (v) => { const i = VIEW_ORDER.indexOf(v); return i < 0 ? 99 : i; };

  function serverPill(pill, server) {
    if (!server || server.state !== "up") {
      pill.className = "pill down";
      pill.textContent = server && server.state === "connecting" ? "connecting…" : "server down";
    } else {
      pill.className = "pill up";
      pill.textContent = "server up" + (server.renderer ? " · " + server.renderer.split(" (")[0] : "");
    }
  }

  return {$, el, getJSON, postJSON, esc, num, pct, FrameLoop, MultipartReader, hudHTML, captionHTML, Plots, order, sleep, serverPill, weatherText};
})();
