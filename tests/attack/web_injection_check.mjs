// Headless Chromium (Debian's, driven by playwright-core from the page's npm install) on a
// snapthread-web replay of a hostile log (web_injection_test.cc). Prints one JSON object;
// the C++ test asserts.
// usage: node web_injection_check.mjs NODE_MODULES URL OUT_DIR
//   pwned:              window.__pwned (null: no payload ran)
//   marker_requests:    requests whose URL has "pwned" (an <img> made from the text fetches one)
//   elements_from_text: img, script, svg or iframe elements in the status panel
//   csp_violations:     securitypolicyviolation events (and their directives)
//   literal_<field>:    the field's payload appears, as text, in the status panel
//   shapes, frames:     the page's counters; last_seq: the last shape's seq, once the replay
//                       ended; csp: the page's Content-Security-Policy header
import path from 'node:path';

import { launchChromium, printCheck, requireFrom, sleep } from '../support/browser_check_support.mjs';

const [modules, url, out] = process.argv.slice(2);
const require = requireFrom(modules);

// The payload web_injection_test.cc puts in each field.
const payload = (field) => `<img src=/pwned-img-${field} onerror="window.__pwned='${field}'">` +
  `<script>window.__pwned='${field}-script'</script>` +
  `<svg onload="window.__pwned='${field}-svg'"></svg>`;

await printCheck(async (browsers) => {
  const browser = await launchChromium(require);
  browsers.push(browser);
  const context = await browser.newContext({ viewport: { width: 1000, height: 700 } });
  const page = await context.newPage();
  const markerRequests = [];
  page.on('request', (req) => { if (/pwned/i.test(req.url())) markerRequests.push(req.url()); });
  const pageErrors = [];
  page.on('pageerror', (e) => pageErrors.push(String(e)));
  // Runs before the page's own script (from the driver, not subject to the page's CSP).
  await page.addInitScript(() => {
    window.__csp = [];
    document.addEventListener('securitypolicyviolation',
      (e) => window.__csp.push(`${e.violatedDirective} ${e.blockedURI}`));
  });
  const response = await page.goto(url, { timeout: 120000 });
  const csp = response.headers()['content-security-policy'] ?? null;
  // Until every kind of message has reached the panel (the bridge's counters come once a
  // second), then a little longer for anything deferred (an onerror fires after the load).
  // (Markup parsed from the text, as before this suite, never shows it: then 15 s at most.)
  // (the test asserts the count: a page that gets no shapes fails there, with the rest)
  await page.waitForFunction(() => Number(document.body.dataset.shapesReceived || 0) > 10, null,
                             { timeout: 90000 }).catch(() => {});
  await page.waitForFunction(() => document.getElementById('status').textContent.includes('pwned-img-session'),
                             null, { timeout: 15000 }).catch(() => {});
  await sleep(2000);
  // Then to the log's end (its second half holds bytes that are not UTF-8).
  await page.waitForFunction(() => document.body.dataset.replayAtEnd === 'true', null, { timeout: 60000 })
    .catch(() => {});
  await sleep(1000);
  const seen = await page.evaluate(() => ({
    pwned: window.__pwned ?? null,
    csp: window.__csp,
    text: document.getElementById('status').textContent,
    elements: document.getElementById('status').querySelectorAll('img, script, svg, iframe').length,
    shapes: Number(document.body.dataset.shapesReceived || 0),
    frames: Number(document.body.dataset.framesDrawn || 0),
    lastSeq: Number(document.body.dataset.lastShapeSeq ?? -1),
  }));
  const result = {
    pwned: seen.pwned, marker_requests: markerRequests.length, marker_urls: [...new Set(markerRequests)].slice(0, 8),
    elements_from_text: seen.elements, csp_violations: seen.csp.length, violations: seen.csp,
    page_errors: pageErrors, shapes: seen.shapes, frames: seen.frames, last_seq: seen.lastSeq, csp,
  };
  for (const field of ['session', 'scene', 'method', 'model', 'knot', 'device']) {
    result[`literal_${field}`] = seen.text.includes(payload(field));
  }
  await page.screenshot({ path: path.join(out, 'injection.png') });
  return result;
});
