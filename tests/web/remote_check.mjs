// Headless Chromium (Debian's, playwright-core) as an observer on another machine: run by
// web_netns_test.sh in a second network namespace against snapthread-web bound to a veth
// address. Prints one JSON object; the script asserts.
// usage: node remote_check.mjs NODE_MODULES URL_WITH_TOKEN OUT_DIR
//   with_token: the page opened with the printed URL (?token=...): the final address (the
//     token must have left it), the HTTP status of every file it loaded, the cookie the
//     bridge set, shapes and frames counted by the page over MEASURE_S, tube pixels of the
//     status's colour on a screenshot of the canvas, Content-Security-Policy violations.
//   without: a fresh browser context opening the same address without the token: the
//     status, whether any script ran (shapes), and the page's files and WebSocket asked
//     for directly.
import { writeFileSync } from 'node:fs';
import path from 'node:path';
import zlib from 'node:zlib';

import { launchChromium, printCheck, requireFrom, sleep } from '../support/browser_check_support.mjs';

const [modules, url, out] = process.argv.slice(2);
const require = requireFrom(modules);
const MEASURE_S = 5;

// The native viewer's tube colours by status (viewer/marker_colors.h), as the page uses.
const STATUS_COLOURS = [[0.55, 0.80, 0.95], [1.00, 0.62, 0.10], [0.95, 0.20, 0.20], [0.55, 0.55, 0.55],
                        [0.85, 0.35, 0.75]];

// Decodes an 8-bit RGB or RGBA PNG (what Chromium's screenshots are) to {width, height,
// channels, pixels}.
function decodePng(buffer) {
  let at = 8;
  let width = 0, height = 0, channels = 0;
  const idat = [];
  while (at < buffer.length) {
    const length = buffer.readUInt32BE(at);
    const type = buffer.toString('latin1', at + 4, at + 8);
    const data = buffer.subarray(at + 8, at + 8 + length);
    if (type === 'IHDR') {
      width = data.readUInt32BE(0); height = data.readUInt32BE(4);
      if (data[8] !== 8 || (data[9] !== 2 && data[9] !== 6)) throw new Error('PNG not 8-bit RGB(A)');
      channels = data[9] === 6 ? 4 : 3;
    } else if (type === 'IDAT') {
      idat.push(data);
    }
    at += 12 + length;
  }
  const raw = zlib.inflateSync(Buffer.concat(idat));
  const stride = width * channels;
  const pixels = Buffer.alloc(height * stride);
  for (let y = 0; y < height; ++y) {
    const filter = raw[y * (stride + 1)];
    const line = raw.subarray(y * (stride + 1) + 1, (y + 1) * (stride + 1));
    for (let x = 0; x < stride; ++x) {
      const a = x >= channels ? pixels[y * stride + x - channels] : 0;
      const b = y > 0 ? pixels[(y - 1) * stride + x] : 0;
      const c = x >= channels && y > 0 ? pixels[(y - 1) * stride + x - channels] : 0;
      let v = line[x];
      if (filter === 1) v += a;
      else if (filter === 2) v += b;
      else if (filter === 3) v += (a + b) >> 1;
      else if (filter === 4) {
        const p = a + b - c, pa = Math.abs(p - a), pb = Math.abs(p - b), pc = Math.abs(p - c);
        v += pa <= pb && pa <= pc ? a : (pb <= pc ? b : c);
      }
      pixels[y * stride + x] = v & 0xff;
    }
  }
  return { width, height, channels, pixels };
}

// Pixels of the headlit tube colour `rgb` (web_browser_test.cc TubePixels).
function tubePixels(png, rgb) {
  const top = rgb[0] >= rgb[1] && rgb[0] >= rgb[2] ? 0 : (rgb[1] >= rgb[2] ? 1 : 2);
  let count = 0;
  for (let i = 0; i < png.width * png.height; ++i) {
    const p = png.pixels.subarray(i * png.channels, i * png.channels + 3);
    if (p[top] < 0.3 * 255 * rgb[top]) continue;
    let match = true;
    for (let c = 0; c < 3; ++c) match = match && Math.abs(p[c] / p[top] - rgb[c] / rgb[top]) < 0.06;
    count += match;
  }
  return count;
}

async function withToken(browser) {
  const context = await browser.newContext({ viewport: { width: 800, height: 500 } });
  const page = await context.newPage();
  const files = {};
  page.on('response', (r) => { files[new URL(r.url()).pathname + (r.status() === 303 ? ' (redirect)' : '')] = r.status(); });
  await page.addInitScript(() => {
    window.__csp = [];
    document.addEventListener('securitypolicyviolation', (e) => window.__csp.push(`${e.violatedDirective} ${e.blockedURI}`));
  });
  const response = await page.goto(url, { timeout: 120000 });
  await page.waitForFunction(() => Number(document.body.dataset.shapesReceived || 0) > 10, null, { timeout: 120000 });
  const count = () => page.evaluate(() => ({ shapes: Number(document.body.dataset.shapesReceived || 0),
                                              frames: Number(document.body.dataset.framesDrawn || 0),
                                              status: Number(document.body.dataset.lastShapeStatus ?? -1) }));
  const before = await count();
  await sleep(MEASURE_S * 1000);
  const after = await count();
  const shot = await page.locator('#view').screenshot();
  writeFileSync(path.join(out, 'remote.png'), shot);
  const png = decodePng(shot);
  const cookies = await context.cookies();
  const csp = await page.evaluate(() => window.__csp);
  await context.close();
  return {
    http: response.status(), final_url: page.url(), files,
    cookie: cookies.map((c) => ({ name: c.name, httpOnly: c.httpOnly, sameSite: c.sameSite })),
    shapes_per_s: (after.shapes - before.shapes) / MEASURE_S, frames_per_s: (after.frames - before.frames) / MEASURE_S,
    shapes: after.shapes, status: after.status,
    tube_pixels: after.status >= 0 && after.status < 5 ? tubePixels(png, STATUS_COLOURS[after.status]) : -1,
    pixels: png.width * png.height, csp_violations: csp,
  };
}

async function without(browser) {
  const clean = url.replace(/\?.*$/, '');
  const context = await browser.newContext();
  const page = await context.newPage();
  const response = await page.goto(clean, { timeout: 120000 });
  await sleep(3000);
  const seen = await page.evaluate(() => ({ shapes: document.body?.dataset.shapesReceived ?? null,
                                            text: document.body?.textContent ?? '' }));
  const fetchStatus = (p) => context.request.get(new URL(p, clean).href, { failOnStatusCode: false }).then((r) => r.status());
  const result = {
    http: response.status(), shapes: seen.shapes, text: seen.text.slice(0, 200),
    app_js: await fetchStatus('/app.js'), style_css: await fetchStatus('/style.css'),
    uplot_css: await fetchStatus('/uplot.css'),
    ws: await page.evaluate((ws) => new Promise((resolve) => {
      const s = new WebSocket(ws);
      s.onopen = () => resolve('open');
      s.onerror = () => resolve('refused');
    }), clean.replace(/^http/, 'ws') + 'ws'),
  };
  await context.close();
  return result;
}

await printCheck(async (browsers) => {
  const browser = await launchChromium(require);
  browsers.push(browser);
  return { without: await without(browser), with_token: await withToken(browser) };
});
