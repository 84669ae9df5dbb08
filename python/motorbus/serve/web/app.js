// motorbus live web view: one page showing a served bench (docs/web.md: what it shows, its API).
// Plain ES2020, no framework, no network beyond this service: it must work offline in a lab.
// Data: the websocket's "hello" (layout + the last 60 s), then "update"s at up to 20 Hz.
// STOP buttons are plain fetch POSTs so they work whatever the websocket is doing.
"use strict";

const RETRY_MS = 2000;     // contract: retry /ws every 2 s
const FRAME_MS = 100;      // plots redraw at most ~10 fps, however fast updates come
const POST_TIMEOUT_MS = 5000;
const MAX_MESSAGES = 4;
// No red in the palette: red means STOP and FAULT on this page.
const PALETTE = ["#1f77b4", "#ff7f0e", "#2ca02c", "#9467bd", "#8c564b", "#e377c2", "#17becf", "#bcbd22", "#7f7f7f"];

const $ = (sel) => document.querySelector(sel);
// el("input", {className: "target", type: "number"}, ...children): DOM properties, never innerHTML.
const el = (tag, props = {}, ...kids) => { const e = Object.assign(document.createElement(tag), props); e.append(...kids); return e; };
const colourOf = (i) => PALETTE[i % PALETTE.length];

let bench = null;          // the hello (or /api/bench) the DOM was built from
let helloSeen = false;     // once a hello arrived, a late /api/bench reply must not rebuild over it
const rows = new Map();    // axis name -> {tr, cells, units, queue}
let hist = { t: [], axes: {}, buses: {} };  // parallel arrays: hist.axes[name][k] belongs to hist.t[k]
const current = { axes: {}, buses: {} };    // last known value of each series, carried into every sample
let lastT = null, lastRecv = 0, frozenNow = null;
let connection = "connecting", socket = null;
let counterKeys = "", counterCells = [];
let dirty = true, lastDraw = -Infinity;
let jogReleases = [];      // one per jog button: the window losing focus ends every jog

// ---- cheap DOM writes: at 20 Hz most values do not change, so skip the write (and the relayout) --------
function setText(node, text) {
  if (node._text !== text) { node.textContent = text; node._text = text; }
}
function setClass(node, cls, on) {
  if (node.classList.contains(cls) !== on) node.classList.toggle(cls, on);
}
const clock = (d = new Date()) => d.toTimeString().slice(0, 8);
const num = (v, digits = 3) => (typeof v === "number" && isFinite(v) ? v.toFixed(digits) : "—");
const withUnits = (v, units) => (v == null ? "—" : `${num(v)} ${units}`);

// ---- messages: results of POSTs (never alert(): it would block the page, and the STOP buttons with it) --
function say(text, isError = false) {
  const box = $("#messages");
  const line = el("div", { textContent: text, className: isError ? "error" : "" });
  line.dataset.time = clock();
  box.prepend(line);
  while (box.children.length > MAX_MESSAGES) box.lastElementChild.remove();
}

async function post(path, body, label, describe = () => "") {
  const abort = new AbortController();
  const timer = setTimeout(() => abort.abort(), POST_TIMEOUT_MS);
  try {
    const r = await fetch(path, {
      method: "POST", headers: { "Content-Type": "application/json" },
      body: JSON.stringify(body || {}), cache: "no-store", signal: abort.signal,
    });
    let reply = null;
    try { reply = await r.json(); } catch (_) { /* not JSON: reported by status below */ }
    if (r.ok && reply && reply.ok) { say(`${label}: ok${describe(reply)}`); return reply; }
    say(`${label} failed: ${(reply && reply.error) || `HTTP ${r.status} ${r.statusText}`}`, true);
  } catch (e) {
    const why = e.name === "AbortError" ? `no reply within ${POST_TIMEOUT_MS / 1000} s` : `service unreachable (${e.message})`;
    say(`${label} failed: ${why}`, true);
  } finally {
    clearTimeout(timer);
  }
  return null;
}

