// The browser's ROS client: the gateway's Foxglove WebSocket subprotocol (foxglove.websocket.v1),
// the web tools' one data path.
//
// The server advertises channels (topics with their type and full ros1msg definition, and the
// JSON channels of the server's own app, e.g. a simulator's view) and services; we subscribe by topic name, decode the raw ROS 1 payloads with ros1msg.js, publish by
// advertising a client channel and sending ROS 1 bytes, and call services with ROS 1 bytes both
// ways. The connection comes back by itself after a drop: subscriptions and advertisements are
// re-made on the new connection, and callers keep their handles.
//
//   const ros = new RosClient();            // ws(s)://<this page's host>/ws
//   const sub = ros.subscribe("/scan", (msg, info) => ..., { type: "sensor_msgs/LaserScan" });
//   const pub = ros.advertise("/move_base_simple/goal", "geometry_msgs/PoseStamped");
//   pub.publish({ header: { frame_id: "map" }, pose: { ... } });
//   const resp = await ros.callService("/rosapi/get_time", {});

import { codecFor, RosMsgError } from "./ros1msg.js";

export { RosMsgError } from "./ros1msg.js";

const SUBPROTOCOL = "foxglove.websocket.v1";
const utf8 = new TextEncoder();
const utf8Decoder = new TextDecoder();
// channels with Foxglove's "json" encoding: an in-process app's own data (a simulator's view)
const JSON_CODEC = { decode: (bytes) => JSON.parse(utf8Decoder.decode(bytes)) };

/** The gateway's address for pages served by the web tools: ws(s)://<host>/ws. */
export function defaultUrl() {
  const proto = location.protocol === "https:" ? "wss:" : "ws:";
  return `${proto}//${location.host}/ws`;
}

/** Fetch a message type's full definition text from the web app (for types nobody advertises yet). */
async function fetchDefinition(type) {
  const resp = await fetch(`/api/msgdef?type=${encodeURIComponent(type)}`);
  const body = await resp.json().catch(() => ({}));
  if (!resp.ok) throw new RosMsgError(body.error || `no definition of ${type} (HTTP ${resp.status})`);
  return body.definition;
}

class Listeners {
  constructor() { this.map = new Map(); }
  on(event, fn) {
    if (!this.map.has(event)) this.map.set(event, new Set());
    this.map.get(event).add(fn);
    return () => this.map.get(event)?.delete(fn);
  }
  emit(event, ...args) {
    for (const fn of [...(this.map.get(event) || [])]) {
      try { fn(...args); } catch (err) { console.error(`ros client: ${event} listener failed`, err); }
    }
  }
}

/**
 * One connection to the gateway. Events (`on(name, fn)` returns an unsubscribe function):
 * `open`, `close`, `channels` (the topic list changed), `services`, `status` ({level, message}),
 * `time` (sim time in ns, under /use_sim_time), `graph` (connectionGraphUpdate; see watchGraph),
 * `removeStatus` (status ids the server withdrew).
 */
export class RosClient {
  constructor(url = defaultUrl(), { reconnect = true, reconnectDelay = 500 } = {}) {
    this.url = url;
    this.reconnect = reconnect;
    this.reconnectDelay = reconnectDelay;
    this.ws = null;
    this.connected = false;
    this.serverInfo = null;
    this.time = null;
    this.channels = new Map(); // channel id -> channel
    this.byTopic = new Map(); // topic -> channel
    this.services = new Map(); // service id -> service
    this.serviceByName = new Map();
    this._listeners = new Listeners();
    this._topicSubs = new Map(); // topic -> {subId, handlers:Set, codec}
    this._subIds = 1;
    this._pubs = new Map(); // topic -> publisher
    this._pubIds = 1;
    this._calls = new Map(); // call id -> {resolve, reject, codec, name}
    this._callIds = 1;
    this._paramReqs = new Map();
    this._paramIds = 1;
    this._paramWatchers = new Map(); // name -> Set(fn)
    this._graphWatchers = 0;
    this._closedByUser = false;
    this._ready = null;
    this._connect();
  }

