// rviz in the browser: a three.js scene in the fixed frame, displays fed by the gateway (RosClient),
// every display placed through the tf buffer each frame. See docs/rviz.md.
//
// URL parameters (for links and tests): view=top|orbit, cx, cy (view centre, m), scale (px per m in
// the top view), fixed (fixed frame).

import * as THREE from "three";
import { OrbitControls } from "/static/vendor/three/OrbitControls.js";
import { RosClient } from "/static/lib/rosclient.js";
import { TfBuffer, fromPose, compose, stripSlash, yawOf } from "/static/lib/tf.js";
import { loadMesh } from "/static/rviz/meshes.js";

const params = new URLSearchParams(location.search);
const $ = (id) => document.getElementById(id);

// ------------------------------------------------------------------------------------------------
// the scene

const canvas = $("rv-canvas");
const viewEl = $("rv-view");
// colours are given in sRGB bytes (messages, .rviz files) and drawn as given: no colour management
THREE.ColorManagement.enabled = false;
/** True when WebGL is rasterized on the CPU (SwiftShader, llvmpipe): multisampling costs too much there. */
function softwareGL() {
  const gl = document.createElement("canvas").getContext("webgl");
  const info = gl?.getExtension("WEBGL_debug_renderer_info");
  const name = info ? String(gl.getParameter(info.UNMASKED_RENDERER_WEBGL)) : "";
  gl?.getExtension("WEBGL_lose_context")?.loseContext();
  return /swiftshader|llvmpipe|software/i.test(name);
}
const renderer = new THREE.WebGLRenderer({ canvas, antialias: !softwareGL() });
renderer.setPixelRatio(1);
renderer.outputColorSpace = THREE.LinearSRGBColorSpace;
const scene = new THREE.Scene();
scene.add(new THREE.AmbientLight(0xffffff, 0.6));
const sun = new THREE.DirectionalLight(0xffffff, 0.9);
sun.position.set(3, -2, 10);
scene.add(sun);

const perspective = new THREE.PerspectiveCamera(60, 1, 0.01, 1000);
perspective.up.set(0, 0, 1);
const ortho = new THREE.OrthographicCamera(-1, 1, 1, -1, -100, 100);
ortho.up.set(0, 1, 0);
let camera = perspective;
let controls = null;
let topScale = Number(params.get("scale") || 50); // px per metre at zoom 1
const viewCentre = [Number(params.get("cx") || 0), Number(params.get("cy") || 0)];

function size() {
  const w = viewEl.clientWidth || 800;
  const h = viewEl.clientHeight || 600;
  return [w, h];
}

function setView(mode) {
  if (controls) controls.dispose();
  const [w, h] = size();
  if (mode === "top") {
    camera = ortho;
    ortho.left = -w / 2 / topScale; ortho.right = w / 2 / topScale;
    ortho.top = h / 2 / topScale; ortho.bottom = -h / 2 / topScale;
    ortho.zoom = 1;
    ortho.position.set(viewCentre[0], viewCentre[1], 50);
    ortho.lookAt(viewCentre[0], viewCentre[1], 0);
    ortho.updateProjectionMatrix();
    controls = new OrbitControls(ortho, canvas);
    controls.enableRotate = false;
    controls.screenSpacePanning = true;
    controls.mouseButtons = { LEFT: THREE.MOUSE.PAN, MIDDLE: THREE.MOUSE.DOLLY, RIGHT: THREE.MOUSE.PAN };
    controls.target.set(viewCentre[0], viewCentre[1], 0);
  } else {
    camera = perspective;
    // rviz's default orbit view: distance 10, yaw 45°, pitch 45° around the focal point
    const d = 10, yaw = 0.785, pitch = 0.785;
    perspective.position.set(viewCentre[0] + d * Math.cos(pitch) * Math.cos(yaw), viewCentre[1] + d * Math.cos(pitch) * Math.sin(yaw), d * Math.sin(pitch));
    controls = new OrbitControls(perspective, canvas);
    controls.target.set(viewCentre[0], viewCentre[1], 0);
  }
  controls.enabled = activeTool === "move";
  controls.addEventListener("change", markDirty);
  controls.update();
  dirty = true;
  $("rv-viewmode").value = mode;
  resize();
}

function resize() {
  const [w, h] = size();
  renderer.setSize(w, h, false);
  perspective.aspect = w / h;
  perspective.updateProjectionMatrix();
  const cx = (ortho.left + ortho.right) / 2;
  ortho.left = -w / 2 / topScale; ortho.right = w / 2 / topScale;
  ortho.top = h / 2 / topScale; ortho.bottom = -h / 2 / topScale;
  void cx;
  ortho.updateProjectionMatrix();
  dirty = true;
}
new ResizeObserver(() => resize()).observe(viewEl);

// ------------------------------------------------------------------------------------------------
// ROS

const ros = new RosClient();
const tf = new TfBuffer();
tf.attach(ros);
// the view is drawn when something changed (a message, tf, the camera, the page), at most at the
// frame rate of the file's Global Options (rviz's default 30), and once a second regardless
let dirty = true;
const markDirty = () => { dirty = true; };
tf.listeners.add(markDirty);
let fixedFrame = params.get("fixed") || "map";
let config = null;
const displays = [];
let toolTopics = { "rviz/SetInitialPose": "/initialpose", "rviz/SetGoal": "/move_base_simple/goal", "rviz/PublishPoint": "/clicked_point" };

ros.on("open", () => { $("rv-conn").textContent = "connected"; });
ros.on("close", () => { $("rv-conn").textContent = "disconnected: reconnecting…"; });
ros.on("status", (s) => { if (s.level >= 2) message(`gateway: ${s.message}`); });
ros.on("channels", () => refreshTopicLists());

function message(text, kind = "error") {
  const div = document.createElement("div");
  div.className = kind;
  div.textContent = text;
  $("rv-messages").appendChild(div);
  while ($("rv-messages").children.length > 6) $("rv-messages").firstChild.remove();
}

// ------------------------------------------------------------------------------------------------
// helpers

function rvizColor(text, fallback) {
  const parts = String(text || fallback).split(";").map((s) => Number(s.trim()));
  if (parts.length < 3 || parts.some((v) => Number.isNaN(v))) return rvizColor(fallback, "255; 255; 255");
  return new THREE.Color(parts[0] / 255, parts[1] / 255, parts[2] / 255);
}
function toRviz(hex) {
  const c = new THREE.Color(hex);
  return `${Math.round(c.r * 255)}; ${Math.round(c.g * 255)}; ${Math.round(c.b * 255)}`;
}
function setPose(obj, p) {
  obj.position.set(p.t[0], p.t[1], p.t[2]);
  obj.quaternion.set(p.q[0], p.q[1], p.q[2], p.q[3]);
}
function disposeTree(obj) {
  obj.traverse((o) => {
    o.geometry?.dispose();
    if (o.material) (Array.isArray(o.material) ? o.material : [o.material]).forEach((m) => { m.map?.dispose(); m.dispose(); });
  });
}
function clearGroup(group) {
  for (const child of [...group.children]) { group.remove(child); disposeTree(child); }
}

/** An arrow along +x from the origin: shaft cylinder and head cone (rviz's Arrow shape). */
function arrowMesh(length, shaftDiameter, headDiameter, headLength, color, opacity = 1) {
  const g = new THREE.Group();
  const mat = new THREE.MeshLambertMaterial({ color, transparent: opacity < 1, opacity });
  const shaftLen = Math.max(length - headLength, 0.0001);
  const shaft = new THREE.Mesh(new THREE.CylinderGeometry(shaftDiameter / 2, shaftDiameter / 2, shaftLen, 12), mat);
  shaft.rotation.z = -Math.PI / 2;
  shaft.position.x = shaftLen / 2;
  const head = new THREE.Mesh(new THREE.ConeGeometry(headDiameter / 2, headLength, 16), mat);
  head.rotation.z = -Math.PI / 2;
  head.position.x = shaftLen + headLength / 2;
  g.add(shaft, head);
  return g;
}

