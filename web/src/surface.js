// The surface view: a mold surface, a ply generated on it as a background job, every tow drawn
// where it is laid (so per-tow cuts show), coloured by a quality figure.

import * as THREE from 'three';
import { getJson, sendJson, sendBody, getBlob } from './api.js';
import { View } from './viewer.js';
import { ramp, diverging, rampCss, css } from './colors.js';

const $ = (id) => document.getElementById(id);
let view = null;
let meshObj = null;
let towObj = null;
let courses = null;
let job = null;

function message(el, text) { el.hidden = !text; el.textContent = text || ''; }

async function meshes(select) {
  const { meshes } = await getJson('/api/meshes');
  $('s-mesh').innerHTML = meshes.map((m) => `<option>${m}</option>`).join('');
  if (select) $('s-mesh').value = select;
}

function request() {
  const kind = $('s-kind').value;
  const r = {
    angle: parseFloat($('s-angle').value),
    axis: $('s-axis').value.split(',').map(Number),
    tows: parseInt($('s-tows').value, 10),
    tow_width: parseFloat($('s-tow').value),
    coverage: parseInt($('s-cov').value, 10),
    method: $('s-method').value,
    guides: $('s-guides').value.split(/\n\s*\n/).map((s) => s.trim()).filter(Boolean),
  };
  if (kind === 'mesh') r.mesh = $('s-mesh').value; else r.surface = $('s-desc').value.trim();
  if ($('s-units').value !== 'mm') r.units = $('s-units').value;
  return r;
}

function value(c, i, mode) {
  if (mode === 'angle') return c.angle_deviation_deg[i] ?? 0;
  if (mode === 'radius') return c.steering_radius[i];
  return -gapNear(c.gap_to_left, c.arc_length ? c.arc_length[i] : 0); // overlap positive, gap negative
}

// The gap (+) or overlap (−) width of the sample nearest arc length `s`: `gaps` holds
// (arc length, width) pairs sampled along the course, not one per point.
function gapNear(gaps, s) {
  if (!gaps || gaps.length === 0) return 0;
  let lo = 0;
  let hi = gaps.length - 1;
  while (lo < hi) {
    const mid = (lo + hi) >> 1;
    if (gaps[mid][0] < s) lo = mid + 1; else hi = mid;
  }
  const k = lo > 0 && Math.abs(gaps[lo - 1][0] - s) < Math.abs(gaps[lo][0] - s) ? lo - 1 : lo;
  return gaps[k][1];
}

function colorFor(v, mode, range) {
  if (mode === 'gap') return diverging(range > 0 ? v / range : 0);
  if (mode === 'radius') return v === null || v === undefined ? [0.55, 0.6, 0.66] : ramp(1 - Math.min(1, range / Math.max(v, 1e-9)));
  return ramp(range > 0 ? v / range : 0);
}

function drawTows() {
  if (!courses) return;
  if (towObj) { view.scene.remove(towObj); towObj.geometry.dispose(); towObj.material.dispose(); }
  const mode = $('s-color').value;
  const meta = courses.meta;
  const w = meta.tow_width;
  let range = 0;
  for (const c of courses.courses) for (let i = 0; i < c.points.length; i++) {
    const v = value(c, i, mode);
    if (mode === 'radius') continue;
    if (v !== null && Math.abs(v) > range) range = Math.abs(v);
  }
  if (mode === 'radius') range = courses.summary.min_steering_radius_limit || 1000;
  const pos = [], col = [];
  const lift = w * 0.05;
  for (const c of courses.courses) {
    const n = c.points.length;
    for (const t of c.tows) {
      const off = (t.tow + 0.5 - meta.tows / 2) * w;
      for (const [s0, s1] of t.laid) {
        for (let i = 0; i + 1 < n; i++) {
          const a = c.arc_length[i], b = c.arc_length[i + 1];
          if (b < s0 || a > s1) continue;
          for (const k of [i, i + 1]) {
            const p = c.points[k], nn = c.normals[k], d = c.directions[k];
            // Lateral direction: normal × direction (left of the course, tow 0 rightmost).
            const lx = nn[1] * d[2] - nn[2] * d[1], ly = nn[2] * d[0] - nn[0] * d[2], lz = nn[0] * d[1] - nn[1] * d[0];
            pos.push(p[0] + lx * off + nn[0] * lift, p[1] + ly * off + nn[1] * lift, p[2] + lz * off + nn[2] * lift);
            col.push(...colorFor(value(c, k, mode), mode, range));
          }
        }
      }
    }
  }
  const g = new THREE.BufferGeometry();
  g.setAttribute('position', new THREE.Float32BufferAttribute(pos, 3));
  g.setAttribute('color', new THREE.Float32BufferAttribute(col, 3));
  towObj = new THREE.LineSegments(g, new THREE.LineBasicMaterial({ vertexColors: true }));
  view.scene.add(towObj);
  const labels = { angle: ['0°', `${range.toFixed(2)}° angle deviation`], radius: ['straight', `${range.toFixed(0)} mm limit`], gap: [`gap ${range.toFixed(2)} mm`, `overlap ${range.toFixed(2)} mm`] }[mode];
  const bg = mode === 'gap' ? `linear-gradient(90deg, ${css(diverging(-1))}, ${css(diverging(0))}, ${css(diverging(1))})` : rampCss();
  $('s-legend').innerHTML = `<div class="ramp" style="background:${bg}"></div><div class="ends"><span>${labels[0]}</span><span>${labels[1]}</span></div>`;
  view.request();
}

