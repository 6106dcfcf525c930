// Drives a headless browser for web_browser_test.cc and prints one JSON object with what
// it measured; the C++ test asserts. BROWSER is
//   chromium: Debian's Chromium (SwiftShader WebGL) driven by playwright-core over CDP;
//   firefox:  Debian's firefox-esr (its own software WebGL) driven by puppeteer-core over
//             WebDriver BiDi (playwright-core drives only its own patched Firefox builds).
// usage: node browser_check.mjs NODE_MODULES BROWSER MODE URL OUT_DIR [ARG]
//   live URL OUT_DIR PAGES: opens PAGES pages, waits for shapes, counts shapes and frames
//        over MEASURE_S seconds per page after WARM_UP_S, screenshots each page's canvas.
//   replay URL OUT_DIR: one page, sets the speed to 16x, waits for the log's end.
//   page URL OUT_DIR SECONDS: one 1280x900 page, a screenshot of all of it after SECONDS
//        (the README's picture).
//   auth URL_WITHOUT_TOKEN OUT_DIR TOKEN: HTTP status of the page and of a WebSocket
//        upgrade without, with a wrong and with the right token (no browser); the page with
//        the right token redirects (303), setting the cookie the script then loads with.
import { readdirSync, readFileSync } from 'node:fs';
import http from 'node:http';
import os from 'node:os';
import path from 'node:path';

import { launchChromium, printCheck, requireFrom, sleep } from '../support/browser_check_support.mjs';

const [modules, browserName, mode, url, out, arg] = process.argv.slice(2);
const require = requireFrom(modules);
const MEASURE_S = 5;
// After the first shapes: the browser compiles the shaders and JIT-compiles the page in
// the first seconds (longer on a loaded machine), and a page then works off the messages
// queued meanwhile; the rates are of the steady state after it, as an observer sees it.
const WARM_UP_S = 8;
// Pages in the background must keep drawing: the test opens two at once.
const CHROMIUM_BACKGROUND_ARGS = [
  '--disable-background-timer-throttling', '--disable-renderer-backgrounding',
  '--disable-backgrounding-occluded-windows',
];

// CPU seconds (user + system) of this script's descendant processes, summed per kind
// (Chromium's --type=, else the program's name): whether the browser got the CPU time its
// pages need is what tells a starved machine from a slow page.
const TICKS_PER_S = 100;  // USER_HZ on Linux
function browserCpu() {
  const procs = new Map();
  for (const name of readdirSync('/proc')) {
    if (!/^\d+$/.test(name)) continue;
    try {
      const stat = readFileSync(`/proc/${name}/stat`, 'utf8');
      const f = stat.slice(stat.lastIndexOf(')') + 2).split(' ');  // fields from state on
      // Chromium rewrites its command line into one string; Firefox's content processes end
      // theirs with their kind (tab, gpu, rdd, socket, utility).
      const raw = readFileSync(`/proc/${name}/cmdline`, 'utf8');
      const args = raw.split(/[\0 ]/).filter((a) => a);
      const type = (/--type=([\w-]+)/.exec(raw) || [])[1] ||
                   (args.includes('-contentproc') ? `content-${args[args.length - 1]}` : path.basename(args[0] || '?'));
      procs.set(Number(name), { ppid: Number(f[1]), cpu: (Number(f[11]) + Number(f[12])) / TICKS_PER_S, type });
    } catch { /* gone meanwhile */ }
  }
  const cpu = {};
  for (const [pid, p] of procs) {
    let up = p.ppid;
    while (up > 1 && up !== process.pid) up = procs.get(up)?.ppid ?? 0;
    if (up === process.pid && pid !== process.pid) cpu[p.type] = (cpu[p.type] || 0) + p.cpu;
  }
  return cpu;
}
const cpuSince = (a, b, s) => Object.fromEntries(Object.keys(b).map((k) => [k, Number(((b[k] - (a[k] || 0)) / s).toFixed(3))]));

