// The node graph page (rqt_graph in the browser), live through the gateway like every page: the
// Foxglove connection graph (who publishes, subscribes, provides), the channels (topic types), the
// gateway's rosBus extension (which nodes answer, which connections are up, from getBusInfo), and
// for the selected topic a subscription that measures its rate and shows its last message.
import { RosClient } from "/static/lib/rosclient.js";
import { toJson } from "/static/rqt/common.js";

// what rqt_graph hides with "Hide Debug": the logging plumbing every node is wired to
const DEBUG_TOPICS = new Set(["/rosout", "/rosout_agg", "/statistics"]);
const DEBUG_NODES = new Set(["/rosout"]);
const RATE_WINDOW = 10; // seconds over which a topic's rate is averaged

const SVGNS = "http://www.w3.org/2000/svg";
const ui = {
  svg: document.getElementById("graph"),
  status: document.getElementById("status"),
  mode: document.getElementById("mode"),
  group: document.getElementById("group"),
  hideDebug: document.getElementById("hide-debug"),
  hideDead: document.getElementById("hide-dead"),
  hideLeaf: document.getElementById("hide-leaf"),
  filter: document.getElementById("filter"),
  details: document.getElementById("details"),
};
let current = null; // last {graph, master_uri, error}
let selectedTopic = null;
let detailsTimer = null;
let watch = null; // the selected topic's subscription: {sub, stamps, count, last, type}

function el(tag, attrs, parent) {
  const e = document.createElementNS(SVGNS, tag);
  for (const [k, v] of Object.entries(attrs || {})) e.setAttribute(k, v);
  if (parent) parent.appendChild(e);
  return e;
}

function textWidth(s) { return Math.max(60, s.length * 7.2 + 24); }

// What is visible under the current options: {vertices, edges} in layout terms.
function visibleGraph(graph) {
  const opt = {
    topics: ui.mode.value === "topics", debug: !ui.hideDebug.checked, dead: !ui.hideDead.checked,
    leaf: !ui.hideLeaf.checked, filter: ui.filter.value.trim(),
  };
  const nodes = graph.nodes.filter((n) => opt.debug || !n.debug);
  const nodeSet = new Set(nodes.map((n) => n.name));
  const topics = graph.topics.filter((t) => {
    if (!opt.debug && t.debug) return false;
    const pubs = t.publishers.filter((p) => nodeSet.has(p));
    const subs = t.subscribers.filter((s) => nodeSet.has(s));
    if (!opt.dead && subs.length === 0) return false;
    if (!opt.leaf && new Set(pubs.concat(subs)).size <= 1) return false; // leaf: one node only
    return pubs.length + subs.length > 0;
  });
  const match = (name) => !opt.filter || name.includes(opt.filter);
  const vertices = [];
  const edges = [];
  const groupOf = (ns) => (ui.group.checked && ns !== "/" ? ns : "");
  const topicSet = new Set(topics.map((t) => t.name));
  if (opt.topics) {
    const used = new Set();
    for (const t of topics) {
      if (!match(t.name) && !t.publishers.concat(t.subscribers).some(match)) continue;
      vertices.push({ id: "t:" + t.name, kind: "topic", name: t.name, w: textWidth(t.name), h: 30, group: groupOf(t.namespace) });
      for (const p of t.publishers) if (nodeSet.has(p)) { edges.push({ source: "n:" + p, target: "t:" + t.name, topic: t.name }); used.add(p); }
      for (const s of t.subscribers) if (nodeSet.has(s)) { edges.push({ source: "t:" + t.name, target: "n:" + s, topic: t.name }); used.add(s); }
    }
    for (const n of nodes) if (used.has(n.name) || match(n.name)) vertices.push(nodeVertex(n, groupOf));
  } else {
    const pairs = new Map();
    for (const e of graph.edges) {
      if (!nodeSet.has(e.source) || !nodeSet.has(e.target) || !topicSet.has(e.topic)) continue;
      if (!(match(e.source) || match(e.target) || match(e.topic))) continue;
      const key = e.source + "\u0000" + e.target;
      const p = pairs.get(key) || { source: "n:" + e.source, target: "n:" + e.target, topics: [], connected: true };
      p.topics.push(e.topic);
      p.connected = p.connected && e.connected;
      pairs.set(key, p);
    }
    for (const p of pairs.values()) edges.push({ source: p.source, target: p.target, topic: p.topics.join("\n"), connected: p.connected });
    const used = new Set(edges.flatMap((e) => [e.source, e.target]));
    for (const n of nodes) if (used.has("n:" + n.name) || match(n.name)) vertices.push(nodeVertex(n, groupOf));
  }
  return { vertices, edges };
}

