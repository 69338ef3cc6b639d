// What every part of the rviz page shares: the gateway connection, the tf buffer, the three.js
// scene, the display list and the small mutable page state (fixed frame, redraw flag, tool).
// Modules import these bindings; the state object is mutated, never replaced.

import * as THREE from "three";
import { RosClient } from "/static/lib/rosclient.js";
import { TfBuffer } from "/static/lib/tf.js";

export const params = new URLSearchParams(location.search);
export const $ = (id) => document.getElementById(id);

// colours are given in sRGB bytes (messages, .rviz files) and drawn as given: no colour management
THREE.ColorManagement.enabled = false;
export const scene = new THREE.Scene();

export const ros = new RosClient();
export const tf = new TfBuffer();
tf.attach(ros);

/** The displays in panel order. */
export const displays = [];

export const state = {
  fixedFrame: params.get("fixed") || "map",
  // the view is drawn when something changed (a message, tf, the camera, the page), at most at the
  // frame rate of the file's Global Options (rviz's default 30), and once a second regardless
  dirty: true,
  /** the interaction tool: move (camera), pose, goal, point */
  activeTool: "move",
  /** a pose tool's drag in progress ({start}) or null */
  drag: null,
  toolTopics: { "rviz/SetInitialPose": "/initialpose", "rviz/SetGoal": "/move_base_simple/goal", "rviz/PublishPoint": "/clicked_point" },
  frameInterval: 1000 / 30,
};
export const markDirty = () => { state.dirty = true; };
tf.listeners.add(markDirty);

/** A line in the page's message area (errors, and the tools' "goal sent" notes as kind "info"). */
export function message(text, kind = "error") {
  const div = document.createElement("div");
  div.className = kind;
  div.textContent = text;
  $("rv-messages").appendChild(div);
  while ($("rv-messages").children.length > 6) $("rv-messages").firstChild.remove();
}
