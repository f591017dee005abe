// towpath's front end: the program view with its solve panel, the machine module and the
// surface view. Plain modules, no framework: the page is a tool, not a site.

import { getJson, sendJson, sendBody, getBlob } from './api.js';
import { View, ProgramLayers, KIND, softwareGL, meshObject } from './viewer.js';
import { categorical, css, rampCss } from './colors.js';
import { initMachine } from './machine.js';
import { initSurface } from './surface.js';

const $ = (id) => document.getElementById(id);
const fmt = (x, d = 1) => (x === null || x === undefined || !Number.isFinite(x) ? '–' : x.toLocaleString('en-US', { maximumFractionDigits: d, minimumFractionDigits: d }));

// Exposed for the browser tests and for a curious user's console.
const app = (window.towpath = {
  programId: null, original: null, optimized: null, job: null, timing: {}, frames: 0,
});

// ---------------------------------------------------------------- tabs
let surfaceStarted = false;
for (const b of document.querySelectorAll('.tab')) {
  b.addEventListener('click', () => {
    document.querySelectorAll('.tab').forEach((t) => t.classList.toggle('active', t === b));
    document.querySelectorAll('.page').forEach((p) => p.classList.toggle('active', p.id === `page-${b.dataset.tab}`));
    if (b.dataset.tab === 'surface' && !surfaceStarted) { surfaceStarted = true; initSurface(); }
    if (b.dataset.tab === 'program') view.resize();
  });
}

// ---------------------------------------------------------------- program view
const view = new View($('viewport'));
app.view = view;
app.softwareGL = softwareGL;

function showError(el, e) {
  if (!e) { el.hidden = true; el.textContent = ''; return; }
  el.hidden = false;
  el.textContent = e.message || String(e);
}

async function refreshStatus() {
  try {
    const s = await getJson('/api/status');
    const jobs = await getJson('/api/jobs');
    const running = jobs.jobs.filter((j) => j.state === 'running').length;
    const queued = jobs.jobs.filter((j) => j.state === 'queued').length;
    $('status').textContent = `workspace ${s.workspace} · ${running} running, ${queued} queued`;
    $('status').title = s.load_problems.length ? `not loaded: ${s.load_problems.join('; ')}` : '';
  } catch { $('status').textContent = 'server not reachable'; }
}

async function loadLists(select) {
  const [{ programs }, { machines }, { dialects }] = await Promise.all([
    getJson('/api/programs'), getJson('/api/machines'), getJson('/api/dialects'),
  ]);
  const sel = $('program-select');
  sel.innerHTML = '';
  const groups = { demo: 'Demo parts', panel: 'Large panel', upload: 'Your programs', result: 'Optimized results' };
  for (const [src, label] of Object.entries(groups)) {
    const items = programs.filter((p) => p.source === src && (src !== 'result'));
    if (!items.length) continue;
    const g = document.createElement('optgroup');
    g.label = label;
    for (const p of items) {
      const o = document.createElement('option');
      o.value = p.id;
      o.textContent = src === 'panel' ? `${p.id} (≈417,000 lines)` : p.id;
      g.appendChild(o);
    }
    sel.appendChild(g);
  }
  app.programs = programs;
  for (const id of ['upload-machine']) {
    $(id).innerHTML = machines.map((m) => `<option>${m.name}</option>`).join('');
  }
  $('upload-dialect').innerHTML = dialects.map((d) => `<option>${d.name}</option>`).join('');
  if (select) sel.value = select;
  await loadMeshes();
}

// ---------------------------------------------------------------- the cell (motion safety)
async function loadMeshes() {
  const chosen = chosenMolds();
  const { meshes } = await getJson('/api/meshes');
  app.meshes = meshes;
  renderCell(chosen);
}

function chosenMolds() {
  return [...document.querySelectorAll('#cell-list input:checked')].map((b) => b.dataset.mesh);
}

