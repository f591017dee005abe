// End-to-end tests of the web application in headless Chromium.

import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { spawnSync } from 'node:child_process';
import { writeFileSync, mkdirSync, readFileSync } from 'node:fs';
import { join } from 'node:path';
import { startServer, startBrowser, litPixels, redPixels, BIN } from './harness.mjs';

let server, browser, page;
const shots = process.env.TOWPATH_SHOTS; // folder to keep screenshots in, for a person to look at

async function shot(name) {
  const png = await page.locator('#viewport').screenshot();
  if (shots) { mkdirSync(shots, { recursive: true }); await page.screenshot({ path: join(shots, `${name}.png`) }); }
  return png;
}

before(async () => {
  server = await startServer();
  browser = await startBrowser();
  page = await browser.newPage({ viewport: { width: 1440, height: 860 }, acceptDownloads: true });
  page.on('pageerror', (e) => console.error('page error:', e));
});

after(async () => {
  await browser?.close();
  server?.stop();
});

test('opens with a demo part drawn in 3D', async () => {
  await page.goto(server.url);
  await page.waitForSelector('body[data-ready="1"]', { timeout: 20000 });
  assert.equal(await page.locator('#program-select').inputValue(), 'demo-planar-45');
  assert.equal(await page.locator('#ply-list .ply').count(), 4);
  assert.match(await page.locator('#program-desc').textContent(), /courses, 4 plies/);
  const lit = await litPixels(page, await shot('01-demo'));
  assert.ok(lit > 5000, `the 3D view is blank (${lit} lit pixels)`);
});

test('toggling a ply hides its courses without rebuilding geometry', async () => {
  const before = await litPixels(page, await shot('02-before-toggle'));
  const geometry = await page.evaluate(() => window.towpath.original.layers[0].geometry.uuid);
  await page.locator('#ply-list input[data-ply="0"]').uncheck();
  const off = await litPixels(page, await shot('03-base-ply-off'));
  assert.equal(await page.evaluate(() => window.towpath.original.plyVisible(0)), false);
  assert.ok(off < before * 0.8, `hiding the base ply should darken the view: ${before} → ${off}`);
  assert.equal(await page.evaluate(() => window.towpath.original.layers[0].geometry.uuid), geometry);
  await page.locator('#ply-list input[data-ply="0"]').check();
  const on = await litPixels(page, await shot('04-base-ply-on'));
  assert.ok(Math.abs(on - before) < before * 0.02, `showing it again restores the view: ${before} vs ${on}`);
});

let jobResult;
test('a solve shows live progress, the saving, and the optimized path', async () => {
  await page.locator('#opt-time').fill('2');
  await page.locator('#solve').click();
  await page.waitForSelector('#progress:not([hidden])');
  // Cancel stays enabled while it runs; progress arrives at 5 a second or faster.
  await page.waitForFunction(() => window.towpath.progressEvents >= 5, null, { timeout: 5000 });
  await page.waitForSelector('#results:not([hidden])', { timeout: 30000 });
  const v = await page.evaluate(() => window.towpath.lastResult);
  jobResult = v;
  const events = await page.evaluate(() => window.towpath.progressEvents);
  assert.ok(events >= 5 * Math.floor(v.elapsed) , `progress events ${events} over ${v.elapsed} s`);
  assert.match(await page.locator('#verdict').textContent(), /^verified/);
  const saved = v.result.savings.find((s) => s.cost === v.result.cost).off_saved_percent;
  assert.ok(saved > 0, `off-part saving ${saved} %`);
  assert.match(await page.locator('#p-saved').textContent(), /%/);
  await page.waitForFunction(() => window.towpath.optimized !== null, null, { timeout: 10000 });
  await shot('05-optimized');
});

