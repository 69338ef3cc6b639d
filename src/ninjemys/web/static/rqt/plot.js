// rqt_plot: live time series of numeric fields (uPlot). A series is "/topic/field/sub[i]": the topic
// is the longest prefix that is an advertised topic, the rest is walked in each decoded message.

import { el, MessageArea, parsePath, splitTopicField, numericAt } from "./common.js";

const COLORS = ["#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2", "#17becf"];

export class PlotTool {
  constructor(pane, ros, params) {
    this.ros = ros;
    this.series = []; // {spec, topic, path, sub, times: [], values: [], error}
    this.paused = false;
    this.window = 10;
    this.t0 = null;
    this.msgs = new MessageArea();
    this.input = el("input", { type: "text", placeholder: "/topic/field[0]", size: 40, list: "plot-topics", class: "plot-input" });
    this.input.addEventListener("keydown", (e) => { if (e.key === "Enter") this.addFromInput(); });
    this.topicList = el("datalist", { id: "plot-topics" });
    this.pauseBox = el("input", { type: "checkbox", class: "plot-pause", onchange: () => { this.paused = this.pauseBox.checked; } });
    this.windowInput = el("input", { type: "number", min: 1, value: this.window, step: 1, style: "width:5em", class: "plot-window", onchange: () => {
      const v = Number(this.windowInput.value);
      if (v > 0) this.window = v; else this.msgs.show(`time window must be a positive number of seconds, got '${this.windowInput.value}'`);
    } });
    this.legend = el("div", { class: "plot-series" });
    this.chartBox = el("div", { class: "rq-plot" });
    pane.append(
      el("div", { class: "rq-bar" }, "Topic ", this.input, this.topicList,
        el("button", { onclick: () => this.addFromInput() }, "+"),
        el("label", {}, this.pauseBox, " pause"),
        el("label", {}, " window (s) ", this.windowInput),
        el("button", { onclick: () => this.resetZoom(), title: "back to the live window" }, "reset view"),
        el("button", { onclick: () => this.clearData() }, "clear")),
      this.msgs.node, this.legend, this.chartBox,
    );
    ros.on("channels", () => this.onChannels());
    for (const spec of params.getAll("topic")) this.add(spec);
    this.makeChart();
    new ResizeObserver(() => this.chart?.setSize(this.size())).observe(this.chartBox);
    const tick = () => { this.redraw(); requestAnimationFrame(tick); };
    requestAnimationFrame(tick);
  }

  size() { return { width: Math.max(300, this.chartBox.clientWidth || 800), height: Math.max(240, window.innerHeight - 240) }; }

  addFromInput() {
    const spec = this.input.value.trim();
    if (spec) this.add(spec);
    this.input.value = "";
  }

  add(spec) {
    if (this.series.some((s) => s.spec === spec)) return;
    const s = { spec, topic: null, path: [], sub: null, times: [], values: [], error: null, color: COLORS[this.series.length % COLORS.length] };
    this.series.push(s);
    this.bind(s);
    this.makeChart();
  }

  remove(s) {
    s.sub?.unsubscribe();
    this.series = this.series.filter((x) => x !== s);
    this.makeChart();
  }

  /** Subscribe a series once its topic is advertised (retried on every channel change). */
  bind(s) {
    if (s.sub) {
      if (this.ros.byTopic.has(s.topic)) return;
      s.sub.unsubscribe(); // the topic went away: wait for it again
      s.sub = null;
      s.error = `topic ${s.topic} is not published any more`;
      this.renderLegend();
      return;
    }
    const names = new Set(this.ros.topics().map((t) => t.name));
    const split = splitTopicField(s.spec, names);
    if (!split) {
      s.error = `waiting for topic of ${s.spec} (no such topic is published)`;
      this.renderLegend();
      return;
    }
    try {
      s.path = parsePath(split.fields);
    } catch (err) {
      s.error = err.message;
      this.renderLegend();
      return;
    }
    if (!s.path.length) {
      s.error = `${s.spec} is a message (${this.ros.byTopic.get(split.topic).schemaName}), not a numeric field: name a field, e.g. ${s.spec}/data`;
      this.renderLegend();
      return;
    }
    s.topic = split.topic;
    s.error = null;
    s.sub = this.ros.subscribe(s.topic, (msg, info) => this.onMessage(s, msg, info), { onError: (text) => { s.error = text; this.renderLegend(); } });
    this.renderLegend();
  }