function renderCell(chosen) {
  const list = $('cell-list');
  list.innerHTML = '';
  for (const m of app.meshes || []) {
    const row = document.createElement('label');
    row.className = 'check';
    const box = document.createElement('input');
    box.type = 'checkbox';
    box.dataset.mesh = m;
    box.checked = chosen.includes(m);
    box.addEventListener('change', countCell);
    row.append(box, document.createTextNode(` ${m}`));
    list.appendChild(row);
  }
  if (!(app.meshes || []).length) list.innerHTML = '<span class="small muted">no meshes: upload one in the Surface tab</span>';
  countCell();
}

function countCell() {
  const n = chosenMolds().length;
  $('cell-count').textContent = n ? `· ${n} chosen` : '· none chosen';
  $('check-motion').disabled = n === 0;
  drawCell();
}

// The chosen meshes drawn in the view (fetched once each).
const cellObjects = new Map();
async function drawCell() {
  const chosen = new Set(chosenMolds());
  for (const [name, obj] of cellObjects) if (obj) obj.visible = chosen.has(name) && $('show-cell').checked;
  for (const name of chosen) {
    if (cellObjects.has(name)) continue;
    cellObjects.set(name, null);
    try {
      const obj = meshObject(await getBlob(`/api/meshes/${encodeURIComponent(name)}/geometry`));
      cellObjects.set(name, obj);
      view.scene.add(obj);
      obj.visible = chosenMolds().includes(name) && $('show-cell').checked;
    } catch (e) {
      cellObjects.delete(name);
      showError($('solve-error'), e);
    }
  }
  app.cellDrawn = [...cellObjects.entries()].filter(([, o]) => o && o.visible).map(([n]) => n);
  view.request();
}
$('show-cell').addEventListener('change', drawCell);

function showSafety(lines, bad) {
  const el = $('safety-summary');
  el.hidden = !lines.length;
  el.className = `safety small${bad ? ' bad' : ''}`;
  el.textContent = lines.join('\n');
}

function safetyLine(label, r) {
  return `${label}: ${r.safe ? 'safe' : 'UNSAFE'} · ${r.summary}`;
}

$('check-motion').onclick = async () => {
  const molds = chosenMolds();
  if (!app.programId || !molds.length) return;
  const body = { molds };
  const c = parseFloat($('opt-clearance').value);
  if (Number.isFinite(c)) body.clearance = c;
  $('check-motion').disabled = true;
  showSafety(['checking…'], false);
  try {
    const targets = [['original', app.programId]];
    if (app.optimized && app.lastResult && app.lastResult.result.original === app.programId) targets.push(['optimized', app.lastResult.result.program]);
    const lines = [];
    let bad = false;
    for (const [which, id] of targets) {
      const r = await sendJson(`/api/programs/${encodeURIComponent(id)}/check`, 'POST', body);
      if (app[which]) app[which].setMarks(r.safety);
      lines.push(safetyLine(which === 'original' ? 'program' : 'optimized', r.safety));
      bad = bad || !r.safety.safe;
    }
    app.safetyChecks = (app.safetyChecks || 0) + 1;
    showSafety(lines, bad);
    applyVisibility();
  } catch (e) {
    showSafety([], false);
    showError($('solve-error'), e);
  } finally {
    countCell();
  }
};
$('cell').addEventListener('toggle', () => { if ($('cell').open) loadMeshes(); });

function shownKinds() {
  return [true, $('show-approach').checked, $('show-transit').checked, $('show-rapid').checked];
}

function applyVisibility() {
  const showO = $('show-original').checked, showP = $('show-optimized').checked && app.optimized;
  const marks = $('show-marks').checked;
  if (app.original) app.original.setMarksShown(marks && showO);
  if (app.optimized) app.optimized.setMarksShown(marks && !!showP);
  if (app.original) {
    const k = shownKinds();
    // Laid moves are the same in both programs: drawn once, from the optimized when it is shown.
    if (showP) { k[KIND.LAYUP] = false; k[KIND.APPROACH] = false; }
    app.original.setShown(showO ? k : [false, false, false, false]);
  }
  if (app.optimized) app.optimized.setShown(showP ? shownKinds() : [false, false, false, false]);
  view.request();
}