const labelLayer = $("rv-labels");
const labels = new Map(); // key -> {el, pos: Vector3 (world)}
function label(key, text, worldPos) {
  let l = labels.get(key);
  if (!l) {
    l = { el: document.createElement("span"), pos: new THREE.Vector3(), used: true };
    l.el.dataset.key = key;
    labelLayer.appendChild(l.el);
    labels.set(key, l);
  }
  if (l.el.textContent !== text) l.el.textContent = text;
  l.pos.copy(worldPos);
  l.used = true;
}
function drawLabels() {
  const [w, h] = size();
  for (const [key, l] of labels) {
    if (!l.used) { l.el.remove(); labels.delete(key); continue; }
    l.used = false;
    const v = l.pos.clone().project(camera);
    const visible = v.z > -1 && v.z < 1;
    l.el.style.display = visible ? "" : "none";
    l.el.style.left = `${((v.x + 1) / 2) * w}px`;
    l.el.style.top = `${((1 - v.y) / 2) * h}px`;
  }
}

// ------------------------------------------------------------------------------------------------
// displays

const MSG_TYPE = {
  "rviz/LaserScan": "sensor_msgs/LaserScan",
  "rviz/PointCloud2": "sensor_msgs/PointCloud2",
  "rviz/Map": "nav_msgs/OccupancyGrid",
  "rviz/Path": "nav_msgs/Path",
  "rviz/Pose": "geometry_msgs/PoseStamped",
  "rviz/PoseArray": "geometry_msgs/PoseArray",
  "rviz/PoseWithCovariance": "geometry_msgs/PoseWithCovarianceStamped",
  "rviz/Odometry": "nav_msgs/Odometry",
  "rviz/Marker": "visualization_msgs/Marker",
  "rviz/MarkerArray": "visualization_msgs/MarkerArray",
  "rviz/Image": "sensor_msgs/Image",
  "rviz/Polygon": "geometry_msgs/PolygonStamped",
};
// rviz's default colours per display
const DEFAULT_COLOR = {
  "rviz/Grid": "160; 160; 164", "rviz/LaserScan": "255; 0; 0", "rviz/PointCloud2": "255; 255; 255",
  "rviz/Path": "25; 255; 0", "rviz/Pose": "255; 25; 0", "rviz/PoseArray": "255; 25; 0",
  "rviz/PoseWithCovariance": "255; 25; 0", "rviz/Odometry": "255; 25; 0", "rviz/Polygon": "25; 255; 0",
};

class Display {
  constructor(cfg) {
    this.cfg = cfg;
    this.group = new THREE.Group();
    scene.add(this.group);
    this.statuses = new Map();
    this.sub = null;
    this.frame = null; // the frame the group's contents are in
    this.stamp = null; // and their time: placed with tf at that stamp, as rviz does
    this.el = null;
    this.received = 0;
  }
  get msgType() { return MSG_TYPE[this.cfg.cls] || null; }
  /** The topic subscribed to (a display with a transport, like Image, may add a suffix). */
  subscribedTopic() { return this.cfg.topic; }
  get color() { return rvizColor(this.cfg.color, DEFAULT_COLOR[this.cfg.cls] || "255; 255; 255"); }
  option(name, fallback) { const v = this.cfg.options?.[name]; return v === undefined ? fallback : v; }

  setStatus(key, level, text) {
    const prev = this.statuses.get(key);
    if (prev && prev.level === level && prev.text === text) return;
    if (level === null) this.statuses.delete(key);
    else this.statuses.set(key, { level, text });
    renderStatus(this);
  }

  start() {
    this.stop();
    dirty = true;
    this.group.visible = this.cfg.enabled;
    if (!this.cfg.enabled) { this.statuses.clear(); renderStatus(this); return; }
    if (this.msgType) {
      const topic = this.subscribedTopic();
      if (!topic) { this.setStatus("Topic", "error", "No topic set"); return; }
      this.setStatus("Topic", "warn", `No messages received on ${topic}`);
      this.sub = ros.subscribe(topic, (msg, info) => {
        this.received++;
        this.lastMsg = msg;
        dirty = true;
        if (this.received === 1) this.setStatus("Topic", "ok", `receiving ${info.type}`);
        try {
          this.onMessage(msg, info);
        } catch (err) {
          this.setStatus("Message", "error", `${topic}: ${err.message}`);
          console.error(err);
        }
      }, { type: this.msgType, onError: (text) => this.setStatus("Topic", "error", text) });
    }
  }
  stop() {
    if (this.sub) { this.sub.unsubscribe(); this.sub = null; }
    this.received = 0;
  }
  destroy() {
    this.stop();
    dirty = true;
    scene.remove(this.group);
    disposeTree(this.group);
  }
  onMessage() {}

  /** Place `obj` at frame `frame` in the fixed frame; false (and a status) when there is no transform. */
  place(obj, frame, key = "Transform", stamp = this.stamp) {
    const T = tf.lookup(fixedFrame, frame, stamp || 0);
    if (!T) {
      obj.visible = false;
      this.setStatus(key, "error", TfBuffer.missing(frame, fixedFrame));
      return false;
    }
    obj.visible = true;
    setPose(obj, T);
    this.setStatus(key, null);
    return true;
  }
  update() {
    if (this.cfg.enabled && this.frame !== null) this.place(this.group, this.frame);
  }
}

class GridDisplay extends Display {
  start() {
    super.start();
    clearGroup(this.group);
    const count = Number(this.option("Plane Cell Count", 10));
    const cell = Number(this.option("Cell Size", 1));
    const grid = new THREE.GridHelper(count * cell, count, this.color, this.color);
    grid.rotation.x = Math.PI / 2; // GridHelper lies in XZ; rviz's grid is in the XY plane
    grid.material.transparent = true;
    grid.material.opacity = Number(this.option("Alpha", 0.5));
    this.group.add(grid);
    this.setStatus("Grid", "ok", `${count}×${count} cells of ${cell} m in the fixed frame`);
  }
  update() { this.group.position.set(0, 0, 0); this.group.quaternion.identity(); }
}

class TFDisplay extends Display {
  constructor(cfg) {
    super(cfg);
    this.axes = new Map();
    this.lines = new THREE.LineSegments(new THREE.BufferGeometry(), new THREE.LineBasicMaterial({ color: 0xffee00 }));
    scene.add(this.lines);
  }
  destroy() { super.destroy(); scene.remove(this.lines); disposeTree(this.lines); }
  update() {
    this.lines.visible = this.cfg.enabled;
    if (!this.cfg.enabled) return;
    const scale = Number(this.option("Marker Scale", 0.3));
    const names = tf.frameNames();
    const pts = [];
    let shown = 0;
    for (const name of names) {
      let ax = this.axes.get(name);
      if (!ax) {
        ax = new THREE.AxesHelper(1);
        this.axes.set(name, ax);
        this.group.add(ax);
      }
      ax.scale.setScalar(scale);
      const T = tf.lookup(fixedFrame, name);
      if (!T) { ax.visible = false; continue; }
      ax.visible = true;
      setPose(ax, T);
      shown++;
      if (this.option("Show Names", true)) label(`tf:${name}`, name, ax.position);
      const parent = tf.frames.get(name)?.parent;
      const P = parent ? tf.lookup(fixedFrame, parent) : null;
      if (P) pts.push(T.t[0], T.t[1], T.t[2], P.t[0], P.t[1], P.t[2]);
    }
    for (const [name, ax] of this.axes) if (!names.includes(name)) { this.group.remove(ax); this.axes.delete(name); }
    this.lines.geometry.setAttribute("position", new THREE.Float32BufferAttribute(pts, 3));
    this.group.position.set(0, 0, 0);
    this.group.quaternion.identity();
    this.setStatus("Frames", shown ? "ok" : "warn", shown ? `${shown} frames` : `no frames connected to [${fixedFrame}]`);
  }
}

