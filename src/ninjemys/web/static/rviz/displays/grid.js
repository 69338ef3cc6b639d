// The Grid display: rviz's reference grid in the fixed frame's XY plane.

import * as THREE from "three";
import { clearGroup } from "/static/rviz/util.js";
import { Display } from "/static/rviz/display.js";

export class GridDisplay extends Display {
  start() {
    super.start();
    clearGroup(this.group);
    const count = Number(this.option("Plane Cell Count", 10));
    const cell = Number(this.option("Cell Size", 1));
    const grid = new THREE.GridHelper(count * cell, count, this.color, this.color);
    grid.rotation.x = Math.PI / 2; // GridHelper lies in XZ; rviz's grid is in the XY plane
    grid.material.transparent = true;
    grid.material.opacity = Number(this.option("Alpha", 0.5));
    this.group.add(grid);
    this.setStatus("Grid", "ok", `${count}×${count} cells of ${cell} m in the fixed frame`);
  }
  update() { this.group.position.set(0, 0, 0); this.group.quaternion.identity(); }
}