function colorMode() { return $('color-mode').value; }

function renderLegend() {
  const el = $('legend');
  const info = app.original && app.original.info;
  if (!info) { el.innerHTML = ''; return; }
  const mode = colorMode();
  if (mode === 'ply') {
    el.innerHTML = '';
  } else {
    const ends = mode === 'order' ? ['first course', 'last course'] : ['slow', `${fmt(app.original.layers[0].material.uniforms.uFeedMax.value, 0)} feed`];
    el.innerHTML = `<div class="ramp" style="background:${rampCss()}"></div><div class="ends"><span>${ends[0]}</span><span>${ends[1]}</span></div>`;
  }
}

function renderPlies() {
  const info = app.original.info;
  const list = $('ply-list');
  list.innerHTML = '';
  info.plies.forEach((p, i) => {
    const row = document.createElement('label');
    row.className = 'ply';
    row.innerHTML = `<input type="checkbox" checked data-ply="${i}"><span class="dot" style="background:${css(categorical(i))}"></span>
      <span title="${p.label}${p.line ? ` (line ${p.line})` : ''}">${p.label}</span>
      <span class="n">${p.courses.length} · ${fmt(p.length / 1000, 1)} m</span>`;
    row.querySelector('input').addEventListener('change', (e) => setPly(i, e.target.checked));
    list.appendChild(row);
  });
}

function setPly(i, on) {
  for (const l of [app.original, app.optimized]) if (l && i < l.plyCount) l.setPlyVisible(i, on);
  const box = document.querySelector(`#ply-list input[data-ply="${i}"]`);
  if (box) box.checked = on;
  view.request();
}

$('plies-all').onclick = () => app.original && app.original.info.plies.forEach((_, i) => setPly(i, true));
$('plies-none').onclick = () => app.original && app.original.info.plies.forEach((_, i) => setPly(i, false));
for (const id of ['show-original', 'show-optimized', 'show-approach', 'show-transit', 'show-rapid', 'show-marks']) $(id).addEventListener('change', applyVisibility);
$('color-mode').addEventListener('change', () => {
  for (const l of [app.original, app.optimized]) if (l) l.setColorMode(colorMode());
  renderLegend();
  view.request();
});
$('fit').onclick = () => app.original && view.fit(app.original.box);
$('view-top').onclick = () => app.original && view.fit(app.original.box, true);

function dropLayers(which) {
  if (app[which]) { app[which].removeFrom(view.scene); app[which] = null; }
}

async function openProgram(id) {
  const t0 = performance.now();
  app.programId = id;
  $('loading').hidden = false;
  showError($('program-error'), null);
  resetResults();
  try {
    const blob = await getBlob(`/api/programs/${encodeURIComponent(id)}/geometry`);
    const t1 = performance.now();
    if (app.programId !== id) return;
    dropLayers('original');
    dropLayers('optimized');
    const layers = new ProgramLayers(blob, 'original');
    layers.setColorMode(colorMode());
    layers.addTo(view.scene);
    app.original = layers;
    $('show-optimized').disabled = true;
    const info = layers.info;
    const p = app.programs.find((x) => x.id === id);
    $('program-desc').textContent = `${p ? p.description + ' · ' : ''}${info.courses.length} courses, ${info.plies.length} plies, ${info.lines.toLocaleString()} lines · machine ${p ? p.machine : ''}`;
    $('view-title').textContent = id;
    $('opt-tow').placeholder = p && p.tow_width ? `${p.tow_width} (program's)` : 'from dialect';
    renderCell(p && p.cell ? p.cell : []);
    showSafety([], false);
    renderPlies();
    renderLegend();
    applyVisibility();
    setupScrub();
    view.fit(layers.box);
    await new Promise((r) => { view.onFrame = r; view.request(); });
    // Wait until the frame is really drawn (the GPU may still be working when render returns).
    const gl = view.renderer.getContext();
    gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, new Uint8Array(4));
    const t2 = performance.now();
    app.timing = { id, fetch_ms: t1 - t0, first_frame_ms: t2 - t0, bytes: blob.bytes, segments: layers.segments, drawn: layers.drawn, draw_calls: layers.layers.length, software_gl: softwareGL };
    $('viewport').dataset.firstFrameMs = String(Math.round(t2 - t0));
    $('viewport').dataset.program = id;
    // The latest result of this program, if one was kept.
    const { jobs } = await getJson('/api/jobs');
    const last = jobs.find((j) => j.kind === 'optimize' && j.state === 'done' && j.target === id);
    if (last && app.programId === id) await showResult(last, false);
  } catch (e) {
    showError($('program-error'), e);
  } finally {
    $('loading').hidden = true;
  }
}

