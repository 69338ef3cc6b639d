// Reads [{type, definition, hex}] (JSON on stdin); for each: decode, re-encode; prints
// [{value, hex}] with typed arrays as plain lists (BigInts as Numbers) so Python can compare.
import { readFileSync } from "node:fs";
import { pathToFileURL } from "node:url";

const lib = process.argv[2];
const { codecFor } = await import(pathToFileURL(lib).href);
const cases = JSON.parse(readFileSync(0, "utf8"));

function plain(v) {
  if (ArrayBuffer.isView(v)) return Array.from(v, (x) => (typeof x === "bigint" ? Number(x) : x));
  if (Array.isArray(v)) return v.map(plain);
  if (v && typeof v === "object") return Object.fromEntries(Object.entries(v).map(([k, x]) => [k, plain(x)]));
  return v;
}

const out = cases.map((c) => {
  const codec = codecFor(c.type, c.definition);
  const bytes = Uint8Array.from(Buffer.from(c.hex, "hex"));
  // an odd offset into a bigger buffer, as in a Foxglove frame: typed arrays must still come out right
  const framed = new Uint8Array(bytes.length + 13);
  framed.set(bytes, 13);
  const value = codec.decode(new Uint8Array(framed.buffer, 13, bytes.length));
  const hex = Buffer.from(codec.encode(value)).toString("hex");
  let error = null;
  try {
    codec.decode(bytes.subarray(0, Math.max(0, bytes.length - 1)));
  } catch (err) {
    error = err.message;
  }
  return { value: plain(value), hex, truncatedError: error };
});
process.stdout.write(JSON.stringify(out));
