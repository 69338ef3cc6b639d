// The PuzzleBot simulator seen from above: world, robots, trails, lidar rays, cameras, keyboard teleop.
// One data path, the gateway: the "view:puzzlebot" JSON channel (world, then updates), the robots'
// camera topics, cmd_vel publications and the /gazebo/* services.
import { RosClient } from "/static/lib/rosclient.js";
import { startGamepad } from "/static/lib/gamepad.js";

const VIEW_CHANNEL = "view:puzzlebot";
const ros = new RosClient();

const canvas = document.getElementById("pb-world");
const ctx = canvas.getContext("2d");
const statusLine = document.getElementById("status");
const robotSelect = document.getElementById("pb-robot");
const robotList = document.getElementById("pb-robots");
const colorCanvas = document.getElementById("pb-color");
const depthCanvas = document.getElementById("pb-depth");
let world = null;
let update = { robots: [], movers: [], time: 0, paused: false };
const trails = new Map();
let frameQueued = false;
let view = { scale: 50, x0: 0, y0: 0 };
let byHeight = [];  // the world's obstacles, the lowest first (drawn in that order)
const floorPictures = new Map();  // url -> Image

function rgb(c, a) { return a === undefined ? `rgb(${c[0]},${c[1]},${c[2]})` : `rgba(${c[0]},${c[1]},${c[2]},${a})`; }

function fit() {
  const [xmin, ymin, xmax, ymax] = world.bounds;
  const scale = Math.min(canvas.width / (xmax - xmin), canvas.height / (ymax - ymin));
  view = { scale, x0: xmin - (canvas.width / scale - (xmax - xmin)) / 2, y0: ymax + (canvas.height / scale - (ymax - ymin)) / 2 };
}
function px(x, y) { return [(x - view.x0) * view.scale, (view.y0 - y) * view.scale]; }

function polygon(points, closed) {
  ctx.beginPath();
  points.forEach(([x, y], i) => { const [a, b] = px(x, y); if (i) ctx.lineTo(a, b); else ctx.moveTo(a, b); });
  if (closed) ctx.closePath();
}

