// The report's player: the embedded data, helpers, the page and its timeline. The report's
// script is this file, view2d.js, view3d.js, plots.js and clock.js in that order, inside one
// function (`piano report` joins them at build time). Everything it shows was computed by
// `piano report`; the script only draws. No network, no libraries, no mechanism's names:
// every name, colour, plot and headline comes from the data.

/**
 * The data `piano report` embeds (Rust: `piano_action::report::data`).
 * @typedef {Object} ReportData
 * @property {string} version  The version of piano that wrote the page.
 * @property {RunData[]} runs  The runs, each in its own view, overlaid in the plots.
 *
 * @typedef {Object} RunData
 * @property {string} name  The run's name (its folder).
 * @property {string} title  The mechanism and the input.
 * @property {string} model  The model (`double`, `pendulum`, a description's name).
 * @property {string} headline  One line under the title.
 * @property {{frames: string[], parts: Part[], contacts: Object[]}} scene  The drawing at rest.
 * @property {number[]} t  Sample times (s).
 * @property {Object<string, {a: number[], x: number[], y: number[]}>} carry  Each frame's
 *   rotation (rad) and translation (mm) from its rest place, per sample.
 * @property {Object<string, {f: number[], px: number[], py: number[], nx: number[], ny: number[]}>} contacts
 *   Each contact's normal force (N), point (mm) and unit normal, per sample.
 * @property {Object<string, string>} contact_labels  Each contact's name for a reader.
 * @property {Object<string, string>} contact_colors  Each contact's colour.
 * @property {{id: string, label: string, values: number[]}[]} series  Plotted quantities.
 * @property {Plot[]} plots  The plots, in order; a series in none gets its own.
 * @property {{name: string, time_s: number}[]} events  Every event.
 * @property {{name: string, time_s: number}[]} listed_events  The events a reader should see.
 * @property {string} minor_events  What the list leaves out.
 * @property {Object} summary  summary.json.
 * @property {Object<string, {center: number[], half_width: number}>} zoom  2D zoom presets.
 * @property {?Object<string, {t: number[], v: number[]}>} measured  Measured series by id.
 *
 * @typedef {Object} Part
 * @property {string} id
 * @property {?string} frame  The frame carrying it (null: fixed).
 * @property {boolean} behind  Seen through the mechanism.
 * @property {number} [thickness]  Across the plane (mm).
 * @property {number} [z]  Its plane's offset (mm).
 * @property {Object[]} pieces  Polygons, circles and wires, each with its fill.
 *
 * @typedef {Object} Plot
 * @property {string} id
 * @property {string} title
 * @property {{series: string, prefix?: string, dashed?: boolean}[]} lines  A line per run each.
 * @property {boolean} [contacts]  Plots every contact's force instead.
 */

/** @type {ReportData} */
const DATA = JSON.parse(document.getElementById('report-data').textContent);
const RUNS = DATA.runs;
const RUN_COLORS = ['#1f4e9c', '#c0392b', '#2e8b57', '#8e44ad', '#d35400', '#555555'];
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
// A contact's name for a reader, from the data.
const contactLabel = (run, name) => (run.contact_labels || {})[name] || name.replace(/_/g, ' ');
const fmtMs = (t) => (t * 1e3).toFixed(2) + ' ms';
// A contact's colour, from the data.
const contactColor = (run, name, fallback) => (run.contact_colors || {})[name] || fallback;

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
const info = RUNS.map((r) => r.name + ': ' + r.headline).join('   ');
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
// ones a reader should see (each run says what it leaves out); ?all-events shows every one.
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
    (allEvents.length - events.length) + ' minor events (' + [...new Set(RUNS.map((r) => r.minor_events))].join('; ') + ') not listed; open the page with ?all-events for all of them.');
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