$('program-select').addEventListener('change', (e) => openProgram(e.target.value));

$('upload-file').addEventListener('change', async (e) => {
  const f = e.target.files[0];
  if (!f) return;
  showError($('program-error'), null);
  const q = new URLSearchParams({ name: f.name.replace(/[^A-Za-z0-9._-]/g, '_').replace(/^\.+/, '') || 'upload.nc', machine: $('upload-machine').value, dialect: $('upload-dialect').value });
  if ($('upload-tow').value) q.set('tow_width', $('upload-tow').value);
  try {
    const r = await sendBody(`/api/programs?${q}`, 'POST', await f.arrayBuffer(), 'application/octet-stream');
    await loadLists(r.listing.id);
    await openProgram(r.listing.id);
  } catch (err) {
    showError($('program-error'), err);
  } finally {
    e.target.value = '';
  }
});

// ---------------------------------------------------------------- playback and hover
function playTarget() {
  return $('play-which').value === 'original' || !app.optimized ? app.original : app.optimized;
}

function setupScrub() {
  const t = playTarget();
  $('scrub').max = String(t ? t.segments : 1);
  $('scrub').value = $('scrub').max;
  for (const l of [app.original, app.optimized]) if (l) l.setUpTo(1e12);
  $('scrub-label').textContent = '';
}

function scrubTo(v) {
  const t = playTarget();
  if (!t) return;
  for (const l of [app.original, app.optimized]) if (l) l.setUpTo(l === t ? v : 1e12);
  const s = Math.min(v, t.segments - 1);
  const c = s >= 0 ? t.segCourse[s] : -1;
  $('scrub-label').textContent = v >= t.segments ? 'whole program' : `move ${v.toLocaleString()} of ${t.segments.toLocaleString()}${c >= 0 ? ` · course ${c + 1} of ${t.info.courses.length}` : ''}`;
  view.request();
}

$('scrub').addEventListener('input', (e) => { stopPlay(); scrubTo(Number(e.target.value)); });
$('play-which').addEventListener('change', setupScrub);
let playing = null;
function stopPlay() { if (playing) { cancelAnimationFrame(playing); playing = null; $('play').textContent = '▶'; } }
$('play').onclick = () => {
  if (playing) return stopPlay();
  const t = playTarget();
  if (!t) return;
  let v = Number($('scrub').value);
  if (v >= t.segments) v = 0;
  const step = Math.max(1, Math.round(t.segments / 600));
  $('play').textContent = '❚❚';
  const tick = () => {
    v = Math.min(t.segments, v + step);
    $('scrub').value = String(v);
    scrubTo(v);
    if (v >= t.segments) return stopPlay();
    playing = requestAnimationFrame(tick);
  };
  playing = requestAnimationFrame(tick);
};

let hoverTimer = null;
$('viewport').addEventListener('pointermove', (e) => {
  clearTimeout(hoverTimer);
  if (e.buttons) { $('hover').hidden = true; return; }
  hoverTimer = setTimeout(() => hover(e), 60);
});
$('viewport').addEventListener('pointerleave', () => { clearTimeout(hoverTimer); $('hover').hidden = true; });

