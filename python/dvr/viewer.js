// dvr.Viewer's view in the browser (an anywidget ES module). The kernel renders and
// sends frames as custom messages with the encoded image as a buffer; this view shows
// each and acknowledges it once shown, and the kernel sends the next only then (frames
// are dropped in the kernel, never queued here). Mouse drags, the wheel and the panel
// go back as messages and synced state.

const SVG = "http://www.w3.org/2000/svg";

function el(tag, attrs = {}, ...children) {
  const e = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs)) {
    if (k === "class") e.className = v;
    else if (k.startsWith("on")) e.addEventListener(k.slice(2), v);
    else e.setAttribute(k, v);
  }
  for (const c of children) e.append(c);
  return e;
}

function select(options, value, onchange, extra = []) {
  const s = el("select", { onchange: () => onchange(s.value) });
  for (const [v, label] of extra.concat(options.map((o) => [o, o]))) {
    const o = el("option", { value: v }, label);
    if (v === value) o.selected = true;
    s.append(o);
  }
  return s;
}

function svgEl(tag, attrs = {}, text = null) {
  const e = document.createElementNS(SVG, tag);
  for (const [k, v] of Object.entries(attrs)) e.setAttribute(k, v);
  if (text !== null) e.textContent = text;
  return e;
}

const clamp01 = (v) => Math.min(1, Math.max(0, v));
const rgb = (c) => `rgb(${(c || [1, 1, 1]).map((v) => Math.round(255 * clamp01(v))).join(",")})`;

// A tick label: `v` with as many decimals as its range needs.
function tickLabel(v, span) {
  const digits = span >= 100 ? 0 : span >= 10 ? 1 : 2;
  return v.toFixed(digits);
}