async function showResult(v) {
  const base = `/api/jobs/${v.id}/files`;
  const [blob, doc] = await Promise.all([getBlob(`${base}/mesh.bin`), getJson(`${base}/courses.json`)]);
  if (meshObj) { view.scene.remove(meshObj); meshObj.geometry.dispose(); }
  const g = new THREE.BufferGeometry();
  g.setAttribute('position', new THREE.BufferAttribute(blob.arrays.positions, 3));
  g.setIndex(new THREE.BufferAttribute(blob.arrays.triangles, 1));
  g.computeVertexNormals();
  meshObj = new THREE.Mesh(g, new THREE.MeshStandardMaterial({ color: 0x8a96a3, roughness: 0.85, metalness: 0.05, side: THREE.DoubleSide, polygonOffset: true, polygonOffsetFactor: 1, polygonOffsetUnits: 1 }));
  view.scene.add(meshObj);
  courses = doc;
  drawTows();
  g.computeBoundingBox();
  view.fit(g.boundingBox);
  const q = doc.summary;
  const s = $('s-summary');
  s.hidden = false;
  s.innerHTML = `<span class="lbl">Ply</span>
    <table class="tbl">
    <tr><td>courses</td><td>${doc.summary.courses}</td></tr>
    <tr><td>units</td><td>inputs in ${{ mm: 'mm', in: 'inches', m: 'metres', ft: 'feet' }[doc.meta.input_units] || doc.meta.input_units || 'mm'}; lengths here in mm</td></tr>
    <tr><td>coverage</td><td>${q.coverage_percent.toFixed(2)} % of ${(q.ply_area / 1e6).toFixed(3)} m²</td></tr>
    <tr><td>gaps / overlaps</td><td>${q.gap_area.toFixed(0)} / ${q.overlap_area.toFixed(0)} mm²</td></tr>
    <tr><td>min steering radius</td><td>${q.min_steering_radius ? q.min_steering_radius.toFixed(0) + ' mm' : 'straight'}</td></tr>
    <tr><td>angle deviation</td><td>mean ${q.mean_angle_deviation_deg.toFixed(3)}°, max ${q.max_angle_deviation_deg.toFixed(3)}°</td></tr>
    </table>
    <div class="downloads"><a href="${base}/courses.json" download>Courses JSON</a><a href="${base}/courses.nc" download>G-code</a></div>`;
}

export async function initSurface() {
  view = new View($('s-viewport'));
  view.setGrid(new THREE.Box3(new THREE.Vector3(-500, -500, 0), new THREE.Vector3(500, 500, 0)));
  await meshes();
  $('s-kind').onchange = (e) => {
    const m = e.target.value === 'mesh';
    $('s-mesh-row').hidden = !m;
    $('s-desc').hidden = m;
    if (!m) $('s-desc').value = e.target.value;
  };
  $('s-mesh-file').onchange = async (e) => {
    const f = e.target.files[0];
    if (!f) return;
    const name = f.name.replace(/[^A-Za-z0-9._-]/g, '_');
    try {
      await sendBody(`/api/meshes?name=${encodeURIComponent(name)}`, 'POST', await f.arrayBuffer(), 'application/octet-stream');
      await meshes(name);
      message($('s-error'), '');
    } catch (err) { message($('s-error'), err.message); }
    e.target.value = '';
  };
  $('s-color').onchange = drawTows;
  $('s-units').onchange = (e) => { $('s-tow-unit').textContent = e.target.value; };
  $('s-run').onclick = async () => {
    message($('s-error'), '');
    try {
      job = await sendJson('/api/jobs/layup', 'POST', request());
    } catch (e) { return message($('s-error'), e.message); }
    $('s-run').disabled = true;
    $('s-cancel').disabled = false;
    const es = new EventSource(`/api/jobs/${job.id}/events`);
    const show = (v) => { $('s-progress').textContent = `${v.phase} · ${v.count} courses · ${v.elapsed.toFixed(1)} s`; };
    es.addEventListener('progress', (m) => show(JSON.parse(m.data)));
    es.addEventListener('end', async (m) => {
      es.close();
      const v = JSON.parse(m.data);
      show(v);
      $('s-run').disabled = false;
      $('s-cancel').disabled = true;
      if (v.state === 'done') await showResult(v);
      else message($('s-error'), v.error || v.state);
    });
  };
  $('s-cancel').onclick = () => job && sendJson(`/api/jobs/${job.id}/cancel`, 'POST', {}).catch(() => {});
}
