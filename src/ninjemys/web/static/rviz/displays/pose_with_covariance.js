// The PoseWithCovariance display: the arrow and the 95% position ellipse.

import * as THREE from "three";
import { fromPose } from "/static/lib/tf.js";
import { setPose, clearGroup, arrowMesh } from "/static/rviz/util.js";
import { Display } from "/static/rviz/display.js";

/** The 95% ellipse of a 2D position covariance (x, y) as a line loop in the pose's parent frame. */
export function covarianceEllipse(cov, color) {
  const a = cov[0], b = cov[1], c = cov[7];
  const mean = (a + c) / 2, d = Math.sqrt(((a - c) / 2) ** 2 + b * b);
  const l1 = Math.max(mean + d, 0), l2 = Math.max(mean - d, 0);
  const angle = 0.5 * Math.atan2(2 * b, a - c);
  const k = Math.sqrt(5.991); // chi-square, 2 dof, 95%
  const r1 = k * Math.sqrt(l1), r2 = k * Math.sqrt(l2);
  const pts = [];
  for (let i = 0; i <= 48; i++) {
    const t = (i / 48) * 2 * Math.PI;
    const x = r1 * Math.cos(t), y = r2 * Math.sin(t);
    pts.push(new THREE.Vector3(x * Math.cos(angle) - y * Math.sin(angle), x * Math.sin(angle) + y * Math.cos(angle), 0));
  }
  const line = new THREE.Line(new THREE.BufferGeometry().setFromPoints(pts), new THREE.LineBasicMaterial({ color }));
  line.userData.radii = [r1, r2];
  return line;
}

export class PoseWithCovarianceDisplay extends Display {
  onMessage(m) {
    clearGroup(this.group);
    const T = fromPose(m.pose.pose);
    const a = arrowMesh(1.3, 0.1, 0.2, 0.3, this.color, Number(this.option("Alpha", 1)));
    setPose(a, T);
    const e = covarianceEllipse(m.pose.covariance, 0xff66ff);
    e.position.set(T.t[0], T.t[1], T.t[2] + 0.01);
    this.group.add(a, e);
    this.frame = m.header.frame_id;
    this.stamp = m.header.stamp;
    const [r1, r2] = e.userData.radii;
    this.setStatus("Covariance", "ok", `95% ellipse ${(2 * r1).toFixed(2)} × ${(2 * r2).toFixed(2)} m`);
  }
}
