// Builds the front end into crates/towpath-server/assets/ (index.html, app.js, app.css), the
// folder the server embeds. Deterministic: same sources and lockfile, same bytes.
// `node build.mjs --check` builds into a temporary folder and fails if the committed assets differ.

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

if (check) {
  const names = (d) => readdirSync(d).sort();
  const a = names(out), b = names(assets);
  let ok = JSON.stringify(a) === JSON.stringify(b);
  for (const f of a) {
    if (!ok) break;
    if (!readFileSync(join(out, f)).equals(readFileSync(join(assets, f)))) { ok = false; console.error(`differs: ${f}`); }
  }
  rmSync(out, { recursive: true, force: true });
  if (!ok) {
    console.error('crates/towpath-server/assets/ is not the build of web/src: run web/build.sh and commit the result');
    process.exit(1);
  }
  console.log('web assets: the committed bundle is the build of web/src');
}
