// The page `towpath layup --report F.html` writes: the mold surface and every tow of every course
// in 3D, coloured by course, angle deviation, steering radius or gap/overlap, with a legend, an
// axis triad and a scale bar. Everything it shows comes from the JSON block #layup-data that the
// binary inlines (typed arrays as base64, little-endian); nothing is fetched.

import * as THREE from 'three';
import { View } from './viewer.js';
import { categorical, ramp, rampCss, css } from './colors.js';

const $ = (id) => document.getElementById(id);

/** A base64 string as a typed array of `Type` (the data is little-endian, as every browser). */
function decode(b64, Type) {
  const bin = atob(b64 || '');
  const u8 = new Uint8Array(bin.length);
  for (let i = 0; i < bin.length; i++) u8[i] = bin.charCodeAt(i);
  return new Type(u8.buffer, 0, u8.length / Type.BYTES_PER_ELEMENT);
}

/** The smallest of 1, 2, 5 × 10^k that is at least x. */
function niceCeil(x) {
  if (!(x > 0)) return 1;
  const p = Math.pow(10, Math.floor(Math.log10(x)));
  for (const m of [1, 2, 5, 10]) if (m * p >= x * (1 - 1e-9)) return m * p;
  return 10 * p;
}

/** The largest of 1, 2, 5 × 10^k that is at most x. */
function niceFloor(x) {
  if (!(x > 0)) return 1;
  const p = Math.pow(10, Math.floor(Math.log10(x)));
  for (const m of [5, 2, 1]) if (m * p <= x * (1 + 1e-9)) return m * p;
  return p;
}

function fmt(x) {
  if (!Number.isFinite(x)) return String(x);
  const a = Math.abs(x);
  if (a < 1e-6) return '0';
  if (a >= 1000) return x.toFixed(0);
  return Number(x.toPrecision(3)).toString();
}

/** Index of the last element of sorted `a` that is ≤ s (−1 if none). */
function below(a, s) {
  let lo = 0, hi = a.length;
  while (lo < hi) { const m = (lo + hi) >> 1; if (a[m] <= s) lo = m + 1; else hi = m; }
  return lo - 1;
}

/** One course's arrays, decoded. */
function course(c) {
  const P = decode(c.position, Float32Array), N = decode(c.normal, Float32Array), D = decode(c.direction, Float32Array);
  const S = decode(c.s, Float32Array), A = decode(c.angle_deviation_deg, Float32Array), R = decode(c.steering_radius, Float32Array);
  const G = decode(c.gap_to_left, Float32Array);
  const gs = [], gw = [];
  for (let i = 0; i + 1 < G.length; i += 2) { gs.push(G[i]); gw.push(G[i + 1]); }
  // Gap samples are taken at a fixed step; a station farther than one step from every sample has none.
  let step = Infinity;
  for (let i = 1; i < gs.length; i++) step = Math.min(step, gs[i] - gs[i - 1]);
  if (!Number.isFinite(step)) step = c.width || 1;
  return { id: c.id, n: S.length, P, N, D, S, A, R, gs, gw, gstep: step * 1.01, tows: c.tows || [] };
}

/** Interpolated station at arc length s: position, normal, left (normal × direction), values. */
function station(c, s) {
  const i = Math.max(0, Math.min(c.n - 2, below(c.S, s)));
  const j = Math.min(c.n - 1, i + 1);
  const t = c.S[j] > c.S[i] ? Math.max(0, Math.min(1, (s - c.S[i]) / (c.S[j] - c.S[i]))) : 0;
  const lerp3 = (X) => [0, 1, 2].map((k) => X[3 * i + k] + (X[3 * j + k] - X[3 * i + k]) * t);
  const p = lerp3(c.P), n = lerp3(c.N), d = lerp3(c.D);
  const nl = Math.hypot(...n) || 1;
  n[0] /= nl; n[1] /= nl; n[2] /= nl;
  const l = [n[1] * d[2] - n[2] * d[1], n[2] * d[0] - n[0] * d[2], n[0] * d[1] - n[1] * d[0]];
  const ll = Math.hypot(...l) || 1;
  l[0] /= ll; l[1] /= ll; l[2] /= ll;
  const angle = c.A[i] + (c.A[j] - c.A[i]) * t;
  // Curvature (1/radius) is what varies smoothly; a straight stretch has curvature 0.
  const k = (1 / c.R[i]) + ((1 / c.R[j]) - (1 / c.R[i])) * t;
  return { p, n, l, angle, radius: k > 0 ? 1 / k : Infinity, gap: gapAt(c, s) };
}

