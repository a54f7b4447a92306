// RoverLink console: the page. Plain JS, no dependencies (the robot has no internet).
"use strict";

const $ = (id) => document.getElementById(id);
const camera = $("camera"), cam = camera.getContext("2d");
const scanCanvas = $("scan"), scanCtx = scanCanvas.getContext("2d");
const trailCanvas = $("trail"), trailCtx = trailCanvas.getContext("2d");

const view = {
  ws: null, driving: false, maxSpeed: [0.5, 2.0], lifetime: 0.25, keepalive: 0.08, autonomous: false,
  frame: null, frameId: 0, overlay: {}, pending: new Map(),
  drag: null, state: {}, trail: [], frames: 0, framesAt: performance.now(), fps: 0, override: false, frameAt: null,
  downSince: null, errors: new Map(), dismissed: new Set(), notes: 0,
};
const STALLED_MS = 1000; // no camera frame this long: "no picture for N s"

// The token came in the URL; the page's own requests carry it in a cookie: keep it out of the
// address bar and the history.
if (new URLSearchParams(location.search).has("token")) history.replaceState(null, "", location.pathname);

// -- the connection -------------------------------------------------------------------------------
function connect() {
  const ws = new WebSocket((location.protocol === "https:" ? "wss://" : "ws://") + location.host + "/ws");
  ws.binaryType = "arraybuffer";
  view.ws = ws;
  ws.onopen = () => {
    view.downSince = null;
    badge("conn", "console: connected", "ok");
    showHeader();
  };
  ws.onclose = () => {
    // Nothing on the page is current any more: say so, and since when.
    if (view.downSince === null) view.downSince = Date.now();
    view.driving = false;
    badge("role", "watching", "");
    showHeader();
    showStatus();
    setTimeout(reconnect, 1000);
  };
  ws.onmessage = (event) => {
    if (typeof event.data === "string") onMessage(JSON.parse(event.data));
    else onFrame(event.data);
  };
}

// Again, unless a socket is open or opening. A page restored from the back-forward cache or woken
// from freezing has had its socket closed under it and may have lost the timer set to reconnect:
// it reconnects when it is shown or resumed, and the keep-alive's tick checks too.
function reconnect() {
  if (!view.ws || view.ws.readyState === WebSocket.CLOSED || view.ws.readyState === WebSocket.CLOSING) connect();
}
window.addEventListener("pageshow", reconnect);
document.addEventListener("resume", reconnect);

function send(message) {
  if (view.ws && view.ws.readyState === WebSocket.OPEN) view.ws.send(JSON.stringify(message));
}

function onMessage(msg) {
  if (msg.type === "hello") {
    view.maxSpeed = msg.max_speed;
    view.lifetime = msg.command_lifetime_s;
    view.keepalive = msg.keepalive_s || msg.command_lifetime_s / 3;
    view.autonomous = !!msg.autonomous;
    view.state = {};
  } else if (msg.type === "state") {  // only what changed since the last one
    Object.assign(view.state, msg);
    if ("driving" in msg) {
      view.driving = msg.driving;
      badge("role", msg.driving ? "driving" : "watching", msg.driving ? "driving" : "");
      $("take").hidden = msg.driving;
    }
    showHeader();
    if (msg.pose) {
      addTrail(msg.pose);
      drawTrail();
    }
    if (msg.scan || msg.motion) drawScan();
    if ("guard" in msg) showGuard();
    showStatus();
  } else if (msg.type === "overlay") {
    view.pending.set(msg.frame, msg);
  } else if (msg.type === "error" || msg.type === "notice") {
    note(msg.error || msg.text); // stays until dismissed
  }
}

