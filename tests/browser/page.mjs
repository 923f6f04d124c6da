// The page of the browser test (bundled for the browser by esbuild at test time): what an
// integrator's Foxglove web app does with `pmuctl serve` (docs/interface.md section 9.2), with
// the browser's own WebSocket and Foxglove's omgidl parser and CDR decoder.
//   index.html?ws=URL&protocol=SUBPROTOCOL&voltages=N
// Connects offering SUBPROTOCOL, subscribes to pmu/voltages and pmu/battery, decodes their
// messages and keeps the server's Time messages (opcode 0x02) until it has N pmu/voltages and
// 2 pmu/battery messages (or the connection closes), then draws pmu/voltages' avionics
// against the time axis a Foxglove player uses (the message timestamp when the server has the
// `time` capability, the arrival time otherwise) and leaves what it saw in window.pmuResult
// for the test to judge. The page judges nothing itself.
import { parseIDL } from "@foxglove/omgidl-parser";
import { MessageReader } from "@foxglove/omgidl-serialization";

const params = new URLSearchParams(location.search);
const url = params.get("ws");
const protocol = params.get("protocol");
const wantedVoltages = Number(params.get("voltages"));
const wanted = ["pmu/voltages", "pmu/battery"];

const errors = [];
const statuses = [];
let serverInfo = null;
const advertised = {}; // topic -> {schemaName, encoding, schemaEncoding, schemaBytes}
const subscriptions = new Map(); // subscription id -> {topic, reader}
const messages = { "pmu/voltages": [], "pmu/battery": [] };
const times = []; // Time messages: {time_ns (string), arrival_ms}
let latestTime = null; // bigint ns of the last Time message
let closeCode = null;
let finished = false;

// Numbers the page hands back: bigints as strings (JSON has no bigint).
const plain = (v) => JSON.parse(JSON.stringify(v, (k, x) => (typeof x === "bigint" ? x.toString() : x)));

const ws = new WebSocket(url, [protocol]);
ws.binaryType = "arraybuffer";
ws.onerror = () => errors.push(`WebSocket error on ${url}`);
ws.onclose = (e) => {
  closeCode = e.code;
  if (!finished) {
    errors.push(`the server closed the connection (code ${e.code} ${e.reason})`);
    finish();
  }
};
ws.onmessage = (event) => {
  if (typeof event.data === "string") return onText(event.data);
  const view = new DataView(event.data);
  const opcode = view.getUint8(0);
  if (opcode === 0x02) {
    latestTime = view.getBigUint64(1, true);
    times.push({ time_ns: latestTime.toString(), arrival_ms: Date.now() });
  } else if (opcode === 0x01) {
    const id = view.getUint32(1, true);
    const timestamp = view.getBigUint64(5, true);
    const sub = subscriptions.get(id);
    if (!sub) return errors.push(`message for unknown subscription ${id}`);
    try {
      const values = sub.reader.readMessage(new Uint8Array(event.data, 13));
      messages[sub.topic].push({
        timestamp_ns: timestamp.toString(),
        arrival_ms: Date.now(),
        latest_time_ns: latestTime === null ? null : latestTime.toString(),
        values: plain(values),
      });
      if (messages["pmu/voltages"].length >= wantedVoltages && messages["pmu/battery"].length >= 2) finish();
    } catch (e) {
      errors.push(`${sub.topic}: message does not decode: ${e.message}`);
    }
  } else {
    errors.push(`binary message with opcode ${opcode}`);
  }
};

function onText(text) {
  let m;
  try {
    m = JSON.parse(text);
  } catch (e) {
    return errors.push(`text message is not JSON: ${text.slice(0, 80)}`);
  }
  if (m.op === "serverInfo") serverInfo = m;
  else if (m.op === "status") statuses.push(m);
  else if (m.op === "advertise") {
    const subscribe = [];
    for (const c of m.channels) {
      advertised[c.topic] = { schemaName: c.schemaName, encoding: c.encoding, schemaEncoding: c.schemaEncoding, schemaBytes: c.schema.length };
      if (!wanted.includes(c.topic)) continue;
      try {
        const reader = new MessageReader(c.schemaName, parseIDL(c.schema));
        const id = subscriptions.size + 1;
        subscriptions.set(id, { topic: c.topic, reader });
        subscribe.push({ id, channelId: c.id });
      } catch (e) {
        errors.push(`${c.topic}: schema ${c.schemaName} does not parse: ${e.message}`);
      }
    }
    if (subscribe.length) ws.send(JSON.stringify({ op: "subscribe", subscriptions: subscribe }));
  }
}