class LaserScanDisplay extends Display {
  constructor(cfg) {
    super(cfg);
    this.geometry = new THREE.BufferGeometry();
    this.points = new THREE.Points(this.geometry, new THREE.PointsMaterial({ color: this.color, size: Number(this.option("Size (Pixels)", 3)), sizeAttenuation: false }));
    this.group.add(this.points);
  }
  start() { super.start(); this.points.material.color = this.color; }
  onMessage(m) {
    const n = m.ranges.length;
    const pos = new Float32Array(n * 3);
    let k = 0;
    for (let i = 0; i < n; i++) {
      const r = m.ranges[i];
      if (!(r >= m.range_min && r <= m.range_max)) continue; // NaN, inf and out of range are skipped
      const a = m.angle_min + i * m.angle_increment;
      pos[k++] = r * Math.cos(a); pos[k++] = r * Math.sin(a); pos[k++] = 0;
    }
    this.geometry.setAttribute("position", new THREE.BufferAttribute(pos.subarray(0, k), 3));
    this.geometry.computeBoundingSphere();
    this.frame = m.header.frame_id;
    this.stamp = m.header.stamp;
    this.setStatus("Points", "ok", `${k / 3} points in [${stripSlash(this.frame)}]`);
  }
}

const FIELD_SIZE = { 1: 1, 2: 1, 3: 2, 4: 2, 5: 4, 6: 4, 7: 4, 8: 8 };
class PointCloud2Display extends Display {
  constructor(cfg) {
    super(cfg);
    this.capacity = 0;
    this.geometry = new THREE.BufferGeometry();
    this.material = new THREE.PointsMaterial({ color: this.color, size: Number(this.option("Size (Pixels)", 2)), sizeAttenuation: false });
    this.points = new THREE.Points(this.geometry, this.material);
    this.points.frustumCulled = false;
    this.group.add(this.points);
  }
  onMessage(m) {
    const f = Object.fromEntries(m.fields.map((x) => [x.name, x]));
    if (!f.x || !f.y || !f.z) throw new Error("PointCloud2 has no x, y, z fields");
    if (m.is_bigendian) throw new Error("big-endian PointCloud2 is not supported");
    const n = m.width * m.height;
    const step = m.point_step;
    if (n * step > m.data.byteLength) throw new Error(`data holds ${m.data.byteLength} bytes, ${n} points of ${step} need ${n * step}`);
    if (n > this.capacity) {
      this.capacity = Math.max(n, this.capacity * 2);
      this.pos = new THREE.BufferAttribute(new Float32Array(this.capacity * 3), 3);
      this.col = new THREE.BufferAttribute(new Float32Array(this.capacity * 3), 3);
      this.pos.setUsage(THREE.DynamicDrawUsage);
      this.col.setUsage(THREE.DynamicDrawUsage);
      this.geometry.setAttribute("position", this.pos);
      this.geometry.setAttribute("color", this.col);
    }
    const out = this.pos.array;
    const rgb = f.rgb || f.rgba;
    const floatXYZ = [f.x, f.y, f.z].every((x) => x.datatype === 7 && x.offset % 4 === 0) && step % 4 === 0;
    let k = 0;
    if (floatXYZ) {
      const bytes = m.data.byteOffset % 4 === 0 ? m.data : m.data.slice();
      const fl = new Float32Array(bytes.buffer, bytes.byteOffset, Math.floor(bytes.byteLength / 4));
      const s = step / 4, ox = f.x.offset / 4, oy = f.y.offset / 4, oz = f.z.offset / 4;
      for (let i = 0; i < n; i++) {
        const b = i * s;
        const x = fl[b + ox], y = fl[b + oy], z = fl[b + oz];
        if (x !== x || y !== y || z !== z) continue; // NaN: not a point
        out[k++] = x; out[k++] = y; out[k++] = z;
      }
    } else {
      const dv = new DataView(m.data.buffer, m.data.byteOffset, m.data.byteLength);
      const get = (fld, o) => (fld.datatype === 8 ? dv.getFloat64(o, true) : dv.getFloat32(o, true));
      for (let i = 0; i < n; i++) {
        const b = i * step;
        const x = get(f.x, b + f.x.offset), y = get(f.y, b + f.y.offset), z = get(f.z, b + f.z.offset);
        if (x !== x || y !== y || z !== z) continue;
        out[k++] = x; out[k++] = y; out[k++] = z;
      }
    }
    const useRgb = rgb && this.option("Color Transformer", "RGB8") === "RGB8" && (rgb.datatype === 7 || rgb.datatype === 6);
    this.material.vertexColors = Boolean(useRgb);
    this.material.color = useRgb ? new THREE.Color(1, 1, 1) : this.color;
    this.material.needsUpdate = true;
    if (useRgb) {
      const c = this.col.array;
      let j = 0;
      for (let i = 0; i < n && j < k; i++) {
        const o = i * step + rgb.offset;
        c[j++] = m.data[o + 2] / 255; c[j++] = m.data[o + 1] / 255; c[j++] = m.data[o] / 255;
      }
      this.col.needsUpdate = true;
    }
    this.pos.needsUpdate = true;
    this.geometry.setDrawRange(0, k / 3);
    this.frame = m.header.frame_id;
    this.stamp = m.header.stamp;
    this.setStatus("Points", "ok", `${k / 3} points in [${stripSlash(this.frame)}]`);
  }
}

/** rviz's three palettes for occupancy values (RGBA bytes for 0..100, -1 and the rest). */
function palette(scheme) {
  const p = new Uint8Array(256 * 4);
  for (let v = 0; v < 256; v++) {
    const s = v > 127 ? v - 256 : v; // the int8 value
    let r, g, b, a = 255;
    if (scheme === "costmap") {
      if (s === 0) { r = g = b = 0; a = 0; }
      else if (s >= 1 && s <= 98) { const t = s / 98; r = Math.round(255 * t); g = 0; b = Math.round(255 * (1 - t)); }
      else if (s === 99) { r = 0; g = 255; b = 255; }
      else if (s === 100) { r = 255; g = 0; b = 255; }
      else if (s === -1) { r = 0x70; g = 0x89; b = 0x86; a = 0; }
      else { r = 0; g = 255; b = 0; }
    } else if (scheme === "raw") {
      r = g = b = v;
    } else {
      if (s >= 0 && s <= 100) { r = g = b = Math.round(255 - (255 * s) / 100); }
      else if (s === -1) { r = 0x70; g = 0x89; b = 0x86; }
      else { r = 255; g = 0; b = 255; }
    }
    p.set([r, g, b, a], v * 4);
  }
  return p;
}

class MapDisplay extends Display {
  constructor(cfg) {
    super(cfg);
    this.mesh = null;
    this.updatesSub = null;
  }
  start() {
    super.start();
    if (this.cfg.enabled && this.cfg.topic && this.option("Use Timestamp", false) === false) {
      this.updatesSub = ros.subscribe(`${this.cfg.topic}_updates`, (u) => this.onUpdate(u), { type: "map_msgs/OccupancyGridUpdate" });
    }
  }
  stop() { super.stop(); if (this.updatesSub) { this.updatesSub.unsubscribe(); this.updatesSub = null; } }
  onMessage(m) {
    const { width, height, resolution } = m.info;
    if (width * height !== m.data.length) throw new Error(`map is ${width}×${height} but has ${m.data.length} cells`);
    this.pal = palette(String(this.option("Color Scheme", "map")));
    this.width = width; this.height = height;
    this.rgba = new Uint8Array(width * height * 4);
    this.paint(m.data, 0, 0, width, height);
    clearGroup(this.group);
    this.texture = new THREE.DataTexture(this.rgba, width, height, THREE.RGBAFormat);
    this.texture.magFilter = THREE.NearestFilter;
    this.texture.minFilter = THREE.NearestFilter;
    this.texture.needsUpdate = true;
    const alpha = Number(this.option("Alpha", 0.7));
    const mat = new THREE.MeshBasicMaterial({ map: this.texture, transparent: true, opacity: alpha, side: THREE.DoubleSide, depthWrite: alpha >= 1 });
    const plane = new THREE.Mesh(new THREE.PlaneGeometry(width * resolution, height * resolution), mat);
    // the plane's centre, in the origin's frame; then the origin pose in the header frame
    const origin = new THREE.Group();
    setPose(origin, fromPose(m.info.origin));
    plane.position.set((width * resolution) / 2, (height * resolution) / 2, this.option("Draw Behind", false) ? -0.01 : 0);
    plane.renderOrder = -1;
    origin.add(plane);
    this.group.add(origin);
    this.frame = m.header.frame_id;
    this.stamp = m.header.stamp;
    this.setStatus("Map", "ok", `${width}×${height} at ${resolution.toFixed(3)} m/cell`);
  }
  paint(data, x0, y0, w, h) {
    const pal = this.pal, out = this.rgba, W = this.width;
    for (let y = 0; y < h; y++) {
      for (let x = 0; x < w; x++) {
        const v = data[y * w + x] & 255;
        const o = ((y0 + y) * W + x0 + x) * 4;
        out[o] = pal[v * 4]; out[o + 1] = pal[v * 4 + 1]; out[o + 2] = pal[v * 4 + 2]; out[o + 3] = pal[v * 4 + 3];
      }
    }
  }
  onUpdate(u) {
    if (!this.rgba || u.x + u.width > this.width || u.y + u.height > this.height) return;
    this.paint(u.data, u.x, u.y, u.width, u.height);
    this.texture.needsUpdate = true;
  }
}