async function onFrame(buffer) {
  const id = new DataView(buffer).getUint32(0, true);
  const blob = new Blob([new Uint8Array(buffer, 4)], { type: "image/jpeg" });
  const bitmap = await createImageBitmap(blob);
  if (view.frame && !(view.drag && view.drag.bitmap === view.frame)) view.frame.close();
  view.frame = bitmap;
  view.frameId = id;
  view.frameAt = performance.now();
  view.overlay = view.pending.get(id) || {};
  for (const key of view.pending.keys()) if (key <= id) view.pending.delete(key);
  if (camera.width !== bitmap.width || camera.height !== bitmap.height) {
    camera.width = bitmap.width;
    camera.height = bitmap.height;
  }
  view.frames += 1;
  const now = performance.now();
  if (now - view.framesAt >= 1000) {
    view.fps = (view.frames * 1000) / (now - view.framesAt);
    view.frames = 0;
    view.framesAt = now;
  }
  showCameraInfo();
  document.body.dataset.frame = String(id); // for tests and tools: the frame on screen
  drawCamera();
}

// -- the camera and what is drawn on it ---------------------------------------------------------
function drawCamera() {
  // While a box is drawn the picture stands still: the box is drawn on that frame and names it.
  const shown = view.drag ? view.drag.bitmap : view.frame;
  if (!shown) return;
  cam.drawImage(shown, 0, 0);
  const o = view.drag ? view.drag.overlay : view.overlay;
  cam.lineWidth = 2;
  cam.font = "12px system-ui, sans-serif";
  for (const d of o.detections || []) {
    cam.strokeStyle = "#ffd54f";
    cam.strokeRect(d[0], d[1], d[2], d[3]);
  }
  if (o.box) {
    cam.strokeStyle = o.state === "lost" ? "#ff5252" : "#69f0ae";
    cam.strokeRect(o.box[0], o.box[1], o.box[2], o.box[3]);
  }
  const label = o.state ? `${o.state}${o.confidence != null ? " " + o.confidence.toFixed(2) : ""}` : "";
  if (label) {
    cam.fillStyle = "rgba(0,0,0,0.6)";
    cam.fillRect(0, 0, cam.measureText(label).width + 8, 16);
    cam.fillStyle = "#fff";
    cam.fillText(label, 4, 12);
  }
  if (view.drag) {
    const b = dragBox();
    cam.strokeStyle = "#40c4ff";
    cam.setLineDash([4, 3]);
    cam.strokeRect(b[0], b[1], b[2], b[3]);
    cam.setLineDash([]);
  }
}

function toImage(event) {
  const r = camera.getBoundingClientRect();
  return [((event.clientX - r.left) * camera.width) / r.width, ((event.clientY - r.top) * camera.height) / r.height];
}

function dragBox() {
  const [x0, y0] = view.drag.from, [x1, y1] = view.drag.to;
  const x = Math.max(0, Math.min(x0, x1)), y = Math.max(0, Math.min(y0, y1));
  const w = Math.min(camera.width, Math.max(x0, x1)) - x, h = Math.min(camera.height, Math.max(y0, y1)) - y;
  return [Math.round(x), Math.round(y), Math.round(w), Math.round(h)];
}

camera.addEventListener("pointerdown", (e) => {
  camera.setPointerCapture(e.pointerId);
  if (!view.frame) return;
  view.drag = { from: toImage(e), to: toImage(e), frame: view.frameId, bitmap: view.frame, overlay: view.overlay };
});
camera.addEventListener("pointermove", (e) => {
  if (!view.drag) return;
  view.drag.to = toImage(e);
  drawCamera();
});
camera.addEventListener("pointerup", (e) => {
  if (!view.drag) return;
  view.drag.to = toImage(e);
  const box = dragBox(), frame = view.drag.frame, held = view.drag.bitmap, overlay = view.drag.overlay;
  view.drag = null;
  if (held !== view.frame) held.close();
  drawCamera();
  if (box[2] >= 6 && box[3] >= 6) {
    send({ type: "select", frame, box });
    return;
  }
  const [px, py] = toImage(e); // a click: a detection under it?
  for (const d of overlay.detections || []) {
    if (px >= d[0] && px <= d[0] + d[2] && py >= d[1] && py <= d[1] + d[3]) {
      send({ type: "select", frame, box: d.map(Math.round) });
      return;
    }
  }
});

