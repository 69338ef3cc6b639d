// The display panel: one entry per display (enable, name, topic, colour, status), the Add and Save
// buttons, the fixed frame field, and the page state that Save writes back to the .rviz file.

import { stripSlash } from "/static/lib/tf.js";
import { $, ros, displays, state, message } from "/static/rviz/context.js";
import { toRviz } from "/static/rviz/util.js";
import { MSG_TYPE, DEFAULT_COLOR } from "/static/rviz/display.js";
import { DISPLAY_CLASSES } from "/static/rviz/registry.js";

export function addDisplay(cfg) {
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

export function refreshTopicLists() {
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

export function setFixedFrame(frame) {
  state.fixedFrame = stripSlash(frame) || "map";
  state.dirty = true;
  $("rv-fixed").value = state.fixedFrame;
  for (const d of displays) d.onFixedFrame?.(); // displays that keep history in the fixed frame restart
}
$("rv-fixed").addEventListener("change", (ev) => setFixedFrame(ev.target.value));

export function pageState() {
  return { fixedFrame: state.fixedFrame, displays: displays.map((d) => ({ cls: d.cfg.cls, name: d.cfg.name, enabled: d.cfg.enabled, topic: d.cfg.topic || "", color: d.cfg.color || DEFAULT_COLOR[d.cfg.cls] || null, options: d.cfg.options || {} })) };
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
