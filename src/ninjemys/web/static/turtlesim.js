// The turtlesim window: a path canvas (pen trails) with the turtles drawn on top, live through the
// gateway (the node's "view:turtlesim" JSON channel: a full state first, then updates).
import { RosClient } from "/static/lib/rosclient.js";

const view = document.getElementById("turtlesim");
const ctx = view.getContext("2d");
const path = document.createElement("canvas"); // the path image, as turtlesim's QImage
const pctx = path.getContext("2d");
const list = document.getElementById("turtle-list");
const statusLine = document.getElementById("status");
let geo = { size: 500, scale: 45, world: 499 / 45 };
let turtles = [];
let frameQueued = false;
const VIEW_CHANNEL = "view:turtlesim";
const SHELLS = ["#2e8b57", "#3b7d3b", "#4a6b2a", "#1f7a6d", "#6b8e23", "#2f6f4f"];

function px(x, y) { return [x * geo.scale, (geo.world - y) * geo.scale]; }

function drawSegment(s) {
  const [x0, y0, x1, y1, r, g, b, w] = s;
  const a = px(x0, y0), c = px(x1, y1);
  pctx.strokeStyle = `rgb(${r},${g},${b})`;
  pctx.lineWidth = w;
  pctx.lineCap = "round";
  pctx.beginPath();
  pctx.moveTo(a[0], a[1]);
  pctx.lineTo(c[0], c[1]);
  pctx.stroke();
}

function drawTurtle(t) {
  const [cx, cy] = px(t.x, t.y);
  ctx.save();
  ctx.translate(cx, cy);
  ctx.rotate(-t.theta);
  ctx.fillStyle = "#e0b070"; // legs and head
  for (const [lx, ly] of [[7, 9], [7, -9], [-7, 9], [-7, -9]]) { ctx.beginPath(); ctx.arc(lx, ly, 4, 0, 2 * Math.PI); ctx.fill(); }
  ctx.beginPath(); ctx.arc(13, 0, 5, 0, 2 * Math.PI); ctx.fill();
  ctx.fillStyle = SHELLS[t.image % SHELLS.length];
  ctx.beginPath(); ctx.ellipse(0, 0, 11, 9, 0, 0, 2 * Math.PI); ctx.fill();
  ctx.strokeStyle = "rgba(0,0,0,0.35)"; ctx.lineWidth = 1; ctx.stroke();
  ctx.restore();
}

function frame() {
  frameQueued = false;
  ctx.drawImage(path, 0, 0);
  for (const t of turtles) drawTurtle(t);
}

function queueFrame() {
  if (!frameQueued) { frameQueued = true; requestAnimationFrame(frame); }
}

function showTurtles(ts) {
  turtles = ts;
  list.textContent = ts.map((t) => `${t.name}  x=${t.x.toFixed(3)} y=${t.y.toFixed(3)} θ=${t.theta.toFixed(3)}`).join("\n");
  list.style.whiteSpace = "pre";
  document.body.dataset.turtles = ts.map((t) => t.name).join(",");
}

function loadState(state) {
  geo = { size: state.size, scale: state.scale, world: state.world };
  view.width = view.height = path.width = path.height = state.size;
  const img = new Image();
  img.onload = () => { pctx.drawImage(img, 0, 0); for (const s of pending) drawSegment(s); pending = null; queueFrame(); };
  let pending = [];
  loadState.pending = (s) => (pending ? pending.push(s) : drawSegment(s));
  img.src = "data:image/png;base64," + state.path_png;
  showTurtles(state.turtles);
  statusLine.textContent = `node ${state.node}`;
  statusLine.className = "";
  queueFrame();
}
loadState.pending = drawSegment;

const ros = new RosClient();
ros.subscribe(VIEW_CHANNEL, (m) => {
  if (m.kind === "state") { loadState(m); return; }
  for (const seg of m.segments) loadState.pending(seg);
  showTurtles(m.turtles);
  queueFrame();
  document.body.dataset.updates = String(Number(document.body.dataset.updates || 0) + 1);
});
ros.on("close", () => { statusLine.textContent = "turtlesim is not reachable, retrying…"; statusLine.className = "error"; });