// -- the scan and the odometry trail ----------------------------------------------------------------
function drawScan() {
  const s = view.state.scan, c = scanCtx, W = scanCanvas.width, H = scanCanvas.height;
  c.fillStyle = "#000";
  c.fillRect(0, 0, W, H);
  if (!s) return;
  const range = s.range_m || 4, k = W / 2 / range;
  const at = (p) => [W / 2 - p[1] * k, H / 2 - p[0] * k]; // x forward (up), y left
  c.strokeStyle = "#263238";
  for (let r = 1; r <= range; r += 1) {
    c.beginPath();
    c.arc(W / 2, H / 2, r * k, 0, 2 * Math.PI);
    c.stroke();
  }
  c.fillStyle = "#ffab40"; // what the avoider treats as obstacles (the filtered scan)
  for (const p of s.points || []) { const [x, y] = at(p); c.fillRect(x - 1, y - 1, 2, 2); }
  if (s.footprint) {
    c.strokeStyle = "#69f0ae";
    c.beginPath();
    s.footprint.forEach((p, i) => { const [x, y] = at(p); if (i) c.lineTo(x, y); else c.moveTo(x, y); });
    c.closePath();
    c.stroke();
  }
  const m = view.state.motion;
  if (m && (m.linear || m.angular)) { // where the chosen command takes the robot in the next 2 s
    c.strokeStyle = "#40c4ff";
    c.lineWidth = 2;
    c.beginPath();
    c.moveTo(...at([0, 0]));
    for (let i = 1; i <= 20; i++) {
      const t = i * 0.1, th = m.angular * t;
      const p = Math.abs(m.angular) < 1e-6 ? [m.linear * t, 0]
        : m.linear === 0 ? [0.3 * Math.cos(th), 0.3 * Math.sin(th)]
          : [m.linear / m.angular * Math.sin(th), m.linear / m.angular * (1 - Math.cos(th))];
      c.lineTo(...at(p));
    }
    c.stroke();
    c.lineWidth = 1;
  }
  $("scan-info").textContent = `${(s.points || []).length} obstacle points`;
}

function addTrail(pose) {
  const last = view.trail[view.trail.length - 1];
  if (!last || Math.hypot(pose.x - last[0], pose.y - last[1]) > 0.02) view.trail.push([pose.x, pose.y]);
  if (view.trail.length > 2000) view.trail.shift();
  $("pose-info").textContent = `x ${pose.x.toFixed(2)} m, y ${pose.y.toFixed(2)} m, heading ${(pose.theta * 180 / Math.PI).toFixed(0)} deg`;
}

function drawTrail() {
  const c = trailCtx, W = trailCanvas.width, H = trailCanvas.height, pose = view.state.pose;
  c.fillStyle = "#000";
  c.fillRect(0, 0, W, H);
  if (!pose) return;
  let span = 2;
  for (const p of view.trail) span = Math.max(span, Math.abs(p[0] - pose.x) * 2.2, Math.abs(p[1] - pose.y) * 2.2);
  const k = W / span, at = (x, y) => [W / 2 - (y - pose.y) * k, H / 2 - (x - pose.x) * k];
  c.strokeStyle = "#40c4ff";
  c.beginPath();
  view.trail.forEach((p, i) => { const [x, y] = at(p[0], p[1]); if (i) c.lineTo(x, y); else c.moveTo(x, y); });
  c.stroke();
  const [x, y] = at(pose.x, pose.y);
  c.fillStyle = "#69f0ae";
  c.beginPath();
  c.arc(x, y, 5, 0, 2 * Math.PI);
  c.fill();
  c.strokeStyle = "#69f0ae";
  c.beginPath();
  c.moveTo(x, y);
  c.lineTo(x - Math.sin(pose.theta) * 14, y - Math.cos(pose.theta) * 14);
  c.stroke();
}

