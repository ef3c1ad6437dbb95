// rendersim explore: the page's state is its --set list (in the address);
// each change asks the server for one run of the real simulator and draws
// what it returns. No library: the pictures are SVG from rendersim's own
// plotting, the rest is text.
"use strict";

const state = { model: null, sets: [], busy: false, pending: false, changedAt: null, capture: null };
// The keys a replay's what-if takes (src/explore/page_replay.rs, WHATIF_PREFIXES).
const WHATIF = ["display.", "pacing.", "frame_generation.", "cpu.max_frames_ahead"];
// Redraw times (ms from a change to the page drawn), read by the browser test.
window.rendersimTimings = [];

const $ = (id) => document.getElementById(id);

function keyOf(assignment) {
  const i = assignment.indexOf("=");
  return (i < 0 ? assignment : assignment.slice(0, i)).trim();
}

function valueOf(assignment) {
  const i = assignment.indexOf("=");
  return i < 0 ? "" : assignment.slice(i + 1).trim();
}

// The value a control shows for an assignment's value: quotes and its unit
// taken off (the page writes "7.5us"; another unit is left to the server).
function parseValue(control, text) {
  const t = kind(control);
  let v = text.replace(/^"(.*)"$/, "$1");
  if (t.type === "duration" && v.endsWith(t.unit)) return Number(v.slice(0, -t.unit.length));
  if (t.type === "rate" && v.endsWith("Hz")) return Number(v.slice(0, -2));
  if (t.type === "bool") return v === "true";
  if (t.type === "int" || t.type === "float") return Number(v);
  return v;
}

function kind(control) { return control.kind; }

// The assignment a control writes, as `--set` takes it (src/explore/controls.rs,
// `assignment`, writes the same).
function assignmentOf(control, key, value) {
  const t = kind(control);
  switch (t.type) {
    case "duration": return `${key}="${value}${t.unit}"`;
    case "rate": return `${key}="${value}Hz"`;
    case "choice": return `${key}="${value}"`;
    default: return `${key}=${value}`;
  }
}

// The key a control writes now: its whole key where the sets replaced it
// whole (a preset's `cpu.non_render="17ms"`), else its set key.
function writeKey(control) {
  return state.sets.some((s) => keyOf(s) === control.key) ? control.key : control.set_key;
}

function controlSet(control) {
  for (let i = state.sets.length - 1; i >= 0; i--) {
    const k = keyOf(state.sets[i]);
    if (k === control.key || k === control.set_key) return state.sets[i];
  }
  return null;
}

function setControl(control, value) {
  const key = writeKey(control);
  state.sets = state.sets.filter((s) => keyOf(s) !== key && keyOf(s) !== control.set_key);
  if (value !== null) state.sets.push(assignmentOf(control, key, value));
}

function fmt(v, unit) {
  if (v === null || v === undefined) return "–";
  if (unit === "frames") return String(v);
  return Math.abs(v) >= 100 ? v.toFixed(1) : v.toFixed(3);
}

function buildControls() {
  const form = $("controls");
  form.textContent = "";
  const groups = new Map();
  for (const c of state.model.controls) {
    if (!groups.has(c.group)) {
      const fs = document.createElement("fieldset");
      const lg = document.createElement("legend");
      lg.textContent = c.group;
      fs.appendChild(lg);
      form.appendChild(fs);
      groups.set(c.group, fs);
    }
    groups.get(c.group).appendChild(controlRow(c));
  }
}

function controlRow(c) {
  const t = kind(c);
  const row = document.createElement("div");
  row.className = "control";
  row.dataset.key = c.key;
  const label = document.createElement("label");
  label.textContent = c.label;
  label.title = c.key;
  row.appendChild(label);
  let input, number = null, toggle = null;
  const changed = (value) => { setControl(c, value); redraw(); };
  if (t.type === "bool") {
    input = document.createElement("input");
    input.type = "checkbox";
    input.addEventListener("change", () => changed(input.checked));
  } else if (t.type === "choice") {
    input = document.createElement("select");
    for (const o of t.options) {
      const opt = document.createElement("option");
      opt.value = o; opt.textContent = o;
      input.appendChild(opt);
    }
    input.addEventListener("change", () => changed(input.value));
  } else {
    input = document.createElement("input");
    input.type = "range";
    input.min = t.min; input.max = t.max; input.step = t.step === undefined ? 1 : t.step;
    number = document.createElement("input");
    number.type = "number";
    number.step = "any";
    input.addEventListener("input", () => { number.value = input.value; changed(input.value); });
    number.addEventListener("change", () => { input.value = number.value; changed(number.value); });
  }
  input.id = "c-" + c.key;
  label.htmlFor = input.id;
  if (c.optional) {
    toggle = document.createElement("input");
    toggle.type = "checkbox";
    toggle.title = "on";
    toggle.id = "on-" + c.key;
    toggle.addEventListener("change", () => {
      input.disabled = !toggle.checked;
      if (number) number.disabled = !toggle.checked;
      changed(toggle.checked ? input.value : null);
    });
    label.prepend(toggle);
  }
  row.appendChild(input);
  const tail = document.createElement("span");
  if (number) tail.appendChild(number);
  const unit = document.createElement("span");
  unit.className = "unit";
  unit.textContent = t.type === "duration" ? " " + t.unit : t.type === "rate" ? " Hz" : "";
  tail.appendChild(unit);
  row.appendChild(tail);
  c.ui = { input, number, toggle };
  return row;
}