  onChannels() {
    this.topicList.replaceChildren(...this.ros.topics().map((t) => el("option", { value: t.name })));
    for (const s of this.series) this.bind(s);
  }

  onMessage(s, msg, info) {
    let v;
    try {
      v = numericAt(msg, s.path, s.spec);
    } catch (err) {
      if (s.error !== err.message) { s.error = err.message; this.renderLegend(); }
      return;
    }
    if (s.error) { s.error = null; this.renderLegend(); }
    // rqt_plot's x axis: the header stamp when the message has one, else the receive time
    const h = msg.header;
    const t = h && h.stamp && h.stamp.secs ? h.stamp.secs + h.stamp.nsecs / 1e9 : info.receiveTimeNs / 1e9;
    if (this.t0 === null) this.t0 = t;
    s.times.push(t - this.t0);
    s.values.push(v);
    this.dirty = true;
  }

  renderLegend() {
    this.legend.replaceChildren(...this.series.map((s) => el("div", { class: "plot-series-row", "data-spec": s.spec },
      el("span", { style: `color:${s.color}` }, "■ "), s.spec, " ",
      el("button", { onclick: () => this.remove(s), title: "remove" }, "−"),
      s.error ? el("span", { class: "rq-msg plot-error" }, s.error) : null)));
  }

  makeChart() {
    this.chart?.destroy();
    const opts = {
      ...this.size(),
      scales: { x: { time: false } },
      axes: [{ label: "time (s)" }, {}],
      cursor: { drag: { x: true, y: true, uni: 20 } },
      hooks: { setSelect: [() => { this.paused = true; this.pauseBox.checked = true; }] },
      series: [{ label: "t" }, ...this.series.map((s) => ({ label: s.spec, stroke: s.color, spanGaps: true, points: { show: false } }))],
    };
    this.chart = new uPlot(opts, this.alignedData(), this.chartBox);
    this.renderLegend();
  }

  /** Every series on one x axis (uPlot's aligned data): the union of their times, gaps as null. */
  alignedData() {
    const now = Math.max(0, ...this.series.map((s) => s.times[s.times.length - 1] ?? 0));
    const lo = now - this.window;
    const keepFrom = now - Math.max(this.window * 3, 60); // some history for zooming out after a pause
    for (const s of this.series) {
      let i = 0;
      while (i < s.times.length && s.times[i] < keepFrom) i++;
      if (i) { s.times.splice(0, i); s.values.splice(0, i); }
    }
    if (this.series.length === 1) {
      const s = this.series[0];
      let i = 0;
      while (i < s.times.length && s.times[i] < lo) i++;
      return [s.times.slice(i), s.values.slice(i)];
    }
    const rows = [];
    this.series.forEach((s, k) => { for (let i = 0; i < s.times.length; i++) if (s.times[i] >= lo) rows.push([s.times[i], k, s.values[i]]); });
    rows.sort((a, b) => a[0] - b[0]);
    const xs = new Float64Array(rows.length);
    const ys = this.series.map(() => new Array(rows.length).fill(null));
    rows.forEach((r, i) => { xs[i] = r[0]; ys[r[1]][i] = r[2]; });
    return [xs, ...ys];
  }

  redraw() {
    if (this.paused || !this.dirty || !this.chart) return;
    this.dirty = false;
    this.chart.setData(this.alignedData());
  }

  resetZoom() {
    this.paused = false;
    this.pauseBox.checked = false;
    this.dirty = true;
  }

  clearData() {
    for (const s of this.series) { s.times = []; s.values = []; }
    this.t0 = null;
    this.dirty = true;
  }

  /** The series' visible values (for tests and scripts): {spec: [[t, v], ...]}. */
  data() {
    return Object.fromEntries(this.series.map((s) => [s.spec, s.times.map((t, i) => [t, s.values[i]])]));
  }
}