// What the board reports goes stale while its link is down; everything does while the console is unreachable.
const FROM_BOARD = new Set(["armed", "doing", "failsafe", "feedback", "round trip", "link errors"]);

function staleBoard() {
  return view.downSince !== null || !!(view.state.link && view.state.link.stale);
}

function showStatus() {
  const s = view.state, rows = [];
  const add = (name, value) => { if (value !== undefined && value !== null) rows.push([name, value]); };
  add("armed", s.armed ? "yes" : "no");
  add("failsafe", s.failsafe_text || s.failsafe);
  add("doing", s.mode);
  if (s.link && s.link.busy) add("request", `${s.link.busy}...`);
  add("following", s.following ? (s.autonomous ? "yes (autonomous)" : "yes") : "no");
  if (s.ended) add("", s.ended);
  add("track", s.track);
  for (const [name, value] of Object.entries(s.health || {})) add(name, value);
  add("browsers", s.clients);
  const all = view.downSince !== null, board = staleBoard();
  $("status").replaceChildren(...rows.map(([name, value]) => {
    const tr = document.createElement("tr");
    if (all || (board && FROM_BOARD.has(name))) tr.className = "stale";
    for (const text of [name, String(value)]) { const td = document.createElement("td"); td.textContent = text; tr.append(td); }
    return tr;
  }));
  $("pose-info").classList.toggle("stale", board);
}

const clock = (ms) => new Date(ms).toLocaleTimeString([], { hour12: false });

// The header: armed, the board's link, the failsafe, following; the banner saying what is wrong and
// what to do; the refusals and errors, each kept until dismissed.
function showHeader() {
  const s = view.state, link = s.link || {}, down = view.downSince !== null;
  const linkUp = !down && link.state === "up";
  badge("armed", down || !link.state ? "armed: ?" : `armed: ${s.armed && linkUp ? "yes" : "no"}`,
    s.armed && linkUp && !down ? "ok" : "");
  badge("link", down ? "board: ?" : `board: ${link.state === "up" ? "link up" : link.state || "?"}`,
    down ? "" : link.state === "up" ? "ok" : "bad");
  $("failsafe").hidden = !s.failsafe || down;
  $("failsafe").textContent = `failsafe ${s.failsafe || ""}`;
  $("following").hidden = !s.following && !view.autonomous;
  badge("following", s.following ? (view.autonomous ? "following (autonomous)" : "following")
    : "autonomous: follows with no browser", s.following ? "driving" : "warn");
  if (down) badge("conn", `console unreachable since ${clock(view.downSince)}`, "bad");
  const banner = $("banner");
  let text = "", hint = "", level = "";
  if (down) {
    const secs = Math.round((Date.now() - view.downSince) / 1000);
    text = `console unreachable since ${clock(view.downSince)} (${secs} s)`;
    hint = "everything shown is from then (greyed); the page reconnects by itself";
    level = "error";
  } else if (link.banner) {
    ({ text, hint, level } = link.banner);
  }
  banner.hidden = !text;
  banner.className = "banner " + level;
  $("banner-text").textContent = text;
  $("banner-hint").textContent = hint ? `: ${hint}` : "";
  const kept = new Set((link.refusals || []).map((r) => r.id));
  for (const r of link.refusals || []) if (!view.errors.has(r.id)) view.errors.set(r.id, r.text);
  for (const id of [...view.errors.keys()]) if (id > 0 && !kept.has(id)) view.errors.delete(id); // dismissed elsewhere
  showErrors();
}

function note(text) {
  view.notes -= 1; // the page's own notes: negative ids, apart from the robot's refusals
  view.errors.set(view.notes, `${clock(Date.now())} ${text}`);
  showErrors();
}

