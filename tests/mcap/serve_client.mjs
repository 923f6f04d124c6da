// A Foxglove WebSocket client built from the ecosystem's own code (@foxglove/ws-protocol's
// FoxgloveClient on the `ws` package; schemas parsed by @foxglove/omgidl-parser, messages
// decoded by @foxglove/omgidl-serialization's MessageReader, as Foxglove and Lichtblick do)
// against `pmuctl serve` on the simulated power system (deploy/examples/sim-power-system.yaml).
//
//   node serve_client.mjs URL check WATCH.jsonl SECONDS
//     serverInfo, the advertised channels and their schemas, error statuses for bad requests;
//     subscribes to pmu/voltages, pmu/health, pmu/battery, pmu/info and pmu/config and checks
//     their messages (the state topics', published once long before this client came, must
//     arrive at once, as DDS gives a late joiner the current state):
//     keys and field names as `pmuctl watch --json` prints them (WATCH.jsonl, recorded over
//     the same seconds), the same values for the same samples, timestamps of now; the
//     capability time: a Time message before the first message, none going back, no live
//     message stamped after the last Time, state sent at subscribe stamped no earlier than it
//     (a player's timeline is not stretched back to when that state was published).
//   node serve_client.mjs URL first SECONDS
//     subscribes to pmu/voltages and ends at the first message that decodes, with its values on
//     stdout; exit status 1 if none came within SECONDS (a bound that only turns "never"
//     into a failure: when the first sample comes is up to DDS discovery).
//   node serve_client.mjs URL count SECONDS OUT.json
//     subscribes to pmu/voltages and writes {"messages": N, "per_second": [...]} to OUT.json
//     (the slow-client test's reader that must keep receiving).
// A wss:// URL is verified against the certificate in $SERVE_TLS_CA (a self-signed one).
// Exit status 0 when every check passed; 1 with the problems on stderr.
import { readFileSync, writeFileSync } from "node:fs";
import wsProtocol from "@foxglove/ws-protocol"; // CommonJS: no named exports
const { FoxgloveClient } = wsProtocol;
import { parseIDL } from "@foxglove/omgidl-parser";
import { MessageReader } from "@foxglove/omgidl-serialization";
import WebSocket from "ws";

const [url, mode, ...rest] = process.argv.slice(2);
const problems = [];
const problem = (p) => problems.push(p);

// The topics `pmuctl record` records by default (docs/interface.md section 9.1), and so serve.
const defaultTopics = {
  "pmu/voltages": "pmu::v5::Voltages",
  "pmu/currents": "pmu::v5::Currents",
  "pmu/battery_energy": "pmu::v5::BatteryEnergy",
  "pmu/temperatures": "pmu::v5::Temperatures",
  "pmu/status": "pmu::v5::Status",
  "pmu/config": "pmu::v5::Config",
  "pmu/info": "pmu::v5::DeviceInfo",
  "pmu/health": "pmu::v5::Health",
  "pmu/battery": "pmu::v5::Battery",
  "pmu/battery_cells": "pmu::v5::BatteryCells",
  "pmu/mppt": "pmu::v5::Mppt",
  "pmu/alarms": "pmu::v5::Alarm",
  "pmu/readiness": "pmu::v5::Readiness",
  "pmu/energy": "pmu::v5::Energy",
  "pmu/bms_energy": "pmu::v5::BmsEnergy",
  "pmu/baseline": "pmu::v5::Baseline",
};

// float32 on the wire: the shortest decimal that is the same float32, as pmuctl prints it.
const f32 = (v) => (typeof v === "number" && Number.isFinite(v) && !Number.isInteger(v) ? Number(Math.fround(v).toPrecision(7)) : v);
const sameNumber = (a, b) => a === b || (typeof a === "number" && typeof b === "number" && Math.abs(a - b) <= 1e-6 * Math.max(1, Math.abs(a)));

const ws = new WebSocket(
  url,
  [FoxgloveClient.SUPPORTED_SUBPROTOCOL],
  process.env.SERVE_TLS_CA ? { ca: readFileSync(process.env.SERVE_TLS_CA) } : {},
);
const client = new FoxgloveClient({ ws });
const channels = new Map(); // id -> {topic, schemaName, reader}
const subscriptions = new Map(); // subscription id -> channel
const received = new Map(); // topic -> [{time (bigint ns), values}]
const statuses = [];
let serverInfo;
let perSecond = [0];
const times = []; // the Time messages' timestamps (bigint ns)