class PathDisplay extends Display {
  onMessage(m) {
    clearGroup(this.group);
    const pts = m.poses.map((p) => new THREE.Vector3(p.pose.position.x, p.pose.position.y, p.pose.position.z));
    const line = new THREE.Line(new THREE.BufferGeometry().setFromPoints(pts), new THREE.LineBasicMaterial({ color: this.color, transparent: true, opacity: Number(this.option("Alpha", 1)) }));
    this.group.add(line);
    this.frame = m.header.frame_id;
    this.stamp = m.header.stamp;
    this.setStatus("Path", "ok", `${m.poses.length} poses`);
  }
}

class PoseDisplay extends Display {
  onMessage(m) {
    clearGroup(this.group);
    const a = arrowMesh(Number(this.option("Shaft Length", 1)) + Number(this.option("Head Length", 0.3)), Number(this.option("Shaft Radius", 0.05)) * 2, Number(this.option("Head Radius", 0.1)) * 2, Number(this.option("Head Length", 0.3)), this.color, Number(this.option("Alpha", 1)));
    setPose(a, fromPose(m.pose));
    this.group.add(a);
    this.frame = m.header.frame_id;
    this.stamp = m.header.stamp;
  }
}

/** Arrows as line segments (cheap for thousands: amcl's particles). */
function arrowSegments(poses, length, color) {
  const pts = new Float32Array(poses.length * 18);
  let k = 0;
  for (const p of poses) {
    const T = fromPose(p);
    const yaw = yawOf(T.q);
    const c = Math.cos(yaw), s = Math.sin(yaw);
    const [x, y, z] = T.t;
    const tx = x + length * c, ty = y + length * s;
    const h = length * 0.3;
    const seg = [x, y, z, tx, ty, z,
      tx, ty, z, tx - h * Math.cos(yaw - 0.5), ty - h * Math.sin(yaw - 0.5), z,
      tx, ty, z, tx - h * Math.cos(yaw + 0.5), ty - h * Math.sin(yaw + 0.5), z];
    pts.set(seg, k);
    k += 18;
  }
  const g = new THREE.BufferGeometry();
  g.setAttribute("position", new THREE.BufferAttribute(pts, 3));
  return new THREE.LineSegments(g, new THREE.LineBasicMaterial({ color }));
}

class PoseArrayDisplay extends Display {
  onMessage(m) {
    clearGroup(this.group);
    this.group.add(arrowSegments(m.poses, Number(this.option("Arrow Length", 0.3)), this.color));
    this.frame = m.header.frame_id;
    this.stamp = m.header.stamp;
    this.setStatus("Poses", "ok", `${m.poses.length} poses`);
  }
}

/** The 95% ellipse of a 2D position covariance (x, y) as a line loop in the pose's parent frame. */
function covarianceEllipse(cov, color) {
  const a = cov[0], b = cov[1], c = cov[7];
  const mean = (a + c) / 2, d = Math.sqrt(((a - c) / 2) ** 2 + b * b);
  const l1 = Math.max(mean + d, 0), l2 = Math.max(mean - d, 0);
  const angle = 0.5 * Math.atan2(2 * b, a - c);
  const k = Math.sqrt(5.991); // chi-square, 2 dof, 95%
  const r1 = k * Math.sqrt(l1), r2 = k * Math.sqrt(l2);
  const pts = [];
  for (let i = 0; i <= 48; i++) {
    const t = (i / 48) * 2 * Math.PI;
    const x = r1 * Math.cos(t), y = r2 * Math.sin(t);
    pts.push(new THREE.Vector3(x * Math.cos(angle) - y * Math.sin(angle), x * Math.sin(angle) + y * Math.cos(angle), 0));
  }
  const line = new THREE.Line(new THREE.BufferGeometry().setFromPoints(pts), new THREE.LineBasicMaterial({ color }));
  line.userData.radii = [r1, r2];
  return line;
}

class PoseWithCovarianceDisplay extends Display {
  onMessage(m) {
    clearGroup(this.group);
    const T = fromPose(m.pose.pose);
    const a = arrowMesh(1.3, 0.1, 0.2, 0.3, this.color, Number(this.option("Alpha", 1)));
    setPose(a, T);
    const e = covarianceEllipse(m.pose.covariance, 0xff66ff);
    e.position.set(T.t[0], T.t[1], T.t[2] + 0.01);
    this.group.add(a, e);
    this.frame = m.header.frame_id;
    this.stamp = m.header.stamp;
    const [r1, r2] = e.userData.radii;
    this.setStatus("Covariance", "ok", `95% ellipse ${(2 * r1).toFixed(2)} × ${(2 * r2).toFixed(2)} m`);
  }
}

class OdometryDisplay extends Display {
  constructor(cfg) { super(cfg); this.kept = []; this.last = null; }
  onMessage(m) {
    // rviz keeps arrows where the robot was, in the fixed frame at the time they arrived
    const T = tf.lookup(fixedFrame, m.header.frame_id, m.header.stamp);
    if (!T) { this.setStatus("Transform", "error", TfBuffer.missing(m.header.frame_id, fixedFrame)); return; }
    this.setStatus("Transform", null);
    const P = compose(T, fromPose(m.pose.pose));
    const tol = Number(this.option("Position Tolerance", 0.1));
    const atol = Number(this.option("Angle Tolerance", 0.1));
    if (this.last) {
      const dd = Math.hypot(P.t[0] - this.last.t[0], P.t[1] - this.last.t[1], P.t[2] - this.last.t[2]);
      const da = Math.abs(yawOf(P.q) - yawOf(this.last.q));
      if (dd < tol && da < atol) return;
    }
    this.last = P;
    const a = arrowMesh(0.4, 0.03, 0.08, 0.12, this.color);
    setPose(a, P);
    this.group.add(a);
    this.kept.push(a);
    const keep = Number(this.option("Keep", 100));
    while (this.kept.length > keep) { const old = this.kept.shift(); this.group.remove(old); disposeTree(old); }
    this.setStatus("Arrows", "ok", `${this.kept.length} arrows`);
  }
  update() { this.group.position.set(0, 0, 0); this.group.quaternion.identity(); }
}

class PolygonDisplay extends Display {
  onMessage(m) {
    clearGroup(this.group);
    const pts = m.polygon.points.map((p) => new THREE.Vector3(p.x, p.y, p.z));
    const line = new THREE.LineLoop(new THREE.BufferGeometry().setFromPoints(pts), new THREE.LineBasicMaterial({ color: this.color }));
    this.group.add(line);
    this.frame = m.header.frame_id;
    this.stamp = m.header.stamp;
  }
}

// -- markers

const MARKER_TYPES = ["ARROW", "CUBE", "SPHERE", "CYLINDER", "LINE_STRIP", "LINE_LIST", "CUBE_LIST", "SPHERE_LIST", "POINTS", "TEXT_VIEW_FACING", "MESH_RESOURCE", "TRIANGLE_LIST"];

