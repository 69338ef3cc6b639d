// ROS 1 message definitions and the ROS 1 binary format, in the browser.
//
// The gateway sends each topic's payload exactly as TCPROS carried it, with the full definition
// text (`ros1msg`: the type's own .msg text, then every dependency after a line of `=`s and a
// `MSG: pkg/Type` line). This module turns that text into field layouts and compiles, per type, a
// reader and a writer, so a page decodes with no per-message interpretation. Numeric arrays become
// typed arrays (a view into the received buffer when aligned, a copy otherwise), so a 100k-point
// cloud or a 4 MB map costs one memcpy at most, never a loop over elements.
//
// Plain objects match rospy's: `time`/`duration` are {secs, nsecs}; int64/uint64 scalars are
// Numbers (exact below 2^53), their arrays BigInt64Array/BigUint64Array; uint8[]/char[] are
// Uint8Array, byte[]/int8[] Int8Array; bool[] a plain array of booleans.

const PRIMITIVE_SIZE = {
  bool: 1, int8: 1, uint8: 1, byte: 1, char: 1,
  int16: 2, uint16: 2, int32: 4, uint32: 4, float32: 4,
  int64: 8, uint64: 8, float64: 8, time: 8, duration: 8,
};
const PRIMITIVES = new Set([...Object.keys(PRIMITIVE_SIZE), "string"]);

const TYPED_ARRAY = {
  int8: Int8Array, byte: Int8Array, uint8: Uint8Array, char: Uint8Array,
  int16: Int16Array, uint16: Uint16Array, int32: Int32Array, uint32: Uint32Array,
  float32: Float32Array, float64: Float64Array, int64: BigInt64Array, uint64: BigUint64Array,
};

/** An error in a definition text or a payload, naming the type and field it concerns. */
export class RosMsgError extends Error {}

/** True for ROS 1's built-in field types (including time, duration and string). */
export function isPrimitive(type) {
  return PRIMITIVES.has(type);
}

function qualify(type, pkg) {
  if (PRIMITIVES.has(type) || type.includes("/")) return type;
  if (type === "Header") return "std_msgs/Header";
  return pkg ? `${pkg}/${type}` : type;
}

function parseSection(name, text) {
  const pkg = name.includes("/") ? name.split("/")[0] : "";
  const fields = [];
  const constants = [];
  const lines = text.split("\n");
  for (let i = 0; i < lines.length; i++) {
    const raw = lines[i];
    const hash = raw.indexOf("#");
    let line = (hash >= 0 ? raw.slice(0, hash) : raw).trim();
    if (!line) continue;
    const m = /^([A-Za-z_][\w/]*)(\[(\d*)\])?\s+([A-Za-z_]\w*)\s*(=\s*(.*))?$/.exec(
      // a string constant keeps everything after '=', '#' included
      /^string\s+\w+\s*=/.test(raw.trim()) ? raw.trim() : line,
    );
    if (!m) throw new RosMsgError(`${name}:${i + 1}: cannot parse '${raw.trim()}'`);
    const [, baseRaw, arr, len, fieldName, isConst, value] = m;
    const base = baseRaw === "Header" && pkg !== "std_msgs" ? "std_msgs/Header" : baseRaw;
    if (isConst !== undefined) {
      let v;
      if (base === "string") v = value;
      else if (base === "bool") v = value.trim() !== "0" && value.trim().toLowerCase() !== "false";
      else v = Number(value.trim());
      constants.push({ name: fieldName, type: base, value: v });
      continue;
    }
    const type = qualify(base, pkg);
    fields.push({
      name: fieldName,
      type,
      isArray: arr !== undefined,
      arrayLength: arr !== undefined && len !== "" ? Number(len) : undefined,
      isComplex: !PRIMITIVES.has(type),
    });
  }
  return { name, fields, constants };
}

/**
 * Parse a full ros1msg definition (the root type's text and its `MSG:` sections).
 * Returns a Map from "pkg/Type" to {name, fields, constants}; the root is under `rootName`.
 */
