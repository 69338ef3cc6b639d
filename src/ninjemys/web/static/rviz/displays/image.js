// The Image display: raw and compressed images drawn on a canvas beside the view.

import { $, state } from "/static/rviz/context.js";
import { Display } from "/static/rviz/display.js";

const RAW_ENCODINGS = new Set(["rgb8", "bgr8", "rgba8", "bgra8", "mono8", "8uc1", "16uc1", "mono16", "32fc1"]);

export class ImageDisplay extends Display {
  constructor(cfg) {
    super(cfg);
    this.figure = document.createElement("figure");
    this.caption = document.createElement("figcaption");
    this.canvas = document.createElement("canvas");
    this.canvas.width = 320; this.canvas.height = 240;
    this.figure.append(this.caption, this.canvas);
    $("rv-images").appendChild(this.figure);
  }
  // rviz's "Transport Hint": compressed subscribes to <Image Topic>/compressed (sensor_msgs/CompressedImage);
  // an Image Topic that itself ends in /compressed is taken as that transport too
  get compressed() { return this.option("Transport Hint", "raw") === "compressed" || /\/compressed$/.test(this.cfg.topic || ""); }
  get msgType() { return this.compressed ? "sensor_msgs/CompressedImage" : "sensor_msgs/Image"; }
  subscribedTopic() {
    const t = this.cfg.topic;
    return t && this.compressed && !/\/compressed$/.test(t) ? `${t}/compressed` : t;
  }
  start() { this.pending = null; this.pendingRaw = null; this.decoding = false; super.start(); this.figure.style.display = this.cfg.enabled ? "" : "none"; this.caption.textContent = `${this.cfg.name}: ${this.subscribedTopic()}`; }
  destroy() { super.destroy(); this.figure.remove(); }
  onMessage(m, info) {
    if (info?.type === "sensor_msgs/CompressedImage" || m.format !== undefined) { this.onCompressed(m); return; }
    this.onRaw(m);
  }
  /** Decode jpeg/png in the browser; while one frame decodes, only the newest waiting frame is kept. */
  onCompressed(m) {
    this.pending = m;
    if (this.decoding) return;
    this.decoding = true;
    const next = async () => {
      while (this.pending) {
        const msg = this.pending;
        this.pending = null;
        const mime = /png/i.test(msg.format) ? "image/png" : "image/jpeg";
        let bitmap;
        try {
          bitmap = await createImageBitmap(new Blob([msg.data], { type: mime }));
        } catch {
          this.setStatus("Message", "error", `cannot decode a CompressedImage of format '${msg.format}' (${msg.data.length} bytes)`);
          continue;
        }
        if (this.canvas.width !== bitmap.width || this.canvas.height !== bitmap.height) { this.canvas.width = bitmap.width; this.canvas.height = bitmap.height; }
        this.canvas.getContext("2d").drawImage(bitmap, 0, 0);
        this.setStatus("Message", null);
        this.setStatus("Image", "ok", `${bitmap.width}×${bitmap.height} ${msg.format}`);
        bitmap.close();
        state.dirty = true;
      }
      this.decoding = false;
    };
    next();
  }
  /** Checked at once (a bad image's status names it), drawn at the next rendered frame: only the newest
   *  image is converted, so a camera faster than the page (a simulator ahead of real time) costs one
   *  conversion a frame, not one a message, and a starved page still takes input. */
  onRaw(m) {
    const { width: w, height: h, encoding, step, data } = m;
    if (!w || !h) throw new Error("empty image");
    if (step * h > data.length) throw new Error(`image data holds ${data.length} bytes; ${h} rows of ${step} need ${step * h}`);
    if (!RAW_ENCODINGS.has(encoding.toLowerCase())) throw new Error(`image encoding ${encoding} is not shown`);
    this.pendingRaw = m;
  }
  update() {
    super.update();
    const m = this.pendingRaw;
    if (!m) return;
    this.pendingRaw = null;
    try {
      this.drawRaw(m);
    } catch (err) {
      this.setStatus("Message", "error", `${this.subscribedTopic()}: ${err.message}`);
    }
  }
  drawRaw(m) {
    const { width: w, height: h, encoding, step, data } = m;
    if (this.canvas.width !== w || this.canvas.height !== h) { this.canvas.width = w; this.canvas.height = h; }
    const ctx = this.canvas.getContext("2d");
    const img = ctx.createImageData(w, h);
    const o = img.data;
    const enc = encoding.toLowerCase();
    const dv = new DataView(data.buffer, data.byteOffset, data.byteLength);
    let depthMax = 0;
    if (enc === "16uc1" || enc === "mono16" || enc === "32fc1") {
      for (let y = 0; y < h; y++) for (let x = 0; x < w; x++) {
        const v = enc === "32fc1" ? dv.getFloat32(y * step + x * 4, !m.is_bigendian) : dv.getUint16(y * step + x * 2, !m.is_bigendian);
        if (v > depthMax && Number.isFinite(v)) depthMax = v;
      }
    }
    // one loop per encoding (no per-pixel dispatch): a 640x480 frame is a few milliseconds
    const le = !m.is_bigendian;
    const colour = { rgb8: [3, 0, 1, 2], bgr8: [3, 2, 1, 0], rgba8: [4, 0, 1, 2], bgra8: [4, 2, 1, 0] }[enc];
    if (colour) {
      const [n, ri, gi, bi] = colour;
      for (let y = 0; y < h; y++) {
        let i = y * step, p = y * w * 4;
        for (let x = 0; x < w; x++, i += n, p += 4) { o[p] = data[i + ri]; o[p + 1] = data[i + gi]; o[p + 2] = data[i + bi]; o[p + 3] = 255; }
      }
    } else if (enc === "mono8" || enc === "8uc1") {
      for (let y = 0; y < h; y++) {
        let i = y * step, p = y * w * 4;
        for (let x = 0; x < w; x++, i++, p += 4) { const v = data[i]; o[p] = v; o[p + 1] = v; o[p + 2] = v; o[p + 3] = 255; }
      }
    } else if (enc === "16uc1" || enc === "mono16" || enc === "32fc1") {
      const float = enc === "32fc1";
      for (let y = 0; y < h; y++) {
        for (let x = 0; x < w; x++) {
          const v = float ? dv.getFloat32(y * step + x * 4, le) : dv.getUint16(y * step + x * 2, le);
          const g = Number.isFinite(v) && depthMax ? Math.round((255 * v) / depthMax) : 0;
          const p = (y * w + x) * 4;
          o[p] = g; o[p + 1] = g; o[p + 2] = g; o[p + 3] = 255;
        }
      }
    } else {
      throw new Error(`image encoding ${encoding} is not shown`);
    }
    ctx.putImageData(img, 0, 0);
    this.setStatus("Image", "ok", `${w}×${h} ${encoding}`);
  }
}