function markerObject(m) {
  const c = m.color;
  const color = new THREE.Color(c.r, c.g, c.b);
  const opacity = c.a;
  const transparent = opacity < 1;
  const s = m.scale;
  const perPoint = m.colors && m.colors.length === m.points.length && m.points.length > 0;
  const pointColors = () => {
    const arr = new Float32Array(m.points.length * 3);
    m.colors.forEach((q, i) => arr.set([q.r, q.g, q.b], i * 3));
    return new THREE.BufferAttribute(arr, 3);
  };
  const pointsGeom = () => {
    const g = new THREE.BufferGeometry().setFromPoints(m.points.map((p) => new THREE.Vector3(p.x, p.y, p.z)));
    if (perPoint) g.setAttribute("color", pointColors());
    return g;
  };
  const lambert = () => new THREE.MeshLambertMaterial({ color, transparent, opacity });
  switch (m.type) {
    case 0: { // ARROW: pose + scale (length, width, height), or two points
      if (m.points.length >= 2) {
        const [p, q] = m.points;
        const dir = new THREE.Vector3(q.x - p.x, q.y - p.y, q.z - p.z);
        const len = dir.length();
        const head = s.z > 0 ? s.z : 0.23 * len;
        const g = arrowMesh(len, s.x, s.y, Math.min(head, len), color, opacity);
        const wrap = new THREE.Group();
        wrap.add(g);
        wrap.position.set(p.x, p.y, p.z);
        wrap.quaternion.setFromUnitVectors(new THREE.Vector3(1, 0, 0), dir.normalize());
        return wrap;
      }
      const g = arrowMesh(s.x, s.y, s.z, 0.23 * s.x, color, opacity);
      return g;
    }
    case 1: return new THREE.Mesh(new THREE.BoxGeometry(s.x, s.y, s.z), lambert());
    case 2: { const o = new THREE.Mesh(new THREE.SphereGeometry(0.5, 20, 14), lambert()); o.scale.set(s.x, s.y, s.z); return o; }
    case 3: { const o = new THREE.Mesh(new THREE.CylinderGeometry(0.5, 0.5, 1, 24), lambert()); o.rotation.x = Math.PI / 2; const w = new THREE.Group(); w.add(o); o.scale.set(s.x, s.z, s.y); return w; }
    case 4: return new THREE.Line(pointsGeom(), new THREE.LineBasicMaterial({ color: perPoint ? 0xffffff : color, vertexColors: perPoint, transparent, opacity }));
    case 5: return new THREE.LineSegments(pointsGeom(), new THREE.LineBasicMaterial({ color: perPoint ? 0xffffff : color, vertexColors: perPoint, transparent, opacity }));
    case 6: case 7: {
      const geom = m.type === 6 ? new THREE.BoxGeometry(s.x, s.y, s.z) : new THREE.SphereGeometry(0.5, 12, 8);
      if (m.type === 7) geom.scale(s.x, s.y, s.z);
      const inst = new THREE.InstancedMesh(geom, new THREE.MeshLambertMaterial({ color: perPoint ? 0xffffff : color, transparent, opacity }), m.points.length);
      const mat = new THREE.Matrix4();
      m.points.forEach((p, i) => {
        inst.setMatrixAt(i, mat.makeTranslation(p.x, p.y, p.z));
        if (perPoint) inst.setColorAt(i, new THREE.Color(m.colors[i].r, m.colors[i].g, m.colors[i].b));
      });
      return inst;
    }
    case 8: return new THREE.Points(pointsGeom(), new THREE.PointsMaterial({ color: perPoint ? 0xffffff : color, vertexColors: perPoint, size: s.x, transparent, opacity }));
    case 9: { const g = new THREE.Group(); g.userData.text = m.text; return g; }
    case 11: {
      const g = pointsGeom();
      g.computeVertexNormals();
      return new THREE.Mesh(g, new THREE.MeshLambertMaterial({ color: perPoint ? 0xffffff : color, vertexColors: perPoint, transparent, opacity, side: THREE.DoubleSide }));
    }
    default:
      throw new Error(`marker type ${MARKER_TYPES[m.type] || m.type} is not shown`);
  }
}

class MarkerDisplay extends Display {
  constructor(cfg) { super(cfg); this.markers = new Map(); }
  onMessage(m) {
    const list = this.cfg.cls === "rviz/MarkerArray" ? m.markers : [m];
    for (const mk of list) this.apply(mk);
    this.setStatus("Markers", "ok", `${this.markers.size} markers`);
  }
  apply(m) {
    const key = `${m.ns}/${m.id}`;
    if (m.action === 3) { // DELETEALL
      for (const k of [...this.markers.keys()]) this.remove(k);
      return;
    }
    this.remove(key);
    if (m.action === 2) return;
    let obj;
    try {
      obj = markerObject(m);
    } catch (err) {
      this.setStatus(`Marker ${key}`, "error", err.message);
      return;
    }
    this.setStatus(`Marker ${key}`, null);
    const holder = new THREE.Group();
    const inner = new THREE.Group();
    setPose(inner, fromPose(m.pose));
    inner.add(obj);
    holder.add(inner);
    this.group.add(holder);
    const life = m.lifetime.secs + m.lifetime.nsecs / 1e9;
    this.markers.set(key, { holder, inner, text: m.type === 9 ? m.text : null, frame: m.header.frame_id, stamp: m.frame_locked ? 0 : m.header.stamp, expires: life > 0 ? performance.now() + life * 1000 : null });
  }
  remove(key) {
    const e = this.markers.get(key);
    if (!e) return;
    this.group.remove(e.holder);
    disposeTree(e.holder);
    this.markers.delete(key);
  }
  update() {
    this.group.position.set(0, 0, 0);
    this.group.quaternion.identity();
    if (!this.cfg.enabled) return;
    const now = performance.now();
    const wp = new THREE.Vector3();
    for (const [key, e] of this.markers) {
      if (e.expires !== null && now > e.expires) { this.remove(key); continue; }
      if (this.place(e.holder, e.frame, `Transform ${stripSlash(e.frame)}`, e.stamp) && e.text !== null) {
        e.inner.getWorldPosition(wp);
        label(`mk:${this.cfg.name}:${key}`, e.text, wp);
      }
    }
  }
}

