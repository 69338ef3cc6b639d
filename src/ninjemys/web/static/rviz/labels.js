// Text labels (frame names, marker text) as HTML spans over the canvas, placed after each render.

import * as THREE from "three";
import { $ } from "/static/rviz/context.js";

const labelLayer = $("rv-labels");
const labels = new Map(); // key -> {el, pos: Vector3 (world)}
export function label(key, text, worldPos) {
  let l = labels.get(key);
  if (!l) {
    l = { el: document.createElement("span"), pos: new THREE.Vector3(), used: true };
    l.el.dataset.key = key;
    labelLayer.appendChild(l.el);
    labels.set(key, l);
  }
  if (l.el.textContent !== text) l.el.textContent = text;
  l.pos.copy(worldPos);
  l.used = true;
}
/** Move every label used since the last call to its point; drop the ones not used. */
export function drawLabels(camera, w, h) {
  for (const [key, l] of labels) {
    if (!l.used) { l.el.remove(); labels.delete(key); continue; }
    l.used = false;
    const v = l.pos.clone().project(camera);
    const visible = v.z > -1 && v.z < 1;
    l.el.style.display = visible ? "" : "none";
    l.el.style.left = `${((v.x + 1) / 2) * w}px`;
    l.el.style.top = `${((1 - v.y) / 2) * h}px`;
  }
}
