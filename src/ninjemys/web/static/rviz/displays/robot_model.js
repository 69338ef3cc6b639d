// The RobotModel display: URDF links (shapes and meshes) placed by tf or through their joints.

import * as THREE from "three";
import { TfBuffer, compose } from "/static/lib/tf.js";
import { ros, tf, state } from "/static/rviz/context.js";
import { setPose, clearGroup } from "/static/rviz/util.js";
import { Display } from "/static/rviz/display.js";
import { loadMesh } from "/static/rviz/meshes.js";

export class RobotModelDisplay extends Display {
  constructor(cfg) { super(cfg); this.links = new Map(); this.joints = new Map(); }
  async start() {
    super.start();
    clearGroup(this.group);
    this.links.clear();
    this.joints.clear();
    if (!this.cfg.enabled) return;
    const param = this.cfg.topic || "robot_description";
    const name = param.startsWith("/") ? param : `/${param}`;
    let values;
    try {
      values = await ros.getParameters([name]);
    } catch (err) {
      this.setStatus("URDF", "error", `cannot read ${name}: ${err.message}`);
      return;
    }
    const text = values[name];
    if (typeof text !== "string" || !text.trim()) {
      this.setStatus("URDF", "error", `Parameter [${param}] does not exist, and was not found by searchParam()`);
      return;
    }
    try {
      this.load(text);
      state.dirty = true;
      this.setStatus("URDF", "ok", `${this.links.size} links from ${name}`);
    } catch (err) {
      this.setStatus("URDF", "error", `URDF in ${name}: ${err.message}`);
    }
  }
  load(text) {
    const doc = new DOMParser().parseFromString(text, "application/xml");
    const err = doc.querySelector("parsererror");
    if (err) throw new Error(err.textContent.split("\n")[0]);
    const xyz = (el, attr, d = [0, 0, 0]) => (el && el.getAttribute(attr) ? el.getAttribute(attr).trim().split(/\s+/).map(Number) : d);
    const originOf = (el) => {
      const o = el?.querySelector(":scope > origin");
      const [r, p, y] = xyz(o, "rpy");
      const q = new THREE.Quaternion().setFromEuler(new THREE.Euler(r, p, y, "ZYX"));
      return { t: xyz(o, "xyz"), q: [q.x, q.y, q.z, q.w] };
    };
    const alpha = Number(this.option("Alpha", 1));
    // materials named at the top level, used by name in visuals (<material name="blue"/>)
    const named = new Map();
    for (const m of doc.querySelectorAll("robot > material")) {
      const rgba = m.querySelector("color")?.getAttribute("rgba");
      if (rgba) named.set(m.getAttribute("name"), rgba);
    }
    const meshes = [];
    for (const link of doc.querySelectorAll("robot > link")) {
      const g = new THREE.Group();
      const shapes = link.querySelectorAll(":scope > visual");
      const list = shapes.length ? shapes : link.querySelectorAll(":scope > collision");
      for (const v of list) {
        const geo = v.querySelector("geometry");
        let mesh = null;
        const matEl = v.querySelector(":scope > material");
        const rgba = matEl?.querySelector("color")?.getAttribute("rgba") || named.get(matEl?.getAttribute("name"));
        const col = rgba ? rgba.trim().split(/\s+/).map(Number) : [0.8, 0.8, 0.8, 1];
        const mat = new THREE.MeshLambertMaterial({ color: new THREE.Color(col[0], col[1], col[2]), transparent: alpha < 1, opacity: alpha });
        const box = geo?.querySelector("box"), cyl = geo?.querySelector("cylinder"), sph = geo?.querySelector("sphere");
        if (box) { const [x, y, z] = xyz(box, "size", [0.1, 0.1, 0.1]); mesh = new THREE.Mesh(new THREE.BoxGeometry(x, y, z), mat); }
        else if (cyl) {
          const r = Number(cyl.getAttribute("radius")), l = Number(cyl.getAttribute("length"));
          const c = new THREE.Mesh(new THREE.CylinderGeometry(r, r, l, 24), mat);
          c.rotation.x = Math.PI / 2; // URDF cylinders run along z, three's along y
          mesh = new THREE.Group(); mesh.add(c);
        } else if (sph) mesh = new THREE.Mesh(new THREE.SphereGeometry(Number(sph.getAttribute("radius")), 20, 14), mat);
        else if (geo?.querySelector("mesh")) {
          // filled in when the file arrives; the link is placed meanwhile
          const m = geo.querySelector("mesh");
          mesh = new THREE.Group();
          mesh.scale.set(...xyz(m, "scale", [1, 1, 1]));
          meshes.push({ uri: (m.getAttribute("filename") || "").trim(), holder: mesh, mat });
        }
        if (!mesh) continue;
        const wrap = new THREE.Group();
        setPose(wrap, originOf(v));
        wrap.add(mesh);
        g.add(wrap);
      }
      this.group.add(g);
      this.links.set(link.getAttribute("name"), g);
    }
    for (const j of doc.querySelectorAll("robot > joint")) {
      const child = j.querySelector("child")?.getAttribute("link");
      const parent = j.querySelector("parent")?.getAttribute("link");
      if (child && parent) this.joints.set(child, { parent, origin: originOf(j) });
    }
    this.loadMeshes(meshes);
  }
  /** Fetch the visuals' mesh files; the status says how many are drawn and names the first failure. */
  async loadMeshes(meshes) {
    this.setStatus("Meshes", null);
    if (!meshes.length) return;
    const generation = (this.generation = (this.generation || 0) + 1);
    this.setStatus("Meshes", "warn", `loading ${meshes.length} meshes`);
    const results = await Promise.allSettled(meshes.map(async ({ uri, holder, mat }) => {
      if (!uri) throw new Error("a <mesh> without a filename");
      holder.add(await loadMesh(uri, mat));
      state.dirty = true;
    }));
    if (generation !== this.generation) return; // reloaded meanwhile
    const failed = results.map((r, i) => [r, meshes[i].uri]).filter(([r]) => r.status === "rejected");
    if (failed.length) {
      const [r, uri] = failed[0];
      this.setStatus("Meshes", "error", `${failed.length} of ${meshes.length} meshes not drawn: ${uri}: ${r.reason.message}`);
    } else this.setStatus("Meshes", "ok", `${meshes.length} meshes`);
  }
  /** A link's pose in the fixed frame: from tf, else through its joint from its parent's. */
  linkPose(name, depth = 0) {
    const T = tf.lookup(state.fixedFrame, name);
    if (T) return T;
    const j = this.joints.get(name);
    if (!j || depth > 50) return null;
    const P = this.linkPose(j.parent, depth + 1);
    return P ? compose(P, j.origin) : null;
  }
  update() {
    this.group.position.set(0, 0, 0);
    this.group.quaternion.identity();
    if (!this.cfg.enabled || !this.links.size) return;
    const missing = [];
    for (const [name, g] of this.links) {
      const P = this.linkPose(name);
      if (!P) { g.visible = false; missing.push(name); continue; }
      g.visible = true;
      setPose(g, P);
    }
    if (missing.length) this.setStatus("Transform", "error", `${TfBuffer.missing(missing[0], state.fixedFrame)}${missing.length > 1 ? ` (and ${missing.length - 1} more links)` : ""}`);
    else this.setStatus("Transform", null);
  }
}