class RobotModelDisplay extends Display {
  constructor(cfg) { super(cfg); this.links = new Map(); this.joints = new Map(); }
  async start() {
    super.start();
    clearGroup(this.group);
    this.links.clear();
    this.joints.clear();
    if (!this.cfg.enabled) return;
    const param = this.cfg.topic || "robot_description";
    const name = param.startsWith("/") ? param : `/${param}`;
    let values;
    try {
      values = await ros.getParameters([name]);
    } catch (err) {
      this.setStatus("URDF", "error", `cannot read ${name}: ${err.message}`);
      return;
    }
    const text = values[name];
    if (typeof text !== "string" || !text.trim()) {
      this.setStatus("URDF", "error", `Parameter [${param}] does not exist, and was not found by searchParam()`);
      return;
    }
    try {
      this.load(text);
      dirty = true;
      this.setStatus("URDF", "ok", `${this.links.size} links from ${name}`);
    } catch (err) {
      this.setStatus("URDF", "error", `URDF in ${name}: ${err.message}`);
    }
  }
  load(text) {
    const doc = new DOMParser().parseFromString(text, "application/xml");
    const err = doc.querySelector("parsererror");
    if (err) throw new Error(err.textContent.split("\n")[0]);
    const xyz = (el, attr, d = [0, 0, 0]) => (el && el.getAttribute(attr) ? el.getAttribute(attr).trim().split(/\s+/).map(Number) : d);
    const originOf = (el) => {
      const o = el?.querySelector(":scope > origin");
      const [r, p, y] = xyz(o, "rpy");
      const q = new THREE.Quaternion().setFromEuler(new THREE.Euler(r, p, y, "ZYX"));
      return { t: xyz(o, "xyz"), q: [q.x, q.y, q.z, q.w] };
    };
    const alpha = Number(this.option("Alpha", 1));
    // materials named at the top level, used by name in visuals (<material name="blue"/>)
    const named = new Map();
    for (const m of doc.querySelectorAll("robot > material")) {
      const rgba = m.querySelector("color")?.getAttribute("rgba");
      if (rgba) named.set(m.getAttribute("name"), rgba);
    }
    const meshes = [];
    for (const link of doc.querySelectorAll("robot > link")) {
      const g = new THREE.Group();
      const shapes = link.querySelectorAll(":scope > visual");
      const list = shapes.length ? shapes : link.querySelectorAll(":scope > collision");
      for (const v of list) {
        const geo = v.querySelector("geometry");
        let mesh = null;
        const matEl = v.querySelector(":scope > material");
        const rgba = matEl?.querySelector("color")?.getAttribute("rgba") || named.get(matEl?.getAttribute("name"));
        const col = rgba ? rgba.trim().split(/\s+/).map(Number) : [0.8, 0.8, 0.8, 1];
        const mat = new THREE.MeshLambertMaterial({ color: new THREE.Color(col[0], col[1], col[2]), transparent: alpha < 1, opacity: alpha });
        const box = geo?.querySelector("box"), cyl = geo?.querySelector("cylinder"), sph = geo?.querySelector("sphere");
        if (box) { const [x, y, z] = xyz(box, "size", [0.1, 0.1, 0.1]); mesh = new THREE.Mesh(new THREE.BoxGeometry(x, y, z), mat); }
        else if (cyl) {
          const r = Number(cyl.getAttribute("radius")), l = Number(cyl.getAttribute("length"));
          const c = new THREE.Mesh(new THREE.CylinderGeometry(r, r, l, 24), mat);
          c.rotation.x = Math.PI / 2; // URDF cylinders run along z, three's along y
          mesh = new THREE.Group(); mesh.add(c);
        } else if (sph) mesh = new THREE.Mesh(new THREE.SphereGeometry(Number(sph.getAttribute("radius")), 20, 14), mat);
        else if (geo?.querySelector("mesh")) {
          // filled in when the file arrives; the link is placed meanwhile
          const m = geo.querySelector("mesh");
          mesh = new THREE.Group();
          mesh.scale.set(...xyz(m, "scale", [1, 1, 1]));
          meshes.push({ uri: (m.getAttribute("filename") || "").trim(), holder: mesh, mat });
        }
        if (!mesh) continue;
        const wrap = new THREE.Group();
        setPose(wrap, originOf(v));
        wrap.add(mesh);
        g.add(wrap);
      }
      this.group.add(g);
      this.links.set(link.getAttribute("name"), g);
    }
    for (const j of doc.querySelectorAll("robot > joint")) {
      const child = j.querySelector("child")?.getAttribute("link");
      const parent = j.querySelector("parent")?.getAttribute("link");
      if (child && parent) this.joints.set(child, { parent, origin: originOf(j) });
    }
    this.loadMeshes(meshes);
  }
  /** Fetch the visuals' mesh files; the status says how many are drawn and names the first failure. */
  async loadMeshes(meshes) {
    this.setStatus("Meshes", null);
    if (!meshes.length) return;
    const generation = (this.generation = (this.generation || 0) + 1);
    this.setStatus("Meshes", "warn", `loading ${meshes.length} meshes`);
    const results = await Promise.allSettled(meshes.map(async ({ uri, holder, mat }) => {
      if (!uri) throw new Error("a <mesh> without a filename");
      holder.add(await loadMesh(uri, mat));
      dirty = true;
    }));
    if (generation !== this.generation) return; // reloaded meanwhile
    const failed = results.map((r, i) => [r, meshes[i].uri]).filter(([r]) => r.status === "rejected");
    if (failed.length) {
      const [r, uri] = failed[0];
      this.setStatus("Meshes", "error", `${failed.length} of ${meshes.length} meshes not drawn: ${uri}: ${r.reason.message}`);
    } else this.setStatus("Meshes", "ok", `${meshes.length} meshes`);
  }
  /** A link's pose in the fixed frame: from tf, else through its joint from its parent's. */
  linkPose(name, depth = 0) {
    const T = tf.lookup(fixedFrame, name);
    if (T) return T;
    const j = this.joints.get(name);
    if (!j || depth > 50) return null;
    const P = this.linkPose(j.parent, depth + 1);
    return P ? compose(P, j.origin) : null;
  }
  update() {
    this.group.position.set(0, 0, 0);
    this.group.quaternion.identity();
    if (!this.cfg.enabled || !this.links.size) return;
    const missing = [];
    for (const [name, g] of this.links) {
      const P = this.linkPose(name);
      if (!P) { g.visible = false; missing.push(name); continue; }
      g.visible = true;
      setPose(g, P);
    }
    if (missing.length) this.setStatus("Transform", "error", `${TfBuffer.missing(missing[0], fixedFrame)}${missing.length > 1 ? ` (and ${missing.length - 1} more links)` : ""}`);
    else this.setStatus("Transform", null);
  }
}

class ImageDisplay extends Display {
  constructor(cfg) {
    super(cfg);
    this.figure = document.createElement("figure");
    this.caption = document.createElement("figcaption");
    this.canvas = document.createElement("canvas");
    this.canvas.width = 320; this.canvas.height = 240;
    this.figure.append(this.caption, this.canvas);
    $("rv-images").appendChild(this.figure);
  }
  // rviz's "Transport Hint": compressed subscribes to <Image Topic>/compressed (sensor_msgs/CompressedImage);
  // an Image Topic that itself ends in /compressed is taken as that transport too
  get compressed() { return this.option("Transport Hint", "raw") === "compressed" || /\/compressed$/.test(this.cfg.topic || ""); }
  get msgType() { return this.compressed ? "sensor_msgs/CompressedImage" : "sensor_msgs/Image"; }
  subscribedTopic() {
    const t = this.cfg.topic;
    return t && this.compressed && !/\/compressed$/.test(t) ? `${t}/compressed` : t;
  }
  start() { this.pending = null; this.decoding = false; super.start(); this.figure.style.display = this.cfg.enabled ? "" : "none"; this.caption.textContent = `${this.cfg.name}: ${this.subscribedTopic()}`; }
  destroy() { super.destroy(); this.figure.remove(); }
  onMessage(m, info) {
    if (info?.type === "sensor_msgs/CompressedImage" || m.format !== undefined) { this.onCompressed(m); return; }
    this.onRaw(m);
  }
  /** Decode jpeg/png in the browser; while one frame decodes, only the newest waiting frame is kept. */
  onCompressed(m) {
    this.pending = m;
    if (this.decoding) return;
    this.decoding = true;
    const next = async () => {
      while (this.pending) {
        const msg = this.pending;
        this.pending = null;
        const mime = /png/i.test(msg.format) ? "image/png" : "image/jpeg";
        let bitmap;
        try {
          bitmap = await createImageBitmap(new Blob([msg.data], { type: mime }));
        } catch {
          this.setStatus("Message", "error", `cannot decode a CompressedImage of format '${msg.format}' (${msg.data.length} bytes)`);
          continue;
        }
        if (this.canvas.width !== bitmap.width || this.canvas.height !== bitmap.height) { this.canvas.width = bitmap.width; this.canvas.height = bitmap.height; }
        this.canvas.getContext("2d").drawImage(bitmap, 0, 0);
        this.setStatus("Message", null);
        this.setStatus("Image", "ok", `${bitmap.width}×${bitmap.height} ${msg.format}`);
        bitmap.close();
        dirty = true;
      }
      this.decoding = false;
    };
    next();
  }
  onRaw(m) {
    const { width: w, height: h, encoding, step, data } = m;
    if (!w || !h) throw new Error("empty image");
    if (step * h > data.length) throw new Error(`image data holds ${data.length} bytes; ${h} rows of ${step} need ${step * h}`);
    if (this.canvas.width !== w || this.canvas.height !== h) { this.canvas.width = w; this.canvas.height = h; }
    const ctx = this.canvas.getContext("2d");
    const img = ctx.createImageData(w, h);
    const o = img.data;
    const enc = encoding.toLowerCase();
    const dv = new DataView(data.buffer, data.byteOffset, data.byteLength);
    let depthMax = 0;
    if (enc === "16uc1" || enc === "mono16" || enc === "32fc1") {
      for (let y = 0; y < h; y++) for (let x = 0; x < w; x++) {
        const v = enc === "32fc1" ? dv.getFloat32(y * step + x * 4, !m.is_bigendian) : dv.getUint16(y * step + x * 2, !m.is_bigendian);
        if (v > depthMax && Number.isFinite(v)) depthMax = v;
      }
    }
    // one loop per encoding (no per-pixel dispatch): a 640x480 frame is a few milliseconds
    const le = !m.is_bigendian;
    const colour = { rgb8: [3, 0, 1, 2], bgr8: [3, 2, 1, 0], rgba8: [4, 0, 1, 2], bgra8: [4, 2, 1, 0] }[enc];
    if (colour) {
      const [n, ri, gi, bi] = colour;
      for (let y = 0; y < h; y++) {
        let i = y * step, p = y * w * 4;
        for (let x = 0; x < w; x++, i += n, p += 4) { o[p] = data[i + ri]; o[p + 1] = data[i + gi]; o[p + 2] = data[i + bi]; o[p + 3] = 255; }
      }
    } else if (enc === "mono8" || enc === "8uc1") {
      for (let y = 0; y < h; y++) {
        let i = y * step, p = y * w * 4;
        for (let x = 0; x < w; x++, i++, p += 4) { const v = data[i]; o[p] = v; o[p + 1] = v; o[p + 2] = v; o[p + 3] = 255; }
      }
    } else if (enc === "16uc1" || enc === "mono16" || enc === "32fc1") {
      const float = enc === "32fc1";
      for (let y = 0; y < h; y++) {
        for (let x = 0; x < w; x++) {
          const v = float ? dv.getFloat32(y * step + x * 4, le) : dv.getUint16(y * step + x * 2, le);
          const g = Number.isFinite(v) && depthMax ? Math.round((255 * v) / depthMax) : 0;
          const p = (y * w + x) * 4;
          o[p] = g; o[p + 1] = g; o[p + 2] = g; o[p + 3] = 255;
        }
      }
    } else {
      throw new Error(`image encoding ${encoding} is not shown`);
    }
    ctx.putImageData(img, 0, 0);
    this.setStatus("Image", "ok", `${w}×${h} ${encoding}`);
  }
}