// The TF editor: the opacity curve of the control points over the density histogram,
// with axes (density 0..1, or the volume's data values where its window maps other
// values to 0..1) and a colour bar (the TF's colour, and that colour at its opacity
// over a checkerboard). Drag a point, double-click to add one, shift-click a point to
// remove it. It always shows the kernel's `tf_points` (the renderer's TF, whoever set
// it); every field of a point (specular, emissive, roughness too) is kept in edits.
// With channels it shows and edits channel `tf_channel`'s TF (density 0..1 over that
// channel's window), and an edit goes to the kernel as a message naming that channel.
function tfEditor(model, uid, send) {
  const W = 210, H = 100, L = 30, T = 6, BAR = 8;
  const VW = L + W + 6, VH = T + H + 4 + 2 * BAR + 26;
  const svg = svgEl("svg", { class: "dvr-tf", viewBox: `0 0 ${VW} ${VH}` });
  let points = [];
  let dragging = -1, stale = false;
  const toX = (d) => L + d * W, toY = (o) => T + H - o * H;
  const fromEvent = (ev) => {
    const p = svg.createSVGPoint();
    p.x = ev.clientX;
    p.y = ev.clientY;
    const q = p.matrixTransform(svg.getScreenCTM().inverse());
    return [clamp01((q.x - L) / W), clamp01((T + H - q.y) / H)];
  };
  const channel = () => (model.get("channels") || [])[model.get("tf_channel")];
  function axes() {
    const win = channel() ? channel().window : (model.get("volume") || {}).window;
    // Data units only where they differ from density: a [0, 1] window is density.
    const data = win && !(win[0] === 0 && win[1] === 1);
    const g = svgEl("g", { class: "dvr-axes" });
    g.append(svgEl("line", { x1: L, y1: T + H, x2: L + W, y2: T + H }));
    g.append(svgEl("line", { x1: L, y1: T, x2: L, y2: T + H }));
    for (const d of [0, 0.25, 0.5, 0.75, 1]) {
      const v = data ? win[0] + d * (win[1] - win[0]) : d;
      g.append(svgEl("line", { x1: toX(d), y1: T + H, x2: toX(d), y2: T + H + 3 }));
      const anchor = d === 0 ? "start" : d === 1 ? "end" : "middle";
      g.append(svgEl("text", { x: toX(d), y: VH - 13, "text-anchor": anchor, class: "dvr-tick" }, tickLabel(v, data ? Math.abs(win[1] - win[0]) : 1)));
    }
    for (const o of [0, 0.5, 1]) {
      g.append(svgEl("line", { x1: L - 3, y1: toY(o), x2: L, y2: toY(o) }));
      g.append(svgEl("text", { x: L - 5, y: toY(o) + 3, "text-anchor": "end", class: "dvr-tick" }, o.toFixed(1)));
    }
    const title = data ? `data value (window ${tickLabel(win[0], win[1] - win[0])} – ${tickLabel(win[1], win[1] - win[0])} → density 0–1)` : "density";
    g.append(svgEl("text", { x: L + W / 2, y: VH - 2, "text-anchor": "middle", class: "dvr-axis-title" }, title));
    g.append(svgEl("text", { x: 8, y: T + H / 2, "text-anchor": "middle", class: "dvr-axis-title", transform: `rotate(-90 8 ${T + H / 2})` }, "opacity"));
    return g;
  }
  function colourBar() {
    // Gradients between the points as the engine interpolates them (linearly in
    // density); before the first and after the last point the end values hold.
    const defs = svgEl("defs");
    const colour = svgEl("linearGradient", { id: `${uid}-c`, x1: 0, x2: 1, y1: 0, y2: 0 });
    const alpha = svgEl("linearGradient", { id: `${uid}-a`, x1: 0, x2: 1, y1: 0, y2: 0 });
    for (const p of points) {
      colour.append(svgEl("stop", { offset: p.density, "stop-color": rgb(p.diffuse) }));
      alpha.append(svgEl("stop", { offset: p.density, "stop-color": rgb(p.diffuse), "stop-opacity": clamp01(p.opacity) }));
    }
    const check = svgEl("pattern", { id: `${uid}-k`, width: 8, height: 8, patternUnits: "userSpaceOnUse" });
    check.append(svgEl("rect", { width: 8, height: 8, fill: "#999" }));
    check.append(svgEl("rect", { width: 4, height: 4, fill: "#555" }));
    check.append(svgEl("rect", { x: 4, y: 4, width: 4, height: 4, fill: "#555" }));
    defs.append(colour, alpha, check);
    const y = T + H + 4;
    const g = svgEl("g", { class: "dvr-colour-bar" });
    g.append(defs);
    g.append(svgEl("rect", { x: L, y, width: W, height: BAR, fill: `url(#${uid}-c)` }));
    g.append(svgEl("rect", { x: L, y: y + BAR, width: W, height: BAR, fill: `url(#${uid}-k)` }));
    g.append(svgEl("rect", { x: L, y: y + BAR, width: W, height: BAR, fill: `url(#${uid}-a)`, class: "dvr-opacity-bar" }));
    return g;
  }
  // The histogram's bins span density 0..1 of the volume's window. With channels the
  // renderer has one histogram, channel 0's (over its data window, at the first time
  // point): it is drawn under channel 0's TF only, placed by that channel's window.
  function histogram() {
    const hist = model.get("histogram") || [];
    const c = channel();
    if (!c) return [hist, 0, 1];
    if (model.get("tf_channel") !== 0) return [[], 0, 1];
    const at = (v) => (v - c.window[0]) / (c.window[1] - c.window[0]);
    return [hist, at(c.data_window[0]), at(c.data_window[1])];
  }
  function draw() {
    svg.replaceChildren();
    const [hist, lo, hi] = histogram();
    const bw = ((hi - lo) * W) / Math.max(1, hist.length);
    svg.append(svgEl("rect", { x: L, y: T, width: W, height: H, class: "dvr-plot" }));
    hist.forEach((h, i) => {
      const x0 = Math.max(L, L + lo * W + i * bw), x1 = Math.min(L + W, L + lo * W + (i + 1) * bw + 0.2);
      if (x1 > x0) svg.append(svgEl("rect", { x: x0, y: T + H - h * H, width: x1 - x0, height: h * H, class: "dvr-hist" }));
    });
    svg.append(axes());
    if (points.length) svg.append(colourBar());
    svg.append(svgEl("polyline", { points: points.map((p) => `${toX(p.density)},${toY(p.opacity)}`).join(" "), class: "dvr-curve" }));
    points.forEach((p, i) => {
      const c = svgEl("circle", { cx: toX(p.density), cy: toY(p.opacity), r: 4.5, fill: rgb(p.diffuse), class: "dvr-point" });
      c.addEventListener("pointerdown", (ev) => {
        ev.stopPropagation();
        if (ev.shiftKey && points.length > 1) {
          points.splice(i, 1);
          commit();
          return;
        }
        dragging = i;
        svg.setPointerCapture(ev.pointerId);
      });
      svg.append(c);
    });
  }
  function commit() {
    points.sort((a, b) => a.density - b.density);
    const edited = points.map((p) => ({ ...p }));
    if (channel()) send({ type: "channel", index: model.get("tf_channel"), tf: edited });
    else {
      model.set("tf_points", edited);
      model.save_changes();
    }
    draw();
  }
  svg.addEventListener("pointermove", (ev) => {
    if (dragging < 0) return;
    const [x, y] = fromEvent(ev);
    const lo = dragging > 0 ? points[dragging - 1].density + 1e-3 : 0;
    const hi = dragging < points.length - 1 ? points[dragging + 1].density - 1e-3 : 1;
    points[dragging].density = Math.min(hi, Math.max(lo, x));
    points[dragging].opacity = y;
    draw();
  });
  svg.addEventListener("pointerup", () => {
    if (dragging >= 0) {
      dragging = -1;
      commit();
      if (stale) load();
    }
  });
  svg.addEventListener("dblclick", (ev) => {
    const [x, y] = fromEvent(ev);
    // The new point takes every other field (colours, specular, emission, roughness)
    // of its nearest neighbour.
    let near = points[0];
    for (const p of points) if (Math.abs(p.density - x) < Math.abs(near.density - x)) near = p;
    points.push({ ...structuredClone(near || { diffuse: [1, 1, 1] }), density: x, opacity: y });
    commit();
  });
  // The kernel's TF replaces the shown one, except under a drag (then right after it).
  function load() {
    if (dragging >= 0) {
      stale = true;
      return;
    }
    stale = false;
    points = (model.get("tf_points") || []).map((p) => structuredClone(p));
    draw();
  }
  model.on("change:tf_points", load);
  model.on("change:histogram", draw);
  model.on("change:volume", draw);
  model.on("change:tf_channel", draw);
  model.on("change:channels", draw);
  load();
  return svg;
}

