/* The comparison page of bench/report.py (issue 30): decodes the embedded
 * half-float images, tonemaps them, and drives the viewer, thumbnails, insets
 * and error plots. Every UI action goes through act(), so the keyboard, the
 * controls and the self-test (#selftest=...) take the same paths. */
"use strict";
(function () {
  const T0 = performance.now();
  const P = window.CDL_PAGE, RAW = window.CDL_RAW;
  const W = P.width, H = P.height, IMGS = P.images;
  const ZOOMS = [1 / 16, 1 / 8, 1 / 4, 1 / 2, 1, 2, 3, 4, 5, 6, 8, 10, 12, 16, 20, 24, 32, 48, 64];
  const COLORS = ["#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b", "#e377c2", "#17becf", "#7f7f7f", "#bcbd22"];
  /* relMSE map: log10 of the per-pixel relMSE over [LO, HI] through a
   * viridis-like ramp (control points of the published map). */
  const REL_LO = -4, REL_HI = 0;
  const RAMP = [[68, 1, 84], [72, 40, 120], [62, 74, 137], [49, 104, 142], [38, 130, 142],
                [31, 158, 137], [53, 183, 121], [109, 205, 89], [180, 222, 44], [253, 231, 37]];
  const $ = (id) => document.getElementById(id);

  /* ---------- data ---------- */
  const HALF = new Float32Array(65536);
  for (let h = 0; h < 65536; h++) {
    const s = h & 0x8000 ? -1 : 1, e = (h >> 10) & 31, m = h & 1023;
    HALF[h] = e === 0 ? s * m * Math.pow(2, -24)
      : e === 31 ? (m ? NaN : s * Infinity) : s * (1 + m / 1024) * Math.pow(2, e - 15);
  }
  /* Images stay as half-float bits: the tonemap is then one table lookup. */
  function decode(b64) {
    let bytes;
    if (Uint8Array.fromBase64) bytes = Uint8Array.fromBase64(b64);
    else {
      const bin = atob(b64), n = bin.length;
      bytes = new Uint8Array(n);
      for (let i = 0; i < n; i++) bytes[i] = bin.charCodeAt(i);
    }
    return new Uint16Array(bytes.buffer, bytes.byteOffset, bytes.length >> 1);
  }
  const data = IMGS.map((im, k) => {
    const raw = RAW[k];
    if (!raw) throw new Error("image data missing for " + im.id + " (" + im.src + ")");
    const u = decode(raw.rgb);
    if (u.length !== W * H * 3) throw new Error("image data of " + im.id + " has the wrong size");
    return u;
  });
  const T1 = performance.now();
  const flipImgs = IMGS.map((im, k) => {
    if (!RAW[k].flip) return null;
    const img = new Image();
    img.onload = () => { cache.clear(); redraw(); };
    img.src = RAW[k].flip; // a data: URL, so canvases stay readable
    return img;
  });
  const byId = new Map(IMGS.map((im, k) => [im.id, k]));
  const methods = P.methods;
  const budgets = P.budgets;
  function find(method, budget) {
    if (method === "reference") return 0;
    let best = -1, bestD = Infinity;
    IMGS.forEach((im, k) => {
      if (im.method !== method) return;
      const d = budget == null || im.budget == null ? 0 : Math.abs(Math.log(im.budget / budget));
      if (d < bestD) { best = k; bestD = d; }
    });
    return best;
  }
  const budgetOf = (k) => IMGS[k].budget != null ? IMGS[k].budget : (budgets.length ? budgets[budgets.length - 1] : null);

  /* ---------- state and tonemapping ---------- */
  const S = { a: IMGS.length > 1 ? 1 : 0, b: 0, mode: "image", exposure: 0, zoom: 1, cx: W / 2, cy: H / 2,
              split: false, splitPos: 0.5, side: false, outlines: true };
  const cache = new Map(); // "k|mode|exposure" -> canvas at 1:1

  const srgb = (v) => {
    v = v <= 0.0031308 ? 12.92 * v : 1.055 * Math.pow(v, 1 / 2.4) - 0.055;
    return v <= 0 ? 0 : v >= 1 ? 255 : Math.round(v * 255);
  };
  const luts = new Map(); // exposure -> sRGB byte of every half value
  function lut(exposure) {
    let t = luts.get(exposure);
    if (t) return t;
    t = new Uint8Array(65536);
    const scale = Math.pow(2, exposure);
    for (let h = 0; h < 65536; h++) t[h] = srgb(HALF[h] * scale); // NaN maps to 0
    luts.set(exposure, t);
    return t;
  }
  function tonemap(k, exposure, out) {
    const u = data[k], t = lut(exposure);
    for (let i = 0, j = 0; i < u.length; i += 3, j += 4) {
      out[j] = t[u[i]]; out[j + 1] = t[u[i + 1]]; out[j + 2] = t[u[i + 2]]; out[j + 3] = 255;
    }
  }
  function ramp(t) {
    t = Math.min(1, Math.max(0, t)) * (RAMP.length - 1);
    const i = Math.min(RAMP.length - 2, Math.floor(t)), u = t - i, a = RAMP[i], b = RAMP[i + 1];
    return [a[0] + u * (b[0] - a[0]), a[1] + u * (b[1] - a[1]), a[2] + u * (b[2] - a[2])];
  }
  const HALF_OF = (u) => { const f = new Float32Array(u.length); for (let i = 0; i < u.length; i++) f[i] = HALF[u[i]]; return f; };
  const relTerm = (t, r) => (t - r) * (t - r) / (r * r + 0.01); // as candela diff
  let refF = null;
  function relmap(k, out) {
    if (!refF) refF = HALF_OF(data[0]);
    const f = HALF_OF(data[k]), r = refF;
    for (let i = 0, j = 0; i < f.length; i += 3, j += 4) {
      const e = (relTerm(f[i], r[i]) + relTerm(f[i + 1], r[i + 1]) + relTerm(f[i + 2], r[i + 2])) / 3;
      const c = ramp((Math.log10(Math.max(e, 1e-30)) - REL_LO) / (REL_HI - REL_LO));
      out[j] = c[0]; out[j + 1] = c[1]; out[j + 2] = c[2]; out[j + 3] = 255;
    }
  }
  /* The image k as displayed in the current mode, at 1:1, cached. */
  function bitmap(k) {
    const key = k + "|" + S.mode + "|" + (S.mode === "image" ? S.exposure : "");
    let c = cache.get(key);
    if (c) return c;
    c = document.createElement("canvas");
    c.width = W; c.height = H;
    const ctx = c.getContext("2d");
    if (S.mode === "flip") {
      ctx.fillStyle = "#000"; ctx.fillRect(0, 0, W, H);
      if (flipImgs[k] && flipImgs[k].complete && flipImgs[k].naturalWidth) ctx.drawImage(flipImgs[k], 0, 0, W, H);
    } else {
      const id = ctx.createImageData(W, H);
      (S.mode === "image" ? tonemap(k, S.exposure, id.data) : relmap(k, id.data));
      ctx.putImageData(id, 0, 0);
    }
    cache.set(key, c);
    return c;
  }

  /* ---------- main viewer ---------- */
  const canvA = $("canvas-a"), canvB = $("canvas-b");
  let VW = 512, VH = 512;
  function layout() {
    let avail = Math.max(256, document.documentElement.clientWidth - 40);
    if (avail >= 1100) avail -= 480; // the plots go beside the viewer
    const per = S.side ? Math.floor((avail - 8) / 2) : avail;
    VW = Math.min(per, 1024);
    VH = Math.max(128, Math.min(Math.round(VW * H / W), Math.round(window.innerHeight * 0.7) || VW, 900));
    for (const c of [canvA, canvB]) { c.width = VW; c.height = VH; c.style.width = VW + "px"; c.style.height = VH + "px"; }
    $("split-pos").style.width = VW + "px";
    $("viewer-section").style.width = (S.side ? 2 * VW + 8 : VW) + "px";
  }
  function fitZoom() {
    let z = ZOOMS[0];
    for (const q of ZOOMS) if (W * q <= VW && H * q <= VH) z = q;
    return z;
  }
  const origin = () => [Math.round(VW / 2 - S.cx * S.zoom), Math.round(VH / 2 - S.cy * S.zoom)];
  function drawImageInto(ctx, k, x0, x1) {
    const [ox, oy] = origin();
    ctx.save();
    ctx.beginPath(); ctx.rect(x0, 0, x1 - x0, VH); ctx.clip();
    ctx.imageSmoothingEnabled = false;
    ctx.drawImage(bitmap(k), ox, oy, W * S.zoom, H * S.zoom);
    ctx.restore();
  }
  function drawOverlays(ctx) {
    if (!S.outlines) return;
    const [ox, oy] = origin();
    ctx.save();
    ctx.strokeStyle = "#ffeb3b"; ctx.lineWidth = 1;
    P.insets.forEach((r, n) => {
      const x = ox + r[0] * S.zoom - 1.5, y = oy + r[1] * S.zoom - 1.5;
      ctx.strokeRect(x, y, (r[2] - r[0]) * S.zoom + 3, (r[3] - r[1]) * S.zoom + 3);
      ctx.fillStyle = "#ffeb3b"; ctx.font = "11px sans-serif"; ctx.fillText(String(n + 1), x + 2, y - 3);
    });
    ctx.restore();
  }
  function drawViews() {
    const ca = canvA.getContext("2d");
    ca.fillStyle = "#333"; ca.fillRect(0, 0, VW, VH);
    if (S.split && !S.side) {
      const sx = Math.round(S.splitPos * VW);
      drawImageInto(ca, S.a, 0, sx);
      drawImageInto(ca, S.b, sx, VW);
      drawOverlays(ca);
      ca.fillStyle = "#fff"; ca.fillRect(sx, 0, 1, VH);
    } else {
      drawImageInto(ca, S.a, 0, VW);
      drawOverlays(ca);
    }
    if (S.side) {
      const cb = canvB.getContext("2d");
      cb.fillStyle = "#333"; cb.fillRect(0, 0, VW, VH);
      drawImageInto(cb, S.b, 0, VW);
      drawOverlays(cb);
    }
  }
  const fmt = (v, d) => v == null ? "–" : Number(v).toPrecision(d || 4);
  function describe(k) {
    const im = IMGS[k];
    const parts = [im.label];
    if (im.spp != null) parts.push(im.spp + " spp");
    if (im.seconds != null) parts.push(fmt(im.seconds, 3) + " s");
    if (k !== 0) parts.push("relMSE " + fmt(im.relmse), "FLIP " + fmt(im.flip));
    return parts.join(", ");
  }
  function redraw() {
    drawViews();
    const split = S.split && !S.side;
    $("label-a").textContent = split ? "A: " + IMGS[S.a].label + "  |  B: " + IMGS[S.b].label : "A: " + IMGS[S.a].label;
    $("label-b").textContent = "B: " + IMGS[S.b].label;
    $("info").textContent = "A = " + describe(S.a) + "   |   B = " + describe(S.b);
    $("zoom-value").textContent = S.zoom >= 1 ? String(S.zoom) : "1/" + Math.round(1 / S.zoom);
    $("exposure").value = S.exposure;
    $("exposure-value").textContent = S.exposure.toFixed(2);
    $("mode").value = S.mode;
    $("split").checked = S.split; $("side").checked = S.side; $("outlines").checked = S.outlines;
    $("split-pos").hidden = !split;
    $("view-b").hidden = !S.side;
    drawLegend();
    updateGrid();
    drawInsets();
    updatePlots();
  }
  function drawLegend() {
    const el = $("legend");
    if (S.mode === "relmse") {
      if (!el.dataset.rel) {
        const c = document.createElement("canvas");
        c.width = 200; c.height = 12;
        const x = c.getContext("2d");
        for (let i = 0; i < 200; i++) { const q = ramp(i / 199); x.fillStyle = "rgb(" + q.map(Math.round) + ")"; x.fillRect(i, 0, 1, 12); }
        el.replaceChildren("per-pixel relMSE against the reference: 1e" + REL_LO + " ", c, " 1e" + REL_HI + " (log scale)");
        el.dataset.rel = "1";
      }
    } else {
      delete el.dataset.rel;
      el.textContent = S.mode === "flip" ? (P.flip ? "FLIP map against the reference (black: no difference)" : P.flipNote)
        : "value × 2^" + S.exposure.toFixed(2) + ", sRGB, clamped";
    }
  }

  /* ---------- actions: every input path ends here ---------- */
  function act(what, arg, shift) {
    const cur = S.a, m = IMGS[cur].method, mi = methods.indexOf(m);
    const pick = (k) => { if (k < 0) return; if (shift) S.b = k; else S.a = k; };
    switch (what) {
      case "method": pick(find(methods[arg], budgetOf(shift ? S.b : S.a))); break;
      case "method-step": pick(find(methods[(mi + arg + methods.length) % methods.length], budgetOf(cur))); break;
      case "budget-step": {
        if (!budgets.length || m === "reference") break;
        const b = IMGS[cur].budget, bi = b == null ? budgets.length - 1 : budgets.indexOf(b);
        const nb = budgets[Math.min(budgets.length - 1, Math.max(0, bi + arg))];
        pick(find(m, nb)); break;
      }
      case "select": pick(arg); break;
      case "swap": [S.a, S.b] = [S.b, S.a]; break;
      case "mode": S.mode = arg; break;
      case "exposure": S.exposure = Math.max(-10, Math.min(10, Number(arg))); break;
      case "exposure-step": S.exposure = Math.max(-10, Math.min(10, S.exposure + arg)); break;
      case "split": S.split = arg; if (arg) S.side = false; break;
      case "split-pos": S.splitPos = arg; break;
      case "side": S.side = arg; if (arg) S.split = false; layout(); break;
      case "outlines": S.outlines = arg; break;
      case "zoom-step": zoomAt(arg, VW / 2, VH / 2); break;
      case "fit": S.zoom = fitZoom(); S.cx = W / 2; S.cy = H / 2; break;
      case "view": S.zoom = arg.zoom; S.cx = arg.cx; S.cy = arg.cy; break;
      case "pan": S.cx -= arg[0] / S.zoom; S.cy -= arg[1] / S.zoom; break;
    }
    redraw();
  }
  function zoomAt(step, mx, my) {
    let i = ZOOMS.indexOf(S.zoom);
    if (i < 0) i = ZOOMS.findIndex((z) => z >= S.zoom);
    const nz = ZOOMS[Math.max(0, Math.min(ZOOMS.length - 1, i + step))];
    const [ox, oy] = origin();
    const px = (mx - ox) / S.zoom, py = (my - oy) / S.zoom; // stays under the cursor
    S.zoom = nz; S.cx = px - (mx - VW / 2) / nz; S.cy = py - (my - VH / 2) / nz;
  }

  document.addEventListener("keydown", (e) => {
    if (e.target && (e.target.tagName === "INPUT" && e.target.type !== "range" && e.target.type !== "checkbox" || e.target.tagName === "SELECT")) return;
    if (e.ctrlKey || e.metaKey || e.altKey) return;
    const k = e.key, digit = /^Digit([1-9])$/.exec(e.code || "");
    let done = true;
    if (digit || /^[1-9]$/.test(k)) {
      const n = Number(digit ? digit[1] : k) - 1;
      if (n < methods.length) act("method", n, e.shiftKey);
    } else if (k === "ArrowLeft") act("method-step", -1);
    else if (k === "ArrowRight") act("method-step", 1);
    else if (k === "ArrowUp") act("budget-step", 1);
    else if (k === "ArrowDown") act("budget-step", -1);
    else if (k === " ") act("swap");
    else if (k === "i") act("mode", "image");
    else if (k === "m") act("mode", "relmse");
    else if (k === "f") act("mode", "flip");
    else if (k === "[") act("exposure-step", -0.5);
    else if (k === "]") act("exposure-step", 0.5);
    else if (k === "x") act("exposure", 0);
    else if (k === "s") act("split", !S.split);
    else if (k === "d") act("side", !S.side);
    else if (k === "o") act("outlines", !S.outlines);
    else if (k === "+" || k === "=") act("zoom-step", 1);
    else if (k === "-" || k === "_") act("zoom-step", -1);
    else if (k === "z") act("fit");
    else done = false;
    if (done) e.preventDefault();
  });
  $("mode").addEventListener("change", (e) => act("mode", e.target.value));
  $("exposure").addEventListener("input", (e) => act("exposure", e.target.value));
  $("split").addEventListener("change", (e) => act("split", e.target.checked));
  $("side").addEventListener("change", (e) => act("side", e.target.checked));
  $("outlines").addEventListener("change", (e) => act("outlines", e.target.checked));
  $("split-pos").addEventListener("input", (e) => act("split-pos", e.target.value / 1000));
  $("zoom-in").addEventListener("click", () => act("zoom-step", 1));
  $("zoom-out").addEventListener("click", () => act("zoom-step", -1));
  $("zoom-fit").addEventListener("click", () => act("fit"));
  for (const c of [canvA, canvB]) {
    let drag = null;
    c.addEventListener("wheel", (e) => {
      e.preventDefault();
      const r = c.getBoundingClientRect();
      zoomAt(e.deltaY < 0 ? 1 : -1, e.clientX - r.left, e.clientY - r.top);
      redraw();
    }, { passive: false });
    c.addEventListener("mousedown", (e) => { drag = [e.clientX, e.clientY]; c.style.cursor = "grabbing"; });
    window.addEventListener("mouseup", () => { drag = null; c.style.cursor = ""; });
    c.addEventListener("mousemove", (e) => {
      if (drag) { act("pan", [e.clientX - drag[0], e.clientY - drag[1]]); drag = [e.clientX, e.clientY]; }
      const r = c.getBoundingClientRect(), [ox, oy] = origin();
      const x = Math.floor((e.clientX - r.left - ox) / S.zoom), y = Math.floor((e.clientY - r.top - oy) / S.zoom);
      $("pixel").textContent = x >= 0 && y >= 0 && x < W && y < H
        ? "pixel (" + x + ", " + y + "): A " + pixelText(S.a, x, y) + "   B " + pixelText(S.b, x, y) : "\u00a0";
    });
  }
  const pixelText = (k, x, y) => { const i = 3 * (y * W + x), f = [HALF[data[k][i]], HALF[data[k][i + 1]], HALF[data[k][i + 2]]]; return "(" + f.map((v) => v.toPrecision(4)).join(", ") + ")"; };
  window.addEventListener("resize", () => { layout(); redraw(); });

  /* ---------- thumbnails of every image ---------- */
  const thumbs = [];
  function buildGrid() {
    const tw = Math.min(96, W), th = Math.max(1, Math.round(tw * H / W));
    const table = document.createElement("table");
    table.className = "grid";
    const cols = budgets.length ? budgets : [null];
    const head = table.insertRow();
    head.insertCell().outerHTML = "<th></th>";
    cols.forEach((b) => { const th_ = document.createElement("th"); th_.textContent = b == null ? "" : b + " s"; head.appendChild(th_); });
    methods.forEach((m) => {
      const row = table.insertRow();
      const name = document.createElement("th"); name.textContent = m; row.appendChild(name);
      cols.forEach((b, ci) => {
        const cell = row.insertCell();
        let k = -1;
        if (m === "reference") k = ci === 0 ? 0 : -1;
        else IMGS.forEach((im, j) => { if (im.method === m && (im.budget === b || (im.budget == null && ci === 0))) k = j; });
        if (k < 0) return;
        const c = document.createElement("canvas");
        c.width = tw; c.height = th; c.title = IMGS[k].label;
        c.addEventListener("click", (e) => act("select", k, e.shiftKey));
        cell.appendChild(c);
        const meta = document.createElement("div");
        meta.className = "metrics";
        const im = IMGS[k];
        meta.innerHTML = k === 0 ? "reference" : "relMSE " + fmt(im.relmse, 3) + "<br>FLIP " + fmt(im.flip, 3)
          + (im.spp != null ? "<br>" + im.spp + " spp" : "");
        cell.appendChild(meta);
        thumbs.push([k, c]);
      });
    });
    $("grid").appendChild(table);
  }
  function updateGrid() {
    for (const [k, c] of thumbs) {
      const x = c.getContext("2d");
      x.imageSmoothingEnabled = true;
      x.drawImage(bitmap(k), 0, 0, c.width, c.height);
      c.classList.toggle("sel-a", k === S.a);
      c.classList.toggle("sel-b", k === S.b && k !== S.a);
    }
  }

  /* ---------- insets: each region for the reference and every method ---------- */
  function drawInsets() {
    const box = $("insets");
    if (!P.insets.length) { $("insets-section").hidden = true; return; }
    const b = budgetOf(S.a);
    const ks = methods.map((m) => find(m, b)).filter((k) => k >= 0);
    box.replaceChildren();
    P.insets.forEach((r, n) => {
      const rw = r[2] - r[0], rh = r[3] - r[1];
      const z = Math.max(1, Math.floor(160 / Math.max(rw, rh)));
      const row = document.createElement("div");
      row.className = "inset-row";
      const title = document.createElement("div");
      title.className = "inset";
      title.textContent = "inset " + (n + 1) + ": " + r.join(",") + " (" + z + "×)";
      row.appendChild(title);
      ks.forEach((k) => {
        const d = document.createElement("div");
        d.className = "inset";
        const c = document.createElement("canvas");
        c.width = rw * z; c.height = rh * z;
        const x = c.getContext("2d");
        x.imageSmoothingEnabled = false;
        x.drawImage(bitmap(k), r[0], r[1], rw, rh, 0, 0, rw * z, rh * z);
        c.classList.toggle("sel-a", k === S.a);
        c.classList.toggle("sel-b", k === S.b && k !== S.a);
        c.addEventListener("click", (e) => {
          if (e.shiftKey) { act("select", k, true); return; }
          S.a = k;
          let zz = ZOOMS[0];
          for (const q of ZOOMS) if (rw * q <= VW && rh * q <= VH) zz = q;
          act("view", { zoom: zz, cx: (r[0] + r[2]) / 2, cy: (r[1] + r[3]) / 2 });
        });
        d.appendChild(c);
        d.appendChild(document.createElement("br"));
        d.appendChild(document.createTextNode(IMGS[k].label));
        row.appendChild(d);
      });
      box.appendChild(row);
    });
  }

  /* ---------- error against time, log-log SVG ---------- */
  const SVG = "http://www.w3.org/2000/svg";
  const plotPoints = [];
  function el(name, attrs, parent, text) {
    const e = document.createElementNS(SVG, name);
    for (const a in attrs) e.setAttribute(a, attrs[a]);
    if (text != null) e.textContent = text;
    if (parent) parent.appendChild(e);
    return e;
  }
  function logTicks(lo, hi) {
    const out = [], span = hi / lo;
    for (let d = Math.floor(Math.log10(lo)); d <= Math.ceil(Math.log10(hi)); d++) {
      for (const m of [1, 2, 3, 4, 5, 6, 7, 8, 9]) {
        const v = m * Math.pow(10, d);
        if (v < lo * 0.999 || v > hi * 1.001) continue;
        const label = m === 1 || (span < 1e3 && (m === 2 || m === 5)) || (span < 3 && m !== 7 && m !== 9);
        out.push([v, label]);
      }
    }
    return out;
  }
  function plot(metric, title) {
    const pts = IMGS.map((im, k) => [k, im.time, im[metric]]).filter((p) => p[1] > 0 && p[2] > 0);
    if (!pts.length) return null;
    const w = 460, h = 320, ml = 62, mr = 110, mt = 24, mb = 42;
    const xs = pts.map((p) => p[1]), ys = pts.map((p) => p[2]);
    let x0 = Math.min(...xs) / 1.25, x1 = Math.max(...xs) * 1.25, y0 = Math.min(...ys) / 1.4, y1 = Math.max(...ys) * 1.4;
    const X = (v) => ml + (Math.log(v) - Math.log(x0)) / (Math.log(x1) - Math.log(x0)) * (w - ml - mr);
    const Y = (v) => h - mb - (Math.log(v) - Math.log(y0)) / (Math.log(y1) - Math.log(y0)) * (h - mt - mb);
    const svg = el("svg", { width: w, height: h, viewBox: "0 0 " + w + " " + h, "font-size": 11, "font-family": "sans-serif" });
    el("text", { x: ml, y: 15, "font-size": 13 }, svg, title);
    for (const [v, lab] of logTicks(x0, x1)) {
      el("line", { x1: X(v), x2: X(v), y1: mt, y2: h - mb, stroke: lab ? "#ccc" : "#eee" }, svg);
      if (lab) el("text", { x: X(v), y: h - mb + 14, "text-anchor": "middle" }, svg, String(+v.toPrecision(3)));
    }
    for (const [v, lab] of logTicks(y0, y1)) {
      el("line", { x1: ml, x2: w - mr, y1: Y(v), y2: Y(v), stroke: lab ? "#ccc" : "#eee" }, svg);
      if (lab) el("text", { x: ml - 4, y: Y(v) + 4, "text-anchor": "end" }, svg, String(+v.toPrecision(3)));
    }
    el("rect", { x: ml, y: mt, width: w - ml - mr, height: h - mt - mb, fill: "none", stroke: "#888" }, svg);
    el("text", { x: (ml + w - mr) / 2, y: h - 8, "text-anchor": "middle" }, svg, P.timeLabel);
    el("text", { x: 12, y: (mt + h - mb) / 2, "text-anchor": "middle", transform: "rotate(-90 12 " + (mt + h - mb) / 2 + ")" }, svg, metric === "flip" ? "FLIP" : "relMSE");
    methods.slice(1).forEach((m, mi) => {
      const col = COLORS[mi % COLORS.length];
      const mp = pts.filter((p) => IMGS[p[0]].method === m).sort((a, b) => a[1] - b[1]);
      if (!mp.length) return;
      el("polyline", { points: mp.map((p) => X(p[1]) + "," + Y(p[2])).join(" "), fill: "none", stroke: col, "stroke-width": 1.5 }, svg);
      for (const p of mp) {
        const c = el("circle", { cx: X(p[1]), cy: Y(p[2]), r: 5, fill: col, class: "pt", "data-id": IMGS[p[0]].id }, svg);
        el("title", {}, c, IMGS[p[0]].label + ": " + fmt(p[2]) + " at " + fmt(p[1], 3) + " s");
        c.addEventListener("click", (e) => act("select", p[0], e.shiftKey));
        plotPoints.push([p[0], c]);
      }
      const ly = mt + 14 + 16 * mi;
      el("line", { x1: w - mr + 10, x2: w - mr + 28, y1: ly - 4, y2: ly - 4, stroke: col, "stroke-width": 2 }, svg);
      el("text", { x: w - mr + 32, y: ly }, svg, m);
    });
    return svg;
  }
  function buildPlots() {
    const box = $("plots");
    const rel = plot("relmse", "relMSE against time (log-log)");
    if (rel) box.appendChild(rel);
    if (P.flip) {
      const fl = plot("flip", "FLIP against time (log-log)");
      if (fl) box.appendChild(fl);
    } else {
      const n = document.createElement("p"); n.className = "note"; n.textContent = P.flipNote; box.appendChild(n);
    }
    if (!rel) {
      const n = document.createElement("p"); n.className = "note";
      n.textContent = "No plot: the images have no time budgets (name them METHOD_BUDGET.exr).";
      box.appendChild(n);
    }
  }
  function updatePlots() {
    for (const [k, c] of plotPoints) {
      c.setAttribute("r", k === S.a || k === S.b ? 7 : 5);
      c.setAttribute("stroke", k === S.a ? "#000" : k === S.b ? "#ef6c00" : "none");
      c.setAttribute("stroke-width", 2);
    }
  }

  /* ---------- self-test: #selftest=method:M,budget:B,exposure:E,x:X,y:Y ---------- */
  function key(k, code) { document.dispatchEvent(new KeyboardEvent("keydown", { key: k, code: code || "", bubbles: true })); }
  function selftest(spec) {
    const o = {};
    spec.split(",").forEach((kv) => { const i = kv.indexOf(":"); o[kv.slice(0, i)] = kv.slice(i + 1); });
    const res = { steps: [] };
    const mi = methods.indexOf(o.method);
    if (mi < 0) throw new Error("selftest: no method " + o.method);
    if (mi < 9) { key(String(mi + 1), "Digit" + (mi + 1)); res.steps.push("key " + (mi + 1)); }
    else for (let n = 0; n < methods.length && IMGS[S.a].method !== o.method; n++) key("ArrowRight");
    if (o.budget != null) {
      const want = find(o.method, Number(o.budget));
      const pt = plotPoints.find((p) => p[0] === want);
      if (pt) { pt[1].dispatchEvent(new MouseEvent("click", { bubbles: true })); res.steps.push("click plot point " + IMGS[want].id); }
      else for (let n = 0; n < budgets.length && S.a !== want; n++) key(IMGS[S.a].budget < Number(o.budget) ? "ArrowUp" : "ArrowDown");
    }
    if (o.exposure != null) {
      const r = $("exposure"); r.value = o.exposure; r.dispatchEvent(new Event("input", { bubbles: true }));
      res.steps.push("exposure slider " + r.value);
    }
    if (S.outlines) key("o");
    const x = Number(o.x), y = Number(o.y);
    const [ox, oy] = origin();
    const cx = ox + Math.floor(x * S.zoom + S.zoom / 2), cy = oy + Math.floor(y * S.zoom + S.zoom / 2);
    const px = canvA.getContext("2d").getImageData(cx, cy, 1, 1).data;
    const i = 3 * (y * W + x), sc = Math.pow(2, S.exposure);
    const f = Array.from(HALF_OF(data[S.a].subarray(i, i + 3)));
    Object.assign(res, { shown: IMGS[S.a].id, method: IMGS[S.a].method, budget: IMGS[S.a].budget, exposure: S.exposure,
      zoom: S.zoom, x: x, y: y, canvas_xy: [cx, cy], canvas: [px[0], px[1], px[2]],
      page_value: f, page_expected: f.map((v) => srgb(v * sc)) });
    /* Then every other control once (errors land in CDL_ERRORS), back to the start. */
    const keys = ["m", "f", "i", "s", " ", "s", "d", "d", "+", "-", "z", "[", "]", "x", "o", "ArrowLeft", "ArrowRight", "ArrowUp", "ArrowDown"];
    keys.forEach((k) => key(k));
    res.keys_exercised = keys.length;
    const mid = canvA.getBoundingClientRect();
    canvA.dispatchEvent(new WheelEvent("wheel", { deltaY: -1, clientX: mid.left + VW / 3, clientY: mid.top + VH / 3, bubbles: true, cancelable: true }));
    canvA.dispatchEvent(new MouseEvent("mousedown", { clientX: mid.left + 10, clientY: mid.top + 10, bubbles: true }));
    canvA.dispatchEvent(new MouseEvent("mousemove", { clientX: mid.left + 30, clientY: mid.top + 25, bubbles: true }));
    window.dispatchEvent(new MouseEvent("mouseup", { bubbles: true }));
    const ins = document.querySelector(".inset canvas");
    if (ins) ins.dispatchEvent(new MouseEvent("click", { bubbles: true }));
    const thumb = document.querySelector("table.grid canvas");
    if (thumb) thumb.dispatchEvent(new MouseEvent("click", { bubbles: true, shiftKey: true }));
    return res;
  }

  /* ---------- start ---------- */
  const notes = $("notes");
  for (const n of P.notes.concat(P.flip ? [] : [P.flipNote])) { const p = document.createElement("div"); p.textContent = n; notes.appendChild(p); }
  if (!P.flip) $("mode").querySelector("option[value=flip]").disabled = true;
  layout();
  S.zoom = fitZoom();
  buildGrid();
  buildPlots();
  /* A view given in the URL: #a=ID&b=ID&mode=relmse&exposure=1&split=1&side=1 */
  for (const kv of (location.hash || "").replace(/^#/, "").split("&")) {
    const [k, v] = kv.split("=").map(decodeURIComponent);
    if ((k === "a" || k === "b") && byId.has(v)) S[k] = byId.get(v);
    else if (k === "mode" && ["image", "relmse", "flip"].includes(v)) S.mode = v;
    else if (k === "exposure" && isFinite(Number(v))) S.exposure = Math.max(-10, Math.min(10, Number(v)));
    else if (k === "split" || k === "side") { S[k] = v === "1"; if (S.side) { S.split = false; layout(); S.zoom = fitZoom(); } }
  }
  redraw();
  const readyMs = performance.now();
  const timing = { scripts_loaded_ms: T0, decoded_ms: T1, ready_ms: readyMs };
  $("timing").textContent = IMGS.length + " images of " + W + "x" + H + "; page ready " + readyMs.toFixed(0)
    + " ms after navigation start (scripts loaded at " + T0.toFixed(0) + " ms, data decoded at " + T1.toFixed(0) + " ms)";
  const m = /selftest=([^&]*)/.exec(decodeURIComponent(location.hash || ""));
  if (m) {
    let res;
    try { res = selftest(m[1]); } catch (e) { res = { error: String(e && e.stack || e) }; }
    Object.assign(res, timing);
    res.images = IMGS.map((im) => im.id);
    res.flip = P.flip;
    res.errors = window.CDL_ERRORS.slice();
    const out = $("selftest-result");
    out.textContent = JSON.stringify(res);
    out.hidden = false;
  }
  if (window.CDL_ERRORS.length) { const e = $("errors"); e.hidden = false; e.textContent = window.CDL_ERRORS.join("\n"); }
})();