const DISPLAY_CLASSES = {
  "rviz/Grid": GridDisplay, "rviz/TF": TFDisplay, "rviz/RobotModel": RobotModelDisplay,
  "rviz/LaserScan": LaserScanDisplay, "rviz/PointCloud2": PointCloud2Display, "rviz/Map": MapDisplay,
  "rviz/Path": PathDisplay, "rviz/Pose": PoseDisplay, "rviz/PoseArray": PoseArrayDisplay,
  "rviz/PoseWithCovariance": PoseWithCovarianceDisplay, "rviz/Odometry": OdometryDisplay,
  "rviz/Marker": MarkerDisplay, "rviz/MarkerArray": MarkerDisplay, "rviz/Image": ImageDisplay,
  "rviz/Polygon": PolygonDisplay,
};

// ------------------------------------------------------------------------------------------------
// the display list

function renderStatus(d) {
  if (!d.el) return;
  const box = d.el.querySelector(".rv-status");
  box.replaceChildren(...[...d.statuses].map(([key, s]) => {
    const div = document.createElement("div");
    div.dataset.level = s.level;
    div.dataset.key = key;
    div.textContent = `${key}: ${s.text}`;
    return div;
  }));
  const worst = [...d.statuses.values()].some((s) => s.level === "error") ? "error" : [...d.statuses.values()].some((s) => s.level === "warn") ? "warn" : "ok";
  d.el.dataset.level = worst;
}

function addDisplay(cfg) {
  const Cls = DISPLAY_CLASSES[cfg.cls];
  const d = new Cls({ options: {}, ...cfg });
  displays.push(d);
  const el = document.createElement("div");
  el.className = "rv-display";
  el.dataset.cls = cfg.cls;
  el.dataset.name = cfg.name;
  const topicKey = cfg.cls === "rviz/RobotModel" ? "Robot Description" : MSG_TYPE[cfg.cls] ? "Topic" : null;
  el.innerHTML = `<header><input type="checkbox" class="enabled"><input class="name"><span class="cls"></span><button class="remove" title="remove">✕</button></header>
    ${topicKey ? `<div class="row"><span>${topicKey}</span><input type="text" class="topic" list="rv-topics-${displays.length}"><datalist id="rv-topics-${displays.length}"></datalist></div>` : ""}
    ${DEFAULT_COLOR[cfg.cls] ? `<div class="row"><span>Color</span><input type="color" class="color"></div>` : ""}
    <div class="rv-status"></div>`;
  el.querySelector(".enabled").checked = cfg.enabled;
  el.querySelector(".name").value = cfg.name;
  el.querySelector(".cls").textContent = cfg.cls.replace("rviz/", "");
  const topicInput = el.querySelector(".topic");
  if (topicInput) {
    topicInput.value = d.cfg.topic || "";
    topicInput.addEventListener("change", () => { d.cfg.topic = topicInput.value.trim(); d.start(); });
  }
  const colorInput = el.querySelector(".color");
  if (colorInput) {
    colorInput.value = `#${d.color.getHexString()}`;
    colorInput.addEventListener("input", () => { d.cfg.color = toRviz(colorInput.value); d.start(); if (d.lastMsg) d.onMessage(d.lastMsg); });
  }
  el.querySelector(".enabled").addEventListener("change", (ev) => { d.cfg.enabled = ev.target.checked; d.start(); });
  el.querySelector(".name").addEventListener("change", (ev) => { d.cfg.name = ev.target.value; el.dataset.name = d.cfg.name; });
  el.querySelector(".remove").addEventListener("click", () => {
    d.destroy();
    displays.splice(displays.indexOf(d), 1);
    el.remove();
  });
  d.el = el;
  $("rv-displays").appendChild(el);
  d.start();
  refreshTopicLists();
  return d;
}

function refreshTopicLists() {
  const topics = ros.topics();
  for (const d of displays) {
    const list = d.el?.querySelector("datalist");
    if (!list) continue;
    const want = d.msgType;
    const names = topics.filter((t) => !want || t.type === want || (d.cfg.cls === "rviz/Map" && t.type === "nav_msgs/OccupancyGrid")).map((t) => t.name);
    if (list.dataset.names === names.join()) continue;
    list.dataset.names = names.join();
    list.replaceChildren(...names.map((n) => Object.assign(document.createElement("option"), { value: n })));
  }
}

function setFixedFrame(frame) {
  fixedFrame = stripSlash(frame) || "map";
  dirty = true;
  $("rv-fixed").value = fixedFrame;
  for (const d of displays) if (d instanceof OdometryDisplay) { d.start(); clearGroup(d.group); d.kept = []; d.last = null; }
}
$("rv-fixed").addEventListener("change", (ev) => setFixedFrame(ev.target.value));

function pageState() {
  return { fixedFrame, displays: displays.map((d) => ({ cls: d.cfg.cls, name: d.cfg.name, enabled: d.cfg.enabled, topic: d.cfg.topic || "", color: d.cfg.color || DEFAULT_COLOR[d.cfg.cls] || null, options: d.cfg.options || {} })) };
}

$("rv-save").addEventListener("click", async () => {
  const resp = await fetch("/api/rviz/config", { method: "POST", headers: { "Content-Type": "application/json" }, body: JSON.stringify(pageState()) });
  const body = await resp.json().catch(() => ({}));
  if (resp.ok) $("rv-saved").textContent = ` saved to ${body.path}`;
  else message(`save: ${body.error || resp.status}`);
});

const addSelect = $("rv-add-class");
for (const cls of Object.keys(DISPLAY_CLASSES)) addSelect.appendChild(Object.assign(document.createElement("option"), { value: cls, textContent: cls.replace("rviz/", "") }));
$("rv-add").addEventListener("click", () => {
  const cls = addSelect.value;
  addDisplay({ cls, name: cls.replace("rviz/", ""), enabled: true, topic: cls === "rviz/RobotModel" ? "robot_description" : "", color: DEFAULT_COLOR[cls] || null, options: {} });
});

// ------------------------------------------------------------------------------------------------
// tools: 2D Pose Estimate, 2D Nav Goal, Publish Point

let activeTool = "move";
let drag = null;
const preview = arrowMesh(1, 0.05, 0.15, 0.3, 0x00ff00, 0.8);
preview.visible = false;
scene.add(preview);

function setTool(tool) {
  activeTool = tool;
  for (const b of document.querySelectorAll("#rv-tools button[data-tool]")) b.classList.toggle("active", b.dataset.tool === tool);
  if (controls) controls.enabled = tool === "move";
}
for (const b of document.querySelectorAll("#rv-tools button[data-tool]")) b.addEventListener("click", () => setTool(b.dataset.tool));

