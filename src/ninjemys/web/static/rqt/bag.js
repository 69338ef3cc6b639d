// rqt_bag: one timeline row per topic from the bag's index (a tick per message), a cursor to scrub,
// the message under the cursor, image thumbnails, play/pause at a speed (published by the server
// while playing) and a plot of a field over the whole bag.

import { codecFor } from "../lib/ros1msg.js";
import { el, MessageArea, getJson, b64bytes, toJson, parsePath, splitTopicField, numericAt } from "./common.js";
import { drawImage } from "./image.js";

const IMAGE_TYPES = new Set(["sensor_msgs/Image", "sensor_msgs/CompressedImage"]);
const THUMBS = 8;

function decodeEntry(entry) {
  return codecFor(entry.type, entry.definition).decode(b64bytes(entry.data));
}

export class BagTool {
  constructor(pane, ros) {
    this.ros = ros;
    this.msgs = new MessageArea();
    this.position = null;
    this.selected = null;
    this.speed = el("input", { type: "number", value: 1, min: 0.01, step: 0.1, style: "width:5em", class: "bag-speed" });
    this.publishBox = el("input", { type: "checkbox", checked: true, class: "bag-publish" });
    this.playButton = el("button", { class: "bag-play", onclick: () => this.togglePlay() }, "▶ play");
    this.clock = el("span", { class: "bag-clock" });
    this.rows = el("div", { id: "bag-timeline" });
    this.view = el("pre", { class: "rq-json bag-message" });
    this.plotInput = el("input", { type: "text", placeholder: "/topic/field to plot", size: 36, class: "bag-plot-input" });
    this.plotInput.addEventListener("keydown", (e) => { if (e.key === "Enter") this.plot(); });
    this.plotBox = el("div", { class: "rq-plot bag-plot" });
    this.header = el("div", { class: "bag-files" });
    pane.append(
      this.header,
      el("div", { class: "rq-bar" }, this.playButton, el("label", {}, " speed ", this.speed, "x"), el("label", {}, this.publishBox, " publish"), this.clock),
      this.msgs.node, this.rows,
      el("div", { class: "rq-bar" }, "Plot ", this.plotInput, el("button", { class: "bag-plot-button", onclick: () => this.plot() }, "plot")),
      this.plotBox, this.view,
    );
    this.load();
  }

  async load() {
    try {
      this.info = await getJson("/api/rqt/bag");
    } catch (err) {
      this.msgs.show(err.message);
      return;
    }
    const info = this.info;
    this.header.textContent = info.paths.length ? info.paths.join(", ") : "no bag file given (rqt_bag file.bag)";
    for (const e of info.errors) this.msgs.add(e);
    for (const w of info.warnings) this.msgs.add(w, "info");
    if (info.start === null) { if (info.paths.length && !info.errors.length) this.msgs.add("the bag holds no messages", "info"); return; }
    this.start = info.start;
    this.end = Math.max(info.end, info.start + 1);
    this.position = this.start;
    this.rowsByTopic = new Map();
    for (const t of info.topics) {
      const canvas = el("canvas", { height: 22, "data-ticks": 0 });
      const row = el("div", { class: "bag-row", "data-topic": t.name, "data-count": t.count },
        el("span", { class: "bag-name", title: `${t.name} (${t.type}, ${t.count} messages)`, onclick: () => this.select(t.name) }, `${t.name} (${t.count})`), canvas);
      this.rows.append(row);
      const entry = { topic: t, row, canvas, thumbs: null };
      if (IMAGE_TYPES.has(t.type)) {
        entry.thumbs = el("div", { class: "bag-thumbs", "data-topic": t.name });
        this.rows.append(entry.thumbs);
        this.thumbnails(entry);
      }
      this.rowsByTopic.set(t.name, entry);
      const onPointer = (ev) => {
        if (ev.buttons !== 1 && ev.type !== "click") return;
        const r = canvas.getBoundingClientRect();
        this.seek(this.start + ((ev.clientX - r.left) / r.width) * (this.end - this.start));
      };
      canvas.addEventListener("pointerdown", onPointer);
      canvas.addEventListener("pointermove", onPointer);
    }
    new ResizeObserver(() => this.drawTimeline()).observe(this.rows);
    this.drawTimeline();
    if (info.topics.length) this.select(info.topics[0].name);
  }

  /** Ticks at each message's time, and the cursor at the current position. */
  drawTimeline() {
    if (!this.rowsByTopic) return;
    for (const { topic, canvas } of this.rowsByTopic.values()) {
      const w = Math.max(50, canvas.clientWidth);
      if (canvas.width !== w) canvas.width = w;
      const ctx = canvas.getContext("2d");
      ctx.clearRect(0, 0, w, canvas.height);
      ctx.fillStyle = "#f4f6fa";
      ctx.fillRect(0, 0, w, canvas.height);
      ctx.fillStyle = "#2f5d8a";
      const span = this.end - this.start;
      let lastX = -1;
      let drawn = 0;
      for (const t of topic.times) {
        const x = Math.round(((t - this.start) / span) * (w - 1));
        if (x === lastX) continue; // several messages in one pixel: one tick
        ctx.fillRect(x, 3, 1, canvas.height - 6);
        lastX = x;
        drawn++;
      }
      canvas.dataset.ticks = drawn;
      if (this.position !== null) {
        ctx.fillStyle = "#d9480f";
        ctx.fillRect(Math.round(((this.position - this.start) / span) * (w - 1)), 0, 2, canvas.height);
      }
    }
    if (this.position !== null) this.clock.textContent = ` ${((this.position - this.start) / 1e9).toFixed(3)} s / ${((this.end - this.start) / 1e9).toFixed(3)} s`;
  }