// Shows each control at the value the sets (or else the model) give it.
function showValues() {
  for (const c of state.model.controls) {
    const s = controlSet(c);
    const v = s === null ? c.value : parseValue(c, valueOf(s));
    const { input, number, toggle } = c.ui;
    if (toggle) {
      toggle.checked = v !== null;
      input.disabled = v === null;
      if (number) number.disabled = v === null;
    }
    if (v === null) continue;
    if (kind(c).type === "bool") input.checked = v === true;
    else input.value = v;
    if (number) number.value = v;
  }
}

function buildPresets() {
  const box = $("preset-buttons");
  if (!state.model.presets.length) {
    $("preset-text").textContent = "The lessons are written for a scene like the default model's: " +
      "run `rendersim explore` without a model to take them.";
  }
  for (const p of state.model.presets) {
    const b = document.createElement("button");
    b.type = "button";
    b.id = "preset-" + p.id;
    b.textContent = p.title;
    b.addEventListener("click", () => {
      state.sets = state.model.start_sets.concat(p.sets);
      $("preset-text").textContent = p.text;
      showValues();
      redraw();
    });
    box.appendChild(b);
  }
}

function query() {
  return state.sets.map((s) => "set=" + encodeURIComponent(s)).join("&");
}

function showError(message) {
  const e = $("error");
  e.textContent = message;
  e.hidden = false;
  $("status").textContent = "not redrawn: see the message";
  $("status").dataset.state = "error";
}

async function redraw() {
  state.changedAt = performance.now();
  const q = query();
  history.replaceState(null, "", q ? "?" + q : location.pathname);
  $("model-toml").href = "/api/model.toml" + (q ? "?" + q : "");
  if (state.capture) replay();
  if (state.busy) { state.pending = true; return; }
  state.busy = true;
  const asked = state.changedAt;
  $("status").textContent = "running…";
  $("status").dataset.state = "loading";
  try {
    const response = await fetch("/api/run" + (q ? "?" + q : ""));
    const body = await response.json();
    if (!response.ok) showError(body.error || response.statusText);
    else { draw(body); window.rendersimTimings.push(performance.now() - asked); }
  } catch (err) {
    showError("the server did not answer: " + err);
  } finally {
    state.busy = false;
    if (state.pending) { state.pending = false; redraw(); }
  }
}

function row(cells) {
  const tr = document.createElement("tr");
  for (const c of cells) {
    const td = document.createElement("td");
    if (c instanceof Node) td.appendChild(c); else td.textContent = c;
    tr.appendChild(td);
  }
  return tr;
}

function draw(r) {
  $("error").hidden = true;
  const v = $("verdict");
  v.textContent = r.verdict.bottleneck === "tie" ? "tie: " + r.verdict.tied.join(", ") : r.verdict.bottleneck;
  v.dataset.bottleneck = r.verdict.bottleneck;
  $("advice").textContent = r.verdict.advice + ". Halving each unit's work: " +
    r.verdict.changes.map(([n, c]) => `${n} ${(c * 100).toFixed(1)}%`).join(", ") + ".";
  const shares = $("shares").tBodies[0];
  shares.textContent = "";
  for (const [unit, share] of r.shares) shares.appendChild(row([unit, (share * 100).toFixed(1) + "%"]));
  const nums = $("numbers").tBodies[0];
  nums.textContent = "";
  for (const n of r.numbers) {
    const value = document.createElement("span");
    value.className = "number";
    value.dataset.json = n.json;
    value.dataset.value = JSON.stringify(n.value);
    value.textContent = fmt(n.value, n.unit);
    nums.appendChild(row([n.label, value, n.unit]));
  }
  const cf = $("closed-form").tBodies[0];
  cf.textContent = "";
  for (const c of r.closed_form) cf.appendChild(row([c.label, fmt(c.closed_form_ms), fmt(c.simulated_ms)]));
  $("run-facts").textContent = `${r.events.toLocaleString()} events, ${r.simulated_seconds.toFixed(3)} s simulated` +
    (r.notes.length ? "; " + r.notes.join("; ") : "");
  for (const id of ["timeline", "frames", "latency", "states"]) {
    $(id).querySelector(".svg").innerHTML = r.views[id];
  }
  $("timeline").dataset.lanes = JSON.stringify(r.lanes);
  $("command").textContent = r.command;
  $("status").textContent = "ready";
  $("status").dataset.state = "ready";
}

