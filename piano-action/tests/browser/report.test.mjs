// Opens a real piano report in headless Chromium and checks what a person would:
// no console error, no network request, Play advances time (less at a slower speed) and
// the hammer moves, the scrubber and #t= seek to the right frame, the hammer–string arrow
// shows at string contact, no two labels overlap or leave the 2D view, the event list does
// not call chatter a let-off, clicking a plot seeks. Saves screenshots for a person to
// look at. No check depends on how fast this machine is: playback runs on Playwright's
// fake clock, and the time the page takes to open is printed, not judged.
//
// node report.test.mjs REPORT.html SCREENSHOT_DIR STRIKE_TIME_S
import { chromium } from 'playwright-core';
import { mkdirSync } from 'node:fs';

const [report, shots, strikeArg] = process.argv.slice(2);
const strike = parseFloat(strikeArg);
mkdirSync(shots, { recursive: true });
const failures = [];
const check = (ok, what) => { if (!ok) failures.push(what); console.log((ok ? 'ok   ' : 'FAIL ') + what); };

const browser = await chromium.launch({
  executablePath: process.env.CHROMIUM || '/usr/bin/chromium',
  args: ['--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
    '--disable-background-networking', '--disable-component-update', '--disable-sync'],
});
try {
  const page = await browser.newPage({ viewport: { width: 1400, height: 1000 } });
  const errors = [];
  const requests = [];
  page.on('console', (m) => { if (m.type() === 'error') errors.push(m.text()); });
  page.on('pageerror', (e) => errors.push(String(e)));
  page.on('request', (r) => { if (!r.url().startsWith('file://')) requests.push(r.url()); });

  const url = 'file://' + report;
  const started = Date.now();
  await page.goto(url);
  await page.waitForFunction(() => window.pianoReport !== undefined);
  console.log('info the report opened in ' + (Date.now() - started) + ' ms (not a check)');
  await page.screenshot({ path: shots + '/01-opened.png' });

  const R = (fn, arg) => page.evaluate(fn, arg);

  // Play advances the clock by the chosen speed, paused it stands still. On Playwright's
  // fake clock, stopped (pauseAt) so that only runFor moves it, the page sees exactly the
  // time we let pass, whatever the machine's load.
  {
    const timed = await browser.newPage({ viewport: { width: 1400, height: 1000 } });
    timed.on('pageerror', (e) => errors.push(String(e)));
    await timed.clock.install({ time: 0 });
    await timed.goto(url);
    await timed.waitForFunction(() => window.pianoReport !== undefined);
    await timed.clock.pauseAt(100000);
    const T = (fn, arg) => timed.evaluate(fn, arg);
    const playFor = async (speed, ms) => {
      await T((v) => { window.pianoReport.seek(0); window.pianoReport.setSpeed(v); window.pianoReport.play(); }, speed);
      await timed.clock.runFor(ms);
      await T(() => window.pianoReport.pause());
      return T(() => window.pianoReport.time());
    };
    const a0 = await T(() => window.pianoReport.seriesValue('hammer_angle_deg'));
    const fast = await playFor(0.1, 600);
    const a1 = await T(() => window.pianoReport.seriesValue('hammer_angle_deg'));
    const slow = await playFor(0.01, 600);
    check(fast > 0 && slow > 0, 'Play advances time (' + (fast * 1e3).toFixed(2) + ' ms at 1/10, ' + (slow * 1e3).toFixed(2) + ' ms at 1/100, in 600 ms)');
    check(slow < fast, 'a slower speed advances it less');
    check(Math.abs(fast / slow - 10) < 0.5, 'ten times slower advances ten times less (' + (fast / slow).toFixed(2) + ')');
    check(Math.abs(a1 - a0) > 0.5, 'the hammer moves (' + a0.toFixed(2) + '° → ' + a1.toFixed(2) + '°)');
    const paused = await T(() => window.pianoReport.time());
    await timed.clock.runFor(600);
    check(!(await T(() => window.pianoReport.playing())) && (await T(() => window.pianoReport.time())) === paused, 'pause stops the clock');
    await timed.close();
  }

  // The scrubber seeks.
  await page.$eval('#scrubber', (e, v) => { e.value = v; e.dispatchEvent(new Event('input')); }, String(strike));
  const ts = await R(() => window.pianoReport.time());
  check(Math.abs(ts - strike) < 1e-9, 'the scrubber seeks to ' + strike + ' s (' + ts + ')');

  // ... to the right frame: frame 40 shows frame 40's hammer.
  const t40 = await R(() => window.pianoReport.frameTime(40));
  await page.$eval('#scrubber', (e, v) => { e.value = v; e.dispatchEvent(new Event('input')); }, String(t40));
  const [f40, a40, want40] = await R(() => [window.pianoReport.frame(), window.pianoReport.seriesValue('hammer_angle_deg'), window.pianoReport.seriesAtFrame('hammer_angle_deg', 40)]);
  check(f40 === 40 && Math.abs(a40 - want40) < 1e-9, 'the scrubber shows frame 40 and its hammer angle (' + f40 + ', ' + a40 + '°)');

  // #t= seeks, also on hashchange.
  await R(() => { location.hash = '#t=0.05'; });
  await page.waitForFunction(() => Math.abs(window.pianoReport.time() - 0.05) < 1e-9, null, { timeout: 60000 }).catch(() => {}); // a hang guard, not a time check
  check(Math.abs((await R(() => window.pianoReport.time())) - 0.05) < 1e-9 && (await R(() => window.pianoReport.frame())) === 50, '#t=0.05 seeks on hashchange, to frame 50');
  const deep = await browser.newPage({ viewport: { width: 1400, height: 1000 } });
  deep.on('pageerror', (e) => errors.push(String(e)));
  await deep.goto(url + '#t=' + strike);
  await deep.waitForFunction(() => window.pianoReport !== undefined);
  check(Math.abs((await deep.evaluate(() => window.pianoReport.time())) - strike) < 1e-9, 'a deep link #t= opens at that time');
  await deep.close();

  // At string contact the hammer–string arrow is drawn.
  const during = strike + 0.0004;
  await R((t) => window.pianoReport.seek(t), during);
  const active = await R(() => window.pianoReport.activeContacts());
  check(active.includes('hammer_string'), 'the hammer–string force arrow is drawn at string contact (' + active.join(', ') + ')');
  const tip = await R(() => window.pianoReport.arrowTip('hammer_string'));
  const pixel = tip && await page.$eval('#canvas2d-0', (c, p) => Array.from(c.getContext('2d').getImageData(Math.round(p[0]), Math.round(p[1]), 1, 1).data), tip);
  check(pixel && pixel[0] > 150 && pixel[1] < 110 && pixel[2] < 110, 'the arrow is red on the canvas (' + pixel + ')');
  // No two labels on the 2D view overlap, none leaves it: at string contact in every zoom,
  // and at every listed event in the whole view.
  const zoomTo = (name) => R((z) => { const e = document.getElementById('zoom'); e.value = z; e.dispatchEvent(new Event('change')); }, name);
  const labelTrouble = async (where) => {
    const [labels, size] = await R(() => [window.pianoReport.labels(), window.pianoReport.canvasSize()]);
    const bad = [];
    labels.forEach((l, i) => {
      const b = l.box;
      if (b[0] < 0 || b[1] < 0 || b[2] > size[0] || b[3] > size[1]) bad.push(where + ': "' + l.text + '" leaves the canvas');
      labels.slice(i + 1).forEach((m) => {
        const c = m.box;
        if (b[0] < c[2] && c[0] < b[2] && b[1] < c[3] && c[1] < b[3]) bad.push(where + ': "' + l.text + '" overlaps "' + m.text + '"');
      });
    });
    return [bad, labels.filter((l) => l.kind === 'force').length];
  };
  const zooms = await R(() => Array.from(document.getElementById('zoom').options).map((o) => o.value));
  const trouble = [];
  let forceLabels = 0;
  for (const z of zooms) {
    await zoomTo(z);
    await R((t) => window.pianoReport.seek(t), during);
    const [bad, n] = await labelTrouble(z + ' at string contact');
    trouble.push(...bad);
    if (z === 'whole action') forceLabels = n;
    if (z === 'whole action') await page.screenshot({ path: shots + '/05-string-contact-whole.png' });
    if (z === 'string') await page.screenshot({ path: shots + '/02-string-contact.png' });
  }
  await zoomTo('whole action');
  for (const e of await R(() => window.pianoReport.events())) {
    await R((t) => window.pianoReport.seek(t), e.t + 1e-5);
    trouble.push(...(await labelTrouble(e.name + ' at ' + (e.t * 1e3).toFixed(2) + ' ms'))[0]);
  }
  check(forceLabels >= 3 && trouble.length === 0, 'no label overlaps another or leaves the 2D view (' + forceLabels + ' force labels at string contact; ' + (trouble.slice(0, 4).join('; ') || 'none') + ')');

  // The listed events: one let-off per escapement (the toe touching its button again after
  // the check is chatter, not a new let-off), in time order.
  const listed = await R(() => window.pianoReport.events().map((e) => [e.name, e.t]));
  const names = listed.map((e) => e[0]);
  const check0 = names.indexOf('check_catch');
  check(names.filter((n) => n === 'let_off').length === 1 && check0 > names.indexOf('let_off') && !names.slice(check0).includes('let_off'),
    'the event list shows one let-off, before the check (' + names.join(', ') + ')');

  await R((t) => window.pianoReport.seek(t), strike - 0.02);
  check((await R(() => window.pianoReport.activeContacts())).indexOf('hammer_string') < 0, 'no string arrow 20 ms before the strike');

  // Clicking a plot seeks there.
  const box = await page.$eval('#plotcanvas-hammer-angle', (c) => { const r = c.getBoundingClientRect(); return [r.left, r.top, r.width, r.height]; });
  const span = await R(() => { const e = window.pianoReport.range(); return e; });
  const fraction = 0.5;
  const margin = 44, right = 22;
  await page.mouse.click(box[0] + margin + fraction * (box[2] - margin - right), box[1] + box[3] / 2);
  const tc = await R(() => window.pianoReport.time());
  const want = span[0] + fraction * (span[1] - span[0]);
  check(Math.abs(tc - want) < 0.01 * (span[1] - span[0]), 'clicking the middle of a plot seeks to ' + (want * 1e3).toFixed(1) + ' ms (' + (tc * 1e3).toFixed(1) + ' ms)');
  await page.screenshot({ path: shots + '/03-plot-click.png', fullPage: true });

  // The 3D view renders: the canvas holds more than its background.
  check(await R(() => window.pianoReport.webgl()), 'WebGL is available for the 3D view');
  const shades = await page.$eval('#canvas3d-0', (c) => {
    const copy = document.createElement('canvas');
    copy.width = c.width; copy.height = c.height;
    const g = copy.getContext('2d');
    g.drawImage(c, 0, 0);
    const px = g.getImageData(0, 0, c.width, c.height).data;
    const seen = new Set();
    let fg = 0;
    for (let k = 0; k < px.length; k += 16) {
      seen.add((px[k] >> 4) + ',' + (px[k + 1] >> 4) + ',' + (px[k + 2] >> 4));
      if (Math.abs(px[k] - 247) + Math.abs(px[k + 1] - 247) + Math.abs(px[k + 2] - 245) > 30) fg++;
    }
    return [seen.size, fg / (px.length / 16)];
  });
  check(shades[0] > 20 && shades[1] > 0.03, 'the 3D view is not blank (' + shades[0] + ' shades, ' + (100 * shades[1]).toFixed(1) + ' % drawn)');
  await page.$eval('#view3d-0', (e) => e.scrollIntoView());
  await page.screenshot({ path: shots + '/04-3d.png' });

  // Without WebGL the page says so and nothing breaks.
  const plain = await chromium.launch({
    executablePath: process.env.CHROMIUM || '/usr/bin/chromium',
    args: ['--no-sandbox', '--disable-gpu', '--disable-webgl', '--disable-3d-apis', '--disable-quic', '--no-first-run',
      '--disable-background-networking', '--disable-component-update', '--disable-sync'],
  });
  try {
    const p2 = await plain.newPage();
    const errs2 = [];
    p2.on('pageerror', (e) => errs2.push(String(e)));
    p2.on('console', (m) => { if (m.type() === 'error') errs2.push(m.text()); });
    await p2.goto(url);
    await p2.waitForFunction(() => window.pianoReport !== undefined);
    const note = await p2.$('#no-webgl-0');
    check(note !== null && errs2.length === 0, 'without WebGL the 3D view explains itself, no error (' + errs2.join(' | ') + ')');
  } finally {
    await plain.close();
  }

  check(errors.length === 0, 'no console error (' + errors.join(' | ') + ')');
  check(requests.length === 0, 'no network request (' + requests.join(' ') + ')');
} finally {
  await browser.close();
}
if (failures.length) {
  console.error(failures.length + ' check(s) failed');
  process.exit(1);
}
