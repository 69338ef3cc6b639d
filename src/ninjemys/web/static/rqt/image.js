// rqt_image_view: sensor_msgs/Image (rgb8, bgr8, rgba8, bgra8, mono8, mono16/16UC1, 32FC1, 8UC1/3)
// and sensor_msgs/CompressedImage (jpeg/png) on a canvas; the newest frame is drawn once per
// animation frame, older ones are skipped.

import { el, MessageArea, fillSelect } from "./common.js";

const IMAGE_TYPES = new Set(["sensor_msgs/Image", "sensor_msgs/CompressedImage"]);

/** Depth-like images are shown scaled from their min to their max (NaN and inf as black). */
function normalized(values, n) {
  let lo = Infinity;
  let hi = -Infinity;
  for (let i = 0; i < n; i++) { const v = values[i]; if (Number.isFinite(v)) { if (v < lo) lo = v; if (v > hi) hi = v; } }
  const scale = hi > lo ? 255 / (hi - lo) : 0;
  const out = new Uint8ClampedArray(n);
  for (let i = 0; i < n; i++) { const v = values[i]; out[i] = Number.isFinite(v) ? (v - lo) * scale : 0; }
  return out;
}

/** A sensor_msgs/Image as ImageData; throws naming the encoding or size mismatch. */
export function imageToImageData(msg) {
  const { width: w, height: h, step, encoding, data } = msg;
  const n = w * h;
  if (!w || !h) throw new Error(`empty image (${w}x${h})`);
  const rgba = new Uint8ClampedArray(n * 4);
  const enc = encoding.toLowerCase();
  const channels = { rgb8: 3, bgr8: 3, "8uc3": 3, rgba8: 4, bgra8: 4, "8uc4": 4, mono8: 1, "8uc1": 1, mono16: 2, "16uc1": 2, "32fc1": 4 }[enc];
  if (channels === undefined) throw new Error(`encoding '${encoding}' is not supported (rgb8, bgr8, rgba8, bgra8, mono8, mono16, 16UC1, 32FC1)`);
  const bpp = channels;
  if (step < w * bpp || data.length < step * h) throw new Error(`${w}x${h} ${encoding} needs ${w * bpp * h} bytes (step ${step}), got ${data.length}`);
  const view = new DataView(data.buffer, data.byteOffset, data.byteLength);
  const little = !msg.is_bigendian;
  if (enc === "mono16" || enc === "16uc1" || enc === "32fc1") {
    const vals = new Float64Array(n);
    for (let y = 0; y < h; y++) for (let x = 0; x < w; x++) {
      const off = y * step + x * bpp;
      vals[y * w + x] = enc === "32fc1" ? view.getFloat32(off, little) : view.getUint16(off, little);
    }
    const g = normalized(vals, n);
    for (let i = 0; i < n; i++) { rgba[i * 4] = rgba[i * 4 + 1] = rgba[i * 4 + 2] = g[i]; rgba[i * 4 + 3] = 255; }
    return new ImageData(rgba, w, h);
  }
  const bgr = enc.startsWith("bgr") || enc === "8uc3" || enc === "8uc4"; // OpenCV's order for untyped 8UC3
  // one 32-bit store per pixel (ImageData is RGBA in memory: ABGR as a little-endian word)
  const out = new Uint32Array(rgba.buffer);
  const r0 = bgr ? 2 : 0;
  const b0 = bgr ? 0 : 2;
  for (let y = 0; y < h; y++) {
    let src = y * step;
    let dst = y * w;
    const end = dst + w;
    if (channels === 1) {
      for (; dst < end; dst++, src++) { const g = data[src]; out[dst] = 0xff000000 | (g << 16) | (g << 8) | g; }
    } else if (channels === 3) {
      for (; dst < end; dst++, src += 3) out[dst] = 0xff000000 | (data[src + b0] << 16) | (data[src + 1] << 8) | data[src + r0];
    } else {
      for (; dst < end; dst++, src += 4) out[dst] = ((data[src + 3] << 24) | (data[src + b0] << 16) | (data[src + 1] << 8) | data[src + r0]) >>> 0;
    }
  }
  return new ImageData(rgba, w, h);
}

