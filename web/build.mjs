// Builds the front end into crates/towpath-server/assets/ (index.html, app.js, app.css), the
// folder the server embeds, and the layup report's page and script into crates/towpath/assets/
// (layup-report.html, layup-report.js), which the binary inlines into `towpath layup --report`.
// Deterministic: same sources and lockfile, same bytes.
// `node build.mjs --check` builds into temporary folders and fails if the committed assets differ.

import { build } from 'esbuild';
import { mkdtempSync, readFileSync, writeFileSync, mkdirSync, readdirSync, copyFileSync, rmSync } from 'node:fs';
import { join, dirname } from 'node:path';
import { tmpdir } from 'node:os';
import { fileURLToPath } from 'node:url';

const here = dirname(fileURLToPath(import.meta.url));
const assets = join(here, '..', 'crates', 'towpath-server', 'assets');
const check = process.argv.includes('--check');
const out = check ? mkdtempSync(join(tmpdir(), 'towpath-web-')) : assets;
mkdirSync(out, { recursive: true });
const reportAssets = join(here, '..', 'crates', 'towpath', 'assets');
const reportOut = check ? mkdtempSync(join(tmpdir(), 'towpath-report-')) : reportAssets;
mkdirSync(reportOut, { recursive: true });

await build({
  entryPoints: [join(here, 'src', 'main.js')],
  bundle: true,
  minify: true,
  format: 'esm',
  target: ['es2020'],
  outfile: join(out, 'app.js'),
  legalComments: 'none',
  logLevel: 'warning',
});
await build({
  entryPoints: [join(here, 'src', 'style.css')],
  bundle: true,
  minify: true,
  outfile: join(out, 'app.css'),
  logLevel: 'warning',
});
copyFileSync(join(here, 'src', 'index.html'), join(out, 'index.html'));
// three.js's licence travels with the bundle that contains it.
writeFileSync(join(out, 'THIRD-PARTY-LICENSES.txt'),
  `The front end bundles three.js (https://threejs.org), MIT licence:\n\n${readFileSync(join(here, 'node_modules', 'three', 'LICENSE'), 'utf8')}`);

// The layup report: one classic script (inlined into a file:// page, so no module loading), with
// three.js's licence comment kept in it, and the page it goes into.
await build({
  entryPoints: [join(here, 'src', 'layup-report.js')],
  bundle: true,
  minify: true,
  format: 'iife',
  target: ['es2020'],
  outfile: join(reportOut, 'layup-report.js'),
  legalComments: 'eof',
  logLevel: 'warning',
});
copyFileSync(join(here, 'src', 'layup-report.html'), join(reportOut, 'layup-report.html'));
// The script is inlined in a <script> element, which the first `</script` would end.
if (/<\/script/i.test(readFileSync(join(reportOut, 'layup-report.js'), 'utf8'))) {
  console.error('layup-report.js contains "</script", which would end the inline script of the report page');
  process.exit(1);
}

if (check) {
  const names = (d) => readdirSync(d).sort();
  let ok = true;
  for (const [built, committed] of [[out, assets], [reportOut, reportAssets]]) {
    const a = names(built), b = names(committed);
    if (JSON.stringify(a) !== JSON.stringify(b)) { ok = false; console.error(`files differ in ${committed}: ${a} vs ${b}`); }
    for (const f of a) {
      if (ok && !readFileSync(join(built, f)).equals(readFileSync(join(committed, f)))) { ok = false; console.error(`differs: ${f}`); }
    }
    rmSync(built, { recursive: true, force: true });
  }
  if (!ok) {
    console.error('crates/towpath-server/assets/ or crates/towpath/assets/ is not the build of web/src: run web/build.sh and commit the result');
    process.exit(1);
  }
  console.log('web assets: the committed bundles are the build of web/src');
}
