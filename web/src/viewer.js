// The 3D view: one renderer, a perspective camera with orbit/pan/zoom, render on demand.
// A program is drawn as a handful of merged line geometries (laid, approach/retract, transit,
// rapid); plies, playback and colour modes are uniforms and small textures, so toggling never
// rebuilds geometry.

import * as THREE from 'three';
import { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';
import { categorical, ramp } from './colors.js';

export const KIND = { LAYUP: 0, APPROACH: 1, TRANSIT: 2, RAPID: 3 };
const MODE = { fixed: 0, ply: 1, order: 2, feed: 3 };

/** True when WebGL runs in software (SwiftShader, llvmpipe): multisampling is then the most
 *  expensive part of a frame, so the views draw without it there. */
export const softwareGL = (() => {
  try {
    const gl = document.createElement('canvas').getContext('webgl2') || document.createElement('canvas').getContext('webgl');
    if (!gl) return false;
    const ext = gl.getExtension('WEBGL_debug_renderer_info');
    const name = String(gl.getParameter(ext ? ext.UNMASKED_RENDERER_WEBGL : gl.RENDERER));
    const lose = gl.getExtension('WEBGL_lose_context');
    if (lose) lose.loseContext();
    return /swiftshader|llvmpipe|softpipe|software/i.test(name);
  } catch {
    return false;
  }
})();

export class View {
  constructor(el) {
    this.el = el;
    this.renderer = new THREE.WebGLRenderer({ antialias: !softwareGL, preserveDrawingBuffer: true });
    this.renderer.setPixelRatio(Math.min(window.devicePixelRatio || 1, 2));
    this.renderer.setClearColor(0x1b2129);
    el.appendChild(this.renderer.domElement);
    this.scene = new THREE.Scene();
    this.camera = new THREE.PerspectiveCamera(40, 1, 1, 1e6);
    this.camera.up.set(0, 0, 1);
    this.camera.position.set(1000, -1500, 1200);
    this.controls = new OrbitControls(this.camera, this.renderer.domElement);
    this.controls.enableDamping = false;
    this.controls.screenSpacePanning = true;
    this.controls.addEventListener('change', () => this.request());
    this.scene.add(new THREE.AmbientLight(0xffffff, 0.7));
    const sun = new THREE.DirectionalLight(0xffffff, 1.6);
    sun.position.set(1, -1, 2);
    this.camera.add(sun);
    this.scene.add(this.camera);
    this.grid = null;
    this.pending = false;
    this.onFrame = null;
    new ResizeObserver(() => this.resize()).observe(el);
    this.resize();
  }

  resize() {
    const w = Math.max(1, this.el.clientWidth), h = Math.max(1, this.el.clientHeight);
    this.renderer.setSize(w, h, false);
    this.camera.aspect = w / h;
    this.camera.updateProjectionMatrix();
    this.request();
  }

  request() {
    if (this.pending) return;
    this.pending = true;
    requestAnimationFrame(() => {
      this.pending = false;
      this.renderer.render(this.scene, this.camera);
      if (this.onFrame) { const f = this.onFrame; this.onFrame = null; f(); }
    });
  }

  /** Frames a box; `top` looks straight down. */
  fit(box, top = false) {
    if (!box || box.isEmpty()) return;
    const c = box.getCenter(new THREE.Vector3());
    const r = Math.max(1, box.getSize(new THREE.Vector3()).length() / 2);
    const d = (r / Math.sin((this.camera.fov * Math.PI) / 360)) * 0.95;
    const dir = top ? new THREE.Vector3(0, -0.001, 1) : new THREE.Vector3(0.55, -0.95, 0.75);
    dir.normalize();
    this.camera.position.copy(c).addScaledVector(dir, d);
    this.camera.near = Math.max(0.1, d / 1000);
    this.camera.far = d * 20;
    this.camera.updateProjectionMatrix();
    this.controls.target.copy(c);
    this.controls.update();
    this.setGrid(box);
    this.request();
  }

  setGrid(box) {
    if (this.grid) { this.scene.remove(this.grid); this.grid.geometry.dispose(); }
    const size = box.getSize(new THREE.Vector3());
    const span = Math.max(size.x, size.y) * 1.3;
    const step = Math.pow(10, Math.floor(Math.log10(span / 5)));
    const n = Math.ceil(span / step);
    this.grid = new THREE.GridHelper(n * step, n, 0x3a4654, 0x2a333d);
    this.grid.rotation.x = Math.PI / 2;
    const c = box.getCenter(new THREE.Vector3());
    this.grid.position.set(c.x, c.y, box.min.z - 0.5);
    this.scene.add(this.grid);
  }

  /** Pixel-space pick with a tolerance (in pixels) among objects. */
  pick(event, objects, px = 6) {
    const rect = this.renderer.domElement.getBoundingClientRect();
    const ndc = new THREE.Vector2(((event.clientX - rect.left) / rect.width) * 2 - 1, -((event.clientY - rect.top) / rect.height) * 2 + 1);
    const ray = new THREE.Raycaster();
    ray.setFromCamera(ndc, this.camera);
    const dist = this.camera.position.distanceTo(this.controls.target);
    ray.params.Line.threshold = (px / rect.height) * 2 * dist * Math.tan((this.camera.fov * Math.PI) / 360);
    return ray.intersectObjects(objects, false);
  }
}

const VERT = `
attribute float aPly;
attribute float aSeq;
attribute float aOrder;
attribute float aFeed;
attribute float aDist;
uniform sampler2D uPlies;
uniform sampler2D uRamp;
uniform float uPlyCount;
uniform float uUpTo;
uniform float uFeedMax;
uniform int uMode;
uniform vec3 uColor;
varying vec3 vColor;
varying float vHide;
varying float vDist;
void main() {
  vec4 ply = aPly >= 0.0 ? texture2D(uPlies, vec2((aPly + 0.5) / uPlyCount, 0.5)) : vec4(uColor, 1.0);
  vHide = (ply.a < 0.5 || aSeq > uUpTo) ? 1.0 : 0.0;
  if (uMode == 1) vColor = ply.rgb;
  else if (uMode == 2) vColor = texture2D(uRamp, vec2(aOrder, 0.5)).rgb;
  else if (uMode == 3) vColor = aFeed < 0.0 ? vec3(0.5) : texture2D(uRamp, vec2(aFeed / uFeedMax, 0.5)).rgb;
  else vColor = uColor;
  vDist = aDist;
  gl_Position = projectionMatrix * modelViewMatrix * vec4(position, 1.0);
}`;

const FRAG = `
uniform float uOpacity;
uniform float uDash;
varying vec3 vColor;
varying float vHide;
varying float vDist;
void main() {
  if (vHide > 0.5) discard;
  if (uDash > 0.0 && mod(vDist, uDash) > uDash * 0.55) discard;
  gl_FragColor = vec4(vColor, uOpacity);
}`;

let rampTexture = null;
function rampTex() {
  if (rampTexture) return rampTexture;
  const d = new Uint8Array(256 * 4);
  for (let i = 0; i < 256; i++) {
    const c = ramp(i / 255);
    d.set([c[0] * 255, c[1] * 255, c[2] * 255, 255], i * 4);
  }
  rampTexture = new THREE.DataTexture(d, 256, 1, THREE.RGBAFormat);
  rampTexture.magFilter = THREE.LinearFilter;
  rampTexture.needsUpdate = true;
  return rampTexture;
}

/** A program drawn as four merged line layers. */
export class ProgramLayers {
  /** `basePlies`: the plies of the program this one was optimized from. An optimized program
   *  lays a ply in several runs, each parsed as a ply of its own; its courses are coloured and
   *  toggled as the original's ply of the same label. */
  constructor(blob, role, basePlies = null) {
    const { header, arrays } = blob;
    this.info = header.program;
    this.listing = header.listing;
    this.role = role;
    const P = arrays.points, from = arrays.seg_from, to = arrays.seg_to;
    const course = arrays.seg_course, kind = arrays.seg_kind, feed = arrays.seg_feed;
    const n = from.length;
    this.segments = n;
    this.segLine = arrays.seg_line;
    this.segCourse = course;
    this.points = P;
    this.segFrom = from;
    this.segTo = to;
    this.marks = null;
    this.marksShown = true;
    this.scene = null;
    const courses = this.info.courses;
    const plyOf = new Int32Array(courses.length);
    let nplies;
    if (basePlies) {
      const byLabel = new Map(basePlies.map((p, i) => [p.label, i]));
      const own = this.info.plies.map((p) => {
        if (!byLabel.has(p.label)) byLabel.set(p.label, byLabel.size);
        return byLabel.get(p.label);
      });
      courses.forEach((c, i) => { plyOf[i] = own[c.ply]; });
      nplies = Math.max(1, byLabel.size);
    } else {
      courses.forEach((c, i) => { plyOf[i] = c.ply; });
      nplies = Math.max(1, this.info.plies.length);
    }
    this.plyOf = plyOf;
    this.plyCount = nplies;
    let feedMax = 1;
    for (let i = 0; i < n; i++) if (feed[i] > feedMax) feedMax = feed[i];
    const counts = [0, 0, 0, 0];
    for (let i = 0; i < n; i++) counts[kind[i]]++;
    const plyData = new Uint8Array(nplies * 4);
    for (let p = 0; p < nplies; p++) {
      const c = categorical(p);
      plyData.set([c[0] * 255, c[1] * 255, c[2] * 255, 255], p * 4);
    }
    this.plyTex = new THREE.DataTexture(plyData, nplies, 1, THREE.RGBAFormat);
    this.plyTex.needsUpdate = true;
    this.box = new THREE.Box3();
    this.layers = [];
    const ncourses = Math.max(1, courses.length - 1);
    for (let k = 0; k < 4; k++) {
      const m = counts[k];
      const pos = new Float32Array(m * 6), aPly = new Float32Array(m * 2), aSeq = new Float32Array(m * 2);
      const aOrder = new Float32Array(m * 2), aFeed = new Float32Array(m * 2), aDist = new Float32Array(m * 2);
      const seg = new Uint32Array(m);
      let j = 0;
      let last = -1; // the previous segment of this kind, if it may be extended
      for (let i = 0; i < n; i++) {
        if (kind[i] !== k) continue;
        const a = from[i] * 3, b = to[i] * 3;
        // A move that continues the previous one in a straight line (same course, same feed)
        // extends it: straight courses become one segment, whatever their point count.
        if (last >= 0 && from[i] === to[last] && course[i] === course[last] && feed[i] === feed[last]) {
          const q = j - 1;
          const ux = pos[q * 6 + 3] - pos[q * 6], uy = pos[q * 6 + 4] - pos[q * 6 + 1], uz = pos[q * 6 + 5] - pos[q * 6 + 2];
          const vx = P[b] - P[a], vy = P[b + 1] - P[a + 1], vz = P[b + 2] - P[a + 2];
          const cx = uy * vz - uz * vy, cy = uz * vx - ux * vz, cz = ux * vy - uy * vx;
          const dot = ux * vx + uy * vy + uz * vz;
          const uu = ux * ux + uy * uy + uz * uz, vv = vx * vx + vy * vy + vz * vz;
          if (dot > 0 && cx * cx + cy * cy + cz * cz <= 1e-12 * uu * vv) {
            pos[q * 6 + 3] = P[b]; pos[q * 6 + 4] = P[b + 1]; pos[q * 6 + 5] = P[b + 2];
            aDist[q * 2 + 1] += Math.sqrt(vv);
            last = i;
            continue;
          }
        }
        last = i;
        pos[j * 6] = P[a]; pos[j * 6 + 1] = P[a + 1]; pos[j * 6 + 2] = P[a + 2];
        pos[j * 6 + 3] = P[b]; pos[j * 6 + 4] = P[b + 1]; pos[j * 6 + 5] = P[b + 2];
        const c = course[i];
        const p = c >= 0 ? plyOf[c] : -1;
        aPly[j * 2] = aPly[j * 2 + 1] = p;
        aSeq[j * 2] = aSeq[j * 2 + 1] = i;
        aOrder[j * 2] = aOrder[j * 2 + 1] = c >= 0 ? c / ncourses : 0;
        aFeed[j * 2] = aFeed[j * 2 + 1] = feed[i];
        aDist[j * 2 + 1] = Math.hypot(P[b] - P[a], P[b + 1] - P[a + 1], P[b + 2] - P[a + 2]);
        seg[j] = i;
        j++;
      }
      const g = new THREE.BufferGeometry();
      this.drawn = (this.drawn || 0) + j;
      const used = (arr, w) => arr.subarray(0, j * w);
      g.setAttribute('position', new THREE.BufferAttribute(used(pos, 6), 3));
      g.setAttribute('aPly', new THREE.BufferAttribute(used(aPly, 2), 1));
      g.setAttribute('aSeq', new THREE.BufferAttribute(used(aSeq, 2), 1));
      g.setAttribute('aOrder', new THREE.BufferAttribute(used(aOrder, 2), 1));
      g.setAttribute('aFeed', new THREE.BufferAttribute(used(aFeed, 2), 1));
      g.setAttribute('aDist', new THREE.BufferAttribute(used(aDist, 2), 1));
      g.computeBoundingSphere();
      g.computeBoundingBox();
      if (k === KIND.LAYUP && m > 0) this.box.union(g.boundingBox);
      const mat = new THREE.ShaderMaterial({
        vertexShader: VERT, fragmentShader: FRAG, transparent: true, depthWrite: k === KIND.LAYUP,
        uniforms: {
          uPlies: { value: this.plyTex }, uRamp: { value: rampTex() }, uPlyCount: { value: nplies },
          uUpTo: { value: 1e12 }, uFeedMax: { value: feedMax }, uMode: { value: 0 },
          uColor: { value: new THREE.Color(0xffffff) }, uOpacity: { value: 1 }, uDash: { value: 0 },
        },
      });
      const obj = new THREE.LineSegments(g, mat);
      // Laid courses are drawn last and never hidden by the transit above them.
      obj.renderOrder = k === KIND.LAYUP ? 10 : 3 - k;
      if (k === KIND.LAYUP) mat.depthTest = false;
      obj.userData = { kind: k, seg, layers: this };
      obj.frustumCulled = false;
      this.layers.push(obj);
    }
    if (this.box.isEmpty()) for (const l of this.layers) if (l.geometry.boundingBox) this.box.union(l.geometry.boundingBox);
    this.style(role);
  }

  style(role) {
    const orig = new THREE.Color(0xf08c3a), opt = new THREE.Color(0x35c18f);
    const transit = role === 'optimized' ? opt : orig;
    const [lay, app, tr, ra] = this.layers;
    app.material.uniforms.uColor.value.set(0x7f90a3);
    app.material.uniforms.uOpacity.value = 0.75;
    tr.material.uniforms.uColor.value.copy(transit);
    tr.material.uniforms.uOpacity.value = 0.8;
    ra.material.uniforms.uColor.value.copy(transit);
    ra.material.uniforms.uOpacity.value = 0.6;
    const size = this.box.getSize(new THREE.Vector3()).length();
    ra.material.uniforms.uDash.value = Math.max(1, size / 150);
    lay.material.uniforms.uColor.value.set(0xdfe6ee);
  }

  addTo(scene) {
    this.scene = scene;
    for (const l of this.layers) scene.add(l);
    if (this.marks) scene.add(this.marks);
  }
  removeFrom(scene) {
    this.clearMarks();
    for (const l of this.layers) { scene.remove(l); l.geometry.dispose(); l.material.dispose(); }
    this.plyTex.dispose();
    this.scene = null;
  }

  /** Safety marks, the fifth layer: every move of a line a safety report names, drawn over
   *  everything (collisions red, near misses orange, travel-limit violations purple), with a
   *  dot where each collision or near miss came closest. Returns the number of marked moves. */
  setMarks(safety) {
    this.clearMarks();
    if (!safety) return 0;
    const byLine = new Map();
    for (const c of safety.near_misses || []) byLine.set(c.line, 1);
    for (const c of safety.limit_violations || []) byLine.set(c.line, 2);
    for (const c of safety.collisions || []) byLine.set(c.line, 0);
    if (!byLine.size) return 0;
    const palette = [[1, 0.02, 0.02], [1, 0.3, 0], [0.55, 0.12, 1]];
    const P = this.points, marked = [];
    for (let i = 0; i < this.segments; i++) {
      const k = byLine.get(this.segLine[i] + 1);
      if (k !== undefined) marked.push([i, k]);
    }
    // Lines are one pixel wide in WebGL, so a marked move is drawn as a thin tube (instanced
    // cylinders) a fixed fraction of the part's size across.
    const group = new THREE.Group();
    const radius = Math.max(0.2, this.box.getSize(new THREE.Vector3()).length() / 500);
    const tube = new THREE.CylinderGeometry(1, 1, 1, 8, 1, false);
    tube.translate(0, 0.5, 0);
    const mat = new THREE.MeshBasicMaterial({ depthTest: false, transparent: true, opacity: 0.95 });
    const inst = new THREE.InstancedMesh(tube, mat, Math.max(1, marked.length));
    const a = new THREE.Vector3(), b = new THREE.Vector3(), d = new THREE.Vector3(), up = new THREE.Vector3(0, 1, 0);
    const q = new THREE.Quaternion(), m = new THREE.Matrix4(), sc = new THREE.Vector3(), col = new THREE.Color();
    marked.forEach(([i, k], j) => {
      a.fromArray(P, this.segFrom[i] * 3);
      b.fromArray(P, this.segTo[i] * 3);
      d.subVectors(b, a);
      const len = d.length();
      q.setFromUnitVectors(up, len > 0 ? d.clone().divideScalar(len) : up);
      sc.set(radius, Math.max(len, 1e-6), radius);
      m.compose(a, q, sc);
      inst.setMatrixAt(j, m);
      inst.setColorAt(j, col.setRGB(...palette[k]));
    });
    inst.count = marked.length;
    inst.renderOrder = 20;
    inst.frustumCulled = false;
    group.add(inst);
    const dots = [], dcol = [];
    for (const [list, k] of [[safety.near_misses || [], 1], [safety.collisions || [], 0]]) {
      for (const c of list) { dots.push(...c.at); dcol.push(...palette[k]); }
    }
    if (dots.length) {
      const pg = new THREE.BufferGeometry();
      pg.setAttribute('position', new THREE.Float32BufferAttribute(dots, 3));
      pg.setAttribute('color', new THREE.Float32BufferAttribute(dcol, 3));
      const pts = new THREE.Points(pg, new THREE.PointsMaterial({ size: 9, sizeAttenuation: false, vertexColors: true, depthTest: false, transparent: true }));
      pts.renderOrder = 21;
      pts.frustumCulled = false;
      group.add(pts);
    }
    group.visible = this.marksShown;
    group.userData = { marked: marked.length };
    this.marks = group;
    if (this.scene) this.scene.add(group);
    return marked;
  }

  clearMarks() {
    if (!this.marks) return;
    if (this.scene) this.scene.remove(this.marks);
    for (const o of this.marks.children) { o.geometry.dispose(); o.material.dispose(); }
    this.marks = null;
  }

  /** Moves marked by the last safety report. */
  markedMoves() { return this.marks ? this.marks.userData.marked : 0; }

  setMarksShown(on) {
    this.marksShown = on;
    if (this.marks) this.marks.visible = on;
  }

  setColorMode(mode) { this.layers[KIND.LAYUP].material.uniforms.uMode.value = MODE[mode] ?? 1; }

  setPlyVisible(p, on) {
    this.plyTex.image.data[p * 4 + 3] = on ? 255 : 0;
    this.plyTex.needsUpdate = true;
  }

  plyVisible(p) { return p < 0 || this.plyTex.image.data[p * 4 + 3] > 0; }

  setUpTo(seq) { for (const l of this.layers) l.material.uniforms.uUpTo.value = seq; }
  upTo() { return this.layers[0].material.uniforms.uUpTo.value; }

  /** Visibility of the layer kinds: laid, approach, transit, rapid. */
  setShown(show) { this.layers.forEach((l, k) => { l.visible = show[k]; }); }

  /** The segment (program order) a pick hit, if it is drawn. */
  hitSegment(hit) {
    const obj = hit.object;
    const local = Math.floor(hit.index / 2);
    const s = obj.userData.seg[local];
    if (s === undefined || s > this.upTo()) return null;
    const c = this.segCourse[s];
    if (c >= 0 && !this.plyVisible(this.plyOf[c])) return null;
    return s;
  }
}

/** A mesh (the `positions`/`triangles` arrays of a mesh geometry response) drawn as a
 *  translucent grey surface: a cell's mold tool or fixture behind the paths. */
export function meshObject(blob) {
  const g = new THREE.BufferGeometry();
  g.setAttribute('position', new THREE.BufferAttribute(blob.arrays.positions, 3));
  g.setIndex(new THREE.BufferAttribute(blob.arrays.triangles, 1));
  g.computeVertexNormals();
  const mat = new THREE.MeshStandardMaterial({
    color: 0x9aa7b4, roughness: 0.8, metalness: 0.05, transparent: true, opacity: 0.45,
    side: THREE.DoubleSide, depthWrite: false, polygonOffset: true, polygonOffsetFactor: 1, polygonOffsetUnits: 1,
  });
  const obj = new THREE.Mesh(g, mat);
  obj.renderOrder = 1;
  return obj;
}