  on(event, fn) { return this._listeners.on(event, fn); }

  /** Resolves once connected and the server's channels are known. */
  ready() { return this._ready; }

  _connect() {
    let resolveReady;
    this._ready = new Promise((res) => { resolveReady = res; });
    const ws = new WebSocket(this.url, [SUBPROTOCOL]);
    ws.binaryType = "arraybuffer";
    this.ws = ws;
    ws.onopen = () => {
      this.connected = true;
      this._listeners.emit("open");
    };
    ws.onmessage = (ev) => {
      if (typeof ev.data === "string") this._control(JSON.parse(ev.data), resolveReady);
      else this._binary(ev.data);
    };
    ws.onclose = (ev) => {
      const was = this.connected;
      this.connected = false;
      this.ws = null;
      for (const [, call] of this._calls) call.reject(new Error(`service ${call.name}: connection closed`));
      this._calls.clear();
      for (const entry of this._topicSubs.values()) entry.subId = null;
      for (const pub of this._pubs.values()) pub.channelId = null;
      this.channels.clear();
      this.byTopic.clear();
      this.services.clear();
      this.serviceByName.clear();
      if (was) this._listeners.emit("close", { code: ev.code, reason: ev.reason });
      if (this.reconnect && !this._closedByUser) setTimeout(() => this._connect(), this.reconnectDelay);
    };
  }

  /** Close for good (no reconnection). */
  close() {
    this._closedByUser = true;
    if (this.ws) this.ws.close(1000, "client closed");
  }

  _send(obj) {
    if (this.ws && this.ws.readyState === WebSocket.OPEN) this.ws.send(JSON.stringify(obj));
  }

  _control(msg, resolveReady) {
    switch (msg.op) {
      case "serverInfo":
        this.serverInfo = msg;
        if (this._graphWatchers > 0) this._send({ op: "subscribeConnectionGraph" });
        break;
      case "advertise": {
        for (const ch of msg.channels) {
          this.channels.set(ch.id, ch);
          this.byTopic.set(ch.topic, ch);
        }
        this._resubscribe();
        this._readvertise();
        for (const [name, watchers] of this._paramWatchers) if (watchers.size) this._send({ op: "subscribeParameterUpdates", parameterNames: [name] });
        resolveReady();
        this._listeners.emit("channels", this.topics());
        break;
      }
      case "unadvertise":
        for (const id of msg.channelIds) {
          const ch = this.channels.get(id);
          this.channels.delete(id);
          if (ch && this.byTopic.get(ch.topic) === ch) {
            this.byTopic.delete(ch.topic);
            const entry = this._topicSubs.get(ch.topic);
            if (entry && entry.channelId === id) entry.subId = null; // the server dropped it with the channel
          }
        }
        this._listeners.emit("channels", this.topics());
        break;
      case "advertiseServices":
        for (const s of msg.services) {
          this.services.set(s.id, s);
          this.serviceByName.set(s.name, s);
        }
        this._listeners.emit("services", this.serviceList());
        break;
      case "unadvertiseServices":
        for (const id of msg.serviceIds) {
          const s = this.services.get(id);
          this.services.delete(id);
          if (s && this.serviceByName.get(s.name) === s) this.serviceByName.delete(s.name);
        }
        this._listeners.emit("services", this.serviceList());
        break;
      case "status":
        this._listeners.emit("status", { level: msg.level, message: msg.message, id: msg.id });
        break;
      case "parameterValues": {
        const pending = msg.id !== undefined ? this._paramReqs.get(msg.id) : undefined;
        if (pending) {
          this._paramReqs.delete(msg.id);
          pending(msg.parameters);
        } else {
          for (const p of msg.parameters) {
            for (const [name, watchers] of this._paramWatchers) {
              if (p.name === name || p.name.startsWith(name.replace(/\/$/, "") + "/")) {
                for (const fn of watchers) fn(p.value, p.name);
              }
            }
          }
        }
        break;
      }
      case "serviceCallFailure": {
        const call = this._calls.get(msg.callId);
        if (call) {
          this._calls.delete(msg.callId);
          call.reject(new Error(`service ${call.name}: ${msg.message}`));
        }
        break;
      }
      case "connectionGraphUpdate":
        this._listeners.emit("graph", msg);
        break;
      case "removeStatus":
        this._listeners.emit("removeStatus", msg.statusIds || []);
        break;
      default:
        break;
    }
  }

