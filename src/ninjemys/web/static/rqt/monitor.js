// rqt_tf_tree, rqt_topic (hz, bw, last value), rqt_publisher and rqt_service_caller.

import { TfBuffer } from "../lib/tf.js";
import { codecFor } from "../lib/ros1msg.js";
import { el, MessageArea, fillSelect, toJson, plain } from "./common.js";

export class TfTreeTool {
  constructor(pane, ros) {
    this.ros = ros;
    this.tf = new TfBuffer();
    this.tf.attach(ros);
    this.tree = el("div", { class: "rq-tree tf-tree" });
    this.msgs = new MessageArea();
    pane.append(el("div", { class: "rq-bar" }, "Frames of /tf and /tf_static: rate of updates, and delay of the newest stamp behind now."), this.msgs.node, this.tree);
    setInterval(() => this.render(), 500);
    this.render();
  }

  render() {
    const children = new Map();
    for (const [child, e] of this.tf.frames) {
      if (!children.has(e.parent)) children.set(e.parent, []);
      children.get(e.parent).push(child);
    }
    const roots = this.tf.frameNames().filter((f) => !this.tf.frames.has(f));
    const now = this.ros.now();
    const seen = new Set();
    const node = (frame) => {
      seen.add(frame);
      const e = this.tf.frames.get(frame);
      let meta = "";
      if (e) {
        const stamp = e.stamp ? e.stamp.secs + e.stamp.nsecs / 1e9 : 0;
        meta = e.isStatic ? "static" : `${this.tf.rate(frame).toFixed(1)} Hz, delay ${(now - stamp).toFixed(3)} s`;
        meta += ` · from ${e.parent}`;
      }
      const kids = (children.get(frame) || []).sort().filter((k) => !seen.has(k));
      return el("li", { "data-frame": frame }, el("span", { class: "frame" }, frame), el("span", { class: "meta" }, meta),
        kids.length ? el("ul", {}, ...kids.map(node)) : null);
    };
    if (!this.tf.frames.size) {
      this.tree.replaceChildren(el("div", { class: "rq-msg info" }, "no transforms received yet on /tf or /tf_static"));
      return;
    }
    const lists = roots.map((r) => el("ul", {}, node(r)));
    const loops = [...this.tf.frames.keys()].filter((f) => !seen.has(f));
    if (loops.length) this.msgs.show(`frames in a loop (no root): ${loops.join(", ")}`);
    else this.msgs.clear();
    this.tree.replaceChildren(...lists);
  }
}

/** A window of (receive time, size) for hz and bw the way rostopic computes them. */
class Stats {
  constructor() { this.samples = []; this.last = null; }
  add(size) {
    this.samples.push([performance.now(), size]);
    if (this.samples.length > 100) this.samples.shift();
  }
  hz() {
    const s = this.samples;
    if (s.length < 2) return 0;
    return (s.length - 1) / ((s[s.length - 1][0] - s[0][0]) / 1000);
  }
  bw() {
    const s = this.samples;
    if (s.length < 2) return 0;
    return s.slice(1).reduce((a, x) => a + x[1], 0) / ((s[s.length - 1][0] - s[0][0]) / 1000);
  }
}

function human(bytesPerSec) {
  if (bytesPerSec >= 1e6) return `${(bytesPerSec / 1e6).toFixed(2)} MB/s`;
  if (bytesPerSec >= 1e3) return `${(bytesPerSec / 1e3).toFixed(2)} KB/s`;
  return `${bytesPerSec.toFixed(0)} B/s`;
}

export class TopicTool {
  constructor(pane, ros) {
    this.ros = ros;
    this.watched = new Map(); // topic -> {sub, stats, last}
    this.body = el("tbody");
    this.detail = el("pre", { class: "rq-json topic-value" });
    pane.append(
      el("table", { class: "rq-table topic-table" }, el("thead", {}, el("tr", {}, ...["", "Topic", "Type", "Bandwidth", "Hz", "Value"].map((h) => el("th", {}, h)))), this.body),
      this.detail,
    );
    ros.on("channels", () => this.render());
    setInterval(() => this.update(), 1000);
    this.render();
  }

  render() {
    this.rows = new Map();
    this.body.replaceChildren(...this.ros.topics().map((t) => {
      const box = el("input", { type: "checkbox", checked: this.watched.has(t.name), onchange: () => this.watch(t.name, box.checked) });
      const cells = { bw: el("td", { class: "bw" }), hz: el("td", { class: "hz" }), value: el("td", { class: "value" }) };
      const row = el("tr", { "data-topic": t.name }, el("td", {}, box), el("td", { onclick: () => { this.selected = t.name; this.update(); } }, t.name), el("td", {}, t.type), cells.bw, cells.hz, cells.value);
      this.rows.set(t.name, cells);
      return row;
    }));
    this.update();
  }

  watch(topic, on) {
    if (!on) {
      this.watched.get(topic)?.sub.unsubscribe();
      this.watched.delete(topic);
    } else if (!this.watched.has(topic)) {
      const w = { stats: new Stats(), last: null, error: null };
      w.sub = this.ros.subscribe(topic, (msg, info) => { w.stats.add(info.size); w.last = msg; }, { onError: (t) => { w.error = t; } });
      this.watched.set(topic, w);
      this.selected = topic;
    }
    this.update();
  }

