// smach_viewer's page: every smach introspection server on the graph, drawn from its
// container_structure messages (containers nested in their parents, states, outcome edges, container
// outcomes) and coloured from container_status (active states), through the gateway only.
import { RosClient } from "/static/lib/rosclient.js";

const STRUCTURE = "/smach/container_structure";
const STATUS = "/smach/container_status";
const SVG = "http://www.w3.org/2000/svg";
const ros = new RosClient();
const msgBox = document.getElementById("sv-msg");
const select = document.getElementById("sv-server");
const svg = document.getElementById("sv-svg");
const info = document.getElementById("sv-info");

// server -> {structures: Map(path -> msg), statuses: Map(path -> msg), subs: [...]}
const servers = new Map();
let current = null;
let pending = false;
// what tests (and curious users) can read: the last drawing's model
window.smachViewer = { servers, drawn: null, ready: false };

function serverOf(topic, suffix) {
  return topic.endsWith(suffix) ? topic.slice(0, topic.length - suffix.length) : null;
}

function watch(channels) {
  for (const { name, type } of channels) {
    const server = serverOf(name, STRUCTURE) ?? serverOf(name, STATUS);
    if (server === null || servers.has(server)) continue;
    if (type !== "smach_msgs/SmachContainerStructure" && type !== "smach_msgs/SmachContainerStatus") continue;
    const entry = { structures: new Map(), statuses: new Map(), subs: [] };
    servers.set(server, entry);
    entry.subs.push(ros.subscribe(server + STRUCTURE, (m) => { entry.structures.set(m.path, m); redraw(); }, { type: "smach_msgs/SmachContainerStructure", onError: (t) => (msgBox.textContent = t) }));
    entry.subs.push(ros.subscribe(server + STATUS, (m) => { entry.statuses.set(m.path, m); redraw(); }, { type: "smach_msgs/SmachContainerStatus", onError: (t) => (msgBox.textContent = t) }));
    const opt = document.createElement("option");
    opt.value = opt.textContent = server;
    select.append(opt);
    if (current === null) current = server;
  }
  if (servers.size === 0) msgBox.textContent = "no smach introspection server on the graph yet";
  else msgBox.textContent = `${servers.size} introspection server(s)`;
}

select.addEventListener("change", () => { current = select.value; redraw(); });

function redraw() {
  if (pending) return;
  pending = true;
  requestAnimationFrame(() => { pending = false; draw(); });
}

function el(name, attrs = {}, parent = null) {
  const node = document.createElementNS(SVG, name);
  for (const [k, v] of Object.entries(attrs)) node.setAttribute(k, v);
  if (parent) parent.append(node);
  return node;
}

function textWidth(s) { return Math.max(60, 7.2 * String(s).length + 24); }

/** Lay one container out (children first, so nested containers get their real size). */
function layoutContainer(entry, path) {
  const s = entry.structures.get(path);
  const status = entry.statuses.get(path);
  const active = new Set(status ? status.active_states : []);
  const initial = new Set(status ? status.initial_states : []);
  const children = s ? s.children : [];
  const kids = new Map();
  const vertices = [];
  for (const child of children) {
    const childPath = `${path === "/" ? "" : path}/${child}`;
    if (entry.structures.has(childPath)) {
      const sub = layoutContainer(entry, childPath);
      kids.set(child, sub);
      vertices.push({ id: `s:${child}`, w: sub.width, h: sub.height });
    } else {
      vertices.push({ id: `s:${child}`, w: textWidth(child), h: 34 });
    }
  }
  const outcomes = s ? s.container_outcomes : [];
  for (const o of outcomes) vertices.push({ id: `o:${o}`, w: textWidth(o), h: 28 });
  const edges = [];
  if (s) {
    for (let i = 0; i < s.internal_outcomes.length; i++) {
      const from = `s:${s.outcomes_from[i]}`;
      const toName = s.outcomes_to[i];
      let to = null;
      if (children.includes(toName)) to = `s:${toName}`;
      else if (outcomes.includes(toName)) to = `o:${toName}`;
      else if (toName === "None" || toName === "") to = outcomes.includes(s.internal_outcomes[i]) ? `o:${s.internal_outcomes[i]}` : null;
      if (to) edges.push({ source: from, target: to, label: s.internal_outcomes[i] });
    }
  }
  const laid = layoutGraph(vertices, edges, { colGap: 90, rowGap: 22, margin: 26 });
  // layoutGraph gives centres; drawing wants top-left corners
  for (const [id, c] of laid.pos) laid.pos.set(id, { x: c.x - c.w / 2, y: c.y - c.h / 2, w: c.w, h: c.h });
  return { path, structure: s, status, active, initial, children, outcomes, kids, vertices, edges, laid, width: laid.width, height: laid.height + 18 };
}

