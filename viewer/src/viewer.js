// The gauss6 run viewer: the script of the page that `gauss6 view` writes (python/gauss6/view.py).
// Bundled with three.js by esbuild (`npm run build` in viewer/) into dist/gauss6-viewer.js, which
// the page inlines: no network at view time. Reads the run data from the page's
// <script id="gauss6-data" type="application/json"> block and draws, for each run side by side:
// the scene's obstacles, the god-object at xs, the handle's ghost at xh, the contact points and
// normals, the force and torque as arrows; below, the phases on a timeline (play, pause, scrub) and
// the force, torque, contacts and timing plots, linked to the time cursor.
// A small API for tests and users: window.gauss6View (seek, play, pause, state, canvasStats).
import * as THREE from 'three';
import { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';

// Colours: per run the god-object's; per component the plots' (x, y, z).
const RUN_COLORS = [0xe07b24, 0x2a7fd4, 0x3a9e4a, 0xb04fc0];
const AXIS_COLORS = ['#d62728', '#2ca02c', '#1f77b4'];
const FORCE_COLOR = 0xd62020;
const TORQUE_COLOR = 0x7a3fd0;
const CONTACT_COLOR = 0x111111;
const NORMAL_COLOR = 0x0a8a8a;
const BACKGROUND = 0xf4f5f7;

// ---------------------------------------------------------------------------------------------
// Data: arrays come base64-encoded ({"__a": dtype, "b": base64}) and are decoded to typed arrays.

const DTYPES = { f4: Float32Array, f8: Float64Array, u4: Uint32Array, i4: Int32Array };

function decodeArrays(node) {
  if (Array.isArray(node)) return node.map(decodeArrays);
  if (node && typeof node === 'object') {
    if (typeof node.__a === 'string') {
      const bin = atob(node.b);
      const bytes = new Uint8Array(bin.length);
      for (let i = 0; i < bin.length; i++) bytes[i] = bin.charCodeAt(i);
      return new DTYPES[node.__a](bytes.buffer);
    }
    const out = {};
    for (const k of Object.keys(node)) out[k] = decodeArrays(node[k]);
    return out;
  }
  return node;
}

// Index of the last element of the sorted array a that is <= x (0 when x is before a[0]).
function lastAtOrBefore(a, x) {
  let lo = 0, hi = a.length - 1;
  if (hi < 0 || x < a[0]) return 0;
  while (lo < hi) {
    const mid = (lo + hi + 1) >> 1;
    if (a[mid] <= x) lo = mid; else hi = mid - 1;
  }
  return lo;
}

function vec3(a, i) { return new THREE.Vector3(a[3 * i], a[3 * i + 1], a[3 * i + 2]); }

// Trace quaternions are (w, x, y, z) and need not be unit: normalised for display.
function quat(a, i) {
  const q = new THREE.Quaternion(a[4 * i + 1], a[4 * i + 2], a[4 * i + 3], a[4 * i]);
  return q.lengthSq() > 0 ? q.normalize() : q.identity();
}

function meshGeometry(V, F) {
  const g = new THREE.BufferGeometry();
  g.setAttribute('position', new THREE.BufferAttribute(V, 3));
  g.setIndex(new THREE.BufferAttribute(F, 1));
  g.computeVertexNormals();
  g.computeBoundingBox();
  return g;
}

function fmt(x, digits = 3) {
  if (x === undefined || x === null) return '-';
  // Non-finite values (an engine that returned NaN) are shown as such, never as a number.
  if (Number.isNaN(x)) return 'NaN';
  if (!Number.isFinite(x)) return x > 0 ? 'inf' : '-inf';
  if (x === 0) return '0';
  const a = Math.abs(x);
  return a >= 1e4 || a < 1e-3 ? x.toExponential(digits - 1) : x.toPrecision(digits);
}

// ---------------------------------------------------------------------------------------------
// The 3D part: one three.js scene per run, drawn side by side with one shared camera.

class RunScene {
  constructor(run, index, geometry, scales) {
    this.run = run;
    this.scene = new THREE.Scene();
    this.scene.background = new THREE.Color(BACKGROUND);
    this.scene.add(new THREE.HemisphereLight(0xffffff, 0x8a8f99, 1.6));
    const sun = new THREE.DirectionalLight(0xffffff, 1.8);
    sun.position.set(1, -1.5, 2.5);
    this.scene.add(sun);

    // Obstacles: see-through, with their sharp edges drawn, so that a peg in a hole shows.
    for (const ob of geometry.obstacles) {
      const mat = new THREE.MeshStandardMaterial({ color: 0x9aa3ad, transparent: true, opacity: 0.35,
        depthWrite: false, side: THREE.DoubleSide, roughness: 0.8 });
      const mesh = new THREE.Mesh(ob.geometry, mat);
      mesh.renderOrder = 2;
      this.scene.add(mesh);
      const edges = new THREE.LineSegments(new THREE.EdgesGeometry(ob.geometry, 30),
        new THREE.LineBasicMaterial({ color: 0x4a525c }));
      this.scene.add(edges);
    }
    // The god-object (xs) and the handle's ghost (xh): the same body-frame mesh (origin at G).
    const color = RUN_COLORS[index % RUN_COLORS.length];
    this.god = new THREE.Mesh(geometry.god, new THREE.MeshStandardMaterial({ color, roughness: 0.5, metalness: 0.2 }));
    this.god.renderOrder = 1;
    this.scene.add(this.god);
    this.ghost = new THREE.Mesh(geometry.god, new THREE.MeshBasicMaterial({ color: 0x3355aa, wireframe: true,
      transparent: true, opacity: 0.25, depthWrite: false }));
    this.ghost.renderOrder = 3;
    this.scene.add(this.ghost);

    // Contact points and normals: buffers sized for the run's largest contact set.
    const maxContacts = Math.max(1, run.max_contacts);
    this.pointsAttr = new THREE.BufferAttribute(new Float32Array(3 * maxContacts), 3);
    const pg = new THREE.BufferGeometry();
    pg.setAttribute('position', this.pointsAttr);
    this.points = new THREE.Points(pg, new THREE.PointsMaterial({ color: CONTACT_COLOR, size: 6,
      sizeAttenuation: false, depthTest: false }));
    this.points.renderOrder = 5;
    this.scene.add(this.points);
    this.normalsAttr = new THREE.BufferAttribute(new Float32Array(6 * maxContacts), 3);
    const ng = new THREE.BufferGeometry();
    ng.setAttribute('position', this.normalsAttr);
    this.normals = new THREE.LineSegments(ng, new THREE.LineBasicMaterial({ color: NORMAL_COLOR, depthTest: false }));
    this.normals.renderOrder = 5;
    this.scene.add(this.normals);
    this.normalLength = scales.normalLength;

    // Force and torque at G, as arrows scaled by the view's common scales.
    this.scales = scales;
    this.force = new THREE.ArrowHelper(new THREE.Vector3(0, 0, 1), new THREE.Vector3(), 1, FORCE_COLOR);
    this.torque = new THREE.ArrowHelper(new THREE.Vector3(0, 0, 1), new THREE.Vector3(), 1, TORQUE_COLOR);
    for (const a of [this.force, this.torque]) {
      a.renderOrder = 6;
      a.traverse((o) => { if (o.material) { o.material.depthTest = false; o.material.transparent = true; } });
      this.scene.add(a);
    }
    this.tick = 0;
    this.step = -1;
  }

  // Puts the bodies, contacts and arrows where they were at time t (the last tick at or before t).
  setTime(t) {
    const r = this.run;
    const i = lastAtOrBefore(r.ticks.t, t);
    this.tick = i;
    this.god.position.copy(vec3(r.ticks.xs_p, i));
    this.god.quaternion.copy(quat(r.ticks.xs_q, i));
    this.ghost.position.copy(vec3(r.ticks.xh_p, i));
    this.ghost.quaternion.copy(quat(r.ticks.xh_q, i));
    // A non-finite pose is not drawn (a gap), rather than drawn somewhere wrong.
    const finitePose = (o) => [o.position.x, o.position.y, o.position.z, o.quaternion.x, o.quaternion.y,
      o.quaternion.z, o.quaternion.w].every(Number.isFinite);
    this.god.visible = finitePose(this.god);
    this.ghost.visible = finitePose(this.ghost);
    this.god.updateMatrixWorld();

    // Arrows: force and torque (wrench = force, torque) at the god-object's G.
    const w = r.ticks.wrench;
    const G = this.god.position;
    const arrow = (helper, x, y, z, scale, minLength) => {
      const v = new THREE.Vector3(x, y, z);
      const len = v.length() * scale;
      helper.visible = len > minLength;
      if (!helper.visible) return;
      helper.position.copy(G);
      helper.setDirection(v.normalize());
      helper.setLength(len, Math.min(0.3 * len, this.scales.head), Math.min(0.2 * len, 0.6 * this.scales.head));
    };
    arrow(this.force, w[6 * i], w[6 * i + 1], w[6 * i + 2], this.scales.force, 1e-4 * this.scales.size);
    arrow(this.torque, w[6 * i + 3], w[6 * i + 4], w[6 * i + 5], this.scales.torque, 1e-4 * this.scales.size);

    // Contacts: those of the last sim step finished at or before t.
    const s = r.steps.t.length ? lastAtOrBefore(r.steps.t, t) : -1;
    const valid = s >= 0 && r.steps.t[s] <= t;
    this.step = valid ? s : -1;
    let n = 0;
    if (valid) {
      const c = r.contacts;
      const start = r.steps.contact_start[s], end = r.steps.contact_end[s];
      const P = this.pointsAttr.array, N = this.normalsAttr.array, L = this.normalLength;
      for (let k = start; k < end && n < this.run.max_contacts; k++, n++) {
        for (let d = 0; d < 3; d++) {
          P[3 * n + d] = c.point[3 * k + d];
          N[6 * n + d] = c.point[3 * k + d];
          N[6 * n + 3 + d] = c.point[3 * k + d] + L * c.normal[3 * k + d];
        }
      }
    }
    this.numContactsShown = n;
    this.points.geometry.setDrawRange(0, n);
    this.normals.geometry.setDrawRange(0, 2 * n);
    this.pointsAttr.needsUpdate = true;
    this.normalsAttr.needsUpdate = true;
  }
}

// ---------------------------------------------------------------------------------------------
// 2D plots: a static layer drawn once per size, the time cursor drawn over it.

class Plot {
  constructor(container, title, series, view, opts = {}) {
    this.view = view;
    this.series = series;   // [{run, label, color, dash, t, y}]
    this.log = !!opts.log;
    this.stepwise = !!opts.stepwise;
    this.div = document.createElement('div');
    this.div.className = 'plot';
    const h = document.createElement('div');
    h.className = 'plot-title';
    h.textContent = title;
    this.div.appendChild(h);
    this.canvas = document.createElement('canvas');
    this.div.appendChild(this.canvas);
    container.appendChild(this.div);
    this.static = document.createElement('canvas');
    attachScrub(this.canvas, view, () => this.xRange());
  }

  xRange() { return { left: 46, right: this.canvas.clientWidth - 8, t0: this.view.t0, t1: this.view.t1 }; }

  resize() {
    const dpr = window.devicePixelRatio || 1;
    const w = this.canvas.clientWidth, h = this.canvas.clientHeight;
    for (const c of [this.canvas, this.static]) { c.width = Math.max(1, w * dpr); c.height = Math.max(1, h * dpr); }
    this.drawStatic();
    this.drawCursor();
  }

  drawStatic() {
    const dpr = window.devicePixelRatio || 1;
    const ctx = this.static.getContext('2d');
    const w = this.canvas.clientWidth, h = this.canvas.clientHeight;
    ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
    ctx.clearRect(0, 0, w, h);
    const { left, right, t0, t1 } = this.xRange();
    const top = 4, bottom = h - 14;
    const X = (t) => left + (right - left) * (t - t0) / Math.max(1e-12, t1 - t0);
    drawPhases(ctx, this.view.phases, X, top, bottom, t1, false);

    // Y range over every series (positive values only on a log axis).
    let lo = Infinity, hi = -Infinity;
    for (const s of this.series) {
      for (let k = 0; k < s.y.length; k++) {
        const v = s.y[k];
        if (!Number.isFinite(v) || (this.log && v <= 0)) continue;
        if (v < lo) lo = v;
        if (v > hi) hi = v;
      }
    }
    if (!(lo <= hi)) { lo = this.log ? 1 : 0; hi = this.log ? 10 : 1; }
    if (this.log) { lo = Math.log10(lo); hi = Math.log10(hi); }
    if (!this.log) { lo = Math.min(lo, 0); hi = Math.max(hi, 0); }
    if (hi - lo < 1e-12) { hi += 0.5; lo -= 0.5; }
    const pad = 0.06 * (hi - lo);
    lo -= pad; hi += pad;
    const Y = (v) => bottom - (bottom - top) * ((this.log ? Math.log10(v) : v) - lo) / (hi - lo);
    this.Y = Y;

    // Axes, zero line, labels.
    ctx.strokeStyle = '#999'; ctx.lineWidth = 1;
    ctx.beginPath(); ctx.moveTo(left, top); ctx.lineTo(left, bottom); ctx.lineTo(right, bottom); ctx.stroke();
    ctx.fillStyle = '#333'; ctx.font = '10px sans-serif'; ctx.textAlign = 'right'; ctx.textBaseline = 'middle';
    const yl = this.log ? [10 ** hi, 10 ** lo] : [hi, lo];
    ctx.fillText(fmt(yl[0], 2), left - 3, top + 6);
    ctx.fillText(fmt(yl[1], 2), left - 3, bottom - 6);
    if (!this.log && lo < 0 && hi > 0) {
      ctx.strokeStyle = '#bbb'; ctx.beginPath(); ctx.moveTo(left, Y(0)); ctx.lineTo(right, Y(0)); ctx.stroke();
      if (Y(0) - top > 16 && bottom - Y(0) > 16) ctx.fillText('0', left - 3, Y(0));
    }
    ctx.textAlign = 'center'; ctx.textBaseline = 'top';
    ctx.fillText(fmt(t0, 3) + ' s', left, bottom + 2);
    ctx.fillText(fmt(t1, 3) + ' s', right - 12, bottom + 2);

    // Series: min/max per pixel column, so that large runs draw fast and keep their peaks.
    ctx.save();
    ctx.beginPath(); ctx.rect(left, top, right - left, bottom - top); ctx.clip();
    for (const s of this.series) {
      ctx.strokeStyle = s.color; ctx.lineWidth = 1; ctx.setLineDash(s.dash || []);
      ctx.beginPath();
      let col = -1, cmin = 0, cmax = 0, first = true, prevY = null;
      const flush = () => {
        if (col < 0) return;
        if (first) { ctx.moveTo(col, cmin); first = false; } else ctx.lineTo(col, cmin);
        if (cmax !== cmin) ctx.lineTo(col, cmax);
      };
      for (let k = 0; k < s.t.length; k++) {
        const v = s.y[k];
        if (!Number.isFinite(v) || (this.log && v <= 0)) continue;
        const x = Math.round(X(s.t[k])), y = Y(v);
        if (this.stepwise && prevY !== null && x !== col) { flush(); col = x; cmin = cmax = prevY; }
        if (x !== col) { flush(); col = x; cmin = cmax = y; } else { cmin = Math.min(cmin, y); cmax = Math.max(cmax, y); }
        prevY = y;
      }
      flush();
      ctx.stroke();
    }
    ctx.restore();
    ctx.setLineDash([]);
    // Legend.
    ctx.textAlign = 'left'; ctx.textBaseline = 'top';
    let lx = left + 6;
    for (const s of this.series) {
      if (!s.label) continue;
      ctx.fillStyle = s.color;
      ctx.fillText(s.label, lx, top + 1);
      lx += ctx.measureText(s.label).width + 10;
    }
  }

  drawCursor() {
    const dpr = window.devicePixelRatio || 1;
    const ctx = this.canvas.getContext('2d');
    ctx.setTransform(1, 0, 0, 1, 0, 0);
    ctx.clearRect(0, 0, this.canvas.width, this.canvas.height);
    ctx.drawImage(this.static, 0, 0);
    ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
    const { left, right, t0, t1 } = this.xRange();
    const x = left + (right - left) * (this.view.time - t0) / Math.max(1e-12, t1 - t0);
    ctx.strokeStyle = '#000'; ctx.lineWidth = 1;
    ctx.beginPath(); ctx.moveTo(x, 2); ctx.lineTo(x, this.canvas.clientHeight - 14); ctx.stroke();
  }
}

// Phase bands (alternating shades) with their names; used by the plots and the timeline.
function drawPhases(ctx, phases, X, top, bottom, tEnd, labels) {
  phases.forEach((p, i) => {
    if (p.start >= tEnd) return;
    const end = Math.min(tEnd, i + 1 < phases.length ? phases[i + 1].start : tEnd);
    const x0 = X(p.start), x1 = X(end);
    ctx.fillStyle = i % 2 === 0 ? 'rgba(0,0,0,0.06)' : 'rgba(0,0,0,0.0)';
    ctx.fillRect(x0, top, x1 - x0, bottom - top);
    if (labels) {
      ctx.fillStyle = '#222'; ctx.font = '11px sans-serif'; ctx.textAlign = 'center'; ctx.textBaseline = 'middle';
      ctx.fillText(p.name.length === 1 ? `(${p.name})` : p.name, 0.5 * (x0 + x1), 0.5 * (top + bottom));
    }
  });
}

// Click or drag on a canvas moves the time cursor.
function attachScrub(canvas, view, range) {
  let dragging = false;
  const seekAt = (ev) => {
    const r = canvas.getBoundingClientRect();
    const { left, right, t0, t1 } = range();
    const u = (ev.clientX - r.left - left) / Math.max(1, right - left);
    view.seek(t0 + Math.min(1, Math.max(0, u)) * (t1 - t0));
  };
  canvas.addEventListener('pointerdown', (ev) => { dragging = true; canvas.setPointerCapture(ev.pointerId); seekAt(ev); });
  canvas.addEventListener('pointermove', (ev) => { if (dragging) seekAt(ev); });
  canvas.addEventListener('pointerup', () => { dragging = false; });
}

// ---------------------------------------------------------------------------------------------
// The view: state, controls, rendering.

class View {
  constructor(data) {
    this.data = data;
    this.runs = data.runs;
    this.t0 = Math.min(...this.runs.map((r) => r.ticks.t[0]));
    this.t1 = Math.max(...this.runs.map((r) => r.ticks.t[r.ticks.t.length - 1]));
    if (!(this.t1 > this.t0)) this.t1 = this.t0 + 1e-3;
    this.phases = this.runs[0].phases;
    this.time = this.t0;
    this.playing = false;
    this.speed = 1;
    this.framesRendered = 0;
    this.ready = false;

    this.buildDom();
    this.buildScenes();
    this.buildPlots();
    this.resize();
    window.addEventListener('resize', () => this.resize());
    window.addEventListener('keydown', (ev) => {
      if (ev.code === 'Space' && ev.target === document.body) { ev.preventDefault(); this.toggle(); }
    });
    this.seek(this.t0);
    this.lastFrame = null;
    requestAnimationFrame((ts) => this.frame(ts));
  }

  buildDom() {
    this.canvasHost = document.getElementById('view3d');
    this.renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
    this.renderer.setPixelRatio(window.devicePixelRatio || 1);
    this.renderer.setScissorTest(true);
    this.canvasHost.appendChild(this.renderer.domElement);
    this.labels = this.runs.map((r, k) => {
      const d = document.createElement('div');
      d.className = 'run-label';
      d.style.color = '#' + RUN_COLORS[k % RUN_COLORS.length].toString(16).padStart(6, '0');
      this.canvasHost.appendChild(d);
      return d;
    });
    this.playButton = document.getElementById('play');
    this.playButton.addEventListener('click', () => this.toggle());
    this.slider = document.getElementById('scrub');
    this.slider.min = 0; this.slider.max = 10000; this.slider.step = 1;
    this.slider.addEventListener('input', () => {
      this.seek(this.t0 + (this.t1 - this.t0) * Number(this.slider.value) / 10000);
    });
    this.speedSelect = document.getElementById('speed');
    this.speedSelect.addEventListener('change', () => { this.speed = Number(this.speedSelect.value); });
    this.timeLabel = document.getElementById('time');
    this.readout = document.getElementById('readout');
    this.timeline = document.getElementById('timeline');
    attachScrub(this.timeline, this, () => ({ left: 8, right: this.timeline.clientWidth - 8, t0: this.t0, t1: this.t1 }));
  }

  buildScenes() {
    const g = this.data.scene;
    const geometry = {
      obstacles: g.obstacles.map((o) => ({ name: o.name, geometry: meshGeometry(o.V, o.F) })),
      god: meshGeometry(g.god_V, g.god_F),
    };
    // The sphere around the obstacles and every god-object pose: the camera and the arrow scales.
    const box = new THREE.Box3();
    for (const o of geometry.obstacles) box.union(o.geometry.boundingBox);
    geometry.god.computeBoundingSphere();
    const godRadius = geometry.god.boundingSphere.radius + geometry.god.boundingSphere.center.length();
    for (const r of this.runs) {
      const p = r.ticks.xs_p, n = p.length / 3;
      for (let i = 0; i < n; i += Math.max(1, Math.floor(n / 500))) {
        const c = vec3(p, i);
        if (!Number.isFinite(c.x + c.y + c.z)) continue;  // a non-finite pose: not part of the view
        box.expandByPoint(c.clone().addScalar(godRadius));
        box.expandByPoint(c.clone().addScalar(-godRadius));
      }
    }
    const sphere = box.getBoundingSphere(new THREE.Sphere());
    const size = 2 * sphere.radius || 1;
    const maxF = Math.max(1e-12, ...this.runs.map((r) => r.max_force));
    const maxT = Math.max(1e-12, ...this.runs.map((r) => r.max_torque));
    this.scales = { size, force: 0.35 * size / maxF, torque: 0.25 * size / maxT, head: 0.04 * size,
                    normalLength: 0.06 * size };
    this.runScenes = this.runs.map((r, k) => new RunScene(r, k, geometry, this.scales));

    const center = sphere.center;
    const fov = 35;
    this.camera = new THREE.PerspectiveCamera(fov, 1, size * 1e-3, size * 100);
    this.camera.up.set(0, 0, 1);
    const distance = 0.95 * sphere.radius / Math.sin(0.5 * fov * Math.PI / 180);
    this.camera.position.copy(center).add(new THREE.Vector3(0.55, -0.75, 0.38).normalize().multiplyScalar(distance));
    this.controls = new OrbitControls(this.camera, this.renderer.domElement);
    this.controls.target.copy(center);
    this.controls.update();
    this.controls.addEventListener('change', () => this.render());
    document.getElementById('scales').textContent =
      `arrows from G: force ${fmt(0.1 * size / this.scales.force, 3)} N and torque ` +
      `${fmt(0.1 * size / this.scales.torque, 3)} N m per ${fmt(0.1 * size, 2)} (scene units); ` +
      `normals ${fmt(this.scales.normalLength, 2)} long`;
  }

  buildPlots() {
    const host = document.getElementById('plots');
    const dashes = [[], [5, 3], [2, 2], [8, 2, 2, 2]];
    const series = (key, width, comps, labels, scale = 1, stream = 'ticks') => {
      const out = [];
      this.runs.forEach((r, k) => {
        const src = r[stream];
        const n = src.t.length;
        comps.forEach((c, j) => {
          const y = new Float64Array(n);
          for (let i = 0; i < n; i++) y[i] = src[key][width * i + c] * scale;
          out.push({ t: src.t, y, color: comps.length > 1 ? AXIS_COLORS[j] : AXIS_COLORS[(k + 2) % 3],
                     dash: dashes[k % dashes.length],
                     label: (this.runs.length > 1 ? `${r.label} ` : '') + labels[j] });
        });
      });
      return out;
    };
    this.plots = [
      new Plot(host, 'force (N)', series('wrench', 6, [0, 1, 2], ['Fx', 'Fy', 'Fz']), this),
      new Plot(host, 'torque (N m)', series('wrench', 6, [3, 4, 5], ['Tx', 'Ty', 'Tz']), this),
      new Plot(host, 'contacts (per sim step)', series('num_contacts', 1, [0], ['contacts'], 1, 'steps'), this,
        { stepwise: true }),
      new Plot(host, 'force time (us, per haptic tick)', series('force_time', 1, [0], ['force_time'], 1e6), this,
        { log: true }),
      new Plot(host, 'god-object update time (ms, per sim step)',
        series('update_time', 1, [0], ['update_time'], 1e3, 'steps'), this, { log: true }),
    ];
  }

  resize() {
    const w = this.canvasHost.clientWidth, h = this.canvasHost.clientHeight;
    this.renderer.setSize(w, h);
    this.plots.forEach((p) => p.resize());
    const dpr = window.devicePixelRatio || 1;
    this.timeline.width = this.timeline.clientWidth * dpr;
    this.timeline.height = this.timeline.clientHeight * dpr;
    this.labels.forEach((d, k) => { d.style.left = `${(k * w) / this.runs.length + 8}px`; });
    this.render();
    this.drawTimeline();
  }

  render() {
    const w = this.canvasHost.clientWidth, h = this.canvasHost.clientHeight;
    const n = this.runs.length;
    const vw = Math.floor(w / n);
    this.camera.aspect = vw / Math.max(1, h);
    this.camera.updateProjectionMatrix();
    this.runScenes.forEach((rs, k) => {
      this.renderer.setViewport(k * vw, 0, vw, h);
      this.renderer.setScissor(k * vw, 0, vw, h);
      this.renderer.render(rs.scene, this.camera);
    });
    this.framesRendered += 1;
    if (!this.ready) { this.ready = true; document.body.dataset.rendered = '1'; }
  }

  drawTimeline() {
    const c = this.timeline, dpr = window.devicePixelRatio || 1;
    const ctx = c.getContext('2d');
    const w = c.clientWidth, h = c.clientHeight;
    ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
    ctx.clearRect(0, 0, w, h);
    const left = 8, right = w - 8;
    const X = (t) => left + (right - left) * (t - this.t0) / (this.t1 - this.t0);
    ctx.fillStyle = '#fff'; ctx.fillRect(left, 0, right - left, h);
    drawPhases(ctx, this.phases, X, 0, h, this.t1, true);
    // Events (phase starts excluded: the bands show them).
    for (const r of this.runs) {
      for (const e of r.events) {
        if (e.name === 'phase') continue;
        const x = X(e.t);
        ctx.strokeStyle = '#b22'; ctx.beginPath(); ctx.moveTo(x, 0); ctx.lineTo(x, h); ctx.stroke();
        ctx.fillStyle = '#b22'; ctx.font = '10px sans-serif'; ctx.textAlign = 'left'; ctx.textBaseline = 'top';
        const value = e.value === null ? ' (non-finite value)' : '';
        ctx.fillText(e.name.replace('_', ' ') + value, x + 2, 1);
      }
    }
    const x = X(this.time);
    ctx.strokeStyle = '#000'; ctx.lineWidth = 2;
    ctx.beginPath(); ctx.moveTo(x, 0); ctx.lineTo(x, h); ctx.stroke();
    ctx.lineWidth = 1;
  }

  phaseAt(t) {
    let name = '';
    for (const p of this.phases) if (p.start <= t) name = p.name;
    return name;
  }

  updateReadout() {
    const rows = this.runScenes.map((rs) => {
      const r = rs.run, i = rs.tick, w = r.ticks.wrench;
      const F = [w[6 * i], w[6 * i + 1], w[6 * i + 2]];
      const s = rs.step;
      return `<tr><td>${r.label}</td><td>${fmt(r.ticks.t[i], 4)}</td>` +
        `<td>${F.map((v) => fmt(v, 3)).join(', ')}</td><td>${r.ticks.num_contacts[i]}</td>` +
        `<td>${fmt(r.ticks.force_time[i] * 1e6, 3)}</td>` +
        `<td>${s >= 0 ? fmt(r.steps.update_time[s] * 1e3, 3) : '-'}</td></tr>`;
    });
    this.readout.innerHTML = '<tr><th>run</th><th>tick t (s)</th><th>force (N)</th><th>contacts</th>' +
      '<th>force time (us)</th><th>update (ms)</th></tr>' + rows.join('');
    const phase = this.phaseAt(this.time);
    this.timeLabel.textContent = `t = ${this.time.toFixed(3)} s` + (phase ? `, phase ${phase}` : '');
    this.labels.forEach((d, k) => {
      const rs = this.runScenes[k];
      d.textContent = `${rs.run.label}: ${rs.numContactsShown} contact${rs.numContactsShown === 1 ? '' : 's'}`;
    });
  }

  // Moves the time cursor to t (clamped to the runs' span) and redraws at once.
  seek(t) {
    this.time = Math.min(this.t1, Math.max(this.t0, Number(t)));
    this.runScenes.forEach((rs) => rs.setTime(this.time));
    this.slider.value = String(Math.round(10000 * (this.time - this.t0) / (this.t1 - this.t0)));
    this.render();
    this.plots.forEach((p) => p.drawCursor());
    this.drawTimeline();
    this.updateReadout();
    return this.time;
  }

  play() {
    if (this.time >= this.t1) this.seek(this.t0);
    this.playing = true;
    this.playButton.textContent = 'pause';
  }

  pause() { this.playing = false; this.playButton.textContent = 'play'; }
  toggle() { if (this.playing) this.pause(); else this.play(); }

  frame(ts) {
    if (this.playing && this.lastFrame !== null) {
      const t = this.time + this.speed * (ts - this.lastFrame) / 1000;
      this.seek(t);
      if (t >= this.t1) this.pause();
    }
    this.lastFrame = ts;
    requestAnimationFrame((x) => this.frame(x));
  }

  // What is displayed for run k: the tick shown, and the bodies' positions read off the 3D scene.
  state(k = 0) {
    const rs = this.runScenes[k];
    const p = rs.god.position, q = rs.god.quaternion, g = rs.ghost.position;
    return { time: this.time, tick: rs.tick, tick_time: rs.run.ticks.t[rs.tick],
             god_position: [p.x, p.y, p.z], god_quaternion_wxyz: [q.w, q.x, q.y, q.z],
             ghost_position: [g.x, g.y, g.z], contacts_shown: rs.numContactsShown,
             force_arrow_visible: rs.force.visible, god_visible: rs.god.visible, step: rs.step,
             readout: this.readout.textContent };
  }

  // Pixels of the 3D canvas just drawn: how many differ from the background, and how many colours.
  canvasStats() {
    this.render();
    const gl = this.renderer.getContext();
    const w = gl.drawingBufferWidth, h = gl.drawingBufferHeight;
    const px = new Uint8Array(4 * w * h);
    gl.readPixels(0, 0, w, h, gl.RGBA, gl.UNSIGNED_BYTE, px);
    const bg = new THREE.Color(BACKGROUND);
    const br = Math.round(bg.r * 255), bgg = Math.round(bg.g * 255), bb = Math.round(bg.b * 255);
    let different = 0;
    const colours = new Set();
    for (let i = 0; i < px.length; i += 4) {
      if (Math.abs(px[i] - br) + Math.abs(px[i + 1] - bgg) + Math.abs(px[i + 2] - bb) > 6) different++;
      colours.add((px[i] >> 3) << 10 | (px[i + 1] >> 3) << 5 | (px[i + 2] >> 3));
    }
    return { width: w, height: h, non_background: different, colours: colours.size,
             frames_rendered: this.framesRendered };
  }
}

function main() {
  const raw = JSON.parse(document.getElementById('gauss6-data').textContent);
  const data = decodeArrays(raw);
  const view = new View(data);
  // A page opened at a time: PAGE#t=SECONDS (the links to validate's witnesses).
  const at = /(?:^#|&)t=([-+0-9.eE]+)/.exec(window.location.hash);
  if (at && Number.isFinite(Number(at[1]))) view.seek(Number(at[1]));
  window.gauss6View = {
    get ready() { return view.ready; },
    get framesRendered() { return view.framesRendered; },
    get time() { return view.time; },
    get span() { return [view.t0, view.t1]; },
    get numRuns() { return view.runs.length; },
    seek: (t) => view.seek(t),
    play: () => view.play(),
    pause: () => view.pause(),
    state: (k) => view.state(k),
    canvasStats: () => view.canvasStats(),
  };
}

try {
  main();
} catch (e) {
  document.body.dataset.error = String(e && e.stack ? e.stack : e);
  const d = document.getElementById('error');
  if (d) { d.style.display = 'block'; d.textContent = 'The viewer failed: ' + e; }
  throw e;
}
