// The interactive page's script (kinetostat/plans/page.py writes it into the page): decodes each
// sheet's arrays and the values stored as differences over the angle (deflated, 7 bits a character), writes the sheet of
// the angle chosen as core.py's Drawing.svg writes it, steps through the kinematic and force plans, checks typed
// lengths at the typed scales. No network, no library.
"use strict";
(async () => {
  const D = JSON.parse(document.getElementById("page-data").textContent);
  const $ = (id) => document.getElementById(id);

  function bytes7(s) {                          // page.py _text7: 7 bits a character
    const bad = D.illegal7, groups = [];
    for (let i = 0; i < s.length; i++) {
      const c = s.charCodeAt(i);
      if (c < 256) { groups.push(c); continue; }
      const k = (c - 256) >> 7;                  // an illegal group, and the next one where k < 3
      groups.push(bad[k % 3]);
      if (k < 3) groups.push((c - 256) & 127);
    }
    const out = new Uint8Array(Math.floor(groups.length * 7 / 8));
    let acc = 0, held = 0, o = 0;
    for (let i = 0; i < groups.length && o < out.length; i++) {
      acc = (acc << 7) | groups[i]; held += 7;
      if (held >= 8) { held -= 8; out[o++] = (acc >> held) & 255; acc &= (1 << held) - 1; }
    }
    return out;
  }
  async function bytes(id, xor) {
    const bin = bytes7($("blob-" + id).textContent);
    if (xor) {                                   // page.py's _obscure: xorshift32, seed 27
      let x = 27;
      for (let i = 0; i < bin.length; i++) {
        x ^= x << 13; x >>>= 0; x ^= x >>> 17; x ^= x << 5; x >>>= 0;
        bin[i] ^= x & 255;
      }
    }
    const stream = new Blob([bin]).stream().pipeThrough(new DecompressionStream("deflate-raw"));
    return new Uint8Array(await new Response(stream).arrayBuffer());
  }
  function varints(b) {                          // zigzag LEB128, exact below 2^53
    const out = [];
    let v = 0, m = 1;
    for (let i = 0; i < b.length; i++) {
      v += (b[i] & 127) * m;
      if (b[i] & 128) { m *= 128; } else { out.push(v % 2 ? -(v + 1) / 2 : v / 2); v = 0; m = 1; }
    }
    return out;
  }
  function local(x, digits) {                     // `digits` significant digits, as i18n.num writes them
    if (!isFinite(x)) return "—";
    if (Math.abs(x) < 1e-9) return "0";            // i18n.ZERO
    if (Math.abs(x) >= 10 ** digits) return String(Math.round(x));
    const places = Math.min(20, Math.max(0, digits - 1 - Math.floor(Math.log10(Math.abs(x)))));
    let s = x.toFixed(places);
    if (s.includes(".")) s = s.replace(/0+$/, "").replace(/\.$/, "");
    return (s === "-0" ? "0" : s).replace(".", D.decimal);
  }

  // ------------------------------------------------------------------ the check of typed lengths
  const check = JSON.parse(new TextDecoder().decode(await bytes("check", true)));
  function parse(s) { const x = parseFloat(s.replace(",", ".")); return s.trim() === "" ? NaN : x; }
  function pct1(x) { return (x >= 0 ? "+" : "−") + Math.abs(x).toFixed(1).replace(".", D.decimal) + " %"; }
  function mark(cell, ok, text) {                 // a verdict cell: ok true/false, null (none), undefined (empty)
    if (ok === undefined) { cell.textContent = ""; cell.className = "verdict"; delete cell.dataset.verdict; return; }
    cell.dataset.verdict = ok === null ? "none" : ok ? "ok" : "bad";
    cell.className = "verdict" + (ok === null ? "" : ok ? " ok" : " bad");
    cell.textContent = text;
  }
  function dev(typed, exact, unit) {              // "+1,23 mm (+0,5 %)": the percentage to 0.1 %
    const d = typed - exact;
    return (d >= 0 ? "+" : "") + local(d, 3) + (unit ? " " + unit : "") + " (" + pct1(100 * d / exact) + ")";
  }
  function band(b) { return b ? local(b[0], 3) + " … " + local(b[1], 3) : "—"; }
  function row(tr, texts, box, classes) {        // a row of the check: its texts, an input, empty cells of `classes`
    texts.forEach((t) => { tr.insertCell().textContent = t; });
    tr.insertCell().appendChild(box);
    classes.forEach((c) => { tr.insertCell().className = c; });
    return tr;
  }
  function box(className, size, data) {          // a text input for a number
    const e = document.createElement("input");
    Object.assign(e, {type: "text", inputMode: "decimal", className, size});
    Object.assign(e.dataset, data);
    return e;
  }
  // The scales the student drew at: one input per scale of the check's lengths (page.py _check_scale),
  // this page's own to start with; a length is judged at its own, its exact length and band times
  // the page's scale over his (the quantity it stands for against the exact one and its band).
  const scales = check.scales.map(([name, mu, u], k) => {
    const input = Object.assign(box("scale", 9, {scale: k}), {value: local(mu, 6)});
    const tr = row($("scale-table").insertRow(), [name + ", " + u], input, ["verdict"]);
    return {mu, input, note: tr.cells[2], bad: D.ui.bad_scale.replace("{mu}", name)};
  });
  function scale(k) {                            // the student's scale k, or NaN (its row says why)
    const S = scales[k], s = S.input.value.trim(), x = Number(s.replace(",", ".")), ok = s !== "" && x > 0 && isFinite(x);
    mark(S.note, ok ? undefined : false, S.bad);
    return ok ? x : NaN;
  }
  let last = $("check-table").rows[0];         // the items' rows (page.py _html writes the moments' rows)
  const items = check.items.map((it, n) => {
    const tr = row(document.createElement("tr"), [check.titles[it.plan], it.label || it.segment],
                   box("measured", 7, {plan: it.plan, segment: it.segment, scale: it.s}), ["quantity num", "exact num", "band num", "verdict"]);
    tr.dataset.item = n;
    last.after(tr);
    return (last = tr);
  });
  function judge(tr) {                           // an item's row at the student's scale
    const it = check.items[+tr.dataset.item], mu = scale(it.s), r = scales[it.s].mu / mu;
    const b = it.band && isFinite(r) ? it.band.map((x) => x * r) : null, cell = tr.querySelector(".verdict");
    if (!D.student) {
      tr.querySelector(".exact").textContent = local(it.exact * r, 4);
      tr.querySelector(".band").textContent = band(b);
    } else if (!it.band) {
      tr.querySelector(".band").textContent = "—";
    }
    const typed = parse(tr.querySelector("input").value);
    tr.querySelector(".quantity").textContent = isFinite(typed * mu) && it.u ? local(typed * mu, 4) + " " + it.u : "";
    if (!isFinite(typed)) return mark(cell);
    if (!isFinite(mu)) return mark(cell, null, scales[it.s].bad);
    const ok = b ? b[0] <= typed && typed <= b[1] : null;
    mark(cell, ok, dev(typed, it.exact * r, D.mm) + (ok === null ? "" : " — " + D.ui[ok ? "in_band" : "out_band"]));
  }
  items.forEach((tr) => { judge(tr); tr.querySelector("input").addEventListener("input", () => judge(tr)); });
  scales.forEach((S) => S.input.addEventListener("input", () => items.forEach(judge)));
  // The two balancing moments (signed, N m): each against its band and sense; then the texts' rule
  // on the student's own two, δ = (M' − M)/M' · 100 %, judged on δ as shown (0.1 %).
  const moments = [...document.querySelectorAll("tr[data-moment]")];
  function judgeMoments() {
    const typed = moments.map((tr) => parse(tr.querySelector("input").value));
    moments.forEach((tr, n) => {
      const [, exact, b] = check.M[+tr.dataset.moment], x = typed[n], cell = tr.querySelector(".verdict");
      if (!isFinite(x)) return mark(cell);
      const sense = Math.sign(x) === Math.sign(exact), inBand = b ? b[0] <= x && x <= b[1] : null;
      const ok = !sense ? false : inBand;
      mark(cell, ok, dev(x, exact, "") + " — " + (!sense ? D.ui.sense : inBand === null ? "" : D.ui[inBand ? "in_band" : "out_band"]));
    });
    const row = $("delta");
    if (!row) return;
    const cell = row.querySelector(".verdict");
    if (!typed.some(isFinite)) return mark(cell);
    if (!typed.every(isFinite) || typed[1] === 0) return mark(cell, false, D.ui.both);
    const delta = Math.round(1000 * (typed[1] - typed[0]) / typed[1]) / 10, ok = Math.abs(delta) <= D.tol;
    row.dataset.delta = String(delta);
    mark(cell, ok, "δ = " + pct1(delta) + " — " + (ok ? D.rule_ok : D.rule_bad));
  }
  moments.forEach((tr) => {
    const [, exact, b] = check.M[+tr.dataset.moment];
    if (!D.student) { tr.querySelector(".exact").textContent = local(exact, 4); tr.querySelector(".band").textContent = band(b); }
    tr.querySelector("input").addEventListener("input", judgeMoments);
  });
  if (D.student) { document.body.dataset.ready = "1"; return; }

  // ------------------------------------------------------------------ the sheets of every angle
  const meta = JSON.parse(new TextDecoder().decode(await bytes("meta")));
  const frames = meta.frames, nf = frames.length;
  function series(nums, p, n) {                 // page.py _series at nums[p]: its order k, then n values
    const out = nums.slice(p + 1, p + 1 + n);
    if (nums[p] === D.maxorder + 1) return unjump(out);
    if (nums[p] === D.maxorder + 2) return unsmooth(out);
    for (let k = nums[p]; k > 0; k--) for (let j = 1; j < n; j++) out[j] += out[j - 1];
    return out;
  }
  function unsmooth(v) {                         // page.py _smooth, taken back
    const C = D.smooth, K = C.length, out = [];
    let fit = 0, line = 0;                       // the two predictions of the value before
    for (let i = 0; i < v.length; i++) {
      const nextLine = i === 0 ? 0 : i === 1 ? out[0] : 2 * out[i - 1] - out[i - 2];
      let nextFit = nextLine;
      if (i >= K) {
        let acc = 0;
        for (let k = 0; k < K; k++) acc = acc + C[k] * out[i - K + k];
        nextFit = Math.floor(acc + 0.5);
      }
      const better = i >= K + 1 && Math.abs(out[i - 1] - fit) <= Math.abs(out[i - 1] - line);
      out.push(v[i] + (better ? nextFit : nextLine));
      fit = nextFit; line = nextLine;
    }
    return out;
  }
  function unjump(v) {                           // page.py _jumps, taken back
    const out = [v[0]];
    let s = 0, before = 0;
    for (let t = 1; t < v.length; t++) {
      const d = s + v[t];
      if (t < 2 || Math.abs(d - before) <= D.jump) s = d;
      before = d;
      out.push(out[t - 1] + d);
    }
    return out;
  }
  function fixed(q, digits) {                    // core.py fixed: q / 10^digits with `digits` decimals
    const s = String(Math.abs(q)).padStart(digits + 1, "0"), cut = s.length - digits;
    return (q < 0 ? "-" : "") + s.slice(0, cut) + "." + s.slice(cut);
  }
  // An earlier length series times f, as page.py _scaled: the part of a series stored less it.
  const plus = (rest, source, f) => rest.map((r, j) => r + Math.floor(source[j] * f + 0.5));
  const kinds = [], lengths = [];                // lengths: every length series of the page, in order
  for (let k = 0; k < meta.kinds.length; k++) {   // page.py encode_drawing, element by element
    const K = meta.kinds[k], nums = varints(await bytes("k" + k));
    let p = 0;
    const made = [];                             // the sheet's series in order: one may repeat an earlier, move it, or follow it
    const take = (n) => {
      let v;
      const j = Math.floor((-1 - nums[p]) / 3), how = (-1 - nums[p]) % 3;
      if (nums[p] >= 0) { v = series(nums, p, n); p += n + 1; }
      else if (how === 0) { v = made[j]; p += 1; }
      else if (how === 1) { const c = nums[p + 1]; v = made[j].map((x) => x + c); p += 2; }
      else { const r = series(nums, p + 1, n); v = made[j].map((x, t) => x + r[t]); p += n + 2; }
      made.push(v);
      return v;
    };
    const elements = K.elements.map((E) => {
      const el = {tag: E.tag, attrs: E.attrs.map(([a, v]) => ` ${a}="${v}"`).join(""),
                  title: E.title ? `<title>${E.title}</title>` : "", rows: E.rows, m: E.m,
                  texts: Array.isArray(E.texts) ? E.texts : meta.mids[E.texts.mids].map((t) => E.texts.pre + t + E.texts.suf)};
      el.drawn = take(E.rows);
      el.variant = E.variants ? take(E.variants) : [0];
      el.finite = E.holes ? [...Array(E.m)].map(() => take(E.rows)) : null;
      el.xy = [...Array(2 * E.m)].map(() => take(E.rows));
      el.len = E.len ? take(E.len) : null;
      if (E.from) el.len = plus(el.len, lengths[E.from[0]], E.from[1]);
      if (el.len) lengths.push(el.len);
      return el;
    });
    kinds.push({kind: K.kind, static: K.static, elements, amounts: K.amounts});
  }
  const at = (a, i) => a[a.length > 1 ? i : 0];
  function element(el, i) {                      // core.py Element.svg(i)
    const r = el.rows > 1 ? i : 0;
    if (!el.drawn[r]) return "";
    const x = (c) => fixed(el.xy[c][r], D.coord);
    const pts = [...Array(el.m).keys()].filter((j) => !el.finite || el.finite[j][r]).map((j) => x(2 * j) + "," + x(2 * j + 1));
    let head = {line: () => ` x1="${x(0)}" y1="${x(1)}" x2="${x(2)}" y2="${x(3)}"`, circle: () => ` cx="${x(0)}" cy="${x(1)}"`,
                text: () => ` x="${x(0)}" y="${x(1)}"`, polyline: () => ` points="${pts.join(" ")}"`,
                path: () => ` d="M${pts.join(" L")} z"`}[el.tag];
    head = (head ? head() : "") + el.attrs + (el.len ? ` data-length-mm="${fixed(at(el.len, i), D.lengthd)}"` : "");
    const body = el.title + (el.tag === "text" ? el.texts[at(el.variant, i)] : "");
    return `<${el.tag}${head}>${body}</${el.tag}>\n`;
  }
  function sheet(K, i) {                          // core.py Drawing.svg(i)
    return K.static.replace(D.elements, () => K.elements.map((el) => element(el, i)).join(""));
  }
  window.sheetSvg = (k, i) => sheet(kinds[k], i);   // for tests: the sheet of kind k at frame i
  // The notes' tokens (draw.py TOKEN: VALUE, LENGTH, RESULT) with the numbers of frame i, as the one-angle sheet
  // writes them (i18n.num): a segment's value (its length times its scale; of its element drawn at frame i),
  // its length (2 decimals), a result (the values table's).
  function amounts(K, i, svg) {
    return svg.replace(/([\ue000\ue002\ue003])(\d+)\ue001/g, (_, mark, k) => {
      if (mark === "\ue003") return local(values[i][K.amounts.res[k]], 4);
      const [els, mu] = K.amounts.seg[k], all = els.map((e) => K.elements[e]);
      const el = all.find((e) => e.drawn[e.rows > 1 ? i : 0]) || all[0], L = at(el.len, i) / 10 ** D.lengthd;
      if (mark === "\ue000") return local(L * mu, 4);
      return Math.abs(L) < 1e-9 ? "0" : L.toFixed(2).replace(".", D.decimal);
    });
  }
  const rows = meta.rows, ncol = rows.length, singular = new Set(D.singular);
  const vals = varints(await bytes("values")), values = frames.map(() => new Array(ncol));
  for (let c = 0, p = 0; c < ncol; c++) {          // column by column: page.py _columns
    const none = series(vals, p, nf), rest = series(vals, p + nf + 1, nf), e = meta.exps[c], src = meta.sources[c];
    const n = src ? plus(rest, lengths[src[0]], src[1]) : rest;
    p += 2 * (nf + 1);
    for (let f = 0; f < nf; f++) values[f][c] = none[f] ? NaN : e < 0 ? n[f] / 10 ** -e : n[f] * 10 ** e;
  }
  const sheets = $("sheets");
  sheets.textContent = "";
  const boxes = kinds.map((K) => {
    const div = document.createElement("div");
    div.className = "sheet"; div.dataset.kind = K.kind;
    sheets.appendChild(div);
    return div;
  });
  const table = $("value-table");
  let section = null;
  const cells = rows.map((r) => {
    if (r.section !== section) {
      section = r.section;
      const th = table.insertRow().appendChild(document.createElement("th"));
      th.colSpan = 3; th.textContent = section;
    }
    const tr = table.insertRow();
    tr.insertCell().textContent = r.shown;
    const td = tr.insertCell();
    td.className = "num"; td.dataset.symbol = r.symbol;
    tr.insertCell().textContent = r.unit;
    return td;
  });

  let frame = 0, step = -1;
  function render(f) {
    frame = f;
    kinds.forEach((K, k) => {
      if (singular.has(f)) { boxes[k].textContent = D.ui.singular; return; }
      boxes[k].innerHTML = amounts(K, f, sheet(K, f)).replace(/^<\?xml[^>]*>\s*/, "").replace(/<\/svg>\s*$/, D.scalebar + "</svg>");
    });
    values[f].forEach((v, c) => {
      cells[c].dataset.value = isFinite(v) ? String(v) : "";
      cells[c].textContent = local(v, 4);
    });
    $("phi-value").textContent = local(frames[f], 6);
    paper();
    highlight();
  }
  function paper() {                              // A4 landscape: the 297 x 210 mm around the plan
    const a4 = $("paper").value === "A4";
    document.documentElement.dataset.paper = $("paper").value;
    $("page-size").textContent = `@page{size:${a4 ? "A4" : "A3"} landscape;margin:0}`;
    boxes.forEach((box) => {
      const svg = box.querySelector("svg"), plan = svg && svg.querySelector("#plan");
      if (!plan) return;
      const bar = svg.querySelector("#scalebar"), old = svg.querySelector("#a4-title"), notes = [...svg.querySelectorAll("text.note")];
      if (old) old.remove();
      notes.forEach((t) => t.removeAttribute("transform"));
      if (!a4) {
        svg.setAttribute("viewBox", "0 0 420 297"); svg.setAttribute("width", "420mm"); svg.setAttribute("height", "297mm");
        bar.removeAttribute("transform"); delete box.dataset.a4; return;
      }
      notes.forEach((t) => { t.style.display = "none"; });      // the crop: around the plan, not its notes
      const b = plan.getBBox(), clamp = (x, hi) => Math.min(Math.max(x, 0), hi);
      notes.forEach((t) => { t.style.display = ""; });
      const x0 = clamp(b.x + b.width / 2 - 148.5, 123), y0 = clamp(b.y + b.height / 2 - 105, 87);
      svg.setAttribute("viewBox", `${x0} ${y0} 297 210`); svg.setAttribute("width", "297mm"); svg.setAttribute("height", "210mm");
      bar.setAttribute("transform", `translate(${x0 - 8} ${y0 - 30})`);   // the bar 8 mm in, 10 mm down
      const cut = b.width > 280 || b.height > 195;
      if (cut) box.dataset.a4 = D.ui.a4_cut; else delete box.dataset.a4;
      a4Title(svg, x0, y0, cut, notes);
    });
  }
  // A4 cuts the title block and the notes off: at the top instead, the title line and under it the notes, on white
  function a4Title(svg, x0, y0, cut, notes) {
    const NS = "http://www.w3.org/2000/svg", g = document.createElementNS(NS, "g"), t = document.createElementNS(NS, "text");
    const name = ["#mechanism", "#mechanism-2"].map((q) => svg.querySelector(q)).filter((e) => e);   // in one line or two
    const line = [...(name.length ? [{textContent: name.map((e) => e.textContent).join(" ")}] : []), ...['text.title[font-weight="bold"]', "#scale"].map((q) => svg.querySelector(q))];   // name, plan and φ, scale
    g.id = "a4-title";
    t.setAttribute("x", x0 + 12); t.setAttribute("y", y0 + 6); t.setAttribute("font-size", "2.8");
    t.textContent = line.filter((e) => e).map((e) => e.textContent).join(" — ");
    if (cut) {                                   // a second line, red
      const w = document.createElementNS(NS, "tspan");
      w.setAttribute("fill", "#b01515"); w.setAttribute("x", x0 + 12); w.setAttribute("dy", "3.6");
      w.textContent = D.ui.a4_cut;
      t.appendChild(w);
    }
    const white = (x, y, w, h) => {             // a white ground under a block of text, its own width
      const r = document.createElementNS(NS, "rect");
      r.setAttribute("x", x); r.setAttribute("y", y); r.setAttribute("width", w); r.setAttribute("height", h);
      r.setAttribute("fill", "#fff");
      return r;
    };
    const top = y0 + (cut ? 11 : 7.5);
    g.append(white(x0 + 11, y0 + 2, t.getComputedTextLength() + 2, top - y0 - 2), t);
    svg.appendChild(g);
    if (notes.length) {                          // the notes' block moved under the title line
      const x = +notes[0].getAttribute("x"), y = +notes[0].getAttribute("y");
      let width = 0;
      notes.forEach((n) => {
        n.setAttribute("transform", `translate(${x0 + 12 - x} ${top + 2 - y})`);
        width = Math.max(width, n.getBBox().width);   // a block of rows is one text: its box, not its run's length
      });
      const bottom = Math.max(...notes.map((n) => n.getBBox().y + n.getBBox().height)) + top + 2 - y;
      g.appendChild(white(x0 + 11, top, width + 2, bottom - top));
      notes.forEach((n) => svg.appendChild(n));  // over the white
    }
    return g;
  }
  $("paper").addEventListener("change", paper);
  function highlight() {
    document.querySelectorAll(".hl").forEach((el) => el.classList.remove("hl"));
    const out = $("step");
    if (step < 0) { out.textContent = ""; $("equation").textContent = ""; return; }
    const s = meta.steps[step];
    const sel = `svg [data-plan="${s.plan}"]` + (s.segment ? `[data-segment="${CSS.escape(s.segment)}"]` : `[data-path="${CSS.escape(s.path)}"]`);
    const el = document.querySelector(sel);
    if (el) { el.classList.add("hl"); el.scrollIntoView({block: "center", behavior: "instant"}); }
    out.dataset.plan = s.plan;
    out.dataset.segment = s.segment || "";
    out.dataset.path = s.path || "";
    out.dataset.n = s.n || "";                       // the step's number on its sheet: (n)
    out.textContent = (s.n ? `(${s.n}) ` : "") + `${step + 1}/${meta.steps.length}`;
    const mm = el && el.dataset.lengthMm !== undefined ? +el.dataset.lengthMm : NaN;
    const len = isFinite(mm) ? ` — ${local(mm, 4)} ${D.mm}` + (mm < D.tiny ? `: ${D.ui.negligible}` : "") : "";
    $("equation").textContent = s.eq + (s.moment ? ": " + momentText(s.plan, s.moment) : "") + len;
  }
  // A moment equation's terms at the angle shown (page.py _moment): each sign the moment's sense as
  // drawn (+ counter-clockwise), each arm its length on the sheet (mm).
  function ends(plan, name) {
    const e = document.querySelector(`svg [data-plan="${plan}"][data-segment="${CSS.escape(name)}"]`);
    return e && [e.x1.baseVal.value, e.y1.baseVal.value, e.x2.baseVal.value, e.y2.baseVal.value, +e.dataset.lengthMm];
  }
  function term(plan, force, arm, atEnd) {        // [sign, "F·h"] or null (no arm: no moment)
    const F = ends(plan, force), h = ends(plan, arm);
    if (!F || !h || !(h[4] > 1e-9)) return null;
    const [mx, my, px, py] = atEnd ? [h[2], h[3], h[0], h[1]] : h;
    const cross = (px - mx) * (F[3] - F[1]) - (py - my) * (F[2] - F[0]);     // the sheet's y runs down
    return [cross > 0 ? -1 : 1, `${force}·${local(h[4], 4)}`];
  }
  function couple(plan, name) {
    const e = document.querySelector(`svg [data-plan="${plan}"][data-path="${CSS.escape(name)}"]`);
    if (!e) return null;
    const p = e.getAttribute("points").trim().split(/\s+/).slice(0, 3).map((xy) => xy.split(",").map(Number));
    const cross = (p[1][0] - p[0][0]) * (p[2][1] - p[1][1]) - (p[1][1] - p[0][1]) * (p[2][0] - p[1][0]);
    return [cross > 0 ? -1 : 1, `${name}/μ_l`];
  }
  function momentText(plan, m) {
    const parts = [];
    if (m.unknown) { const u = term(plan, ...m.unknown); if (u) parts.push(u); }
    m.terms.forEach((t) => { const x = term(plan, ...t); if (x) parts.push(x); });
    m.couples.forEach((c) => { const x = couple(plan, c); if (x) parts.push(x); });
    const sum = parts.map(([sg, t], i) => (sg < 0 ? (i ? " − " : "−") : i ? " + " : "") + t).join("") || "0";
    return (m.M ? `${m.M} + μ_l·(${sum})` : sum) + " = 0 (h, l: " + D.mm + ")";
  }
  const slider = $("phi");
  function frameOf(deg) {                        // the frame of the nearest angle on the slider
    let best = 0;
    for (let f = 0; f < D.slider; f++) if (Math.abs(frames[f] - deg) < Math.abs(frames[best] - deg)) best = f;
    return best;
  }
  slider.addEventListener("input", () => render(frameOf(+slider.value)));
  $("design").addEventListener("click", () => { slider.value = Math.round(D.design) % 360; render(D.slider); });
  $("next").addEventListener("click", () => { step = (step + 1) % meta.steps.length; highlight(); });
  $("prev").addEventListener("click", () => { step = step <= 0 ? meta.steps.length - 1 : step - 1; highlight(); });
  slider.value = Math.round(D.design) % 360;
  render(D.slider);
  document.body.dataset.ready = "1";
})();