const axisUrl = (name, verb) => `api/axes/${encodeURIComponent(name)}/${verb}`;

// Motion commands of one axis go out one after the other: a quick jog press/release could otherwise travel
// on two connections and arrive as "jog 0" then "jog 2", leaving the axis running. STOP bypasses this queue
// and bumps the axis' epoch, so a command still waiting in the queue is dropped instead of sent after it.
function motion(r, verb, body, label) {
  const epoch = r.epoch;
  r.queue = r.queue.then(() => (epoch === r.epoch ? post(axisUrl(r.name, verb), body, label)
    : say(`${label}: not sent, a STOP came first`, true)));
  return r.queue;
}
function stopAxes(names) {
  for (const n of names) { const r = rows.get(n); if (r) r.epoch++; }
}

function button(className, textContent, title, onClick) {
  const b = el("button", { type: "button", className, textContent, title });
  if (onClick) b.addEventListener("click", onClick);
  return b;
}

// ---- building the page from a hello / bench description ---------------------------------------------
function build(b) {
  bench = b;
  setText($("#bench"), b.bench || "motorbus");
  document.title = `${b.bench || "bench"} · motorbus`;
  const buses = (b.buses || []).map((u) =>
    `${u.name} ${u.bitrate ? `${u.bitrate / 1000} kbit/s` : "?"}${u.bitrate_assumed ? " (assumed)" : ""}`);
  setText($("#about"), [
    b.pid != null ? `pid ${b.pid}` : null,
    b.sim ? "simulated drives" : "real drives",
    b.allow_motion ? "motion allowed" : "view only (motion needs --allow-motion)",
    buses.length ? `buses: ${buses.join(", ")}` : "no CAN bus",
  ].filter(Boolean).join(" · "));
  document.body.classList.toggle("motion", !!b.allow_motion);

  $("#axes-head").replaceChildren(...["Axis", "Kind", "Identity", "Position", "Velocity", "State", "Fault",
    "Last move", b.allow_motion ? "Control" : "Stop"].map((h) => el("th", { textContent: h })));
  const body = $("#axes tbody");
  body.replaceChildren();
  rows.clear();
  jogReleases = [];
  (b.axes || []).forEach((ax, i) => body.append(makeRow(ax, i, !!b.allow_motion)));

  // One lane per axis in the position plot (see drawPositions); its height follows the axis count.
  const n = Math.max(1, (b.axes || []).length);
  $("#plot").style.height = `${n * (n > 6 ? 52 : 72) + 22}px`;  // many axes: thinner lanes, page stays short
  dirty = true;
}

function makeRow(ax, i, allowMotion) {
  const tr = el("tr");
  tr.dataset.axis = ax.name;
  tr.style.setProperty("--colour", colourOf(i));  // the name cell's edge matches the plot colour
  const cells = {};
  for (const c of ["name", "kind", "identity", "position", "velocity", "state", "fault", "outcome"])
    cells[c] = tr.appendChild(el("td", { className: c }));
  setText(cells.name, ax.name);
  setText(cells.kind, ax.kind || "");
  setText(cells.identity, ax.identity || "");
  if (ax.where) cells.identity.title = ax.where;
  // .state holds the state words plus, when the axis could not be read, the reason (shown in red).
  const words = el("span"), err = el("span", { className: "error" });
  cells.state.append(words, err);
  const r = { name: ax.name, tr, cells, words, err, units: ax.units || "", queue: Promise.resolve(), epoch: 0 };
  rows.set(ax.name, r);

  const ctl = el("div");  // the flex box is a <div>: a <td> itself must stay a table cell
  tr.append(el("td", { className: "controls" }, ctl));
  ctl.append(button("stop", "STOP", `Stop ${ax.name} (POST ${axisUrl(ax.name, "stop")})`,
    () => { post(axisUrl(ax.name, "stop"), {}, `STOP ${ax.name}`); stopAxes([ax.name]); }));
  if (allowMotion) addMotionControls(ctl, r);
  return tr;
}