  _binary(buffer) {
    const view = new DataView(buffer);
    const op = view.getUint8(0);
    if (op === 0x01) {
      const subId = view.getUint32(1, true);
      const stampNs = Number(view.getBigUint64(5, true));
      for (const [topic, entry] of this._topicSubs) {
        if (entry.subId !== subId) continue;
        const bytes = new Uint8Array(buffer, 13);
        let msg;
        try {
          msg = entry.codec.decode(bytes);
        } catch (err) {
          const text = `${topic}: cannot decode ${entry.channel.schemaName}: ${err.message}`;
          for (const h of entry.handlers) h.onError?.(text);
          return;
        }
        const info = { topic, type: entry.channel.schemaName, receiveTimeNs: stampNs, size: bytes.byteLength };
        for (const h of entry.handlers) {
          if (h.type && h.type !== info.type) continue; // refused: told through onError
          try { h.callback(msg, info); } catch (err) { console.error(`ros client: ${topic} callback failed`, err); }
        }
        return;
      }
    } else if (op === 0x02) {
      this.time = Number(view.getBigUint64(1, true));
      this._listeners.emit("time", this.time);
    } else if (op === 0x03) {
      const callId = view.getUint32(5, true);
      const encLen = view.getUint32(9, true);
      const call = this._calls.get(callId);
      if (!call) return;
      this._calls.delete(callId);
      try {
        call.resolve(call.codec.decode(new Uint8Array(buffer, 13 + encLen)));
      } catch (err) {
        call.reject(err);
      }
    }
  }

  /**
   * Watch the connection graph: `fn(update)` gets every connectionGraphUpdate, the first one (after
   * each connection) the full graph. Returns a stop function.
   */
  watchGraph(fn) {
    const off = this.on("graph", fn);
    this._graphWatchers += 1;
    this._send({ op: "subscribeConnectionGraph" });
    return () => {
      off();
      this._graphWatchers -= 1;
      if (this._graphWatchers === 0) this._send({ op: "unsubscribeConnectionGraph" });
    };
  }

  /** The advertised topics: [{name, type}], sorted by name. */
  topics() {
    return [...this.byTopic.values()].map((c) => ({ name: c.topic, type: c.schemaName })).sort((a, b) => a.name.localeCompare(b.name));
  }

  /** The advertised services: [{name, type}], sorted by name. */
  serviceList() {
    return [...this.serviceByName.values()].map((s) => ({ name: s.name, type: s.type })).sort((a, b) => a.name.localeCompare(b.name));
  }

  /** The codec of a topic's advertised type, or null when nobody publishes it yet. */
  codecForTopic(topic) {
    const ch = this.byTopic.get(topic);
    if (!ch) return null;
    return ch.encoding === "json" ? JSON_CODEC : codecFor(ch.schemaName, ch.schema);
  }

  /** The codec of a type, from any advertised channel or service using it, else from the web app. */
  async codecForType(type) {
    for (const ch of this.byTopic.values()) {
      if (ch.schemaName === type) return codecFor(type, ch.schema);
      if (ch.schema.includes(`MSG: ${type}\n`)) return codecFor(type, sectionText(ch.schema, type));
    }
    return codecFor(type, await fetchDefinition(type));
  }