  update() {
    for (const [topic, cells] of this.rows || []) {
      const w = this.watched.get(topic);
      if (!w) { cells.bw.textContent = cells.hz.textContent = cells.value.textContent = ""; continue; }
      cells.bw.textContent = human(w.stats.bw());
      cells.hz.textContent = w.stats.hz().toFixed(2);
      cells.value.textContent = w.error || (w.last ? toJson(w.last, 8).replace(/\s+/g, " ").slice(0, 120) : "(no message yet)");
    }
    const w = this.watched.get(this.selected);
    this.detail.textContent = w && w.last ? `${this.selected}\n${toJson(w.last)}` : "";
  }
}

export class PublisherTool {
  constructor(pane, ros) {
    this.ros = ros;
    this.msgs = new MessageArea();
    this.topic = el("input", { type: "text", placeholder: "/topic", class: "pub-topic", size: 28 });
    this.type = el("input", { type: "text", placeholder: "pkg/Type", class: "pub-type", size: 28, list: "pub-types" });
    this.types = el("datalist", { id: "pub-types" });
    this.rate = el("input", { type: "number", value: 1, min: 0, step: 0.5, style: "width:5em", class: "pub-rate" });
    this.editor = el("textarea", { class: "rq-edit pub-message", spellcheck: false });
    this.startButton = el("button", { class: "pub-start", onclick: () => this.toggle() }, "start");
    pane.append(
      el("div", { class: "rq-bar" }, "Topic ", this.topic, " Type ", this.type, this.types,
        el("button", { onclick: () => this.template() }, "load fields"), " rate (Hz, 0 = once) ", this.rate,
        el("button", { class: "pub-once", onclick: () => this.publishOnce() }, "publish once"), this.startButton),
      this.msgs.node, this.editor,
    );
    ros.on("channels", () => this.types.replaceChildren(...[...new Set(this.ros.topics().map((t) => t.type))].sort().map((t) => el("option", { value: t }))));
    this.topic.addEventListener("change", () => {
      const t = this.ros.topics().find((x) => x.name === this.topic.value.trim());
      if (t && !this.type.value) { this.type.value = t.type; this.template(); }
    });
  }

  async template() {
    const type = this.type.value.trim();
    if (!type) return;
    try {
      const codec = await this.ros.codecForType(type);
      this.editor.value = JSON.stringify(plain(codec.defaults()), null, 2);
      this.msgs.clear();
    } catch (err) {
      this.msgs.show(`type ${type}: ${err.message}`);
    }
  }

  message() {
    try {
      return JSON.parse(this.editor.value || "{}");
    } catch (err) {
      throw new Error(`message is not valid JSON: ${err.message}`);
    }
  }

  async publishOnce() {
    const topic = this.topic.value.trim();
    const type = this.type.value.trim();
    if (!topic || !type) { this.msgs.show("give a topic and a type"); return false; }
    try {
      const msg = this.message();
      const pub = this.ros.advertise(topic, type);
      await pub.ready;
      pub.publish(msg);
      this.count = (this.count || 0) + 1;
      this.msgs.show(`published ${this.count} message(s) on ${topic}`, "info");
      return true;
    } catch (err) {
      this.msgs.show(`${topic}: ${err.message}`);
      return false;
    }
  }

  async toggle() {
    if (this.timer) {
      clearInterval(this.timer);
      this.timer = null;
      this.startButton.textContent = "start";
      return;
    }
    const hz = Number(this.rate.value);
    if (!(await this.publishOnce()) || !(hz > 0)) return;
    this.timer = setInterval(() => this.publishOnce().then((ok) => { if (!ok) this.toggle(); }), 1000 / hz);
    this.startButton.textContent = "stop";
  }
}

export class ServiceCallerTool {
  constructor(pane, ros) {
    this.ros = ros;
    this.msgs = new MessageArea();
    this.select = el("select", { class: "sc-service", onchange: () => this.template() });
    this.editor = el("textarea", { class: "rq-edit sc-request", spellcheck: false });
    this.response = el("pre", { class: "rq-json sc-response" });
    pane.append(
      el("div", { class: "rq-bar" }, "Service ", this.select, el("button", { class: "sc-call", onclick: () => this.call() }, "call")),
      this.msgs.node, el("div", {}, "Request"), this.editor, el("div", {}, "Response"), this.response,
    );
    ros.on("services", () => this.refresh());
    this.refresh();
  }

  refresh() {
    fillSelect(this.select, this.ros.serviceList().map((s) => ({ value: s.name, label: `${s.name} (${s.type})` })), "(choose a service)");
  }

  template() {
    const s = this.ros.serviceByName.get(this.select.value);
    if (!s) return;
    try {
      const codec = codecFor(s.request?.schemaName ?? `${s.type}Request`, s.request?.schema ?? s.requestSchema);
      this.editor.value = JSON.stringify(plain(codec.defaults()), null, 2);
      this.msgs.clear();
    } catch (err) {
      this.msgs.show(`${s.name}: ${err.message}`);
    }
  }

  async call() {
    const name = this.select.value;
    if (!name) { this.msgs.show("choose a service"); return; }
    let request;
    try {
      request = JSON.parse(this.editor.value || "{}");
    } catch (err) {
      this.msgs.show(`request is not valid JSON: ${err.message}`);
      return;
    }
    this.response.textContent = "…";
    try {
      const resp = await this.ros.callService(name, request);
      this.response.textContent = toJson(resp);
      this.msgs.clear();
    } catch (err) {
      this.response.textContent = "";
      this.msgs.show(err.message);
    }
  }
}