function addMotionControls(ctl, r) {
  const target = el("input", { className: "target", type: "number", step: "any", placeholder: `target ${r.units}` });
  const move = () => {
    const v = target.valueAsNumber;
    if (!isFinite(v)) { say(`MOVE ${r.name}: the target is not a number`, true); return; }
    motion(r, "move", { target: v }, `MOVE ${r.name} to ${num(v)} ${r.units}`);
  };
  target.addEventListener("keydown", (e) => { if (e.key === "Enter") move(); });

  // A "small velocity" needs a scale; we only know the units, so start from one per unit and let them edit it.
  const speed = el("input", { className: "jog-speed", type: "number", min: "0", step: "any",
    value: /deg/.test(r.units) ? "5" : "1", title: `jog speed, ${r.units}/s` });
  const line1 = el("div", {}, target, button("move", "move", "absolute move to the target", move),
    jogButton(r, -1, speed), speed, jogButton(r, +1, speed));
  const line2 = el("div", {},
    button("home", "home", "home", () => motion(r, "home", {}, `HOME ${r.name}`)),
    button("enable", "enable", "enable", () => motion(r, "enable", {}, `ENABLE ${r.name}`)),
    button("disable", "disable", "disable", () => motion(r, "disable", {}, `DISABLE ${r.name}`)),
    button("clear", "clear", "clear the fault", () => motion(r, "clear", {}, `CLEAR ${r.name}`)));
  ctl.append(el("div", { className: "motion" }, line1, line2));
}

// Hold to jog: press sends the velocity, release (anywhere: pointer capture) or losing the window sends 0.
function jogButton(r, sign, speed) {
  const b = button(sign < 0 ? "jog-neg" : "jog-pos", sign < 0 ? "◀" : "▶", `hold to jog ${sign < 0 ? "−" : "+"}`);
  let jogging = false;
  const release = () => {
    if (!jogging) return;
    jogging = false;
    motion(r, "jog", { velocity: 0 }, `JOG ${r.name} 0`);
  };
  b.addEventListener("pointerdown", (e) => {
    if (e.button !== 0) return;
    const v = speed.valueAsNumber;
    if (!(v > 0)) { say(`JOG ${r.name}: the jog speed must be a number > 0`, true); return; }
    b.setPointerCapture(e.pointerId);
    jogging = true;
    motion(r, "jog", { velocity: sign * v }, `JOG ${r.name} ${sign * v} ${r.units}/s`);
  });
  for (const ev of ["pointerup", "pointercancel", "lostpointercapture"]) b.addEventListener(ev, release);
  jogReleases.push(release);
  return b;
}

// ---- live data -----------------------------------------------------------------------------------
function stateWords(a) {
  const w = [a.enabled ? "enabled" : "disabled"];
  if (a.moving) w.push("moving");
  if (a.at_target) w.push("at target");
  if (a.limit_positive) w.push("+limit");
  if (a.limit_negative) w.push("-limit");
  if (a.homed) w.push("homed");
  return w.join(", ");
}

function outcomeText(m, units) {
  if (!m) return "";
  if (m.state === "done") return `done at ${withUnits(m.position ?? m.target, units)}`;
  if (m.state === "running" && !m.reason)
    return `running: ${m.what || "move"}${m.target != null ? ` to ${withUnits(m.target, units)}` : ""}`;
  return `${m.state}: ${m.reason || "(no reason given)"}`;
}

function showAxis(name, a) {
  const r = rows.get(name);
  if (!r) return;
  setText(r.cells.position, withUnits(a.position, r.units));
  setText(r.cells.velocity, withUnits(a.velocity, `${r.units}/s`));
  setText(r.words, stateWords(a));
  setText(r.err, a.error ? ` ${a.error}` : "");
  setClass(r.tr, "unreadable", !!a.error);
  setText(r.cells.fault, a.fault ? `FAULT: ${a.text || "(no text from the drive)"}` : "");
  setClass(r.tr, "faulted", !!a.fault);
  const m = a.last_move;
  setText(r.cells.outcome, outcomeText(m, r.units));
  setClass(r.cells.outcome, "failed", !!m && m.state !== "running" && !m.ok);
}