function draw() {
  frameQueued = false;
  if (!world) return;
  ctx.fillStyle = "#f4f1ea";
  ctx.fillRect(0, 0, canvas.width, canvas.height);
  ctx.strokeStyle = "rgba(0,0,0,0.06)"; ctx.lineWidth = 1;  // 1 m grid
  for (let x = Math.ceil(world.bounds[0]); x <= world.bounds[2]; x++) { const [a] = px(x, 0); ctx.beginPath(); ctx.moveTo(a, 0); ctx.lineTo(a, canvas.height); ctx.stroke(); }
  for (let y = Math.ceil(world.bounds[1]); y <= world.bounds[3]; y++) { const [, b] = px(0, y); ctx.beginPath(); ctx.moveTo(0, b); ctx.lineTo(canvas.width, b); ctx.stroke(); }
  for (const f of world.floor_images) {  // pictures on the floor (a course's track), under everything
    const img = floorPictures.get(f.url);
    if (!img || !img.complete || !img.naturalWidth) continue;
    const [cx, cy] = px(f.cx, f.cy);
    ctx.save(); ctx.translate(cx, cy); ctx.rotate(-f.yaw);
    ctx.drawImage(img, -f.width * view.scale / 2, -f.height * view.scale / 2, f.width * view.scale, f.height * view.scale);
    ctx.restore();
  }
  for (const m of world.markings) {
    polygon(m.points, m.closed);
    ctx.strokeStyle = rgb(m.color); ctx.lineWidth = Math.max(2, m.width * view.scale); ctx.stroke();
  }
  // models in their colours, the lower first; a shadow as long as the piece is tall; what is held
  // in the air (a table top, a shelf) see-through with a dashed edge, so what is under it shows
  for (const o of byHeight) {
    const closed = o.outline.length > 2;
    polygon(o.outline, closed);
    ctx.save();
    if (closed) {
      const off = Math.min(14, 2 + 6 * o.height);
      ctx.shadowColor = "rgba(0,0,0,0.3)"; ctx.shadowOffsetX = off; ctx.shadowOffsetY = off; ctx.shadowBlur = 2;
      ctx.fillStyle = rgb(o.color, o.base > 0 ? 0.55 : undefined); ctx.fill();
    }
    ctx.restore();
    ctx.strokeStyle = "#555"; ctx.lineWidth = 1;
    if (o.base > 0) ctx.setLineDash([4, 3]);
    ctx.stroke(); ctx.setLineDash([]);
  }
  ctx.strokeStyle = "#333"; ctx.lineWidth = 2;
  for (const [x0, y0, x1, y1] of world.grid_edges) { const a = px(x0, y0), b = px(x1, y1); ctx.beginPath(); ctx.moveTo(a[0], a[1]); ctx.lineTo(b[0], b[1]); ctx.stroke(); }
  for (const m of update.movers) { polygon(m.outline, true); ctx.fillStyle = rgb(m.color); ctx.fill(); }
  const selected = robotSelect.value;
  for (const r of update.robots) {
    const trail = trails.get(r.name) || [];
    if (trail.length > 1) { polygon(trail, false); ctx.strokeStyle = "rgba(40,90,200,0.7)"; ctx.lineWidth = 2; ctx.stroke(); }
    if (r.scan) {
      const c = Math.cos(r.yaw), s = Math.sin(r.yaw);
      const lx = r.x + c * r.scan.offset[0] - s * r.scan.offset[1], ly = r.y + s * r.scan.offset[0] + c * r.scan.offset[1];
      const [ox, oy] = px(lx, ly);
      ctx.strokeStyle = r.name === selected ? "rgba(220,40,40,0.25)" : "rgba(220,120,40,0.18)"; ctx.lineWidth = 1;
      ctx.fillStyle = "rgba(220,30,30,0.9)";
      r.scan.ranges.forEach((d, i) => {
        if (d === null) return;
        const a = r.yaw + r.scan.angle_min + i * r.scan.increment;
        const [hx, hy] = px(lx + d * Math.cos(a), ly + d * Math.sin(a));
        ctx.beginPath(); ctx.moveTo(ox, oy); ctx.lineTo(hx, hy); ctx.stroke();
        ctx.fillRect(hx - 1.5, hy - 1.5, 3, 3);
      });
    }
    const [cx, cy] = px(r.x, r.y);
    ctx.save(); ctx.translate(cx, cy); ctx.rotate(-r.yaw);
    const rad = r.radius * view.scale;
    ctx.beginPath(); ctx.arc(0, 0, rad, 0, 2 * Math.PI); ctx.fillStyle = rgb(r.color); ctx.fill();
    ctx.lineWidth = r.contact ? 3 : 1.5; ctx.strokeStyle = r.contact ? "#e02020" : (r.name === selected ? "#2060e0" : "#222"); ctx.stroke();
    ctx.fillStyle = "#111"; ctx.fillRect(-rad * 0.35, rad * 0.75, rad * 0.7, rad * 0.3); ctx.fillRect(-rad * 0.35, -rad * 1.05, rad * 0.7, rad * 0.3); // wheels
    ctx.beginPath(); ctx.moveTo(rad * 0.9, 0); ctx.lineTo(rad * 0.2, rad * 0.35); ctx.lineTo(rad * 0.2, -rad * 0.35); ctx.closePath(); ctx.fillStyle = "#f0c040"; ctx.fill();
    ctx.restore();
    ctx.fillStyle = "#222"; ctx.font = "11px sans-serif"; ctx.fillText(r.name, cx + rad + 3, cy - rad - 2);
  }
}
function queueDraw() { if (!frameQueued) { frameQueued = true; requestAnimationFrame(draw); } }

