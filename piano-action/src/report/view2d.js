// The report's 2D views: each run's mechanism drawn to scale, with its contact forces.
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
          // A part seen through the mechanism (behind it): dashed.
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
