// Drives Debian's Chromium (headless, SwiftShader WebGL) with playwright-core for
// web_browser_test.cc and prints one JSON object with what it measured; the C++ test
// asserts. usage: node browser_check.mjs NODE_MODULES MODE URL OUT_DIR [ARG]
//   live URL OUT_DIR PAGES: opens PAGES pages, waits for shapes, counts shapes and frames
//        over MEASURE_S seconds per page, screenshots each page's canvas.
//   replay URL OUT_DIR: one page, sets the speed to 16x, waits for the log's end.
//   page URL OUT_DIR SECONDS: one 1280x900 page, a screenshot of all of it after SECONDS
//        (the README's picture).
//   auth URL_WITHOUT_TOKEN OUT_DIR TOKEN: HTTP status of the page and of a WebSocket
//        upgrade without, with a wrong and with the right token.
import { createRequire } from 'node:module';
import http from 'node:http';
import path from 'node:path';

const [modules, mode, url, out, arg] = process.argv.slice(2);
const require = createRequire(path.join(path.resolve(modules), 'index.js'));
const MEASURE_S = 5;
// After the first shapes: Chromium compiles the shaders and JIT-compiles the page in the
// first seconds (longer on a loaded machine), and a page then works off the messages
// queued meanwhile; the rates are of the steady state after it.
const WARM_UP_S = 8;

const CHROMIUM_ARGS = [
  '--headless', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
  '--disable-background-networking', '--disable-component-update', '--disable-sync',
  '--use-angle=swiftshader', '--enable-unsafe-swiftshader',
  // Pages in the background must keep drawing: the test opens two at once.
  '--disable-background-timer-throttling', '--disable-renderer-backgrounding',
  '--disable-backgrounding-occluded-windows',
];

async function launch() {
  const { chromium } = require('playwright-core');
  // launch() gives Chromium a new empty --user-data-dir of its own.
  return chromium.launch({ executablePath: '/usr/bin/chromium', args: CHROMIUM_ARGS, timeout: 60000 });
}

const counters = (page) => page.evaluate(() => ({
  shapes: Number(document.body.dataset.shapesReceived || 0),
  frames: Number(document.body.dataset.framesDrawn || 0),
  seq: Number(document.body.dataset.lastShapeSeq ?? -1),
  status: Number(document.body.dataset.lastShapeStatus ?? -1),
  utime: Number(document.body.dataset.lastShapeUtime ?? 0),
  t: performance.now(),
}));

async function live(browser, pages) {
  const opened = [];
  for (let i = 0; i < pages; ++i) {
    // A context (a window) per page: two tabs of one window would leave one in the
    // background, where Chromium throttles its animation frames.
    const context = await browser.newContext({ viewport: { width: 800, height: 500 } });
    const page = await context.newPage();
    const response = await page.goto(url, { timeout: 120000 });
    opened.push({ page, http: response.status() });
  }
  for (const { page } of opened) {
    await page.waitForFunction(() => Number(document.body.dataset.shapesReceived || 0) > 10, null, { timeout: 120000 });
  }
  await new Promise((r) => setTimeout(r, WARM_UP_S * 1000));
  const before = await Promise.all(opened.map(({ page }) => counters(page)));
  await new Promise((r) => setTimeout(r, MEASURE_S * 1000));
  const after = await Promise.all(opened.map(({ page }) => counters(page)));
  const result = [];
  for (let i = 0; i < pages; ++i) {
    const { page } = opened[i];
    const s = (after[i].t - before[i].t) / 1000;
    const webgl = await page.evaluate(() => {
      const gl = document.getElementById('view').getContext('webgl2');
      return gl ? gl.getParameter(gl.VERSION) : null;
    });
    const shot = path.join(out, `page${i}.png`);
    const status = (await counters(page)).status;
    await page.locator('#view').screenshot({ path: shot });
    result.push({
      http: opened[i].http, seconds: s, webgl,
      shapes_per_s: (after[i].shapes - before[i].shapes) / s,
      // Over the server's time stamps of the shapes: the rate the bridge sent them at,
      // whatever bursts the page's own event loop added.
      shapes_per_server_s: (after[i].shapes - before[i].shapes) / ((after[i].utime - before[i].utime) / 1e6),
      frames_per_s: (after[i].frames - before[i].frames) / s,
      shapes: after[i].shapes, frames: after[i].frames, status, screenshot: shot,
    });
  }
  return { pages: result };
}

async function replay(browser) {
  const page = await browser.newPage({ viewport: { width: 800, height: 500 } });
  await page.goto(url, { timeout: 120000 });
  await page.waitForFunction(() => document.body.dataset.replayShapes !== undefined, null, { timeout: 120000 });
  await page.selectOption('#replay-speed', '16');
  const start = Date.now();
  await page.waitForFunction(() => document.body.dataset.replayAtEnd === 'true', null, { timeout: 120000 });
  // The bridge sends the last shape once its pacing allows: give it a moment to arrive.
  await page.waitForTimeout(500);
  const d = await page.evaluate(() => ({ ...document.body.dataset }));
  const shot = path.join(out, 'replay.png');
  await page.locator('#view').screenshot({ path: shot });
  return { seconds: (Date.now() - start) / 1000, replay_shape: Number(d.replayShape),
           replay_shapes: Number(d.replayShapes), last_seq: Number(d.lastShapeSeq ?? -1),
           shapes: Number(d.shapesReceived), frames: Number(d.framesDrawn),
           status: Number(d.lastShapeStatus ?? -1), screenshot: shot };
}

async function wholePage(browser, seconds) {
  const page = await browser.newPage({ viewport: { width: 1280, height: 900 } });
  await page.goto(url, { timeout: 120000 });
  await page.waitForTimeout(seconds * 1000);
  const shot = path.join(out, 'page.png');
  await page.screenshot({ path: shot });
  return { screenshot: shot, ...(await page.evaluate(() => ({ ...document.body.dataset }))) };
}

function status(target, headers = {}) {
  return new Promise((resolve, reject) => {
    const req = http.get(target, { headers }, (res) => { res.resume(); resolve(res.statusCode); });
    req.on('upgrade', (res, socket) => { socket.destroy(); resolve(res.statusCode); });
    req.on('error', reject);
    req.setTimeout(10000, () => req.destroy(new Error('timeout')));
  });
}

async function auth(token) {
  const upgrade = { Connection: 'Upgrade', Upgrade: 'websocket', 'Sec-WebSocket-Version': '13',
                    'Sec-WebSocket-Key': 'dGhlIHNhbXBsZSBub25jZQ==' };
  const base = url.replace(/\/$/, '');
  return {
    page_without: await status(`${base}/`),
    script_without: await status(`${base}/app.js`),
    page_wrong: await status(`${base}/?token=${'0'.repeat(token.length)}`),
    page_right: await status(`${base}/?token=${token}`),
    ws_without: await status(`${base}/ws`, upgrade),
    ws_right: await status(`${base}/ws?token=${token}`, upgrade),
  };
}

let browser;
try {
  let result;
  if (mode === 'auth') {
    result = await auth(arg);
  } else {
    browser = await launch();
    if (mode === 'live') result = await live(browser, Number(arg || 2));
    else if (mode === 'page') result = await wholePage(browser, Number(arg || 15));
    else result = await replay(browser);
  }
  console.log(JSON.stringify(result));
} catch (e) {
  console.log(JSON.stringify({ error: String(e && e.stack ? e.stack : e) }));
  process.exitCode = 1;
} finally {
  if (browser) await browser.close();
}
