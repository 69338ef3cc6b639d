// Small three.js helpers the displays share: rviz colours, poses, disposal, the arrow shape.

import * as THREE from "three";

export function rvizColor(text, fallback) {
  const parts = String(text || fallback).split(";").map((s) => Number(s.trim()));
  if (parts.length < 3 || parts.some((v) => Number.isNaN(v))) return rvizColor(fallback, "255; 255; 255");
  return new THREE.Color(parts[0] / 255, parts[1] / 255, parts[2] / 255);
}
export function toRviz(hex) {
  const c = new THREE.Color(hex);
  return `${Math.round(c.r * 255)}; ${Math.round(c.g * 255)}; ${Math.round(c.b * 255)}`;
}
export function setPose(obj, p) {
  obj.position.set(p.t[0], p.t[1], p.t[2]);
  obj.quaternion.set(p.q[0], p.q[1], p.q[2], p.q[3]);
}
export function disposeTree(obj) {
  obj.traverse((o) => {
    o.geometry?.dispose();
    if (o.material) (Array.isArray(o.material) ? o.material : [o.material]).forEach((m) => { m.map?.dispose(); m.dispose(); });
  });
}
export function clearGroup(group) {
  for (const child of [...group.children]) { group.remove(child); disposeTree(child); }
}

/** An arrow along +x from the origin: shaft cylinder and head cone (rviz's Arrow shape). */
export function arrowMesh(length, shaftDiameter, headDiameter, headLength, color, opacity = 1) {
  const g = new THREE.Group();
  const mat = new THREE.MeshLambertMaterial({ color, transparent: opacity < 1, opacity });
  const shaftLen = Math.max(length - headLength, 0.0001);
  const shaft = new THREE.Mesh(new THREE.CylinderGeometry(shaftDiameter / 2, shaftDiameter / 2, shaftLen, 12), mat);
  shaft.rotation.z = -Math.PI / 2;
  shaft.position.x = shaftLen / 2;
  const head = new THREE.Mesh(new THREE.ConeGeometry(headDiameter / 2, headLength, 16), mat);
  head.rotation.z = -Math.PI / 2;
  head.position.x = shaftLen + headLength / 2;
  g.add(shaft, head);
  return g;
}
