// A tf buffer in the browser, fed by /tf and /tf_static (tf2_msgs/TFMessage) through the ROS client.
//
// It keeps the last HISTORY_S seconds of every child frame's transforms and composes chains through
// the tree's common root, at a given stamp (interpolated: lerp and slerp between the two nearest
// transforms; clamped to the oldest/newest instead of failing, so a display never blinks while tf
// catches up) or at the latest (stamp 0, tf2's Time(0)). Frame ids are stored without a leading "/"
// (tf2's convention, and ROS 1 publishers still send "/base_link" now and then).

const HISTORY_S = 10;

/** Quaternion and vector helpers on plain arrays: q = [x, y, z, w], v = [x, y, z]. */
export function qmul(a, b) {
  return [
    a[3] * b[0] + a[0] * b[3] + a[1] * b[2] - a[2] * b[1],
    a[3] * b[1] - a[0] * b[2] + a[1] * b[3] + a[2] * b[0],
    a[3] * b[2] + a[0] * b[1] - a[1] * b[0] + a[2] * b[3],
    a[3] * b[3] - a[0] * b[0] - a[1] * b[1] - a[2] * b[2],
  ];
}

export function qrotate(q, v) {
  // v' = q v q*, expanded
  const [x, y, z, w] = q;
  const ix = w * v[0] + y * v[2] - z * v[1];
  const iy = w * v[1] + z * v[0] - x * v[2];
  const iz = w * v[2] + x * v[1] - y * v[0];
  const iw = -x * v[0] - y * v[1] - z * v[2];
  return [
    ix * w + iw * -x + iy * -z - iz * -y,
    iy * w + iw * -y + iz * -x - ix * -z,
    iz * w + iw * -z + ix * -y - iy * -x,
  ];
}

export function slerp(a, b, u) {
  let dot = a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3];
  const bb = dot < 0 ? b.map((v) => -v) : b;
  dot = Math.abs(dot);
  if (dot > 0.9995) {
    const q = a.map((v, i) => v + u * (bb[i] - v));
    const n = Math.hypot(...q);
    return q.map((v) => v / n);
  }
  const th = Math.acos(dot);
  const s0 = Math.sin((1 - u) * th) / Math.sin(th), s1 = Math.sin(u * th) / Math.sin(th);
  return a.map((v, i) => s0 * v + s1 * bb[i]);
}

/** A ROS time {secs, nsecs} as seconds (0 for a missing or zero stamp: "the latest"). */
export function toSec(stamp) {
  return stamp ? stamp.secs + stamp.nsecs / 1e9 : 0;
}

/** A rigid transform {t, q}. */
export const IDENTITY = Object.freeze({ t: [0, 0, 0], q: [0, 0, 0, 1] });

export function compose(a, b) {
  const r = qrotate(a.q, b.t);
  return { t: [a.t[0] + r[0], a.t[1] + r[1], a.t[2] + r[2]], q: qmul(a.q, b.q) };
}

export function invert(a) {
  const qi = [-a.q[0], -a.q[1], -a.q[2], a.q[3]];
  const r = qrotate(qi, a.t);
  return { t: [-r[0], -r[1], -r[2]], q: qi };
}

/** A geometry_msgs/Pose (or Transform) as {t, q}. */
export function fromPose(p) {
  const pos = p.position || p.translation;
  const o = p.orientation || p.rotation;
  const n = Math.hypot(o.x, o.y, o.z, o.w) || 1;
  return { t: [pos.x, pos.y, pos.z], q: [o.x / n, o.y / n, o.z / n, o.w / n] };
}

/** The yaw of a quaternion (rotation about z). */
export function yawOf(q) {
  return Math.atan2(2 * (q[3] * q[2] + q[0] * q[1]), 1 - 2 * (q[1] * q[1] + q[2] * q[2]));
}

export function stripSlash(frame) {
  return frame && frame[0] === "/" ? frame.slice(1) : frame || "";
}

export class TfBuffer {
  constructor() {
    this.frames = new Map(); // child -> {parent, tf, stamp, isStatic, history: [[sec, tf]], times: [receive ms]}
    this.listeners = new Set();
  }