/** Gap (+) or overlap (−) to the left neighbour at s, NaN where there is no sample. */
function gapAt(c, s) {
  if (!c.gs.length) return NaN;
  const i = below(c.gs, s);
  if (i >= 0 && i + 1 < c.gs.length && c.gs[i + 1] - c.gs[i] <= c.gstep) {
    const t = (s - c.gs[i]) / (c.gs[i + 1] - c.gs[i]);
    return c.gw[i] + (c.gw[i + 1] - c.gw[i]) * t;
  }
  const near = [i, i + 1].filter((k) => k >= 0 && k < c.gs.length && Math.abs(c.gs[k] - s) <= c.gstep / 2);
  return near.length ? c.gw[near[0]] : NaN;
}

/** Every laid tow as a band of its width (so per-tow cuts and restarts show), and each course's
 *  outer edges as dark lines. Per vertex: course index and the three figures. */
function buildCourses(data) {
  const w = data.tow_width, nt = data.tows;
  const lift = Math.max(0.02 * w, data.diagonal * 2e-5);
  const pos = [], nor = [], idx = [], vCourse = [], vAngle = [], vRadius = [], vGap = [];
  const edges = [];
  const courses = data.courses.map(course);
  courses.forEach((c, ci) => {
    if (c.n < 2) return;
    c.tows.forEach((ivs, k) => {
      const mid = (k + 0.5 - nt / 2) * w;
      for (const [s0, s1] of ivs) {
        if (!(s1 > s0)) continue;
        const ss = [s0];
        for (let i = 0; i < c.n; i++) if (c.S[i] > s0 && c.S[i] < s1) ss.push(c.S[i]);
        ss.push(s1);
        const first = pos.length / 3;
        const right = [], left = [];
        for (const s of ss) {
          const st = station(c, s);
          for (const side of [-0.5, 0.5]) {
            const o = mid + side * w;
            pos.push(st.p[0] + st.l[0] * o + st.n[0] * lift, st.p[1] + st.l[1] * o + st.n[1] * lift, st.p[2] + st.l[2] * o + st.n[2] * lift);
            nor.push(st.n[0], st.n[1], st.n[2]);
            vCourse.push(ci); vAngle.push(st.angle); vRadius.push(st.radius); vGap.push(st.gap);
          }
          const e = (o, arr) => arr.push(st.p[0] + st.l[0] * o + st.n[0] * lift * 2, st.p[1] + st.l[1] * o + st.n[1] * lift * 2, st.p[2] + st.l[2] * o + st.n[2] * lift * 2);
          if (k === 0) e(-nt * w / 2, right);
          if (k === nt - 1) e(nt * w / 2, left);
        }
        for (let q = 0; q + 1 < ss.length; q++) {
          const a = first + 2 * q;
          idx.push(a, a + 1, a + 3, a, a + 3, a + 2);
        }
        for (const line of [right, left]) for (let q = 0; q + 3 < line.length; q += 3) edges.push(...line.slice(q, q + 6));
      }
    });
  });
  const g = new THREE.BufferGeometry();
  g.setAttribute('position', new THREE.Float32BufferAttribute(pos, 3));
  g.setAttribute('normal', new THREE.Float32BufferAttribute(nor, 3));
  g.setAttribute('color', new THREE.Float32BufferAttribute(new Float32Array(pos.length), 3));
  g.setIndex(idx);
  // Depth: the mesh is pushed furthest back, the bands a little, the edge lines not at all, so
  // lines win over bands and bands over the mesh at any distance.
  const bands = new THREE.Mesh(g, new THREE.MeshLambertMaterial({
    vertexColors: true, side: THREE.DoubleSide, polygonOffset: true, polygonOffsetFactor: 1, polygonOffsetUnits: 2,
  }));
  const eg = new THREE.BufferGeometry();
  eg.setAttribute('position', new THREE.Float32BufferAttribute(edges, 3));
  const lines = new THREE.LineSegments(eg, new THREE.LineBasicMaterial({ color: 0x10151b }));
  return { bands, lines, values: { course: vCourse, angle: vAngle, radius: vRadius, gap: vGap }, count: courses.length };
}

const NO_VALUE = [0.3, 0.31, 0.34];
const FLAG = [0.86, 0.1, 0.12];
const GAP = [[0.16, 0.38, 0.95], [0.3, 0.74, 0.42], [0.92, 0.22, 0.18]];