// The capture replayed with the what-if the controls give; one request at
// a time, the newest state replayed after it.
const replaying = { busy: false, pending: false };

async function replay() {
  if (replaying.busy) { replaying.pending = true; return; }
  replaying.busy = true;
  const status = $("replay-status");
  status.textContent = `replaying ${state.capture.name}…`;
  status.dataset.state = "loading";
  const params = new URLSearchParams();
  params.append("file", state.capture.name);
  const app = $("capture-app").value.trim();
  if (app) params.append("app", app);
  for (const s of state.sets) if (WHATIF.some((p) => keyOf(s).startsWith(p))) params.append("set", s);
  try {
    const response = await fetch("/api/replay?" + params.toString(), { method: "POST", body: state.capture.bytes });
    const body = await response.json();
    if (!response.ok) {
      status.textContent = body.error || response.statusText;
      status.dataset.state = "error";
    } else drawReplay(body);
  } catch (err) {
    status.textContent = "the server did not answer: " + err;
    status.dataset.state = "error";
  } finally {
    replaying.busy = false;
    if (replaying.pending) { replaying.pending = false; replay(); }
  }
}

function pct(v) { return v === null || v === undefined ? "–" : (v * 100).toFixed(1) + "%"; }

function drawReplay(r) {
  const status = $("replay-status");
  status.textContent = `${r.file}: ${r.application} (${r.swapchain}), ${r.frames} frames replayed`;
  status.dataset.state = "ready";
  status.dataset.agreement = String(r.agreement);
  const sum = $("replay-summary").tBodies[0];
  sum.textContent = "";
  sum.appendChild(row(["displayed or dropped: replay agrees on", pct(r.agreement)]));
  sum.appendChild(row(["present to screen, |error| median / p90",
    `${fmt(r.until_displayed_error_ms[0])} / ${fmt(r.until_displayed_error_ms[1])} ms`]));
  sum.appendChild(row(["present to GPU done, |error| median", `${fmt(r.render_complete_error_ms)} ms`]));
  sum.appendChild(row(["display inferred", `${r.refresh_hz.toFixed(2)} Hz (from ${r.refresh_from}); ` +
    `${r.present_mode[0]} replayed as ${r.present_mode[1]}`]));
  for (const n of r.capture_notes) sum.appendChild(row(["note", n]));
  const stats = $("replay-stats").tBodies[0];
  stats.textContent = "";
  const cols = [r.measured, r.as_captured, r.whatif[1]];
  const line = (label, pick) => stats.appendChild(row([label, ...cols.map((c) => { const v = pick(c); return v === null || v === undefined ? "–" : fmt(v); })]));
  line("presents a second", (c) => c.fps);
  line("display changes a second", (c) => c.displayed_fps);
  line("latency (CPU start to screen), median, ms", (c) => c.display_latency_ms.median);
  line("latency, p90, ms", (c) => c.display_latency_ms.p90);
  line("frames dropped", (c) => c.dropped);
  $("replay-view").querySelector(".svg").innerHTML = r.view;
  $("replay-command").textContent = r.command + (r.whatif[0].length ? "" : "    # no what-if: set a display or pacing control");
}

function setUpCapture() {
  const load = async (file) => {
    if (!file) return;
    state.capture = { name: file.name, bytes: await file.arrayBuffer() };
    replay();
  };
  $("capture-file").addEventListener("change", (e) => load(e.target.files[0]));
  $("capture-app").addEventListener("change", () => { if (state.capture) replay(); });
  const zone = $("drop-zone");
  zone.addEventListener("dragover", (e) => { e.preventDefault(); zone.classList.add("over"); });
  zone.addEventListener("dragleave", () => zone.classList.remove("over"));
  zone.addEventListener("drop", (e) => {
    e.preventDefault();
    zone.classList.remove("over");
    load(e.dataTransfer.files[0]);
  });
}

async function init() {
  try {
    const response = await fetch("/api/model");
    const body = await response.json();
    if (!response.ok) { showError(body.error); return; }
    state.model = body;
  } catch (err) {
    showError("the server did not answer: " + err);
    return;
  }
  $("model-name").textContent = state.model.model + ": " + state.model.description;
  const given = new URLSearchParams(location.search).getAll("set");
  state.sets = given.length ? given : state.model.start_sets.slice();
  buildControls();
  buildPresets();
  setUpCapture();
  showValues();
  $("free-add").addEventListener("click", () => {
    const s = $("free-set").value.trim();
    if (!s) return;
    state.sets = state.sets.filter((x) => keyOf(x) !== keyOf(s));
    state.sets.push(s);
    showValues();
    redraw();
  });
  redraw();
}

init();