  /** Feed a tf2_msgs/TFMessage. */
  add(msg, isStatic = false) {
    const now = performance.now();
    for (const ts of msg.transforms) {
      const child = stripSlash(ts.child_frame_id);
      const parent = stripSlash(ts.header.frame_id);
      if (!child || !parent || child === parent) continue;
      let entry = this.frames.get(child);
      if (!entry || entry.parent !== parent) {
        entry = { parent, tf: IDENTITY, stamp: null, isStatic, history: [], times: [] };
        this.frames.set(child, entry);
      }
      entry.tf = fromPose(ts.transform);
      entry.stamp = ts.header.stamp;
      entry.isStatic = isStatic;
      const sec = toSec(ts.header.stamp);
      const h = entry.history;
      if (h.length && sec < h[h.length - 1][0] - HISTORY_S) h.length = 0; // time went back (sim reset)
      let k = h.length;
      while (k > 0 && h[k - 1][0] > sec) k--;
      if (k > 0 && h[k - 1][0] === sec) h[k - 1] = [sec, entry.tf];
      else h.splice(k, 0, [sec, entry.tf]);
      while (h.length > 2 && h[h.length - 1][0] - h[0][0] > HISTORY_S) h.shift();
      entry.times.push(now);
      if (entry.times.length > 50) entry.times.shift();
    }
    for (const fn of this.listeners) fn();
  }

  /** Subscribe the buffer to /tf and /tf_static on a RosClient. */
  attach(ros) {
    const a = ros.subscribe("/tf", (m) => this.add(m, false), { type: "tf2_msgs/TFMessage" });
    const b = ros.subscribe("/tf_static", (m) => this.add(m, true), { type: "tf2_msgs/TFMessage" });
    return () => { a.unsubscribe(); b.unsubscribe(); };
  }

  /** Every frame known (parents included), sorted. */
  frameNames() {
    const names = new Set();
    for (const [child, e] of this.frames) { names.add(child); names.add(e.parent); }
    return [...names].sort();
  }

  /** A frame's transform to its parent at `sec` (0: the latest). */
  _at(e, sec) {
    const h = e.history;
    if (!sec || e.isStatic || h.length < 2) return e.tf;
    if (sec >= h[h.length - 1][0]) return h[h.length - 1][1];
    if (sec <= h[0][0]) return h[0][1];
    let k = h.length - 1;
    while (h[k - 1][0] > sec) k--;
    const [s0, a] = h[k - 1];
    const [s1, b] = h[k];
    const u = (sec - s0) / (s1 - s0);
    return { t: a.t.map((v, i) => v + u * (b.t[i] - v)), q: slerp(a.q, b.q, u) };
  }

  _toRoot(frame, sec) {
    let tf = IDENTITY;
    let cur = frame;
    const seen = new Set();
    while (this.frames.has(cur)) {
      if (seen.has(cur)) return null; // a loop in the tree: nothing sensible to compose
      seen.add(cur);
      const e = this.frames.get(cur);
      tf = compose(this._at(e, sec), tf);
      cur = e.parent;
    }
    return { root: cur, tf };
  }

  /** True when `frame` is in the tree (as a child or a parent). */
  hasFrame(frame) {
    frame = stripSlash(frame);
    if (this.frames.has(frame)) return true;
    for (const e of this.frames.values()) if (e.parent === frame) return true;
    return false;
  }

  /**
   * The pose of `source` in `target` (maps points in source to target) at `stamp` ({secs, nsecs}
   * or seconds; omitted or zero: the latest), or null when they are not connected.
   */
  lookup(target, source, stamp = 0) {
    target = stripSlash(target);
    source = stripSlash(source);
    if (target === source) return IDENTITY;
    const sec = typeof stamp === "number" ? stamp : toSec(stamp);
    const a = this._toRoot(target, sec);
    const b = this._toRoot(source, sec);
    if (!a || !b || a.root !== b.root) return null;
    return compose(invert(a.tf), b.tf);
  }

  /** rviz's status text for a missing transform. */
  static missing(source, target) {
    return `No transform from [${stripSlash(source) || "(empty frame_id)"}] to [${stripSlash(target)}]`;
  }

  /** Publish rate (Hz) of a child frame over its recent updates, 0 for a static or single one. */
  rate(child) {
    const e = this.frames.get(child);
    if (!e || e.times.length < 2) return 0;
    const span = (e.times[e.times.length - 1] - e.times[0]) / 1000;
    return span > 0 ? (e.times.length - 1) / span : 0;
  }
}
