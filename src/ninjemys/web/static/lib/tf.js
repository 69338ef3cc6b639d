// A tf buffer in the browser, fed by /tf and /tf_static (tf2_msgs/TFMessage) through the ROS client.
//
// It keeps the latest transform of every child frame (a page draws "now", so no history is kept: a
// display looks up the current pose of its message's frame, see docs/rviz.md) and composes chains
// through the tree's common root. Frame ids are stored without a leading "/" (tf2's convention, and
// ROS 1 publishers still send "/base_link" now and then).

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
    this.frames = new Map(); // child -> {parent, tf, stamp, isStatic, times: [receive ms]}
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
      if (!entry) {
        entry = { parent, tf: IDENTITY, stamp: null, isStatic, times: [] };
        this.frames.set(child, entry);
      }
      entry.parent = parent;
      entry.tf = fromPose(ts.transform);
      entry.stamp = ts.header.stamp;
      entry.isStatic = isStatic;
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

  _toRoot(frame) {
    let tf = IDENTITY;
    let cur = frame;
    const seen = new Set();
    while (this.frames.has(cur)) {
      if (seen.has(cur)) return null; // a loop in the tree: nothing sensible to compose
      seen.add(cur);
      const e = this.frames.get(cur);
      tf = compose(e.tf, tf);
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
   * The pose of `source` in `target` (maps points in source to target), or null. `why(error)` gets
   * rviz's wording when there is none.
   */
  lookup(target, source) {
    target = stripSlash(target);
    source = stripSlash(source);
    if (target === source) return IDENTITY;
    const a = this._toRoot(target);
    const b = this._toRoot(source);
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
