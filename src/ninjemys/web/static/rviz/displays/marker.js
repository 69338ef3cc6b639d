// The Marker and MarkerArray displays: visualization_msgs shapes, lifetimes, text labels.

import * as THREE from "three";
import { fromPose, stripSlash } from "/static/lib/tf.js";
import { setPose, disposeTree, arrowMesh } from "/static/rviz/util.js";
import { label } from "/static/rviz/labels.js";
import { markDirty } from "/static/rviz/context.js";
import { loadMesh } from "/static/rviz/meshes.js";
import { Display } from "/static/rviz/display.js";

// -- markers

export const MARKER_TYPES = ["ARROW", "CUBE", "SPHERE", "CYLINDER", "LINE_STRIP", "LINE_LIST", "CUBE_LIST", "SPHERE_LIST", "POINTS", "TEXT_VIEW_FACING", "MESH_RESOURCE", "TRIANGLE_LIST"];

/** The three.js object of a marker; a MESH_RESOURCE's file arrives later (``onError`` if it cannot). */
export function markerObject(m, onError = () => {}) {
  const c = m.color;
  const color = new THREE.Color(c.r, c.g, c.b);
  const opacity = c.a;
  const transparent = opacity < 1;
  const s = m.scale;
  const perPoint = m.colors && m.colors.length === m.points.length && m.points.length > 0;
  const pointColors = () => {
    const arr = new Float32Array(m.points.length * 3);
    m.colors.forEach((q, i) => arr.set([q.r, q.g, q.b], i * 3));
    return new THREE.BufferAttribute(arr, 3);
  };
  const pointsGeom = () => {
    const g = new THREE.BufferGeometry().setFromPoints(m.points.map((p) => new THREE.Vector3(p.x, p.y, p.z)));
    if (perPoint) g.setAttribute("color", pointColors());
    return g;
  };
  const lambert = () => new THREE.MeshLambertMaterial({ color, transparent, opacity });
  switch (m.type) {
    case 0: { // ARROW: pose + scale (length, width, height), or two points
      if (m.points.length >= 2) {
        const [p, q] = m.points;
        const dir = new THREE.Vector3(q.x - p.x, q.y - p.y, q.z - p.z);
        const len = dir.length();
        const head = s.z > 0 ? s.z : 0.23 * len;
        const g = arrowMesh(len, s.x, s.y, Math.min(head, len), color, opacity);
        const wrap = new THREE.Group();
        wrap.add(g);
        wrap.position.set(p.x, p.y, p.z);
        wrap.quaternion.setFromUnitVectors(new THREE.Vector3(1, 0, 0), dir.normalize());
        return wrap;
      }
      const g = arrowMesh(s.x, s.y, s.z, 0.23 * s.x, color, opacity);
      return g;
    }
    case 1: return new THREE.Mesh(new THREE.BoxGeometry(s.x, s.y, s.z), lambert());
    case 2: { const o = new THREE.Mesh(new THREE.SphereGeometry(0.5, 20, 14), lambert()); o.scale.set(s.x, s.y, s.z); return o; }
    case 3: { const o = new THREE.Mesh(new THREE.CylinderGeometry(0.5, 0.5, 1, 24), lambert()); o.rotation.x = Math.PI / 2; const w = new THREE.Group(); w.add(o); o.scale.set(s.x, s.z, s.y); return w; }
    case 4: return new THREE.Line(pointsGeom(), new THREE.LineBasicMaterial({ color: perPoint ? 0xffffff : color, vertexColors: perPoint, transparent, opacity }));
    case 5: return new THREE.LineSegments(pointsGeom(), new THREE.LineBasicMaterial({ color: perPoint ? 0xffffff : color, vertexColors: perPoint, transparent, opacity }));
    case 6: case 7: {
      const geom = m.type === 6 ? new THREE.BoxGeometry(s.x, s.y, s.z) : new THREE.SphereGeometry(0.5, 12, 8);
      if (m.type === 7) geom.scale(s.x, s.y, s.z);
      const inst = new THREE.InstancedMesh(geom, new THREE.MeshLambertMaterial({ color: perPoint ? 0xffffff : color, transparent, opacity }), m.points.length);
      const mat = new THREE.Matrix4();
      m.points.forEach((p, i) => {
        inst.setMatrixAt(i, mat.makeTranslation(p.x, p.y, p.z));
        if (perPoint) inst.setColorAt(i, new THREE.Color(m.colors[i].r, m.colors[i].g, m.colors[i].b));
      });
      return inst;
    }
    case 8: return new THREE.Points(pointsGeom(), new THREE.PointsMaterial({ color: perPoint ? 0xffffff : color, vertexColors: perPoint, size: s.x, transparent, opacity }));
    case 9: { const g = new THREE.Group(); g.userData.text = m.text; return g; }
    case 10: { // MESH_RESOURCE: the file through the web app, scaled; the marker's colour unless
      // a COLLADA file's or an OBJ's (its mtllib) own materials are asked for (mesh_use_embedded_materials)
      if (!m.mesh_resource) throw new Error("MESH_RESOURCE marker without a mesh_resource");
      const g = new THREE.Group();
      g.scale.set(s.x, s.y, s.z);
      const embedded = m.mesh_use_embedded_materials && /\.(dae|obj)$/i.test(m.mesh_resource);
      loadMesh(m.mesh_resource, lambert()).then((o) => {
        if (!embedded) o.traverse((x) => { if (x.isMesh) x.material = lambert(); });
        g.add(o);
        markDirty();
      }).catch((err) => onError(err));
      return g;
    }
    case 11: {
      const g = pointsGeom();
      g.computeVertexNormals();
      return new THREE.Mesh(g, new THREE.MeshLambertMaterial({ color: perPoint ? 0xffffff : color, vertexColors: perPoint, transparent, opacity, side: THREE.DoubleSide }));
    }
    default:
      throw new Error(`marker type ${MARKER_TYPES[m.type] || m.type} is not shown`);
  }
}