function applyUpdate(u) {
  update = u;
  window.puzzlebot = { world, update, trails, px };
  for (const r of u.robots) {
    if (r.trail_reset || !trails.has(r.name)) trails.set(r.name, []);
    const t = trails.get(r.name);
    for (const p of r.trail) t.push(p);
    if (t.length > 4000) t.splice(0, t.length - 4000);
  }
  const names = u.robots.map((r) => r.name);
  if (names.join(",") !== [...robotSelect.options].map((o) => o.value).join(",")) {
    const keep = robotSelect.value;
    robotSelect.innerHTML = "";
    for (const n of names) { const o = document.createElement("option"); o.value = o.textContent = n; robotSelect.appendChild(o); }
    if (names.includes(keep)) robotSelect.value = keep;
  }
  robotList.textContent = `t = ${u.time.toFixed(2)} s${u.paused ? "  (paused)" : ""}\n` + u.robots.map((r) =>
    `${r.name}${r.namespace ? " " + r.namespace : ""}  x=${r.x.toFixed(3)} y=${r.y.toFixed(3)} yaw=${r.yaw.toFixed(3)}  v=${r.v.toFixed(2)} w=${r.w.toFixed(2)}${r.contact ? "  CONTACT " + r.contact_with : ""}`).join("\n");
  document.body.dataset.robots = names.join(",");
  document.body.dataset.simTime = String(u.time);
  document.body.dataset.scanRobots = u.robots.filter((r) => r.scan).map((r) => r.name).join(",");
  queueDraw();
}

function loadState(state) {
  const first = !world || world.bounds.join() !== state.bounds.join();
  world = state;
  byHeight = [...state.obstacles].sort((a, b) => a.height - b.height);
  for (const f of state.floor_images) {
    if (floorPictures.has(f.url)) continue;
    const img = new Image();
    img.onload = () => { document.body.dataset.floorPictures = String(Number(document.body.dataset.floorPictures || 0) + 1); queueDraw(); };
    img.src = f.url;
    floorPictures.set(f.url, img);
  }
  document.body.dataset.worldRevision = String(state.revision);
  trails.clear();
  if (first) fit();
  statusLine.textContent = `node ${state.node} · world ${state.world}`;
  statusLine.className = "";
  applyUpdate(state.update);
}

ros.subscribe(VIEW_CHANNEL, (m) => (m.kind === "state" ? loadState(m) : applyUpdate(m)));
ros.on("close", () => { statusLine.textContent = "disconnected (retrying)"; statusLine.className = "error"; });

// camera images: the selected robot's colour (rgb8) and depth (16UC1, mm) topics. Only the newest image of
// each is drawn, once per animation frame: a simulator running faster than real time sends more frames than a
// page can convert, and drawing every one kept the page busy enough to miss clicks on a loaded machine.
let cameraSubs = [];
const newestImages = new Map(); // canvas -> the newest image not drawn yet
let imagesQueued = false;
function showImage(target, msg) {
  newestImages.set(target, msg);
  if (imagesQueued) return;
  imagesQueued = true;
  requestAnimationFrame(() => {
    imagesQueued = false;
    for (const [canvasOf, newest] of newestImages) drawImage(canvasOf, newest);
    newestImages.clear();
  });
}
let cameraRobot = null;
function drawImage(target, msg) {
  const { width, height } = msg;
  if (target.width !== width || target.height !== height) { target.width = width; target.height = height; }
  const c = target.getContext("2d");
  const img = c.createImageData(width, height);
  const out = img.data, data = msg.data;
  if (msg.encoding === "rgb8") {
    for (let i = 0, j = 0; i < width * height; i++, j += 3) {
      out[4 * i] = data[j]; out[4 * i + 1] = data[j + 1]; out[4 * i + 2] = data[j + 2]; out[4 * i + 3] = 255;
    }
  } else if (msg.encoding === "16UC1") {
    const view = new DataView(data.buffer, data.byteOffset, data.byteLength);
    for (let i = 0; i < width * height; i++) {
      const d = view.getUint16(2 * i, !msg.is_bigendian);
      const v = d > 0 ? 255 - Math.min(Math.max(d / 40, 0), 235) : 0; // near bright, 10 m dark
      out[4 * i] = out[4 * i + 1] = out[4 * i + 2] = v; out[4 * i + 3] = 255;
    }
  } else return;
  c.putImageData(img, 0, 0);
  target.dataset.loaded = String(Number(target.dataset.loaded || 0) + 1);
}
function followCameras() {
  const r = update.robots.find((x) => x.name === robotSelect.value);
  const name = r && r.camera ? r.name : null;
  if (name === cameraRobot) return;
  for (const sub of cameraSubs) sub.unsubscribe();
  cameraSubs = [];
  cameraRobot = name;
  if (!r || !name) return;
  cameraSubs = [
    ros.subscribe(r.topics.color, (msg) => showImage(colorCanvas, msg), { type: "sensor_msgs/Image" }),
    ros.subscribe(r.topics.depth, (msg) => showImage(depthCanvas, msg), { type: "sensor_msgs/Image" }),
  ];
}
setInterval(followCameras, 200);

