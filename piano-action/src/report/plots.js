// The report's plots: the runs' series and contact forces against time, linked to the clock.
// ---------------------------------------------------------------- plots
const plotsBox = el('section', { id: 'plots' }, main);
const plotDefs = [];
const seriesOf = (run, id) => (run.series.find((s) => s.id === id) || {}).values;
// The runs' plots, in order, merged by id (the first run's title); then every series
// that no plot shows, on its own.
const lineOf = (pl, r, k) => ({
  run: k, id: pl.series, label: (pl.prefix ? pl.prefix + ' ' : '') + r.name,
  values: seriesOf(r, pl.series), color: RUN_COLORS[k % 6], dash: pl.dashed ? [5, 3] : [],
});
const forceLines = () => {
  const out = [];
  RUNS.forEach((r, k) => {
    for (const [name, c] of Object.entries(r.contacts)) {
      if (!c.f.some((f) => f > 0)) continue;
      out.push({ run: k, label: contactLabel(r, name) + (RUNS.length > 1 ? ' [' + (k + 1) + ']' : ''), values: c.f, color: contactColor(r, name, '#333'), dash: k ? [5, 3] : [] });
    }
  });
  return out;
};
const shown = new Set();
for (const r of RUNS) {
  for (const p of r.plots || []) {
    if (plotDefs.some((d) => d.id === p.id)) continue;
    p.lines.forEach((pl) => shown.add(pl.series));
    plotDefs.push({
      id: p.id, title: p.title,
      lines: p.contacts ? forceLines() : RUNS.flatMap((q, k) => p.lines.map((pl) => lineOf(pl, q, k))).filter((l) => l.values),
    });
  }
}
for (const r of RUNS) {
  for (const s of r.series) {
    if (shown.has(s.id)) continue;
    shown.add(s.id);
    plotDefs.push({ id: s.id.replace(/[^a-z0-9]+/gi, '-'), title: s.label.charAt(0).toUpperCase() + s.label.slice(1), lines: RUNS.map((q, k) => lineOf({ series: s.id }, q, k)) });
  }
}
// Plots of quantities no run has (a pendulum has no key, no contacts) are left out.
const plots = plotDefs.filter((def) => def.lines.some((l) => l.values && l.values.length)).map((def) => {
  const box = el('div', { class: 'plot', id: 'plot-' + def.id }, plotsBox);
  el('h3', {}, box, def.title);
  const canvas = el('canvas', { id: 'plotcanvas-' + def.id }, box);
  const legend = el('div', { class: 'legend' }, box);
  def.lines.forEach((l) => {
    const s = el('span', {}, legend);
    const sw = el('i', {}, s); sw.style.background = l.color;
    s.appendChild(document.createTextNode(l.label));
  });
  let lo = Infinity, hi = -Infinity;
  for (const l of def.lines) {
    const m = l.id && RUNS[l.run].measured && RUNS[l.run].measured[l.id];
    for (const v of (l.values || []).concat(m ? m.v : [])) { lo = Math.min(lo, v); hi = Math.max(hi, v); }
    if (m && m.t.length) {
      const s = el('span', {}, legend, ' ● measured ' + RUNS[l.run].name);
      s.style.color = l.color;
    }
  }
  if (!isFinite(lo)) { lo = 0; hi = 1; }
  if (hi - lo < 1e-9) { hi += 1; lo -= 1; }
  const pad = 0.06 * (hi - lo);
  const plot = { def, canvas, lo: lo - pad, hi: hi + pad, margin: 44 };
  canvas.addEventListener('click', (ev) => {
    const rect = canvas.getBoundingClientRect();
    const x = ev.clientX - rect.left;
    const w = rect.width - plot.margin - 22;
    seek(tStart + clamp((x - plot.margin) / w, 0, 1) * (tEnd - tStart), true);
  });
  return plot;
});

