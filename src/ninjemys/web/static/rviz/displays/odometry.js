// The Odometry display: arrows kept where the robot was, in the fixed frame.

import { TfBuffer, fromPose, compose, yawOf } from "/static/lib/tf.js";
import { tf, state } from "/static/rviz/context.js";
import { setPose, disposeTree, clearGroup, arrowMesh } from "/static/rviz/util.js";
import { Display } from "/static/rviz/display.js";

export class OdometryDisplay extends Display {
  constructor(cfg) { super(cfg); this.kept = []; this.last = null; }
  onMessage(m) {
    // rviz keeps arrows where the robot was, in the fixed frame at the time they arrived
    const T = tf.lookup(state.fixedFrame, m.header.frame_id, m.header.stamp);
    if (!T) { this.setStatus("Transform", "error", TfBuffer.missing(m.header.frame_id, state.fixedFrame)); return; }
    this.setStatus("Transform", null);
    const P = compose(T, fromPose(m.pose.pose));
    const tol = Number(this.option("Position Tolerance", 0.1));
    const atol = Number(this.option("Angle Tolerance", 0.1));
    if (this.last) {
      const dd = Math.hypot(P.t[0] - this.last.t[0], P.t[1] - this.last.t[1], P.t[2] - this.last.t[2]);
      const da = Math.abs(yawOf(P.q) - yawOf(this.last.q));
      if (dd < tol && da < atol) return;
    }
    this.last = P;
    const a = arrowMesh(0.4, 0.03, 0.08, 0.12, this.color);
    setPose(a, P);
    this.group.add(a);
    this.kept.push(a);
    const keep = Number(this.option("Keep", 100));
    while (this.kept.length > keep) { const old = this.kept.shift(); this.group.remove(old); disposeTree(old); }
    this.setStatus("Arrows", "ok", `${this.kept.length} arrows`);
  }
  update() { this.group.position.set(0, 0, 0); this.group.quaternion.identity(); }
  /** Arrows kept in the old fixed frame mean nothing in the new one: start over. */
  onFixedFrame() { this.start(); clearGroup(this.group); this.kept = []; this.last = null; }
}
