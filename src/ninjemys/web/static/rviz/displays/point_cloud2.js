// The PointCloud2 display: float x, y, z (and rgb) fields as points, buffers reused.

import * as THREE from "three";
import { stripSlash } from "/static/lib/tf.js";
import { Display } from "/static/rviz/display.js";

export const FIELD_SIZE = { 1: 1, 2: 1, 3: 2, 4: 2, 5: 4, 6: 4, 7: 4, 8: 8 };
export class PointCloud2Display extends Display {
  constructor(cfg) {
    super(cfg);
    this.capacity = 0;
    this.geometry = new THREE.BufferGeometry();
    this.material = new THREE.PointsMaterial({ color: this.color, size: Number(this.option("Size (Pixels)", 2)), sizeAttenuation: false });
    this.points = new THREE.Points(this.geometry, this.material);
    this.points.frustumCulled = false;
    this.group.add(this.points);
  }
  onMessage(m) {
    const f = Object.fromEntries(m.fields.map((x) => [x.name, x]));
    if (!f.x || !f.y || !f.z) throw new Error("PointCloud2 has no x, y, z fields");
    if (m.is_bigendian) throw new Error("big-endian PointCloud2 is not supported");
    const n = m.width * m.height;
    const step = m.point_step;
    if (n * step > m.data.byteLength) throw new Error(`data holds ${m.data.byteLength} bytes, ${n} points of ${step} need ${n * step}`);
    if (n > this.capacity) {
      this.capacity = Math.max(n, this.capacity * 2);
      this.pos = new THREE.BufferAttribute(new Float32Array(this.capacity * 3), 3);
      this.col = new THREE.BufferAttribute(new Float32Array(this.capacity * 3), 3);
      this.pos.setUsage(THREE.DynamicDrawUsage);
      this.col.setUsage(THREE.DynamicDrawUsage);
      this.geometry.setAttribute("position", this.pos);
      this.geometry.setAttribute("color", this.col);
    }
    const out = this.pos.array;
    const rgb = f.rgb || f.rgba;
    const floatXYZ = [f.x, f.y, f.z].every((x) => x.datatype === 7 && x.offset % 4 === 0) && step % 4 === 0;
    let k = 0;
    if (floatXYZ) {
      const bytes = m.data.byteOffset % 4 === 0 ? m.data : m.data.slice();
      const fl = new Float32Array(bytes.buffer, bytes.byteOffset, Math.floor(bytes.byteLength / 4));
      const s = step / 4, ox = f.x.offset / 4, oy = f.y.offset / 4, oz = f.z.offset / 4;
      for (let i = 0; i < n; i++) {
        const b = i * s;
        const x = fl[b + ox], y = fl[b + oy], z = fl[b + oz];
        if (x !== x || y !== y || z !== z) continue; // NaN: not a point
        out[k++] = x; out[k++] = y; out[k++] = z;
      }
    } else {
      const dv = new DataView(m.data.buffer, m.data.byteOffset, m.data.byteLength);
      const get = (fld, o) => (fld.datatype === 8 ? dv.getFloat64(o, true) : dv.getFloat32(o, true));
      for (let i = 0; i < n; i++) {
        const b = i * step;
        const x = get(f.x, b + f.x.offset), y = get(f.y, b + f.y.offset), z = get(f.z, b + f.z.offset);
        if (x !== x || y !== y || z !== z) continue;
        out[k++] = x; out[k++] = y; out[k++] = z;
      }
    }
    const useRgb = rgb && this.option("Color Transformer", "RGB8") === "RGB8" && (rgb.datatype === 7 || rgb.datatype === 6);
    this.material.vertexColors = Boolean(useRgb);
    this.material.color = useRgb ? new THREE.Color(1, 1, 1) : this.color;
    this.material.needsUpdate = true;
    if (useRgb) {
      const c = this.col.array;
      let j = 0;
      for (let i = 0; i < n && j < k; i++) {
        const o = i * step + rgb.offset;
        c[j++] = m.data[o + 2] / 255; c[j++] = m.data[o + 1] / 255; c[j++] = m.data[o] / 255;
      }
      this.col.needsUpdate = true;
    }
    this.pos.needsUpdate = true;
    this.geometry.setDrawRange(0, k / 3);
    this.frame = m.header.frame_id;
    this.stamp = m.header.stamp;
    this.setStatus("Points", "ok", `${k / 3} points in [${stripSlash(this.frame)}]`);
  }
}
