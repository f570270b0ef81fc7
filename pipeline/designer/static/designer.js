// lookdev designer page. It holds no formula and no model knowledge: controls are drawn
// from the descriptors the server makes from each model's Pydantic schema, every edit is
// validated by the server (refused edits come back with the schema's message), and every
// pixel of the viewport comes from the server's renderer.
"use strict";

const $ = (id) => document.getElementById(id);
const el = (tag, props = {}, ...children) => {
  const e = Object.assign(document.createElement(tag), props);
  for (const c of children) e.append(c);
  return e;
};

let state = null;
let meta = null;
let library = [];
let images = [];
let target = null; // null: the preset's own parameters; an index: a layer
let plotView = "slice";
let frames = { A: null, B: null };
let split = 0.5;
let pendingMeta = null;
let ws = null;

async function api(path, body) {
  const opts = body === undefined ? {} : {
    method: "POST", headers: { "Content-Type": "application/json" }, body: JSON.stringify(body),
  };
  const r = await fetch(path, opts);
  const data = await r.json().catch(() => ({ error: `HTTP ${r.status}` }));
  if (!r.ok) throw new Error(data.error || `HTTP ${r.status}`);
  if (data.refused) throw new Error(data.refused); // the schema's message, shown in place
  return data;
}

function say(text, error = false) {
  const m = $("message");
  m.textContent = text;
  m.className = error ? "error" : "";
}

// -- state -------------------------------------------------------------------------------
async function refresh(newState) {
  state = newState || await api("api/state");
  if (state.layered && (target === null || target >= state.targets.length)) target = 0;
  if (!state.layered) target = null;
  $("title").textContent = state.name + (state.path ? "" : " (new)");
  $("dirty").textContent = state.dirty ? " ● unsaved" : "";
  $("undo").disabled = !state.can_undo;
  $("redo").disabled = !state.can_redo;
  $("save-over").disabled = !state.path;
  drawLayers();
  drawControls();
  drawPlot();
  drawLosses();
  for (const p of document.querySelectorAll(".preset")) {
    p.classList.toggle("current", p.dataset.name === state.name);
  }
}

async function edit(op) {
  try {
    const s = await api("api/edit", op);
    say("");
    await refresh(s);
    return null;
  } catch (e) {
    return e.message;
  }
}

// -- controls ----------------------------------------------------------------------------
function currentTarget() {
  return state.targets.find((t) => t.index === target) || state.targets[0];
}

function drawControls() {
  const box = $("controls");
  box.replaceChildren();
  const t = currentTarget();
  if (!t) return;
  $("controls-title").textContent = t.index === null ? `Parameters: ${t.label} (${t.model})`
    : `Layer ${t.index}: ${t.label} (${t.model})`;
  box.append(metaRow());
  const descriptors = state.controls[t.model];
  if (!descriptors) {
    box.append(el("p", { textContent: "A layered preset as a layer: open it to edit its layers." }));
    return;
  }
  for (const c of descriptors) box.append(control(c, t));
}

function metaRow() {
  const wrap = el("div", { className: "control" });
  const desc = el("input", { value: state.doc.description || "", placeholder: "description", style: "width:100%" });
  const tags = el("input", { value: (state.doc.tags || []).join(", "), placeholder: "tags, comma-separated",
    style: "width:100%" });
  const error = el("div", { className: "error" });
  const send = async (field, value) => {
    const message = await edit({ op: "meta", field, value });
    if (message) error.textContent = message;
  };
  desc.onchange = () => send("description", desc.value);
  tags.onchange = () => send("tags", tags.value.split(",").map((x) => x.trim()).filter(Boolean));
  wrap.append(desc, tags, error);
  return wrap;
}