client.on("error", (e) => problem(`client error: ${e.message ?? e}`));
client.on("serverInfo", (info) => (serverInfo = info));
client.on("status", (s) => statuses.push(s));
client.on("time", ({ timestamp }) => times.push(timestamp));
client.on("advertise", (list) => {
  for (const c of list) {
    try {
      const definitions = parseIDL(c.schema);
      channels.set(c.id, { ...c, reader: new MessageReader(c.schemaName, definitions) });
    } catch (e) {
      problem(`channel ${c.topic}: schema ${c.schemaName} does not parse: ${e.message}`);
      channels.set(c.id, c);
    }
  }
  start();
});
client.on("message", ({ subscriptionId, timestamp, data }) => {
  const channel = subscriptions.get(subscriptionId);
  if (!channel) return problem(`message for unknown subscription ${subscriptionId}`);
  perSecond[perSecond.length - 1]++;
  if (mode === "first") {
    try {
      const bytes = new Uint8Array(data.buffer, data.byteOffset, data.byteLength);
      const v = channel.reader.readMessage(bytes);
      if (!(v.avionics > 5 && v.avionics < 40)) problem(`voltages avionics ${v.avionics}`);
      finish(() => console.log(`serve_client first: ${channel.topic} of ${v.bus}/${v.address}, avionics ${v.avionics}`));
    } catch (e) {
      problem(`${channel.topic}: message does not decode: ${e.message}`);
    }
    return;
  }
  if (mode !== "check") return;
  try {
    const bytes = new Uint8Array(data.buffer, data.byteOffset, data.byteLength);
    const values = channel.reader.readMessage(bytes);
    if (!received.has(channel.topic)) received.set(channel.topic, []);
    received.get(channel.topic).push({ time: timestamp, values, clock: times.at(-1) });
  } catch (e) {
    problem(`${channel.topic}: message does not decode: ${e.message}`);
  }
});
client.on("close", (e) => {
  if (!finished) problem(`server closed the connection early (code ${e.code})`);
});

let started = false;
let finished = false;
function subscribe(topic) {
  const entry = [...channels.entries()].find(([, c]) => c.topic === topic);
  if (!entry) return problem(`no channel ${topic}`);
  subscriptions.set(client.subscribe(entry[0]), entry[1]);
}

function start() {
  if (started) return;
  started = true;
  if (mode === "check") {
    for (const t of ["pmu/voltages", "pmu/health", "pmu/battery", "pmu/info", "pmu/config"]) subscribe(t);
    // Requests the server must refuse with a status of level error, and go on serving.
    ws.send("not json");
    ws.send(JSON.stringify({ op: "fly" }));
    ws.send(JSON.stringify({ op: "subscribe", subscriptions: [{ id: 900, channelId: 4000 }] }));
    ws.send(JSON.stringify({ op: "subscribe", subscriptions: [{ id: -1, channelId: 0 }] }));
    ws.send(new Uint8Array([1, 0, 0, 0, 0]));
    setTimeout(finishCheck, Number(rest[1]) * 1000);
  } else if (mode === "first") {
    subscribe("pmu/voltages");
    setTimeout(() => {
      problem(`no pmu/voltages message within ${rest[0]} s`);
      finish();
    }, Number(rest[0]) * 1000);
  } else {
    subscribe("pmu/voltages");
    const tick = setInterval(() => perSecond.push(0), 1000);
    setTimeout(() => {
      clearInterval(tick);
      finish(() => {
        const total = perSecond.reduce((a, b) => a + b, 0);
        writeFileSync(rest[1], JSON.stringify({ messages: total, per_second: perSecond }) + "\n");
        console.log(`serve_client count: ${total} messages, per second ${perSecond.join(" ")}`);
      });
    }, Number(rest[0]) * 1000);
  }
}

function finish(report) {
  finished = true;
  client.close();
  report?.();
  if (problems.length) {
    console.error(problems.slice(0, 30).join("\n"));
    process.exit(1);
  }
  process.exit(0);
}