export function parseDefinition(rootName, text) {
  const types = new Map();
  const sections = text.split(/\n=+\n/);
  sections.forEach((section, index) => {
    let name = rootName;
    let body = section;
    if (index > 0) {
      const m = /^\s*MSG:\s*(\S+)\s*\n?/.exec(section);
      if (!m) throw new RosMsgError(`${rootName}: dependency section ${index} has no 'MSG: pkg/Type' line`);
      name = m[1];
      body = section.slice(m[0].length);
    }
    types.set(name, parseSection(name, body));
  });
  for (const [name, def] of types) {
    for (const f of def.fields) {
      if (f.isComplex && !types.has(f.type)) {
        throw new RosMsgError(`${name}.${f.name}: no definition of ${f.type} in ${rootName}'s text`);
      }
    }
  }
  return types;
}

// ------------------------------------------------------------------------------------------------
// reading

const utf8 = new TextDecoder("utf-8");

class Reader {
  constructor(bytes) {
    this.bytes = bytes;
    this.view = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
    this.off = 0;
  }
  need(n, what) {
    if (this.off + n > this.bytes.byteLength) {
      throw new RosMsgError(`payload too short reading ${what} at byte ${this.off} (${this.bytes.byteLength} bytes)`);
    }
  }
  u32(what) {
    this.need(4, what);
    const v = this.view.getUint32(this.off, true);
    this.off += 4;
    return v;
  }
  string(what) {
    const n = this.u32(what);
    this.need(n, what);
    const b = this.bytes;
    const start = this.off;
    this.off += n;
    if (n < 32) {
      let s = "";
      for (let i = start; i < start + n; i++) {
        const c = b[i];
        if (c > 127) return utf8.decode(b.subarray(start, start + n));
        s += String.fromCharCode(c);
      }
      return s;
    }
    return utf8.decode(b.subarray(start, start + n));
  }
  typedArray(type, n, what) {
    const Ctor = TYPED_ARRAY[type];
    const size = Ctor.BYTES_PER_ELEMENT;
    this.need(n * size, what);
    const abs = this.bytes.byteOffset + this.off;
    let out;
    if (abs % size === 0) out = new Ctor(this.bytes.buffer, abs, n);
    else out = new Ctor(this.bytes.buffer.slice(abs, abs + n * size));
    this.off += n * size;
    return out;
  }
}

function primitiveReader(type, what) {
  switch (type) {
    case "bool": return (r) => { r.need(1, what); return r.bytes[r.off++] !== 0; };
    case "int8": case "byte": return (r) => { r.need(1, what); const v = r.view.getInt8(r.off); r.off += 1; return v; };
    case "uint8": case "char": return (r) => { r.need(1, what); return r.bytes[r.off++]; };
    case "int16": return (r) => { r.need(2, what); const v = r.view.getInt16(r.off, true); r.off += 2; return v; };
    case "uint16": return (r) => { r.need(2, what); const v = r.view.getUint16(r.off, true); r.off += 2; return v; };
    case "int32": return (r) => { r.need(4, what); const v = r.view.getInt32(r.off, true); r.off += 4; return v; };
    case "uint32": return (r) => r.u32(what);
    case "int64": return (r) => { r.need(8, what); const v = Number(r.view.getBigInt64(r.off, true)); r.off += 8; return v; };
    case "uint64": return (r) => { r.need(8, what); const v = Number(r.view.getBigUint64(r.off, true)); r.off += 8; return v; };
    case "float32": return (r) => { r.need(4, what); const v = r.view.getFloat32(r.off, true); r.off += 4; return v; };
    case "float64": return (r) => { r.need(8, what); const v = r.view.getFloat64(r.off, true); r.off += 8; return v; };
    case "string": return (r) => r.string(what);
    case "time": case "duration": {
      const signed = type === "duration";
      return (r) => {
        r.need(8, what);
        const secs = signed ? r.view.getInt32(r.off, true) : r.view.getUint32(r.off, true);
        const nsecs = signed ? r.view.getInt32(r.off + 4, true) : r.view.getUint32(r.off + 4, true);
        r.off += 8;
        return { secs, nsecs };
      };
    }
    default: throw new RosMsgError(`unknown primitive ${type}`);
  }
}

