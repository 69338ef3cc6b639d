// rviz's tools: 2D Pose Estimate, 2D Nav Goal and Publish Point, published on the topics the .rviz
// file names (advertised up front by main.js), with a preview arrow while a pose is dragged.

import { $, ros, scene, state, message } from "/static/rviz/context.js";
import { arrowMesh } from "/static/rviz/util.js";
import { canvas, view, groundPoint } from "/static/rviz/view.js";

const preview = arrowMesh(1, 0.05, 0.15, 0.3, 0x00ff00, 0.8);
preview.visible = false;
scene.add(preview);

export function setTool(tool) {
  state.activeTool = tool;
  for (const b of document.querySelectorAll("#rv-tools button[data-tool]")) b.classList.toggle("active", b.dataset.tool === tool);
  if (view.controls) view.controls.enabled = tool === "move";
}
for (const b of document.querySelectorAll("#rv-tools button[data-tool]")) b.addEventListener("click", () => setTool(b.dataset.tool));

function yawQuat(yaw) { return { x: 0, y: 0, z: Math.sin(yaw / 2), w: Math.cos(yaw / 2) }; }

function publishTool(tool, p, yaw) {
  const header = { seq: 0, stamp: ros.stamp(), frame_id: state.fixedFrame };
  if (tool === "goal") {
    const topic = state.toolTopics["rviz/SetGoal"];
    ros.advertise(topic, "geometry_msgs/PoseStamped").publish({ header, pose: { position: { x: p.x, y: p.y, z: 0 }, orientation: yawQuat(yaw) } });
    message(`goal ${p.x.toFixed(2)}, ${p.y.toFixed(2)}, ${(yaw * 180 / Math.PI).toFixed(0)}° → ${topic}`, "info");
  } else if (tool === "pose") {
    const topic = state.toolTopics["rviz/SetInitialPose"];
    const cov = new Array(36).fill(0);
    cov[0] = 0.25; cov[7] = 0.25; cov[35] = (Math.PI / 12) ** 2; // rviz's: 0.5 m, 15°
    ros.advertise(topic, "geometry_msgs/PoseWithCovarianceStamped").publish({ header, pose: { pose: { position: { x: p.x, y: p.y, z: 0 }, orientation: yawQuat(yaw) }, covariance: cov } });
    message(`initial pose ${p.x.toFixed(2)}, ${p.y.toFixed(2)}, ${(yaw * 180 / Math.PI).toFixed(0)}° → ${topic}`, "info");
  } else if (tool === "point") {
    const topic = state.toolTopics["rviz/PublishPoint"];
    ros.advertise(topic, "geometry_msgs/PointStamped").publish({ header, point: { x: p.x, y: p.y, z: p.z } });
    message(`point ${p.x.toFixed(2)}, ${p.y.toFixed(2)}, ${p.z.toFixed(2)} → ${topic}`, "info");
  }
}

canvas.addEventListener("pointerdown", (ev) => {
  if (state.activeTool === "move" || ev.button !== 0) return;
  const p = groundPoint(ev.clientX, ev.clientY);
  if (!p) return;
  if (state.activeTool === "point") { publishTool("point", p, 0); return; }
  state.drag = { start: p };
  canvas.setPointerCapture(ev.pointerId);
  preview.position.copy(p);
  preview.rotation.set(0, 0, 0);
  preview.visible = true;
});
canvas.addEventListener("pointermove", (ev) => {
  const p = groundPoint(ev.clientX, ev.clientY);
  if (p) $("rv-coords").textContent = `${state.fixedFrame}: ${p.x.toFixed(2)}, ${p.y.toFixed(2)}`;
  if (!state.drag || !p) return;
  preview.rotation.set(0, 0, Math.atan2(p.y - state.drag.start.y, p.x - state.drag.start.x));
});
canvas.addEventListener("pointerup", (ev) => {
  if (!state.drag) return;
  const p = groundPoint(ev.clientX, ev.clientY) || state.drag.start;
  const dx = p.x - state.drag.start.x, dy = p.y - state.drag.start.y;
  const yaw = Math.hypot(dx, dy) > 1e-6 ? Math.atan2(dy, dx) : 0;
  publishTool(state.activeTool, state.drag.start, yaw);
  state.drag = null;
  preview.visible = false;
  setTool("move"); // rviz's pose tools are one-shot
});
