// The display base class (subscription, status, placement through tf) and the tables of message
// types and default colours per display class. Each display class lives in displays/, and
// registry.js is their index.

import * as THREE from "three";
import { TfBuffer } from "/static/lib/tf.js";
import { ros, tf, scene, state } from "/static/rviz/context.js";
import { rvizColor, setPose, disposeTree } from "/static/rviz/util.js";

export const MSG_TYPE = {
  "rviz/LaserScan": "sensor_msgs/LaserScan",
  "rviz/PointCloud2": "sensor_msgs/PointCloud2",
  "rviz/Map": "nav_msgs/OccupancyGrid",
  "rviz/Path": "nav_msgs/Path",
  "rviz/Pose": "geometry_msgs/PoseStamped",
  "rviz/PoseArray": "geometry_msgs/PoseArray",
  "rviz/PoseWithCovariance": "geometry_msgs/PoseWithCovarianceStamped",
  "rviz/Odometry": "nav_msgs/Odometry",
  "rviz/Marker": "visualization_msgs/Marker",
  "rviz/MarkerArray": "visualization_msgs/MarkerArray",
  "rviz/Image": "sensor_msgs/Image",
  "rviz/Polygon": "geometry_msgs/PolygonStamped",
};
// rviz's default colours per display
export const DEFAULT_COLOR = {
  "rviz/Grid": "160; 160; 164", "rviz/LaserScan": "255; 0; 0", "rviz/PointCloud2": "255; 255; 255",
  "rviz/Path": "25; 255; 0", "rviz/Pose": "255; 25; 0", "rviz/PoseArray": "255; 25; 0",
  "rviz/PoseWithCovariance": "255; 25; 0", "rviz/Odometry": "255; 25; 0", "rviz/Polygon": "25; 255; 0",
};

export class Display {
  constructor(cfg) {
    this.cfg = cfg;
    this.group = new THREE.Group();
    scene.add(this.group);
    this.statuses = new Map();
    this.sub = null;
    this.frame = null; // the frame the group's contents are in
    this.stamp = null; // and their time: placed with tf at that stamp, as rviz does
    this.el = null;
    this.received = 0;
  }
  get msgType() { return MSG_TYPE[this.cfg.cls] || null; }
  /** The topic subscribed to (a display with a transport, like Image, may add a suffix). */
  subscribedTopic() { return this.cfg.topic; }
  get color() { return rvizColor(this.cfg.color, DEFAULT_COLOR[this.cfg.cls] || "255; 255; 255"); }
  option(name, fallback) { const v = this.cfg.options?.[name]; return v === undefined ? fallback : v; }

  setStatus(key, level, text) {
    const prev = this.statuses.get(key);
    if (prev && prev.level === level && prev.text === text) return;
    if (level === null) this.statuses.delete(key);
    else this.statuses.set(key, { level, text });
    renderStatus(this);
  }

  start() {
    this.stop();
    state.dirty = true;
    this.group.visible = this.cfg.enabled;
    if (!this.cfg.enabled) { this.statuses.clear(); renderStatus(this); return; }
    if (this.msgType) {
      const topic = this.subscribedTopic();
      if (!topic) { this.setStatus("Topic", "error", "No topic set"); return; }
      this.setStatus("Topic", "warn", `No messages received on ${topic}`);
      this.sub = ros.subscribe(topic, (msg, info) => {
        this.received++;
        this.lastMsg = msg;
        state.dirty = true;
        if (this.received === 1) this.setStatus("Topic", "ok", `receiving ${info.type}`);
        try {
          this.onMessage(msg, info);
        } catch (err) {
          this.setStatus("Message", "error", `${topic}: ${err.message}`);
          console.error(err);
        }
      }, { type: this.msgType, onError: (text) => this.setStatus("Topic", "error", text) });
    }
  }
  stop() {
    if (this.sub) { this.sub.unsubscribe(); this.sub = null; }
    this.received = 0;
  }
  destroy() {
    this.stop();
    state.dirty = true;
    scene.remove(this.group);
    disposeTree(this.group);
  }
  onMessage() {}

  /** Place `obj` at frame `frame` in the fixed frame; false (and a status) when there is no transform. */
  place(obj, frame, key = "Transform", stamp = this.stamp) {
    const T = tf.lookup(state.fixedFrame, frame, stamp || 0);
    if (!T) {
      obj.visible = false;
      this.setStatus(key, "error", TfBuffer.missing(frame, state.fixedFrame));
      return false;
    }
    obj.visible = true;
    setPose(obj, T);
    this.setStatus(key, null);
    return true;
  }
  update() {
    if (this.cfg.enabled && this.frame !== null) this.place(this.group, this.frame);
  }
}


/** Show a display's statuses in its panel entry, and its worst level as the entry's colour. */
export function renderStatus(d) {
  if (!d.el) return;
  const box = d.el.querySelector(".rv-status");
  box.replaceChildren(...[...d.statuses].map(([key, s]) => {
    const div = document.createElement("div");
    div.dataset.level = s.level;
    div.dataset.key = key;
    div.textContent = `${key}: ${s.text}`;
    return div;
  }));
  const worst = [...d.statuses.values()].some((s) => s.level === "error") ? "error" : [...d.statuses.values()].some((s) => s.level === "warn") ? "warn" : "ok";
  d.el.dataset.level = worst;
}