function button(label, cls, onclick) {
  return el("button", { class: `dvr-button ${cls}`, type: "button", onclick }, label);
}

function slider(min, max, step, value, oninput, cls = "") {
  const s = el("input", { type: "range", min, max, step, class: cls });
  s.value = value;
  s.addEventListener("input", () => oninput(parseFloat(s.value)));
  return s;
}

// The cuts panel: clip planes (an axis-aligned plane added at the centre, its offset
// dragged along its normal, flipped, switched off, removed) and the crop box (a min and
// max slider per axis, in the box's units: -0.5 to 0.5). It shows the kernel's
// `clip_planes` and `crop_box`, whoever set them.
function cutsPanel(model) {
  const AXES = { x: [1, 0, 0], y: [0, 1, 0], z: [0, 0, 1] };
  const planesEl = el("div", { class: "dvr-clips" });
  const axis = select(Object.keys(AXES), "z", () => {});
  axis.classList.add("dvr-clip-axis");
  const save = (planes) => {
    model.set("clip_planes", planes);
    model.save_changes();
  };
  const norm = (n) => Math.hypot(...n) || 1;
  const offsetOf = (p) => p.point.reduce((s, v, i) => s + v * p.normal[i], 0) / norm(p.normal);
  const add = button("add clip plane", "dvr-add-clip", () => {
    const planes = structuredClone(model.get("clip_planes") || []);
    if (planes.length >= 6) return;
    planes.push({ point: [0, 0, 0], normal: AXES[axis.value], enabled: true });
    save(planes);
  });
  function drawPlanes() {
    const planes = model.get("clip_planes") || [];
    add.disabled = planes.length >= 6;
    planesEl.replaceChildren(...planes.map((p, i) => {
      const edit = (f) => {
        const all = structuredClone(model.get("clip_planes") || []);
        f(all[i]);
        save(all);
      };
      const n = p.normal.map((v) => v / norm(p.normal));
      const on = el("input", { type: "checkbox", title: "enabled" });
      on.checked = p.enabled !== false;
      on.addEventListener("change", () => edit((q) => (q.enabled = on.checked)));
      return el("div", { class: "dvr-clip" },
        on,
        el("span", { class: "dvr-clip-normal" }, `n=(${n.map((v) => v.toFixed(2)).join(",")})`),
        slider("-0.87", "0.87", "0.01", offsetOf(p), (v) => edit((q) => (q.point = n.map((c) => c * v))), "dvr-clip-offset"),
        button("flip", "dvr-clip-flip", () => edit((q) => (q.normal = q.normal.map((c) => -c)))),
        button("×", "dvr-clip-remove", () => save((model.get("clip_planes") || []).filter((_, j) => j !== i))));
    }));
  }
  const crop = el("input", { type: "checkbox", class: "dvr-crop-on" });
  const cropSliders = {};
  const cropRows = ["x", "y", "z"].map((a, i) => {
    cropSliders[a] = [
      slider("-0.5", "0.5", "0.01", -0.5, () => sendCrop(), `dvr-crop-${a}-min`),
      slider("-0.5", "0.5", "0.01", 0.5, () => sendCrop(), `dvr-crop-${a}-max`),
    ];
    return el("div", { class: "dvr-crop-row" }, `${a} `, ...cropSliders[a]);
  });
  function sendCrop() {
    if (!crop.checked) crop.checked = true;
    const lo = [], hi = [];
    for (const a of ["x", "y", "z"]) {
      let [a0, a1] = cropSliders[a].map((s) => parseFloat(s.value));
      if (a0 > a1 - 0.01) a0 = a1 - 0.01; // the engine takes min < max only
      lo.push(Math.max(-0.5, a0));
      hi.push(Math.max(-0.49, a1));
    }
    model.set("crop_box", { min: lo, max: hi, enabled: true });
    model.save_changes();
  }
  crop.addEventListener("change", () => {
    if (crop.checked) sendCrop();
    else {
      model.set("crop_box", {});
      model.save_changes();
    }
  });
  function drawCrop() {
    const box = model.get("crop_box") || {};
    crop.checked = !!box.min && box.enabled !== false;
    ["x", "y", "z"].forEach((a, i) => {
      cropSliders[a][0].value = box.min ? box.min[i] : -0.5;
      cropSliders[a][1].value = box.max ? box.max[i] : 0.5;
    });
  }
  model.on("change:clip_planes", drawPlanes);
  model.on("change:crop_box", drawCrop);
  drawPlanes();
  drawCrop();
  return el("details", { class: "dvr-cuts" },
    el("summary", {}, "cuts"),
    el("div", { class: "dvr-row" }, axis, add),
    planesEl,
    el("label", {}, crop, "crop box"),
    ...cropRows);
}