// One page API over both drivers: open(viewport) gives {page, goto, waitFor, shot, shotAll,
// select}; page.evaluate(fn) is the same in both.
const DRIVERS = {
  chromium: {
    launch: () => launchChromium(require, CHROMIUM_BACKGROUND_ARGS),
    async open(browser, viewport) {
      // A context (a window) per page: two tabs of one window would leave one in the
      // background, where Chromium throttles its animation frames.
      const context = await browser.newContext({ viewport });
      const page = await context.newPage();
      return {
        page,
        goto: async (target) => (await page.goto(target, { timeout: 120000 })).status(),
        waitFor: (fn) => page.waitForFunction(fn, null, { timeout: 120000 }),
        shot: (selector, file) => page.locator(selector).screenshot({ path: file }),
        shotAll: (file) => page.screenshot({ path: file }),
        select: (selector, value) => page.selectOption(selector, value),
      };
    },
  },
  firefox: {
    async launch() {
      const puppeteer = require('puppeteer-core');
      // puppeteer-core makes a fresh profile with its automation prefs; BiDi is its
      // protocol for Firefox.
      return puppeteer.launch({
        browser: 'firefox', executablePath: '/usr/bin/firefox-esr', headless: true,
        // Start-up allowance, not a speed figure: on a fresh machine (CI) or a loaded one
        // the first starts of a new Firefox took over 60 s here before its BiDi endpoint
        // appeared (2 failures in a row right after `apt-get install firefox-esr`, then a pass).
        timeout: 180000, protocolTimeout: 180000,
        extraPrefsFirefox: {
          // WebGL on whatever GL the display has, blocklisted or not (here Mesa's llvmpipe,
          // which gave WebGL 2 with and without this pref; without a display, none).
          'webgl.force-enabled': true,
          // Pages in the background keep their timers and animation frames.
          'dom.min_background_timeout_value': 4,
          'dom.timeout.enable_budget_timer_throttling': false,
        },
      });
    },
    async open(browser, viewport) {
      const context = await browser.createBrowserContext();
      const page = await context.newPage();
      await page.setViewport(viewport);
      return {
        page,
        goto: async (target) => (await page.goto(target, { timeout: 120000 })).status(),
        waitFor: (fn) => page.waitForFunction(fn, { timeout: 120000, polling: 100 }),
        shot: async (selector, file) => (await page.$(selector)).screenshot({ path: file }),
        shotAll: (file) => page.screenshot({ path: file }),
        select: (selector, value) => page.select(selector, value),
      };
    },
  },
};
const driver = DRIVERS[browserName];

const counters = (page) => page.evaluate(() => ({
  shapes: Number(document.body.dataset.shapesReceived || 0),
  frames: Number(document.body.dataset.framesDrawn || 0),
  seq: Number(document.body.dataset.lastShapeSeq ?? -1),
  status: Number(document.body.dataset.lastShapeStatus ?? -1),
  utime: Number(document.body.dataset.lastShapeUtime ?? 0),
  round_trip_ms: Number(document.body.dataset.roundTripMs ?? NaN),
  t: performance.now(),
}));

async function live(browser, pages) {
  const opened = [];
  for (let i = 0; i < pages; ++i) {
    const p = await driver.open(browser, { width: 800, height: 500 });
    opened.push({ ...p, http: await p.goto(url) });
  }
  for (const p of opened) await p.waitFor(() => Number(document.body.dataset.shapesReceived || 0) > 10);
  await sleep(WARM_UP_S * 1000);
  // The status panel shows the last force model's certified force error as text: wait for a
  // value in newtons (a live solve makes one), then read what the page shows.
  const forceErrorCell = () => {
    for (const tr of document.querySelectorAll('#status tr')) {
      const cells = tr.querySelectorAll('td');
      if (cells.length === 2 && cells[0].textContent === 'force error (certified)') return cells[1].textContent;
    }
    return null;
  };
  for (const p of opened) {
    await p.waitFor(`(${forceErrorCell.toString()})()?.endsWith(' N') === true`);
  }
  const forceErrorTexts = await Promise.all(opened.map(({ page }) => page.evaluate(forceErrorCell)));
  const cpuBefore = browserCpu();
  const wallBefore = Date.now();
  const before = await Promise.all(opened.map(({ page }) => counters(page)));
  await sleep(MEASURE_S * 1000);
  const after = await Promise.all(opened.map(({ page }) => counters(page)));
  // Cores' worth of CPU each kind of browser process had over the window, and the load.
  const cpu = cpuSince(cpuBefore, browserCpu(), (Date.now() - wallBefore) / 1000);
  const load = os.loadavg()[0];
  const result = [];
  for (let i = 0; i < pages; ++i) {
    const { page, shot: shotOf } = opened[i];
    const s = (after[i].t - before[i].t) / 1000;
    const webgl = await page.evaluate(() => {
      const gl = document.getElementById('view').getContext('webgl2');
      return gl ? gl.getParameter(gl.VERSION) : null;
    });
    const shot = path.join(out, `page${i}.png`);
    const status = (await counters(page)).status;
    await shotOf('#view', shot);
    result.push({
      http: opened[i].http, seconds: s, webgl,
      shapes_per_s: (after[i].shapes - before[i].shapes) / s,
      // Over the server's time stamps of the shapes: the rate the bridge sent them at,
      // whatever bursts the page's own event loop added.
      shapes_per_server_s: (after[i].shapes - before[i].shapes) / ((after[i].utime - before[i].utime) / 1e6),
      frames_per_s: (after[i].frames - before[i].frames) / s,
      shapes: after[i].shapes, frames: after[i].frames, status, screenshot: shot,
      // The page's last ping to the bridge and back: the ack window's round trip.
      round_trip_ms: after[i].round_trip_ms,
      force_error_text: forceErrorTexts[i],
    });
  }
  return { pages: result, browser_cpu: cpu, load };
}

