// rqt_reconfigure (dynamic_reconfigure servers: ~parameter_descriptions, ~parameter_updates,
// ~set_parameters) and axclient (any action server: goal, feedback, result, status, cancel).

import { el, MessageArea, fillSelect, toJson, plain } from "./common.js";

const KIND = { int: "ints", double: "doubles", bool: "bools", str: "strs" };

/** The enum of a parameter's edit_method (Python's repr of a dict): [{name, value}], or null. */
function enumOf(editMethod, type) {
  if (!editMethod || !editMethod.includes("'enum'")) return null;
  const out = [];
  for (const item of editMethod.matchAll(/\{[^{}]*\}/g)) {
    const name = /'name':\s*'([^']*)'/.exec(item[0]);
    const value = /'value':\s*('(?:[^'\\]|\\.)*'|[^,}]+)/.exec(item[0]);
    if (!name || !value) continue;
    let v = value[1].trim();
    if (type === "str") v = v.replace(/^'|'$/g, "");
    else if (type === "bool") v = v === "True";
    else v = Number(v);
    out.push({ name: name[1], value: v });
  }
  return out.length ? out : null;
}

function configValues(config) {
  const out = {};
  for (const key of ["bools", "ints", "strs", "doubles"]) for (const p of config[key] || []) out[p.name] = p.value;
  return out;
}

export class ReconfigureTool {
  constructor(pane, ros, params) {
    this.ros = ros;
    this.msgs = new MessageArea();
    this.select = el("select", { class: "rc-server", onchange: () => this.open(this.select.value) });
    this.form = el("div", { class: "rc-form" });
    pane.append(el("div", { class: "rq-bar" }, "Server ", this.select), this.msgs.node, this.form);
    this.wanted = params.get("node");
    ros.on("services", () => this.refresh());
    this.refresh();
  }

  refresh() {
    const servers = this.ros.serviceList().filter((s) => s.name.endsWith("/set_parameters") && s.type === "dynamic_reconfigure/Reconfigure")
      .map((s) => ({ value: s.name.slice(0, -"/set_parameters".length) }));
    fillSelect(this.select, servers, "(choose a server)");
    if (this.wanted) {
      const want = this.wanted.startsWith("/") ? this.wanted : `/${this.wanted}`;
      if (servers.some((s) => s.value === want)) { this.wanted = null; this.select.value = want; this.open(want); }
    }
  }

  open(server) {
    this.subs?.forEach((s) => s.unsubscribe());
    this.subs = [];
    this.server = server;
    this.widgets = new Map();
    this.form.replaceChildren();
    this.msgs.clear();
    if (!server) return;
    this.form.dataset.server = server;
    this.subs.push(this.ros.subscribe(`${server}/parameter_descriptions`, (d) => this.build(d), { type: "dynamic_reconfigure/ConfigDescription", onError: (t) => this.msgs.show(t) }));
    this.subs.push(this.ros.subscribe(`${server}/parameter_updates`, (c) => this.apply(c), { type: "dynamic_reconfigure/Config", onError: (t) => this.msgs.show(t) }));
  }

  build(desc) {
    const min = configValues(desc.min);
    const max = configValues(desc.max);
    const dflt = configValues(desc.dflt);
    this.form.replaceChildren();
    this.widgets = new Map();
    for (const group of desc.groups) {
      if (group.parameters.length === 0) continue;
      const box = el("fieldset", { "data-group": group.name }, el("legend", {}, group.name));
      for (const p of group.parameters) box.append(this.widget(p, min[p.name], max[p.name], dflt[p.name]));
      this.form.append(box);
    }
    if (this.last) this.apply(this.last);
  }

