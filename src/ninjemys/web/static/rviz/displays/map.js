// The Map display: an OccupancyGrid as a texture, in rviz's three palettes, with _updates.

import * as THREE from "three";
import { fromPose } from "/static/lib/tf.js";
import { ros } from "/static/rviz/context.js";
import { setPose, clearGroup } from "/static/rviz/util.js";
import { Display } from "/static/rviz/display.js";

/** rviz's three palettes for occupancy values (RGBA bytes for 0..100, -1 and the rest). */
export function palette(scheme) {
  const p = new Uint8Array(256 * 4);
  for (let v = 0; v < 256; v++) {
    const s = v > 127 ? v - 256 : v; // the int8 value
    let r, g, b, a = 255;
    if (scheme === "costmap") {
      if (s === 0) { r = g = b = 0; a = 0; }
      else if (s >= 1 && s <= 98) { const t = s / 98; r = Math.round(255 * t); g = 0; b = Math.round(255 * (1 - t)); }
      else if (s === 99) { r = 0; g = 255; b = 255; }
      else if (s === 100) { r = 255; g = 0; b = 255; }
      else if (s === -1) { r = 0x70; g = 0x89; b = 0x86; a = 0; }
      else { r = 0; g = 255; b = 0; }
    } else if (scheme === "raw") {
      r = g = b = v;
    } else {
      if (s >= 0 && s <= 100) { r = g = b = Math.round(255 - (255 * s) / 100); }
      else if (s === -1) { r = 0x70; g = 0x89; b = 0x86; }
      else { r = 255; g = 0; b = 255; }
    }
    p.set([r, g, b, a], v * 4);
  }
  return p;
}

export class MapDisplay extends Display {
  constructor(cfg) {
    super(cfg);
    this.mesh = null;
    this.updatesSub = null;
  }
  start() {
    super.start();
    if (this.cfg.enabled && this.cfg.topic && this.option("Use Timestamp", false) === false) {
      this.updatesSub = ros.subscribe(`${this.cfg.topic}_updates`, (u) => this.onUpdate(u), { type: "map_msgs/OccupancyGridUpdate" });
    }
  }
  stop() { super.stop(); if (this.updatesSub) { this.updatesSub.unsubscribe(); this.updatesSub = null; } }
  onMessage(m) {
    const { width, height, resolution } = m.info;
    if (width * height !== m.data.length) throw new Error(`map is ${width}×${height} but has ${m.data.length} cells`);
    this.pal = palette(String(this.option("Color Scheme", "map")));
    this.width = width; this.height = height;
    this.rgba = new Uint8Array(width * height * 4);
    this.paint(m.data, 0, 0, width, height);
    clearGroup(this.group);
    this.texture = new THREE.DataTexture(this.rgba, width, height, THREE.RGBAFormat);
    this.texture.magFilter = THREE.NearestFilter;
    this.texture.minFilter = THREE.NearestFilter;
    this.texture.needsUpdate = true;
    const alpha = Number(this.option("Alpha", 0.7));
    const mat = new THREE.MeshBasicMaterial({ map: this.texture, transparent: true, opacity: alpha, side: THREE.DoubleSide, depthWrite: alpha >= 1 });
    const plane = new THREE.Mesh(new THREE.PlaneGeometry(width * resolution, height * resolution), mat);
    // the plane's centre, in the origin's frame; then the origin pose in the header frame
    const origin = new THREE.Group();
    setPose(origin, fromPose(m.info.origin));
    plane.position.set((width * resolution) / 2, (height * resolution) / 2, this.option("Draw Behind", false) ? -0.01 : 0);
    plane.renderOrder = -1;
    origin.add(plane);
    this.group.add(origin);
    this.frame = m.header.frame_id;
    this.stamp = m.header.stamp;
    this.setStatus("Map", "ok", `${width}×${height} at ${resolution.toFixed(3)} m/cell`);
  }
  paint(data, x0, y0, w, h) {
    const pal = this.pal, out = this.rgba, W = this.width;
    for (let y = 0; y < h; y++) {
      for (let x = 0; x < w; x++) {
        const v = data[y * w + x] & 255;
        const o = ((y0 + y) * W + x0 + x) * 4;
        out[o] = pal[v * 4]; out[o + 1] = pal[v * 4 + 1]; out[o + 2] = pal[v * 4 + 2]; out[o + 3] = pal[v * 4 + 3];
      }
    }
  }
  onUpdate(u) {
    if (!this.rgba || u.x + u.width > this.width || u.y + u.height > this.height) return;
    this.paint(u.data, u.x, u.y, u.width, u.height);
    this.texture.needsUpdate = true;
  }
}