const hex = (c) => "#" + c.map((v) => Math.round(255 * clamp01(v)).toString(16).padStart(2, "0")).join("");
const fromHex = (h) => [1, 3, 5].map((i) => parseInt(h.slice(i, i + 2), 16) / 255);

// The channels panel (a medium of several channels; hidden otherwise): per channel its
// colour (a colour picker), whether it is shown, its name, and whether the TF editor
// edits its TF. Edits go to the kernel as messages; the rows show the kernel's
// `channels` (the renderer's), whoever changed them, except a colour being picked.
function channelsPanel(model, send, uid) {
  const rows = el("div", { class: "dvr-channel-rows" });
  const box = el("div", { class: "dvr-channels" }, el("div", { class: "dvr-hint" }, "channels: colour · shown · name · TF in the editor"), rows);
  let inputs = [];
  function build(n) {
    inputs = Array.from({ length: n }, (_, i) => {
      const colour = el("input", { type: "color", class: "dvr-channel-colour", title: "colour" });
      colour.addEventListener("input", () => {
        colour.dataset.picking = "1";
        send({ type: "channel", index: i, colour: fromHex(colour.value) });
      });
      colour.addEventListener("change", () => delete colour.dataset.picking);
      const on = el("input", { type: "checkbox", class: "dvr-channel-visible", title: "shown" });
      on.addEventListener("change", () => send({ type: "channel", index: i, visible: on.checked }));
      const tf = el("input", { type: "radio", name: `${uid}-channel`, class: "dvr-channel-tf", title: "the TF editor edits this channel's TF" });
      tf.addEventListener("change", () => {
        if (!tf.checked) return;
        model.set("channel", i);
        model.save_changes();
      });
      const name = el("span", { class: "dvr-channel-name" });
      rows.append(el("div", { class: "dvr-channel", "data-index": i }, colour, on, name, tf));
      return { colour, on, name, tf };
    });
  }
  function update() {
    const channels = model.get("channels") || [];
    box.hidden = !channels.length;
    if (channels.length !== inputs.length) {
      rows.replaceChildren();
      build(channels.length);
    }
    channels.forEach((c, i) => {
      const r = inputs[i];
      if (!r.colour.dataset.picking) r.colour.value = hex(c.colour);
      r.on.checked = c.visible;
      r.name.textContent = c.name;
      r.tf.checked = i === model.get("channel");
    });
  }
  model.on("change:channels", update);
  model.on("change:channel", update);
  update();
  return box;
}