function control(c, t) {
  const value = t.values[c.name];
  const overridden = t.overridden.includes(c.name);
  const wrap = el("div", { className: "control", title: c.doc });
  wrap.dataset.field = c.name;
  const badge = el("span", {
    className: "badge" + (overridden ? " over" : ""),
    textContent: overridden ? "overridden" : (t.index === null && !state.doc.extends ? "default" : "inherited"),
  });
  const head = el("div", { className: "head" }, el("span", { className: "name", textContent: c.title }), badge);
  if (overridden) {
    head.append(el("button", {
      textContent: "reset", title: "Back to the inherited value",
      onclick: () => edit({ op: "reset", target: t.index, field: c.name }),
    }));
  }
  const error = el("div", { className: "error" });
  const send = async (v, input) => {
    const message = await edit({ op: "set", target: t.index, field: c.name, value: v });
    if (message) { // refused in place: the field keeps its old value, the reason shown
      const box = document.querySelector(`.control[data-field="${c.name}"]`) || wrap;
      const inp = box.querySelector(input ? `input[name="${input}"]` : "input");
      if (inp) inp.classList.add("invalid");
      const err = box.querySelector(".error");
      if (err) err.textContent = message;
      if (inp && input) inp.value = input === "text" ? inp.value : inp.value;
    }
  };
  wrap.append(head, el("div", { className: "doc", textContent: c.doc }));
  const row = el("div", { className: "row" });
  if (value && typeof value === "object" && !Array.isArray(value)) {
    wrap.append(textureRow(c, t, value));
  } else if (c.kind === "number") {
    const v = value === null || value === undefined ? c.default : value;
    const range = el("input", {
      type: "range", min: c.slider_min, max: c.slider_max, step: (c.slider_max - c.slider_min) / 1000,
      value: v ?? c.slider_min, name: "slider",
    });
    const num = el("input", { type: "number", value: v ?? "", step: "any", name: "number" });
    range.oninput = () => { num.value = range.value; };
    range.onchange = () => send(parseFloat(range.value), "slider");
    num.onchange = () => {
      const x = num.value.trim() === "" ? null : Number(num.value);
      send(Number.isNaN(x) ? num.value : x, "number");
    };
    row.append(range, num);
  } else if (c.kind === "colour") {
    const rgb = Array.isArray(value) ? value : c.default;
    const inputs = rgb.map((x, i) => el("input", { type: "number", step: "any", value: x, name: `c${i}` }));
    for (const inp of inputs) {
      inp.onchange = () => send(inputs.map((i) => Number(i.value)), inp.name);
    }
    const picker = el("input", { type: "color", title: "pick an sRGB colour (#rrggbb)", name: "picker" });
    picker.onchange = () => send(picker.value, "picker");
    row.append(...inputs, picker);
  } else if (c.kind === "switch") {
    const box = el("input", { type: "checkbox", checked: !!value, name: "switch" });
    box.onchange = () => send(box.checked, "switch");
    row.append(box);
  } else if (c.kind === "choice") {
    const sel = el("select", { name: "choice" });
    for (const ch of c.choices) sel.append(el("option", { value: ch, textContent: ch, selected: ch === value }));
    sel.onchange = () => send(sel.value, "choice");
    row.append(sel);
  }
  if (c.texturable && !(value && typeof value === "object" && !Array.isArray(value))) {
    row.append(el("button", {
      textContent: "map…", title: "Drive this parameter by a texture",
      onclick: () => pickTexture(c, t, null),
    }));
  }
  wrap.append(row, error);
  return wrap;
}

function textureRow(c, t, tex) {
  const row = el("div", { className: "row" });
  row.append(el("span", {
    className: "map",
    textContent: `map ${tex.texture} · channel ${tex.channel ?? "auto"} · ${tex.colorspace ?? "by file rules"}`,
  }));
  row.append(el("button", { textContent: "swap…", onclick: () => pickTexture(c, t, tex) }));
  const constant = Array.isArray(c.default) || typeof c.default === "number" ? c.default : 0.5;
  row.append(el("button", {
    textContent: "constant", title: "Replace the map by a constant",
    onclick: () => edit({ op: "set", target: t.index, field: c.name, value: constant }),
  }));
  return row;
}