function flatten(obj, prefix, out) {
  for (const [k, v] of Object.entries(obj)) {
    const key = prefix ? `${prefix}.${k}` : k;
    if (v && typeof v === "object" && !Array.isArray(v)) flatten(v, key, out);
    else out.push([key, v]);
  }
  return out;
}

function counterText(key, v) {
  if (v == null) return "—";
  if (typeof v === "number") return key.endsWith("_s") ? `${v.toFixed(1)} s` : Number.isInteger(v) ? String(v) : v.toFixed(2);
  if (typeof v === "boolean") return v ? "yes" : "no";
  return Array.isArray(v) ? v.join(", ") : String(v);
}

function showCounters(c) {
  const items = flatten(c, "", []);
  const keys = items.map(([k]) => k).join("\n");
  if (keys !== counterKeys) {  // the set of counters rarely changes: rebuild the <dl> only then
    counterKeys = keys;
    const dl = $("#counters");
    dl.replaceChildren();
    counterCells = items.map(([k]) => {
      const dd = el("dd");
      dl.append(el("dt", { textContent: k }), dd);
      return dd;
    });
  }
  items.forEach(([k, v], i) => setText(counterCells[i], counterText(k, v)));
}

function onHello(m) {
  helloSeen = true;
  build(m);
  const h = m.history || {};
  hist = { t: (h.t || []).slice(), axes: {}, buses: {} };
  current.axes = {};
  current.buses = {};
  const adopt = (names, src, dst, cur) => {
    for (const n of names) {
      const v = (src && src[n]) || [];
      dst[n] = hist.t.map((_, k) => (v[k] ?? null));
      cur[n] = dst[n].length ? dst[n][dst[n].length - 1] : null;
    }
  };
  adopt((m.axes || []).map((a) => a.name), h.axes, hist.axes, current.axes);
  adopt((m.buses || []).map((b) => b.name), h.buses, hist.buses, current.buses);
  lastT = hist.t.length ? hist.t[hist.t.length - 1] : null;
  lastRecv = performance.now();
  frozenNow = null;
  setConnection("live", "live");
}

function onUpdate(u) {
  for (const [name, a] of Object.entries(u.axes || {})) {
    showAxis(name, a);
    if (name in current.axes) current.axes[name] = a.position ?? null;
  }
  for (const [name, b] of Object.entries(u.buses || {})) {
    if (name in current.buses) current.buses[name] = b.load ?? null;
  }
  if (u.counters) showCounters(u.counters);
  if (typeof u.t !== "number") return;
  // An update may carry only the axes that changed: every series gets its last known value at this t.
  hist.t.push(u.t);
  for (const n in hist.axes) hist.axes[n].push(current.axes[n]);
  for (const n in hist.buses) hist.buses[n].push(current.buses[n]);
  lastT = u.t;
  lastRecv = performance.now();
  trim();
  dirty = true;
}

// Keep the plot window (plus a second, so lines enter from the left edge); cut in batches, not per sample.
function trim() {
  const keepFrom = lastT - (bench.history_s || 60) - 1;
  let i = 0;
  while (i < hist.t.length && hist.t[i] < keepFrom) i++;
  if (i < 20) return;
  hist.t.splice(0, i);
  for (const n in hist.axes) hist.axes[n].splice(0, i);
  for (const n in hist.buses) hist.buses[n].splice(0, i);
}

// The service sends updates only when something changed, so "now" on its clock is estimated from the last
// update plus local elapsed time; the plots keep scrolling while a bench sits still. Frozen once gone.
function serviceNow() {
  if (frozenNow != null) return frozenNow;
  if (lastT == null) return 0;
  return lastT + (performance.now() - lastRecv) / 1000;
}

// ---- connection -------------------------------------------------------------------------------------
function setConnection(state, text) {
  connection = state;
  document.body.dataset.connection = state;
  setText($("#connection"), text);
}