// The labels panel (a renderer with a label map; hidden otherwise): per label its
// colour (a colour picker), whether it is shown, its opacity, its value and name; show
// all and hide all; a search box filtering the rows by name or value (a parcellation
// has a hundred labels: the rows scroll). Edits go to the kernel as messages; the rows
// show the kernel's `labels` (the renderer's), whoever changed them, except a colour
// being picked or an opacity being dragged.
function labelsPanel(model, send) {
  const rows = el("div", { class: "dvr-label-rows" });
  const search = el("input", { type: "search", class: "dvr-label-search", placeholder: "search labels" });
  const mode = el("span", { class: "dvr-label-mode" });
  const box = el("div", { class: "dvr-labels-panel" },
    el("div", { class: "dvr-row" }, "labels ", mode,
      button("show all", "dvr-labels-show", () => send({ type: "labels", visible: true })),
      button("hide all", "dvr-labels-hide", () => send({ type: "labels", visible: false }))),
    search,
    el("div", { class: "dvr-hint" }, "colour · shown · opacity · value name"),
    rows);
  let inputs = [];
  function build(labels) {
    rows.replaceChildren();
    inputs = labels.map((l) => {
      const value = l.value;
      const colour = el("input", { type: "color", class: "dvr-label-colour", title: "colour" });
      colour.addEventListener("input", () => {
        colour.dataset.picking = "1";
        send({ type: "label", value, colour: fromHex(colour.value) });
      });
      colour.addEventListener("change", () => delete colour.dataset.picking);
      const on = el("input", { type: "checkbox", class: "dvr-label-visible", title: "shown" });
      on.addEventListener("change", () => send({ type: "label", value, visible: on.checked }));
      const opacity = slider("0", "1", "0.01", l.opacity, (o) => send({ type: "label", value, opacity: o }), "dvr-label-opacity");
      opacity.title = "opacity";
      opacity.addEventListener("pointerdown", () => (opacity.dataset.held = "1"));
      for (const ev of ["pointerup", "pointercancel", "change"]) opacity.addEventListener(ev, () => delete opacity.dataset.held);
      const name = el("span", { class: "dvr-label-name" });
      const row = el("div", { class: "dvr-label", "data-value": value }, colour, on, opacity, name);
      rows.append(row);
      return { value, row, colour, on, opacity, name };
    });
  }
  function filter() {
    const t = search.value.trim().toLowerCase();
    for (const r of inputs) r.row.hidden = !!t && !r.name.textContent.toLowerCase().includes(t);
  }
  function update() {
    const labels = model.get("labels") || [];
    box.hidden = !labels.length;
    mode.textContent = model.get("label_mode") ? `(${model.get("label_mode")})` : "";
    // The map's values are fixed for the renderer's life: rows are built once.
    if (labels.length !== inputs.length || labels.some((l, i) => l.value !== inputs[i].value)) build(labels);
    labels.forEach((l, i) => {
      const r = inputs[i];
      if (!r.colour.dataset.picking) r.colour.value = hex(l.colour);
      if (!r.opacity.dataset.held) r.opacity.value = l.opacity;
      r.on.checked = l.visible;
      r.name.textContent = `${l.value} ${l.name}`;
      r.row.classList.toggle("dvr-label-hidden", !l.visible);
    });
    filter();
  }
  search.addEventListener("input", filter);
  model.on("change:labels", update);
  model.on("change:label_mode", update);
  update();
  return box;
}

// The pick readout: what lies under the pixel last clicked in the image (the kernel's
// `picked`): the label's value and name, the intensity, the voxel.
function pickReadout(model) {
  const out = el("div", { class: "dvr-pick" }, "click the image to pick");
  const num = (v) => (v === null || v === undefined ? "–" : Math.abs(v) >= 1000 || v === Math.round(v) ? v.toFixed(0) : v.toPrecision(4));
  model.on("change:picked", () => {
    const p = model.get("picked") || {};
    out.dataset.label = p.hit ? p.label : "";
    if (!p.hit) out.textContent = `(${p.x}, ${p.y}): nothing`;
    else {
      const label = p.label ? `${p.label} ${p.label_name || ""}`.trim() : "no label";
      out.textContent = `label ${label} · intensity ${num(p.intensity)} · voxel (${p.voxel.join(", ")})`;
    }
  });
  return out;
}