function hover(e) {
  const objs = [];
  for (const l of [app.optimized, app.original]) if (l) for (const o of l.layers) if (o.visible && (o.userData.kind <= KIND.APPROACH)) objs.push(o);
  const hits = view.pick(e, objs);
  for (const h of hits) {
    const layers = h.object.userData.layers;
    const s = layers.hitSegment(h);
    if (s === null) continue;
    const c = layers.segCourse[s];
    if (c < 0) continue;
    const info = layers.info.courses[c];
    const ply = layers.info.plies[info.ply];
    let text = `ply ${ply.name}${ply.name !== ply.label ? ` (${ply.label})` : ''} · course ${info.number ?? c + 1}\n` +
      `lines ${info.lines[0]}–${info.lines[1]} (contact at ${info.contact_line}), move line ${layers.segLine[s] + 1}\n` +
      `order: ${info.position} of ${layers.info.courses.length} in ${layers.role === 'optimized' ? 'the optimized program' : 'the program'}`;
    if (info.original !== undefined && info.original !== null) text += `\noriginal position ${info.original + 1}${info.reversed ? ', laid reversed' : ''}`;
    const rect = $('viewport').getBoundingClientRect();
    const el = $('hover');
    el.textContent = text;
    el.hidden = false;
    el.style.left = `${Math.min(e.clientX - rect.left + 14, rect.width - 300)}px`;
    el.style.top = `${e.clientY - rect.top + 14}px`;
    return;
  }
  $('hover').hidden = true;
}

// ---------------------------------------------------------------- solve panel
function resetResults() {
  $('results').hidden = true;
  $('progress').hidden = true;
  showError($('solve-error'), null);
}

function solveRequest() {
  const r = {
    program: app.programId,
    cost: $('opt-cost').value,
    bidirectional: $('opt-dir').value === 'bi',
    precedence: $('opt-prec').value,
    solver: $('opt-solver').value,
  };
  const t = parseFloat($('opt-time').value);
  if (Number.isFinite(t)) r.time_limit = t;
  const w = parseFloat($('opt-tow').value);
  if (Number.isFinite(w)) r.tow_width = w;
  const molds = chosenMolds();
  if (molds.length) {
    r.molds = molds;
    const c = parseFloat($('opt-clearance').value);
    if (Number.isFinite(c)) r.clearance = c;
  }
  return r;
}

function showProgress(v) {
  $('progress').hidden = false;
  $('progress-fill').style.width = `${Math.round(100 * Math.min(1, v.fraction || 0))}%`;
  $('p-elapsed').textContent = `${fmt(v.elapsed, 1)} s`;
  $('p-best').textContent = v.best_cost === null ? '–' : fmt(v.best_cost, 1);
  $('p-saved').textContent = v.saved_percent === null ? '–' : `${fmt(v.saved_percent, 1)} %`;
  $('p-phase').textContent = v.state === 'queued' ? 'waiting for a free slot…' : v.phase;
  app.progressEvents = (app.progressEvents || 0) + 1;
}

$('solve').onclick = async () => {
  if (!app.programId) return;
  showError($('solve-error'), null);
  $('results').hidden = true;
  try {
    const job = await sendJson('/api/jobs/optimize', 'POST', solveRequest());
    follow(job);
  } catch (e) { showError($('solve-error'), e); }
};

$('cancel').onclick = async () => {
  if (!app.job) return;
  try { await sendJson(`/api/jobs/${app.job.id}/cancel`, 'POST', {}); } catch (e) { showError($('solve-error'), e); }
};