function finishCheck() {
  // serverInfo
  if (!serverInfo) problem("no serverInfo");
  else {
    if (!/pmuctl/.test(serverInfo.name)) problem(`serverInfo name ${serverInfo.name}`);
    if (JSON.stringify(serverInfo.capabilities) !== JSON.stringify(["time"]))
      problem(`serverInfo capabilities ${JSON.stringify(serverInfo.capabilities)}, not ["time"]`);
  }
  // The capability time: the server's clock is the source time of what it forwards.
  if (!times.length) problem("no Time message");
  if (times.some((t, i) => i > 0 && t < times[i - 1])) problem(`the server's time went back: ${times.slice(0, 10)}`);
  const stateTopics = ["pmu/info", "pmu/config", "pmu/health"];
  for (const [topic, list] of received)
    for (const m of list) {
      if (m.clock === undefined) problem(`${topic}: a message before any Time message`);
      else if (!stateTopics.includes(topic) && m.time > m.clock)
        problem(`${topic}: stamped ${m.time}, after the server's time ${m.clock}`);
    }
  // pmu/info was published once, when the service started: what the late subscriber gets is
  // stamped with the server's time then, not that old source time.
  for (const m of received.get("pmu/info") ?? [])
    if (m.clock !== undefined && m.time < m.clock) problem(`pmu/info stamped ${m.time}, before the server's time ${m.clock}`);
  if (ws.protocol !== FoxgloveClient.SUPPORTED_SUBPROTOCOL) problem(`negotiated subprotocol "${ws.protocol}"`);

  // advertise: record's default topics, named as the DDS topics, cdr + omgidl
  const advertised = Object.fromEntries([...channels.values()].map((c) => [c.topic, c.schemaName]));
  if (JSON.stringify(Object.keys(advertised).sort()) !== JSON.stringify(Object.keys(defaultTopics).sort()))
    problem(`advertised topics ${Object.keys(advertised).join(", ")}`);
  for (const c of channels.values()) {
    if (c.encoding !== "cdr" || c.schemaEncoding !== "omgidl") problem(`${c.topic}: ${c.encoding}/${c.schemaEncoding}`);
    if (defaultTopics[c.topic] && c.schemaName !== defaultTopics[c.topic]) problem(`${c.topic}: schemaName ${c.schemaName}`);
  }

  // statuses for the bad requests
  const errors = statuses.filter((s) => s.level === 2).map((s) => s.message);
  for (const want of [/not JSON/, /unknown op "fly"/, /channel 4000 was not advertised/, /id must be an integer/, /binary message with opcode 1/])
    if (!errors.some((m) => want.test(m))) problem(`no error status matching ${want}: got ${JSON.stringify(errors)}`);

  // messages: timestamps of now, keys, field names and values as pmuctl watch --json
  const now = BigInt(Date.now()) * 1000000n;
  for (const [topic, list] of received)
    for (const m of list)
      if (m.time < now - 60n * 1000000000n || m.time > now + 5n * 1000000000n)
        problem(`${topic}: timestamp ${m.time} is not near now (${now})`);
  const watch = readFileSync(rest[0], "utf8").split("\n").filter((l) => l.trim()).map((l) => JSON.parse(l));
  const compare = (topic, watchTopic, keyName) => {
    const ours = received.get(topic) ?? [];
    const theirs = watch.filter((w) => w.topic === watchTopic);
    if (ours.length < 2) return problem(`${ours.length} ${topic} messages`);
    if (!theirs.length) return problem(`pmuctl watch printed no ${watchTopic}`);
    const fields = Object.keys(theirs[0].values).sort();
    let matched = 0;
    for (const m of ours) {
      const names = Object.keys(m.values).filter((k) => !["vehicle", "bus", keyName, "received"].includes(k)).sort();
      if (JSON.stringify(names) !== JSON.stringify(fields)) {
        problem(`${topic} fields ${names} differ from pmuctl watch's ${fields}`);
        break;
      }
      const seconds = Number(m.time) / 1e9;
      const w = theirs.find((x) => Math.abs(x.time - seconds) < 1e-5 && x.bus === m.values.bus && x[keyName] === m.values[keyName]);
      if (!w) continue;
      matched++;
      for (const f of fields)
        if (w.values[f] !== null && !sameNumber(f32(m.values[f]), w.values[f]))
          problem(`${topic} ${f}: ${f32(m.values[f])} here, ${w.values[f]} in pmuctl watch (time ${seconds})`);
    }
    if (!matched) problem(`no ${topic} message has the time of a pmuctl watch line`);
    return matched;
  };
  const v = compare("pmu/voltages", "voltages", "address");
  const b = compare("pmu/battery", "battery", "node");
  for (const m of received.get("pmu/voltages") ?? []) {
    if (m.values.bus !== "sim0" || m.values.address !== 1) problem(`voltages keys ${m.values.bus}/${m.values.address}`);
    if (!(m.values.avionics > 5 && m.values.avionics < 40)) problem(`voltages avionics ${m.values.avionics}`);
  }
  for (const m of received.get("pmu/battery") ?? [])
    if (m.values.node !== 2 || !(m.values.state_of_charge >= 0 && m.values.state_of_charge <= 100))
      problem(`battery ${JSON.stringify(m.values, (k, x) => (typeof x === "bigint" ? x.toString() : x))}`);
  const health = received.get("pmu/health") ?? [];
  if (!health.length) problem("no pmu/health message (state: TRANSIENT_LOCAL gives the current one at once)");
  for (const m of health) if (m.values.bus !== "sim0") problem(`health bus ${m.values.bus}`);
  const info = received.get("pmu/info") ?? [];
  if (info.length !== 1) problem(`${info.length} pmu/info messages, not the one current sample of the one PMU`);
  for (const m of info)
    if (m.values.bus !== "sim0" || m.values.address !== 1 || !(m.values.firmware_major >= 1))
      problem(`info ${m.values.bus}/${m.values.address} firmware ${m.values.firmware_major}.${m.values.firmware_minor}`);
  const config = received.get("pmu/config") ?? [];
  if (!config.length) problem("no pmu/config message: the current state was not sent to a late subscriber");
  for (const m of config) if (!(m.values.packet_period > 0)) problem(`config packet_period ${m.values.packet_period}`);
  finish(() =>
    console.log(
      `serve_client check: ${channels.size} channels; ${[...received].map(([t, l]) => `${t} ${l.length}`).join(", ")}; ` +
        `${v} voltages and ${b} battery samples equal to pmuctl watch's; ${errors.length} error statuses`,
    ),
  );
}
