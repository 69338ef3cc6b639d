// Mesh files named by robot descriptions (package://, file://), fetched through the web app's
// /api/resource route and parsed by three.js' loaders (vendored from the three package).
//
// STL and OBJ carry no colour: they take the URDF visual's material. COLLADA keeps its own
// materials, and its up axis and unit are applied (three's loader turns the scene Y-up; rviz's world
// is Z-up, so the loaded scene is turned back a quarter turn about x).

import * as THREE from "three";
import { STLLoader } from "/static/vendor/three/loaders/STLLoader.js";
import { ColladaLoader } from "/static/vendor/three/loaders/ColladaLoader.js";
import { OBJLoader } from "/static/vendor/three/loaders/OBJLoader.js";

export const RESOURCE_ROUTE = "/api/resource";

/** The page URL that serves `uri` (package://pkg/path or file:///path). */
export function resourceUrl(uri) {
  return `${RESOURCE_ROUTE}?uri=${encodeURIComponent(uri)}`;
}

/** The parsed meshes by URI: a robot with four identical wheels fetches the wheel once. */
const cache = new Map();

async function fetchResource(uri, as) {
  const resp = await fetch(resourceUrl(uri));
  if (!resp.ok) {
    const text = await resp.text();
    let reason = text.trim();
    try { reason = JSON.parse(text).error || reason; } catch { /* not JSON: the text itself */ }
    throw new Error(reason || `HTTP ${resp.status}`);
  }
  return as === "text" ? resp.text() : resp.arrayBuffer();
}

function parse(uri) {
  const ext = uri.split("?")[0].split(".").pop().toLowerCase();
  if (ext === "stl") return fetchResource(uri, "bytes").then((buf) => ({ kind: "stl", geometry: new STLLoader().parse(buf) }));
  if (ext === "dae") {
    // textures are named relative to the .dae: the loader appends them to this base
    const base = resourceUrl(uri.slice(0, uri.lastIndexOf("/") + 1));
    return fetchResource(uri, "text").then((text) => ({ kind: "dae", collada: new ColladaLoader().parse(text, base) }));
  }
  if (ext === "obj") return fetchResource(uri, "text").then((text) => ({ kind: "obj", group: new OBJLoader().parse(text) }));
  return Promise.reject(new Error(`unsupported mesh format .${ext} (STL, DAE and OBJ are drawn)`));
}

/** A new object drawing the mesh at `uri` with `material` (STL, OBJ); rejects with the server's reason. */
export async function loadMesh(uri, material) {
  if (!cache.has(uri)) {
    const p = parse(uri);
    cache.set(uri, p);
    p.catch(() => cache.delete(uri)); // a fixed file can be tried again
  }
  const parsed = await cache.get(uri);
  if (parsed.kind === "stl") {
    const mesh = new THREE.Mesh(parsed.geometry, material);
    mesh.userData.meshUri = uri;
    return mesh;
  }
  if (parsed.kind === "obj") {
    const group = parsed.group.clone();
    group.traverse((o) => { if (o.isMesh) o.material = material; });
    group.userData.meshUri = uri;
    return group;
  }
  const wrap = new THREE.Group();
  wrap.rotation.x = Math.PI / 2; // three's Y-up back to rviz's Z-up
  wrap.add(parsed.collada.scene.clone());
  wrap.userData.meshUri = uri;
  return wrap;
}
