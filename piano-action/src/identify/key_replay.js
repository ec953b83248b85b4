// The key-drive diagnosis's replay: the action drawn to scale as the baseline (grey) and
// the corrected model (blue; purple: the best candidate of a partial explanation) move it, the tracked markers over it (red: measured; crosses:
// the model's), the gap between them magnified. REPLAY is written by the report.
(function () {
  const R = REPLAY;
  const canvas = document.getElementById('replay');
  const ctx = canvas.getContext('2d');
  const runSel = document.getElementById('replay-run');
  const zoomSel = document.getElementById('replay-zoom');
  const gainSel = document.getElementById('replay-gain');
  const slider = document.getElementById('replay-frame');
  const label = document.getElementById('replay-time');
  const play = document.getElementById('replay-play');
  R.runs.forEach((r, i) => runSel.add(new Option(r.id, i)));
  zoomSel.add(new Option('whole action', -1));
  R.markers.forEach((m, i) => zoomSel.add(new Option('around ' + m, i)));
  [1, 10, 100].forEach((g) => gainSel.add(new Option('gap ×' + g, g)));
  gainSel.value = 10;
  const colors = { baseline: '#888', corrected: '#1f77b4', 'best candidate': '#8e44ad' };

  function bounds() {
    const b = { x0: Infinity, x1: -Infinity, y0: Infinity, y1: -Infinity };
    for (const part of R.scene.parts) {
      for (const pc of part.pieces) {
        const pts = pc.kind === 'circle' ? [[pc.c[0] - pc.r, pc.c[1] - pc.r], [pc.c[0] + pc.r, pc.c[1] + pc.r]] : pc.pts;
        for (const p of pts) {
          b.x0 = Math.min(b.x0, p[0]); b.x1 = Math.max(b.x1, p[0]);
          b.y0 = Math.min(b.y0, p[1]); b.y1 = Math.max(b.y1, p[1]);
        }
      }
    }
    return b;
  }
  const whole = bounds();

  function draw() {
    const run = R.runs[+runSel.value];
    const k = Math.min(+slider.value, run.t.length - 1);
    const dpr = window.devicePixelRatio || 1;
    const W = canvas.clientWidth * dpr;
    const H = canvas.clientHeight * dpr;
    canvas.width = W; canvas.height = H;
    ctx.fillStyle = 'white'; ctx.fillRect(0, 0, W, H);
    const z = +zoomSel.value;
    let cx, cy, half;
    if (z < 0) {
      cx = (whole.x0 + whole.x1) / 2; cy = (whole.y0 + whole.y1) / 2;
      half = Math.max((whole.x1 - whole.x0) / 2, (whole.y1 - whole.y0) / 2 * W / H) * 1.05;
    } else {
      const p = run.models[0].markers[z][k];
      cx = p[0]; cy = p[1]; half = 12;
    }
    const s = W / (2 * half);
    const toScreen = (p) => [W / 2 + (p[0] - cx) * s, H / 2 - (p[1] - cy) * s];
    const gain = +gainSel.value;
    for (const model of run.models) {
      ctx.strokeStyle = colors[model.name] || '#1f77b4';
      ctx.lineWidth = 1.2 * dpr;
      for (const part of R.scene.parts) {
        const c = part.frame ? model.carry[part.frame] : null;
        const [a, x, y] = c ? [c[0][k], c[1][k], c[2][k]] : [0, 0, 0];
        const move = (p) => toScreen([x + Math.cos(a) * p[0] - Math.sin(a) * p[1], y + Math.sin(a) * p[0] + Math.cos(a) * p[1]]);
        for (const pc of part.pieces) {
          ctx.beginPath();
          if (pc.kind === 'circle') {
            const q = move(pc.c);
            ctx.arc(q[0], q[1], pc.r * s, 0, 2 * Math.PI);
          } else {
            pc.pts.forEach((p, i) => { const q = move(p); if (i) ctx.lineTo(q[0], q[1]); else ctx.moveTo(q[0], q[1]); });
            if (pc.kind === 'polygon') ctx.closePath();
          }
          ctx.stroke();
        }
      }
      // The model's markers (crosses) and the measured ones (red), the gap magnified.
      model.markers.forEach((track, m) => {
        const p = track[k];
        const meas = run.measured[m][k];
        const q = toScreen(p);
        ctx.beginPath();
        ctx.moveTo(q[0] - 5 * dpr, q[1]); ctx.lineTo(q[0] + 5 * dpr, q[1]);
        ctx.moveTo(q[0], q[1] - 5 * dpr); ctx.lineTo(q[0], q[1] + 5 * dpr);
        ctx.stroke();
        if (meas) {
          const g = toScreen([p[0] + gain * (meas[0] - p[0]), p[1] + gain * (meas[1] - p[1])]);
          ctx.beginPath(); ctx.moveTo(q[0], q[1]); ctx.lineTo(g[0], g[1]); ctx.stroke();
          ctx.fillStyle = '#d62728';
          ctx.beginPath(); ctx.arc(g[0], g[1], 3 * dpr, 0, 2 * Math.PI); ctx.fill();
        }
      });
    }
    label.textContent = (1000 * run.t[k]).toFixed(1) + ' ms, ' + run.phase[k];
    canvas.dataset.frame = k;
  }
  runSel.onchange = () => { slider.max = R.runs[+runSel.value].t.length - 1; draw(); };
  [zoomSel, gainSel].forEach((e) => { e.onchange = draw; });
  slider.oninput = draw;
  let timer = null;
  play.onclick = () => {
    if (timer) { clearInterval(timer); timer = null; play.textContent = 'play'; return; }
    play.textContent = 'pause';
    timer = setInterval(() => {
      const run = R.runs[+runSel.value];
      slider.value = (+slider.value + 1) % run.t.length;
      draw();
    }, 40);
  };
  window.addEventListener('resize', draw);
  slider.max = R.runs[0].t.length - 1;
  draw();
})();