  widget(p, lo, hi, dflt) {
    const options = enumOf(p.edit_method, p.type);
    const row = el("div", { class: "rc-param", "data-param": p.name, title: p.description });
    const label = el("label", {}, p.name);
    let input;
    let number = null;
    const send = (v) => this.set(p, v);
    if (options) {
      input = el("select", { class: "rc-enum", onchange: () => send(p.type === "str" ? input.value : p.type === "bool" ? input.value === "true" : Number(input.value)) },
        ...options.map((o) => el("option", { value: String(o.value) }, `${o.name} (${o.value})`)));
      row.append(label, input, el("span"));
      this.widgets.set(p.name, { set: (v) => { input.value = String(v); } });
    } else if (p.type === "bool") {
      input = el("input", { type: "checkbox", class: "rc-bool", onchange: () => send(input.checked) });
      row.append(label, input, el("span"));
      this.widgets.set(p.name, { set: (v) => { input.checked = !!v; } });
    } else if (p.type === "str") {
      input = el("input", { type: "text", class: "rc-str", onchange: () => send(input.value) });
      row.append(label, input, el("span"));
      this.widgets.set(p.name, { set: (v) => { input.value = v; } });
    } else {
      const isInt = p.type === "int";
      const finite = Number.isFinite(lo) && Number.isFinite(hi) && Math.abs(hi - lo) < 1e12;
      input = el("input", { type: "range", class: "rc-slider", min: finite ? lo : 0, max: finite ? hi : 1, step: isInt ? 1 : finite ? (hi - lo) / 1000 : 0.001, disabled: !finite });
      number = el("input", { type: "number", class: "rc-number", step: isInt ? 1 : "any", style: "width:8em" });
      input.addEventListener("change", () => send(isInt ? Math.round(Number(input.value)) : Number(input.value)));
      input.addEventListener("input", () => { number.value = input.value; });
      number.addEventListener("change", () => {
        const v = Number(number.value);
        if (number.value === "" || !Number.isFinite(v) || (isInt && !Number.isInteger(v))) { this.msgs.show(`${p.name}: '${number.value}' is not ${isInt ? "an integer" : "a number"}`); return; }
        send(v);
      });
      row.append(label, input, number);
      // a server update never overwrites the number the user is typing (it arrives late on a busy machine)
      this.widgets.set(p.name, { set: (v) => { input.value = v; if (document.activeElement !== number) number.value = v; } });
    }
    row.append(el("small", { style: "grid-column: 1 / 4; color: #666" }, `${p.description}${dflt !== undefined ? ` (default ${dflt})` : ""}`));
    return row;
  }

  apply(config) {
    this.last = config;
    for (const [name, v] of Object.entries(configValues(config))) this.widgets.get(name)?.set(v);
  }

  async set(p, value) {
    const config = { bools: [], ints: [], strs: [], doubles: [], groups: [] };
    config[KIND[p.type]].push({ name: p.name, value });
    try {
      const resp = await this.ros.callService(`${this.server}/set_parameters`, { config });
      this.apply(resp.config);
      this.msgs.clear();
    } catch (err) {
      this.msgs.show(`${this.server}: set ${p.name}: ${err.message}`);
    }
  }
}

const STATUS = ["PENDING", "ACTIVE", "PREEMPTED", "SUCCEEDED", "ABORTED", "REJECTED", "PREEMPTING", "RECALLING", "RECALLED", "LOST"];

export class AxClientTool {
  constructor(pane, ros, params) {
    this.ros = ros;
    this.msgs = new MessageArea();
    this.actionInput = el("input", { type: "text", class: "ax-action", placeholder: "/action_name", size: 28, value: params.get("action") || "" });
    this.typeInput = el("input", { type: "text", class: "ax-type", placeholder: "pkg/NameAction (optional)", size: 34, value: params.get("type") || "" });
    this.editor = el("textarea", { class: "rq-edit ax-goal", spellcheck: false });
    this.sendButton = el("button", { class: "ax-send", disabled: true, onclick: () => this.send() }, "SEND GOAL");
    this.cancelButton = el("button", { class: "ax-cancel", disabled: true, onclick: () => this.cancel() }, "CANCEL GOAL");
    this.status = el("div", { class: "ax-status" }, "");
    this.feedback = el("pre", { class: "rq-json ax-feedback" });
    this.result = el("pre", { class: "rq-json ax-result" });
    pane.append(
      el("div", { class: "rq-bar" }, "Action ", this.actionInput, " Type ", this.typeInput, el("button", { class: "ax-connect", onclick: () => this.connect() }, "connect")),
      this.msgs.node, el("div", {}, "Goal"), this.editor,
      el("div", { class: "rq-bar" }, this.sendButton, this.cancelButton, this.status),
      el("div", {}, "Feedback"), this.feedback, el("div", {}, "Result"), this.result,
    );
    this.goalId = null;
    if (this.actionInput.value) {
      if (this.typeInput.value) this.connect();
      else ros.ready().then(() => this.connect());
    }
  }

