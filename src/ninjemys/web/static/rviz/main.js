// rviz in the browser: a three.js scene in the fixed frame, displays fed by the gateway (RosClient),
// every display placed through the tf buffer each frame. See docs/rviz.md.
//
// The page's modules: context.js (shared connection, tf, scene, state), view.js (renderer, cameras),
// display.js (the base class) with one module per display in displays/ and registry.js as their
// index, panel.js (the display list), tools.js (pose, goal, point), loop.js (the render loop),
// meshes.js (mesh files for RobotModel). This one loads the .rviz config and starts the loop.
//
// URL parameters (for links and tests): view=top|orbit, cx, cy (view centre, m), scale (px per m in
// the top view), fixed (fixed frame).

import { $, params, ros, tf, scene, displays, state, message } from "/static/rviz/context.js";
import { rvizColor } from "/static/rviz/util.js";
import { view, setView, groundPoint, project } from "/static/rviz/view.js";
import { addDisplay, refreshTopicLists, setFixedFrame, pageState } from "/static/rviz/panel.js";
import { setTool } from "/static/rviz/tools.js";
import { frame, stats, frameHooks } from "/static/rviz/loop.js";
import { startGamepad } from "/static/lib/gamepad.js";

ros.on("open", () => { $("rv-conn").textContent = "connected"; });
ros.on("close", () => { $("rv-conn").textContent = "disconnected: reconnecting…"; });
ros.on("status", (s) => { if (s.level >= 2) message(`gateway: ${s.message}`); });
ros.on("channels", () => refreshTopicLists());

let config = null;

async function loadConfig() {
  let body;
  try {
    const resp = await fetch("/api/rviz/config");
    body = await resp.json();
  } catch (err) {
    message(`cannot load the display config: ${err.message}`);
    body = { fixedFrame: "map", displays: [], unsupported: [], tools: state.toolTopics };
  }
  config = body;
  if (body.error) message(`config: ${body.error}`);
  state.toolTopics = { ...state.toolTopics, ...(body.tools || {}) };
  const toolTopics = state.toolTopics;
  // advertised up front, as rviz's tools do: subscribers are connected before the first click
  ros.advertise(toolTopics["rviz/SetGoal"], "geometry_msgs/PoseStamped");
  ros.advertise(toolTopics["rviz/SetInitialPose"], "geometry_msgs/PoseWithCovarianceStamped");
  ros.advertise(toolTopics["rviz/PublishPoint"], "geometry_msgs/PointStamped");
  setFixedFrame(params.get("fixed") || body.fixedFrame || "map");
  if (Number(body.frameRate) > 0) state.frameInterval = 1000 / Number(body.frameRate);
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
if (!params.has("scale") && fileView.scale) view.topScale = Number(fileView.scale);
if (!params.has("cx") && fileView.x !== undefined) view.centre[0] = Number(fileView.x);
if (!params.has("cy") && fileView.y !== undefined) view.centre[1] = Number(fileView.y);
setView(params.get("view") || fileView.mode || "orbit");
requestAnimationFrame(frame);

// a game controller publishes sensor_msgs/Joy on /joy, as joy_node would (run teleop_twist_joy to drive)
const gamepad = startGamepad(ros, {
  status: (id) => { $("rv-gamepad").textContent = id ? `gamepad: ${id} → /joy` : ""; document.body.dataset.gamepad = id || ""; },
});

/** For tests and benchmarks: the page's state, and the page pixel of a fixed-frame point. */
window.rviz = {
  ros, tf, displays, stats, frameHooks, groundPoint, setFixedFrame, addDisplay, pageState, setTool, project,
  gamepad: gamepad.state,
  get fixedFrame() { return state.fixedFrame; },
  ready: true,
};
