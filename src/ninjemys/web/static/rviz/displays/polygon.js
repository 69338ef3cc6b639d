// The Polygon display: a PolygonStamped as a closed line (a robot footprint).

import * as THREE from "three";
import { clearGroup } from "/static/rviz/util.js";
import { Display } from "/static/rviz/display.js";

export class PolygonDisplay extends Display {
  onMessage(m) {
    clearGroup(this.group);
    const pts = m.polygon.points.map((p) => new THREE.Vector3(p.x, p.y, p.z));
    const line = new THREE.LineLoop(new THREE.BufferGeometry().setFromPoints(pts), new THREE.LineBasicMaterial({ color: this.color }));
    this.group.add(line);
    this.frame = m.header.frame_id;
    this.stamp = m.header.stamp;
  }
}
