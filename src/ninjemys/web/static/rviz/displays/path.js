// The Path display: a nav_msgs/Path as a line.

import * as THREE from "three";
import { clearGroup } from "/static/rviz/util.js";
import { Display } from "/static/rviz/display.js";

export class PathDisplay extends Display {
  onMessage(m) {
    clearGroup(this.group);
    const pts = m.poses.map((p) => new THREE.Vector3(p.pose.position.x, p.pose.position.y, p.pose.position.z));
    const line = new THREE.Line(new THREE.BufferGeometry().setFromPoints(pts), new THREE.LineBasicMaterial({ color: this.color, transparent: true, opacity: Number(this.option("Alpha", 1)) }));
    this.group.add(line);
    this.frame = m.header.frame_id;
    this.stamp = m.header.stamp;
    this.setStatus("Path", "ok", `${m.poses.length} poses`);
  }
}