function connect() {
  const url = new URL("ws", location.href);
  url.protocol = location.protocol === "https:" ? "wss:" : "ws:";
  let ws;
  try { ws = new WebSocket(url); } catch (_) { lost(); return; }
  socket = ws;
  ws.onmessage = (ev) => {
    let m;
    try { m = JSON.parse(ev.data); } catch (_) { return; }
    if (m.type === "hello") onHello(m);
    else if (m.type === "update" && helloSeen) onUpdate(m);
  };
  ws.onclose = () => { if (socket === ws) { socket = null; lost(); } };
}

function lost() {
  if (connection !== "gone") {  // keep the time it went away, not the time of the latest failed retry
    frozenNow = lastT == null ? null : serviceNow();
    helloSeen = false;
    setConnection("gone", `service gone at ${clock()}, retrying every ${RETRY_MS / 1000} s`);
    dirty = true;
  }
  setTimeout(connect, RETRY_MS);
}

// ---- plots -------------------------------------------------------------------------------------------
const GUTTER = 150;   // left margin for the legend / per-lane labels
const AXIS_H = 20;    // bottom margin for the time axis

function prepare(canvas) {
  const dpr = window.devicePixelRatio || 1;
  const w = canvas.clientWidth, h = canvas.clientHeight;
  if (canvas.width !== Math.round(w * dpr) || canvas.height !== Math.round(h * dpr)) {
    canvas.width = Math.round(w * dpr);
    canvas.height = Math.round(h * dpr);
  }
  const ctx = canvas.getContext("2d");
  ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
  ctx.clearRect(0, 0, w, h);
  return { ctx, w, h };
}

function label(ctx, str, x, y, align, baseline, colour = "#5b636d", font = "11px system-ui, sans-serif") {
  Object.assign(ctx, { textAlign: align, textBaseline: baseline, fillStyle: colour, font });
  ctx.fillText(str, x, y);
}
function hline(ctx, x0, x1, y, colour) {
  ctx.strokeStyle = colour;
  ctx.beginPath(); ctx.moveTo(x0, y); ctx.lineTo(x1, y); ctx.stroke();
}

// Time grid and labels, and the t -> x mapping both plots share (right edge = the service's "now").
function timeAxis(ctx, w, h) {
  const span = bench.history_s || 60, now = serviceNow(), t0 = now - span;
  const step = (w - GUTTER) / (span / 10) >= 45 ? 10 : 20;  // labels 10 s apart unless they would collide
  ctx.strokeStyle = "#e3e6ea";
  for (let s = 0; s <= span; s += step) {
    const x = GUTTER + (w - GUTTER) * (1 - s / span);
    ctx.beginPath(); ctx.moveTo(x, 0); ctx.lineTo(x, h - AXIS_H); ctx.stroke();
    label(ctx, s === 0 ? "now" : `−${s} s`, Math.min(x, w - 14), h - AXIS_H + 4, "center", "top");
  }
  return { now, X: (t) => GUTTER + (w - GUTTER) * ((t - t0) / span) };
}

// One polyline of a series, clipped to its box; null samples break it. The last value runs on to "now":
// the service sends nothing while nothing changes.
function trace(ctx, box, colour, values, X, Y, now) {
  ctx.save();
  ctx.beginPath(); ctx.rect(...box); ctx.clip();
  Object.assign(ctx, { strokeStyle: colour, lineWidth: 2 });
  ctx.beginPath();
  let last = null;
  for (let k = 0; k < values.length; k++) {
    const v = values[k];
    if (v == null) { last = null; continue; }
    const x = X(hist.t[k]), y = Y(v);
    if (last != null) ctx.lineTo(x, y); else ctx.moveTo(x, y);
    last = y;
  }
  if (last != null) ctx.lineTo(X(now), last);
  ctx.stroke();
  ctx.restore();
}