function niceTicks(lo, hi, n) {
  const span = hi - lo, raw = span / n;
  const mag = Math.pow(10, Math.floor(Math.log10(raw)));
  const step = [1, 2, 5, 10].map((m) => m * mag).find((s) => s >= raw) || mag * 10;
  const out = [];
  for (let v = Math.ceil(lo / step) * step; v <= hi + 1e-12; v += step) out.push(v);
  return out;
}

function drawPlot(plot) {
  const { canvas, def } = plot;
  const dpr = sizeCanvas(canvas);
  const ctx = canvas.getContext('2d');
  const W = canvas.width, H = canvas.height;
  const m = plot.margin * dpr, top = 6 * dpr, bottom = 18 * dpr, right = 22 * dpr;
  const X = (t) => m + ((t - tStart) / (tEnd - tStart || 1)) * (W - m - right);
  const Y = (v) => top + (1 - (v - plot.lo) / (plot.hi - plot.lo)) * (H - top - bottom);
  ctx.setTransform(1, 0, 0, 1, 0, 0);
  ctx.fillStyle = '#fff'; ctx.fillRect(0, 0, W, H);
  ctx.font = (10 * dpr) + 'px system-ui, sans-serif';
  ctx.strokeStyle = '#eee'; ctx.fillStyle = '#666'; ctx.lineWidth = dpr;
  ctx.textAlign = 'right'; ctx.textBaseline = 'middle';
  for (const v of niceTicks(plot.lo, plot.hi, 4)) {
    ctx.beginPath(); ctx.moveTo(m, Y(v)); ctx.lineTo(W - right, Y(v)); ctx.stroke();
    ctx.fillText(Math.abs(v) < 1e-12 ? '0' : +v.toPrecision(4) + '', m - 4 * dpr, Y(v));
  }
  ctx.textAlign = 'center'; ctx.textBaseline = 'top';
  for (const v of niceTicks(tStart * 1e3, tEnd * 1e3, 6)) {
    ctx.beginPath(); ctx.moveTo(X(v / 1e3), top); ctx.lineTo(X(v / 1e3), H - bottom); ctx.stroke();
    ctx.fillText(+v.toPrecision(4) + ' ms', X(v / 1e3), H - bottom + 3 * dpr);
  }
  ctx.strokeStyle = 'rgba(192,57,43,0.25)';
  for (const e of events) { ctx.beginPath(); ctx.moveTo(X(e.t), top); ctx.lineTo(X(e.t), H - bottom); ctx.stroke(); }
  for (const l of def.lines) {
    if (!l.values) continue;
    const ts = RUNS[l.run].t;
    ctx.strokeStyle = l.color; ctx.lineWidth = 1.4 * dpr; ctx.setLineDash((l.dash || []).map((d) => d * dpr));
    ctx.beginPath();
    l.values.forEach((v, k) => (k ? ctx.lineTo(X(ts[k]), Y(v)) : ctx.moveTo(X(ts[k]), Y(v))));
    ctx.stroke();
    ctx.setLineDash([]);
  }
  // Measured data of the same quantity, as points.
  for (const l of def.lines) {
    const m = l.id && RUNS[l.run].measured && RUNS[l.run].measured[l.id];
    if (!m) continue;
    ctx.fillStyle = l.color;
    m.t.forEach((t, k) => {
      ctx.beginPath(); ctx.arc(X(t), Y(m.v[k]), 2.2 * dpr, 0, 2 * Math.PI); ctx.fill();
    });
  }
  ctx.strokeStyle = '#000'; ctx.lineWidth = 1.2 * dpr;
  ctx.beginPath(); ctx.moveTo(X(state.t), top); ctx.lineTo(X(state.t), H - bottom); ctx.stroke();
}

el('footer', {}, body,
  'Generated by piano report ' + DATA.version + '. Times from the start of the run; the mechanism is drawn to scale from the run\'s own data. ' +
  'Link to a moment with #t=SECONDS.');
