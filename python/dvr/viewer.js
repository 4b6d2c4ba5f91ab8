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

// The TF editor: the opacity curve of the control points over the density histogram.
// Drag a point, double-click to add one, shift-click a point to remove it.
function tfEditor(model) {
  const W = 240, H = 110;
  const svg = document.createElementNS(SVG, "svg");
  svg.setAttribute("class", "dvr-tf");
  svg.setAttribute("viewBox", `0 0 ${W} ${H}`);
  let points = [];
  let dragging = -1;
  const toX = (d) => d * W, toY = (o) => H - o * H;
  const fromEvent = (ev) => {
    const r = svg.getBoundingClientRect();
    const x = Math.min(1, Math.max(0, (ev.clientX - r.left) / r.width));
    const y = Math.min(1, Math.max(0, 1 - (ev.clientY - r.top) / r.height));
    return [x, y];
  };
  const colour = (p) => {
    const c = p.diffuse || [1, 1, 1];
    return `rgb(${c.map((v) => Math.round(255 * Math.min(1, Math.max(0, v)))).join(",")})`;
  };
  function draw() {
    svg.replaceChildren();
    const hist = model.get("histogram") || [];
    const bw = W / Math.max(1, hist.length);
    hist.forEach((h, i) => {
      const r = document.createElementNS(SVG, "rect");
      r.setAttribute("x", i * bw);
      r.setAttribute("y", H - h * H);
      r.setAttribute("width", bw + 0.2);
      r.setAttribute("height", h * H);
      r.setAttribute("class", "dvr-hist");
      svg.append(r);
    });
    const line = document.createElementNS(SVG, "polyline");
    line.setAttribute("points", points.map((p) => `${toX(p.density)},${toY(p.opacity)}`).join(" "));
    line.setAttribute("class", "dvr-curve");
    svg.append(line);
    points.forEach((p, i) => {
      const c = document.createElementNS(SVG, "circle");
      c.setAttribute("cx", toX(p.density));
      c.setAttribute("cy", toY(p.opacity));
      c.setAttribute("r", 4.5);
      c.setAttribute("fill", colour(p));
      c.setAttribute("class", "dvr-point");
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
    model.set("tf_points", points.map((p) => ({ ...p })));
    model.save_changes();
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
    }
  });
  svg.addEventListener("dblclick", (ev) => {
    const [x, y] = fromEvent(ev);
    // The new point takes the colour of its nearest neighbour.
    let near = points[0];
    for (const p of points) if (Math.abs(p.density - x) < Math.abs(near.density - x)) near = p;
    points.push({ density: x, opacity: y, diffuse: [...(near ? near.diffuse || [1, 1, 1] : [1, 1, 1])] });
    commit();
  });
  const load = () => {
    points = (model.get("tf_points") || []).map((p) => ({ ...p }));
    draw();
  };
  model.on("change:tf_points", load);
  model.on("change:histogram", draw);
  load();
  return svg;
}

function render({ model, el: root }) {
  root.classList.add("dvr-viewer");
  const img = el("img", { class: "dvr-frame", alt: "dvr frame", draggable: "false" });
  const labels = el("div", { class: "dvr-labels" });
  const stage = el("div", { class: "dvr-stage" }, img, labels);
  const counter = el("span", { class: "dvr-frame-counter" }, "0");
  const fps = el("span", { class: "dvr-fps" }, "–");
  const latency = el("span", { class: "dvr-latency" }, "–");
  const timings = el("table", { class: "dvr-timings" });
  const status = el("div", { class: "dvr-status" });

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
      model.set("preset", v);
      model.save_changes();
    }, [["", "(edited)"]]);
  const splitPos = el("input", { type: "range", min: "0.05", max: "0.95", step: "0.01", class: "dvr-split-position" });
  splitPos.value = model.get("split_position");
  splitPos.addEventListener("input", () => {
    model.set("split_position", parseFloat(splitPos.value));
    model.save_changes();
  });
  const spp = el("input", { type: "number", min: "1", class: "dvr-spp" });
  spp.max = model.get("max_spp");
  spp.value = model.get("spp");
  spp.addEventListener("change", () => {
    const n = parseInt(spp.value, 10);
    if (n >= 1 && n <= model.get("max_spp")) {
      model.set("spp", n);
      model.save_changes();
    }
  });
  let denoiserSel = denoiser(), splitSel = split(), presetSel = preset();
  denoiserSel.classList.add("dvr-denoiser");
  splitSel.classList.add("dvr-split");
  presetSel.classList.add("dvr-preset");
  const panel = el(
    "div",
    { class: "dvr-panel" },
    el("div", { class: "dvr-row" }, "frame ", counter, " · ", fps, " fps"),
    el("div", { class: "dvr-row" }, "drag latency ", latency),
    el("label", {}, "denoiser ", denoiserSel),
    el("label", {}, "split ", splitSel, splitPos),
    el("label", {}, "spp ", spp),
    el("label", {}, "TF preset ", presetSel),
    tfEditor(model),
    el("div", { class: "dvr-hint" }, "drag a point · double-click adds · shift-click removes"),
    timings,
    status,
  );
  root.append(stage, panel);
  model.on("change:denoiser", () => (denoiserSel.value = model.get("denoiser")));
  model.on("change:split", () => (splitSel.value = model.get("split")));
  model.on("change:preset", () => (presetSel.value = model.get("preset")));
  model.on("change:spp", () => (spp.value = model.get("spp")));
  model.on("change:status", () => (status.textContent = model.get("status")));

  // Mouse: left drag orbits, right (or middle) drag pans, the wheel zooms. Movements
  // are summed and sent at most once per animation frame.
  let seq = 0, drag = null, sum = [0, 0], scheduled = false;
  const sentAt = new Map(); // seq -> time sent
  const send = (msg) => {
    seq += 1;
    sentAt.set(seq, performance.now());
    model.send({ ...msg, seq });
  };
  const flush = () => {
    scheduled = false;
    if (!drag || (sum[0] === 0 && sum[1] === 0)) return;
    send({ type: drag, dx: sum[0], dy: sum[1] });
    sum = [0, 0];
  };
  stage.addEventListener("contextmenu", (ev) => ev.preventDefault());
  stage.addEventListener("pointerdown", (ev) => {
    drag = ev.button === 0 ? "orbit" : "pan";
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
  };
  stage.addEventListener("pointerup", end);
  stage.addEventListener("pointercancel", end);
  stage.addEventListener(
    "wheel",
    (ev) => {
      ev.preventDefault();
      send({ type: "zoom", steps: -ev.deltaY / 100 });
    },
    { passive: false },
  );

  // Frames from the kernel: show, then acknowledge (the kernel sends the next then).
  let url = null;
  const onMessage = (msg, buffers) => {
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
    labels.replaceChildren(...msg.names.map((n) => el("span", {}, n)));
    labels.classList.toggle("dvr-split-labels", msg.names.length > 1);
    timings.replaceChildren(
      el("tr", {}, el("th", {}, "pass"), el("th", {}, "GPU ms")),
      ...Object.entries(msg.timings).map(([k, v]) => el("tr", {}, el("td", {}, k), el("td", {}, v.toFixed(2)))),
    );
  };
  model.on("msg:custom", onMessage);
  return () => {
    model.off("msg:custom", onMessage);
    if (url) URL.revokeObjectURL(url);
  };
}

export default { render };