/** The point of the fixed frame's z = 0 plane under a client (page) position, or null. */
function groundPoint(clientX, clientY) {
  const rect = canvas.getBoundingClientRect();
  const ndc = new THREE.Vector2(((clientX - rect.left) / rect.width) * 2 - 1, -((clientY - rect.top) / rect.height) * 2 + 1);
  const ray = new THREE.Raycaster();
  ray.setFromCamera(ndc, camera);
  const hit = new THREE.Vector3();
  return ray.ray.intersectPlane(new THREE.Plane(new THREE.Vector3(0, 0, 1), 0), hit) ? hit : null;
}

function yawQuat(yaw) { return { x: 0, y: 0, z: Math.sin(yaw / 2), w: Math.cos(yaw / 2) }; }

function publishTool(tool, p, yaw) {
  const header = { seq: 0, stamp: ros.stamp(), frame_id: fixedFrame };
  if (tool === "goal") {
    const topic = toolTopics["rviz/SetGoal"];
    ros.advertise(topic, "geometry_msgs/PoseStamped").publish({ header, pose: { position: { x: p.x, y: p.y, z: 0 }, orientation: yawQuat(yaw) } });
    message(`goal ${p.x.toFixed(2)}, ${p.y.toFixed(2)}, ${(yaw * 180 / Math.PI).toFixed(0)}° → ${topic}`, "info");
  } else if (tool === "pose") {
    const topic = toolTopics["rviz/SetInitialPose"];
    const cov = new Array(36).fill(0);
    cov[0] = 0.25; cov[7] = 0.25; cov[35] = (Math.PI / 12) ** 2; // rviz's: 0.5 m, 15°
    ros.advertise(topic, "geometry_msgs/PoseWithCovarianceStamped").publish({ header, pose: { pose: { position: { x: p.x, y: p.y, z: 0 }, orientation: yawQuat(yaw) }, covariance: cov } });
    message(`initial pose ${p.x.toFixed(2)}, ${p.y.toFixed(2)}, ${(yaw * 180 / Math.PI).toFixed(0)}° → ${topic}`, "info");
  } else if (tool === "point") {
    const topic = toolTopics["rviz/PublishPoint"];
    ros.advertise(topic, "geometry_msgs/PointStamped").publish({ header, point: { x: p.x, y: p.y, z: p.z } });
    message(`point ${p.x.toFixed(2)}, ${p.y.toFixed(2)}, ${p.z.toFixed(2)} → ${topic}`, "info");
  }
}

canvas.addEventListener("pointerdown", (ev) => {
  if (activeTool === "move" || ev.button !== 0) return;
  const p = groundPoint(ev.clientX, ev.clientY);
  if (!p) return;
  if (activeTool === "point") { publishTool("point", p, 0); return; }
  drag = { start: p };
  canvas.setPointerCapture(ev.pointerId);
  preview.position.copy(p);
  preview.rotation.set(0, 0, 0);
  preview.visible = true;
});
canvas.addEventListener("pointermove", (ev) => {
  const p = groundPoint(ev.clientX, ev.clientY);
  if (p) $("rv-coords").textContent = `${fixedFrame}: ${p.x.toFixed(2)}, ${p.y.toFixed(2)}`;
  if (!drag || !p) return;
  preview.rotation.set(0, 0, Math.atan2(p.y - drag.start.y, p.x - drag.start.x));
});
canvas.addEventListener("pointerup", (ev) => {
  if (!drag) return;
  const p = groundPoint(ev.clientX, ev.clientY) || drag.start;
  const dx = p.x - drag.start.x, dy = p.y - drag.start.y;
  const yaw = Math.hypot(dx, dy) > 1e-6 ? Math.atan2(dy, dx) : 0;
  publishTool(activeTool, drag.start, yaw);
  drag = null;
  preview.visible = false;
  setTool("move"); // rviz's pose tools are one-shot
});

// ------------------------------------------------------------------------------------------------
// the loop

const stats = { frames: 0, frameMs: [] };
const frameHooks = []; // called after each render (benchmarks: publish-to-paint)
let frameInterval = 1000 / 30;
let lastRender = 0;
function frame(now) {
  requestAnimationFrame(frame);
  if (now - lastRender < frameInterval - 2) return;
  if (!dirty && now - lastRender < 1000 && !drag) return;
  dirty = false;
  lastRender = now;
  const t0 = performance.now();
  const known = tf.frameNames();
  const list = $("rv-frames");
  if (list.dataset.names !== known.join()) {
    list.dataset.names = known.join();
    list.replaceChildren(...known.map((n) => Object.assign(document.createElement("option"), { value: n })));
  }
  const fs = $("rv-fixed-status");
  const fixedOk = tf.hasFrame(fixedFrame) || known.length === 0;
  const text = fixedOk ? "" : `Fixed Frame: Frame [${fixedFrame}] does not exist`;
  if (fs.textContent !== text) {
    fs.replaceChildren();
    if (text) fs.appendChild(Object.assign(document.createElement("div"), { textContent: text })).dataset.level = "error";
  }
  for (const d of displays) {
    try {
      d.update();
    } catch (err) {
      d.setStatus("Display", "error", err.message);
    }
  }
  controls?.update();
  renderer.render(scene, camera);
  drawLabels();
  for (const fn of frameHooks) fn();
  stats.frames++;
  stats.frameMs.push(performance.now() - t0);
  if (stats.frameMs.length > 2000) stats.frameMs.shift();
}

async function loadConfig() {
  let body;
  try {
    const resp = await fetch("/api/rviz/config");
    body = await resp.json();
  } catch (err) {
    message(`cannot load the display config: ${err.message}`);
    body = { fixedFrame: "map", displays: [], unsupported: [], tools: toolTopics };
  }
  config = body;
  if (body.error) message(`config: ${body.error}`);
  toolTopics = { ...toolTopics, ...(body.tools || {}) };
  // advertised up front, as rviz's tools do: subscribers are connected before the first click
  ros.advertise(toolTopics["rviz/SetGoal"], "geometry_msgs/PoseStamped");
  ros.advertise(toolTopics["rviz/SetInitialPose"], "geometry_msgs/PoseWithCovarianceStamped");
  ros.advertise(toolTopics["rviz/PublishPoint"], "geometry_msgs/PointStamped");
  setFixedFrame(params.get("fixed") || body.fixedFrame || "map");
  if (Number(body.frameRate) > 0) frameInterval = 1000 / Number(body.frameRate);
  if (body.background) scene.background = rvizColor(body.background, "48; 48; 48");
  for (const cfg of body.displays) addDisplay(cfg);
  if (body.unsupported?.length) {
    $("rv-unsupported").textContent = `Not shown (no web version yet): ${body.unsupported.map((u) => `${u.cls} "${u.name}"${u.topic ? ` (${u.topic})` : ""}`).join(", ")}`;
  }
}

$("rv-viewmode").addEventListener("change", (ev) => setView(ev.target.value));
$("rv-reset-view").addEventListener("click", () => setView($("rv-viewmode").value));
await loadConfig();
// the view: URL parameters, else the file's current view (rviz/TopDownOrtho is the top view)
const fileView = config?.view || {};
if (!params.has("scale") && fileView.scale) topScale = Number(fileView.scale);
if (!params.has("cx") && fileView.x !== undefined) viewCentre[0] = Number(fileView.x);
if (!params.has("cy") && fileView.y !== undefined) viewCentre[1] = Number(fileView.y);
setView(params.get("view") || fileView.mode || "orbit");
requestAnimationFrame(frame);

/** For tests and benchmarks: the page's state, and the page pixel of a fixed-frame point. */
window.rviz = {
  ros, tf, displays, stats, frameHooks, groundPoint, setFixedFrame, addDisplay, pageState, setTool,
  get fixedFrame() { return fixedFrame; },
  project(x, y, z = 0) {
    const rect = canvas.getBoundingClientRect();
    const v = new THREE.Vector3(x, y, z).project(camera);
    return { x: rect.left + ((v.x + 1) / 2) * rect.width, y: rect.top + ((1 - v.y) / 2) * rect.height };
  },
  ready: true,
};
