// Mesh files named by robot descriptions (package://, file://), fetched through the web app's
// /api/resource route and parsed by three.js' loaders (vendored from the three package).
//
// STL carries no colour: it takes the URDF visual's material. An OBJ's parts named by `usemtl` take
// their colour (Kd) and opacity (d, or 1 - Tr) from the `mtllib` file next to it, as rviz draws a
// mesh's own materials; parts without one (no mtllib, a file that cannot be read, a name it does not
// define) take the URDF visual's material. COLLADA keeps its own materials, and its up axis and unit are applied (three's loader turns the scene Y-up; rviz's world
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
  if (ext === "obj") {
    return fetchResource(uri, "text").then(async (text) => {
      const group = new OBJLoader().parse(text);
      return { kind: "obj", group, materials: await objMaterials(uri, text) };
    });
  }
  return Promise.reject(new Error(`unsupported mesh format .${ext} (STL, DAE and OBJ are drawn)`));
}

/** `newmtl` name -> { color: [r, g, b], opacity } of a Wavefront material library's text. */
export function parseMtl(text) {
  const out = new Map();
  let cur = null;
  for (const raw of text.split("\n")) {
    const [key, ...rest] = raw.trim().split(/\s+/);
    if (key === "newmtl") { cur = { color: null, opacity: 1 }; out.set(rest.join(" "), cur); continue; }
    if (!cur) continue;
    const nums = rest.map(Number);
    if (key === "Kd" && nums.length >= 3 && nums.slice(0, 3).every(Number.isFinite)) cur.color = nums.slice(0, 3);
    else if (key === "d" && Number.isFinite(nums[0])) cur.opacity = nums[0];
    else if (key === "Tr" && Number.isFinite(nums[0])) cur.opacity = 1 - nums[0];
  }
  return out;
}

/** The materials of an OBJ's `mtllib` files (relative to the OBJ's URI); a file that cannot be
 *  read is named in the console and leaves its parts in the URDF visual's material. */
async function objMaterials(uri, text) {
  const base = uri.slice(0, uri.lastIndexOf("/") + 1);
  const libs = [...text.matchAll(/^\s*mtllib\s+(.+?)\s*$/gm)].map((m) => m[1]);
  const out = new Map();
  for (const lib of libs) {
    try {
      for (const [name, m] of parseMtl(await fetchResource(base + lib, "text"))) out.set(name, m);
    } catch (err) {
      console.warn(`${uri}: material library ${lib}: ${err.message}`);
    }
  }
  return out;
}

/** An OBJ part's material: its own from the library, else the visual's. */
function objMaterial(own, materials, fallback) {
  const m = own && materials.get(own.name);
  if (!m || !m.color) return fallback;
  const opacity = Math.min(m.opacity, fallback.opacity);
  return new THREE.MeshLambertMaterial({
    color: new THREE.Color(m.color[0], m.color[1], m.color[2]), transparent: opacity < 1, opacity, name: own.name,
  });
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
    group.traverse((o) => {
      if (!o.isMesh) return;
      o.material = Array.isArray(o.material)
        ? o.material.map((own) => objMaterial(own, parsed.materials, material))
        : objMaterial(o.material, parsed.materials, material);
    });
    group.userData.meshUri = uri;
    return group;
  }
  const wrap = new THREE.Group();
  wrap.rotation.x = Math.PI / 2; // three's Y-up back to rviz's Z-up
  wrap.add(parsed.collada.scene.clone());
  wrap.userData.meshUri = uri;
  return wrap;
}