async function replay(browser) {
  const p = await driver.open(browser, { width: 800, height: 500 });
  const { page } = p;
  await p.goto(url);
  await p.waitFor(() => document.body.dataset.replayShapes !== undefined);
  await p.select('#replay-speed', '16');
  const start = Date.now();
  await p.waitFor(() => document.body.dataset.replayAtEnd === 'true');
  // The bridge sends the last shape once its pacing allows: give it a moment to arrive.
  await sleep(500);
  const d = await page.evaluate(() => ({ ...document.body.dataset }));
  const shot = path.join(out, 'replay.png');
  await p.shot('#view', shot);
  return { seconds: (Date.now() - start) / 1000, replay_shape: Number(d.replayShape),
           replay_shapes: Number(d.replayShapes), last_seq: Number(d.lastShapeSeq ?? -1),
           shapes: Number(d.shapesReceived), frames: Number(d.framesDrawn),
           status: Number(d.lastShapeStatus ?? -1), screenshot: shot };
}

async function wholePage(browser, seconds) {
  const p = await driver.open(browser, { width: 1280, height: 900 });
  await p.goto(url);
  await sleep(seconds * 1000);
  const shot = path.join(out, 'page.png');
  await p.shotAll(shot);
  return { screenshot: shot, ...(await p.page.evaluate(() => ({ ...document.body.dataset }))) };
}

function status(target, headers = {}, withCookie = false) {
  return new Promise((resolve, reject) => {
    const req = http.get(target, { headers }, (res) => {
      res.resume();
      resolve(withCookie ? { status: res.statusCode, cookie: (res.headers['set-cookie'] || [''])[0] } : res.statusCode);
    });
    req.on('upgrade', (res, socket) => { socket.destroy(); resolve(res.statusCode); });
    req.on('error', reject);
    req.setTimeout(10000, () => req.destroy(new Error('timeout')));
  });
}

async function auth(token) {
  const base = url.replace(/\/$/, '');
  const upgrade = { Connection: 'Upgrade', Upgrade: 'websocket', 'Sec-WebSocket-Version': '13',
                    'Sec-WebSocket-Key': 'dGhlIHNhbXBsZSBub25jZQ==', Origin: base };
  const right = await status(`${base}/?token=${token}`, {}, true);
  const cookie = { Cookie: right.cookie.split(';')[0] };
  return {
    page_without: await status(`${base}/`),
    script_without: await status(`${base}/app.js`),
    page_wrong: await status(`${base}/?token=${'0'.repeat(token.length)}`),
    page_right: right.status,
    page_cookie: await status(`${base}/`, cookie),
    script_cookie: await status(`${base}/app.js`, cookie),
    ws_without: await status(`${base}/ws`, upgrade),
    ws_right: await status(`${base}/ws?token=${token}`, upgrade),
    ws_cookie: await status(`${base}/ws`, { ...upgrade, ...cookie }),
  };
}

await printCheck(async (browsers) => {
  if (mode === 'auth') return auth(arg);
  if (!driver) throw new Error(`browser ${browserName}: chromium or firefox`);
  const browser = await driver.launch();
  browsers.push(browser);
  if (mode === 'live') return live(browser, Number(arg || 2));
  if (mode === 'page') return wholePage(browser, Number(arg || 15));
  return replay(browser);
});