function nodeVertex(n, groupOf) {
  return { id: "n:" + n.name, kind: "node", name: n.name, w: textWidth(n.name) + 10, h: 36, group: groupOf(n.namespace), reachable: n.reachable };
}

// The layout depends only on the shapes and the arrows; a bus update (who answers, which links
// are up) or a selection keeps them, so it re-uses the last layout instead of computing it again.
let lastLayout = { key: "", result: null };
function layoutOf(vertices, edges) {
  const key = JSON.stringify([vertices.map((v) => [v.id, v.w, v.h, v.group]), edges.map((e) => [e.source, e.target])]);
  if (key !== lastLayout.key) lastLayout = { key, result: layoutGraph(vertices, edges) };
  return lastLayout.result;
}

function render() {
  const svg = ui.svg;
  while (svg.firstChild) svg.removeChild(svg.firstChild);
  if (!current || !current.graph) return;
  const { vertices, edges } = visibleGraph(current.graph);
  const { pos, width, height } = layoutOf(vertices, edges);
  svg.setAttribute("width", Math.max(width, 200));
  svg.setAttribute("height", Math.max(height, 120));
  const defs = el("defs", {}, svg);
  const marker = el("marker", { id: "arrow", viewBox: "0 0 10 10", refX: 10, refY: 5, markerWidth: 8, markerHeight: 8, orient: "auto-start-reverse" }, defs);
  el("path", { d: "M0,0 L10,5 L0,10 z", fill: "#9aa0a6" }, marker);
  // namespace groups behind everything
  if (ui.group.checked) {
    const groups = new Map();
    for (const v of vertices) if (v.group) (groups.get(v.group) || groups.set(v.group, []).get(v.group)).push(pos.get(v.id));
    for (const [name, ps] of groups) {
      const x0 = Math.min(...ps.map((p) => p.x - p.w / 2)) - 10, x1 = Math.max(...ps.map((p) => p.x + p.w / 2)) + 10;
      const y0 = Math.min(...ps.map((p) => p.y - p.h / 2)) - 22, y1 = Math.max(...ps.map((p) => p.y + p.h / 2)) + 8;
      const g = el("g", { class: "group", "data-name": name }, svg);
      el("rect", { x: x0, y: y0, width: x1 - x0, height: y1 - y0, rx: 8 }, g);
      el("text", { x: x0 + 6, y: y0 + 13 }, g).textContent = name;
    }
  }
  for (const e of edges) {
    const a = pos.get(e.source), b = pos.get(e.target);
    if (!a || !b) continue;
    const x0 = a.x + a.w / 2, y0 = a.y, x1 = b.x - b.w / 2, y1 = b.y;
    const mid = (x0 + x1) / 2;
    const d = x1 > x0 ? `M${x0},${y0} C${mid},${y0} ${mid},${y1} ${x1},${y1}` : `M${x0},${y0} C${x0 + 60},${y0 - 80} ${x1 - 60},${y1 - 80} ${x1},${y1}`;
    const cls = "edge" + (e.connected === false ? " pending" : "") + (selectedTopic && e.topic === selectedTopic ? " selected" : "");
    el("path", { d, class: cls, "marker-end": "url(#arrow)", "data-source": e.source.slice(2), "data-target": e.target.slice(2), "data-topic": e.topic }, svg);
    if (ui.mode.value === "nodes") {
      const t = el("text", { x: mid, y: (y0 + y1) / 2 - 5, class: "edge-label" }, svg);
      t.textContent = e.topic.split("\n").join(", ");
    }
  }
  for (const v of vertices) {
    const p = pos.get(v.id);
    const g = el("g", { class: v.kind + (v.kind === "node" && !v.reachable ? " unreachable" : "") + (v.name === selectedTopic ? " selected" : ""), "data-name": v.name }, svg);
    if (v.kind === "node") el("ellipse", { cx: p.x, cy: p.y, rx: p.w / 2, ry: p.h / 2 }, g);
    else {
      el("rect", { x: p.x - p.w / 2, y: p.y - p.h / 2, width: p.w, height: p.h, rx: 3 }, g);
      g.addEventListener("click", () => selectTopic(v.name));
    }
    el("text", { x: p.x, y: p.y }, g).textContent = v.name;
    el("title", {}, g).textContent = v.kind === "node" ? v.name + (v.reachable ? "" : " (not answering)") : v.name + " (click for details)";
  }
  const g = current.graph;
  ui.status.textContent = `${g.nodes.length} nodes, ${g.topics.length} topics — master ${current.master_uri}`;
  ui.status.className = "";
}

