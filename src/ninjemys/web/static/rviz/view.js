// The 3D view: the WebGL renderer on the page's canvas, the lights, the orbit (perspective) and top
// (orthographic) cameras with their controls, and the mapping between page pixels and the ground.

import * as THREE from "three";
import { OrbitControls } from "/static/vendor/three/OrbitControls.js";
import { $, params, scene, state, markDirty } from "/static/rviz/context.js";

export const canvas = $("rv-canvas");
const viewEl = $("rv-view");
/** True when WebGL is rasterized on the CPU (SwiftShader, llvmpipe): multisampling costs too much there. */
function softwareGL() {
  const gl = document.createElement("canvas").getContext("webgl");
  const info = gl?.getExtension("WEBGL_debug_renderer_info");
  const name = info ? String(gl.getParameter(info.UNMASKED_RENDERER_WEBGL)) : "";
  gl?.getExtension("WEBGL_lose_context")?.loseContext();
  return /swiftshader|llvmpipe|software/i.test(name);
}
export const renderer = new THREE.WebGLRenderer({ canvas, antialias: !softwareGL() });
renderer.setPixelRatio(1);
renderer.outputColorSpace = THREE.LinearSRGBColorSpace;
scene.add(new THREE.AmbientLight(0xffffff, 0.6));
const sun = new THREE.DirectionalLight(0xffffff, 0.9);
sun.position.set(3, -2, 10);
scene.add(sun);

const perspective = new THREE.PerspectiveCamera(60, 1, 0.01, 1000);
perspective.up.set(0, 0, 1);
const ortho = new THREE.OrthographicCamera(-1, 1, 1, -1, -100, 100);
ortho.up.set(0, 1, 0);
/** The camera in use and its controls (setView replaces both), and the top view's framing. */
export const view = {
  camera: perspective,
  controls: null,
  topScale: Number(params.get("scale") || 50), // px per metre at zoom 1
  centre: [Number(params.get("cx") || 0), Number(params.get("cy") || 0)],
};

export function size() {
  const w = viewEl.clientWidth || 800;
  const h = viewEl.clientHeight || 600;
  return [w, h];
}

export function setView(mode) {
  if (view.controls) view.controls.dispose();
  const [w, h] = size();
  const [cx, cy] = view.centre;
  let controls;
  if (mode === "top") {
    view.camera = ortho;
    const s = view.topScale;
    ortho.left = -w / 2 / s; ortho.right = w / 2 / s;
    ortho.top = h / 2 / s; ortho.bottom = -h / 2 / s;
    ortho.zoom = 1;
    ortho.position.set(cx, cy, 50);
    ortho.lookAt(cx, cy, 0);
    ortho.updateProjectionMatrix();
    controls = new OrbitControls(ortho, canvas);
    controls.enableRotate = false;
    controls.screenSpacePanning = true;
    controls.mouseButtons = { LEFT: THREE.MOUSE.PAN, MIDDLE: THREE.MOUSE.DOLLY, RIGHT: THREE.MOUSE.PAN };
    controls.target.set(cx, cy, 0);
  } else {
    view.camera = perspective;
    // rviz's default orbit view: distance 10, yaw 45°, pitch 45° around the focal point
    const d = 10, yaw = 0.785, pitch = 0.785;
    perspective.position.set(cx + d * Math.cos(pitch) * Math.cos(yaw), cy + d * Math.cos(pitch) * Math.sin(yaw), d * Math.sin(pitch));
    controls = new OrbitControls(perspective, canvas);
    controls.target.set(cx, cy, 0);
  }
  view.controls = controls;
  controls.enabled = state.activeTool === "move";
  controls.addEventListener("change", markDirty);
  controls.update();
  state.dirty = true;
  $("rv-viewmode").value = mode;
  resize();
}

function resize() {
  const [w, h] = size();
  renderer.setSize(w, h, false);
  perspective.aspect = w / h;
  perspective.updateProjectionMatrix();
  const s = view.topScale;
  ortho.left = -w / 2 / s; ortho.right = w / 2 / s;
  ortho.top = h / 2 / s; ortho.bottom = -h / 2 / s;
  ortho.updateProjectionMatrix();
  state.dirty = true;
}
new ResizeObserver(() => resize()).observe(viewEl);

/** The point of the fixed frame's z = 0 plane under a client (page) position, or null. */
export function groundPoint(clientX, clientY) {
  const rect = canvas.getBoundingClientRect();
  const ndc = new THREE.Vector2(((clientX - rect.left) / rect.width) * 2 - 1, -((clientY - rect.top) / rect.height) * 2 + 1);
  const ray = new THREE.Raycaster();
  ray.setFromCamera(ndc, view.camera);
  const hit = new THREE.Vector3();
  return ray.ray.intersectPlane(new THREE.Plane(new THREE.Vector3(0, 0, 1), 0), hit) ? hit : null;
}

/** The page pixel of a fixed-frame point. */
export function project(x, y, z = 0) {
  const rect = canvas.getBoundingClientRect();
  const v = new THREE.Vector3(x, y, z).project(view.camera);
  return { x: rect.left + ((v.x + 1) / 2) * rect.width, y: rect.top + ((1 - v.y) / 2) * rect.height };
}
