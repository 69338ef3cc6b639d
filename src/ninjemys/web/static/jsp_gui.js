// joint_state_publisher_gui's page: one slider per free joint of the robot description, read through
// the gateway; moving a slider publishes a sensor_msgs/JointState on the node's ~slider_input topic.
import { RosClient } from "/static/lib/rosclient.js";

const params = new URLSearchParams(location.search);
const descriptionParam = params.get("description") || "/robot_description";
const inputTopic = params.get("input") || "/joint_state_publisher_gui/slider_input";
const privateNs = params.get("ns") || "/joint_state_publisher_gui/";
const ros = new RosClient();
const msg = document.getElementById("jsp-msg");
const box = document.getElementById("jsp-joints");
const sliders = new Map();
window.jspGui = { sliders, ready: false };

/** The free joints of a URDF: movable, with limits (continuous: -pi..pi), not mimicking another. */
function freeJoints(xml, { zeros = {}, dependent = {}, useMimic = true } = {}) {
  const doc = new DOMParser().parseFromString(xml, "application/xml");
  if (doc.querySelector("parsererror")) throw new Error(`${descriptionParam} is not well-formed XML`);
  const out = [];
  for (const j of doc.documentElement.children) {
    if (j.tagName !== "joint") continue;
    const type = j.getAttribute("type");
    if (!["revolute", "continuous", "prismatic"].includes(type)) continue;
    if (useMimic && [...j.children].some((c) => c.tagName === "mimic")) continue;
    if (Object.prototype.hasOwnProperty.call(dependent, j.getAttribute("name"))) continue;
    const limit = [...j.children].find((c) => c.tagName === "limit");
    let lo = -Math.PI, hi = Math.PI;
    if (type !== "continuous") {
      if (!limit || limit.getAttribute("lower") === null || limit.getAttribute("upper") === null) continue;
      lo = Number(limit.getAttribute("lower"));
      hi = Number(limit.getAttribute("upper"));
    }
    const given = Number(zeros[j.getAttribute("name")]);
    const zero = given ? given : lo > 0 || hi < 0 ? (lo + hi) / 2 : 0;
    out.push({ name: j.getAttribute("name"), lo, hi, zero });
  }
  return out;
}

function publishAll(pub) {
  const names = [...sliders.keys()];
  pub.publish({ name: names, position: names.map((n) => Number(sliders.get(n).input.value)), velocity: [], effort: [] });
}

async function main() {
  await ros.ready();
  // the node reads each of these as ~name, then name in its namespace: so does the page
  const nodeNs = privateNs.replace(/[^/]+\/$/, "");
  const names = ["dependent_joints", "zeros", "use_mimic_tags"].flatMap((n) => [privateNs + n, nodeNs + n]);
  const got = await ros.getParameters([descriptionParam, ...names]);
  const pick = (n, fallback) => got[privateNs + n] ?? got[nodeNs + n] ?? fallback;
  const description = got[descriptionParam];
  if (typeof description !== "string") {
    msg.textContent = `parameter ${descriptionParam} is not set`;
    return;
  }
  const joints = freeJoints(description, {
    zeros: pick("zeros", {}) || {},
    dependent: pick("dependent_joints", {}) || {},
    useMimic: pick("use_mimic_tags", true) !== false,
  });
  const pub = ros.advertise(inputTopic, "sensor_msgs/JointState");
  for (const j of joints) {
    const row = document.createElement("label");
    row.className = "jsp-joint";
    const name = document.createElement("span");
    name.textContent = j.name;
    const input = document.createElement("input");
    Object.assign(input, { type: "range", min: j.lo, max: j.hi, step: (j.hi - j.lo) / 1000 || 0.001, value: j.zero });
    input.dataset.joint = j.name;
    const out = document.createElement("output");
    out.textContent = Number(input.value).toFixed(3);
    input.addEventListener("input", () => {
      out.textContent = Number(input.value).toFixed(3);
      publishAll(pub);
    });
    row.append(name, input, out);
    box.append(row);
    sliders.set(j.name, { input, out, joint: j });
  }
  const set = (fn) => {
    for (const { input, out, joint } of sliders.values()) {
      input.value = fn(joint);
      out.textContent = Number(input.value).toFixed(3);
    }
    publishAll(pub);
  };
  document.getElementById("jsp-center").onclick = () => set((j) => j.zero);
  document.getElementById("jsp-randomize").onclick = () => set((j) => j.lo + Math.random() * (j.hi - j.lo));
  msg.textContent = joints.length ? "" : "the robot has no free joints";
  msg.className = joints.length ? "" : "rq-msg info";
  window.jspGui.ready = true;
}

main().catch((err) => { msg.textContent = String(err.message || err); msg.className = "rq-msg error"; });
