// Bundles the page for snapthread-web: node build.mjs NODE_MODULES OUT_DIR
// (web/CMakeLists.txt runs it after `npm ci`). One ES module bundle (three.js, its orbit
// controls, uPlot and src/), the page, its style and uPlot's style: everything the page
// loads comes from the bridge.
import { copyFileSync, mkdirSync } from 'node:fs';
import { createRequire } from 'node:module';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

const [modules, out] = process.argv.slice(2);
if (!modules || !out) {
  console.error('usage: node build.mjs NODE_MODULES OUT_DIR');
  process.exit(2);
}
const here = path.dirname(fileURLToPath(import.meta.url));
const require = createRequire(path.join(path.resolve(modules), 'index.js'));
const esbuild = require('esbuild');

mkdirSync(out, { recursive: true });
await esbuild.build({
  entryPoints: [path.join(here, 'src', 'main.js')],
  bundle: true,
  format: 'esm',
  minify: true,
  target: ['chrome100', 'firefox100'],
  nodePaths: [path.resolve(modules)],
  outfile: path.join(out, 'app.js'),
  legalComments: 'eof',  // three.js's and uPlot's licence notices stay in the bundle
  logLevel: 'warning',
});
copyFileSync(path.join(here, 'index.html'), path.join(out, 'index.html'));
copyFileSync(path.join(here, 'style.css'), path.join(out, 'style.css'));
copyFileSync(path.join(modules, 'uplot', 'dist', 'uPlot.min.css'), path.join(out, 'uplot.css'));