// -- the graph model, from the gateway's connection graph -------------------------------------
const ros = new RosClient();
const known = { pub: new Map(), sub: new Map(), srv: new Map(), bus: { nodes: {}, live: {} }, error: null };

function namespaceOf(name) {
  const head = name.replace(/\/+$/, "").split("/").slice(0, -1).join("/");
  return head || "/";
}

function lookerNodes() {
  const meta = (ros.serverInfo && ros.serverInfo.metadata) || {};
  return new Set((meta.debugNodes || "").split(",").filter(Boolean));
}

/** nodes, topics and node->node edges, as rqt_graph draws them */
function buildGraph() {
  const types = new Map(ros.topics().map((t) => [t.name, t.type]));
  // the nodes are the master's (the bus sweep only annotates them, and lags behind a departure)
  const names = new Set();
  for (const table of [known.pub, known.sub, known.srv]) for (const ids of table.values()) for (const n of ids) names.add(n);
  const lookers = lookerNodes();
  const nodes = [...names].sort().map((name) => ({
    name,
    namespace: namespaceOf(name),
    uri: (known.bus.nodes[name] || {}).uri || "",
    reachable: (known.bus.nodes[name] || { reachable: true }).reachable,
    debug: DEBUG_NODES.has(name) || lookers.has(name),
  }));
  const live = (node, topic) => (known.bus.live[node] || []).includes(topic);
  const topics = [];
  const edges = [];
  const topicNames = new Set([...known.pub.keys(), ...known.sub.keys(), ...types.keys()]);
  for (const name of [...topicNames].sort()) {
    const publishers = [...(known.pub.get(name) || [])].sort();
    const subscribers = [...(known.sub.get(name) || [])].sort();
    topics.push({ name, namespace: namespaceOf(name), type: types.get(name) || "", publishers, subscribers, debug: DEBUG_TOPICS.has(name) });
    for (const a of publishers) for (const b of subscribers) edges.push({ source: a, target: b, topic: name, connected: live(a, name) || live(b, name) });
  }
  return { nodes, topics, edges };
}

function onGraph(update) {
  for (const t of update.publishedTopics || []) known.pub.set(t.name, t.publisherIds);
  for (const t of update.subscribedTopics || []) known.sub.set(t.name, t.subscriberIds);
  for (const sv of update.advertisedServices || []) known.srv.set(sv.name, sv.providerIds);
  for (const name of update.removedTopics || []) { known.pub.delete(name); known.sub.delete(name); }
  for (const name of update.removedServices || []) known.srv.delete(name);
  // a topic keeps its entry in one table while the other side changes: drop the emptied ones
  for (const table of [known.pub, known.sub]) for (const [name, ids] of table) if (!ids.length) table.delete(name);
  if (update.rosBus) known.bus = update.rosBus;
  refreshState();
}

let stateQueued = false;
function refreshState() {
  if (stateQueued) return;
  stateQueued = true;
  setTimeout(() => { // one re-layout for a burst of updates (graph, bus, channels)
    stateQueued = false;
    showState({ graph: buildGraph(), master_uri: ((ros.serverInfo || {}).metadata || {}).ROS_MASTER_URI || "", error: known.error });
  }, 0);
}

