// Foxglove's own client (npm @foxglove/ws-protocol) against the gateway, for tests/bridge.
// usage: node foxglove_client.js URL SUBPROTOCOL [TOKEN]
// Prints one JSON object per line for each step; the Python test drives the ROS side and checks them.
"use strict";
const { FoxgloveClient } = require("@foxglove/ws-protocol");
const { parse } = require("@foxglove/rosmsg");
const { MessageReader, MessageWriter } = require("@foxglove/rosmsg-serialization");
const WebSocket = require("ws");

const [url, subprotocol] = process.argv.slice(2);
const ws = new WebSocket(url, [subprotocol]);
// FoxgloveClient (up to 0.8) insists on the name foxglove.websocket.v1; foxglove.sdk.v1 is the newer
// SDKs' name for the same wire protocol, so for that handshake the client sees the socket through a
// view that reports the name it knows (the real negotiated name is printed on "open").
const view =
  subprotocol === FoxgloveClient.SUPPORTED_SUBPROTOCOL
    ? ws
    : new Proxy(ws, {
        get(target, key) {
          if (key === "protocol") return FoxgloveClient.SUPPORTED_SUBPROTOCOL;
          const value = Reflect.get(target, key);
          return typeof value === "function" ? value.bind(target) : value;
        },
        set(target, key, value) {
          target[key] = value;
          return true;
        },
      });
const client = new FoxgloveClient({ ws: view });
const out = (event, data) => process.stdout.write(JSON.stringify({ event, ...data }) + "\n");
const plain = (value) => JSON.parse(JSON.stringify(value, (_k, v) => (typeof v === "bigint" ? Number(v) : v)));

let readers = new Map();
let published = false;
let called = false;

client.on("open", () => out("open", { protocol: ws.protocol }));
client.on("serverInfo", (info) => {
  out("serverInfo", { name: info.name, capabilities: info.capabilities, encodings: info.supportedEncodings });
  client.getParameters(["/fox/speed", "/fox/name"], "params-1");
});
client.on("status", (s) => out("status", { level: s.level, message: s.message }));
client.on("error", (e) => out("error", { message: String(e) }));
client.on("advertise", (channels) => {
  for (const ch of channels) {
    if (ch.topic === "/fox_out") {
      const sub = client.subscribe(ch.id);
      readers.set(sub, new MessageReader(parse(ch.schema)));
      out("advertise", { topic: ch.topic, encoding: ch.encoding, schemaName: ch.schemaName, schemaEncoding: ch.schemaEncoding });
    }
  }
  if (!published) {
    published = true;
    const def = "string data\n";
    const channel = client.advertise({ topic: "/fox_in", encoding: "ros1", schemaName: "std_msgs/String", schema: def });
    const writer = new MessageWriter(parse(def));
    const timer = setInterval(() => client.sendMessage(channel, writer.writeMessage({ data: "hello from foxglove" })), 100);
    setTimeout(() => clearInterval(timer), 20000).unref();
  }
});
client.on("message", ({ subscriptionId, timestamp, data }) => {
  const reader = readers.get(subscriptionId);
  if (reader) {
    const msg = reader.readMessage(new Uint8Array(data.buffer, data.byteOffset, data.byteLength));
    out("message", { timestamp: Number(timestamp), msg: plain(msg) });
  }
});
client.on("advertiseServices", (services) => {
  for (const srv of services) {
    if (srv.name === "/add_two_ints" && !called) {
      called = true;
      const req = new MessageWriter(parse(srv.requestSchema)).writeMessage({ a: 40n, b: 2n });
      const reader = new MessageReader(parse(srv.responseSchema));
      client.on("serviceCallResponse", (resp) => {
        const d = resp.data;
        out("serviceCallResponse", { encoding: resp.encoding, msg: plain(reader.readMessage(new Uint8Array(d.buffer, d.byteOffset, d.byteLength))) });
      });
      client.sendServiceCallRequest({ serviceId: srv.id, callId: 7, encoding: "ros1", data: new DataView(req.buffer, req.byteOffset, req.byteLength) });
      out("advertiseServices", { name: srv.name, type: srv.type });
    }
  }
});
client.on("parameterValues", ({ parameters, id }) => out("parameterValues", { id, parameters }));
client.on("close", (e) => {
  out("close", { code: e && e.code });
  process.exit(0);
});
process.stdin.on("data", () => {});
process.stdin.on("end", () => process.exit(0));
