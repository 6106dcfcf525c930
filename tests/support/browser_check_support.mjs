// What the headless-browser checks share (tests/web/browser_check.mjs, remote_check.mjs,
// tests/attack/web_injection_check.mjs): the drivers from the page's npm install, Debian's
// Chromium with software WebGL, and the one JSON line each prints for its C++ test or
// script to assert on.
import { createRequire } from 'node:module';
import path from 'node:path';

// require() resolving in NODE_MODULES (the page's npm install: playwright-core,
// puppeteer-core).
export const requireFrom = (modules) => createRequire(path.join(path.resolve(modules), 'index.js'));

export const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

// Headless, no GPU here: WebGL through SwiftShader; no background traffic of its own.
export const CHROMIUM_ARGS = [
  '--headless', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
  '--disable-background-networking', '--disable-component-update', '--disable-sync',
  '--use-angle=swiftshader', '--enable-unsafe-swiftshader',
];

// Debian's Chromium driven by playwright-core, with CHROMIUM_ARGS and extraArgs. launch()
// gives it a new empty --user-data-dir of its own.
export function launchChromium(require, extraArgs = []) {
  const { chromium } = require('playwright-core');
  return chromium.launch({ executablePath: '/usr/bin/chromium', timeout: 60000,
                           args: [...CHROMIUM_ARGS, ...extraArgs] });
}

// Prints what check(browsers) returns as one JSON line, or {error} with exit code 1 when it
// throws; every browser check pushed onto `browsers` is closed either way.
export async function printCheck(check) {
  const browsers = [];
  try {
    console.log(JSON.stringify(await check(browsers)));
  } catch (e) {
    console.log(JSON.stringify({ error: String(e && e.stack ? e.stack : e) }));
    process.exitCode = 1;
  } finally {
    for (const browser of browsers) await browser.close();
  }
}
