// rqt_console (/rosout_agg: severity, node and regex filters, pause, clear, save) and
// rqt_logger_level (a node's loggers through its ~get_loggers / ~set_logger_level services).

import { el, MessageArea, fillSelect } from "./common.js";

const LEVELS = [[1, "Debug"], [2, "Info"], [4, "Warn"], [8, "Error"], [16, "Fatal"]];
const LEVEL_NAME = Object.fromEntries(LEVELS);
const MAX_MESSAGES = 20000;

export class ConsoleTool {
  constructor(pane, ros) {
    this.ros = ros;
    this.messages = [];
    this.paused = false;
    this.msgs = new MessageArea();
    this.levelBoxes = LEVELS.map(([v, name]) => {
      const box = el("input", { type: "checkbox", checked: true, "data-level": name, onchange: () => this.render() });
      box.value = v;
      return el("label", {}, box, name);
    });
    this.nodeFilter = el("input", { type: "text", placeholder: "node contains", class: "console-node", oninput: () => this.render() });
    this.regex = el("input", { type: "text", placeholder: "message regex", class: "console-regex", oninput: () => this.render() });
    this.pauseBox = el("input", { type: "checkbox", class: "console-pause", onchange: () => { this.paused = this.pauseBox.checked; this.render(); } });
    this.count = el("span", { class: "console-count" });
    this.body = el("tbody");
    pane.append(
      el("div", { class: "rq-bar" }, ...this.levelBoxes, this.nodeFilter, this.regex,
        el("label", {}, this.pauseBox, " pause"),
        el("button", { class: "console-clear", onclick: () => { this.messages = []; this.render(); } }, "clear"),
        el("button", { class: "console-save", onclick: () => this.save() }, "save"), this.count),
      this.msgs.node,
      el("table", { class: "rq-table console-table" },
        el("thead", {}, el("tr", {}, ...["#", "Severity", "Message", "Node", "Stamp", "Topics", "Location"].map((h) => el("th", {}, h)))),
        this.body),
    );
    this.seq = 0;
    ros.subscribe("/rosout_agg", (m) => this.onLog(m), { type: "rosgraph_msgs/Log", onError: (t) => this.msgs.show(t) });
    this.pending = false;
  }

  onLog(m) {
    if (this.paused) return; // rqt_console drops what arrives while paused
    this.messages.push({ n: ++this.seq, ...m });
    if (this.messages.length > MAX_MESSAGES) this.messages.splice(0, this.messages.length - MAX_MESSAGES);
    if (!this.pending) {
      this.pending = true;
      requestAnimationFrame(() => { this.pending = false; this.render(); });
    }
  }

  filtered() {
    const levels = new Set(this.levelBoxes.map((l) => l.firstChild).filter((b) => b.checked).map((b) => Number(b.value)));
    const node = this.nodeFilter.value.trim();
    let re = null;
    if (this.regex.value) {
      try {
        re = new RegExp(this.regex.value);
        this.msgs.clear();
      } catch (err) {
        this.msgs.show(`message filter: invalid regular expression: ${err.message}`);
      }
    } else this.msgs.clear();
    return this.messages.filter((m) => levels.has(m.level) && (!node || m.name.includes(node)) && (!re || re.test(m.msg)));
  }

  render() {
    const rows = this.filtered();
    const shown = rows.slice(-1000); // the newest thousand; save writes them all
    this.count.textContent = `${rows.length} of ${this.messages.length} messages`;
    this.body.replaceChildren(...shown.reverse().map((m) => el("tr", { class: `sev-${m.level}`, "data-node": m.name },
      el("td", {}, m.n), el("td", { class: "sev" }, LEVEL_NAME[m.level] || m.level), el("td", { class: "msg" }, m.msg), el("td", {}, m.name),
      el("td", {}, `${m.header.stamp.secs}.${String(m.header.stamp.nsecs).padStart(9, "0")}`), el("td", {}, m.topics.join(", ")),
      el("td", {}, `${m.file}:${m.function}:${m.line}`))));
  }

  /** Download the filtered messages as rqt_console's .csv layout. */
  save() {
    const quote = (s) => `"${String(s).replace(/"/g, '""')}"`;
    const lines = ["message;severity;node;stamp;topics;location"];
    for (const m of this.filtered()) {
      lines.push([m.msg, LEVEL_NAME[m.level], m.name, `${m.header.stamp.secs}.${String(m.header.stamp.nsecs).padStart(9, "0")}`, m.topics.join(", "), `${m.file}:${m.function}:${m.line}`].map(quote).join(";"));
    }
    const a = el("a", { href: URL.createObjectURL(new Blob([lines.join("\n") + "\n"], { type: "text/csv" })), download: "rqt_console.csv" });
    a.click();
    setTimeout(() => URL.revokeObjectURL(a.href), 1000);
  }
}

export class LoggerLevelTool {
  constructor(pane, ros) {
    this.ros = ros;
    this.msgs = new MessageArea();
    this.nodeSelect = el("select", { class: "ll-node", onchange: () => this.loadLoggers() });
    this.loggerList = el("select", { class: "ll-logger", size: 12, onchange: () => this.showLevel() });
    this.levelList = el("select", { class: "ll-level", size: 5, onchange: () => this.setLevel() },
      ...["debug", "info", "warn", "error", "fatal"].map((l) => el("option", { value: l }, l)));
    pane.append(
      el("div", { class: "rq-bar" }, "Node ", this.nodeSelect, el("button", { onclick: () => this.refresh() }, "refresh")),
      this.msgs.node,
      el("div", { class: "rq-bar", style: "align-items:flex-start" }, el("div", {}, "Loggers", el("br"), this.loggerList), el("div", {}, "Level", el("br"), this.levelList)),
    );
    ros.on("services", () => this.refresh());
    this.refresh();
    this.loggers = [];
  }

  refresh() {
    const nodes = this.ros.serviceList().filter((s) => s.name.endsWith("/get_loggers")).map((s) => ({ value: s.name.slice(0, -"/get_loggers".length) }));
    fillSelect(this.nodeSelect, nodes, "(choose a node)");
  }

  async loadLoggers() {
    const node = this.nodeSelect.value;
    this.loggerList.replaceChildren();
    if (!node) return;
    try {
      const resp = await this.ros.callService(`${node}/get_loggers`, {});
      this.loggers = resp.loggers;
      this.loggerList.replaceChildren(...resp.loggers.map((l) => el("option", { value: l.name }, l.name)));
      this.msgs.clear();
    } catch (err) {
      this.msgs.show(`${node}: ${err.message}`);
    }
  }

  showLevel() {
    const l = this.loggers.find((x) => x.name === this.loggerList.value);
    if (l) this.levelList.value = l.level.toLowerCase();
  }

  async setLevel() {
    const node = this.nodeSelect.value;
    const logger = this.loggerList.value;
    const level = this.levelList.value;
    if (!node || !logger) { this.msgs.show("choose a node and a logger first"); return; }
    try {
      await this.ros.callService(`${node}/set_logger_level`, { logger, level });
      const l = this.loggers.find((x) => x.name === logger);
      if (l) l.level = level;
      this.msgs.show(`${node}: ${logger} set to ${level}`, "info");
    } catch (err) {
      this.msgs.show(`${node}: ${err.message}`);
    }
  }
}
