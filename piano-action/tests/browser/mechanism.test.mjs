// Opens the report of a mechanism description's run (not the grand action) in headless
// Chromium and checks what a person would: no console error, no network request, Play
// advances time and moves the named body, seeking to the named event shows the named
// contact pressed with its arrow, the description's own plots and named events are there,
// and the 3D view draws the outlines. Saves screenshots. No check depends on the machine's
// speed (Playwright's fake clock).
//
// node mechanism.test.mjs REPORT.html SCREENSHOT_DIR BODY EVENT_TIME_S CONTACT EVENT_NAME
import { chromium } from 'playwright-core';
import { mkdirSync } from 'node:fs';

const [report, shots, body, eventArg, contact, eventName] = process.argv.slice(2);
const eventTime = parseFloat(eventArg);
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
  await page.clock.install({ time: 0 });
  await page.goto(url);
  await page.waitForFunction(() => window.pianoReport !== undefined);
  await page.clock.pauseAt(100000);
  await page.screenshot({ path: shots + '/01-opened.png' });
  const R = (fn, arg) => page.evaluate(fn, arg);

  // Play advances the clock and moves the body.
  const c0 = await R((b) => window.pianoReport.carry(b), body);
  await R(() => { window.pianoReport.seek(0); window.pianoReport.setSpeed(0.1); window.pianoReport.play(); });
  await page.clock.runFor(400);
  await R(() => window.pianoReport.pause());
  const t1 = await R(() => window.pianoReport.time());
  check(t1 > 0.02 && t1 <= 0.0401, 'Play at 1/10 for 400 ms of the fake clock advances up to 40 ms (' + (t1 * 1e3).toFixed(1) + ' ms)');
  await R((t) => window.pianoReport.seek(t), eventTime);
  const c1 = await R((b) => window.pianoReport.carry(b), body);
  const moved = Math.hypot(c1[1] - c0[1], c1[2] - c0[2]) + 50 * Math.abs(c1[0] - c0[0]);
  check(moved > 0.5, 'the ' + body + ' moves from rest to the ' + eventName + ' (' + c0.map((v) => v.toFixed(3)) + ' → ' + c1.map((v) => v.toFixed(3)) + ')');
  // At the event, its contact is pressed and its arrow drawn.
  const active = await R(() => window.pianoReport.activeContacts());
  check(active.includes(contact), 'the ' + contact + ' contact is pressed at the ' + eventName + ' (' + active.join(', ') + ')');
  check((await R((c) => window.pianoReport.arrowTip(c), contact)) !== null, 'its force arrow is drawn');
  await page.screenshot({ path: shots + '/02-event.png' });
  // The named events are listed, the description's own plots are there.
  const names = (await R(() => window.pianoReport.events())).map((e) => e.name);
  check(names.includes(eventName), 'the event list names the ' + eventName + ' (' + names.slice(0, 8).join(', ') + ')');
  const plots = await R(() => window.pianoReport.plots());
  check(plots.some((p) => p.includes(body)), 'a plot of the ' + body + ' (' + plots.join(', ') + ')');
  // The 3D view draws the outlines.
  if (await R(() => window.pianoReport.webgl())) {
    const drawn = await page.$eval('#canvas3d-0', (c) => {
      const copy = document.createElement('canvas');
      copy.width = c.width; copy.height = c.height;
      const g = copy.getContext('2d');
      g.drawImage(c, 0, 0);
      const px = g.getImageData(0, 0, c.width, c.height).data;
      let fg = 0;
      for (let k = 0; k < px.length; k += 16) {
        if (Math.abs(px[k] - 247) + Math.abs(px[k + 1] - 247) + Math.abs(px[k + 2] - 245) > 30) fg++;
      }
      return fg / (px.length / 16);
    });
    check(drawn > 0.02, 'the 3D view draws the outlines (' + (100 * drawn).toFixed(1) + ' % drawn)');
    await page.$eval('#view3d-0', (e) => e.scrollIntoView());
    await page.screenshot({ path: shots + '/03-3d.png' });
  } else {
    check(false, 'WebGL is available for the 3D view');
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