// The time slider (a series of time points; hidden otherwise): 0 to times - 1 in
// fractional steps (the renderer mixes the two time points around a fraction), play and
// pause, and the speed in time points per second. Playback runs in the kernel's render
// thread; the slider follows the time of each frame shown, except while it is held or
// until the frames show the page's last time.
function timeRow(model, send) {
  const times = model.get("times") || 1;
  const value = el("span", { class: "dvr-time-value" });
  const show = (t) => (value.textContent = `${t.toFixed(2)} / ${times - 1}`);
  let held = false, asked = 0;
  const range = slider("0", String(Math.max(1, times - 1)), "0.05", 0, (t) => {
    asked = send({ type: "time", time: t });
    show(t);
  }, "dvr-time");
  range.addEventListener("pointerdown", () => (held = true));
  for (const ev of ["pointerup", "pointercancel", "change", "blur"]) range.addEventListener(ev, () => (held = false));
  const play = button("play", "dvr-play", () => send({ type: "play", playing: !model.get("playing") }));
  const speed = el("input", { type: "number", min: "0.1", max: "100", step: "0.5", class: "dvr-speed", title: "time points per second" });
  speed.addEventListener("change", () => send({ type: "play", speed: parseFloat(speed.value) }));
  const drawPlay = () => {
    play.textContent = model.get("playing") ? "pause" : "play";
    speed.value = model.get("speed");
  };
  model.on("change:playing", drawPlay);
  model.on("change:speed", drawPlay);
  drawPlay();
  show(0);
  const row = el("div", { class: "dvr-time-row" },
    el("div", { class: "dvr-row" }, "time ", range, value),
    el("div", { class: "dvr-row" }, play, "speed ", speed, " /s"));
  row.hidden = times < 2;
  // A frame's time point (with the newest page message it follows, `seq`).
  row.follow = (t, seq) => {
    if (held || seq < asked || t === null || t === undefined) return;
    range.value = t;
    show(t);
  };
  return row;
}