function finish() {
  if (finished) return;
  finished = true;
  ws.close();
  const timeAxis = Boolean(serverInfo?.capabilities?.includes("time"));
  const plot = draw(timeAxis);
  window.pmuResult = {
    href: location.href,
    origin: location.origin,
    url,
    offered: protocol,
    negotiated: ws.protocol,
    serverInfo,
    advertised,
    statuses,
    times,
    messages,
    plot,
    closeCode,
    errors,
  };
  document.title = "done";
}

// pmu/voltages' avionics against the player's time axis, with both axes labelled.
function draw(timeAxis) {
  const canvas = document.getElementById("plot");
  const g = canvas.getContext("2d");
  const W = canvas.width;
  const H = canvas.height;
  const left = 70;
  const right = 60;
  const top = 40;
  const bottom = 70;
  const points = messages["pmu/voltages"].map((m) => ({
    t: timeAxis ? Number(BigInt(m.timestamp_ns) / 1000000n) / 1000 : m.arrival_ms / 1000,
    v: m.values.avionics,
  }));
  const xLabel = timeAxis
    ? "time (UTC): message timestamp = CAN receive time (server capability `time`)"
    : "time (UTC): arrival in the browser (server without the `time` capability)";
  const yLabel = "pmu/voltages avionics (V)";
  g.fillStyle = "#fff";
  g.fillRect(0, 0, W, H);
  g.fillStyle = "#000";
  g.font = "14px sans-serif";
  g.fillText(`pmuctl serve over ${url.split(":")[0]}:// from ${location.origin}, ${ws.protocol || protocol}`, left, 22);
  g.strokeStyle = "#000";
  g.strokeRect(left, top, W - left - right, H - top - bottom);
  g.font = "12px sans-serif";
  g.fillText(xLabel, left, H - 26);
  const last = latestTime === null ? "none" : new Date(Number(latestTime / 1000000n)).toISOString().slice(11, 23);
  g.fillText(`${points.length} samples; ${times.length} Time messages, the last ${last}`, left, H - 8);
  g.save();
  g.translate(16, top + (H - top - bottom) / 2 + 70);
  g.rotate(-Math.PI / 2);
  g.fillText(yLabel, 0, 0);
  g.restore();
  if (points.length < 2) {
    g.fillText(`${points.length} samples`, left + 10, top + 20);
    return { points: points.length, xLabel, yLabel, timeAxis };
  }
  const t0 = Math.min(...points.map((p) => p.t));
  const t1 = Math.max(...points.map((p) => p.t));
  let v0 = Math.min(...points.map((p) => p.v));
  let v1 = Math.max(...points.map((p) => p.v));
  if (v1 - v0 < 0.5) {
    v0 -= 0.25;
    v1 += 0.25;
  }
  const x = (t) => left + ((t - t0) / (t1 - t0 || 1)) * (W - left - right);
  const y = (v) => H - bottom - ((v - v0) / (v1 - v0)) * (H - top - bottom);
  for (let i = 0; i <= 4; i++) {
    const t = t0 + ((t1 - t0) * i) / 4;
    const label = new Date(t * 1000).toISOString().slice(11, 22);
    g.fillText(label, x(t) - 30, H - bottom + 16);
    const v = v0 + ((v1 - v0) * i) / 4;
    g.fillText(v.toFixed(2), 20, y(v) + 4);
  }
  g.strokeStyle = "#1f77b4";
  g.lineWidth = 2;
  g.beginPath();
  points.forEach((p, i) => (i ? g.lineTo(x(p.t), y(p.v)) : g.moveTo(x(p.t), y(p.v))));
  g.stroke();
  g.fillStyle = "#1f77b4";
  for (const p of points) g.fillRect(x(p.t) - 2, y(p.v) - 2, 4, 4);
  return { points: points.length, xLabel, yLabel, timeAxis, t0, t1, v0, v1 };
}