let shownErrors = "";
function showErrors() {
  // Rebuilt only when the list changes: a button replaced under the pointer would miss its click.
  const ids = [...view.errors.keys()].filter((id) => !view.dismissed.has(id)).join(",");
  if (ids === shownErrors) return;
  shownErrors = ids;
  const items = [];
  for (const [id, text] of view.errors) {
    if (view.dismissed.has(id)) continue;
    const li = document.createElement("li"), span = document.createElement("span"), x = document.createElement("button");
    span.textContent = text;
    x.textContent = "\u2715";
    x.title = "Dismiss";
    x.addEventListener("click", () => {
      view.dismissed.add(id);
      if (id > 0) send({ type: "dismiss", id }); // the robot's refusal: gone for every page
      showErrors();
    });
    li.append(span, x);
    items.push(li);
  }
  $("errors").replaceChildren(...items);
}

function showCameraInfo() {
  const info = $("camera-info");
  if (!view.frame) { info.textContent = "no picture yet"; return; }
  const quiet = performance.now() - view.frameAt;
  info.textContent = quiet >= STALLED_MS ? `no picture for ${Math.round(quiet / 1000)} s`
    : `${view.frame.width}x${view.frame.height}${view.fps ? `, ${view.fps.toFixed(0)} fps` : ""}, frame ${view.frameId}`;
  info.classList.toggle("stale", quiet >= STALLED_MS);
}

// The obstacle guard's word on the last drive command, and the override while it is held.
function showGuard() {
  const g = view.state.guard, el = $("guard");
  if (view.override) el.textContent = g && g.state === "override" ? g.text : "override held: no obstacle protection";
  else el.textContent = g && g.state !== "override" ? g.text : "obstacle protection on";
  el.className = "hint " + (view.override ? "override" : g && g.state !== "clear" && g.state !== "override" ? "limited" : "");
}

function badge(id, text, kind) {
  const el = $(id);
  el.textContent = text;
  el.className = "badge " + (kind || "");
}

// -- driving: keys, the joystick, a gamepad -----------------------------------------------------------
const keys = new Set(), stick = { x: 0, y: 0, active: false };

function stopNow() {
  keys.clear();
  stick.active = false;
  fetch("api/stop", { method: "POST", credentials: "same-origin" }).catch(() => {});
  send({ type: "stop" });
}

$("stop").addEventListener("click", stopNow);
$("take").addEventListener("click", () => send({ type: "take" }));
$("arm").addEventListener("click", () => send({ type: "arm", on: true }));
$("disarm").addEventListener("click", () => send({ type: "arm", on: false }));
$("follow").addEventListener("click", () => send({ type: "follow", on: true }));
$("unfollow").addEventListener("click", () => send({ type: "follow", on: false }));
$("target-person").addEventListener("click", () => send({ type: "target", kind: "person" }));
$("target-face").addEventListener("click", () => send({ type: "target", kind: "face" }));

// The override is held, never latched: the on-screen button, Shift, or a gamepad shoulder button.
// Each drive command carries it; letting go restores the obstacle protection with the next one.
const held = { button: false, shift: false };
const overrideButton = $("override");
function padOverride() {
  for (const gp of navigator.getGamepads ? navigator.getGamepads() : []) {
    if (gp && [4, 5, 6, 7].some((i) => gp.buttons[i] && gp.buttons[i].pressed)) return true;
  }
  return false;
}
function showOverride() { // also from the drive timer: a gamepad's button sends no event
  const on = held.button || held.shift || padOverride();
  if (on === view.override) return;
  view.override = on;
  overrideButton.classList.toggle("held", on);
  showGuard();
}
function holdOverride(which, on) {
  held[which] = on;
  showOverride();
}
overrideButton.addEventListener("pointerdown", (e) => { overrideButton.setPointerCapture(e.pointerId); holdOverride("button", true); });
for (const end of ["pointerup", "pointercancel", "lostpointercapture"]) {
  overrideButton.addEventListener(end, () => holdOverride("button", false));
}