function pickTexture(c, t, tex) {
  const sel = el("select");
  sel.append(el("option", { textContent: "choose an image…", value: "" }));
  images.forEach((im, i) => sel.append(el("option", { value: i, textContent: `${im.root}/${im.path}` })));
  const box = document.querySelector(`.control[data-field="${c.name}"] .row`);
  box.append(sel);
  sel.onchange = async () => {
    if (sel.value === "") return;
    const value = Object.assign({}, tex || {}, { texture: images[Number(sel.value)] });
    const message = await edit({ op: "set", target: t.index, field: c.name, value });
    if (message) say(message, true);
  };
}

// -- layers ------------------------------------------------------------------------------
function maskText(m) {
  if (m === undefined || m === null) return "mask: full";
  if (typeof m === "number") return `mask: ${m}`;
  return "mask: " + JSON.stringify(m);
}

function drawLayers() {
  const panel = $("layers-panel");
  panel.hidden = !state.layered;
  if (!state.layered) return;
  const list = $("layers");
  list.replaceChildren();
  const layers = state.doc.layers || [];
  for (let i = layers.length - 1; i >= 0; i--) {
    const la = layers[i];
    const hidden = state.hidden.includes(i);
    const li = el("li", { className: (i === target ? "selected" : "") + (hidden ? " hidden-layer" : "") });
    li.dataset.index = i;
    const eye = el("input", { type: "checkbox", checked: !hidden, title: "show this layer" });
    eye.onchange = async () => refresh(await api("api/hide", { index: i, hidden: !eye.checked }));
    const label = el("span", {
      textContent: ` ${i}: ${la.name || la.preset || la.model}`, style: "cursor:pointer",
      onclick: () => { target = i; refresh(state); },
    });
    const up = el("button", { textContent: "↑", disabled: i === layers.length - 1, title: "move up",
      onclick: () => edit({ op: "layer_move", index: i, to: i + 1 }) });
    const down = el("button", { textContent: "↓", disabled: i === 0, title: "move down",
      onclick: () => edit({ op: "layer_move", index: i, to: i - 1 }) });
    const del = el("button", { textContent: "✕", title: "delete the layer",
      onclick: () => edit({ op: "layer_remove", index: i }) });
    const mask = el("textarea", { className: "mask-json", value: JSON.stringify(la.mask ?? 1.0) });
    const error = el("div", { className: "error" });
    mask.onchange = async () => {
      let parsed;
      try { parsed = JSON.parse(mask.value); } catch (e) { error.textContent = `not JSON: ${e.message}`; return; }
      const message = await edit({ op: "layer_mask", index: i, mask: parsed });
      if (message) { error.textContent = message; mask.classList.add("invalid"); }
    };
    const presence = el("input", { type: "number", step: "any", value: la.presence ?? 1, title:
      "presence (Pixar layers: opacity, 0..1)", style: "width:56px" });
    presence.onchange = async () => {
      const message = await edit({ op: "layer_presence", index: i, value: Number(presence.value) });
      if (message) { error.textContent = message; presence.classList.add("invalid"); }
    };
    const pixar = (state.targets[i] || {}).model === "pixar";
    li.append(eye, label, " ", up, down, del, ...(pixar ? [" presence ", presence] : []),
      el("span", { className: "mask", textContent: maskText(la.mask) }), mask, error);
    list.append(li);
  }
}

function maskTemplate(kind) {
  if (kind === "none") return null;
  if (kind === "texture") {
    const im = images.find((x) => !/\.(exr|hdr)$/i.test(x.path)) || images[0];
    return { kind: "texture", path: im, channel: 0 };
  }
  return { kind };
}

async function addLayer() {
  const preset = $("add-preset").value;
  const mask = maskTemplate($("add-mask-kind").value);
  const message = await edit({ op: "layer_add", preset, mask });
  if (message) say(message, true);
}

