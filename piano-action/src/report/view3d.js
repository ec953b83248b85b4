// The report's 3D views: every part extruded by its thickness, in WebGL.
// ---------------------------------------------------------------- 3D views
// Our own small WebGL renderer: every part's outline extruded by its thickness, moved by
// its frame's motion, lit by one light, seen through an orbit camera.
// A part seen through the mechanism (behind it) stands this far behind it.
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
    // Every part carries its thickness and plane (mm).
    const h = part.thickness || 10;
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
  // Far enough back for the whole width, and for the whole height (a hanging part).
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