// Positions: one horizontal lane per axis, each scaled to its own min..max over the window, the range
// written at the lane's left. Chosen over one shared axis because mm and deg (or 0.01 mm and 300 mm)
// on a shared scale flatten the small movers into a line; lanes also never draw on top of each other.
function drawPositions() {
  const { ctx, w, h } = prepare($("#plot"));
  const { now, X } = timeAxis(ctx, w, h);
  const axes = bench.axes || [], laneH = (h - AXIS_H) / Math.max(1, axes.length);
  axes.forEach((ax, i) => {
    const top = i * laneH, bottom = top + laneH, values = hist.axes[ax.name] || [];
    let lo = Infinity, hi = -Infinity;
    for (const v of values) if (v != null) { if (v < lo) lo = v; if (v > hi) hi = v; }
    if (i > 0) hline(ctx, 0, w, top, "#c9ced4");
    label(ctx, `${ax.name}  ${withUnits(current.axes[ax.name], ax.units || "")}`, 6, top + laneH / 2,
      "left", "middle", colourOf(i), "bold 13px system-ui, sans-serif");
    if (!isFinite(lo)) return;
    const mid = (lo + hi) / 2, half = Math.max((hi - lo) / 2, 0.005);  // a still axis: a flat line mid-lane
    const ylo = mid - half * 1.15, yhi = mid + half * 1.15;
    const Y = (v) => bottom - 6 - (laneH - 12) * ((v - ylo) / (yhi - ylo));
    label(ctx, num(hi), GUTTER - 6, top + 3, "right", "top");
    label(ctx, num(lo), GUTTER - 6, bottom - 3, "right", "bottom");
    trace(ctx, [GUTTER, top, w - GUTTER, laneH], colourOf(i), values, X, Y, now);
  });
}

// Bus load: one shared 0..top % axis (same unit for every bus), top a round number above the peak.
function drawBusload() {
  const { ctx, w, h } = prepare($("#busload"));
  const { now, X } = timeAxis(ctx, w, h);
  const buses = bench.buses || [];
  let peak = 0;
  for (const b of buses) for (const v of hist.buses[b.name] || []) if (v != null && v > peak) peak = v;
  const top = [1, 2, 5, 10, 20, 50, 100].find((s) => s >= peak * 1.1) || Math.ceil(peak / 50) * 50;
  const Y = (v) => 8 + (h - AXIS_H - 8) * (1 - v / top);
  for (const f of [0, 0.5, 1]) {
    hline(ctx, GUTTER, w, Y(top * f), "#e3e6ea");
    label(ctx, `${top * f} %`, GUTTER - 6, Y(top * f), "right", "middle");
  }
  if (!buses.length) label(ctx, "no CAN bus on this bench", GUTTER + 10, h / 2, "left", "middle");
  buses.forEach((b, i) => {
    label(ctx, `${b.name}  ${num(current.buses[b.name], 1)} %`, 6, 16 + i * 18, "left", "middle",
      colourOf(i), "bold 13px system-ui, sans-serif");
    trace(ctx, [GUTTER, 0, w - GUTTER, h - AXIS_H], colourOf(i), hist.buses[b.name] || [], X, Y, now);
  });
}

// While live the window scrolls with time, so redraw at the frame cap; once gone, only on a change.
function frame(ts) {
  requestAnimationFrame(frame);
  if (!bench || ts - lastDraw < FRAME_MS || !(dirty || connection === "live")) return;
  lastDraw = ts;
  dirty = false;
  drawPositions();
  drawBusload();
}

// ---- start ---------------------------------------------------------------------------------------------
$("#stop-all").addEventListener("click", () => {
  post("api/stop", {}, "STOP ALL", (r) => (Array.isArray(r.stopped) ? ` (stopped ${r.stopped.join(", ") || "nothing"})` : ""));
  stopAxes(rows.keys());
});
// Build the table (and so the per-axis STOP buttons) from /api/bench even before, or without, a websocket.
fetch("api/bench", { cache: "no-store" })
  .then((r) => (r.ok ? r.json() : null))
  .then((b) => { if (b && !helloSeen) build(b); })
  .catch(() => { /* the websocket's retries report the service's absence */ });
window.addEventListener("resize", () => { dirty = true; });
window.addEventListener("blur", () => jogReleases.forEach((release) => release()));
connect();
requestAnimationFrame(frame);