test('original and optimized can be switched', async () => {
  const both = await litPixels(page, await shot('06-both'));
  await page.locator('#show-optimized').uncheck();
  const orig = await litPixels(page, await shot('07-original-only'));
  assert.equal(await page.evaluate(() => window.towpath.optimized.layers.every((l) => !l.visible)), true);
  await page.locator('#show-original').uncheck();
  await page.locator('#show-optimized').check();
  const opt = await litPixels(page, await shot('08-optimized-only'));
  assert.equal(await page.evaluate(() => window.towpath.original.layers.every((l) => !l.visible)), true);
  assert.ok(orig !== opt && both > 0, `${both} ${orig} ${opt}`);
  await page.locator('#show-original').check();
});

test('the downloaded optimized program verifies with `towpath verify`', async () => {
  const dir = join(server.workspace, 'check');
  mkdirSync(dir, { recursive: true });
  const [download] = await Promise.all([page.waitForEvent('download'), page.locator('#dl-program').click()]);
  const optimized = join(dir, 'optimized.nc');
  await download.saveAs(optimized);
  const original = join(dir, 'original.nc');
  writeFileSync(original, await (await fetch(`${server.url}api/programs/demo-planar-45/text`)).text());
  const m = await (await fetch(`${server.url}api/machines/gantry-afp`)).json();
  const machine = join(dir, 'gantry.toml');
  writeFileSync(machine, m.toml);
  const r = spawnSync(BIN, ['verify', original, optimized, '--machine', machine, '--tow-width', '6.35'], { encoding: 'utf8' });
  assert.equal(r.status, 0, `towpath verify refused the download:\n${r.stdout}\n${r.stderr}`);
  assert.notEqual(readFileSync(optimized, 'utf8'), readFileSync(original, 'utf8'), 'the download is the optimized program, not the original');
});

test('a malformed program is refused with its file, line and problem', async () => {
  await page.locator('details.upload summary').click();
  const bad = '%\n(PLY 1)\n(COURSE 1)\nG0 X0 Y0 Z25\nG1 X10 Y QQ F3000\nM20\nG1 X100\nM21\nM30\n%\n';
  await page.locator('#upload-file').setInputFiles({ name: 'broken.nc', mimeType: 'text/plain', buffer: Buffer.from(bad) });
  await page.waitForSelector('#program-error:not([hidden])');
  const text = await page.locator('#program-error').textContent();
  assert.match(text, /^broken\.nc: line 5: /, text);
  await shot('09-malformed');
  // The view still shows the program that was open.
  assert.equal(await page.evaluate(() => window.towpath.programId), 'demo-planar-45');
});

test('a part in a cell: its collisions are marked, and a solve in the cell writes a safe program', async () => {
  await page.locator('#program-select').selectOption('demo-planar-stringer');
  await page.waitForFunction(() => window.towpath.timing.id === 'demo-planar-stringer', null, { timeout: 15000 });
  // The demo part's own meshes are chosen and drawn.
  assert.match(await page.locator('#cell-count').textContent(), /3 chosen/);
  await page.waitForFunction(() => (window.towpath.cellDrawn || []).length === 3, null, { timeout: 10000 });
  // Colour by feed, so that no course is red: the red in the view is the marks'.
  await page.locator('#color-mode').selectOption('feed');
  const redBefore = await redPixels(page, await shot('11-cell'));
  await page.locator('#check-motion').click();
  await page.waitForFunction(() => window.towpath.safetyChecks >= 1, null, { timeout: 30000 });
  assert.match(await page.locator('#safety-summary').textContent(), /^program: UNSAFE · [1-9]\d* collisions?/);
  const marked = await page.evaluate(() => window.towpath.original.markedMoves());
  assert.ok(marked > 0, 'the colliding moves are marked');
  const redMarked = await redPixels(page, await shot('12-cell-marked'));
  assert.ok(redMarked > redBefore + 200, `the marks are drawn: ${redBefore} → ${redMarked} red pixels`);
  // Hiding the marks hides them.
  await page.locator('#show-marks').uncheck();
  const redHidden = await redPixels(page, await shot('13-marks-hidden'));
  assert.ok(redHidden < redMarked - 200, `hidden: ${redMarked} → ${redHidden}`);
  await page.locator('#show-marks').check();
  // A solve in the cell: the output is safe and says so; the input's marks stay on the input.
  await page.locator('#opt-time').fill('1');
  await page.locator('#solve').click();
  await page.waitForFunction(() => window.towpath.lastResult && window.towpath.lastResult.result.original === 'demo-planar-stringer', null, { timeout: 60000 });
  await page.waitForFunction(() => window.towpath.optimized !== null, null, { timeout: 10000 });
  const r = await page.evaluate(() => window.towpath.lastResult.result);
  assert.deepEqual(r.molds.length, 3);
  assert.equal(r.safety.after.safe, true);
  assert.equal(r.safety.after.collision_count, 0);
  assert.match(await page.locator('#safety-summary').textContent(), /optimized: safe · 0 collisions/);
  assert.equal(await page.evaluate(() => window.towpath.optimized.markedMoves()), 0);
  assert.ok(await page.evaluate(() => window.towpath.original.markedMoves()) > 0);
  await shot('14-cell-solved');
  await page.locator('#color-mode').selectOption('ply');
});

