// The LaserScan display: the ranges within limits as points in the scan's frame.

import * as THREE from "three";
import { stripSlash } from "/static/lib/tf.js";
import { Display } from "/static/rviz/display.js";

export class LaserScanDisplay extends Display {
  constructor(cfg) {
    super(cfg);
    this.geometry = new THREE.BufferGeometry();
    this.points = new THREE.Points(this.geometry, new THREE.PointsMaterial({ color: this.color, size: Number(this.option("Size (Pixels)", 3)), sizeAttenuation: false }));
    this.group.add(this.points);
  }
  start() { super.start(); this.points.material.color = this.color; }
  onMessage(m) {
    const n = m.ranges.length;
    const pos = new Float32Array(n * 3);
    let k = 0;
    for (let i = 0; i < n; i++) {
      const r = m.ranges[i];
      if (!(r >= m.range_min && r <= m.range_max)) continue; // NaN, inf and out of range are skipped
      const a = m.angle_min + i * m.angle_increment;
      pos[k++] = r * Math.cos(a); pos[k++] = r * Math.sin(a); pos[k++] = 0;
    }
    this.geometry.setAttribute("position", new THREE.BufferAttribute(pos.subarray(0, k), 3));
    this.geometry.computeBoundingSphere();
    this.frame = m.header.frame_id;
    this.stamp = m.header.stamp;
    this.setStatus("Points", "ok", `${k / 3} points in [${stripSlash(this.frame)}]`);
  }
}