function fieldReader(field, compiled, owner) {
  const what = `${owner}.${field.name}`;
  const one = field.isComplex ? compiled(field.type) : primitiveReader(field.type, what);
  if (!field.isArray) return field.isComplex ? (r) => one.read(r) : one;
  const fixed = field.arrayLength;
  const count = fixed !== undefined ? () => fixed : (r) => r.u32(what);
  if (!field.isComplex && TYPED_ARRAY[field.type]) {
    return (r) => r.typedArray(field.type, count(r), what);
  }
  if (field.isComplex) {
    return (r) => {
      const n = count(r);
      const out = new Array(n);
      for (let i = 0; i < n; i++) out[i] = one.read(r);
      return out;
    };
  }
  return (r) => {
    const n = count(r);
    const out = new Array(n);
    for (let i = 0; i < n; i++) out[i] = one(r);
    return out;
  };
}

// ------------------------------------------------------------------------------------------------
// writing

const utf8enc = new TextEncoder();

class Writer {
  constructor(size = 256) {
    this.buf = new Uint8Array(size);
    this.view = new DataView(this.buf.buffer);
    this.off = 0;
  }
  reserve(n) {
    if (this.off + n <= this.buf.length) return;
    let size = this.buf.length * 2;
    while (size < this.off + n) size *= 2;
    const next = new Uint8Array(size);
    next.set(this.buf.subarray(0, this.off));
    this.buf = next;
    this.view = new DataView(next.buffer);
  }
  u32(v) {
    this.reserve(4);
    this.view.setUint32(this.off, v, true);
    this.off += 4;
  }
  bytes(b) {
    this.reserve(b.length);
    this.buf.set(b, this.off);
    this.off += b.length;
  }
  result() {
    return this.buf.slice(0, this.off);
  }
}

function num(v, what) {
  if (typeof v === "bigint") return Number(v);
  if (typeof v === "boolean") return v ? 1 : 0;
  if (v === undefined || v === null) return 0;
  const n = Number(v);
  if (Number.isNaN(n) && typeof v !== "number") throw new RosMsgError(`${what}: ${JSON.stringify(v)} is not a number`);
  return n;
}

function primitiveWriter(type, what) {
  const set = (size, fn) => (w, v) => { w.reserve(size); fn(w.view, w.off, v); w.off += size; };
  switch (type) {
    case "bool": return set(1, (d, o, v) => d.setUint8(o, v ? 1 : 0));
    case "int8": case "byte": return set(1, (d, o, v) => d.setInt8(o, num(v, what)));
    case "uint8": case "char": return set(1, (d, o, v) => d.setUint8(o, num(v, what)));
    case "int16": return set(2, (d, o, v) => d.setInt16(o, num(v, what), true));
    case "uint16": return set(2, (d, o, v) => d.setUint16(o, num(v, what), true));
    case "int32": return set(4, (d, o, v) => d.setInt32(o, num(v, what), true));
    case "uint32": return set(4, (d, o, v) => d.setUint32(o, num(v, what), true));
    case "int64": return set(8, (d, o, v) => d.setBigInt64(o, BigInt(Math.trunc(num(v, what))), true));
    case "uint64": return set(8, (d, o, v) => d.setBigUint64(o, BigInt(Math.trunc(num(v, what))), true));
    case "float32": return set(4, (d, o, v) => d.setFloat32(o, num(v, what), true));
    case "float64": return set(8, (d, o, v) => d.setFloat64(o, num(v, what), true));
    case "string": return (w, v) => {
      const b = utf8enc.encode(v === undefined || v === null ? "" : String(v));
      w.u32(b.length);
      w.bytes(b);
    };
    case "time": case "duration": return set(8, (d, o, v) => {
      const t = v || { secs: 0, nsecs: 0 };
      const secs = num(t.secs ?? t.sec, what);
      const nsecs = num(t.nsecs ?? t.nsec, what);
      if (type === "time") { d.setUint32(o, secs, true); d.setUint32(o + 4, nsecs, true); }
      else { d.setInt32(o, secs, true); d.setInt32(o + 4, nsecs, true); }
    });
    default: throw new RosMsgError(`unknown primitive ${type}`);
  }
}

