// The rqt page: every plugin as a tab, all on one gateway connection (RosClient).
// ?tool=<id> opens that tab; the plugins read their own arguments from the URL.

import { RosClient } from "../lib/rosclient.js";
import { el } from "./common.js";
import { PlotTool } from "./plot.js";
import { ConsoleTool, LoggerLevelTool } from "./console.js";
import { BagTool } from "./bag.js";
import { ImageViewTool } from "./image.js";
import { TfTreeTool, TopicTool, PublisherTool, ServiceCallerTool } from "./monitor.js";
import { ReconfigureTool, AxClientTool } from "./reconfigure.js";

class GraphTool {
  constructor(pane) { pane.append(el("iframe", { src: "/graph", title: "node graph" })); }
}

const TOOLS = [
  ["graph", "Node Graph", GraphTool],
  ["plot", "Plot", PlotTool],
  ["console", "Console", ConsoleTool],
  ["logger_level", "Logger Level", LoggerLevelTool],
  ["bag", "Bag", BagTool],
  ["image_view", "Image View", ImageViewTool],
  ["tf_tree", "TF Tree", TfTreeTool],
  ["reconfigure", "Reconfigure", ReconfigureTool],
  ["topic", "Topic Monitor", TopicTool],
  ["publisher", "Message Publisher", PublisherTool],
  ["service_caller", "Service Caller", ServiceCallerTool],
  ["axclient", "Action Client", AxClientTool],
];

const params = new URLSearchParams(location.search);
const ros = new RosClient();
const tabs = document.getElementById("rqt-tabs");
const panes = document.getElementById("rqt-panes");
const conn = document.getElementById("rqt-conn");
const tools = {};
const app = { ros, tools, params, ready: false, show };
window.rqt = app;

ros.on("open", () => { conn.textContent = ""; });
ros.on("close", () => { conn.textContent = "gateway connection lost: reconnecting…"; });
ros.on("status", (s) => { if (s.level >= 2) conn.textContent = s.message; });

const buttons = {};
const paneOf = {};
for (const [id, title] of TOOLS) {
  buttons[id] = el("button", { role: "tab", "data-tool": id, onclick: () => show(id) }, title);
  paneOf[id] = el("section", { class: "rq-pane", id: `pane-${id}`, "data-tool": id });
  tabs.append(buttons[id]);
  panes.append(paneOf[id]);
}

/** Open a tab; its plugin starts the first time it is shown (so a closed tab costs nothing). */
function show(id) {
  const entry = TOOLS.find((t) => t[0] === id) || TOOLS[0];
  for (const [other] of TOOLS) {
    buttons[other].classList.toggle("active", other === entry[0]);
    paneOf[other].classList.toggle("active", other === entry[0]);
  }
  if (!tools[entry[0]]) {
    try {
      tools[entry[0]] = new entry[2](paneOf[entry[0]], ros, params);
    } catch (err) {
      paneOf[entry[0]].append(el("div", { class: "rq-msg" }, `${entry[1]}: ${err.message}`));
    }
  }
  const url = new URL(location.href);
  if (url.searchParams.get("tool") !== entry[0]) {
    url.searchParams.set("tool", entry[0]);
    history.replaceState(null, "", url);
  }
}

show(params.get("tool") || "graph");
ros.ready().then(() => { app.ready = true; });
