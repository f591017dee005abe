// Starts `towpath serve` on a free port with a fresh workspace, and headless Debian Chromium
// driven by playwright-core. The binary is $TOWPATH_BIN, else target/debug/towpath (the one
// `cargo test --workspace` builds); Chromium is $CHROMIUM, else /usr/bin/chromium.

import { spawn } from 'node:child_process';
import { mkdtempSync, existsSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join, dirname } from 'node:path';
import { fileURLToPath } from 'node:url';
import { chromium } from 'playwright-core';

const root = join(dirname(fileURLToPath(import.meta.url)), '..', '..');
export const BIN = process.env.TOWPATH_BIN || join(root, 'target', 'debug', 'towpath');

export async function startServer() {
  if (!existsSync(BIN)) throw new Error(`${BIN} not found: build it (cargo build -p towpath) or set TOWPATH_BIN`);
  const workspace = mkdtempSync(join(tmpdir(), 'towpath-e2e-'));
  const proc = spawn(BIN, ['serve', '--port', '0', '--workspace', workspace], { stdio: ['ignore', 'pipe', 'inherit'] });
  const url = await new Promise((resolve, reject) => {
    let out = '';
    const timer = setTimeout(() => reject(new Error(`towpath serve did not start: ${out}`)), 20000);
    proc.stdout.on('data', (d) => {
      out += d;
      const m = out.match(/http:\/\/127\.0\.0\.1:\d+\//);
      if (m) { clearTimeout(timer); resolve(m[0]); }
    });
    proc.on('exit', (code) => reject(new Error(`towpath serve exited with ${code}: ${out}`)));
  });
  return { url, workspace, stop: () => proc.kill('SIGINT') };
}

export async function startBrowser() {
  // playwright gives every launch a new empty profile folder of its own.
  return chromium.launch({
    executablePath: process.env.CHROMIUM || '/usr/bin/chromium',
    headless: true,
    args: ['--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run', '--disable-background-networking',
      '--disable-component-update', '--disable-sync', '--use-angle=swiftshader', '--enable-unsafe-swiftshader'],
  });
}

/** Counts the pixels of a PNG screenshot that differ from the viewport's background colour. */
export async function litPixels(page, png) {
  return page.evaluate(async (b64) => {
    const img = new Image();
    img.src = `data:image/png;base64,${b64}`;
    await img.decode();
    const c = document.createElement('canvas');
    c.width = img.width; c.height = img.height;
    const g = c.getContext('2d');
    g.drawImage(img, 0, 0);
    const d = g.getImageData(0, 0, c.width, c.height).data;
    let n = 0;
    for (let i = 0; i < d.length; i += 4) {
      // Background #1b2129 and the grid lines are dark and grey; drawn moves are bright or coloured.
      const r = d[i], gg = d[i + 1], b = d[i + 2];
      if (Math.max(r, gg, b) > 110 || Math.max(r, gg, b) - Math.min(r, gg, b) > 40) n++;
    }
    return n;
  }, png.toString('base64'));
}

/** Counts the strongly red pixels of a PNG screenshot (the safety marks of collisions). */
export async function redPixels(page, png) {
  return page.evaluate(async (b64) => {
    const img = new Image();
    img.src = `data:image/png;base64,${b64}`;
    await img.decode();
    const c = document.createElement('canvas');
    c.width = img.width; c.height = img.height;
    const g = c.getContext('2d');
    g.drawImage(img, 0, 0);
    const d = g.getImageData(0, 0, c.width, c.height).data;
    let n = 0;
    for (let i = 0; i < d.length; i += 4) if (d[i] > 200 && d[i + 1] < 110 && d[i + 2] < 110) n++;
    return n;
  }, png.toString('base64'));
}