function fieldWriter(field, compiled, owner) {
  const what = `${owner}.${field.name}`;
  const one = field.isComplex ? compiled(field.type) : primitiveWriter(field.type, what);
  const writeOne = field.isComplex ? (w, v) => one.write(w, v || {}) : one;
  if (!field.isArray) return writeOne;
  const fixed = field.arrayLength;
  const Ctor = field.isComplex ? undefined : TYPED_ARRAY[field.type];
  return (w, value) => {
    let v = value || [];
    if (typeof v === "string" && (field.type === "uint8" || field.type === "char")) v = utf8enc.encode(v);
    const n = fixed !== undefined ? fixed : v.length;
    if (fixed !== undefined && v.length !== fixed && v.length !== 0) {
      throw new RosMsgError(`${what}: needs ${fixed} elements, got ${v.length}`);
    }
    if (fixed === undefined) w.u32(n);
    if (Ctor && Ctor !== BigInt64Array && Ctor !== BigUint64Array && (v.length === n)) {
      const typed = v instanceof Ctor ? v : Ctor.from(v, (x) => num(x, what));
      w.bytes(new Uint8Array(typed.buffer, typed.byteOffset, typed.byteLength));
      return;
    }
    for (let i = 0; i < n; i++) writeOne(w, v[i]);
  };
}

// ------------------------------------------------------------------------------------------------

/** A compiled message type: `decode(bytes)` → plain object, `encode(object)` → Uint8Array. */
export class MessageCodec {
  /** @param {string} name "pkg/Type"; @param {string} definition the full ros1msg text */
  constructor(name, definition) {
    this.name = name;
    this.types = parseDefinition(name, definition);
    this._compiled = new Map();
    this.root = this._compile(name);
  }

  _compile(name) {
    let c = this._compiled.get(name);
    if (c) return c;
    const def = this.types.get(name);
    if (!def) throw new RosMsgError(`no definition of ${name}`);
    c = { def, read: null, write: null };
    this._compiled.set(name, c); // set before compiling the fields: types may nest deeply
    const compile = (t) => this._compile(t);
    const readers = def.fields.map((f) => [f.name, fieldReader(f, compile, name)]);
    const writers = def.fields.map((f) => [f.name, fieldWriter(f, compile, name)]);
    c.read = (r) => {
      const out = {};
      for (let i = 0; i < readers.length; i++) out[readers[i][0]] = readers[i][1](r);
      return out;
    };
    c.write = (w, v) => {
      for (let i = 0; i < writers.length; i++) writers[i][1](w, v[writers[i][0]]);
    };
    return c;
  }

  /** Decode one payload (Uint8Array, or ArrayBuffer) into a plain object. */
  decode(data) {
    const bytes = data instanceof Uint8Array ? data : new Uint8Array(data);
    const r = new Reader(bytes);
    const out = this.root.read(r);
    if (r.off !== bytes.byteLength) {
      throw new RosMsgError(`${this.name}: ${bytes.byteLength - r.off} bytes left over after decoding (a different definition?)`);
    }
    return out;
  }

  /** Serialize a plain object (missing fields are zero/empty, as rospy's defaults). */
  encode(value) {
    const w = new Writer();
    this.root.write(w, value || {});
    return w.result();
  }

  /** A message of this type with every field at its default (zeros, empty strings and arrays). */
  defaults(name = this.name) {
    const def = this.types.get(name);
    const out = {};
    for (const f of def.fields) {
      if (f.isArray) {
        const n = f.arrayLength || 0;
        out[f.name] = f.isComplex ? Array.from({ length: n }, () => this.defaults(f.type))
          : TYPED_ARRAY[f.type] ? new TYPED_ARRAY[f.type](n) : new Array(n).fill(f.type === "string" ? "" : false);
      } else if (f.isComplex) out[f.name] = this.defaults(f.type);
      else if (f.type === "string") out[f.name] = "";
      else if (f.type === "time" || f.type === "duration") out[f.name] = { secs: 0, nsecs: 0 };
      else if (f.type === "bool") out[f.name] = false;
      else out[f.name] = 0;
    }
    return out;
  }
}

const codecCache = new Map();

/** The codec for a type and definition text, compiled once per (type, text). */
export function codecFor(name, definition) {
  const key = `${name}\n${definition}`;
  let c = codecCache.get(key);
  if (!c) {
    c = new MessageCodec(name, definition);
    codecCache.set(key, c);
  }
  return c;
}
