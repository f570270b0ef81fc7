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
let openMasks = new Set(); // layers whose mask editor is unfolded
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
    // linear working-space values (what the model takes) and their sRGB hex (what a
    // picker shows); the server converts both ways, so the page holds no colour formula
    const rgb = Array.isArray(value) ? value : c.default;
    const hex = (t.hex || {})[c.name] || "#000000";
    const picker = el("input", { type: "color", value: hex, title: "pick an sRGB colour", name: "picker" });
    picker.onchange = () => send(picker.value, "picker");
    const hexBox = el("input", { value: hex, name: "hex", size: 7, title: "sRGB hex (#rrggbb)", className: "hex" });
    hexBox.onchange = () => send(hexBox.value.trim(), "hex");
    const inputs = rgb.map((x, i) => el("input", {
      type: "number", step: "any", value: x, name: `c${i}`, title: `linear ${"rgb"[i]}`,
    }));
    for (const inp of inputs) {
      inp.onchange = () => send(inputs.map((i) => Number(i.value)), inp.name);
    }
    row.append(picker, hexBox, el("span", { className: "unit", textContent: "linear" }), ...inputs);
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
      onclick: () => pickFile((ref) => edit({ op: "set", target: t.index, field: c.name, value: { texture: ref } })
        .then((m) => m && say(m, true))),
    }));
  }
  wrap.append(row, error);
  return wrap;
}

function textureRow(c, t, tex) {
  // the map driving a parameter: its file, channel, colour space and the rest of the
  // texture input's schema, a preview of the channel read, and "constant" to drop it
  const box = el("div", { className: "map-editor" });
  const error = el("div", { className: "error" });
  const commit = async (v, input) => {
    const message = await edit({ op: "set", target: t.index, field: c.name, value: v });
    if (message) { error.textContent = message; if (input) input.classList.add("invalid"); }
  };
  const constant = Array.isArray(c.default) || typeof c.default === "number" ? c.default : 0.5;
  const head = el("div", { className: "row" });
  if (!String(tex.texture).includes("<UDIM>")) head.append(preview(t.index, c.name));
  head.append(el("button", {
    textContent: "constant", title: "Replace the map by a constant (the default)",
    onclick: () => commit(constant),
  }));
  box.append(head, form(meta.texture_fields, tex, commit), error);
  return box;
}

function preview(target, field) {
  const q = `target=${target === null ? "" : target}&field=${encodeURIComponent(field)}&v=${state.version}`;
  return el("img", { className: "preview", src: `api/preview.png?${q}`, alt: `${field} preview`,
    title: "as the blend reads it: 0 black, 1 white" });
}

// -- forms from the server's field descriptors (controls.form_field) ---------------------
// `value` is the object edited; `commit(next, input)` sends the whole new object and
// shows a refusal beside the form (nothing is applied then).
function form(fields, value, commit) {
  const box = el("div", { className: "form" });
  for (const f of fields) {
    const row = el("div", { className: "frow", title: f.doc });
    row.dataset.name = f.name;
    const set = (v, input) => {
      const next = Object.assign({}, value);
      if (v === undefined) delete next[f.name]; else next[f.name] = v;
      commit(next, input);
    };
    row.append(el("label", { textContent: f.title }), field(f, value[f.name], set));
    box.append(row);
  }
  return box;
}

function numberOrText(text) {
  const x = text.trim();
  return x === "" ? undefined : (Number.isNaN(Number(x)) ? x : Number(x));
}