test('the 10,000-course panel draws its first frame within 3 s of choosing it', async () => {
  // The server builds the panel's arrays in the background from its start; wait for that,
  // then time the choice → first frame.
  for (let i = 0; i < 240; i++) {
    const s = await (await fetch(`${server.url}api/status`)).json();
    if (s.panel_ready) break;
    await new Promise((r) => setTimeout(r, 500));
  }
  const t0 = Date.now();
  await page.locator('#program-select').selectOption('panel-10000-courses');
  await page.waitForFunction(() => window.towpath.timing.id === 'panel-10000-courses', null, { timeout: 15000 });
  const wall = Date.now() - t0;
  const t = await page.evaluate(() => window.towpath.timing);
  console.log(`panel: ${t.segments} moves drawn as ${t.drawn} lines in ${t.draw_calls} layers, ${(t.bytes / 1e6).toFixed(1)} MB, fetch ${t.fetch_ms.toFixed(0)} ms, first frame drawn ${t.first_frame_ms.toFixed(0)} ms after the choice (wall ${wall} ms${t.software_gl ? ', software WebGL' : ''})`);
  assert.ok(t.segments > 250000, `${t.segments} moves`);
  assert.ok(t.first_frame_ms < 3000, `first frame after ${t.first_frame_ms} ms (wall ${wall} ms)`);
  assert.ok(t.draw_calls <= 4);
  assert.equal(await page.locator('#ply-list .ply').count(), 100);
  const lit = await litPixels(page, await shot('10-panel'));
  assert.ok(lit > 5000, `panel view blank (${lit})`);
});

test('the surface view takes its lengths in inches and says so', async () => {
  await page.locator('.tab[data-tab="surface"]').click();
  await page.locator('#s-desc').fill('cylinder:r=12,l=40');
  await page.locator('#s-units').selectOption('in');
  assert.equal(await page.locator('#s-tow-unit').textContent(), 'in');
  await page.locator('#s-tow').fill('0.25');
  await page.locator('#s-run').click();
  await page.waitForSelector('#s-summary:not([hidden])', { timeout: 60000 });
  const text = await page.locator('#s-summary').textContent();
  assert.match(text, /inputs in inches; lengths here in mm/);
  // 12 in × 40 in cylinder: 2π · 304.8 mm · 1016 mm = 1.946 m².
  const m2 = Number(text.match(/of ([\d.]+) m²/)[1]);
  assert.ok(Math.abs(m2 - (2 * Math.PI * 304.8 * 1016) / 1e6) < 0.01, `${m2} m²`);
  if (shots) await page.screenshot({ path: join(shots, '15-surface-inches.png') });
  await page.locator('.tab[data-tab="program"]').click();
});