// -- library -----------------------------------------------------------------------------
function drawLibrary() {
  const q = $("search").value.toLowerCase();
  const model = $("filter-model").value;
  const tag = $("filter-tag").value;
  const box = $("presets");
  box.replaceChildren();
  for (const p of library) {
    if (q && !(p.name + " " + p.description + " " + p.tags.join(" ")).toLowerCase().includes(q)) continue;
    if (model && p.model !== model) continue;
    if (tag && !p.tags.includes(tag)) continue;
    const item = el("div", { className: "preset", title: p.description },
      el("img", { src: `api/thumbnail/${encodeURIComponent(p.name)}.png`, loading: "lazy", alt: "" }),
      p.name);
    item.dataset.name = p.name;
    item.onclick = () => openPreset(p.name);
    box.append(item);
  }
}

async function openPreset(name) {
  if (state && state.dirty && !confirm(`Discard the unsaved changes to ${state.name}?`)) return;
  try {
    target = null;
    await refresh(await api("api/open", { name }));
    say(`opened ${name}`);
  } catch (e) { say(e.message, true); }
}

async function loadLibrary() {
  library = await api("api/library");
  const models = [...new Set(library.map((p) => p.model).filter(Boolean))].sort();
  const tags = [...new Set(library.flatMap((p) => p.tags))].sort();
  for (const m of models) $("filter-model").append(el("option", { value: m, textContent: m }));
  for (const t of tags) $("filter-tag").append(el("option", { value: t, textContent: t }));
  for (const p of library) {
    if (p.model && p.model !== "layered") $("add-preset").append(el("option", { value: p.name, textContent: p.name }));
  }
  drawLibrary();
}

// -- explorer, losses, tasks -------------------------------------------------------------
function drawPlot() {
  $("plot").src = `api/plot/${plotView}.png?v=${state.version}`;
}

async function drawLosses() {
  const table = $("losses");
  try {
    const losses = await api("api/losses");
    table.replaceChildren(...Object.entries(losses).map(([ctx, note]) =>
      el("tr", {}, el("td", { textContent: ctx }), el("td", { textContent: note || "nothing lost" }))));
  } catch (e) {
    table.replaceChildren(el("tr", {}, el("td", { textContent: e.message })));
  }
}

async function pollTask(task) {
  const line = el("div", { textContent: `proof ${task.name}: ${task.state}` });
  $("tasks").append(line);
  for (;;) {
    const s = await api(`api/task/${task.id}`);
    line.textContent = `proof ${s.name}: ${s.state}` + (s.error ? ` — ${s.error}` : "");
    if (s.state === "done") {
      line.append(" ", el("a", { href: s.page, target: "_blank", textContent: "review page" }));
      return;
    }
    if (s.state === "failed" || s.state === "unknown") return;
    await new Promise((r) => setTimeout(r, 2000));
  }
}

// -- viewport ----------------------------------------------------------------------------
function paint() {
  const canvas = $("viewport");
  const a = frames.A;
  if (!a) return;
  if (canvas.width !== a.width) { canvas.width = a.width; canvas.height = a.height; }
  const ctx = canvas.getContext("2d");
  ctx.drawImage(a, 0, 0);
  if ($("ab").checked && frames.B) {
    const x = Math.round(split * canvas.width);
    ctx.drawImage(frames.B, x, 0, canvas.width - x, canvas.height, x, 0, canvas.width - x, canvas.height);
    ctx.fillStyle = "#fff";
    ctx.fillRect(x, 0, 1, canvas.height);
  }
}