function showState(state) {
  current = state;
  if (state.error) {
    ui.status.textContent = state.error;
    ui.status.className = "error";
  }
  if (state.graph && !state.error) render();
  else if (state.graph) { const keep = ui.status.textContent; render(); ui.status.textContent = keep; ui.status.className = "error"; }
  document.body.dataset.nodes = String(state.graph ? state.graph.nodes.length : 0);
}
// for bench/web_graph.py's timing of one re-layout (the cached layout dropped first)
window.render = () => { lastLayout = { key: "", result: null }; render(); };

// topic details panel: type, publishers, subscribers, and (watched through the gateway while the
// panel is open) rate and last message, refreshed each second
function selectTopic(name) {
  selectedTopic = name;
  ui.details.hidden = false;
  document.getElementById("details-title").textContent = name;
  render();
  clearInterval(detailsTimer);
  watchTopic(name);
  loadDetails();
  detailsTimer = setInterval(loadDetails, 1000);
}

function watchTopic(name) {
  if (watch) watch.sub.unsubscribe();
  watch = { stamps: [], count: 0, last: null, error: null };
  const w = watch;
  w.sub = ros.subscribe(name, (msg) => {
    const now = performance.now() / 1000;
    w.count += 1;
    w.last = msg;
    w.stamps.push(now);
    while (w.stamps.length && now - w.stamps[0] > RATE_WINDOW) w.stamps.shift();
  }, { onError: (text) => { w.error = text; } });
}

function rateOf(w) {
  const now = performance.now() / 1000;
  while (w.stamps.length && now - w.stamps[0] > RATE_WINDOW) w.stamps.shift();
  if (w.stamps.length < 2) return null;
  const span = w.stamps[w.stamps.length - 1] - w.stamps[0];
  return span > 0 ? (w.stamps.length - 1) / span : null;
}

function loadDetails() {
  if (!selectedTopic || !current || !current.graph) return;
  const info = current.graph.topics.find((t) => t.name === selectedTopic);
  const body = document.getElementById("details-body");
  body.textContent = "";
  if (!info) { body.textContent = `topic ${selectedTopic} is not in the graph`; return; }
  const row = (label, value, key) => {
    const dt = document.createElement("dt"); dt.textContent = label;
    const dd = document.createElement("dd"); dd.textContent = value; dd.dataset.key = key;
    body.append(dt, dd);
  };
  row("Type", info.type || "(unknown)", "type");
  row("Publishers", info.publishers.join(", ") || "none", "publishers");
  row("Subscribers", info.subscribers.join(", ") || "none", "subscribers");
  if (watch) {
    const rate = rateOf(watch);
    row("Rate", rate === null ? "no messages yet" : `${rate.toFixed(2)} Hz (${watch.count} messages)`, "rate");
    if (watch.error) row("Monitor", watch.error, "monitor");
  }
  document.getElementById("details-message").textContent = watch && watch.last ? toJson(watch.last) : "";
}

document.getElementById("close-details").addEventListener("click", () => {
  selectedTopic = null;
  clearInterval(detailsTimer);
  if (watch) { watch.sub.unsubscribe(); watch = null; }
  ui.details.hidden = true;
  render();
});
for (const input of [ui.mode, ui.group, ui.hideDebug, ui.hideDead, ui.hideLeaf]) input.addEventListener("change", render);
ui.filter.addEventListener("input", render);

let stopGraph = ros.watchGraph(onGraph);
document.getElementById("refresh").addEventListener("click", () => {
  // a fresh subscription brings the full graph and an immediate bus sweep
  stopGraph();
  known.pub.clear(); known.sub.clear(); known.srv.clear();
  stopGraph = ros.watchGraph(onGraph);
});
ros.on("channels", refreshState);
ros.on("status", (st) => { if (st.id === "master") { known.error = st.message; refreshState(); } });
ros.on("removeStatus", (ids) => { if (ids.includes("master")) { known.error = null; ui.status.className = ""; refreshState(); } });
ros.on("close", () => {
  known.pub.clear(); known.sub.clear(); known.srv.clear();
  ui.status.textContent = "connection to the gateway lost, retrying…";
  ui.status.className = "error";
});
