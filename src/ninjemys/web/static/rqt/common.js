// Small helpers shared by the rqt plugins: DOM building, a message area, field paths, JSON views.

/** Build an element: el("button", {class: "x", onclick: fn}, "text", child...). */
export function el(tag, attrs = {}, ...children) {
  const node = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs || {})) {
    if (v === undefined || v === null || v === false) continue;
    if (k.startsWith("on")) node.addEventListener(k.slice(2), v);
    else if (k === "class") node.className = v;
    else if (k in node && k !== "list") node[k] = v;
    else node.setAttribute(k, v === true ? "" : v);
  }
  for (const c of children.flat()) if (c !== null && c !== undefined) node.append(c instanceof Node ? c : String(c));
  return node;
}

/** A message area: show(text, level) replaces what it says; clear() empties it. */
export class MessageArea {
  constructor() { this.node = el("div", { class: "rq-msgs" }); }
  show(text, level = "error") {
    this.node.replaceChildren(el("div", { class: level === "error" ? "" : level }, text));
  }
  add(text, level = "error") {
    this.node.append(el("div", { class: level === "error" ? "" : level }, text));
    while (this.node.childElementCount > 5) this.node.firstChild.remove();
  }
  clear() { this.node.replaceChildren(); }
}

/** "a/b[2]/c" -> ["a", "b", 2, "c"]; throws on a malformed path. */
export function parsePath(path) {
  const out = [];
  for (const part of path.split("/").filter(Boolean)) {
    const m = /^([A-Za-z_]\w*)((?:\[\d+\])*)$/.exec(part);
    if (!m) throw new Error(`bad field '${part}' in '${path}'`);
    out.push(m[1]);
    for (const idx of m[2].matchAll(/\[(\d+)\]/g)) out.push(Number(idx[1]));
  }
  return out;
}

/**
 * Split "/topic/ns/field[0]/x" into the longest advertised topic prefix and the field path.
 * Returns {topic, fields} or null when no prefix is a known topic.
 */
export function splitTopicField(spec, topicNames) {
  const parts = spec.split("/").filter(Boolean);
  for (let n = parts.length; n > 0; n--) {
    const base = "/" + parts.slice(0, n).join("/");
    const m = /^(.*?)(\[\d+\])+$/.exec(base); // "/scan/ranges[0]" is never a topic, but "/scan" may be
    const candidate = topicNames.has(base) ? base : m && topicNames.has(m[1]) ? m[1] : null;
    if (candidate) return { topic: candidate, fields: spec.slice(spec.indexOf(candidate) + candidate.length) };
  }
  return null;
}

/** The numeric value at `path` in `msg`; throws with a one-line reason (missing, not numeric). */
export function numericAt(msg, path, label) {
  let v = msg;
  for (const key of path) {
    if (v === null || v === undefined) throw new Error(`${label}: no field ${key}`);
    if (typeof key === "number") {
      if (typeof v.length !== "number") throw new Error(`${label}: not an array before [${key}]`);
      if (key >= v.length) throw new Error(`${label}: index ${key} out of range (length ${v.length})`);
    } else if (!(key in v)) throw new Error(`${label}: no field '${key}'`);
    v = v[key];
  }
  if (typeof v === "number") return v;
  if (typeof v === "bigint") return Number(v);
  if (typeof v === "boolean") return v ? 1 : 0;
  if (v && typeof v === "object" && "secs" in v && "nsecs" in v && Object.keys(v).length === 2) return v.secs + v.nsecs / 1e9;
  const kind = typeof v === "string" ? "a string" : Array.isArray(v) || ArrayBuffer.isView(v) ? "an array" : typeof v === "object" ? "a message" : typeof v;
  throw new Error(`${label} is ${kind}, not a numeric field`);
}

/** JSON text of a decoded message, typed arrays shortened to their first `maxArray` items. */
export function toJson(msg, maxArray = 32) {
  return JSON.stringify(msg, (_k, v) => {
    if (typeof v === "bigint") return Number(v);
    if (ArrayBuffer.isView(v)) {
      const items = Array.from(v.length > maxArray ? v.subarray(0, maxArray) : v, (x) => (typeof x === "bigint" ? Number(x) : x));
      return v.length > maxArray ? [...items, `… ${v.length} items`] : items;
    }
    if (Array.isArray(v) && v.length > maxArray) return [...v.slice(0, maxArray), `… ${v.length} items`];
    return v;
  }, 2);
}

/** Typed arrays as plain arrays (for an editable JSON of a message's defaults). */
export function plain(msg) {
  return JSON.parse(JSON.stringify(msg, (_k, v) => (typeof v === "bigint" ? Number(v) : ArrayBuffer.isView(v) ? Array.from(v, Number) : v)));
}

/** Decode base64 text into bytes. */
export function b64bytes(text) {
  const bin = atob(text);
  const out = new Uint8Array(bin.length);
  for (let i = 0; i < bin.length; i++) out[i] = bin.charCodeAt(i);
  return out;
}

/** Fetch JSON; rejects with the server's one-line error. */
export async function getJson(url, init) {
  const resp = await fetch(url, init);
  const body = await resp.json().catch(() => ({}));
  if (!resp.ok) throw new Error(body.error || `${url}: HTTP ${resp.status}`);
  return body;
}

/** A <select> filled with options [{value, label}], keeping the current choice when it still exists. */
export function fillSelect(select, options, placeholder) {
  const current = select.value;
  select.replaceChildren(el("option", { value: "" }, placeholder), ...options.map((o) => el("option", { value: o.value }, o.label ?? o.value)));
  if (options.some((o) => o.value === current)) select.value = current;
}