  /**
   * Subscribe to a topic; `callback(msg, info)` gets plain decoded objects. With `type`, a topic
   * of another type is refused: `onError(text)` is called (and again whenever the topic changes
   * type), nothing is delivered. The subscription waits for a topic nobody publishes yet.
   * Returns {unsubscribe()}.
   */
  subscribe(topic, callback, { type = null, onError = null } = {}) {
    let entry = this._topicSubs.get(topic);
    if (!entry) {
      entry = { subId: null, channelId: null, channel: null, codec: null, handlers: new Set() };
      this._topicSubs.set(topic, entry);
    }
    const handler = { callback, type, onError };
    entry.handlers.add(handler);
    this._ensureSub(topic, entry, handler);
    return {
      unsubscribe: () => {
        entry.handlers.delete(handler);
        if (entry.handlers.size === 0) {
          if (entry.subId !== null) this._send({ op: "unsubscribe", subscriptionIds: [entry.subId] });
          this._topicSubs.delete(topic);
        }
      },
    };
  }

  _ensureSub(topic, entry, newHandler = null) {
    const ch = this.byTopic.get(topic);
    if (!ch) return;
    for (const h of newHandler ? [newHandler] : entry.handlers) {
      if (h.type && h.type !== ch.schemaName) h.onError?.(`topic ${topic} is ${ch.schemaName}, not ${h.type}`);
    }
    if (entry.subId !== null && entry.channelId === ch.id) return;
    try {
      entry.codec = ch.encoding === "json" ? JSON_CODEC : codecFor(ch.schemaName, ch.schema);
    } catch (err) {
      for (const h of entry.handlers) h.onError?.(`${topic}: bad definition of ${ch.schemaName}: ${err.message}`);
      return;
    }
    if (entry.subId !== null) this._send({ op: "unsubscribe", subscriptionIds: [entry.subId] });
    entry.channel = ch;
    entry.channelId = ch.id;
    entry.subId = this._subIds++;
    this._send({ op: "subscribe", subscriptions: [{ id: entry.subId, channelId: ch.id }] });
  }

  _resubscribe() {
    for (const [topic, entry] of this._topicSubs) this._ensureSub(topic, entry);
  }

  /**
   * Advertise a topic (client publish). Returns {publish(obj), unadvertise(), ready: Promise}; the
   * publisher survives reconnections. Messages published before the type is known wait in order.
   */
  advertise(topic, type) {
    const existing = this._pubs.get(topic);
    if (existing && existing.type === type) return existing;
    if (existing) existing.unadvertise();
    const pub = {
      topic,
      type,
      channelId: null,
      codec: null,
      pending: [],
      error: null,
      publish: (obj) => {
        if (pub.codec && pub.channelId !== null && this.connected) this._publishNow(pub, obj);
        else pub.pending.push(obj);
      },
      unadvertise: () => {
        if (pub.channelId !== null) this._send({ op: "unadvertise", channelIds: [pub.channelId] });
        this._pubs.delete(topic);
      },
    };
    pub.ready = this.codecForType(type).then(
      (codec) => { pub.codec = codec; this._advertiseOne(pub); },
      (err) => { pub.error = err; this._listeners.emit("status", { level: 2, message: `advertise ${topic}: ${err.message}` }); throw err; },
    );
    pub.ready.catch(() => {});
    this._pubs.set(topic, pub);
    return pub;
  }

  _advertiseOne(pub) {
    if (!pub.codec || !this.connected || pub.channelId !== null) return;
    pub.channelId = this._pubIds++;
    this._send({ op: "advertise", channels: [{ id: pub.channelId, topic: pub.topic, encoding: "ros1", schemaName: pub.type }] });
    const pending = pub.pending.splice(0);
    for (const obj of pending) this._publishNow(pub, obj);
  }

  _readvertise() {
    for (const pub of this._pubs.values()) this._advertiseOne(pub);
  }

  _publishNow(pub, obj) {
    const payload = pub.codec.encode(obj);
    const frame = new Uint8Array(5 + payload.length);
    const view = new DataView(frame.buffer);
    view.setUint8(0, 0x01);
    view.setUint32(1, pub.channelId, true);
    frame.set(payload, 5);
    this.ws.send(frame);
  }

