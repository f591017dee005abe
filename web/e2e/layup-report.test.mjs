// The page `towpath layup --report` writes, opened from a file in headless Chromium: it draws
// without fetching anything, every colouring switches, and the courses stand out from the mesh.

import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { spawnSync } from 'node:child_process';
import { mkdtempSync, mkdirSync, existsSync, readFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { pathToFileURL } from 'node:url';
import { startBrowser, BIN } from './harness.mjs';

const shots = process.env.TOWPATH_SHOTS; // folder to keep screenshots in, for a person to look at
const dir = mkdtempSync(join(tmpdir(), 'towpath-report-'));
let browser;

function layup(name, args) {
  if (!existsSync(BIN)) throw new Error(`${BIN} not found: build it (cargo build -p towpath) or set TOWPATH_BIN`);
  const r = spawnSync(BIN, ['layup', ...args, '-o', join(dir, `${name}.json`), '--report', join(dir, `${name}.html`)], { encoding: 'utf8' });
  assert.equal(r.status, 0, r.stderr);
  return join(dir, `${name}.html`);
}

/** Pixels of a PNG screenshot: [coloured (saturated), grey-bright (the mesh)]. */
async function pixels(page, png) {
  return page.evaluate(async (b64) => {
    const img = new Image();
    img.src = `data:image/png;base64,${b64}`;
    await img.decode();
    const c = document.createElement('canvas');
    c.width = img.width; c.height = img.height;
    const g = c.getContext('2d');
    g.drawImage(img, 0, 0);
    const d = g.getImageData(0, 0, c.width, c.height).data;
    let coloured = 0, grey = 0;
    for (let i = 0; i < d.length; i += 4) {
      const hi = Math.max(d[i], d[i + 1], d[i + 2]), lo = Math.min(d[i], d[i + 1], d[i + 2]);
      if (hi - lo > 40) coloured++;
      else if (hi > 110) grey++;
    }
    return [coloured, grey];
  }, png.toString('base64'));
}

before(async () => {
  browser = await startBrowser();
});

after(async () => {
  await browser?.close();
});

async function open(file, name) {
  const page = await browser.newPage({ viewport: { width: 1280, height: 760 } });
  const remote = [];
  page.on('request', (r) => { if (!/^(file|data|blob):/.test(r.url())) remote.push(r.url()); });
  const errors = [];
  page.on('pageerror', (e) => errors.push(String(e)));
  await page.goto(pathToFileURL(file).href);
  await page.waitForSelector('body[data-ready="1"]', { timeout: 30000 });
  const shot = async (mode) => {
    const png = await page.locator('#viewport').screenshot();
    if (shots) { mkdirSync(shots, { recursive: true }); await page.screenshot({ path: join(shots, `report-${name}-${mode}.png`) }); }
    return png;
  };
  return { page, remote, errors, shot };
}

async function checkReport(file, name, courses) {
  const { page, remote, errors, shot } = await open(file, name);
  assert.equal(await page.evaluate(() => window.layupReport.courses), courses);
  const [coloured, grey] = await pixels(page, await shot('course'));
  // Courses in their own colours cover much of the part; the mesh shows between and around them.
  assert.ok(coloured > 20000, `courses barely drawn: ${coloured} coloured pixels`);
  assert.ok(grey > 500, `the mesh is not drawn: ${grey} grey pixels`);
  assert.match(await page.locator('#legend').textContent(), new RegExp(`${courses} courses?`));
  assert.match(await page.locator('#scale').textContent(), /\d+ mm/);
  assert.match(await page.locator('#axes-labels').textContent(), /XYZ\d+ mm/);
  const expect = { angle: /deg/, radius: /mm.*minimum steering radius|minimum steering radius.*mm/s, gap: /overlap.*mm/ };
  const pngs = {};
  for (const mode of ['angle', 'radius', 'gap']) {
    await page.locator('#color-mode').selectOption(mode);
    await page.waitForFunction((m) => document.body.dataset.mode === m, mode);
    await page.evaluate(() => new Promise((r) => { window.layupReport.view.onFrame = r; window.layupReport.view.request(); }));
    assert.match(await page.locator('#legend').textContent(), expect[mode]);
    pngs[mode] = await shot(mode);
  }
  // Recolouring changes the picture (the three figures are coloured differently).
  assert.notDeepEqual(pngs.angle, pngs.gap);
  await page.locator('#color-mode').selectOption('course');
  // The summary beside the view names its units.
  const summary = await page.locator('#summary').textContent();
  assert.match(summary, /surface and lengths in mm/);
  assert.match(summary, /coverage\s*[\d.]+ % of [\d.]+ mm²/);
  assert.deepEqual(remote, [], 'the page fetched something');
  assert.deepEqual(errors, []);
  await page.close();
}

test('cylinder, +45° ply: drawn from a file with nothing fetched, every colouring', async () => {
  const file = layup('cyl45', ['cylinder:r=300,l=1000', '--angle', '45', '--axis', '0,0,1', '--tow-width', '6.35', '--tows', '16', '--triangles', '20000']);
  await checkReport(file, 'cyl45', 14);
});

test('cylinder, −45° ply', async () => {
  const file = layup('cyl-45', ['cylinder:r=300,l=1000', '--angle', '-45', '--axis', '0,0,1', '--tow-width', '6.35', '--tows', '16', '--triangles', '20000']);
  await checkReport(file, 'cyl-45', 14);
});

test('plate, 30° ply with cut tows at the edges', async () => {
  const file = layup('plate', ['plane:a=600,b=400', '--angle', '30', '--tow-width', '6.35', '--tows', '8', '--triangles', '2000']);
  const doc = JSON.parse(readFileSync(join(dir, 'plate.json'), 'utf8'));
  await checkReport(file, 'plate', doc.courses.length);
});