  select(topic) {
    this.selected = topic;
    for (const [name, e] of this.rowsByTopic) e.row.classList.toggle("selected", name === topic);
    this.showMessage();
  }

  seek(ns) {
    this.position = Math.min(this.end, Math.max(this.start, Math.round(ns)));
    this.drawTimeline();
    this.showMessage();
    if (this.playing) this.play(); // continue from the new place
  }

  async showMessage() {
    if (!this.selected || this.position === null) return;
    const want = this.position;
    try {
      const entry = await getJson(`/api/rqt/bag/message?topic=${encodeURIComponent(this.selected)}&time=${want}`);
      if (want !== this.position && !this.playing) return; // a newer request is on its way
      const msg = decodeEntry(entry);
      this.view.textContent = `${entry.topic} @ ${(entry.time / 1e9).toFixed(9)} (${entry.type})\n${toJson(msg)}`;
    } catch (err) {
      this.view.textContent = "";
      this.msgs.show(`${this.selected}: ${err.message}`);
    }
  }

  async thumbnails(entry) {
    const times = entry.topic.times;
    const picks = [...new Set(Array.from({ length: Math.min(THUMBS, times.length) }, (_, i) => times[Math.floor((i * times.length) / Math.min(THUMBS, times.length))]))];
    for (const t of picks) {
      const canvas = el("canvas", { "data-time": t, title: `${(t - this.start) / 1e9} s`, onclick: () => this.seek(t) });
      entry.thumbs.append(canvas);
      try {
        const m = await getJson(`/api/rqt/bag/message?topic=${encodeURIComponent(entry.topic.name)}&time=${t}`);
        await drawImage(canvas, m.type, decodeEntry(m));
      } catch (err) {
        canvas.remove();
        this.msgs.add(`${entry.topic.name}: thumbnail at ${(t - this.start) / 1e9} s: ${err.message}`);
      }
    }
  }

  togglePlay() {
    if (this.playing) this.pause();
    else this.play();
  }

  async play() {
    const speed = Number(this.speed.value);
    if (!(speed > 0)) { this.msgs.show(`speed must be a positive number, got '${this.speed.value}'`); return; }
    try {
      const at = this.position >= this.end ? this.start : this.position;
      await getJson("/api/rqt/bag/play", { method: "POST", body: JSON.stringify({ start: at, speed, publish: this.publishBox.checked }) });
    } catch (err) {
      this.msgs.show(err.message);
      return;
    }
    this.playing = true;
    this.playButton.textContent = "⏸ pause";
    clearInterval(this.poll);
    this.poll = setInterval(() => this.follow(), 100);
  }

  async pause() {
    clearInterval(this.poll);
    this.playing = false;
    this.playButton.textContent = "▶ play";
    try {
      const st = await getJson("/api/rqt/bag/pause", { method: "POST" });
      this.position = st.position;
      this.drawTimeline();
      this.showMessage();
    } catch (err) {
      this.msgs.show(err.message);
    }
  }

  async follow() {
    let st;
    try {
      st = await getJson("/api/rqt/bag/state");
    } catch (err) {
      this.msgs.show(err.message);
      return;
    }
    if (st.position !== null) this.position = st.position;
    this.drawTimeline();
    if (!st.playing) {
      clearInterval(this.poll);
      this.playing = false;
      this.playButton.textContent = "▶ play";
      this.showMessage();
    }
  }

  /** Plot a numeric field of a topic over the whole bag. */
  async plot() {
    const spec = this.plotInput.value.trim();
    if (!spec || !this.info) return;
    const split = splitTopicField(spec, new Set(this.info.topics.map((t) => t.name)));
    if (!split) { this.msgs.show(`${spec}: no topic of the bag is a prefix of it`); return; }
    let path;
    try {
      path = parsePath(split.fields);
      if (!path.length) throw new Error(`${spec} is a whole message: name a numeric field`);
      const entries = await getJson(`/api/rqt/bag/messages?topic=${encodeURIComponent(split.topic)}`);
      const xs = [];
      const ys = [];
      for (const e of entries) {
        xs.push((e.time - this.start) / 1e9);
        ys.push(numericAt(decodeEntry(e), path, spec));
      }
      this.chart?.destroy();
      this.chart = new uPlot({ width: Math.max(300, this.plotBox.clientWidth || 800), height: 240, scales: { x: { time: false } },
        series: [{ label: "t (s)" }, { label: spec, stroke: "#1f77b4" }] }, [xs, ys], this.plotBox);
      this.plotBox.dataset.points = xs.length;
      this.msgs.clear();
    } catch (err) {
      this.msgs.show(err.message);
    }
  }
}