function field(f, cur, set) {
  const shown = cur ?? f.default;
  if (f.kind === "number" || f.kind === "channel" || f.kind === "text") {
    const inp = el("input", { value: shown ?? "", name: f.name, size: 8,
      placeholder: f.kind === "channel" ? "index or name" : "" });
    if (f.kind === "number") Object.assign(inp, { type: "number", step: f.integer ? 1 : "any" });
    if (f.min !== null && f.min !== undefined) inp.min = f.min;
    if (f.max !== null && f.max !== undefined) inp.max = f.max;
    inp.onchange = () => set(f.kind === "text" ? inp.value : numberOrText(inp.value), inp);
    return inp;
  }
  if (f.kind === "switch") {
    const inp = el("input", { type: "checkbox", checked: !!shown, name: f.name });
    inp.onchange = () => set(inp.checked, inp);
    return inp;
  }
  if (f.kind === "choice" || f.kind === "space") {
    const sel = el("select", { name: f.name });
    if (f.optional) sel.append(el("option", { value: "", textContent: f.kind === "space" ? "by file rule" : "—" }));
    for (const ch of f.choices) sel.append(el("option", { value: ch, textContent: ch, selected: ch === shown }));
    sel.onchange = () => set(sel.value === "" ? undefined : sel.value, sel);
    return sel;
  }
  if (f.kind === "pair") {
    const span = el("span", { className: "pair" });
    const vals = Array.isArray(shown) ? shown : [];
    const inputs = [0, 1].map((i) => el("input", { type: "number", step: "any", value: vals[i] ?? "",
      name: `${f.name}${i}`, size: 5 }));
    for (const inp of inputs) {
      inp.onchange = () => {
        const v = inputs.map((x) => numberOrText(x.value));
        set(v.every((x) => x === undefined) ? undefined : v, inp);
      };
    }
    span.append(...inputs);
    return span;
  }
  if (f.kind === "file") {
    const span = el("span", { className: "file" });
    const name = typeof cur === "string" ? cur : (cur ? `${cur.root}/${cur.path}` : "no file");
    span.append(el("code", { textContent: name.split("/").pop(), title: name }),
      el("button", { textContent: "choose…", name: `${f.name}-choose`,
        title: "Pick an image from the library folders", onclick: () => pickFile((ref) => set(ref)) }));
    return span;
  }
  if (f.kind === "mask") return maskEditor(cur, (m) => set(m));
  if (f.kind === "masks") {
    const list = el("div", { className: "masks" });
    const items = Array.isArray(cur) ? cur : [];
    items.forEach((m, i) => {
      const drop = el("button", { textContent: "✕", title: "remove this input", disabled: items.length <= (f.min_items || 0),
        onclick: () => set(items.filter((_, k) => k !== i)) });
      list.append(el("div", { className: "mask-item" },
        maskEditor(m, (v) => set(items.map((x, k) => (k === i ? v : x)))), drop));
    });
    list.append(el("button", { textContent: "+ input", onclick: () => set([...items, { kind: "constant", value: 1 }]) }));
    return list;
  }
  return el("span", { textContent: JSON.stringify(cur) });
}

// -- the file picker: folders of the library path and the session, through the server ----
function pickFile(onPick, where = {}) {
  const old = document.getElementById("picker");
  if (old) old.remove();
  const dialog = el("div", { id: "picker", role: "dialog" });
  const close = el("button", { textContent: "close", onclick: () => dialog.remove() });
  dialog.append(el("p", { textContent: "reading the library folders…" }), close);
  document.body.append(dialog);
  const show = async (root, path) => {
    let listing;
    try {
      listing = await api(`api/browse?root=${encodeURIComponent(root || "")}&path=${encodeURIComponent(path || "")}`);
    } catch (e) { dialog.replaceChildren(el("p", { className: "error", textContent: e.message }), close); return; }
    const roots = el("select", { name: "root" });
    for (const r of listing.roots) roots.append(el("option", { value: r, textContent: r, selected: r === listing.root }));
    roots.onchange = () => show(roots.value, "");
    const entries = el("ul");
    if (listing.up !== null) {
      entries.append(el("li", { className: "dir" }, el("button", { textContent: "⬑ ..", onclick: () => show(listing.root, listing.up) })));
    }
    for (const d of listing.dirs) {
      entries.append(el("li", { className: "dir" }, el("button", { textContent: `▸ ${d.split("/").pop()}/`,
        onclick: () => show(listing.root, d) })));
    }
    for (const f of listing.files) {
      const b = el("button", { textContent: f.split("/").pop(), className: "pick", title: `${listing.root}/${f}`,
        onclick: () => { dialog.remove(); onPick({ root: listing.root, path: f }); } });
      b.dataset.path = f;
      entries.append(el("li", {}, b));
    }
    if (!listing.dirs.length && !listing.files.length) entries.append(el("li", { textContent: "no images here" }));
    dialog.replaceChildren(el("div", { className: "row" }, el("strong", { textContent: "Choose an image" }), roots,
      el("code", { textContent: `/${listing.path}` }), close), entries);
  };
  show(where.root, where.path);
}