  /** Call a service; resolves with the decoded response or rejects with the failure text. */
  async callService(name, request = {}, { timeout = 10000 } = {}) {
    await this._ready;
    let service = this.serviceByName.get(name);
    if (!service) {
      await new Promise((res) => setTimeout(res, 1100)); // the gateway polls the graph once a second
      service = this.serviceByName.get(name);
      if (!service) throw new Error(`service ${name} is not advertised`);
    }
    const reqSchema = service.request?.schema ?? service.requestSchema;
    const respSchema = service.response?.schema ?? service.responseSchema;
    const reqCodec = codecFor(service.request?.schemaName ?? `${service.type}Request`, reqSchema);
    const respCodec = codecFor(service.response?.schemaName ?? `${service.type}Response`, respSchema);
    const payload = reqCodec.encode(request);
    const callId = this._callIds++;
    const enc = utf8.encode("ros1");
    const frame = new Uint8Array(13 + enc.length + payload.length);
    const view = new DataView(frame.buffer);
    view.setUint8(0, 0x02);
    view.setUint32(1, service.id, true);
    view.setUint32(5, callId, true);
    view.setUint32(9, enc.length, true);
    frame.set(enc, 13);
    frame.set(payload, 13 + enc.length);
    return new Promise((resolve, reject) => {
      const timer = setTimeout(() => {
        if (this._calls.delete(callId)) reject(new Error(`service ${name}: no response in ${timeout / 1000} s`));
      }, timeout);
      this._calls.set(callId, {
        name,
        codec: respCodec,
        resolve: (v) => { clearTimeout(timer); resolve(v); },
        reject: (e) => { clearTimeout(timer); reject(e); },
      });
      this.ws.send(frame);
    });
  }

  /** Parameters by name (all of them with no names): resolves with {name: value}. */
  async getParameters(names = []) {
    await this._ready;
    const id = `p${this._paramIds++}`;
    const params = await new Promise((resolve) => {
      this._paramReqs.set(id, resolve);
      this._send({ op: "getParameters", parameterNames: names, id });
    });
    return Object.fromEntries(params.map((p) => [p.name, p.value]));
  }

  /** Set parameters ({name: value}); resolves with the values the master now holds. */
  async setParameters(values) {
    await this._ready;
    const id = `p${this._paramIds++}`;
    const parameters = Object.entries(values).map(([name, value]) => ({ name, value }));
    const params = await new Promise((resolve) => {
      this._paramReqs.set(id, resolve);
      this._send({ op: "setParameters", parameters, id });
    });
    return Object.fromEntries(params.map((p) => [p.name, p.value]));
  }

  /** Watch a parameter (or namespace): `fn(value, name)` on each change. Returns a stop function. */
  watchParameter(name, fn) {
    if (!this._paramWatchers.has(name)) this._paramWatchers.set(name, new Set());
    this._paramWatchers.get(name).add(fn);
    this._send({ op: "subscribeParameterUpdates", parameterNames: [name] });
    return () => this._paramWatchers.get(name)?.delete(fn);
  }

  /** The current time in seconds: the gateway's sim time under /use_sim_time, else the wall clock. */
  now() {
    return this.time !== null ? this.time / 1e9 : Date.now() / 1000;
  }

  /** A ROS time {secs, nsecs} for stamping outgoing messages (see now()). */
  stamp() {
    const ns = this.time !== null ? BigInt(this.time) : BigInt(Date.now()) * 1000000n;
    return { secs: Number(ns / 1000000000n), nsecs: Number(ns % 1000000000n) };
  }
}

/** A dependency's own definition text cut out of a full one (with its own dependencies kept). */
function sectionText(full, type) {
  const parts = full.split(/\n(?==+\nMSG: )/);
  const sep = parts.findIndex((p) => new RegExp(`^=+\\nMSG: ${type.replace("/", "\\/")}\\n`).test(p));
  const own = parts[sep].replace(/^=+\nMSG: \S+\n/, "");
  return [own, ...parts.filter((_, i) => i !== sep && i !== 0)].join("\n");
}