const DRIVE_KEYS = ["w", "a", "s", "d", "arrowup", "arrowdown", "arrowleft", "arrowright"];
document.addEventListener("keydown", (e) => {
  const k = e.key.toLowerCase();
  if (k === "shift") { holdOverride("shift", true); return; }
  if (k === " ") { e.preventDefault(); stopNow(); return; }
  if (DRIVE_KEYS.includes(k)) { e.preventDefault(); keys.add(k); }
});
document.addEventListener("keyup", (e) => {
  const k = e.key.toLowerCase();
  if (k === "shift") holdOverride("shift", false);
  keys.delete(k);
});
window.addEventListener("blur", () => { keys.clear(); holdOverride("shift", false); holdOverride("button", false); });

const pad = $("joystick"), knob = $("knob");
function moveStick(e) {
  const r = pad.getBoundingClientRect(), R = r.width / 2;
  let x = (e.clientX - r.left - R) / R, y = (e.clientY - r.top - R) / R;
  const n = Math.hypot(x, y);
  if (n > 1) { x /= n; y /= n; }
  stick.x = x;
  stick.y = y;
  knob.style.left = `${R - 25 + x * (R - 25)}px`;
  knob.style.top = `${R - 25 + y * (R - 25)}px`;
}
pad.addEventListener("pointerdown", (e) => { pad.setPointerCapture(e.pointerId); stick.active = true; moveStick(e); });
pad.addEventListener("pointermove", (e) => { if (stick.active) moveStick(e); });
const release = () => { stick.active = false; stick.x = stick.y = 0; knob.style.left = knob.style.top = "55px"; };
pad.addEventListener("pointerup", release);
pad.addEventListener("pointercancel", release);
// A hidden tab's timers run once a second: its commands would come in bursts, so it stops driving.
document.addEventListener("visibilitychange", () => {
  if (document.hidden) {
    keys.clear();
    release();
    holdOverride("shift", false);
    holdOverride("button", false);
    if (view.driving) send({ type: "drive", linear: 0, angular: 0 });
  }
});

function wanted() {
  // (forward, left) in -1..1 from whichever input is in use
  if (stick.active) return [-stick.y, -stick.x];
  for (const gp of navigator.getGamepads ? navigator.getGamepads() : []) {
    if (!gp) continue;
    const fx = -gp.axes[1] || 0, fy = -gp.axes[0] || 0;
    if (Math.abs(fx) > 0.15 || Math.abs(fy) > 0.15) return [fx, fy];
  }
  if (keys.size) {
    const has = (...ks) => ks.some((k) => keys.has(k));
    return [(has("w", "arrowup") ? 1 : 0) - (has("s", "arrowdown") ? 1 : 0),
      (has("a", "arrowleft") ? 1 : 0) - (has("d", "arrowright") ? 1 : 0)];
  }
  return null;
}

let wasDriving = false;
setInterval(() => {
  const w = wanted();
  showOverride();
  if (w) {
    send({ type: "drive", linear: w[0] * view.maxSpeed[0] * 0.6, angular: w[1] * view.maxSpeed[1] * 0.6,
      override: view.override });
    wasDriving = true;
  } else if (wasDriving) {
    send({ type: "drive", linear: 0, angular: 0 });
    wasDriving = false;
  }
}, 50);

// The keep-alive following lasts on: at least every third of the command lifetime, pressed or not; a
// hidden tab sends none (it is not watching), a frozen or closed one cannot.
function keepAlive() {
  reconnect();
  if (!document.hidden) send({ type: "alive" });
  setTimeout(keepAlive, view.keepalive * 800);
}
keepAlive();
setInterval(() => { showCameraInfo(); if (view.downSince !== null) showHeader(); }, 500);

connect();