// -- layers ------------------------------------------------------------------------------
function asMask(m) {
  if (m === undefined || m === null) return { kind: "constant", value: 1 };
  return typeof m === "number" ? { kind: "constant", value: m } : m;
}

function maskSummary(m) {
  m = asMask(m);
  if (m.kind === "constant") return `constant ${m.value ?? 1}`;
  if (m.kind === "texture") return `texture ${m.path}${m.invert ? " (inverted)" : ""}`;
  const inner = m.input ? ` of ${maskSummary(m.input)}` : (m.inputs ? ` of ${m.inputs.length}` : "");
  return m.kind + inner;
}

// A mask of any kind with its schema's fields; a kind that wraps others (invert, levels,
// multiply, …) keeps the mask it replaces as its input, so masks are built up in place.
function maskEditor(mask, commit) {
  mask = asMask(mask);
  const box = el("div", { className: "mask-editor" });
  const kind = el("select", { name: "mask-kind", title: meta.masks[mask.kind]?.doc || "" });
  for (const k of Object.keys(meta.masks)) kind.append(el("option", { value: k, textContent: k, selected: k === mask.kind }));
  kind.onchange = () => {
    const k = kind.value;
    const fields = meta.masks[k].fields;
    const next = { kind: k };
    if (fields.some((f) => f.kind === "mask")) next.input = mask;
    if (fields.some((f) => f.kind === "masks")) next.inputs = [mask];
    if (fields.some((f) => f.kind === "file" && f.required)) {
      pickFile((ref) => commit(Object.assign(next, { path: ref })));
      kind.value = mask.kind; // unchanged until an image is chosen
      return;
    }
    commit(next);
  };
  box.append(el("div", { className: "row" }, el("label", { textContent: "kind" }), kind),
    form(meta.masks[mask.kind].fields, mask, commit));
  return box;
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
      className: "layer-name", textContent: ` ${i}: ${la.name || la.preset || la.model}`,
      onclick: () => { target = i; refresh(state); },
    });
    const up = el("button", { textContent: "↑", disabled: i === layers.length - 1, title: "move up",
      onclick: () => edit({ op: "layer_move", index: i, to: i + 1 }) });
    const down = el("button", { textContent: "↓", disabled: i === 0, title: "move down",
      onclick: () => edit({ op: "layer_move", index: i, to: i - 1 }) });
    const del = el("button", { textContent: "✕", title: "delete the layer",
      onclick: () => edit({ op: "layer_remove", index: i }) });
    const error = el("div", { className: "error" });
    const presence = el("input", { type: "number", step: "any", value: la.presence ?? 1, title:
      "presence (Pixar layers: opacity, 0..1)", style: "width:56px" });
    presence.onchange = async () => {
      const message = await edit({ op: "layer_presence", index: i, value: Number(presence.value) });
      if (message) { error.textContent = message; presence.classList.add("invalid"); }
    };
    const pixar = (state.targets[i] || {}).model === "pixar";
    const mask = el("details", { className: "mask", open: openMasks.has(i) });
    mask.ontoggle = () => (mask.open ? openMasks.add(i) : openMasks.delete(i));
    const commit = async (m, input) => {
      const message = await edit({ op: "layer_mask", index: i, mask: m });
      if (message) {
        const shown = list.querySelector(`li[data-index="${i}"] .error`) || error;
        shown.textContent = message;
        if (input) input.classList.add("invalid");
      }
    };
    mask.append(el("summary", {}, preview(i, "mask"), el("span", { textContent: ` mask: ${maskSummary(la.mask)}` })),
      maskEditor(la.mask, commit));
    li.append(el("div", { className: "row" }, eye, label, up, down, del, ...(pixar ? [" presence ", presence] : [])),
      mask, error);
    list.append(li);
  }
}

async function addLayer() {
  const preset = $("add-preset").value;
  const message = await edit({ op: "layer_add", preset });
  if (message) { say(message, true); return; }
  openMasks.add(state.doc.layers.length - 1); // the new layer's mask editor, ready to use
  drawLayers();
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
      say([`saved ${r.name} to ${r.saved}`, ...r.copied].join("; "));
      await refresh();
    } catch (e) { say(e.message, true); }
  };
  $("save-over").onclick = async () => {
    try {
      const r = await api("api/save", { mode: "over" });
      say([`saved ${r.saved}`, ...r.copied].join("; "));
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
  setup();
  await refresh();
  connect();
  await loadLibrary();
})();
