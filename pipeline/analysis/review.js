/* lookdev review page: turntable players, a synchronised comparison, raw/denoised.
 *
 * Static and offline: the batch is the JSON in #lookdev-data (written by
 * lookdev.pipeline.analysis.review). Every text enters the page through text nodes,
 * never as HTML: material and IBL names are user input. No framework, no network.
 */
"use strict";
(function () {
  const data = JSON.parse(document.getElementById("lookdev-data").textContent);
  const FPS = 6;
  const hasDenoised = data.proofs.some((p) => p.frames.some((f) => f.denoised));
  // a batch that was denoised (the main job's default) opens on the denoised frames
  const state = { denoised: hasDenoised, difference: false };
  const views = []; // everything that shows frames: redrawn when the toggle changes

  function el(tag, attrs, ...children) {
    const e = document.createElement(tag);
    for (const [k, v] of Object.entries(attrs || {})) {
      if (v === null || v === undefined || v === false) continue;
      if (k === "class") e.className = v;
      else if (k.startsWith("on")) e.addEventListener(k.slice(2), v);
      else e.setAttribute(k, v === true ? "" : String(v));
    }
    for (const c of children) {
      if (c === null || c === undefined) continue;
      e.append(c instanceof Node ? c : String(c)); // a string becomes a text node
    }
    return e;
  }

  function num(v, digits) {
    if (v === null || v === undefined) return "–";
    if (typeof v !== "number") return String(v);
    return Number.isInteger(v) ? String(v) : String(Number(v.toPrecision(digits || 3)));
  }

  function percent(v) {
    return v === null || v === undefined ? null : num(100 * v, 2) + " %";
  }

  /* A frame in words a look-dev artist reads: did it converge, how noisy, how long. */
  function statsText(f) {
    const noise = percent(f.noise), target = percent(f.noise_target);
    const samples = f.spp === null ? null : num(f.spp) + " samples per pixel";
    const time = f.time_s === null ? null : num(f.time_s) + " s";
    const noiseText = noise === null ? "noise not recorded" : "noise " + noise +
      (target === null ? "" : " (target " + target + ")");
    let head;
    if (f.stop === "target") head = "Converged: " + noiseText;
    else if (f.stop === "max_spp") head = "Not converged: " + noiseText + " at the sample cap";
    else if (f.stop === "time_budget") head = "Not converged: " + noiseText + " when the time budget ran out";
    else if (f.stop === "spp") head = "Fixed sample count (no noise target): " + noiseText;
    else head = noiseText;
    return [head, samples, time].filter(Boolean).join(", ") + ".";
  }

  /* The numbers behind the caption, for whoever asks (inside "details"). */
  function detailText(f) {
    const parts = [];
    if (f.firefly_share !== null)
      parts.push("the brightest 0.1 % of pixels hold " + num(100 * f.firefly_share, 2) +
        " % of the remaining error" + (f.firefly_share > 0.5 ? " (fireflies)" : ""));
    parts.push(f.clamp === null ? "radiance not clamped" : "radiance clamped at " + num(f.clamp) + " (biased)");
    if (f.residual !== undefined && f.residual !== null)
      parts.push("denoised residual " + num(f.residual) + " (raw noise " + num(f.noise_raw) + ")");
    if (f.converged !== undefined && f.converged !== null)
      parts.push(num(100 * f.converged, 4) + " % of pixels met the target");
    if (f.stop !== null) parts.push("stopped by: " + f.stop);
    return parts.join("; ");
  }

  /* What a turntable shows: how many frames turn the element, how many the light. */
  function turnText(frames) {
    const count = (kind) => frames.filter((f) => f.kind === kind).length;
    const element = count("element"), light = count("light");
    if (!element && !light) return frames.length + " frames";
    return [element ? element + " frames turning the object" : null,
      light ? light + " turning the light" : null].filter(Boolean).join(", ");
  }

  /* Frames are fetched once by a cached Image and put on screen only when loaded: the
   * shown image then never has a load pending that the next frame would abort, and a
   * playing turntable does not flicker. */
  const cache = new Map();
  function setFrame(img, src) {
    img.dataset.want = src;
    if (img.dataset.lazy === "wait") return; // not scrolled to yet: nothing fetched
    if (img.getAttribute("src") === src) return;
    let pre = cache.get(src);
    if (!pre) {
      pre = new Image();
      pre.src = src;
      cache.set(src, pre);
    }
    const put = () => { if (img.dataset.want === src) img.src = src; };
    if (pre.complete) put();
    else {
      pre.addEventListener("load", put, { once: true });
      pre.addEventListener("error", put, { once: true }); // shown broken: a test sees it
    }
  }

  function source(f) {
    if (state.difference && f.difference) return { src: f.difference, which: "difference" };
    const denoised = state.denoised && f.denoised;
    return { src: denoised ? f.denoised : f.raw, which: denoised ? "denoised" : "raw" };
  }

  /* Players fetch their frames when first scrolled near the view: a batch of many proofs
   * opens at once and loads only what is looked at. */
  const watcher = "IntersectionObserver" in window
    ? new IntersectionObserver((seen) => {
      for (const e of seen) {
        if (!e.isIntersecting) continue;
        watcher.unobserve(e.target);
        e.target.lookdevSeen();
      }
    }, { rootMargin: "200px 0px" })
    : null;
  function whenSeen(node, load) {
    if (watcher === null) { load(); return; }
    node.lookdevSeen = load;
    watcher.observe(node);
  }

  /* A clock stepping a view's frame at FPS while playing. */
  function clock(step, button) {
    let timer = null;
    const c = {
      get playing() { return timer !== null; },
      play() {
        if (timer !== null) return;
        timer = setInterval(step, 1000 / FPS);
        button.textContent = "❚❚ pause";
        button.setAttribute("aria-pressed", "true");
      },
      pause() {
        if (timer === null) return;
        clearInterval(timer);
        timer = null;
        button.textContent = "▶ play";
        button.setAttribute("aria-pressed", "false");
      },
      toggle() { c.playing ? c.pause() : c.play(); },
    };
    button.addEventListener("click", c.toggle);
    return c;
  }

  /* Segments of a turntable: all frames, the element turn, the light turn. */
  function segments(frames) {
    const out = { all: [0, frames.length - 1] };
    for (const kind of ["element", "light"]) {
      const idx = frames.map((f, i) => (f.kind === kind ? i : -1)).filter((i) => i >= 0);
      if (idx.length) out[kind] = [idx[0], idx[idx.length - 1]];
    }
    return out;
  }

  /* A frame's image, its shape held before it is fetched, so the page does not move as
   * frames arrive (and players further down stay unfetched until scrolled to). */
  function frameImage(proof, attrs) {
    return el("img", { class: "frame", ...attrs });
  }
  function stage(proof, img, which) {
    const box = el("div", { class: "stage" }, img, which);
    const [w, h] = proof.size || [2, 1];
    box.style.aspectRatio = w + " / " + h;
    return box;
  }

  /* One proof's turntable player. */
  function player(proof) {
    const frames = proof.frames;
    const img = frameImage(proof, { alt: proof.material + " under " + proof.ibl,
      "data-lazy": "wait" });
    const which = el("span", { class: "which" });
    const label = el("span", { class: "label" });
    const stats = el("div", { class: "stats" });
    const detail = el("div", { class: "detail" });
    const scrub = el("input", {
      type: "range", class: "scrub", min: 0, max: Math.max(0, frames.length - 1), value: 0,
      "aria-label": "frame of " + proof.id,
    });
    const play = el("button", { type: "button", class: "play", "aria-pressed": "false" }, "▶ play");
    const segs = segments(frames);
    const loop = el("select", { class: "segment", "aria-label": "which turn" });
    for (const [key, text] of [["all", "both turns"], ["element", "element turn"], ["light", "light turn"]])
      if (segs[key]) loop.append(el("option", { value: key }, text));
    const rows = frames.map((f, i) =>
      el("tr", { "data-index": i, onclick: () => { p.clock.pause(); p.show(i); } },
        el("td", {}, f.label), el("td", {}, num(f.spp)), el("td", {}, num(f.noise)),
        el("td", {}, num(f.noise_target)), el("td", {}, num(f.time_s)),
        el("td", {}, f.stop === null ? "–" : f.stop),
        el("td", {}, f.firefly_share === null ? "–" : num(100 * f.firefly_share, 2) + " %"),
        el("td", {}, f.clamp === null ? "none" : num(f.clamp))));
    const table = el("details", { class: "frames" }, el("summary", {}, "every frame"),
      el("table", {},
        el("thead", {}, el("tr", {}, ...["frame", "spp", "noise", "target", "time s", "stop",
          "hottest 0.1 %", "clamp"].map((h) => el("th", {}, h)))),
        el("tbody", {}, ...rows)));
    const p = {
      proof, img, scrub, index: 0,
      show(i) {
        if (!frames.length) return;
        p.index = Math.min(Math.max(0, i), frames.length - 1);
        const f = frames[p.index];
        const s = source(f);
        setFrame(img, s.src);
        img.dataset.which = s.which;
        which.textContent = s.which;
        which.className = "which " + s.which;
        scrub.value = String(p.index);
        label.textContent = f.label + "  (" + (p.index + 1) + "/" + frames.length + ")";
        stats.textContent = statsText(f);
        detail.textContent = detailText(f);
        rows.forEach((r, k) => r.classList.toggle("current", k === p.index));
      },
      redraw() { p.show(p.index); },
    };
    p.clock = clock(() => {
      const [a, b] = segs[loop.value] || segs.all;
      p.show(p.index >= b || p.index < a ? a : p.index + 1);
    }, play);
    scrub.addEventListener("input", () => { p.clock.pause(); p.show(Number(scrub.value)); });
    loop.addEventListener("change", () => p.show((segs[loop.value] || segs.all)[0]));
    const info = [proof.filter ? "pixel filter " + proof.filter : "pixel filter not recorded",
      proof.rig ? "calibration rig: " + proof.rig : null,
      proof.variant ? "Mitsuba variant " + proof.variant : null].filter(Boolean).join("; ");
    p.node = el("div", { class: "player", "data-proof": proof.id },
      el("h3", {}, proof.material + " under " + proof.ibl),
      el("div", { class: "what" }, "Turntable: " + turnText(frames)),
      stage(proof, img, which),
      el("div", { class: "controls" }, play, scrub, loop, label),
      stats,
      el("details", { class: "more" }, el("summary", {}, "details"),
        detail, el("div", { class: "meta" }, info), table));
    views.push(p);
    if (!frames.length) p.node.append(el("p", { class: "none" }, "no frames on disk"));
    p.show(0);
    whenSeen(p.node, () => { delete img.dataset.lazy; p.redraw(); });
    return p;
  }

  /* The comparison: all materials under one IBL, or one material under every IBL. */
  function comparison() {
    const materials = [...new Set(data.proofs.map((p) => p.material))];
    const mode = el("select", { id: "compare-mode", "aria-label": "compare" },
      el("option", { value: "ibl" }, "all materials under one IBL"),
      el("option", { value: "material" }, "one material under every IBL"));
    const pick = el("select", { id: "compare-pick", "aria-label": "which" });
    const play = el("button", { type: "button", id: "compare-play", "aria-pressed": "false" }, "▶ play");
    const scrub = el("input", { type: "range", id: "compare-scrub", min: 0, max: 0, value: 0,
      "aria-label": "frame" });
    const label = el("span", { class: "label" });
    const grid = el("div", { class: "grid", id: "compare-grid" });
    let cells = [];
    const c = {
      index: 0,
      fill() {
        const chosen = pick.value;
        pick.replaceChildren(...(mode.value === "ibl" ? data.ibls : materials).map((v) =>
          el("option", { value: v }, v)));
        if ([...pick.options].some((o) => o.value === chosen)) pick.value = chosen;
        c.build();
      },
      build() {
        const proofs = data.proofs.filter((p) =>
          mode.value === "ibl" ? p.ibl === pick.value : p.material === pick.value);
        cells = proofs.map((proof) => {
          const img = frameImage(proof, { alt: proof.id });
          const stats = el("div", { class: "stats" });
          const which = el("span", { class: "which" });
          const caption = mode.value === "ibl" ? proof.material : proof.ibl;
          const node = el("figure", { "data-proof": proof.id },
            stage(proof, img, which), el("figcaption", {}, caption), stats);
          return { proof, img, stats, which, node };
        });
        grid.replaceChildren(...cells.map((x) => x.node));
        if (!cells.length) grid.append(el("p", { class: "none" }, "no proofs to compare"));
        const longest = Math.max(1, ...cells.map((x) => x.proof.frames.length));
        scrub.max = String(longest - 1);
        c.show(Math.min(c.index, longest - 1));
      },
      show(i) {
        c.index = Math.max(0, i);
        scrub.value = String(c.index);
        let text = "";
        for (const x of cells) {
          const frames = x.proof.frames;
          if (!frames.length) continue;
          const f = frames[Math.min(c.index, frames.length - 1)];
          const s = source(f);
          setFrame(x.img, s.src);
          x.img.dataset.which = s.which;
          x.which.textContent = s.which;
          x.which.className = "which " + s.which;
          x.stats.textContent = statsText(f);
          text = f.label;
        }
        label.textContent = text + "  (" + (c.index + 1) + "/" + (Number(scrub.max) + 1) + ")";
      },
      redraw() { c.show(c.index); },
    };
    c.clock = clock(() => c.show(c.index >= Number(scrub.max) ? 0 : c.index + 1), play);
    scrub.addEventListener("input", () => { c.clock.pause(); c.show(Number(scrub.value)); });
    mode.addEventListener("change", c.fill);
    pick.addEventListener("change", c.build);
    views.push(c);
    const orientation = (data.proofs.find((p) => p.orientation) || {}).orientation;
    const convention = orientation
      ? el("details", { class: "meta" }, el("summary", {}, "IBL orientation"),
        ...Object.entries(orientation).map(([k, v]) => el("div", {}, k + ": " + v)))
      : null;
    c.node = el("section", { id: "compare" }, el("h2", {}, "Compare"),
      el("div", { class: "controls" }, mode, pick, play, scrub, label), grid, convention);
    c.fill();
    return c;
  }

  function materialInfo(name) {
    const info = data.materials[name];
    const box = el("div", { class: "info" });
    if (!info) {
      box.append(el("p", { class: "none" },
        "parameters, source and USD loss notes: not recorded by this batch"));
      return box;
    }
    if (info.description) box.append(el("p", {}, info.description));
    const src = info.source || {};
    box.append(el("p", {}, "model ", el("b", {}, info.model || "–"),
      " · live lobes: ", (info.live_lobes || []).join(", ") || "none"));
    box.append(el("p", {}, "source: ", el("code", {}, src.file || "not recorded"),
      (src.extends || []).length ? " (extends " + src.extends.join(", ") + ")" : null));
    if (src.citation) box.append(el("p", { class: "citation" }, src.citation));
    const params = Object.entries(info.parameters || {}).map(([k, v]) =>
      el("tr", {}, el("td", {}, k), el("td", {}, Array.isArray(v) ? v.map((x) => num(x, 4)).join(", ") : num(v, 4))));
    for (const [k, m] of Object.entries(info.maps || {}))
      params.push(el("tr", {}, el("td", {}, k),
        el("td", {}, "map " + m.size.join("×") + ", " + JSON.stringify(m.min) + " … " + JSON.stringify(m.max))));
    box.append(el("details", { class: "params" }, el("summary", {}, "resolved parameters (" + params.length + ")"),
      el("table", {}, el("tbody", {}, ...params))));
    const losses = info.usd_losses;
    const lossBox = el("div", { class: "losses" }, el("h4", {}, "exported to USD, what is lost"));
    if (!losses) {
      lossBox.append(el("p", { class: "none" }, info.usd_losses_error || "not known to this batch"));
    } else {
      const lost = Object.entries(losses).filter(([, note]) => note);
      if (!lost.length) lossBox.append(el("p", {}, "none: every render context expresses it"));
      for (const [context, note] of lost) lossBox.append(el("p", {}, el("b", {}, context + ": "), note));
    }
    box.append(lossBox);
    return box;
  }

  const materialNames = [...new Set(data.proofs.map((p) => p.material))];
  const sectionId = (i) => "material-" + i; // names are user input: ids are indices

  /* A table of contents of the materials, and a filter by name over it and the page. */
  function contents() {
    const filter = el("input", { type: "search", id: "filter", placeholder: "filter materials",
      "aria-label": "filter materials by name" });
    const items = materialNames.map((name, i) =>
      el("li", { "data-material": name }, el("a", { href: "#" + sectionId(i) }, name)));
    const count = el("span", { class: "note", id: "filter-count" });
    const apply = () => {
      const want = filter.value.trim().toLowerCase();
      let shown = 0;
      materialNames.forEach((name, i) => {
        const hit = !want || name.toLowerCase().includes(want);
        items[i].hidden = !hit;
        document.getElementById(sectionId(i)).hidden = !hit;
        shown += hit;
      });
      count.textContent = shown + " of " + materialNames.length + " materials";
    };
    filter.addEventListener("input", apply);
    const nav = el("nav", { id: "toc", "aria-label": "materials" },
      el("div", { class: "controls" }, filter, count), el("ol", {}, ...items));
    return { node: nav, apply };
  }

  function materials() {
    const root = el("section", { id: "materials" });
    for (const [i, name] of materialNames.entries()) {
      const section = el("section", { class: "material", id: sectionId(i), "data-material": name },
        el("h2", {}, name), materialInfo(name));
      const plots = data.plots[name];
      if (plots) section.append(el("div", { class: "plots" },
        ...Object.entries(plots).map(([view, src]) => el("img", { src, alt: name + " " + view }))));
      const row = el("div", { class: "players" });
      for (const proof of data.proofs.filter((p) => p.material === name)) row.append(player(proof).node);
      section.append(row);
      root.append(section);
    }
    return root;
  }

  function toolbar() {
    const box = el("input", {
      type: "checkbox", id: "denoised", disabled: !hasDenoised, checked: state.denoised,
    });
    box.addEventListener("change", () => {
      state.denoised = box.checked;
      views.forEach((v) => v.redraw());
    });
    const note = hasDenoised
      ? "denoised frames where the proof has them; switch off to check the raw frame"
      : "this batch has no denoised frames";
    return el("div", { id: "toolbar" }, el("label", {}, box, " show denoised"),
      el("span", { class: "note" }, note), differenceToggle());
  }

  /* What the denoiser changed: 0.5 + 4 × (view(denoised) − view(raw)), grey = unchanged. */
  function differenceToggle() {
    const has = data.proofs.some((p) => p.frames.some((f) => f.difference));
    const box = el("input", { type: "checkbox", id: "difference", disabled: !has });
    box.addEventListener("change", () => {
      state.difference = box.checked;
      views.forEach((v) => v.redraw());
    });
    return el("label", { title: "grey: unchanged; brighter/darker: what denoising added/removed (×4)" },
      box, " show denoised − raw (×4)");
  }

  const main = document.getElementById("review");
  const toc = contents();
  main.append(toolbar(), toc.node, comparison().node, materials());
  toc.apply();
})();