export class MarkerDisplay extends Display {
  constructor(cfg) { super(cfg); this.markers = new Map(); }
  onMessage(m) {
    const list = this.cfg.cls === "rviz/MarkerArray" ? m.markers : [m];
    for (const mk of list) this.apply(mk);
    this.setStatus("Markers", "ok", `${this.markers.size} markers`);
  }
  apply(m) {
    const key = `${m.ns}/${m.id}`;
    if (m.action === 3) { // DELETEALL
      for (const k of [...this.markers.keys()]) this.remove(k);
      return;
    }
    this.remove(key);
    if (m.action === 2) return;
    let obj;
    try {
      obj = markerObject(m, (err) => {
        if (this.markers.get(key)?.holder.children[0]?.children[0] === obj) this.setStatus(`Marker ${key}`, "error", `${m.mesh_resource}: ${err.message}`);
      });
    } catch (err) {
      this.setStatus(`Marker ${key}`, "error", err.message);
      return;
    }
    this.setStatus(`Marker ${key}`, null);
    const holder = new THREE.Group();
    const inner = new THREE.Group();
    setPose(inner, fromPose(m.pose));
    inner.add(obj);
    holder.add(inner);
    this.group.add(holder);
    const life = m.lifetime.secs + m.lifetime.nsecs / 1e9;
    this.markers.set(key, { holder, inner, text: m.type === 9 ? m.text : null, frame: m.header.frame_id, stamp: m.frame_locked ? 0 : m.header.stamp, expires: life > 0 ? performance.now() + life * 1000 : null });
  }
  remove(key) {
    const e = this.markers.get(key);
    if (!e) return;
    this.group.remove(e.holder);
    disposeTree(e.holder);
    this.markers.delete(key);
  }
  update() {
    this.group.position.set(0, 0, 0);
    this.group.quaternion.identity();
    if (!this.cfg.enabled) return;
    const now = performance.now();
    const wp = new THREE.Vector3();
    for (const [key, e] of this.markers) {
      if (e.expires !== null && now > e.expires) { this.remove(key); continue; }
      if (this.place(e.holder, e.frame, `Transform ${stripSlash(e.frame)}`, e.stamp) && e.text !== null) {
        e.inner.getWorldPosition(wp);
        label(`mk:${this.cfg.name}:${key}`, e.text, wp);
      }
    }
  }
}
