// The render loop: when something changed (or once a second), update every display through tf, keep
// the fixed-frame list and its status current, render, place the labels, call the frame hooks.

import { $, tf, scene, displays, state } from "/static/rviz/context.js";
import { drawLabels } from "/static/rviz/labels.js";
import { renderer, view, size } from "/static/rviz/view.js";

export const stats = { frames: 0, frameMs: [] };
export const frameHooks = []; // called after each render (benchmarks: publish-to-paint)
let lastRender = 0;

export function frame(now) {
  requestAnimationFrame(frame);
  if (now - lastRender < state.frameInterval - 2) return;
  if (!state.dirty && now - lastRender < 1000 && !state.drag) return;
  state.dirty = false;
  lastRender = now;
  const t0 = performance.now();
  const known = tf.frameNames();
  const list = $("rv-frames");
  if (list.dataset.names !== known.join()) {
    list.dataset.names = known.join();
    list.replaceChildren(...known.map((n) => Object.assign(document.createElement("option"), { value: n })));
  }
  const fs = $("rv-fixed-status");
  const fixedOk = tf.hasFrame(state.fixedFrame) || known.length === 0;
  const text = fixedOk ? "" : `Fixed Frame: Frame [${state.fixedFrame}] does not exist`;
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
  view.controls?.update();
  renderer.render(scene, view.camera);
  const [w, h] = size();
  drawLabels(view.camera, w, h);
  for (const fn of frameHooks) fn();
  stats.frames++;
  stats.frameMs.push(performance.now() - t0);
  if (stats.frameMs.length > 2000) stats.frameMs.shift();
}