// keyboard teleop: held keys set the velocity, sent 10 times a second while any is held
const keys = new Set();
const LINEAR = 0.3, ANGULAR = 1.2;
let lastSent = "";
function command() {
  let v = 0, w = 0;
  if (keys.has("ArrowUp") || keys.has("w")) v += LINEAR;
  if (keys.has("ArrowDown") || keys.has("s")) v -= LINEAR;
  if (keys.has("ArrowLeft") || keys.has("a")) w += ANGULAR;
  if (keys.has("ArrowRight") || keys.has("d")) w -= ANGULAR;
  return [v, w];
}
const drivers = new Map(); // cmd_vel topic -> publisher (through the gateway)
function send(force) {
  const [v, w] = command();
  const key = `${v},${w}`;
  if (!force && key === lastSent && v === 0 && w === 0) return;
  lastSent = key;
  const r = update.robots.find((x) => x.name === robotSelect.value);
  if (!r) return;
  let pub = drivers.get(r.topics.cmd_vel);
  if (!pub) { pub = ros.advertise(r.topics.cmd_vel, "geometry_msgs/Twist"); drivers.set(r.topics.cmd_vel, pub); }
  pub.publish({ linear: { x: v, y: 0, z: 0 }, angular: { x: 0, y: 0, z: w } });
  document.body.dataset.lastCommand = key;
}
const DRIVE_KEYS = ["ArrowUp", "ArrowDown", "ArrowLeft", "ArrowRight", "w", "a", "s", "d", " "];
document.addEventListener("keydown", (ev) => {
  if (!DRIVE_KEYS.includes(ev.key) || ev.target === robotSelect) return;
  ev.preventDefault();
  if (ev.key === " ") { keys.clear(); send(true); return; }
  keys.add(ev.key); send(true);
});
document.addEventListener("keyup", (ev) => { if (keys.delete(ev.key)) send(true); });
setInterval(() => { if (keys.size) send(true); }, 100);
window.addEventListener("blur", () => { if (keys.size) { keys.clear(); send(true); } });

for (const b of document.querySelectorAll(".pb-buttons button")) {
  const service = { pause: "pause_physics", unpause: "unpause_physics" }[b.dataset.action] || b.dataset.action;
  b.addEventListener("click", () => ros.callService(`/gazebo/${service}`, {}).catch((err) => {
    statusLine.textContent = String(err.message || err); statusLine.className = "error";
  }));
}
// a game controller publishes sensor_msgs/Joy on /joy, as joy_node would: run teleop_twist_joy to drive
const gamepadLine = document.getElementById("pb-gamepad");
const gamepad = startGamepad(ros, {
  status: (id) => { gamepadLine.textContent = id ? `gamepad: ${id} → /joy` : ""; document.body.dataset.gamepad = id || ""; },
});
window.puzzlebotGamepad = gamepad.state;
robotSelect.addEventListener("change", queueDraw);
window.addEventListener("resize", queueDraw);