  /** The action's base type "pkg/Name": from the type given, else from the server's topics. */
  baseType(action) {
    const given = this.typeInput.value.trim();
    if (given) return given.replace(/Action$/, "");
    for (const [suffix, tail] of [["feedback", "ActionFeedback"], ["result", "ActionResult"], ["goal", "ActionGoal"]]) {
      const ch = this.ros.byTopic.get(`${action}/${suffix}`);
      if (ch && ch.schemaName.endsWith(tail)) return ch.schemaName.slice(0, -tail.length);
    }
    return null;
  }

  async connect() {
    const action = this.actionInput.value.trim().replace(/\/$/, "");
    this.subs?.forEach((s) => s.unsubscribe());
    this.subs = [];
    this.sendButton.disabled = true;
    this.cancelButton.disabled = true;
    if (!action) { this.msgs.show("give an action name, e.g. /fibonacci"); return; }
    const base = this.baseType(action);
    if (!base) {
      this.msgs.show(`no action server at ${action} (nothing publishes ${action}/feedback or ${action}/result): start it, or give the type`);
      clearTimeout(this.retry);
      this.retry = setTimeout(() => this.connect(), 1500);
      return;
    }
    this.action = action;
    this.base = base;
    try {
      const goalCodec = await this.ros.codecForType(`${base}Goal`);
      if (!this.editor.value.trim()) this.editor.value = JSON.stringify(plain(goalCodec.defaults()), null, 2);
      this.goalPub = this.ros.advertise(`${action}/goal`, `${base}ActionGoal`);
      this.cancelPub = this.ros.advertise(`${action}/cancel`, "actionlib_msgs/GoalID");
      await Promise.all([this.goalPub.ready, this.cancelPub.ready]);
    } catch (err) {
      this.msgs.show(`${action}: ${err.message}`);
      return;
    }
    this.subs.push(this.ros.subscribe(`${action}/feedback`, (m) => { if (this.mine(m.status)) this.feedback.textContent = toJson(m.feedback); }, { type: `${base}ActionFeedback`, onError: (t) => this.msgs.show(t) }));
    this.subs.push(this.ros.subscribe(`${action}/result`, (m) => {
      if (!this.mine(m.status)) return;
      this.result.textContent = toJson(m.result);
      this.showStatus(m.status);
      this.cancelButton.disabled = true;
    }, { type: `${base}ActionResult`, onError: (t) => this.msgs.show(t) }));
    this.subs.push(this.ros.subscribe(`${action}/status`, (m) => {
      const s = m.status_list.find((x) => x.goal_id.id === this.goalId);
      if (s) this.showStatus(s);
    }, { type: "actionlib_msgs/GoalStatusArray" }));
    this.msgs.show(`connected to ${action} (${base}Action)`, "info");
    // the server's subscriber connects to our new publisher a moment after the master tells it
    setTimeout(() => { this.sendButton.disabled = false; }, 1000);
  }

  mine(status) { return this.goalId !== null && status.goal_id.id === this.goalId; }

  showStatus(s) {
    this.status.textContent = `${STATUS[s.status] || s.status}${s.text ? `: ${s.text}` : ""}`;
    this.status.dataset.status = STATUS[s.status] || s.status;
  }

  send() {
    let goal;
    try {
      goal = JSON.parse(this.editor.value || "{}");
    } catch (err) {
      this.msgs.show(`goal is not valid JSON: ${err.message}`);
      return;
    }
    const stamp = this.ros.stamp();
    this.goalId = `/axclient-${stamp.secs}.${stamp.nsecs}-${Math.random().toString(36).slice(2, 8)}`;
    this.feedback.textContent = "";
    this.result.textContent = "";
    this.status.textContent = "sent";
    this.status.dataset.status = "SENT";
    try {
      this.goalPub.publish({ header: { stamp }, goal_id: { stamp, id: this.goalId }, goal });
      this.cancelButton.disabled = false;
      this.msgs.clear();
    } catch (err) {
      this.msgs.show(`${this.action}/goal: ${err.message}`);
    }
  }

  cancel() {
    if (!this.goalId) return;
    this.cancelPub.publish({ stamp: { secs: 0, nsecs: 0 }, id: this.goalId });
  }
}
