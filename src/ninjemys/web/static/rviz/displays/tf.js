// The TF display: axes for every frame, lines to their parents, names as labels.

import * as THREE from "three";
import { tf, scene, state } from "/static/rviz/context.js";
import { setPose, disposeTree } from "/static/rviz/util.js";
import { label } from "/static/rviz/labels.js";
import { Display } from "/static/rviz/display.js";

export class TFDisplay extends Display {
  constructor(cfg) {
    super(cfg);
    this.axes = new Map();
    this.lines = new THREE.LineSegments(new THREE.BufferGeometry(), new THREE.LineBasicMaterial({ color: 0xffee00 }));
    scene.add(this.lines);
  }
  destroy() { super.destroy(); scene.remove(this.lines); disposeTree(this.lines); }
  update() {
    this.lines.visible = this.cfg.enabled;
    if (!this.cfg.enabled) return;
    const scale = Number(this.option("Marker Scale", 0.3));
    const names = tf.frameNames();
    const pts = [];
    let shown = 0;
    for (const name of names) {
      let ax = this.axes.get(name);
      if (!ax) {
        ax = new THREE.AxesHelper(1);
        this.axes.set(name, ax);
        this.group.add(ax);
      }
      ax.scale.setScalar(scale);
      const T = tf.lookup(state.fixedFrame, name);
      if (!T) { ax.visible = false; continue; }
      ax.visible = true;
      setPose(ax, T);
      shown++;
      if (this.option("Show Names", true)) label(`tf:${name}`, name, ax.position);
      const parent = tf.frames.get(name)?.parent;
      const P = parent ? tf.lookup(state.fixedFrame, parent) : null;
      if (P) pts.push(T.t[0], T.t[1], T.t[2], P.t[0], P.t[1], P.t[2]);
    }
    for (const [name, ax] of this.axes) if (!names.includes(name)) { this.group.remove(ax); this.axes.delete(name); }
    this.lines.geometry.setAttribute("position", new THREE.Float32BufferAttribute(pts, 3));
    this.group.position.set(0, 0, 0);
    this.group.quaternion.identity();
    this.setStatus("Frames", shown ? "ok" : "warn", shown ? `${shown} frames` : `no frames connected to [${state.fixedFrame}]`);
  }
}