function follow(job) {
  app.job = job;
  app.progressEvents = 0;
  $('solve').disabled = true;
  $('cancel').disabled = false;
  showProgress(job);
  const es = new EventSource(`/api/jobs/${job.id}/events`);
  es.addEventListener('progress', (m) => showProgress(JSON.parse(m.data)));
  es.addEventListener('end', async (m) => {
    es.close();
    const v = JSON.parse(m.data);
    showProgress(v);
    $('solve').disabled = false;
    $('cancel').disabled = true;
    if (v.state === 'done') await showResult(v, true);
    else if (v.state === 'cancelled') $('p-phase').textContent = 'cancelled';
    else showError($('solve-error'), new Error(v.error || v.state));
    refreshStatus();
  });
  es.onerror = () => { /* the browser reconnects; the end event closes it */ };
  refreshStatus();
}

async function showResult(v, fresh) {
  const r = v.result;
  app.lastResult = v;
  $('results').hidden = false;
  const verdict = $('verdict');
  verdict.className = `verdict${r.verified ? '' : ' bad'}`;
  verdict.textContent = r.fell_back ? `${r.verdict} · nothing cheaper found: the program is unchanged` : r.verdict;
  const rows = r.savings.map((s) => `<tr title="${s.unit}"><td>${s.cost === r.cost ? '<b>' + s.cost + '</b>' : s.cost}</td>
    <td>${fmt(s.off_before, 1)}</td><td>${fmt(s.off_after, 1)}</td><td class="${s.off_saved_percent > 0 ? 'good' : ''}">${fmt(s.off_saved_percent, 1)} %</td><td>${fmt(s.total_saved_percent, 1)} %</td></tr>`);
  $('savings').innerHTML = `<tr><th>off-part</th><th>before</th><th>after</th><th>saved</th><th>total</th></tr>${rows.join('')}`;
  $('per-ply').innerHTML = `<tr><th>ply</th><th>courses</th><th>before</th><th>after</th><th>saved</th></tr>` +
    r.per_ply.map((p) => `<tr><td>${p.ply}</td><td>${p.courses}</td><td>${fmt(p.before, 0)}</td><td>${fmt(p.after, 0)}</td><td class="${p.saved_percent > 0 ? 'good' : ''}">${fmt(p.saved_percent, 1)} %</td></tr>`).join('');
  const base = `/api/jobs/${v.id}/files`;
  $('downloads').innerHTML = `<a id="dl-program" href="${base}/optimized.nc" download="${r.download_name}">Optimized program</a>
    <a id="dl-report-html" href="${base}/report.html" target="_blank">Report (HTML)</a>
    <a id="dl-report-json" href="${base}/report.json" download>Report (JSON)</a>`;
  if (app.programId !== r.original) return;
  const blob = await getBlob(`/api/programs/${encodeURIComponent(r.program)}/geometry`);
  if (app.programId !== r.original) return;
  dropLayers('optimized');
  const layers = new ProgramLayers(blob, 'optimized', app.original.info.plies);
  layers.setColorMode(colorMode());
  for (let i = 0; i < layers.plyCount; i++) {
    const box = document.querySelector(`#ply-list input[data-ply="${i}"]`);
    if (box && !box.checked) layers.setPlyVisible(i, false);
  }
  layers.addTo(view.scene);
  app.optimized = layers;
  if (r.safety) {
    app.original.setMarks(r.safety.before);
    layers.setMarks(r.safety.after);
    showSafety([safetyLine('program', r.safety.before), safetyLine('optimized', r.safety.after)], !r.safety.after.safe);
  } else {
    app.original.clearMarks();
    showSafety(r.molds && r.molds.length ? [] : ['optimized without a cell: choose its meshes and press Check motion to check it'], false);
  }
  $('show-optimized').disabled = false;
  $('show-optimized').checked = true;
  if (fresh) $('play-which').value = 'optimized';
  applyVisibility();
  setupScrub();
}

// ---------------------------------------------------------------- start
(async () => {
  await loadLists();
  refreshStatus();
  setInterval(refreshStatus, 5000);
  initMachine();
  const first = app.programs.find((p) => p.id === 'demo-planar-45') || app.programs[0];
  if (first) { $('program-select').value = first.id; await openProgram(first.id); }
  document.body.dataset.ready = '1';
})();
