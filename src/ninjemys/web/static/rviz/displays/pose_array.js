// The PoseArray display: thousands of arrows as line segments (amcl's particles).

import * as THREE from "three";
import { fromPose, yawOf } from "/static/lib/tf.js";
import { clearGroup } from "/static/rviz/util.js";
import { Display } from "/static/rviz/display.js";

/** Arrows as line segments (cheap for thousands: amcl's particles). */
export function arrowSegments(poses, length, color) {
  const pts = new Float32Array(poses.length * 18);
  let k = 0;
  for (const p of poses) {
    const T = fromPose(p);
    const yaw = yawOf(T.q);
    const c = Math.cos(yaw), s = Math.sin(yaw);
    const [x, y, z] = T.t;
    const tx = x + length * c, ty = y + length * s;
    const h = length * 0.3;
    const seg = [x, y, z, tx, ty, z,
      tx, ty, z, tx - h * Math.cos(yaw - 0.5), ty - h * Math.sin(yaw - 0.5), z,
      tx, ty, z, tx - h * Math.cos(yaw + 0.5), ty - h * Math.sin(yaw + 0.5), z];
    pts.set(seg, k);
    k += 18;
  }
  const g = new THREE.BufferGeometry();
  g.setAttribute("position", new THREE.BufferAttribute(pts, 3));
  return new THREE.LineSegments(g, new THREE.LineBasicMaterial({ color }));
}

export class PoseArrayDisplay extends Display {
  onMessage(m) {
    clearGroup(this.group);
    this.group.add(arrowSegments(m.poses, Number(this.option("Arrow Length", 0.3)), this.color));
    this.frame = m.header.frame_id;
    this.stamp = m.header.stamp;
    this.setStatus("Poses", "ok", `${m.poses.length} poses`);
  }
}