/** Draw an Image or CompressedImage message on a canvas (resized to the image). */
export async function drawImage(canvas, type, msg) {
  if (type === "sensor_msgs/CompressedImage") {
    const fmt = msg.format.toLowerCase();
    const mime = fmt.includes("png") ? "image/png" : "image/jpeg";
    let bitmap;
    try {
      bitmap = await createImageBitmap(new Blob([msg.data], { type: mime }));
    } catch {
      throw new Error(`cannot decode a CompressedImage of format '${msg.format}' (${msg.data.length} bytes)`);
    }
    if (canvas.width !== bitmap.width || canvas.height !== bitmap.height) { canvas.width = bitmap.width; canvas.height = bitmap.height; }
    canvas.getContext("2d").drawImage(bitmap, 0, 0);
    bitmap.close();
    return;
  }
  const img = imageToImageData(msg);
  if (canvas.width !== img.width || canvas.height !== img.height) { canvas.width = img.width; canvas.height = img.height; }
  canvas.getContext("2d").putImageData(img, 0, 0);
}

export class ImageViewTool {
  constructor(pane, ros, params) {
    this.ros = ros;
    this.frames = 0; // frames drawn (for the benchmark)
    this.received = 0;
    this.latest = null;
    this.drawing = false;
    this.msgs = new MessageArea();
    this.select = el("select", { class: "iv-topic", onchange: () => this.choose(this.select.value) });
    this.info = el("span", { class: "iv-info" });
    this.canvas = el("canvas", { id: "iv-canvas", width: 1, height: 1 });
    pane.append(el("div", { class: "rq-bar" }, "Topic ", this.select, el("button", { onclick: () => this.refresh() }, "refresh"), this.info), this.msgs.node, this.canvas);
    this.wanted = params.get("topic") || "";
    ros.on("channels", () => this.refresh());
    this.refresh();
    if (this.wanted) this.choose(this.wanted);
    const tick = () => { this.paint(); requestAnimationFrame(tick); };
    requestAnimationFrame(tick);
  }

  refresh() {
    const topics = this.ros.topics().filter((t) => IMAGE_TYPES.has(t.type)).map((t) => ({ value: t.name, label: `${t.name} (${t.type.split("/")[1]})` }));
    if (this.topic && !topics.some((t) => t.value === this.topic)) topics.push({ value: this.topic, label: `${this.topic} (not published)` });
    fillSelect(this.select, topics, "(choose an image topic)");
    if (this.topic) this.select.value = this.topic;
  }

  choose(topic) {
    this.sub?.unsubscribe();
    this.sub = null;
    this.topic = topic;
    this.latest = null;
    this.msgs.clear();
    if (!topic) return;
    this.sub = this.ros.subscribe(topic, (msg, info) => {
      if (!IMAGE_TYPES.has(info.type)) { this.msgs.show(`topic ${topic} is ${info.type}, not an image`); return; }
      this.received++;
      this.latest = { msg, type: info.type };
    }, { onError: (t) => this.msgs.show(t) });
    this.refresh();
  }

  async paint() {
    if (!this.latest || this.drawing) return;
    const { msg, type } = this.latest;
    this.latest = null;
    this.drawing = true;
    try {
      await drawImage(this.canvas, type, msg);
      this.frames++;
      this.info.textContent = type === "sensor_msgs/Image" ? `${msg.width}x${msg.height} ${msg.encoding}` : `${this.canvas.width}x${this.canvas.height} ${msg.format}`;
      if (this.msgs.node.childElementCount) this.msgs.clear();
    } catch (err) {
      this.msgs.show(`${this.topic}: ${err.message}`);
    } finally {
      this.drawing = false;
    }
  }
}
