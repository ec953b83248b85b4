// The report's clock: playback, keys, links to a moment, and the hooks for tests.
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
  seriesValue: (id, k) => { const r = RUNS[k || 0]; const [i, u] = locate(r, state.t); return lerp(seriesOf(r, id), i, u); },
  activeContacts: (k) => views[k || 0].canvas.dataset.activeContacts.split(' ').filter(Boolean),
  arrowTip: (name, k) => (views[k || 0].arrowTips || {})[name] || null,
  range: () => [tStart, tEnd],
  frame: (k) => locate(RUNS[k || 0], state.t)[0],
  frameTime: (i, k) => RUNS[k || 0].t[i],
  seriesAtFrame: (id, i, k) => seriesOf(RUNS[k || 0], id)[i],
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