function render({ model, el: root }) {
  root.classList.add("dvr-viewer");
  const uid = `dvr${Math.random().toString(36).slice(2, 10)}`;
  const img = el("img", { class: "dvr-frame", alt: "dvr frame", draggable: "false" });
  const labels = el("div", { class: "dvr-labels" });
  // The patient's side each edge of the view faces, and a scale bar (in mm at the
  // target's depth; absent where the volume's physical size is unknown).
  const orient = Object.fromEntries(["left", "right", "top", "bottom"].map((k) => [k, el("span", { class: `dvr-orient dvr-orient-${k}` })]));
  const triad = svgEl("svg", { class: "dvr-triad", viewBox: "-22 -22 44 44" });
  const scaleBar = el("div", { class: "dvr-scale-bar" });
  const scaleLabel = el("span", { class: "dvr-scale-label" });
  const scale = el("div", { class: "dvr-scale", hidden: "" }, scaleBar, scaleLabel);
  const stage = el("div", { class: "dvr-stage" }, img, labels, ...Object.values(orient), triad, scale);
  const counter = el("span", { class: "dvr-frame-counter" }, "0");
  const fps = el("span", { class: "dvr-fps" }, "–");
  const latency = el("span", { class: "dvr-latency" }, "–");
  const timings = el("table", { class: "dvr-timings" });
  const status = el("div", { class: "dvr-status" });
  const captures = el("ul", { class: "dvr-captures" });
  const downloads = new Map(); // path -> blob URL of its bytes

  const denoiser = () =>
    select(model.get("methods"), model.get("denoiser"), (v) => {
      model.set("denoiser", v);
      model.save_changes();
    });
  const split = () =>
    select(model.get("methods"), model.get("split"), (v) => {
      model.set("split", v);
      model.save_changes();
    }, [["", "off"]]);
  const preset = () =>
    select(model.get("presets"), model.get("preset"), (v) => {
      if (!v) return;
      if ((model.get("channels") || []).length) {
        send({ type: "channel", index: model.get("tf_channel"), preset: v });
        return;
      }
      model.set("preset", v);
      model.save_changes();
    }, [["", "(edited)"]]);
  const splitPos = el("input", { type: "range", min: "0.05", max: "0.95", step: "0.01", class: "dvr-split-position" });
  splitPos.value = model.get("split_position");
  splitPos.addEventListener("input", () => {
    model.set("split_position", parseFloat(splitPos.value));
    model.save_changes();
  });
  // spp: the box holds only what the renderer takes (1 to the engine's limit on this
  // device, from the kernel); a number past it is clamped there, and says so.
  const spp = el("input", { type: "number", min: "1", step: "1", class: "dvr-spp" });
  const sppRange = el("span", { class: "dvr-spp-range" });
  const showLimit = () => {
    spp.max = model.get("max_spp");
    sppRange.textContent = `(1–${model.get("max_spp")})`;
  };
  showLimit();
  spp.value = model.get("spp");
  spp.addEventListener("change", () => {
    const max = model.get("max_spp");
    const n = parseInt(spp.value, 10);
    const ok = Math.min(max, Math.max(1, Number.isFinite(n) ? n : model.get("spp")));
    if (ok !== n) status.textContent = `spp ${spp.value} is outside 1–${max} (this device's limit): set to ${ok}`;
    spp.value = ok;
    model.set("spp", ok);
    model.save_changes();
  });
  let denoiserSel = denoiser(), splitSel = split(), presetSel = preset();
  denoiserSel.classList.add("dvr-denoiser");
  splitSel.classList.add("dvr-split");
  presetSel.classList.add("dvr-preset");
  const send = (msg) => {
    seq += 1;
    sentAt.set(seq, performance.now());
    model.send({ ...msg, seq });
    return seq;
  };
  const time = timeRow(model, send);
  const cameraRow = el("div", { class: "dvr-row dvr-camera-buttons" },
    button("reset", "dvr-reset", () => send({ type: "reset" })),
    button("fit", "dvr-fit", () => send({ type: "fit" })));
  const sidesRow = el("div", { class: "dvr-row dvr-sides" },
    ...(model.get("sides") || []).map((s) => button(s.slice(0, 3), `dvr-view-${s}`, () => send({ type: "view", side: s }))));
  sidesRow.querySelectorAll("button").forEach((b, i) => (b.title = `view from the ${model.get("sides")[i]} side`));
  const captureRow = el("div", { class: "dvr-row" },
    button("screenshot", "dvr-screenshot", () => model.send({ type: "screenshot" })),
    button("movie", "dvr-movie", () => model.send({ type: "movie" })));
  const panel = el(
    "div",
    { class: "dvr-panel" },
    el("div", { class: "dvr-row" }, "frame ", counter, " · ", fps, " fps"),
    el("div", { class: "dvr-row" }, "drag latency ", latency),
    pickReadout(model),
    el("label", {}, "denoiser ", denoiserSel),
    el("label", {}, "split ", splitSel, splitPos),
    el("label", {}, "spp ", spp, sppRange),
    cameraRow,
    sidesRow,
    time,
    channelsPanel(model, send, uid),
    labelsPanel(model, send),
    el("label", {}, "TF preset ", presetSel),
    tfEditor(model, uid, send),
    el("div", { class: "dvr-hint" }, "drag a point · double-click adds · shift-click removes"),
    cutsPanel(model),
    captureRow,
    captures,
    timings,
    status,
  );
  root.append(stage, panel);
  model.on("change:denoiser", () => (denoiserSel.value = model.get("denoiser")));
  model.on("change:split", () => (splitSel.value = model.get("split")));
  model.on("change:preset", () => (presetSel.value = model.get("preset")));
  model.on("change:spp", () => (spp.value = model.get("spp")));
  model.on("change:max_spp", showLimit);
  model.on("change:status", () => (status.textContent = model.get("status")));
  const drawCaptures = () =>
    captures.replaceChildren(...(model.get("captures") || []).map((c) => {
      const url = downloads.get(c.path);
      const name = c.path.split("/").pop();
      return el("li", { class: `dvr-capture dvr-capture-${c.kind}`, "data-path": c.path },
        `${c.kind}: ${c.path} `, url ? el("a", { href: url, download: name }, "download") : "");
    }));
  model.on("change:captures", drawCaptures);

  // Mouse: left drag orbits, right (or middle) drag pans, the wheel zooms. Movements
  // are summed and sent at most once per animation frame.
  let seq = 0, drag = null, sum = [0, 0], scheduled = false;
  let frameSize = [0, 0]; // the rendered size of the frame shown
  const sentAt = new Map(); // seq -> time sent
  const flush = () => {
    scheduled = false;
    if (!drag || (sum[0] === 0 && sum[1] === 0)) return;
    send({ type: drag, dx: sum[0], dy: sum[1] });
    sum = [0, 0];
  };
  stage.addEventListener("contextmenu", (ev) => ev.preventDefault());
  // A left press and release that moved less than this many CSS pixels is a click: a
  // pick, not a drag (a drag of that little does orbit, by a hair).
  const CLICK_PX = 4;
  let down = null;
  stage.addEventListener("pointerdown", (ev) => {
    drag = ev.button === 0 ? "orbit" : "pan";
    down = ev.button === 0 ? [ev.clientX, ev.clientY] : null;
    stage.setPointerCapture(ev.pointerId);
    ev.preventDefault();
  });
  stage.addEventListener("pointermove", (ev) => {
    if (!drag) return;
    sum[0] += ev.movementX;
    sum[1] += ev.movementY;
    if (!scheduled) {
      scheduled = true;
      requestAnimationFrame(flush);
    }
  });
  const end = () => {
    flush();
    drag = null;
    down = null;
  };
  // The page pixel to the rendered image's pixel (row 0 at the top): the image is
  // drawn scaled to the stage's width (CSS pixels, whatever the display's scaling),
  // so the offset within it scaled by the frame's size over the drawn size.
  const imagePixel = (ev) => {
    const r = img.getBoundingClientRect();
    const w = frameSize[0] || model.get("width"), h = frameSize[1] || model.get("height");
    const x = Math.floor(((ev.clientX - r.left) / r.width) * w), y = Math.floor(((ev.clientY - r.top) / r.height) * h);
    return x >= 0 && y >= 0 && x < w && y < h ? [x, y] : null;
  };
  stage.addEventListener("pointerup", (ev) => {
    const click = down && Math.hypot(ev.clientX - down[0], ev.clientY - down[1]) < CLICK_PX;
    end();
    const at = click ? imagePixel(ev) : null;
    if (at) send({ type: "pick", x: at[0], y: at[1] });
  });
  stage.addEventListener("pointercancel", end);
  stage.addEventListener(
    "wheel",
    (ev) => {
      ev.preventDefault();
      send({ type: "zoom", steps: -ev.deltaY / 100 });
    },
    { passive: false },
  );

  function drawOrientation(o) {
    for (const k of Object.keys(orient)) orient[k].textContent = o[k];
    // The triad: world x, y, z on the screen, labelled at their + ends (R, A, S).
    triad.replaceChildren();
    ["R", "A", "S"].forEach((name, i) => {
      const [x, y] = o.axes[i];
      triad.append(svgEl("line", { x1: 0, y1: 0, x2: 14 * x, y2: -14 * y, class: `dvr-triad-${name}` }));
      triad.append(svgEl("text", { x: 19 * x, y: -19 * y + 3, "text-anchor": "middle", class: `dvr-triad-${name}` }, name));
    });
  }

  // Frames from the kernel: show, then acknowledge (the kernel sends the next then).
  // Captures: their bytes, for a download link.
  let url = null;
  const onMessage = (msg, buffers) => {
    if (msg && msg.type === "capture" && buffers && buffers.length) {
      downloads.set(msg.path, URL.createObjectURL(new Blob([buffers[0]], { type: msg.mime })));
      drawCaptures();
      return;
    }
    if (!msg || msg.type !== "frame" || !buffers || !buffers.length) return;
    const blob = new Blob([buffers[0]], { type: msg.mime });
    const next = URL.createObjectURL(blob);
    img.onload = () => {
      if (url) URL.revokeObjectURL(url);
      url = next;
      model.send({ type: "ack" });
    };
    img.onerror = () => model.send({ type: "ack" });
    img.src = next;
    img.dataset.frame = msg.frame;
    img.style.aspectRatio = `${msg.width} / ${msg.height}`;
    frameSize = [msg.width, msg.height];
    counter.textContent = msg.frame;
    fps.textContent = msg.fps.toFixed(1);
    // Latency of an edit: from its message leaving the page to the first frame that
    // shows it on the page, in ms and in the kernel's frame times.
    for (const [s, t] of sentAt) {
      if (s <= msg.seq) {
        const ms = performance.now() - t;
        const frames = msg.fps > 0 ? (ms * msg.fps) / 1000 : 0;
        latency.textContent = `${Math.round(ms)} ms (${frames.toFixed(1)} frames)`;
        latency.dataset.ms = ms.toFixed(1);
        latency.dataset.frames = frames.toFixed(2);
        sentAt.delete(s);
      }
    }
    time.follow(msg.time, msg.seq);
    labels.replaceChildren(...msg.names.map((n) => el("span", {}, n)));
    labels.classList.toggle("dvr-split-labels", msg.names.length > 1);
    if (msg.orientation) drawOrientation(msg.orientation);
    if (msg.scale) {
      scale.hidden = false;
      scaleBar.style.width = `${(100 * msg.scale.fraction).toFixed(2)}%`;
      scaleLabel.textContent = `${msg.scale.mm} mm`;
      scale.dataset.mm = msg.scale.mm;
    } else scale.hidden = true;
    timings.replaceChildren(
      el("tr", {}, el("th", {}, "pass"), el("th", {}, "GPU ms")),
      ...Object.entries(msg.timings).map(([k, v]) => el("tr", {}, el("td", {}, k), el("td", {}, v.toFixed(2)))),
    );
  };
  model.on("msg:custom", onMessage);
  return () => {
    model.off("msg:custom", onMessage);
    if (url) URL.revokeObjectURL(url);
    for (const u of downloads.values()) URL.revokeObjectURL(u);
  };
}

export default { render };