/** Gap (t = −1, blue) through a butt joint (0, green) to overlap (+1, red): no end of it is grey,
 *  so it never reads as the bare mesh. */
function gapColor(t) {
  const x = Math.max(-1, Math.min(1, t));
  const [a, b] = x < 0 ? [GAP[1], GAP[0]] : [GAP[1], GAP[2]];
  return a.map((v, k) => v + (b[k] - v) * Math.abs(x));
}

/** Colour scales: a function of a vertex's value, and the legend that explains it. */
function scales(data) {
  const q = data.summary;
  const angleMax = niceCeil(Math.max(q.max_angle_deviation_deg, 0.5));
  const limit = q.min_steering_radius_limit;
  const gapMax = niceCeil(Math.max(q.max_gap, q.max_overlap, 0.1));
  const decades = 2; // radius ramp from the minimum to 100 × the minimum
  const ncourses = data.courses.length;
  return {
    course: {
      color: (v) => categorical(v),
      legend: `<div class="small">${ncourses} course${ncourses === 1 ? '' : 's'}, one colour each, every tow (${data.tows} × ${fmt(data.tow_width)} mm) drawn where it is laid; dark lines: course edges; bare grey: mesh not covered.</div>`,
    },
    angle: {
      color: (v) => (Number.isFinite(v) ? ramp(v / angleMax) : NO_VALUE),
      legend: `<div class="ramp" style="background:${rampCss()}"></div><div class="ends"><span>0 deg</span><span>${fmt(angleMax / 2)} deg</span><span>≥ ${fmt(angleMax)} deg</span></div>
        <div class="small muted">angle between the course and the design direction, degrees (max ${fmt(q.max_angle_deviation_deg)} deg, mean ${fmt(q.mean_angle_deviation_deg)} deg)</div>`,
    },
    radius: {
      color: (v) => {
        if (!(v > 0)) return NO_VALUE;
        if (v < limit) return FLAG;
        if (!Number.isFinite(v)) return ramp(0);
        return ramp(1 - Math.min(1, Math.log10(v / limit) / decades));
      },
      legend: `<div class="ramp" style="background:linear-gradient(90deg, ${css(FLAG)} 0 12%, ${[...Array(9).keys()].map((i) => `${css(ramp(1 - i / 8))} ${12 + (88 * i) / 8}%`).join(', ')})"></div>
        <div class="ends"><span>&lt; ${fmt(limit)} mm</span><span>${fmt(limit)} mm</span><span>≥ ${fmt(limit * 10 ** decades)} mm, straight</span></div>
        <div class="small muted"><span class="swatch" style="background:${css(FLAG)}"></span>below the minimum steering radius ${fmt(limit)} mm: ${q.points_below_min_radius} point${q.points_below_min_radius === 1 ? '' : 's'}${q.min_steering_radius ? `; smallest ${fmt(q.min_steering_radius)} mm` : '; every course straight'}</div>`,
    },
    gap: {
      color: (v) => (Number.isFinite(v) ? gapColor(-v / gapMax) : NO_VALUE),
      legend: `<div class="ramp" style="background:linear-gradient(90deg, ${css(gapColor(-1))}, ${css(gapColor(0))}, ${css(gapColor(1))})"></div>
        <div class="ends"><span>gap ${fmt(gapMax)} mm</span><span>0 (butt joint)</span><span>overlap ${fmt(gapMax)} mm</span></div>
        <div class="small muted">width of the gap or overlap between each course and its left neighbour, mm (widest gap ${fmt(q.max_gap)} mm, widest overlap ${fmt(q.max_overlap)} mm); <span class="swatch" style="background:${css(NO_VALUE)}"></span>no neighbour</div>`,
    },
  };
}

/** Axis triad at the part's lower corner, labelled with its length in mm. */
function triad(box) {
  const size = box.getSize(new THREE.Vector3());
  const len = niceFloor(Math.max(size.x, size.y, size.z) * 0.25);
  const group = new THREE.Group();
  const o = box.min.clone();
  const dirs = [[1, 0, 0, 0xe5484d], [0, 1, 0, 0x30a46c], [0, 0, 1, 0x3e8ef7]];
  const tips = [];
  for (const [x, y, z, c] of dirs) {
    const d = new THREE.Vector3(x, y, z);
    group.add(new THREE.ArrowHelper(d, o, len, c, len * 0.12, len * 0.06));
    tips.push(o.clone().addScaledVector(d, len * 1.12));
  }
  return { group, len, origin: o, tips };
}