function connect() {
  const url = location.href.replace(/^http/, "ws").replace(/[?#].*$/, "").replace(/\/?$/, "/") + "ws";
  ws = new WebSocket(url);
  ws.binaryType = "blob";
  ws.onmessage = async (ev) => {
    if (typeof ev.data === "string") {
      const m = JSON.parse(ev.data);
      if (m.type === "frame") pendingMeta = m;
      else if (m.type === "state" && state && m.version !== state.version) refresh();
      else if (m.type === "error") say(`renderer: ${m.error}`, true);
      return;
    }
    const m = pendingMeta;
    const bitmap = await createImageBitmap(ev.data);
    frames[m.view] = bitmap;
    if (m.view === "A") {
      $("frame-info").textContent = `${m.mode} · ${m.spp} spp · ${m.denoised ? "denoised" : "raw"}` +
        `${m.converged ? " · converged" : ""} · ${m.ms} ms`;
      $("viewport").dataset.frames = String(Number($("viewport").dataset.frames || 0) + 1);
    }
    paint();
  };
  ws.onclose = () => { say("connection to the designer closed", true); };
}

function sendView(message) {
  if (ws && ws.readyState === WebSocket.OPEN) ws.send(JSON.stringify(message));
}

function setupViewport() {
  const canvas = $("viewport");
  const angle = { rotate_ibl: 0, rotate_element: 0 };
  let drag = null;
  canvas.onpointerdown = (e) => {
    drag = { x: e.clientX, start: angle[$("drag").value], key: $("drag").value };
    canvas.setPointerCapture(e.pointerId);
  };
  canvas.onpointermove = (e) => {
    if (!drag) return;
    if ($("ab").checked && e.shiftKey) {
      split = Math.min(1, Math.max(0, e.offsetX / canvas.clientWidth));
      paint();
      return;
    }
    angle[drag.key] = drag.start + (e.clientX - drag.x) * 0.5;
    sendView({ [drag.key]: angle[drag.key] });
  };
  canvas.onpointerup = () => { drag = null; };
  $("exposure").oninput = () => sendView({ exposure: Number($("exposure").value) });
  $("mode").onchange = () => sendView({ mode: $("mode").value });
  $("raw").onchange = () => sendView({ raw: $("raw").checked });
  $("ab").onchange = () => { sendView({ ab: $("ab").checked }); paint(); };
  $("ab-against").onchange = () => sendView({ ab_against: $("ab-against").value });
}

// -- wiring ------------------------------------------------------------------------------
function setup() {
  $("undo").onclick = async () => refresh(await api("api/undo", {}));
  $("redo").onclick = async () => refresh(await api("api/redo", {}));
  $("save-new").onclick = async () => {
    try {
      const r = await api("api/save", { mode: "new", name: $("save-name").value.trim() });
      say(`saved ${r.name} to ${r.saved}`);
      await refresh();
    } catch (e) { say(e.message, true); }
  };
  $("save-over").onclick = async () => {
    try {
      const r = await api("api/save", { mode: "over" });
      say(`saved ${r.saved}`);
      await refresh();
    } catch (e) { say(e.message, true); }
  };
  $("new-layered").onclick = async () => {
    try {
      target = 0;
      await refresh(await api("api/new_layered", { name: $("save-name").value.trim() || "untitled" }));
    } catch (e) { say(e.message, true); }
  };
  $("proof").onclick = async () => {
    try { pollTask(await api("api/proof", {})); } catch (e) { say(e.message, true); }
  };
  $("export").onclick = async () => {
    try {
      const r = await api("api/export_usd", {});
      $("tasks").append(el("div", {}, "USD: ", el("a", { href: r.file, textContent: r.file, download: "" })));
    } catch (e) { say(e.message, true); }
  };
  $("add-layer-btn").onclick = addLayer;
  for (const id of ["search", "filter-model", "filter-tag"]) $(id).oninput = drawLibrary;
  for (const v of meta.plot_views) {
    const b = el("button", { textContent: v, onclick: () => {
      plotView = v;
      for (const x of $("plot-tabs").children) x.classList.toggle("on", x === b);
      drawPlot();
    } });
    b.classList.toggle("on", v === plotView);
    $("plot-tabs").append(b);
  }
  for (const k of ["none", ...Object.keys(meta.masks)]) {
    $("add-mask-kind").append(el("option", { value: k, textContent: k === "none" ? "no mask" : `${k} mask` }));
  }
  document.addEventListener("keydown", (e) => {
    if ((e.ctrlKey || e.metaKey) && e.key.toLowerCase() === "z") {
      e.preventDefault();
      $(e.shiftKey ? "redo" : "undo").click();
    }
  });
  window.addEventListener("beforeunload", (e) => {
    if (state && state.dirty) { e.preventDefault(); e.returnValue = ""; }
  });
  setupViewport();
}

(async () => {
  meta = await api("api/meta");
  images = await api("api/images");
  setup();
  await refresh();
  connect();
  await loadLibrary();
})();