function render(box, x, y, parent, model) {
  const g = el("g", { class: "sv-container", "data-path": box.path, transform: `translate(${x},${y})` }, parent);
  el("rect", { x: 0, y: 0, width: box.width, height: box.height, rx: 8 }, g);
  el("text", { x: 10, y: 14, class: "sv-title" }, g).textContent = box.path;
  const inner = el("g", { transform: "translate(0,18)" }, g);
  const edgeLayer = el("g", { class: "sv-edges" });
  const pos = box.laid.pos;
  const defs = svg.querySelector("defs");
  for (const e of box.edges) {
    const a = pos.get(e.source), b = pos.get(e.target);
    if (!a || !b) continue;
    let d;
    if (e.source === e.target) {
      d = `M${a.x + a.w * 0.7},${a.y} C${a.x + a.w * 0.9},${a.y - 30} ${a.x + a.w * 0.3},${a.y - 30} ${a.x + a.w * 0.3},${a.y}`;
    } else {
      const x1 = a.x + a.w, y1 = a.y + a.h / 2, x2 = b.x, y2 = b.y + b.h / 2;
      const back = x2 <= x1;
      d = back
        ? `M${a.x + a.w / 2},${a.y + a.h} C${a.x + a.w / 2},${a.y + a.h + 40} ${b.x + b.w / 2},${b.y + b.h + 40} ${b.x + b.w / 2},${b.y + b.h}`
        : `M${x1},${y1} C${(x1 + x2) / 2},${y1} ${(x1 + x2) / 2},${y2} ${x2},${y2}`;
    }
    el("path", { d, class: "sv-edge", "marker-end": defs ? "url(#sv-arrow)" : "", "data-from": e.source.slice(2), "data-to": e.target.slice(2), "data-outcome": e.label }, edgeLayer);
    const lx = e.source === e.target ? a.x + a.w / 2 : (a.x + a.w + b.x) / 2;
    const ly = e.source === e.target ? a.y - 24 : (a.y + a.h / 2 + b.y + b.h / 2) / 2 - 4;
    el("text", { x: lx, y: ly, class: "sv-edge-label" }, edgeLayer).textContent = e.label;
  }
  for (const child of box.children) {
    const p = pos.get(`s:${child}`);
    if (!p) continue;
    const sub = box.kids.get(child);
    if (sub) {
      const cg = render(sub, p.x, p.y, inner, model);
      if (box.active.has(child)) cg.classList.add("active");
      continue;
    }
    const cls = ["sv-state"];
    if (box.active.has(child)) cls.push("active");
    if (box.initial.has(child)) cls.push("initial");
    const sg = el("g", { class: cls.join(" "), "data-state": child, "data-path": box.path }, inner);
    el("rect", { x: p.x, y: p.y, width: p.w, height: p.h, rx: 6 }, sg);
    el("text", { x: p.x + p.w / 2, y: p.y + p.h / 2 }, sg).textContent = child;
    if (box.active.has(child)) model.active.push(`${box.path === "/" ? "" : box.path}/${child}`);
  }
  for (const o of box.outcomes) {
    const p = pos.get(`o:${o}`);
    if (!p) continue;
    const og = el("g", { class: "sv-outcome", "data-outcome": o, "data-path": box.path }, inner);
    el("rect", { x: p.x, y: p.y, width: p.w, height: p.h, rx: 14 }, og);
    el("text", { x: p.x + p.w / 2, y: p.y + p.h / 2 }, og).textContent = o;
  }
  inner.append(edgeLayer); // on top of nested containers' boxes
  model.containers.push({ path: box.path, children: box.children, outcomes: box.outcomes, edges: box.edges.map((e) => [e.label, e.source.slice(2), e.target.slice(2)]) });
  return g;
}

function draw() {
  svg.replaceChildren();
  const defs = el("defs", {}, svg);
  const marker = el("marker", { id: "sv-arrow", viewBox: "0 0 10 10", refX: 10, refY: 5, markerWidth: 7, markerHeight: 7, orient: "auto-start-reverse" }, defs);
  el("path", { d: "M0,0 L10,5 L0,10 z", fill: "#6b6b70" }, marker);
  const entry = servers.get(current);
  if (!entry) return;
  // roots: structures whose parent path has no structure of its own
  const paths = [...entry.structures.keys()];
  const roots = paths.filter((p) => !entry.structures.has(p.slice(0, p.lastIndexOf("/")) || "/") || p === "/").filter((p) => {
    const parent = p.slice(0, p.lastIndexOf("/"));
    return !parent || !entry.structures.has(parent);
  });
  const model = { server: current, containers: [], active: [] };
  let y = 4, width = 10;
  for (const root of roots.sort()) {
    const box = layoutContainer(entry, root);
    render(box, 4, y, svg, model);
    y += box.height + 16;
    width = Math.max(width, box.width + 8);
  }
  svg.setAttribute("width", width);
  svg.setAttribute("height", y);
  const rootStatus = roots.map((r) => entry.statuses.get(r)).find(Boolean);
  info.textContent = rootStatus ? `last status: ${rootStatus.path} active ${JSON.stringify(rootStatus.active_states)} (${rootStatus.info})` : "";
  window.smachViewer.drawn = model;
}

async function main() {
  await ros.ready();
  ros.on("channels", watch);
  watch(ros.topics());
  window.smachViewer.ready = true;
}

main().catch((err) => { msgBox.textContent = `error: ${err.message}`; });
