// Reference-client check of mocap's Foxglove live view, run by the test suite (ctest
// foxglove_reference_client): connects to ws://HOST:PORT with @foxglove/ws-protocol's
// FoxgloveClient (the protocol's reference implementation) over `ws`, subscribes to
// /tf, /markers, /joints and the cameras' /camN/blobs overlays, validates EVERY message
// against Foxglove's published JSON schemas (@foxglove/schemas) or the advertised schema
// (/joints), checks that each overlay's pixels decode to width x height with some blob
// drawn, and checks that
// FrameTransforms and SceneUpdate arrive at >= MIN_HZ. Optional hostile mode: at the
// same time one viewer subscribes and never reads again, and others flood malformed
// frames; the checks above must still pass. Exit status 0 = pass; failures print one
// line each.
//   node viewer_check.mjs URL SECONDS MIN_HZ [--hostile]
import { createRequire } from "node:module";
import WebSocket from "ws";

const require = createRequire(import.meta.url);  // CommonJS-only packages
const { FoxgloveClient } = require("@foxglove/ws-protocol");
const schemas = require("@foxglove/schemas/jsonschema");
const Ajv = require("ajv");

const [url, secondsArg, minHzArg, mode] = process.argv.slice(2);
const seconds = Number(secondsArg ?? 3);
const minHz = Number(minHzArg ?? 30);
const failures = [];
const fail = (m) => failures.push(m);

const ajv = new Ajv({ strict: false, allErrors: true });
const expected = {
  "/tf": { schemaName: "foxglove.FrameTransforms", validate: ajv.compile(schemas.FrameTransforms) },
  "/markers": { schemaName: "foxglove.SceneUpdate", validate: ajv.compile(schemas.SceneUpdate) },
  "/joints": { schemaName: "mocap.JointAngles", validate: null },
  "/cam0/blobs": { schemaName: "foxglove.RawImage", validate: ajv.compile(schemas.RawImage) },
  "/cam1/blobs": { schemaName: "foxglove.RawImage", validate: ajv.compile(schemas.RawImage) },
};
const stats = {};
const bySubscription = new Map();

function hostile() {
  const sockets = [];
  // A viewer that subscribes and then never reads (its socket is paused).
  const stalled = new WebSocket(url, [FoxgloveClient.SUPPORTED_SUBPROTOCOL]);
  stalled.on("message", (data, isBinary) => {
    if (isBinary) return;
    const m = JSON.parse(data.toString());
    if (m.op === "advertise") {
      stalled.send(JSON.stringify({ op: "subscribe",
        subscriptions: m.channels.map((c, i) => ({ id: i, channelId: c.id })) }));
      setTimeout(() => stalled._socket.pause(), 50);
    }
  });
  stalled.on("error", () => {});
  sockets.push(stalled);
  // Floods of malformed frames, one new connection every 50 ms.
  const junk = ["{", "[]", '{"op":"nope"}', '{"op":"subscribe","subscriptions":[{"id":1,"channelId":999}]}',
                Buffer.from([1, 2, 3, 4]), "x".repeat(70000)];
  let n = 0;
  const timer = setInterval(() => {
    const ws = new WebSocket(url, [FoxgloveClient.SUPPORTED_SUBPROTOCOL]);
    const payload = junk[n++ % junk.length];
    ws.on("open", () => { for (let i = 0; i < 5; ++i) ws.send(payload); });
    ws.on("error", () => {});
    ws.on("close", () => {});
  }, 50);
  return () => { clearInterval(timer); for (const s of sockets) s.terminate(); };
}

const client = new FoxgloveClient({ ws: new WebSocket(url, [FoxgloveClient.SUPPORTED_SUBPROTOCOL]) });
let stopHostile = null;
client.on("error", (e) => fail(`client error: ${e.message ?? e}`));
client.on("close", () => {});
client.on("serverInfo", (info) => {
  if (info.name !== "mocap") fail(`serverInfo name '${info.name}'`);
});
client.on("advertise", (channels) => {
  for (const [topic, want] of Object.entries(expected)) {
    const ch = channels.find((c) => c.topic === topic);
    if (!ch) { fail(`channel ${topic} not advertised`); continue; }
    if (ch.schemaName !== want.schemaName) fail(`${topic}: schema ${ch.schemaName}`);
    if (ch.encoding !== "json") fail(`${topic}: encoding ${ch.encoding}`);
    const own = ajv.compile(JSON.parse(ch.schema));  // the advertised schema itself
    const validate = want.validate ?? own;
    stats[topic] = { n: 0, first: 0, last: 0, bad: 0, entities: 0, transforms: 0 };
    bySubscription.set(client.subscribe(ch.id), { topic, validate, own });
  }
  if (mode === "--hostile") stopHostile = hostile();
});
const decoder = new TextDecoder();
client.on("message", ({ subscriptionId, data }) => {
  const sub = bySubscription.get(subscriptionId);
  if (!sub) return fail(`message for unknown subscription ${subscriptionId}`);
  const s = stats[sub.topic];
  const now = performance.now();
  if (s.n === 0) s.first = now;
  s.last = now;
  s.n += 1;
  let msg;
  try { msg = JSON.parse(decoder.decode(data)); } catch { s.bad += 1; return; }
  for (const validate of [sub.validate, sub.own]) {
    if (!validate(msg)) {
      if (s.bad++ < 3) fail(`${sub.topic}: schema violation ${ajv.errorsText(validate.errors)}`);
    }
  }
  if (sub.topic === "/tf") s.transforms += msg.transforms?.length ?? 0;
  if (sub.topic === "/markers") s.entities += msg.entities?.length ?? 0;
  if (sub.topic.endsWith("/blobs")) {
    // mono8: width*height bytes; blobs are the pixels brighter than the border (40).
    const px = Buffer.from(msg.data ?? "", "base64");
    if (msg.encoding !== "mono8" || px.length !== msg.width * msg.height || msg.step !== msg.width) {
      if (s.bad++ < 3) fail(`${sub.topic}: ${msg.encoding} ${msg.width}x${msg.height} with ${px.length} bytes`);
    }
    s.entities += px.some((v) => v > 40) ? 1 : 0;
  }
});

setTimeout(() => {
  if (stopHostile) stopHostile();
  client.close();
  for (const topic of Object.keys(expected)) {
    const s = stats[topic];
    if (!s || s.n < 2) { fail(`${topic}: ${s ? s.n : 0} messages`); continue; }
    const hz = (s.n - 1) / ((s.last - s.first) / 1000);
    console.log(`${topic}: ${s.n} messages, ${hz.toFixed(1)} Hz, ${s.bad} invalid`);
    if ((topic === "/tf" || topic === "/markers") && hz < minHz) fail(`${topic}: ${hz.toFixed(1)} Hz < ${minHz} Hz`);
  }
  if (stats["/tf"] && stats["/tf"].transforms === 0) fail("/tf: no body transform in any message");
  if (stats["/markers"] && stats["/markers"].entities === 0) fail("/markers: no entity");
  for (const t of ["/cam0/blobs", "/cam1/blobs"]) {
    if (stats[t] && stats[t].entities === 0) fail(`${t}: no blob drawn in any image`);
  }
  for (const f of failures) console.error(`FAIL ${f}`);
  process.exit(failures.length === 0 ? 0 : 1);
}, seconds * 1000);
