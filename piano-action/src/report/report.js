// The piano action report: replays the embedded runs in slow motion. Everything it shows
// was computed by `piano report`; this script only draws. No network, no libraries.
(function () {
  'use strict';

  const DATA = JSON.parse(document.getElementById('report-data').textContent);
  const RUNS = DATA.runs;
  const RUN_COLORS = ['#1f4e9c', '#c0392b', '#2e8b57', '#8e44ad', '#d35400', '#555555'];
  const CONTACT_COLORS = {
    hammer_string: '#c0392b', capstan_heel: '#2e8b57', jack_knuckle: '#8e44ad',
    lever_knuckle: '#2980b9', front_rail: '#d35400', back_rail: '#7f8c8d',
    let_off_button: '#16a085', drop_screw: '#34495e', backcheck: '#b7950b',
    rest_rail: '#95a5a6', presser_key: '#555555',
  };
  const SPEEDS = [
    ['1/1000', 0.001], ['1/300', 1 / 300], ['1/100', 0.01], ['1/30', 1 / 30],
    ['1/10', 0.1], ['1/3', 1 / 3], ['real time', 1],
  ];
  // Arrow length (screen px) for a force f (N): logarithmic, so 0.1 N and 100 N both read.
  const ARROW_PX_PER_DECADE = 22;
  const arrowPx = (f, gain) => gain * ARROW_PX_PER_DECADE * Math.log10(1 + f / 0.1);

  const tStart = Math.min(...RUNS.map((r) => r.t[0]));
  const tEnd = Math.max(...RUNS.map((r) => r.t[r.t.length - 1]));
  const frameDt = Math.min(...RUNS.map((r) => (r.t.length > 1 ? r.t[1] - r.t[0] : 1e-3)));

  const state = { t: tStart, playing: false, speed: 0.01, loop: false, gain: 1, last: null };

  // ---------------------------------------------------------------- helpers
  function el(tag, attrs, parent, text) {
    const e = document.createElement(tag);
    for (const [k, v] of Object.entries(attrs || {})) {
      if (k === 'class') e.className = v; else e.setAttribute(k, v);
    }
    if (text !== undefined) e.textContent = text;
    if (parent) parent.appendChild(e);
    return e;
  }
  const clamp = (x, a, b) => Math.min(b, Math.max(a, x));
  // A contact's name for a reader (the presser's pad is a finger's or a mass's).
  const contactLabel = (run, name) => (run.contact_labels || {})[name] || name.replace(/_/g, ' ');
  const fmtMs = (t) => (t * 1e3).toFixed(2) + ' ms';
  // A contact's colour: the run's own (a mechanism description's), else the action's.
  const contactColor = (run, name, fallback) => (run.contact_colors || {})[name] || CONTACT_COLORS[name] || fallback;

  // Index i and weight u with t between run.t[i] and run.t[i + 1].
  function locate(run, t) {
    const ts = run.t;
    if (t <= ts[0]) return [0, 0];
    if (t >= ts[ts.length - 1]) return [ts.length - 1, 0];
    let lo = 0, hi = ts.length - 1;
    while (hi - lo > 1) {
      const mid = (lo + hi) >> 1;
      if (ts[mid] <= t) lo = mid; else hi = mid;
    }
    return [lo, (t - ts[lo]) / (ts[lo + 1] - ts[lo])];
  }
  const lerp = (arr, i, u) => (u > 0 && i + 1 < arr.length ? arr[i] + u * (arr[i + 1] - arr[i]) : arr[i]);

  // ---------------------------------------------------------------- page
  const body = document.body;
  const header = el('header', {}, body);
  el('h1', {}, header, RUNS.map((r) => r.title).join('  ·  '));
  const info = RUNS.map((r) => {
    const s = r.summary || {};
    if (s.pendulum) {
      const p = s.pendulum;
      return r.name + ': ' + p.turns.length + ' turning points, period ' +
        (p.period_s ? p.period_s.toFixed(3) + ' s' : '–') + ' (small swings: ' + p.small_amplitude_period_s.toFixed(3) + ' s)';
    }
    if (s.metrics) {
      // A mechanism description's run: its metrics.
      return r.name + ': ' + (s.metrics.length ? s.metrics.map((m) => m.name + ' ' +
        (m.value === null ? '–' : m.value.toPrecision(4) + ' ' + m.unit)).join(', ') : 'no metrics');
    }
    const first = (s.strikes || [])[0];
    const v = first ? first.hammer_velocity_m_s.toFixed(2) + ' m/s at ' + fmtMs(first.time_s) : 'no strike';
    return r.name + ': ' + v;
  }).join('   ');
  el('p', {}, header, info);

  const controls = el('div', { id: 'controls' }, body);
  const btn = (id, label, title) => el('button', { id, title, type: 'button' }, controls, label);
  const bPrevEvent = btn('prev-event', '« event', 'previous event (Shift+←)');
  const bStepBack = btn('step-back', '‹ frame', 'one frame back (←)');
  const bPlay = btn('play', '▶ play', 'play / pause (Space)');
  const bStepFwd = btn('step-forward', 'frame ›', 'one frame on (→)');
  const bNextEvent = btn('next-event', 'event »', 'next event (Shift+→)');
  const timeLabel = el('span', { id: 'time' }, controls, '');
  const speedLabel = el('label', {}, controls, 'speed');
  const speedSel = el('select', { id: 'speed', title: 'slow motion (+ / −)' }, speedLabel);
  SPEEDS.forEach(([name, v]) => {
    const o = el('option', { value: String(v) }, speedSel, name);
    if (v === state.speed) o.selected = true;
  });
  const loopLabel = el('label', {}, controls, 'loop');
  const loopBox = el('input', { id: 'loop', type: 'checkbox', title: 'loop (L)' }, loopLabel);
  const zoomLabel = el('label', {}, controls, 'zoom');
  const zoomSel = el('select', { id: 'zoom', title: 'zoom presets (Z cycles)' }, zoomLabel);
  const zoomNames = ['whole action'];
  for (const run of RUNS) for (const k of Object.keys(run.zoom || {})) if (!zoomNames.includes(k)) zoomNames.push(k);
  zoomNames.forEach((z) => el('option', { value: z }, zoomSel, z));
  const gainLabel = el('label', {}, controls, 'arrows');
  const gainInput = el('input', { id: 'arrow-gain', type: 'range', min: '0.25', max: '4', step: '0.25', value: '1', title: 'force arrow length' }, gainLabel);
  el('span', { class: 'legend' }, controls,
    'keys: Space play, ←/→ frame, Shift+←/→ event, +/− speed, L loop, Z zoom, Home/End');

  const timeline = el('div', { id: 'timeline' }, body);
  const scrubber = el('input', {
    id: 'scrubber', type: 'range', min: String(tStart), max: String(tEnd), step: 'any', value: String(tStart),
  }, timeline);
  const marks = el('div', { id: 'event-marks' }, timeline);
  const eventList = el('div', { id: 'event-list' }, timeline);
  // Events of all runs, in time order, each tagged with its run. `piano report` lists the
  // ones a reader should see (no releases, no chatter, no let-off again before the jack is
  // reset, no second check without a new blow); ?all-events shows every one.
  const tagged = (key) => {
    const out = [];
    RUNS.forEach((run, k) => (run[key] || []).forEach((e) => out.push({ name: e.name, t: e.time_s, run: k })));
    return out.sort((a, b) => a.t - b.t);
  };
  const allEvents = tagged('events');
  const showAll = new URLSearchParams(location.search).has('all-events');
  const events = showAll ? allEvents : tagged('listed_events');
  if (events.length < allEvents.length) {
    el('span', { class: 'legend' }, timeline,
      (allEvents.length - events.length) + ' minor events (releases, chatter, the jack toe on its button again before the jack is reset, a second catch without a new blow) not listed; open the page with ?all-events for all of them.');
  }
  const eventButtons = events.map((e) => {
    const pos = (100 * (e.t - tStart)) / (tEnd - tStart || 1);
    const m = el('span', { title: e.name + ' at ' + fmtMs(e.t) + (RUNS.length > 1 ? ' (' + RUNS[e.run].name + ')' : '') }, marks);
    m.style.left = 'calc(' + pos + '% - 1px)';
    m.style.background = RUN_COLORS[e.run % RUN_COLORS.length];
    m.addEventListener('click', () => seek(e.t, true));
    const b = el('button', { type: 'button', 'data-time': String(e.t) }, eventList,
      e.name.replace(/_/g, ' ') + ' ' + fmtMs(e.t) + (RUNS.length > 1 ? ' [' + (e.run + 1) + ']' : ''));
    b.addEventListener('click', () => seek(e.t, true));
    return b;
  });

  const main = el('main', {}, body);

  // ---------------------------------------------------------------- 2D views
  function sceneBounds(scene) {
    const b = { x0: Infinity, x1: -Infinity, y0: Infinity, y1: -Infinity };
    const add = (p, pad) => {
      b.x0 = Math.min(b.x0, p[0] - pad); b.x1 = Math.max(b.x1, p[0] + pad);
      b.y0 = Math.min(b.y0, p[1] - pad); b.y1 = Math.max(b.y1, p[1] + pad);
    };
    for (const part of scene.parts) {
      for (const pc of part.pieces) {
        if (pc.kind === 'circle') add(pc.c, pc.r); else pc.pts.forEach((p) => add(p, 0));
      }
    }
    return b;
  }

  function carryAt(run, frame, i, u) {
    const c = run.carry[frame];
    if (!c) return [0, 0, 0];
    return [lerp(c.a, i, u), lerp(c.x, i, u), lerp(c.y, i, u)];
  }

  const views = RUNS.map((run, k) => {
    const box = el('section', { class: 'view', id: 'view-' + k }, main);
    el('h2', {}, box, (RUNS.length > 1 ? '[' + (k + 1) + '] ' : '') + run.title + ' — 2D, to scale');
    const canvas = el('canvas', { id: 'canvas2d-' + k, 'aria-label': '2D view of ' + run.title }, box);
    el('div', { class: 'note' }, box, 'Drag to pan, wheel to zoom.' + (Object.keys(run.contacts).length
      ? ' Arrows: the contact forces on the moving part, one colour per contact, named beside them; length on a log scale (legend at the bottom left).'
      : ''));
    const view = { run, canvas, box, bounds: sceneBounds(run.scene), center: null, halfWidth: null };
    fitZoom(view, 'whole action');
    let drag = null;
    canvas.addEventListener('mousedown', (ev) => { drag = [ev.clientX, ev.clientY]; canvas.style.cursor = 'grabbing'; });
    window.addEventListener('mouseup', () => { drag = null; canvas.style.cursor = 'grab'; });
    window.addEventListener('mousemove', (ev) => {
      if (!drag) return;
      const s = scaleOf(view);
      view.center = [view.center[0] - (ev.clientX - drag[0]) / s, view.center[1] + (ev.clientY - drag[1]) / s];
      drag = [ev.clientX, ev.clientY];
      draw();
    });
    canvas.addEventListener('wheel', (ev) => {
      ev.preventDefault();
      view.halfWidth = clamp(view.halfWidth * Math.exp(ev.deltaY * 0.001), 2, 2000);
      draw();
    }, { passive: false });
    return view;
  });

  // Label placement on a canvas (device px). A label is a box [x0, y0, x1, y1]; `placed`
  // holds the boxes already taken. Candidates go round the point `at` (right, left, above,
  // below, at `gap`), then ever further above and below those; each is moved inside the
  // canvas; the first that meets no placed box wins (the last resort is the freest place
  // on a column at the canvas's right edge). The chosen box joins `placed`.
  const overlap = (p, q) => p[0] < q[2] && q[0] < p[2] && p[1] < q[3] && q[1] < p[3];
  function placeLabel(ctx, text, at, gap, placed, W, H, dpr) {
    const w = ctx.measureText(text).width + 4 * dpr;
    const h = parseFloat(ctx.font) * 1.25;
    const fit = (x0, y0) => {
      const x = clamp(x0, 1, W - w - 1), y = clamp(y0, 1, H - h - 1);
      return [x, y, x + w, y + h];
    };
    const spots = [
      [at[0] + gap, at[1] - h / 2], [at[0] - gap - w, at[1] - h / 2],
      [at[0] - w / 2, at[1] - gap - h], [at[0] - w / 2, at[1] + gap],
    ];
    if (gap === 0) spots.unshift([at[0] - w / 2, at[1] - h / 2]);
    const candidates = spots.map(([x, y]) => fit(x, y));
    for (let k = 1; k * h < H; k++) {
      for (const [x, y] of spots.slice(0, 2)) candidates.push(fit(x, y - k * h), fit(x, y + k * h));
    }
    for (let y = 1; y + h < H; y += h) candidates.push(fit(W - w - 1, y));
    const box = candidates.find((b) => !placed.some((p) => overlap(p, b))) || candidates[0];
    placed.push(box);
    return box;
  }
  // Writes `text` in its box (on a white ground when `halo`); a thin line in `color` joins
  // it to `from` (if given) when the box is not already there.
  function drawLabel(ctx, text, box, from, color, dpr, halo) {
    if (from) {
      const near = [clamp(from[0], box[0], box[2]), clamp(from[1], box[1], box[3])];
      if (Math.hypot(near[0] - from[0], near[1] - from[1]) > 3 * dpr) {
        ctx.strokeStyle = color; ctx.lineWidth = 0.8 * dpr;
        ctx.beginPath(); ctx.moveTo(from[0], from[1]); ctx.lineTo(near[0], near[1]); ctx.stroke();
      }
    }
    if (halo) {
      ctx.fillStyle = 'rgba(255,255,255,0.8)';
      ctx.fillRect(box[0], box[1], box[2] - box[0], box[3] - box[1]);
    }
    ctx.fillStyle = color;
    ctx.textAlign = 'left';
    ctx.fillText(text, box[0] + 2 * dpr, (box[1] + box[3]) / 2);
  }

  function fitZoom(view, name) {
    const z = (view.run.zoom || {})[name];
    if (z) {
      view.center = z.center.slice();
      view.halfWidth = z.half_width;
    } else {
      const b = view.bounds;
      const aspect = (view.canvas.clientWidth || 600) / (view.canvas.clientHeight || 360);
      view.center = [(b.x0 + b.x1) / 2, (b.y0 + b.y1) / 2];
      view.halfWidth = 1.04 * Math.max((b.x1 - b.x0) / 2, ((b.y1 - b.y0) / 2) * aspect);
    }
  }

  function scaleOf(view) {
    const w = view.canvas.clientWidth || 600;
    return w / (2 * view.halfWidth);
  }

  function sizeCanvas(canvas) {
    const dpr = window.devicePixelRatio || 1;
    const w = Math.max(1, Math.round(canvas.clientWidth * dpr));
    const h = Math.max(1, Math.round(canvas.clientHeight * dpr));
    if (canvas.width !== w || canvas.height !== h) { canvas.width = w; canvas.height = h; }
    return dpr;
  }

  function drawView(view) {
    const { run, canvas } = view;
    const dpr = sizeCanvas(canvas);
    const ctx = canvas.getContext('2d');
    const W = canvas.width, H = canvas.height;
    ctx.setTransform(1, 0, 0, 1, 0, 0);
    ctx.fillStyle = '#ffffff';
    ctx.fillRect(0, 0, W, H);
    const s = scaleOf(view) * dpr; // device px per mm
    const toScreen = (p) => [W / 2 + (p[0] - view.center[0]) * s, H / 2 - (p[1] - view.center[1]) * s];
    const [i, u] = locate(run, state.t);
    ctx.setTransform(s, 0, 0, -s, W / 2 - view.center[0] * s, H / 2 + view.center[1] * s);
    const px = 1 / s; // one device pixel in mm
    const withFrame = (frame, fn) => {
      ctx.save();
      if (frame) {
        const [a, x, y] = carryAt(run, frame, i, u);
        ctx.translate(x, y);
        ctx.rotate(a);
      }
      fn();
      ctx.restore();
    };
    // Parts.
    for (const part of run.scene.parts) {
      withFrame(part.frame, () => {
        for (const pc of part.pieces) {
          ctx.beginPath();
          if (pc.kind === 'circle') {
            ctx.arc(pc.c[0], pc.c[1], pc.r, 0, 2 * Math.PI);
            ctx.fillStyle = pc.fill; ctx.fill();
            ctx.lineWidth = px; ctx.strokeStyle = '#333'; ctx.stroke();
          } else if (pc.kind === 'polygon') {
            pc.pts.forEach((p, k) => (k ? ctx.lineTo(p[0], p[1]) : ctx.moveTo(p[0], p[1])));
            ctx.closePath();
            ctx.fillStyle = pc.fill; ctx.fill();
            // A part seen through the action (the bracket between keys): dashed.
            if (part.behind) ctx.setLineDash([1.5, 1]);
            ctx.lineWidth = px; ctx.strokeStyle = part.behind ? '#8c8c8c' : '#333'; ctx.stroke();
            ctx.setLineDash([]);
          } else if (pc.kind === 'wire') {
            pc.pts.forEach((p, k) => (k ? ctx.lineTo(p[0], p[1]) : ctx.moveTo(p[0], p[1])));
            ctx.lineWidth = pc.width; ctx.strokeStyle = pc.fill; ctx.stroke();
          }
        }
        for (const p of part.pivots) {
          ctx.beginPath(); ctx.arc(p[0], p[1], 0.9, 0, 2 * Math.PI);
          ctx.fillStyle = '#fff'; ctx.fill(); ctx.lineWidth = px; ctx.strokeStyle = '#000'; ctx.stroke();
        }
      });
    }
    // Contact shapes (thin), as the simulation uses them.
    ctx.strokeStyle = '#1f4e9c';
    for (const c of run.scene.contacts) {
      for (const side of c.sides) {
        withFrame(side.frame, () => {
          ctx.lineWidth = px;
          for (const sh of side.shapes) {
            ctx.beginPath();
            if (sh.kind === 'circle') ctx.arc(sh.c[0], sh.c[1], sh.r, 0, 2 * Math.PI);
            else if (sh.kind === 'segment') { ctx.moveTo(sh.pts[0][0], sh.pts[0][1]); ctx.lineTo(sh.pts[1][0], sh.pts[1][1]); }
            else if (sh.kind === 'arc') ctx.arc(sh.c[0], sh.c[1], sh.r, sh.start, sh.start + sh.sweep);
            ctx.stroke();
          }
        });
      }
    }
    // Pressed contacts: which, how hard, where (arrows drawn below, in screen space).
    const active = [];
    for (const [name, c] of Object.entries(run.contacts)) {
      const k = u > 0.5 && i + 1 < c.f.length ? i + 1 : i;
      const f = lerp(c.f, i, u);
      if (!(c.f[k] > 0) || !(f > 0)) continue;
      active.push({ name, f, p: [c.px[k], c.py[k]], n: [c.nx[k], c.ny[k]], color: contactColor(run, name, '#c0392b') });
    }
    // Text in screen space. Every label is placed where it overlaps no other and stays on
    // the canvas (see placeLabel); what is written where is kept for tests.
    ctx.setTransform(1, 0, 0, 1, 0, 0);
    ctx.textBaseline = 'middle';
    const placed = [];
    view.labels = [];
    // Fixed texts first: the clock at the top left, scale bar and arrow legend at the bottom.
    ctx.fillStyle = '#111';
    ctx.font = (13 * dpr) + 'px system-ui, sans-serif';
    ctx.textAlign = 'left';
    const clock = 't = ' + fmtMs(state.t);
    ctx.fillText(clock, 10 * dpr, 14 * dpr);
    placed.push([6 * dpr, 4 * dpr, 14 * dpr + ctx.measureText(clock).width, 24 * dpr]);
    ctx.font = (11 * dpr) + 'px system-ui, sans-serif';
    const bar = [1, 2, 5, 10, 20, 50, 100].find((mm) => mm * s > 60 * dpr) || 100;
    const bx = W - 16 * dpr - bar * s, by = H - 14 * dpr;
    ctx.strokeStyle = '#000'; ctx.lineWidth = 1.5 * dpr;
    ctx.beginPath(); ctx.moveTo(bx, by); ctx.lineTo(bx + bar * s, by);
    ctx.moveTo(bx, by - 4 * dpr); ctx.lineTo(bx, by + 4 * dpr);
    ctx.moveTo(bx + bar * s, by - 4 * dpr); ctx.lineTo(bx + bar * s, by + 4 * dpr); ctx.stroke();
    ctx.textAlign = 'center'; ctx.fillText(bar + ' mm', bx + (bar * s) / 2, by - 9 * dpr);
    placed.push([bx - 4 * dpr, by - 17 * dpr, bx + bar * s + 4 * dpr, H]);
    ctx.textAlign = 'left';
    // Arrow legend: length only (the colour names the contact); none without contacts.
    if (Object.keys(run.contacts).length) {
      let lx = 10 * dpr;
      const ly = H - 14 * dpr;
      ctx.fillStyle = '#444'; ctx.strokeStyle = '#444'; ctx.lineWidth = 2 * dpr;
      for (const f of [1, 10, 100]) {
        const len = arrowPx(f, state.gain) * dpr;
        ctx.beginPath(); ctx.moveTo(lx, ly); ctx.lineTo(lx + len, ly); ctx.stroke();
        ctx.fillText(f + ' N', lx + len + 3 * dpr, ly);
        lx += len + 40 * dpr;
      }
      placed.push([0, ly - 9 * dpr, lx, H]);
    }

    // Force arrows on the moving part, log scaled in screen pixels so they read at any
    // zoom: 0.1 N, 1 N, 10 N and 100 N are equal steps (see the legend).
    view.arrowTips = {};
    const arrows = active.map((a) => {
      const L = arrowPx(a.f, state.gain) * dpr;
      const p0 = toScreen(a.p);
      const d = [a.n[0], -a.n[1]];
      const tip = [p0[0] + d[0] * L, p0[1] + d[1] * L];
      ctx.strokeStyle = a.color; ctx.fillStyle = a.color; ctx.lineWidth = 2.5 * dpr;
      ctx.beginPath(); ctx.moveTo(p0[0], p0[1]); ctx.lineTo(tip[0], tip[1]); ctx.stroke();
      const h = 8 * dpr, w = 4 * dpr;
      ctx.beginPath();
      ctx.moveTo(tip[0] + d[0] * h, tip[1] + d[1] * h);
      ctx.lineTo(tip[0] - d[1] * w, tip[1] + d[0] * w);
      ctx.lineTo(tip[0] + d[1] * w, tip[1] - d[0] * w);
      ctx.closePath(); ctx.fill();
      ctx.beginPath(); ctx.arc(p0[0], p0[1], 3 * dpr, 0, 2 * Math.PI); ctx.fill();
      view.arrowTips[a.name] = [(p0[0] + tip[0]) / 2, (p0[1] + tip[1]) / 2];
      return { a, tip: [tip[0] + d[0] * h, tip[1] + d[1] * h] };
    });
    // Their labels, the largest force first: beside the arrow head if there is room, else
    // the nearest free place, joined to the head by a thin line.
    ctx.font = (11 * dpr) + 'px system-ui, sans-serif';
    arrows.sort((p, q) => q.a.f - p.a.f);
    for (const { a, tip } of arrows) {
      // An arrow whose head is off the canvas (zoomed elsewhere) is not named.
      if (tip[0] < 0 || tip[0] > W || tip[1] < 0 || tip[1] > H) continue;
      const text = contactLabel(run, a.name) + ' ' + a.f.toFixed(a.f < 10 ? 2 : 1) + ' N';
      const box = placeLabel(ctx, text, tip, 6 * dpr, placed, W, H, dpr);
      drawLabel(ctx, text, box, tip, a.color, dpr, true);
      view.labels.push({ text, kind: 'force', box });
    }
    // Part names (smaller when the whole action is in view) where they do not hide a
    // force label; a name whose part is off the canvas is not written.
    ctx.font = ((view.halfWidth < 120 ? 11 : 9.5) * dpr) + 'px system-ui, sans-serif';
    for (const part of run.scene.parts) {
      const [a, x, y] = part.frame ? carryAt(run, part.frame, i, u) : [0, 0, 0];
      for (const l of part.labels) {
        const q = [x + Math.cos(a) * l.anchor[0] - Math.sin(a) * l.anchor[1], y + Math.sin(a) * l.anchor[0] + Math.cos(a) * l.anchor[1]];
        const anchor = toScreen(q);
        const at = toScreen([q[0] + l.offset[0], q[1] + l.offset[1]]);
        if (at[0] < 0 || at[0] > W || at[1] < 0 || at[1] > H) continue;
        const w = ctx.measureText(l.text).width;
        const x0 = l.align === 'middle' ? at[0] - w / 2 : l.align === 'end' ? at[0] - w : at[0];
        const box = placeLabel(ctx, l.text, [x0 + w / 2, at[1]], 0, placed, W, H, dpr);
        const moved = Math.abs((box[0] + box[2]) / 2 - (x0 + w / 2)) > 1 || Math.abs((box[1] + box[3]) / 2 - at[1]) > 1;
        const lead = moved || l.offset[0] !== 0 || l.offset[1] !== 0;
        drawLabel(ctx, l.text, box, lead ? anchor : null, '#555', dpr);
        view.labels.push({ text: l.text, kind: 'part', box });
      }
    }
    view.canvas.dataset.activeContacts = active.map((a) => a.name).join(' ');
  }

  // ---------------------------------------------------------------- 3D views
  // Our own small WebGL renderer: every part's outline extruded by its thickness, moved by
  // its frame's motion, lit by one light, seen through an orbit camera.
  const THICKNESS = {
    'fixed-parts': 36, 'body-key': 22, 'body-wippen': 14, 'body-jack': 8,
    'body-repetition_lever': 10, 'body-hammer': 14, 'key-backcheck': 14, 'body-presser': 14,
    'key-capstan': 8, 'action-bracket': 10,
  };
  // A part seen through the action (the bracket, between keys) stands this far behind it.
  const BEHIND_Z = -40;
  const hexColor = (h) => [1, 3, 5].map((k) => parseInt(h.slice(k, k + 2), 16) / 255);

  // Ear clipping of a simple polygon (any winding) into triangles of indices.
  function triangulate(pts) {
    const n = pts.length;
    if (n < 3) return [];
    let area = 0;
    for (let k = 0; k < n; k++) {
      const a = pts[k], b = pts[(k + 1) % n];
      area += a[0] * b[1] - b[0] * a[1];
    }
    const idx = [...Array(n).keys()];
    if (area < 0) idx.reverse();
    const cross = (o, a, b) => (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]);
    const inside = (p, a, b, c) => cross(a, b, p) >= 0 && cross(b, c, p) >= 0 && cross(c, a, p) >= 0;
    const tris = [];
    let guard = 0;
    while (idx.length > 3 && guard++ < 10000) {
      let cut = false;
      for (let k = 0; k < idx.length; k++) {
        const i0 = idx[(k + idx.length - 1) % idx.length], i1 = idx[k], i2 = idx[(k + 1) % idx.length];
        const a = pts[i0], b = pts[i1], c = pts[i2];
        if (cross(a, b, c) <= 1e-12) continue;
        if (idx.some((j) => j !== i0 && j !== i1 && j !== i2 && inside(pts[j], a, b, c))) continue;
        tris.push([i0, i1, i2]);
        idx.splice(k, 1);
        cut = true;
        break;
      }
      if (!cut) break;
    }
    if (idx.length === 3) tris.push(idx.slice());
    else for (let k = 1; k + 1 < idx.length; k++) tris.push([idx[0], idx[k], idx[k + 1]]);
    return tris;
  }

  function circlePts(c, r, n) {
    return [...Array(n).keys()].map((k) => [c[0] + r * Math.cos((2 * Math.PI * k) / n), c[1] + r * Math.sin((2 * Math.PI * k) / n)]);
  }

  function wirePts(pts, w) {
    // A thin band around the polyline's first segment chain (enough for wires and screws).
    const left = [], right = [];
    for (let k = 0; k < pts.length; k++) {
      const a = pts[Math.max(0, k - 1)], b = pts[Math.min(pts.length - 1, k + 1)];
      let d = [b[0] - a[0], b[1] - a[1]];
      const L = Math.hypot(d[0], d[1]) || 1;
      d = [-d[1] / L * w / 2, d[0] / L * w / 2];
      left.push([pts[k][0] + d[0], pts[k][1] + d[1]]);
      right.push([pts[k][0] - d[0], pts[k][1] - d[1]]);
    }
    return left.concat(right.reverse());
  }

  // Triangles (x, y, z, nx, ny, nz) of a polygon extruded from z = -h/2 to h/2.
  function extrude(pts, h, out, zc) {
    const z0 = (zc || 0) - h / 2, z1 = (zc || 0) + h / 2;
    for (const [a, b, c] of triangulate(pts)) {
      for (const i of [a, b, c]) out.push(pts[i][0], pts[i][1], z1, 0, 0, 1);
      for (const i of [a, c, b]) out.push(pts[i][0], pts[i][1], z0, 0, 0, -1);
    }
    for (let k = 0; k < pts.length; k++) {
      const p = pts[k], q = pts[(k + 1) % pts.length];
      const d = [q[0] - p[0], q[1] - p[1]];
      const L = Math.hypot(d[0], d[1]);
      if (L < 1e-9) continue;
      const n = [d[1] / L, -d[0] / L];
      const quad = [[p, z0], [q, z0], [q, z1], [p, z0], [q, z1], [p, z1]];
      for (const [r, z] of quad) out.push(r[0], r[1], z, n[0], n[1], 0);
    }
  }

  const M4 = {
    mul(a, b) {
      const o = new Float32Array(16);
      for (let i = 0; i < 4; i++) for (let j = 0; j < 4; j++) {
        let s = 0;
        for (let k = 0; k < 4; k++) s += a[k * 4 + j] * b[i * 4 + k];
        o[i * 4 + j] = s;
      }
      return o;
    },
    perspective(fov, aspect, near, far) {
      const f = 1 / Math.tan(fov / 2), nf = 1 / (near - far);
      return new Float32Array([f / aspect, 0, 0, 0, 0, f, 0, 0, 0, 0, (far + near) * nf, -1, 0, 0, 2 * far * near * nf, 0]);
    },
    lookAt(eye, at, up) {
      const sub = (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
      const crs = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
      const nrm = (a) => { const l = Math.hypot(a[0], a[1], a[2]) || 1; return [a[0] / l, a[1] / l, a[2] / l]; };
      const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
      const z = nrm(sub(eye, at)), x = nrm(crs(up, z)), y = crs(z, x);
      return new Float32Array([x[0], y[0], z[0], 0, x[1], y[1], z[1], 0, x[2], y[2], z[2], 0, -dot(x, eye), -dot(y, eye), -dot(z, eye), 1]);
    },
    // Rotation a about z, then translation (x, y).
    planar(a, x, y) {
      const c = Math.cos(a), s = Math.sin(a);
      return new Float32Array([c, s, 0, 0, -s, c, 0, 0, 0, 0, 1, 0, x, y, 0, 1]);
    },
  };

  const VS = 'attribute vec3 pos; attribute vec3 nrm; uniform mat4 mvp; uniform mat4 model; varying vec3 vN;' +
    'void main() { vN = (model * vec4(nrm, 0.0)).xyz; gl_Position = mvp * vec4(pos, 1.0); }';
  const FS = 'precision mediump float; varying vec3 vN; uniform vec3 color; uniform vec3 light;' +
    'void main() { float d = abs(dot(normalize(vN), light)); gl_FragColor = vec4(color * (0.38 + 0.62 * d), 1.0); }';

  function setup3d(view) {
    const { canvas, run } = view;
    let gl = null;
    try {
      gl = canvas.getContext('webgl', { preserveDrawingBuffer: true, antialias: true });
    } catch (e) { gl = null; }
    if (!gl) return false;
    const compile = (type, src) => {
      const sh = gl.createShader(type);
      gl.shaderSource(sh, src); gl.compileShader(sh);
      if (!gl.getShaderParameter(sh, gl.COMPILE_STATUS)) throw new Error(gl.getShaderInfoLog(sh));
      return sh;
    };
    const prog = gl.createProgram();
    gl.attachShader(prog, compile(gl.VERTEX_SHADER, VS));
    gl.attachShader(prog, compile(gl.FRAGMENT_SHADER, FS));
    gl.linkProgram(prog);
    if (!gl.getProgramParameter(prog, gl.LINK_STATUS)) throw new Error(gl.getProgramInfoLog(prog));
    const meshes = [];
    for (const part of run.scene.parts) {
      // A description's part carries its own thickness and plane (mm).
      const h = part.thickness || THICKNESS[part.id] || 10;
      const zc = part.behind ? BEHIND_Z : (part.z || 0);
      for (const pc of part.pieces) {
        const data = [];
        if (pc.kind === 'polygon') extrude(pc.pts, h, data, zc);
        else if (pc.kind === 'circle') extrude(circlePts(pc.c, pc.r, 28), h * 0.8, data, zc);
        else if (pc.kind === 'wire') extrude(wirePts(pc.pts, pc.width), Math.max(pc.width, 1.5), data, zc);
        if (!data.length) continue;
        const buf = gl.createBuffer();
        gl.bindBuffer(gl.ARRAY_BUFFER, buf);
        gl.bufferData(gl.ARRAY_BUFFER, new Float32Array(data), gl.STATIC_DRAW);
        meshes.push({ frame: part.frame, buf, count: data.length / 6, color: hexColor(pc.fill) });
      }
    }
    const b = sceneBounds(run.scene);
    view.gl = gl;
    view.prog = prog;
    view.meshes = meshes;
    view.loc = {
      pos: gl.getAttribLocation(prog, 'pos'), nrm: gl.getAttribLocation(prog, 'nrm'),
      mvp: gl.getUniformLocation(prog, 'mvp'), model: gl.getUniformLocation(prog, 'model'),
      color: gl.getUniformLocation(prog, 'color'), light: gl.getUniformLocation(prog, 'light'),
    };
    view.target = [(b.x0 + b.x1) / 2, (b.y0 + b.y1) / 2, 0];
    // Far enough back for the whole width, and for the whole height (a hanging hammer).
    view.distance = Math.max(1.3 * (b.x1 - b.x0), 1.9 * (b.y1 - b.y0));
    view.azimuth = -0.42;
    view.elevation = 0.22;
    return true;
  }

  function drawView3d(view) {
    if (!view.gl) return;
    const { gl, run, canvas, loc } = view;
    sizeCanvas(canvas);
    gl.viewport(0, 0, canvas.width, canvas.height);
    gl.clearColor(0.97, 0.97, 0.96, 1);
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
    gl.enable(gl.DEPTH_TEST);
    gl.useProgram(view.prog);
    const ce = Math.cos(view.elevation);
    const eye = [
      view.target[0] + view.distance * ce * Math.sin(view.azimuth),
      view.target[1] + view.distance * Math.sin(view.elevation),
      view.target[2] + view.distance * ce * Math.cos(view.azimuth),
    ];
    const proj = M4.perspective(0.6, canvas.width / Math.max(1, canvas.height), view.distance / 50, view.distance * 5);
    const pv = M4.mul(proj, M4.lookAt(eye, view.target, [0, 1, 0]));
    const l = [0.35, 0.75, 0.56];
    gl.uniform3fv(loc.light, l);
    const [i, u] = locate(run, state.t);
    for (const m of view.meshes) {
      const [a, x, y] = m.frame ? carryAt(run, m.frame, i, u) : [0, 0, 0];
      const model = M4.planar(a, x, y);
      gl.uniformMatrix4fv(loc.model, false, model);
      gl.uniformMatrix4fv(loc.mvp, false, M4.mul(pv, model));
      gl.uniform3fv(loc.color, m.color);
      gl.bindBuffer(gl.ARRAY_BUFFER, m.buf);
      gl.enableVertexAttribArray(loc.pos);
      gl.vertexAttribPointer(loc.pos, 3, gl.FLOAT, false, 24, 0);
      gl.enableVertexAttribArray(loc.nrm);
      gl.vertexAttribPointer(loc.nrm, 3, gl.FLOAT, false, 24, 12);
      gl.drawArrays(gl.TRIANGLES, 0, m.count);
    }
  }

  const views3d = RUNS.map((run, k) => {
    const box = el('section', { class: 'view view3d', id: 'view3d-' + k }, main);
    el('h2', {}, box, (RUNS.length > 1 ? '[' + (k + 1) + '] ' : '') + run.title + ' — 3D');
    const canvas = el('canvas', { id: 'canvas3d-' + k, 'aria-label': '3D view of ' + run.title }, box);
    const view = { run, canvas, gl: null };
    let ok = false;
    try { ok = setup3d(view); } catch (e) { ok = false; view.gl = null; }
    if (!ok) {
      canvas.remove();
      el('p', { class: 'note', id: 'no-webgl-' + k }, box,
        'The 3D view needs WebGL, which this browser does not offer here; the 2D view and the plots show the same motion.');
      return view;
    }
    el('div', { class: 'note' }, box, 'Drag to orbit, wheel to come closer. Parts extruded by their thickness.');
    let drag = null;
    canvas.addEventListener('mousedown', (ev) => { drag = [ev.clientX, ev.clientY]; });
    window.addEventListener('mouseup', () => { drag = null; });
    window.addEventListener('mousemove', (ev) => {
      if (!drag) return;
      view.azimuth -= (ev.clientX - drag[0]) * 0.01;
      view.elevation = clamp(view.elevation + (ev.clientY - drag[1]) * 0.01, -1.5, 1.5);
      drag = [ev.clientX, ev.clientY];
      drawView3d(view);
    });
    canvas.addEventListener('wheel', (ev) => {
      ev.preventDefault();
      view.distance = clamp(view.distance * Math.exp(ev.deltaY * 0.001), 30, 5000);
      drawView3d(view);
    }, { passive: false });
    return view;
  });

  // ---------------------------------------------------------------- plots
  const plotsBox = el('section', { id: 'plots' }, main);
  const plotDefs = [];
  const seriesOf = (run, id) => (run.series.find((s) => s.id === id) || {}).values;
  // A plot's title from its series' label in the first run that has it (a pendulum's
  // hammer angle is from hanging).
  const titleOf = (id, fallback) => {
    const s = RUNS.map((r) => r.series.find((x) => x.id === id)).find((x) => x);
    return s ? s.label.charAt(0).toUpperCase() + s.label.slice(1) : fallback;
  };
  plotDefs.push({ id: 'hammer-angle', title: titleOf('hammer_angle_deg', 'Hammer angle (°)'), lines: RUNS.map((r, k) => ({ run: k, id: 'hammer_angle_deg', label: r.name, values: seriesOf(r, 'hammer_angle_deg'), color: RUN_COLORS[k % 6] })) });
  plotDefs.push({ id: 'hammer-speed', title: 'Hammer speed at the strike point (m/s)', lines: RUNS.map((r, k) => ({ run: k, id: 'hammer_speed_m_s', label: r.name, values: seriesOf(r, 'hammer_speed_m_s'), color: RUN_COLORS[k % 6] })) });
  plotDefs.push({ id: 'key-depth', title: 'Key-front depth below rest (mm)', lines: RUNS.map((r, k) => ({ run: k, id: 'key_depth_mm', label: r.name, values: seriesOf(r, 'key_depth_mm'), color: RUN_COLORS[k % 6] })) });
  const forceLines = [];
  RUNS.forEach((r, k) => {
    for (const [name, c] of Object.entries(r.contacts)) {
      if (!c.f.some((f) => f > 0)) continue;
      forceLines.push({ run: k, label: contactLabel(r, name) + (RUNS.length > 1 ? ' [' + (k + 1) + ']' : ''), values: c.f, color: contactColor(r, name, '#333'), dash: k ? [5, 3] : [] });
    }
  });
  plotDefs.push({ id: 'contact-forces', title: 'Contact forces (N)', lines: forceLines });
  plotDefs.push({ id: 'energy', title: 'Energy (mJ): kinetic (solid), gravity from rest (dashed)', lines: RUNS.flatMap((r, k) => [
    { run: k, label: 'kinetic ' + r.name, values: seriesOf(r, 'kinetic_mj'), color: RUN_COLORS[k % 6] },
    { run: k, label: 'gravity ' + r.name, values: seriesOf(r, 'gravity_mj'), color: RUN_COLORS[k % 6], dash: [5, 3] },
  ]) });
  if (RUNS.some((r) => seriesOf(r, 'key_drive_force_n'))) {
    plotDefs.push({ id: 'hand-force', title: 'Hand force at the key front (N)', lines: RUNS.map((r, k) => ({ run: k, id: 'key_drive_force_n', label: r.name, values: seriesOf(r, 'key_drive_force_n'), color: RUN_COLORS[k % 6] })).filter((l) => l.values) });
  }
  // A mechanism description's own series (coordinates, marker speeds): one plot each.
  const shown = new Set(['hammer_angle_deg', 'hammer_speed_m_s', 'key_depth_mm', 'kinetic_mj', 'gravity_mj', 'key_drive_force_n']);
  for (const r of RUNS) {
    for (const s of r.series) {
      if (shown.has(s.id)) continue;
      shown.add(s.id);
      plotDefs.push({ id: s.id.replace(/[^a-z0-9]+/gi, '-'), title: s.label.charAt(0).toUpperCase() + s.label.slice(1), lines: RUNS.map((q, k) => ({ run: k, id: s.id, label: q.name, values: seriesOf(q, s.id), color: RUN_COLORS[k % 6] })) });
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
    'Generated by piano report ' + DATA.version + '. Times from the start of the run; the action is drawn to scale from the run\'s parameters. ' +
    'Link to a moment with #t=SECONDS.');

  // ---------------------------------------------------------------- clock
  function draw() {
    views.forEach(drawView);
    views3d.forEach(drawView3d);
    plots.forEach(drawPlot);
    timeLabel.textContent = 't = ' + fmtMs(state.t) + ' / ' + fmtMs(tEnd);
    scrubber.value = String(state.t);
    eventButtons.forEach((b, k) => b.classList.toggle('past', events[k].t <= state.t + 1e-12));
    bPlay.textContent = state.playing ? '❚❚ pause' : '▶ play';
    body.dataset.time = String(state.t);
    body.dataset.playing = String(state.playing);
  }

  function seek(t, updateHash) {
    state.t = clamp(t, tStart, tEnd);
    if (updateHash) {
      try { history.replaceState(null, '', '#t=' + state.t.toFixed(6)); } catch (e) { /* file:// may refuse */ }
    }
    draw();
  }

  function play(on) {
    state.playing = on;
    state.last = null;
    if (on && state.t >= tEnd) state.t = tStart;
    if (!on) seek(state.t, true); else draw();
    if (on) requestAnimationFrame(tick);
  }

  function tick(now) {
    if (!state.playing) return;
    if (state.last !== null) {
      let t = state.t + ((now - state.last) / 1000) * state.speed;
      if (t > tEnd) {
        if (state.loop) t = tStart + ((t - tStart) % (tEnd - tStart || 1));
        else { state.t = tEnd; play(false); return; }
      }
      state.t = t;
      draw();
    }
    state.last = now;
    requestAnimationFrame(tick);
  }

  const step = (k) => { play(false); seek(state.t + k * frameDt, true); };
  function jumpEvent(dir) {
    play(false);
    const eps = 1e-9;
    const e = dir > 0 ? events.find((x) => x.t > state.t + eps) : [...events].reverse().find((x) => x.t < state.t - eps);
    if (e) seek(e.t, true);
  }
  function setSpeed(delta) {
    const k = clamp(SPEEDS.findIndex(([, v]) => v === state.speed) + delta, 0, SPEEDS.length - 1);
    state.speed = SPEEDS[k][1];
    speedSel.value = String(state.speed);
  }

  bPlay.addEventListener('click', () => play(!state.playing));
  bStepBack.addEventListener('click', () => step(-1));
  bStepFwd.addEventListener('click', () => step(1));
  bPrevEvent.addEventListener('click', () => jumpEvent(-1));
  bNextEvent.addEventListener('click', () => jumpEvent(1));
  speedSel.addEventListener('change', () => { state.speed = parseFloat(speedSel.value); });
  loopBox.addEventListener('change', () => { state.loop = loopBox.checked; });
  zoomSel.addEventListener('change', () => { views.forEach((v) => fitZoom(v, zoomSel.value)); draw(); });
  gainInput.addEventListener('input', () => { state.gain = parseFloat(gainInput.value); draw(); });
  scrubber.addEventListener('input', () => {
    const t = parseFloat(scrubber.value);
    state.playing = false;
    seek(t, true);
  });
  window.addEventListener('resize', () => { views.forEach((v) => fitZoom(v, zoomSel.value)); draw(); });
  window.addEventListener('keydown', (ev) => {
    if (ev.target && ev.target.tagName === 'SELECT') return;
    switch (ev.key) {
      case ' ': ev.preventDefault(); play(!state.playing); break;
      case 'ArrowRight': ev.preventDefault(); ev.shiftKey ? jumpEvent(1) : step(1); break;
      case 'ArrowLeft': ev.preventDefault(); ev.shiftKey ? jumpEvent(-1) : step(-1); break;
      case '+': case '=': setSpeed(1); break;
      case '-': case '_': setSpeed(-1); break;
      case 'l': case 'L': state.loop = !state.loop; loopBox.checked = state.loop; break;
      case 'z': case 'Z': {
        zoomSel.selectedIndex = (zoomSel.selectedIndex + 1) % zoomSel.options.length;
        views.forEach((v) => fitZoom(v, zoomSel.value)); draw(); break;
      }
      case 'Home': seek(tStart, true); break;
      case 'End': seek(tEnd, true); break;
      default: return;
    }
  });

  function fromHash() {
    const m = /(?:^#|&)t=([-+0-9.eE]+)/.exec(location.hash);
    if (m && isFinite(parseFloat(m[1]))) { play(false); seek(parseFloat(m[1]), false); }
  }
  window.addEventListener('hashchange', fromHash);

  // For tests and for scripting from the console.
  window.pianoReport = {
    seek: (t) => seek(t, true), play: () => play(true), pause: () => play(false),
    time: () => state.t, playing: () => state.playing, setSpeed: (v) => { state.speed = v; speedSel.value = String(v); },
    events: () => events.slice(), runs: () => RUNS.map((r) => r.name),
    hammerAngle: (k) => { const r = RUNS[k || 0]; const [i, u] = locate(r, state.t); return lerp(seriesOf(r, 'hammer_angle_deg'), i, u); },
    activeContacts: (k) => views[k || 0].canvas.dataset.activeContacts.split(' ').filter(Boolean),
    arrowTip: (name, k) => (views[k || 0].arrowTips || {})[name] || null,
    range: () => [tStart, tEnd],
    frame: (k) => locate(RUNS[k || 0], state.t)[0],
    frameTime: (i, k) => RUNS[k || 0].t[i],
    angleAtFrame: (i, k) => seriesOf(RUNS[k || 0], 'hammer_angle_deg')[i],
    webgl: (k) => !!views3d[k || 0].gl,
    // Every text written on the 2D view now: its words, 'force' or 'part', and its box
    // [x0, y0, x1, y1] in canvas pixels; and the canvas size in the same pixels.
    labels: (k) => (views[k || 0].labels || []).map((l) => ({ text: l.text, kind: l.kind, box: l.box.slice() })),
    canvasSize: (k) => [views[k || 0].canvas.width, views[k || 0].canvas.height],
    plots: () => plots.map((p) => p.def.id),
    // Where a body (a frame of the scene) is carried now: [angle rad, x mm, y mm].
    carry: (frame, k) => { const r = RUNS[k || 0]; const [i, u] = locate(r, state.t); return carryAt(r, frame, i, u); },
  };

  draw();
  fromHash();
})();