function init() {
  const data = JSON.parse($('layup-data').textContent);
  window.layupReport = { data, ready: false };
  let view;
  try {
    view = new View($('viewport'));
  } catch (e) {
    $('nogl').hidden = false;
    document.body.dataset.ready = 'no-webgl';
    return;
  }
  view.renderer.setClearColor(0x1b2129);
  // More ambient light than the app's view: faces turned to the camera show the legend's colours
  // nearly as they are, and the shading still shows the part's shape.
  view.scene.add(new THREE.AmbientLight(0xffffff, 1.1));
  const positions = decode(data.mesh.positions, Float32Array);
  const triangles = decode(data.mesh.triangles, Uint32Array);
  const mg = new THREE.BufferGeometry();
  mg.setAttribute('position', new THREE.BufferAttribute(positions, 3));
  mg.setIndex(new THREE.BufferAttribute(triangles, 1));
  mg.computeVertexNormals();
  mg.computeBoundingBox();
  const box = mg.boundingBox.clone();
  data.diagonal = box.getSize(new THREE.Vector3()).length();
  const mesh = new THREE.Mesh(mg, new THREE.MeshStandardMaterial({
    color: 0xd4d8dc, roughness: 0.9, metalness: 0, side: THREE.DoubleSide,
    polygonOffset: true, polygonOffsetFactor: 2, polygonOffsetUnits: 4,
  }));
  view.scene.add(mesh);
  const built = buildCourses(data);
  view.scene.add(built.bands, built.lines);
  built.bands.geometry.computeBoundingBox();
  if (!built.bands.geometry.boundingBox.isEmpty()) box.union(built.bands.geometry.boundingBox);
  const axes = triad(box);
  view.scene.add(axes.group);
  const labels = $('axes-labels');
  labels.innerHTML = ['X', 'Y', 'Z'].map((a, i) => `<span style="color:${['#ff7b7f', '#5fd49a', '#7fb4ff'][i]}">${a}</span>`).join('')
    + `<span style="color:#e6edf3;font-weight:400">${fmt(axes.len)} mm</span>`;
  const sc = scales(data);

  function setMode(mode) {
    const s = sc[mode] || sc.course;
    const values = built.values[mode] || built.values.course;
    const col = built.bands.geometry.getAttribute('color');
    for (let i = 0; i < values.length; i++) {
      const c = s.color(values[i]);
      col.setXYZ(i, c[0], c[1], c[2]);
    }
    col.needsUpdate = true;
    $('legend').innerHTML = s.legend;
    document.body.dataset.mode = mode;
    view.request();
  }

  // The scale bar and the triad's labels follow the camera.
  const v = new THREE.Vector3();
  function overlay() {
    const el = view.renderer.domElement;
    const h = el.clientHeight || 1, w = el.clientWidth || 1;
    const dist = view.camera.position.distanceTo(view.controls.target);
    const perPx = (2 * dist * Math.tan((view.camera.fov * Math.PI) / 360)) / h;
    const len = niceFloor(perPx * 140);
    $('scale').querySelector('.bar').style.width = `${len / perPx}px`;
    $('scale').querySelector('.text').textContent = `${fmt(len)} mm (at the centre of view)`;
    const spans = labels.children;
    const at = [...axes.tips, axes.origin.clone().add(new THREE.Vector3(-0.06, -0.06, -0.06).multiplyScalar(axes.len))];
    at.forEach((p, i) => {
      v.copy(p).project(view.camera);
      const hide = v.z > 1 || v.z < -1;
      spans[i].style.display = hide ? 'none' : '';
      spans[i].style.left = `${((v.x + 1) / 2) * w}px`;
      spans[i].style.top = `${((1 - v.y) / 2) * h}px`;
    });
  }
  view.controls.addEventListener('change', overlay);
  new ResizeObserver(overlay).observe($('viewport'));

  // The floor grid sits clearly below the part, so depth offsets never draw it over a flat ply.
  const fit = () => { view.fit(box); view.grid.position.z = box.min.z - 0.01 * data.diagonal; overlay(); };
  fit();
  window.addEventListener('keydown', (e) => { if (e.key === 'f' || e.key === 'F') fit(); });
  $('color-mode').addEventListener('change', (e) => setMode(e.target.value));
  setMode($('color-mode').value);
  Object.assign(window.layupReport, { view, setMode, courses: built.count, vertices: built.values.course.length });
  view.onFrame = () => { window.layupReport.ready = true; document.body.dataset.ready = '1'; };
  view.request();
}

init();
